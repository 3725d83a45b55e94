#!/usr/bin/python3
"""A diagnostic baseline for the segmentation network: a classifier of one pixel's colour alone.

    python3 tools/training/colour_baseline.py DATASET OUT [--tau 0.25] [--pixels 150]

A multilayer perceptron (RGB -> 64 -> 64 -> 12 classes) trained on `pixels` labelled pixels of every
training image of DATASET (a g2p_make_dataset folder), with train.py's validation models, class weights and
logit adjustment. It prints the validation pixel mIoU for each tau and exports itself as 1x1 convolutions
(OUT/g2p-materials.onnx and its card), so that `g2p eval seg --segmenter onnx --set model_card=...` scores it
exactly as it scores the network. If the network does not beat this, it has learnt colour and little else
(docs/training-log.md, "Colour alone").
"""
import argparse
import json
import os
import random
import sys

import numpy as np
import torch
import torch.nn as nn

if __name__ == "__main__" and not __package__:  # run as a script: import the package as python3 -m does
    sys.path[0] = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
    __package__ = "tools.training"

from .data import CLASSES, class_weights, read_png, training_rows  # noqa: E402
from .metrics import mean_iou  # noqa: E402


def pixels(root, rows, per_image):
    xs, ys = [], []
    for r in rows:
        rgb = read_png(os.path.join(root, "images", r["image"])).reshape(-1, 3)
        label = read_png(os.path.join(root, "labels", r["image"])).ravel()
        idx = np.nonzero(label != 255)[0]
        if per_image and len(idx) > per_image:
            idx = np.random.choice(idx, per_image, replace=False)
        xs.append(rgb[idx])
        ys.append(label[idx])
    return torch.tensor(np.concatenate(xs)).float() / 255, torch.tensor(np.concatenate(ys)).long()


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("dataset")
    ap.add_argument("out")
    ap.add_argument("--tau", type=float, default=0.25, help="logit adjustment folded into the export")
    ap.add_argument("--pixels", type=int, default=150, help="labelled pixels drawn per training image")
    ap.add_argument("--seed", type=int, default=1)
    a = ap.parse_args()
    random.seed(a.seed)
    np.random.seed(a.seed)
    torch.manual_seed(a.seed)
    try:
        rows, val_rows, _, _ = training_rows(a.dataset, [], 0.1, a.seed)  # the validation models train.py uses
    except ValueError as e:
        ap.error(str(e))
    val_rows = val_rows[::max(1, len(val_rows) // 256)]
    weights, counts = class_weights(rows, 0.5)
    x, y = pixels(a.dataset, rows, a.pixels)
    xv, yv = pixels(a.dataset, val_rows, 0)
    mlp = nn.Sequential(nn.Linear(3, 64), nn.ReLU(), nn.Linear(64, 64), nn.ReLU(), nn.Linear(64, len(CLASSES)))
    opt = torch.optim.Adam(mlp.parameters(), 1e-2)
    loss_fn = nn.CrossEntropyLoss(weight=weights)
    for _ in range(6):
        order = torch.randperm(len(y))
        for i in range(0, len(y), 4096):
            b = order[i:i + 4096]
            loss = loss_fn(mlp(x[b]), y[b])
            opt.zero_grad()
            loss.backward()
            opt.step()
    prior = torch.tensor(counts / max(counts.sum(), 1), dtype=torch.float32)

    def adjustment(tau):
        return torch.where(prior > 0, -tau * torch.log(prior.clamp(min=1e-12)), torch.full_like(prior, -30.0))

    with torch.no_grad():
        logits = mlp(xv)
        for tau in (0.0, 0.25, 0.5, 0.75, 1.0):
            predicted = (logits + adjustment(tau)).argmax(1)
            matrix = torch.bincount(yv * len(CLASSES) + predicted, minlength=len(CLASSES) ** 2)
            print(f"tau {tau}: validation pixel mIoU {mean_iou(matrix.view(len(CLASSES), -1).double()):.3f}")
    layers = []
    for layer in mlp:
        if isinstance(layer, nn.Linear):
            conv = nn.Conv2d(layer.in_features, layer.out_features, 1)
            conv.weight.data = layer.weight.data[:, :, None, None].clone()
            conv.bias.data = layer.bias.data.clone()
            layers.append(conv)
        else:
            layers.append(nn.ReLU())
    net = nn.Sequential(*layers).eval()
    with torch.no_grad():
        net[-1].bias += adjustment(a.tau)
    os.makedirs(a.out, exist_ok=True)
    torch.onnx.export(net, torch.zeros(1, 3, 128, 128), os.path.join(a.out, "g2p-materials.onnx"),
                      input_names=["pixels"], output_names=["logits"], opset_version=11)
    card = {"format": "g2p-onnx-model-card", "version": 1, "model": "g2p-materials.onnx",
            "input": {"width": 128, "height": 128, "channel_order": "RGB", "scale": 1 / 255, "mean": [0, 0, 0],
                      "std": [1, 1, 1], "name": "pixels"},
            "output": {"kind": "logits", "name": "logits"}, "classes": CLASSES,
            "trained_on": "colour-only baseline (tools/training/colour_baseline.py)"}
    with open(os.path.join(a.out, "g2p-materials.json"), "w") as f:
        json.dump(card, f, indent=2)
        f.write("\n")


if __name__ == "__main__":
    main()
