"""Runs a TensorFlow.js layers model (a Keras topology and its weights manifest) as a torch module.

train.py uses it for an ImageNet encoder from the npm registry: the MobileNetV2 (Sandler et al. 2018) of the
package nsfwjs, unpacked by unpack_nsfwjs.js (docs/training.md, "Pretrained encoders"). The interpreter covers
the layers Keras' MobileNetV2 is built from: InputLayer, Conv2D, DepthwiseConv2D, BatchNormalization (inference
form: moving statistics), ReLU (with max_value), ZeroPadding2D and Add. Only the layers the requested outputs
depend on are built, so a classifier's head (Dense, pooling) may follow them unread.

Keras stores NHWC activations and HWIO kernels; here activations are NCHW and kernels are transposed once at
load. 'same' padding follows TensorFlow (the extra pixel of an odd total goes after), 'valid' pads nothing.
check_tfjs_graph.py runs the same model in TensorFlow.js to check the interpreter.
"""
import json
import os

import numpy as np
import torch
import torch.nn as nn
import torch.nn.functional as F

from .tfjs_graph import read_weights

_SUPPORTED = {"InputLayer", "Conv2D", "DepthwiseConv2D", "BatchNormalization", "ReLU", "ZeroPadding2D", "Add"}


def _same_padding(size, kernel, stride, dilation):
    """TensorFlow's 'same' padding of one axis: (before, after)."""
    effective = (kernel - 1) * dilation + 1
    out = -(-size // stride)
    total = max((out - 1) * stride + effective - size, 0)
    return total // 2, total - total // 2


class LayersModel(nn.Module):
    """The layers of the Keras model in FOLDER/MODEL_JSON that `outputs` (layer names) need; forward(x) takes
    the model's single input as NCHW and returns the outputs' values as NCHW tensors. Kernels, biases and batch
    normalisation's gamma and beta are parameters (frozen unless `trainable`); moving statistics are buffers."""

    def __init__(self, folder, model_json, outputs, trainable=False):
        super().__init__()
        with open(os.path.join(folder, model_json)) as f:
            model = json.load(f)
        topology = model["modelTopology"]
        config = topology.get("model_config", topology)["config"]
        self.layers = {layer["name"]: layer for layer in config["layers"]}
        self.outputs = list(outputs)
        for name in self.outputs:
            if name not in self.layers:
                raise KeyError(f"{model_json}: no layer {name}")
        inputs = [layer for layer in config["layers"] if layer["class_name"] == "InputLayer"]
        if len(inputs) != 1:
            raise ValueError(f"{model_json}: expected one InputLayer, found {len(inputs)}")
        self.input_name = inputs[0]["name"]
        self.order = self._needed()
        for name in self.order:
            kind = self.layers[name]["class_name"]
            if kind not in _SUPPORTED:
                raise ValueError(f"{model_json}: layer {name} is a {kind}, which keras_layers.py does not run "
                                 f"(it runs {', '.join(sorted(_SUPPORTED))})")
        wanted = {f"{name}/{w}" for name in self.order
                  for w in ("kernel", "depthwise_kernel", "bias", "gamma", "beta", "moving_mean", "moving_variance")}
        stored = read_weights(folder, model["weightsManifest"], wanted)
        self.params = nn.ParameterDict()
        for name in self.order:
            layer = self.layers[name]
            kind, cfg = layer["class_name"], layer["config"]
            key = name.replace("/", "__").replace(".", "_")

            def weight(part, required=True):
                value = stored.get(f"{name}/{part}")
                if value is None and required:
                    raise KeyError(f"{model_json}: layer {name} has no weight {part}")
                return None if value is None else torch.from_numpy(np.ascontiguousarray(value, dtype=np.float32))

            if kind == "Conv2D":
                self.params[key + "__kernel"] = nn.Parameter(weight("kernel").permute(3, 2, 0, 1).contiguous(),
                                                             requires_grad=trainable)
            elif kind == "DepthwiseConv2D":
                k = weight("depthwise_kernel")  # kh, kw, in, multiplier
                self.params[key + "__kernel"] = nn.Parameter(
                    k.permute(2, 3, 0, 1).reshape(k.shape[2] * k.shape[3], 1, k.shape[0], k.shape[1]).contiguous(),
                    requires_grad=trainable)
            if kind in ("Conv2D", "DepthwiseConv2D") and cfg.get("use_bias", True):
                self.params[key + "__bias"] = nn.Parameter(weight("bias"), requires_grad=trainable)
            if kind == "BatchNormalization":
                if cfg.get("axis", -1) not in (-1, 3, [3], [-1]):
                    raise ValueError(f"{model_json}: layer {name} normalises axis {cfg['axis']}, not channels")
                mean, var = weight("moving_mean"), weight("moving_variance")
                if cfg.get("scale", True):
                    self.params[key + "__gamma"] = nn.Parameter(weight("gamma"), requires_grad=trainable)
                if cfg.get("center", True):
                    self.params[key + "__beta"] = nn.Parameter(weight("beta"), requires_grad=trainable)
                self.register_buffer(key + "__mean", mean)
                self.register_buffer(key + "__var", var)
            if kind in ("Conv2D", "DepthwiseConv2D") and cfg.get("activation", "linear") not in ("linear", "relu"):
                raise ValueError(f"{model_json}: layer {name} has activation {cfg['activation']}")
            if kind == "ReLU" and (cfg.get("negative_slope") or cfg.get("threshold")):
                raise ValueError(f"{model_json}: layer {name} is a leaky or thresholded ReLU")

    def _needed(self):
        """The names of the layers the outputs depend on, in an order that evaluates inputs first."""
        order, state = [], {}

        def visit(name):
            if state.get(name) == 2:
                return
            if state.get(name) == 1:
                raise ValueError(f"the model has a cycle through layer {name}")
            state[name] = 1
            for source in self._inbound(name):
                visit(source)
            state[name] = 2
            order.append(name)

        for name in self.outputs:
            visit(name)
        return order

    def _inbound(self, name):
        nodes = self.layers[name].get("inbound_nodes", [])
        if len(nodes) > 1:
            raise ValueError(f"layer {name} is shared (called {len(nodes)} times); not supported")
        return [entry[0] for entry in nodes[0]] if nodes else []

    def forward(self, x):
        return self._run({self.input_name: x}, self.order)

    def _below(self, start):
        """The layers that `start` feeds, directly or not, in evaluation order (start itself left out)."""
        below = {start}
        for name in self.order:
            if any(source in below for source in self._inbound(name)):
                below.add(name)
        return [n for n in self.order if n in below and n != start]

    def forward_from(self, start, value):
        """The outputs from `start`'s value (NCHW) alone: only the layers downstream of `start` run (fine-tuning
        the last blocks on cached values). Every output must follow from `start`, and the layers after it may not
        read a layer before it."""
        if getattr(self, "_downstream", (None,))[0] != start:
            below = self._below(start)
            missing = [n for n in self.outputs if n not in below]
            if missing:
                raise ValueError(f"outputs {missing} do not follow from layer {start}")
            self._downstream = (start, below)
        return self._run({start: value}, self._downstream[1])

    def downstream_parameters(self, start):
        """{name: parameter} of the layers forward_from(start, ...) runs."""
        keys = {n.replace("/", "__").replace(".", "_") for n in self._below(start)}
        return {k: p for k, p in self.params.items() if k.rsplit("__", 1)[0] in keys}

    def _run(self, values, order):
        for name in order:
            if name in values:
                continue
            layer = self.layers[name]
            kind, cfg = layer["class_name"], layer["config"]
            key = name.replace("/", "__").replace(".", "_")
            args = [values[s] for s in self._inbound(name)]
            v = args[0]
            if kind in ("Conv2D", "DepthwiseConv2D"):
                kernel = self.params[key + "__kernel"]
                stride, dilation = tuple(cfg.get("strides", (1, 1))), tuple(cfg.get("dilation_rate", (1, 1)))
                if cfg.get("padding", "valid") == "same":
                    # Plain ints, so that an ONNX export pads by constants (OpenCV's importer needs them).
                    top, bottom = _same_padding(int(v.shape[2]), kernel.shape[2], stride[0], dilation[0])
                    left, right = _same_padding(int(v.shape[3]), kernel.shape[3], stride[1], dilation[1])
                    if top or bottom or left or right:
                        v = F.pad(v, (left, right, top, bottom))
                bias = self.params[key + "__bias"] if key + "__bias" in self.params else None
                groups = v.shape[1] if kind == "DepthwiseConv2D" else 1
                v = F.conv2d(v, kernel, bias, stride, 0, dilation, groups)
                if cfg.get("activation", "linear") == "relu":
                    v = F.relu(v)
            elif kind == "BatchNormalization":
                v = F.batch_norm(v, getattr(self, key + "__mean"), getattr(self, key + "__var"),
                                 self.params[key + "__gamma"] if key + "__gamma" in self.params else None,
                                 self.params[key + "__beta"] if key + "__beta" in self.params else None,
                                 False, 0.0, cfg.get("epsilon", 1e-3))
            elif kind == "ReLU":
                v = F.relu(v) if cfg.get("max_value") is None else torch.clamp(v, 0.0, float(cfg["max_value"]))
            elif kind == "ZeroPadding2D":
                (top, bottom), (left, right) = cfg["padding"]
                v = F.pad(v, (left, right, top, bottom))
            elif kind == "Add":
                v = args[0]
                for other in args[1:]:
                    v = v + other
            values[name] = v
        return [values[name] for name in self.outputs]
