#!/usr/bin/python3
"""tools/training/quantize.py: convolution weights become int8 per output channel within half a step of the
float ones, each quantised convolution is rewritten as Conv(x, Cast(Q)) * S + B, small or shared weights stay in
float, dequantisation gives back the float model's nodes with the rounded weights, and a file that is not an ONNX
model gets a clear error."""
import os
import subprocess
import sys
import tempfile
import unittest

import numpy as np
import torch
import torch.nn as nn

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", ".."))  # the repository root: tools.training is a package
from tools.training import quantize  # noqa: E402

QUANTIZE = os.path.join(HERE, "..", "..", "tools", "training", "quantize.py")


class Net(nn.Module):
    def __init__(self):
        super().__init__()
        torch.manual_seed(1)
        self.a = nn.Conv2d(3, 16, 3, padding=1)              # 432 weights: stays in float
        self.b = nn.Conv2d(16, 32, 3, padding=1)             # 4,608 weights, bias
        self.c = nn.Conv2d(32, 8, 3, padding=1, bias=False)  # 2,304 weights, no bias
        with torch.no_grad():
            self.b.weight[5].zero_()  # a channel of zeros must not divide by zero
            self.b.weight[7] *= 100   # channels of very different ranges get their own scales

    def forward(self, x):
        return self.c(torch.relu(self.b(torch.relu(self.a(x)))))


def export(folder):
    path = os.path.join(folder, "net.onnx")
    torch.onnx.export(Net().eval(), torch.zeros(1, 3, 8, 8), path, input_names=["x"], output_names=["y"],
                      opset_version=11)
    return path


class QuantizeTest(unittest.TestCase):
    def test_weights_round_per_channel_and_convolutions_are_rewritten(self):
        import onnx
        from onnx import numpy_helper
        with tempfile.TemporaryDirectory() as tmp:
            model = onnx.load(export(tmp))
        original = {t.name: numpy_helper.to_array(t) for t in model.graph.initializer}
        count, before, after = quantize.quantize_conv_weights(model)
        onnx.checker.check_model(model)
        self.assertEqual(count, 2)
        self.assertEqual(before, (4608 + 2304) * 4)
        self.assertEqual(after, 4608 + 2304 + (32 + 8) * 4)
        constants = {t.name: numpy_helper.to_array(t) for t in model.graph.initializer}
        self.assertEqual(constants["a.weight"].dtype, np.float32)  # below MIN_WEIGHTS
        for name, channels in (("b.weight", 32), ("c.weight", 8)):
            q, s = constants[name + "_int8"], constants[name + "_scale"]
            self.assertEqual((q.dtype, s.shape), (np.int8, (1, channels, 1, 1)))
            self.assertLessEqual(int(np.abs(q).max()), 127)
            w = original[name]
            error = np.abs(q * s.reshape(-1, 1, 1, 1) - w).reshape(channels, -1).max(1)
            self.assertTrue((error <= s.ravel() / 2 + 1e-7).all())
        self.assertEqual(constants["b.weight_scale"].ravel()[5], 1.0)  # the zero channel
        self.assertGreater(constants["b.weight_scale"].ravel()[7], 50 * np.median(constants["b.weight_scale"]))
        np.testing.assert_array_equal(constants["b.weight_bias"].ravel(), original["b.bias"])
        self.assertNotIn("b.bias", constants)  # replaced by its [1, C, 1, 1] form
        self.assertNotIn("c.weight_bias", constants)
        ops = [n.op_type for n in model.graph.node]
        self.assertEqual(ops, ["Conv", "Relu", "Cast", "Conv", "Mul", "Add", "Relu", "Cast", "Conv", "Mul"])
        self.assertEqual(model.graph.node[-1].output[0], "y")  # the graph's output keeps its name

    def test_dequantisation_restores_the_float_models_nodes_with_the_rounded_weights(self):
        import onnx
        from onnx import numpy_helper
        with tempfile.TemporaryDirectory() as tmp:
            model = onnx.load(export(tmp))
        original = onnx.ModelProto()
        original.CopyFrom(model)
        quantize.quantize_conv_weights(model)
        constants = {t.name: numpy_helper.to_array(t) for t in model.graph.initializer}
        self.assertEqual(quantize.dequantize_conv_weights(model), 2)
        onnx.checker.check_model(model)
        self.assertEqual([n.op_type for n in model.graph.node], [n.op_type for n in original.graph.node])
        self.assertEqual([n.output[0] for n in model.graph.node], [n.output[0] for n in original.graph.node])
        values = {t.name: numpy_helper.to_array(t) for t in model.graph.initializer}
        before = {t.name: numpy_helper.to_array(t) for t in original.graph.initializer}
        for node, float_node in zip(model.graph.node, original.graph.node):
            self.assertEqual(len(node.input), len(float_node.input), node.name)
            for name, float_name in zip(node.input[1:], float_node.input[1:]):
                self.assertEqual(values[name].shape, before[float_name].shape, name)
        np.testing.assert_array_equal(values["a.weight"], before["a.weight"])  # never quantised
        for name, channels in (("b.weight", 32), ("c.weight", 8)):  # exactly Q x S, within half a step of w
            q, s = constants[name + "_int8"], constants[name + "_scale"].reshape(-1, 1, 1, 1)
            np.testing.assert_array_equal(values[name], q.astype(np.float32) * s)
            self.assertGreater(np.abs(values[name] - before[name]).max(), 0)
        np.testing.assert_array_equal(values["b.weight_bias_flat"], before["b.bias"])
        self.assertFalse([t.name for t in model.graph.initializer if t.data_type == onnx.TensorProto.INT8])
        self.assertEqual(quantize.dequantize_conv_weights(model), 0)  # a float model is left as it is

    def test_the_tool_refuses_what_is_not_a_model(self):
        with tempfile.TemporaryDirectory() as tmp:
            bad = os.path.join(tmp, "bad.onnx")
            with open(bad, "w") as f:
                f.write("not a model")
            done = subprocess.run([sys.executable, QUANTIZE, bad, os.path.join(tmp, "out.onnx")],
                                  capture_output=True, text=True)
            self.assertEqual(done.returncode, 2)
            self.assertRegex(done.stderr, "bad.onnx: not an ONNX model")
            self.assertFalse(os.path.exists(os.path.join(tmp, "out.onnx")))
            done = subprocess.run([sys.executable, QUANTIZE, export(tmp), os.path.join(tmp, "out.onnx")],
                                  capture_output=True, text=True)
            self.assertEqual(done.returncode, 0, done.stderr)
            self.assertRegex(done.stdout, "2 convolutions quantised")


if __name__ == "__main__":
    unittest.main()
