#!/usr/bin/python3
"""tools/training/tfjs_graph.py against plain NCHW torch: a small TensorFlow.js graph in the shape an
ONNX-to-TensorFlow conversion writes (explicit pads, NHWC transposes around every convolution) is built
here, run through the interpreter and compared with the same network written directly."""
import json
import os
import sys
import tempfile
import unittest

import numpy as np
import torch
import torch.nn.functional as F

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "tools", "training"))
from tfjs_graph import GraphModel, read_weights  # noqa: E402

NHWC, NCHW = [0, 2, 3, 1], [0, 3, 1, 2]


def node(name, op, inputs=(), **attr):
    return {"name": name, "op": op, "input": list(inputs), "attr": attr}


def s(text):  # a string attribute as the converter writes it (base64)
    import base64
    return {"s": base64.b64encode(text.encode()).decode()}


def ints(values):
    return {"list": {"i": [str(v) for v in values]}}


class Graph:
    """Nodes and weights of a graph model being written; save() writes model.json and one shard."""

    def __init__(self, size):
        self.nodes = [node("input_1", "Placeholder")]
        self.weights = []  # (spec, bytes)
        self.size = size

    def const(self, name, value, quantise=False):
        value = np.asarray(value)
        spec = {"name": name, "shape": list(value.shape),
                "dtype": "int32" if value.dtype.kind == "i" else "float32"}
        if quantise:
            spec["quantization"] = {"dtype": "float16", "original_dtype": "float32"}
            data = value.astype(np.float16).tobytes()
        else:
            data = value.astype(np.int32 if spec["dtype"] == "int32" else np.float32).tobytes()
        self.nodes.append(node(name, "Const", dtype={"type": "DT_INT32" if spec["dtype"] == "int32" else "DT_FLOAT"}))
        self.weights.append((spec, data))
        return name

    def op(self, name, op, inputs, **attr):
        self.nodes.append(node(name, op, inputs, **attr))
        return name

    def save(self, folder):
        model = {"format": "graph-model",
                 "signature": {"inputs": {"input_1:0": {"name": "input_1:0", "dtype": "DT_FLOAT", "tensorShape": {
                     "dim": [{"size": "1"}, {"size": "3"}, {"size": str(self.size)}, {"size": str(self.size)}]}}}},
                 "modelTopology": {"node": self.nodes},
                 "weightsManifest": [{"paths": ["weights.bin"], "weights": [w for w, _ in self.weights]}]}
        with open(os.path.join(folder, "model.json"), "w") as f:
            json.dump(model, f)
        with open(os.path.join(folder, "weights.bin"), "wb") as f:
            f.write(b"".join(d for _, d in self.weights))


def build(folder, rng, size=16):
    """conv 3x3/2 (pad 1) + bias + leaky -> max-pool 3x3/2 (pad -inf) -> depthwise 3x3 + relu6, concatenated with
    its input -> bilinear x2 -> sigmoid. Returns the weights for the reference."""
    g = Graph(size)
    w = {"w0": rng.normal(0, 0.3, (3, 3, 3, 8)), "b0": rng.normal(0, 0.1, 8), "wd": rng.normal(0, 0.3, (3, 3, 8, 1)),
         "up": np.array([size // 2, size // 2])}  # the pooled map (size / 4) doubled
    pad1 = g.const("pad1", np.array([[0, 0], [0, 0], [1, 1], [1, 1]]))
    to_nhwc, to_nchw = g.const("to_nhwc", np.array(NHWC)), g.const("to_nchw", np.array(NCHW))
    g.op("p0", "Pad", ["input_1", pad1])
    g.op("t0", "Transpose", ["p0", to_nhwc])
    g.op("conv0", "Conv2D", ["t0", g.const("w0", w["w0"], quantise=True)], strides=ints([1, 2, 2, 1]),
         padding=s("VALID"), data_format=s("NHWC"), dilations=ints([1, 1, 1, 1]))
    g.op("add0", "Add", ["conv0", g.const("b0", w["b0"])])
    g.op("t1", "Transpose", ["add0", to_nchw])
    g.op("act0", "LeakyRelu", ["t1"], alpha={"f": 0.1})
    g.op("pm", "PadV2", ["act0", pad1, g.const("ninf", np.array(-np.inf, dtype=np.float32))])
    g.op("t2", "Transpose", ["pm", to_nhwc])
    g.op("pool", "MaxPool", ["t2"], ksize=ints([1, 3, 3, 1]), strides=ints([1, 2, 2, 1]), padding=s("VALID"),
         data_format=s("NHWC"))
    g.op("t3", "Transpose", ["pool", to_nchw])
    g.op("p1", "Pad", ["t3", pad1])
    g.op("t4", "Transpose", ["p1", to_nhwc])
    g.op("dw", "DepthwiseConv2dNative", ["t4", g.const("wd", w["wd"])], strides=ints([1, 1, 1, 1]),
         padding=s("VALID"), data_format=s("NHWC"))
    g.op("t5", "Transpose", ["dw", to_nchw])
    g.op("act1", "Relu6", ["t5"])
    g.op("cat", "ConcatV2", ["t3", "act1", g.const("axis", np.array(1))])
    g.op("t6", "Transpose", ["cat", to_nhwc])
    g.op("up", "ResizeBilinear", ["t6", g.const("size", w["up"])], half_pixel_centers={"b": True},
         align_corners={"b": False})
    g.op("t7", "Transpose", ["up", to_nchw])
    g.op("out", "Sigmoid", ["t7"])
    g.op("unused", "Erf", ["out"])  # not needed for "out": never evaluated
    g.save(folder)
    return w


def reference(x, w):
    w0 = torch.tensor(w["w0"].astype(np.float16).astype(np.float32)).permute(3, 2, 0, 1)
    y = F.leaky_relu(F.conv2d(x, w0, torch.tensor(w["b0"], dtype=torch.float32), 2, 1), 0.1)
    y = F.max_pool2d(y, 3, 2, 1)
    d = F.relu6(F.conv2d(y, torch.tensor(w["wd"], dtype=torch.float32).permute(2, 3, 0, 1), None, 1, 1, 1, 8))
    y = torch.cat([y, d], 1)
    return torch.sigmoid(F.interpolate(y, scale_factor=2, mode="bilinear", align_corners=False))


class TfjsGraphTest(unittest.TestCase):
    def setUp(self):
        self.tmp = tempfile.TemporaryDirectory()
        self.w = build(self.tmp.name, np.random.default_rng(3))

    def tearDown(self):
        self.tmp.cleanup()

    def test_matches_the_network_written_directly(self):
        model = GraphModel(self.tmp.name, "model.json", ["out"])
        self.assertEqual(sum(p.numel() for p in model.parameters()), 3 * 3 * 3 * 8 + 8 + 3 * 3 * 8)
        self.assertFalse(any(p.requires_grad for p in model.parameters()))
        x = torch.randn(2, 3, 16, 16)
        with torch.no_grad():
            (ours,) = model(x)
        expected = reference(x, self.w)
        self.assertEqual(tuple(ours.shape), (2, 16, 8, 8))
        self.assertLess(float((ours - expected).abs().max()), 1e-5)
        # Another input size: the resize keeps its ratio (x2) rather than the graph's constant size.
        x = torch.randn(1, 3, 32, 32)
        with torch.no_grad():
            (ours,) = model(x)
        self.assertEqual(tuple(ours.shape), (1, 16, 16, 16))
        self.assertLess(float((ours - reference(x, self.w)).abs().max()), 1e-5)

    def test_export_holds_no_transposes_or_pads(self):
        import onnx  # python3-onnx
        model = GraphModel(self.tmp.name, "model.json", ["out"]).eval()
        path = os.path.join(self.tmp.name, "model.onnx")
        torch.onnx.export(model, torch.zeros(1, 3, 16, 16), path, opset_version=11)
        ops = [n.op_type for n in onnx.load(path).graph.node]
        self.assertEqual(ops.count("Conv"), 2)
        self.assertEqual(ops.count("MaxPool"), 1)
        self.assertNotIn("Transpose", ops)
        self.assertNotIn("Pad", ops)

    def test_bad_graphs_name_what_is_wrong(self):
        with self.assertRaisesRegex(KeyError, "no node nowhere"):
            GraphModel(self.tmp.name, "model.json", ["nowhere"])
        with self.assertRaisesRegex(NotImplementedError, "Erf.*unused"):
            GraphModel(self.tmp.name, "model.json", ["unused"])
        with open(os.path.join(self.tmp.name, "weights.bin"), "ab") as f:
            f.write(b"\0\0\0\0")
        with open(os.path.join(self.tmp.name, "model.json")) as f:
            manifest = json.load(f)["weightsManifest"]
        with self.assertRaisesRegex(ValueError, "shards hold"):
            read_weights(self.tmp.name, manifest)


if __name__ == "__main__":
    unittest.main()
