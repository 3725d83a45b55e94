#!/usr/bin/python3
"""tools/training/keras_layers.py against plain NCHW torch: a small Keras topology built from the layers of
MobileNetV2 (asymmetric zero padding before a strided convolution, 'same' padding of odd totals, a depthwise
convolution with a multiplier, batch normalisation, ReLU6, a residual Add, and a Dense head nobody asks for) is
written here with 8-bit quantised weights, run through the interpreter and compared with the same network
written directly."""
import json
import os
import sys
import tempfile
import unittest

import numpy as np
import torch
import torch.nn.functional as F

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", ".."))  # the repository root: tools.training is a package
from tools.training.keras_layers import LayersModel  # noqa: E402


def layer(name, kind, inputs, **config):
    return {"name": name, "class_name": kind, "config": dict(config, name=name),
            "inbound_nodes": [[[i, 0, 0, {}] for i in inputs]] if inputs else []}


class Topology:
    """Layers and weights of a layers model being written; save() writes MODEL.json and one shard."""

    def __init__(self):
        self.layers = [layer("input_1", "InputLayer", [], batch_input_shape=[None, 32, 32, 3])]
        self.weights = []  # (spec, bytes)
        self.rng = np.random.default_rng(7)

    def add(self, name, kind, inputs, weights=(), **config):
        self.layers.append(layer(name, kind, inputs, **config))
        values = {}
        for part, shape, low, high in weights:
            v = self.rng.uniform(low, high, shape).astype(np.float32)
            # 8-bit affine quantisation, as nsfwjs stores its weights: keep what the interpreter will read.
            lo, scale = float(v.min()), float(v.max() - v.min()) / 255 or 1.0
            q = np.round((v - lo) / scale).astype(np.uint8)
            self.weights.append(({"name": f"{name}/{part}", "shape": list(shape), "dtype": "float32",
                                  "quantization": {"min": lo, "scale": scale, "dtype": "uint8"}}, q.tobytes()))
            values[part] = torch.from_numpy(q.astype(np.float32) * scale + lo)
        return values

    def save(self, folder, name="model.json"):
        topology = {"keras_version": "2.2.4", "backend": "tensorflow",
                    "model_config": {"class_name": "Model", "config": {"name": "m", "layers": self.layers}}}
        manifest = [{"paths": ["shard.bin"], "weights": [spec for spec, _ in self.weights]}]
        with open(os.path.join(folder, "shard.bin"), "wb") as f:
            for _, data in self.weights:
                f.write(data)
        with open(os.path.join(folder, name), "w") as f:
            json.dump({"format": "layers-model", "modelTopology": topology, "weightsManifest": manifest}, f)


def build(folder):
    """Writes the test model to `folder`; returns its weights and a direct torch implementation."""
    t = Topology()
    t.add("pad", "ZeroPadding2D", ["input_1"], padding=[[0, 1], [0, 1]])
    conv = t.add("conv", "Conv2D", ["pad"], [("kernel", (3, 3, 3, 8), -0.5, 0.5)], filters=8, kernel_size=[3, 3],
                 strides=[2, 2], padding="valid", use_bias=False, activation="linear")
    bn = t.add("bn", "BatchNormalization", ["conv"],
               [("gamma", (8,), 0.5, 1.5), ("beta", (8,), -0.2, 0.2), ("moving_mean", (8,), -0.1, 0.1),
                ("moving_variance", (8,), 0.5, 2.0)], axis=-1, epsilon=1e-3)
    t.add("relu", "ReLU", ["bn"], max_value=6, negative_slope=0, threshold=0)
    dw = t.add("dw", "DepthwiseConv2D", ["relu"], [("depthwise_kernel", (3, 3, 8, 2), -0.5, 0.5), ("bias", (16,), -1, 1)],
               kernel_size=[3, 3], strides=[2, 2], padding="same", depth_multiplier=2, use_bias=True,
               activation="relu")
    pw = t.add("pw", "Conv2D", ["dw"], [("kernel", (1, 1, 16, 16), -0.3, 0.3), ("bias", (16,), -0.1, 0.1)],
               filters=16, kernel_size=[1, 1], strides=[1, 1], padding="same", use_bias=True, activation="linear")
    t.add("add", "Add", ["dw", "pw"])
    t.add("pool", "GlobalAveragePooling2D", ["add"])  # a head the outputs do not need
    t.add("dense", "Dense", ["pool"], [("kernel", (16, 2), -1, 1)], units=2)
    t.save(folder)

    def direct(x):  # NCHW
        v = F.pad(x, (0, 1, 0, 1))
        v = F.conv2d(v, conv["kernel"].permute(3, 2, 0, 1), stride=2)
        v = (v - bn["moving_mean"][:, None, None]) / torch.sqrt(bn["moving_variance"][:, None, None] + 1e-3)
        v = torch.clamp(v * bn["gamma"][:, None, None] + bn["beta"][:, None, None], 0, 6)
        relu = v
        # TensorFlow's 'same' for a 3x3 kernel at stride 2: total padding max(k - s, 0) on an even side, k - 1 -
        # (n - 1) % s in general; the odd pixel goes after.
        h = relu.shape[2]
        total = max((-(-h // 2) - 1) * 2 + 3 - h, 0)
        v = F.pad(relu, (total // 2, total - total // 2, total // 2, total - total // 2))
        k = dw["depthwise_kernel"]  # kh, kw, in, mult -> out channel i * mult + m
        v = F.relu(F.conv2d(v, k.permute(2, 3, 0, 1).reshape(16, 1, 3, 3), dw["bias"], stride=2, groups=8))
        p = F.conv2d(v, pw["kernel"].permute(3, 2, 0, 1), pw["bias"])
        return relu, v + p

    return direct


class LayersModelTest(unittest.TestCase):
    def test_matches_the_network_written_directly(self):
        with tempfile.TemporaryDirectory() as tmp:
            direct = build(tmp)
            model = LayersModel(tmp, "model.json", ["relu", "add"])
            for side in (32, 33, 45):  # even and odd sides: padding splits differ
                x = torch.rand(2, 3, side, side) * 2 - 1
                with torch.no_grad():
                    ours, expected = model(x), direct(x)
                for name, a, b in zip(("relu", "add"), ours, expected):
                    self.assertEqual(a.shape, b.shape, f"{name} at side {side}")
                    self.assertLess(float((a - b).abs().max()), 1e-4, f"{name} at side {side}")

    def test_builds_only_what_the_outputs_need_and_freezes_it(self):
        with tempfile.TemporaryDirectory() as tmp:
            build(tmp)
            model = LayersModel(tmp, "model.json", ["bn"])
            self.assertEqual(model.order, ["input_1", "pad", "conv", "bn"])
            self.assertTrue(all(not p.requires_grad for p in model.parameters()))
            trainable = LayersModel(tmp, "model.json", ["add"], trainable=True)
            trainable(torch.rand(1, 3, 32, 32))[0].sum().backward()
            self.assertGreater(float(trainable.params["conv__kernel"].grad.abs().sum()), 0)

    def test_refusals_name_the_layer(self):
        with tempfile.TemporaryDirectory() as tmp:
            build(tmp)
            with self.assertRaisesRegex(KeyError, "no layer nope"):
                LayersModel(tmp, "model.json", ["nope"])
            with self.assertRaisesRegex(ValueError, "layer pool is a GlobalAveragePooling2D"):
                LayersModel(tmp, "model.json", ["dense"])


if __name__ == "__main__":
    unittest.main()
