#!/usr/bin/env python3
"""Writes a tiny ONNX "segmentation network" and its libg2p model card, for the tests.

The network is one 1x1 convolution: output channel c = 10 * input channel c,
so the predicted class of a pixel is its strongest colour channel (after the
card's normalisation). With the card's classes [Wood, Metal, Glass], red
pixels are Wood, green ones Metal and blue ones Glass when the channel order
is RGB. The 2x2 average pool halves the output size, so the segmenter has to
resize the output back to the view.

A second network, tiny_normals.onnx (card card_normals.json, input channels
["rgb", "normal"]), ignores colour and reads the camera-space normal n:
logits (10 n_x, -10 n_x, 1), so surfaces facing right (n_x > 0.1) are Wood,
those facing left Metal and the rest, or a view without normals, Glass.
A third, tiny_normals_only.onnx (card card_normals_only.json, input channels
["normal"]), is the same network without the colour planes.

usage: make_tiny_onnx.py OUT_DIR
"""
import json
import os
import sys

import numpy as np
import onnx
from onnx import TensorProto, helper, numpy_helper


def main(out_dir):
    os.makedirs(out_dir, exist_ok=True)
    weights = numpy_helper.from_array((10.0 * np.eye(3, dtype=np.float32)).reshape(3, 3, 1, 1), name="w")
    conv = helper.make_node("Conv", ["input", "w"], ["conv"], kernel_shape=[1, 1])
    pool = helper.make_node("AveragePool", ["conv"], ["logits"], kernel_shape=[2, 2], strides=[2, 2])
    graph = helper.make_graph(
        [conv, pool], "tiny_seg",
        [helper.make_tensor_value_info("input", TensorProto.FLOAT, [1, 3, 32, 32])],
        [helper.make_tensor_value_info("logits", TensorProto.FLOAT, [1, 3, 16, 16])],
        initializer=[weights])
    model = helper.make_model(graph, producer_name="libg2p-tests", opset_imports=[helper.make_opsetid("", 11)])
    model.ir_version = 7
    onnx.checker.check_model(model)
    onnx.save(model, os.path.join(out_dir, "tiny_seg.onnx"))
    for order in ("RGB", "BGR"):
        card = {
            "format": "g2p-onnx-model-card", "version": 1, "model": "tiny_seg.onnx",
            "input": {"width": 32, "height": 32, "channel_order": order, "scale": 1.0 / 255.0,
                      "mean": [0.0, 0.0, 0.0], "std": [1.0, 1.0, 1.0], "name": "input"},
            "output": {"kind": "logits", "name": "logits"},
            "classes": ["Wood", "Metal", "Glass"],
        }
        with open(os.path.join(out_dir, "card_%s.json" % order.lower()), "w") as f:
            json.dump(card, f, indent=2)

    w = np.zeros((3, 6, 1, 1), dtype=np.float32)
    w[0, 3], w[1, 3] = 10.0, -10.0  # input channel 3 is the normal's x
    conv = helper.make_node("Conv", ["input", "w", "b"], ["logits"], kernel_shape=[1, 1])
    graph = helper.make_graph(
        [conv], "tiny_normals",
        [helper.make_tensor_value_info("input", TensorProto.FLOAT, [1, 6, 32, 32])],
        [helper.make_tensor_value_info("logits", TensorProto.FLOAT, [1, 3, 32, 32])],
        initializer=[numpy_helper.from_array(w, name="w"),
                     numpy_helper.from_array(np.array([0.0, 0.0, 1.0], dtype=np.float32), name="b")])
    model = helper.make_model(graph, producer_name="libg2p-tests", opset_imports=[helper.make_opsetid("", 11)])
    model.ir_version = 7
    onnx.checker.check_model(model)
    onnx.save(model, os.path.join(out_dir, "tiny_normals.onnx"))
    card = {"format": "g2p-onnx-model-card", "version": 1, "model": "tiny_normals.onnx",
            "input": {"width": 32, "height": 32, "name": "input", "channels": ["rgb", "normal"]},
            "output": {"kind": "logits", "name": "logits"}, "classes": ["Wood", "Metal", "Glass"]}
    with open(os.path.join(out_dir, "card_normals.json"), "w") as f:
        json.dump(card, f, indent=2)

    conv = helper.make_node("Conv", ["input", "w", "b"], ["logits"], kernel_shape=[1, 1])
    graph = helper.make_graph(
        [conv], "tiny_normals_only",
        [helper.make_tensor_value_info("input", TensorProto.FLOAT, [1, 3, 32, 32])],
        [helper.make_tensor_value_info("logits", TensorProto.FLOAT, [1, 3, 32, 32])],
        initializer=[numpy_helper.from_array(np.ascontiguousarray(w[:, 3:]), name="w"),
                     numpy_helper.from_array(np.array([0.0, 0.0, 1.0], dtype=np.float32), name="b")])
    model = helper.make_model(graph, producer_name="libg2p-tests", opset_imports=[helper.make_opsetid("", 11)])
    model.ir_version = 7
    onnx.checker.check_model(model)
    onnx.save(model, os.path.join(out_dir, "tiny_normals_only.onnx"))
    card = dict(card, model="tiny_normals_only.onnx", input=dict(card["input"], channels=["normal"]))
    with open(os.path.join(out_dir, "card_normals_only.json"), "w") as f:
        json.dump(card, f, indent=2)


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    main(sys.argv[1])
