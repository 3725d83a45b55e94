#!/usr/bin/python3
"""Checks tfjs_graph.py (graph models) or keras_layers.py (layers models, such as unpack_nsfwjs.js writes)
against TensorFlow.js on one random input: both run the model, the largest absolute difference per requested
node (a layer's name, for a layers model) is printed, and the exit status is 1 if any exceeds --tolerance.

    python3 tools/training/check_tfjs_graph.py MODEL_DIR MODEL.json [--size 416] [NODE ...]

Needs node and, in --node-modules (default: tools/training/node_modules), the packages check_tfjs_graph.js
names. With no NODE, the outputs train.py's --context uses are checked (NanoDet's, or MobileNetV2's for a
layers model). docs/training.md gives the results.
"""
import argparse
import json
import os
import subprocess
import sys
import tempfile

import numpy as np
import torch

if __name__ == "__main__" and not __package__:  # run as a script: import the package as python3 -m does
    sys.path[0] = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
    __package__ = "tools.training"

from .keras_layers import LayersModel  # noqa: E402
from .model import CONTEXTS  # noqa: E402
from .tfjs_graph import GraphModel  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("model_dir")
    ap.add_argument("graph", metavar="model")
    ap.add_argument("nodes", nargs="*")
    ap.add_argument("--size", type=int, default=416, help="input height and width, pixels")
    ap.add_argument("--channels", type=int, default=3)
    ap.add_argument("--tolerance", type=float, default=1e-3, help="largest allowed absolute difference")
    ap.add_argument("--node-modules", default=os.path.join(HERE, "node_modules"))
    a = ap.parse_args()
    with open(os.path.join(a.model_dir, a.graph)) as f:
        layers = json.load(f).get("format") == "layers-model"
    nodes = a.nodes
    if not nodes:
        nodes = CONTEXTS["mobilenet_v2" if layers else "nanodet"]["outputs"]
    torch.manual_seed(0)
    if layers:  # Keras' MobileNetV2 takes -1..1
        x = torch.rand(1, a.channels, a.size, a.size) * 2 - 1
    else:
        x = torch.rand(1, a.channels, a.size, a.size) * 255
    with torch.no_grad():
        model = LayersModel if layers else GraphModel
        ours = model(a.model_dir, a.graph, nodes)(x)
    # A layers model's reference runs on NHWC; compare in that layout.
    fed = x.permute(0, 2, 3, 1).contiguous() if layers else x
    ours = [v.permute(0, 2, 3, 1) if layers else v for v in ours]
    worst = 0.0
    with tempfile.TemporaryDirectory() as tmp:
        fed.numpy().astype(np.float32).tofile(os.path.join(tmp, "input.bin"))
        env = dict(os.environ, NODE_PATH=a.node_modules)
        subprocess.run(["node", os.path.join(HERE, "check_tfjs_graph.js"), a.model_dir, a.graph,
                        os.path.join(tmp, "input.bin"), ",".join(map(str, fed.shape)), os.path.join(tmp, "out"),
                        *nodes], check=True, env=env)
        for i, (name, value) in enumerate(zip(nodes, ours)):
            with open(os.path.join(tmp, f"out{i}.shape")) as f:
                shape = tuple(int(v) for v in f.read().split(","))
            reference = np.fromfile(os.path.join(tmp, f"out{i}.bin"), np.float32).reshape(shape)
            if tuple(value.shape) != shape:
                print(f"{name}: shape {tuple(value.shape)}, TensorFlow.js {shape}")
                worst = float("inf")
                continue
            diff = float(np.abs(value.numpy() - reference).max())
            worst = max(worst, diff)
            print(f"{name}: shape {shape}, max |difference| {diff:.3g} (values up to {np.abs(reference).max():.3g})")
    print("ok" if worst <= a.tolerance else f"FAILED: difference {worst:.3g} > {a.tolerance}")
    return 0 if worst <= a.tolerance else 1


if __name__ == "__main__":
    sys.exit(main())
