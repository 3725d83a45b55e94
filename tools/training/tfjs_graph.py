"""Runs a TensorFlow.js graph model (model.json and its weight shards) as a torch module.

train.py uses it to borrow a pretrained image encoder from a package on the npm registry (the only model
source these machines reach): NanoDet-g, a COCO object detector (docs/training.md, "Pretrained encoders").
The interpreter covers the operations such converted graphs use: Conv2D, DepthwiseConv2dNative, MaxPool,
Pad/PadV2, Transpose, Add/AddV2/Sub/Mul, ConcatV2, ResizeBilinear, LeakyRelu/Relu/Relu6/Sigmoid, Identity.

Layouts are tracked rather than applied: a value carries the map from its logical axes (what the graph
means) to the axes of the stored tensor, so the NHWC transposes an ONNX-to-TensorFlow conversion puts
around every convolution move no data, and a torch.onnx export of the module holds plain NCHW
convolutions. Explicit Pad operations before a convolution (zeros) or a max-pool (-inf) become that
operation's padding. check_tfjs_graph.js runs the same graph in TensorFlow.js to check the interpreter.
"""
import json
import math
import os

import numpy as np
import torch
import torch.nn as nn
import torch.nn.functional as F

_DTYPES = {"float32": np.float32, "int32": np.int32}
_QUANTISED = {"float16": np.float16, "uint8": np.uint8, "uint16": np.uint16}
_NHWC_IN_NCHW = (0, 2, 3, 1)  # logical NHWC axes stored as an NCHW tensor


def read_weights(folder, manifest, names=None):
    """{name: numpy array} from a weights manifest (only `names`, if given); float16 and affine-quantised
    entries are widened."""
    out = {}
    for group in manifest:
        blob = b""
        for p in group["paths"]:
            with open(os.path.join(folder, p), "rb") as f:
                blob += f.read()
        at = 0
        for w in group["weights"]:
            n = int(np.prod(w["shape"])) if w["shape"] else 1
            q = w.get("quantization")
            stored = _QUANTISED[q["dtype"]] if q else _DTYPES.get(w["dtype"])
            if stored is None:
                if names is not None and w["name"] not in names:
                    raise ValueError(f"weight {w['name']}: dtype {w['dtype']} is not supported (and its size is "
                                     "unknown, so the weights after it cannot be read)")
                raise ValueError(f"weight {w['name']}: dtype {w['dtype']} is not supported")
            raw = np.frombuffer(blob, stored, n, at)
            at += n * np.dtype(stored).itemsize
            if names is not None and w["name"] not in names:
                continue
            if q and q["dtype"] != "float16":
                raw = raw.astype(np.float32) * q["scale"] + q["min"]
            out[w["name"]] = raw.astype(_DTYPES[w["dtype"]]).reshape(w["shape"])
        if at != len(blob):
            raise ValueError(f"{group['paths']}: the manifest describes {at} bytes, the shards hold {len(blob)}")
    return out


class _Value:
    """A tensor `t`; `axes[i]` is the stored axis of logical axis i (4-D values; None otherwise); `pad` a
    pending constant padding (logical [rank][2]) of value `fill` a convolution or pool may absorb."""

    def __init__(self, t, axes=None, pad=None, fill=0.0):
        self.t, self.axes, self.pad, self.fill = t, axes, pad, fill

    def settled(self):
        """The same value with any pending padding applied (once, however many operations read it)."""
        if self.pad is None:
            return self
        if getattr(self, "_settled", None) is None:
            stored = [[0, 0] for _ in range(self.t.dim())]
            for i, p in enumerate(self.pad):
                stored[self.axes[i] if self.axes else i] = list(p)
            flat = [v for a in reversed(range(self.t.dim())) for v in stored[a]]
            self._settled = _Value(F.pad(self.t, flat, value=self.fill), self.axes)
        return self._settled

    def logical(self):
        v = self.settled()
        if v.axes is not None and list(v.axes) != list(range(len(v.axes))):
            return v.t.permute(*v.axes)
        return v.t

    def nchw(self):
        """The tensor as NCHW for a value whose logical layout is NHWC."""
        v = self.settled()
        return v.t if v.axes == _NHWC_IN_NCHW else v.logical().permute(0, 3, 1, 2)


def _identity(rank):
    return tuple(range(rank))


def _ints(attr, key):
    return [int(v) for v in attr[key]["list"]["i"]]


class GraphModel(nn.Module):
    """The part of a TF.js graph model that `outputs` (node names) need, as a torch module. Float weights
    become parameters (frozen unless `trainable`); forward(x) takes the graph's single input and returns the
    outputs in their logical layout. Resize operations keep the ratio of their output to their input size in
    the graph as converted (its input size is fixed; see calibrate()), so other input sizes work."""

    def __init__(self, folder, graph_json, outputs, trainable=False):
        super().__init__()
        with open(os.path.join(folder, graph_json)) as f:
            model = json.load(f)
        self.nodes = {n["name"]: n for n in model["modelTopology"]["node"]}
        self.outputs = list(outputs)
        for o in self.outputs:
            if o.partition(":")[0] not in self.nodes:
                raise KeyError(f"{graph_json}: no node {o}")
        needed = self._needed()
        weights = read_weights(folder, model["weightsManifest"], needed)
        self.weights = nn.ParameterDict()
        self.constants = {}
        self.keys = {}
        for name, value in weights.items():
            if name not in needed:
                continue
            t = torch.from_numpy(np.ascontiguousarray(value))
            if value.dtype == np.float32 and value.ndim >= 1:
                key = name.replace("/", "__").replace(".", "_")
                self.weights[key] = nn.Parameter(t, requires_grad=trainable)
                self.keys[name] = key
            else:
                self.constants[name] = t
        self.input_name = next(n for n, v in self.nodes.items() if v["op"] == "Placeholder")
        self.ratios = {}
        self._calibrating = False
        signature = model.get("signature", {}).get("inputs", {})
        shape = [int(d["size"]) for d in next(iter(signature.values()))["tensorShape"]["dim"]] if signature else None
        if shape and all(d > 0 for d in shape):
            self.calibrate(shape)

    def _needed(self):
        seen, stack = set(), [o.partition(":")[0] for o in self.outputs]
        while stack:
            n = stack.pop()
            if n in seen:
                continue
            seen.add(n)
            stack += [i.lstrip("^").partition(":")[0] for i in self.nodes[n].get("input", [])]
        return seen

    def forward(self, x):
        values = {self.input_name: _Value(x, _identity(x.dim()) if x.dim() == 4 else None)}
        return [self._eval(o, values).logical() for o in self.outputs]

    def _const(self, name):
        return self.weights[self.keys[name]] if name in self.keys else self.constants[name]

    def _eval(self, ref, values):
        if ref in values:
            return values[ref]
        name = ref.partition(":")[0]
        if name in self.keys or name in self.constants:
            values[ref] = _Value(self._const(name))
            return values[ref]
        node = self.nodes[name]
        op, attr = node["op"], node.get("attr", {})
        inputs = [i for i in node.get("input", []) if not i.startswith("^")]

        def arg(i):
            return self._eval(inputs[i], values)

        if op == "Identity":
            out = arg(0)
        elif op == "Transpose":
            x = arg(0)
            perm = [int(v) for v in arg(1).t.tolist()]
            if x.axes:  # a pending padding moves with its axes
                pad = [x.pad[q] for q in perm] if x.pad is not None else None
                out = _Value(x.t, tuple(x.axes[q] for q in perm), pad, x.fill)
            else:
                out = _Value(x.settled().t.permute(*perm))
        elif op in ("Pad", "PadV2"):
            x = arg(0).settled()
            fill = float(arg(2).t) if op == "PadV2" else 0.0
            out = _Value(x.t, x.axes, arg(1).t.tolist(), fill)
        elif op in ("Conv2D", "DepthwiseConv2dNative", "MaxPool"):
            out = self._window(op, attr, arg, name)
        elif op in ("Add", "AddV2", "Sub", "Mul"):
            fn = {"Add": torch.add, "AddV2": torch.add, "Sub": torch.sub, "Mul": torch.mul}[op]
            x, y = arg(0).settled(), arg(1).settled()
            if x.axes and y.axes and x.axes == y.axes:
                out = _Value(fn(x.t, y.t), x.axes)
            elif x.axes and not y.axes:
                out = _Value(fn(x.t, self._stored(y.t, x.axes)), x.axes)
            elif y.axes and not x.axes:
                out = _Value(fn(self._stored(x.t, y.axes), y.t), y.axes)
            else:
                t = fn(x.logical(), y.logical())
                out = _Value(t, _identity(4) if t.dim() == 4 else None)
        elif op in ("LeakyRelu", "Relu", "Relu6", "Sigmoid"):
            x = arg(0).settled()
            if op == "LeakyRelu":
                t = F.leaky_relu(x.t, attr["alpha"]["f"])
            else:
                t = {"Relu": F.relu, "Relu6": F.relu6, "Sigmoid": torch.sigmoid}[op](x.t)
            out = _Value(t, x.axes)
        elif op == "ConcatV2":
            parts = [arg(i).settled() for i in range(len(inputs) - 1)]
            axis = int(arg(len(inputs) - 1).t)
            if all(p.axes and p.axes == parts[0].axes for p in parts):
                out = _Value(torch.cat([p.t for p in parts], parts[0].axes[axis]), parts[0].axes)
            else:
                ts = [p.logical() for p in parts]
                out = _Value(torch.cat(ts, axis), _identity(4) if ts[0].dim() == 4 else None)
        elif op == "ResizeBilinear":
            if attr.get("align_corners", {}).get("b") or not attr.get("half_pixel_centers", {}).get("b"):
                raise NotImplementedError(f"{name}: ResizeBilinear without half-pixel centres")
            t = arg(0).nchw()
            h, w = [int(v) for v in arg(1).t.tolist()]
            size = self._resized(name, t.shape[-2:], (h, w))
            out = _Value(F.interpolate(t, size=size, mode="bilinear", align_corners=False), _NHWC_IN_NCHW)
        else:
            raise NotImplementedError(f"operation {op} (node {name}) is not supported")
        values[ref] = out
        return out

    def _window(self, op, attr, arg, name):
        if attr.get("data_format", {}).get("s", "TkhXQw==") != "TkhXQw==":  # base64 of "NHWC"
            raise NotImplementedError(f"{name}: only NHWC {op} is supported")
        if attr["padding"]["s"] != "VkFMSUQ=":  # "VALID": the converted graphs pad with explicit Pad nodes
            raise NotImplementedError(f"{name}: only VALID padding is supported")
        x = arg(0)
        stride = _ints(attr, "strides")[1:3]
        padding = (0, 0)
        absorbable = -math.inf if op == "MaxPool" else 0.0
        if x.pad is not None and x.fill == absorbable:
            (n0, n1), (h0, h1), (w0, w1), (c0, c1) = x.pad
            if h0 == h1 and w0 == w1 and not (n0 or n1 or c0 or c1):
                padding, x = (h0, w0), _Value(x.t, x.axes)
        t = x.nchw()
        if op == "MaxPool":
            y = F.max_pool2d(t, _ints(attr, "ksize")[1:3], stride, padding)
        else:
            w = arg(1).t  # HWIO; depthwise: H, W, in, multiplier
            dilation = _ints(attr, "dilations")[1:3] if "dilations" in attr else [1, 1]
            if op == "DepthwiseConv2dNative":
                w = w.permute(2, 3, 0, 1).reshape(-1, 1, w.shape[0], w.shape[1])
                groups = t.shape[1]
            else:
                groups = t.shape[1] // w.shape[2]
                w = w.permute(3, 2, 0, 1)
            y = F.conv2d(t, w, None, stride, padding, dilation, groups)
        return _Value(y, _NHWC_IN_NCHW)

    def _resized(self, name, hw, size):
        # The converted graph's sizes assume its own input size; calibrate() runs it at that size (the
        # constructor does when the graph's signature gives the input shape) and records the ratios.
        if self._calibrating:
            self.ratios[name] = (size[0] / int(hw[0]), size[1] / int(hw[1]))
        if name not in self.ratios:
            raise ValueError(f"{name}: resize ratio unknown; the graph has no fixed input shape, call calibrate()")
        ratio = self.ratios[name]
        # floor, as TensorFlow and torch size a downsampled odd map
        return (int(math.floor(int(hw[0]) * ratio[0])), int(math.floor(int(hw[1]) * ratio[1])))

    def calibrate(self, input_shape):
        """Runs the graph once at its converted input size so that resize ratios are known."""
        self._calibrating = True
        try:
            with torch.no_grad():
                self.forward(torch.zeros(input_shape))
        finally:
            self._calibrating = False

    @staticmethod
    def _stored(c, axes):
        # A constant broadcast against a 4-D value: from logical to stored axis order.
        while c.dim() < 4:
            c = c[None]
        inverse = [0] * 4
        for i, a in enumerate(axes):
            inverse[a] = i
        return c.permute(*inverse)
