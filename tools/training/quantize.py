#!/usr/bin/python3
"""Stores an ONNX model's convolution weights as 8-bit integers, a quarter of their float size, in a form OpenCV
4.6's dnn module loads.

    python3 tools/training/quantize.py IN.onnx OUT.onnx

Weight-only quantisation, symmetric and per output channel (Krishnamoorthi 2018, "Quantizing deep convolutional
networks for efficient inference: a whitepaper", section 2): channel c's weights become round(w / s_c) in
-127..127 with s_c = max|w_c| / 127. Arithmetic stays in float: OpenCV 4.6 reads neither float16 tensors nor a
DequantizeLinear of a constant, and cannot multiply two constants of different shapes, but it folds a Cast of a
constant into a constant. So each quantised convolution

    Conv(x, W, b)   becomes   Add(Mul(Conv(x, Cast(Q)), S), B)

with Q the int8 weights, S the scales and B the bias as [1, C, 1, 1] tensors: the same result up to the rounding of
the weights. Convolutions with fewer than MIN_WEIGHTS weights are kept in float. dequantize_conv_weights() undoes
the rewriting (the weights staying rounded), so that onnx_weights.py can recover the networks of an int8 file.
"""
import argparse
import sys

import numpy as np

MIN_WEIGHTS = 1024


def quantize_conv_weights(model):
    """Rewrites `model` (an onnx.ModelProto) in place as the module docstring says; returns (convolutions
    quantised, bytes of weights before, after)."""
    from onnx import TensorProto, helper, numpy_helper
    graph = model.graph
    constants = {t.name: t for t in graph.initializer}
    users = {}
    for node in graph.node:
        for name in node.input:
            users[name] = users.get(name, 0) + 1
    nodes, count, before, after = [], 0, 0, 0
    for node in graph.node:
        weight = constants.get(node.input[1]) if node.op_type == "Conv" and len(node.input) > 1 else None
        if (weight is None or weight.data_type != TensorProto.FLOAT or users[weight.name] != 1
                or int(np.prod(weight.dims)) < MIN_WEIGHTS):
            nodes.append(node)
            continue
        w = numpy_helper.to_array(weight).astype(np.float32)
        scale = np.abs(w).reshape(w.shape[0], -1).max(1) / 127.0
        scale[scale == 0] = 1.0
        q = np.clip(np.round(w / scale[:, None, None, None]), -127, 127).astype(np.int8)
        bias = None
        if len(node.input) > 2 and node.input[2]:
            bias = numpy_helper.to_array(constants[node.input[2]]).astype(np.float32)
        name = weight.name
        graph.initializer.remove(weight)
        graph.initializer.append(numpy_helper.from_array(q, name + "_int8"))
        graph.initializer.append(numpy_helper.from_array(scale.astype(np.float32).reshape(1, -1, 1, 1),
                                                         name + "_scale"))
        before += w.nbytes
        after += q.nbytes + scale.size * 4
        out = node.output[0]
        nodes.append(helper.make_node("Cast", [name + "_int8"], [name + "_float"], to=TensorProto.FLOAT))
        conv = helper.make_node("Conv", [node.input[0], name + "_float"], [out + "_unscaled"])
        conv.attribute.extend(node.attribute)
        nodes.append(conv)
        scaled = out + "_scaled" if bias is not None else out
        nodes.append(helper.make_node("Mul", [out + "_unscaled", name + "_scale"], [scaled]))
        if bias is not None:
            graph.initializer.append(numpy_helper.from_array(bias.reshape(1, -1, 1, 1), name + "_bias"))
            nodes.append(helper.make_node("Add", [scaled, name + "_bias"], [out]))
        count += 1
    del graph.node[:]
    graph.node.extend(nodes)
    used = {name for node in graph.node for name in node.input}
    for t in [t for t in graph.initializer if t.name not in used]:  # biases now held as [1, C, 1, 1]
        graph.initializer.remove(t)
    return count, before, after


def dequantize_conv_weights(model):
    """Undoes quantize_conv_weights on `model` (an onnx.ModelProto) in place: each Cast(Q) -> Conv -> Mul(S) [-> Add(B)]
    it wrote becomes one float Conv(x, Q x S, B) again, at the same place among the nodes, so the graph has the nodes of
    the float model it came from (the weights as rounded). Returns the number of convolutions restored."""
    from onnx import TensorProto, helper, numpy_helper
    graph = model.graph
    constants = {t.name: t for t in graph.initializer}
    nodes, count, i = list(graph.node), 0, 0
    restored = []
    while i < len(nodes):
        cast = nodes[i]
        q = constants.get(cast.input[0]) if cast.op_type == "Cast" and cast.input else None
        conv = nodes[i + 1] if i + 1 < len(nodes) else None
        mul = nodes[i + 2] if i + 2 < len(nodes) else None
        if (q is None or q.data_type != TensorProto.INT8 or not cast.input[0].endswith("_int8") or conv is None
                or conv.op_type != "Conv" or list(conv.input[1:]) != [cast.output[0]] or mul is None
                or mul.op_type != "Mul" or list(mul.input) != [conv.output[0], cast.input[0][:-5] + "_scale"]):
            restored.append(cast)
            i += 1
            continue
        name = cast.input[0][:-5]
        scale = numpy_helper.to_array(constants[name + "_scale"]).astype(np.float32).ravel()
        weight = numpy_helper.to_array(q).astype(np.float32) * scale[:, None, None, None]
        add = nodes[i + 3] if i + 3 < len(nodes) else None
        has_bias = (add is not None and add.op_type == "Add" and list(add.input) == [mul.output[0], name + "_bias"])
        inputs = [conv.input[0], name]
        graph.initializer.append(numpy_helper.from_array(weight, name))
        if has_bias:
            bias = numpy_helper.to_array(constants[name + "_bias"]).astype(np.float32).ravel()
            graph.initializer.append(numpy_helper.from_array(bias, name + "_bias_flat"))
            inputs.append(name + "_bias_flat")
        out = (add if has_bias else mul).output[0]
        node = helper.make_node("Conv", inputs, [out])
        node.attribute.extend(conv.attribute)
        restored.append(node)
        count += 1
        i += 4 if has_bias else 3
    del graph.node[:]
    graph.node.extend(restored)
    used = {name for node in graph.node for name in node.input}
    for t in [t for t in graph.initializer if t.name not in used]:  # the int8 weights, scales and [1, C, 1, 1] biases
        graph.initializer.remove(t)
    return count


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("input")
    ap.add_argument("output")
    a = ap.parse_args()
    import onnx  # python3-onnx
    try:
        model = onnx.load(a.input)
    except Exception as e:  # onnx raises DecodeError, OSError, ... for files that are not ONNX models
        ap.error(f"{a.input}: not an ONNX model ({e})")
    count, before, after = quantize_conv_weights(model)
    onnx.checker.check_model(model)
    onnx.save(model, a.output)
    print(f"{count} convolutions quantised: {before / 1e6:.1f} MB of weights -> {after / 1e6:.1f} MB; {a.output}")


if __name__ == "__main__":
    sys.exit(main())
