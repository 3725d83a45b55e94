#!/usr/bin/python3
"""Checks tfjs_graph.py against TensorFlow.js on one random input: both run the graph, the largest absolute
difference per requested node is printed, and the exit status is 1 if any exceeds --tolerance.

    python3 tools/training/check_tfjs_graph.py MODEL_DIR GRAPH.json [--size 416] [NODE ...]

Needs node and, in --node-modules (default: tools/training/node_modules), the packages check_tfjs_graph.js
names. With no NODE, the nodes train.py's --context uses are checked. docs/training.md gives the result.
"""
import argparse
import os
import subprocess
import sys
import tempfile

import numpy as np
import torch

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
from tfjs_graph import GraphModel  # noqa: E402


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("model_dir")
    ap.add_argument("graph")
    ap.add_argument("nodes", nargs="*")
    ap.add_argument("--size", type=int, default=416, help="input height and width, pixels")
    ap.add_argument("--channels", type=int, default=3)
    ap.add_argument("--tolerance", type=float, default=1e-3, help="largest allowed absolute difference")
    ap.add_argument("--node-modules", default=os.path.join(HERE, "node_modules"))
    a = ap.parse_args()
    nodes = a.nodes
    if not nodes:
        import train  # noqa: E402 (the same folder)
        nodes = train.CONTEXT_OUTPUTS
    torch.manual_seed(0)
    x = torch.rand(1, a.channels, a.size, a.size) * 255
    with torch.no_grad():
        ours = GraphModel(a.model_dir, a.graph, nodes)(x)
    worst = 0.0
    with tempfile.TemporaryDirectory() as tmp:
        x.numpy().astype(np.float32).tofile(os.path.join(tmp, "input.bin"))
        env = dict(os.environ, NODE_PATH=a.node_modules)
        subprocess.run(["node", os.path.join(HERE, "check_tfjs_graph.js"), a.model_dir, a.graph,
                        os.path.join(tmp, "input.bin"), ",".join(map(str, x.shape)), os.path.join(tmp, "out"),
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
