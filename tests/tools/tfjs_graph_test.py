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

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", ".."))  # the repository root: tools.training is a package
from tools.training.tfjs_graph import GraphModel, read_weights  # noqa: E402

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

    def __init__(self, height, width):
        self.nodes = [node("input_1", "Placeholder")]
        self.weights = []  # (spec, bytes)
        self.height, self.width = height, width

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
                     "dim": [{"size": "1"}, {"size": "3"}, {"size": str(self.height)}, {"size": str(self.width)}]}}}},
                 "modelTopology": {"node": self.nodes},
                 "weightsManifest": [{"paths": ["weights.bin"], "weights": [w for w, _ in self.weights]}]}
        with open(os.path.join(folder, "model.json"), "w") as f:
            json.dump(model, f)
        with open(os.path.join(folder, "weights.bin"), "wb") as f:
            f.write(b"".join(d for _, d in self.weights))


def build(folder, rng, height=16, width=24):
    """A non-square input; an asymmetric pad (kept) before two convolutions of stride (2, 1) whose NHWC outputs are
    concatenated on the channel axis (3); leaky ReLU; a -inf pad absorbed by a 3x3/2 max-pool; a zero pad before a
    2x2/1 max-pool (kept: zeros are not what a pool pads with); a depthwise 3x3 + ReLU6 concatenated with its input;
    bilinear x2; two transposes that are not inverses in a row; sigmoid. Returns the weights for the reference."""
    g = Graph(height, width)
    w = {"w0": rng.normal(0, 0.3, (3, 3, 3, 8)), "b0": rng.normal(0, 0.1, 8), "w1": rng.normal(0, 0.3, (3, 3, 3, 4)),
         "wd": rng.normal(0, 0.3, (3, 3, 12, 1))}
    pad1 = g.const("pad1", np.array([[0, 0], [0, 0], [1, 1], [1, 1]]))
    to_nhwc, to_nchw = g.const("to_nhwc", np.array(NHWC)), g.const("to_nchw", np.array(NCHW))
    conv = dict(padding=s("VALID"), data_format=s("NHWC"), dilations=ints([1, 1, 1, 1]))
    g.op("pa", "Pad", ["input_1", g.const("pad_asym", np.array([[0, 0], [0, 0], [0, 1], [1, 2]]))])
    g.op("t0", "Transpose", ["pa", to_nhwc])
    g.op("conv0", "Conv2D", ["t0", g.const("w0", w["w0"], quantise=True)], strides=ints([1, 2, 1, 1]), **conv)
    g.op("add0", "Add", ["conv0", g.const("b0", w["b0"])])
    g.op("conv1", "Conv2D", ["t0", g.const("w1", w["w1"])], strides=ints([1, 2, 1, 1]), **conv)
    g.op("cat0", "ConcatV2", ["add0", "conv1", g.const("axis3", np.array(3))])
    g.op("t1", "Transpose", ["cat0", to_nchw])
    g.op("act0", "LeakyRelu", ["t1"], alpha={"f": 0.1})
    g.op("pm", "PadV2", ["act0", pad1, g.const("ninf", np.array(-np.inf, dtype=np.float32))])
    g.op("t2", "Transpose", ["pm", to_nhwc])
    g.op("pool", "MaxPool", ["t2"], ksize=ints([1, 3, 3, 1]), strides=ints([1, 2, 2, 1]), padding=s("VALID"),
         data_format=s("NHWC"))
    g.op("t3", "Transpose", ["pool", to_nchw])
    g.op("pz", "Pad", ["t3", pad1])
    g.op("t4", "Transpose", ["pz", to_nhwc])
    g.op("pool2", "MaxPool", ["t4"], ksize=ints([1, 2, 2, 1]), strides=ints([1, 1, 1, 1]), padding=s("VALID"),
         data_format=s("NHWC"))
    g.op("t5", "Transpose", ["pool2", to_nchw])
    g.op("p1", "Pad", ["t5", pad1])
    g.op("t6", "Transpose", ["p1", to_nhwc])
    g.op("dw", "DepthwiseConv2dNative", ["t6", g.const("wd", w["wd"])], strides=ints([1, 1, 1, 1]),
         padding=s("VALID"), data_format=s("NHWC"))
    g.op("t7", "Transpose", ["dw", to_nchw])
    g.op("act1", "Relu6", ["t7"])
    g.op("cat", "ConcatV2", ["t5", "act1", g.const("axis1", np.array(1))])
    g.op("t8", "Transpose", ["cat", to_nhwc])
    pooled = (((height + 1 - 3) // 2 + 1 + 2 - 3) // 2 + 1 + 1, ((width + 3 - 3) + 1 + 2 - 3) // 2 + 1 + 1)
    g.op("up", "ResizeBilinear", ["t8", g.const("size", np.array([2 * pooled[0], 2 * pooled[1]]))],
         half_pixel_centers={"b": True}, align_corners={"b": False})
    g.op("t9", "Transpose", ["up", g.const("swap_hw", np.array([0, 2, 1, 3]))])  # NHWC -> NWHC
    g.op("t10", "Transpose", ["t9", to_nchw])  # -> N, C, W, H
    g.op("out", "Sigmoid", ["t10"])
    g.op("unused", "Erf", ["out"])  # not needed for "out": never evaluated
    g.save(folder)
    return w


def reference(x, w):
    """The same network written in NCHW torch."""
    t = lambda a: torch.tensor(a, dtype=torch.float32)
    x = F.pad(x, (1, 2, 0, 1))
    w0 = t(w["w0"].astype(np.float16).astype(np.float32)).permute(3, 2, 0, 1)
    y = torch.cat([F.conv2d(x, w0, t(w["b0"]), (2, 1)), F.conv2d(x, t(w["w1"]).permute(3, 2, 0, 1), None, (2, 1))], 1)
    y = F.max_pool2d(F.leaky_relu(y, 0.1), 3, 2, 1)
    y = F.max_pool2d(F.pad(y, (1, 1, 1, 1)), 2, 1)
    d = F.relu6(F.conv2d(y, t(w["wd"]).permute(2, 3, 0, 1), None, 1, 1, 1, 12))
    y = F.interpolate(torch.cat([y, d], 1), scale_factor=2, mode="bilinear", align_corners=False)
    return torch.sigmoid(y).transpose(2, 3)


class TfjsGraphTest(unittest.TestCase):
    def setUp(self):
        self.tmp = tempfile.TemporaryDirectory()
        self.w = build(self.tmp.name, np.random.default_rng(3))

    def tearDown(self):
        self.tmp.cleanup()

    def test_matches_the_network_written_directly(self):
        model = GraphModel(self.tmp.name, "model.json", ["out"])
        self.assertEqual(sum(p.numel() for p in model.parameters()), 216 + 8 + 108 + 108)
        self.assertFalse(any(p.requires_grad for p in model.parameters()))
        x = torch.randn(2, 3, 16, 24)
        with torch.no_grad():
            (ours,) = model(x)
        self.assertEqual(tuple(ours.shape), (2, 24, 28, 10))  # N, C, then W and H swapped by the last transpose
        self.assertLess(float((ours - reference(x, self.w)).abs().max()), 1e-5)
        # Another input size: the resize keeps its ratio (x2) rather than the graph's constant size.
        x = torch.randn(1, 3, 32, 48)
        with torch.no_grad():
            (ours,) = model(x)
        self.assertEqual(tuple(ours.shape), (1, 24, 52, 18))
        self.assertLess(float((ours - reference(x, self.w)).abs().max()), 1e-5)

    def test_export_folds_the_layout_transposes_and_the_pads_it_can(self):
        import onnx  # python3-onnx
        model = GraphModel(self.tmp.name, "model.json", ["out"]).eval()
        path = os.path.join(self.tmp.name, "model.onnx")
        torch.onnx.export(model, torch.zeros(1, 3, 16, 24), path, opset_version=11)
        nodes = onnx.load(path).graph.node
        ops = [n.op_type for n in nodes]
        # (torch writes a Pad's amounts through a small 2-D transpose of its own; only 4-D ones move images)
        image_transposes = [n for n in nodes if n.op_type == "Transpose" and len(n.attribute[0].ints) == 4]
        self.assertEqual(ops.count("Conv"), 3)
        self.assertEqual(ops.count("MaxPool"), 2)
        # Left: the last transpose (a real one: it swaps H and W), the asymmetric pad (once, though two
        # convolutions read it) and the zero pad before the 2x2 pool. Ten layout transposes and the
        # symmetric pads are gone.
        self.assertEqual(len(image_transposes), 1)
        self.assertEqual(ops.count("Pad"), 2)

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
