#!/usr/bin/python3
"""Trains libg2p's material segmentation network and exports it for the `onnx` backend.

    python3 tools/training/train.py DATASET OUT [--epochs 12] [--threads 2] [--device cpu]

DATASET is a folder written by g2p_make_dataset (images/, labels/, manifest.csv). Only the rows of
split "train" are used; the held-out libraries are never read here. OUT receives g2p-materials.onnx,
its model card g2p-materials.json (the format docs/segment.md describes), training.json (the exact
settings, per-epoch losses and the data manifest's checksum) and the checkpoint. docs/training.md
gives the recipe and the measured accuracy.

The network is a compact U-Net (Ronneberger et al. 2015): four stride-2 stages of two 3x3 convolutions
with batch normalisation (16-32-64-128 channels, 128 at the bottleneck), bilinear upsampling with skip
connections, a 1x1 classifier to the 12 classes; 1.2 M parameters (4.9 MB as ONNX). Augmentations model what
image-to-3D meshes look like: colour jitter, blur (baked, low-resolution textures), grey-scale, flips and
random resized crops. Pixels labelled 255 (unlabelled materials, background) are ignored by the loss.
"""
import argparse
import csv
import hashlib
import json
import math
import os
import random
import time

import numpy as np
import torch
import torch.nn as nn
import torch.nn.functional as F

CLASSES = ["Wood", "Rubber", "Fabric", "Organic", "Leather", "Metal", "Paper", "Plastic", "Glass",
           "Ceramic", "Stone", "Other"]
MEAN = [0.485, 0.456, 0.406]
STD = [0.229, 0.224, 0.225]


def read_png(path):
    from PIL import Image  # python3-pil
    with Image.open(path) as image:
        array = np.asarray(image)
    return array[:, :, :3] if array.ndim == 3 else array


class Dataset(torch.utils.data.Dataset):
    def __init__(self, root, rows, size, train):
        self.root, self.rows, self.size, self.train = root, rows, size, train

    def __len__(self):
        return len(self.rows)

    def __getitem__(self, i):
        name = self.rows[i]["image"]
        rgb = torch.from_numpy(np.array(read_png(os.path.join(self.root, "images", name)))).float() / 255
        label = torch.from_numpy(read_png(os.path.join(self.root, "labels", name)).astype(np.int64))
        rgb = rgb.permute(2, 0, 1)
        if self.train:
            rgb, label = augment(rgb, label, self.size)
        rgb = (rgb - torch.tensor(MEAN)[:, None, None]) / torch.tensor(STD)[:, None, None]
        return rgb, label


def augment(rgb, label, size):
    # Random resized crop (scale 0.6-1 of the side), flip.
    h, w = label.shape
    s = random.uniform(0.6, 1.0)
    ch, cw = int(h * s), int(w * s)
    y, x = random.randint(0, h - ch), random.randint(0, w - cw)
    rgb = F.interpolate(rgb[None, :, y:y + ch, x:x + cw], size=(size, size), mode="bilinear", align_corners=False)[0]
    label = F.interpolate(label[None, None, y:y + ch, x:x + cw].float(), size=(size, size), mode="nearest")[0, 0].long()
    if random.random() < 0.5:
        rgb, label = rgb.flip(-1), label.flip(-1)
    # Colour: brightness, contrast, saturation, a small hue shift (channel mixing), grey-scale.
    rgb = rgb * random.uniform(0.7, 1.3)
    mean = rgb.mean()
    rgb = (rgb - mean) * random.uniform(0.7, 1.3) + mean
    grey = rgb.mean(0, keepdim=True)
    rgb = (rgb - grey) * random.uniform(0.6, 1.4) + grey
    if random.random() < 0.3:
        mix = torch.eye(3) + 0.08 * torch.randn(3, 3)
        rgb = torch.einsum("ij,jhw->ihw", mix, rgb)
    if random.random() < 0.1:
        rgb = rgb.mean(0, keepdim=True).expand(3, -1, -1).clone()
    # Blur: baked, low-resolution textures.
    if random.random() < 0.3:
        k = random.choice([3, 5])
        rgb = F.avg_pool2d(rgb[None], k, stride=1, padding=k // 2, count_include_pad=False)[0]
    return rgb.clamp(0, 1), label


def block(cin, cout):
    return nn.Sequential(nn.Conv2d(cin, cout, 3, padding=1, bias=False), nn.BatchNorm2d(cout), nn.ReLU(inplace=True),
                         nn.Conv2d(cout, cout, 3, padding=1, bias=False), nn.BatchNorm2d(cout), nn.ReLU(inplace=True))


class UNet(nn.Module):
    def __init__(self, classes=len(CLASSES), width=(16, 32, 64, 128, 128)):
        super().__init__()
        self.enc = nn.ModuleList([block(3, width[0])] + [block(width[i], width[i + 1]) for i in range(len(width) - 1)])
        self.dec = nn.ModuleList([block(width[i + 1] + width[i], width[i]) for i in reversed(range(len(width) - 1))])
        self.head = nn.Conv2d(width[0], classes, 1)

    def forward(self, x):
        skips = []
        for i, e in enumerate(self.enc):
            x = e(x if i == 0 else F.max_pool2d(x, 2))
            skips.append(x)
        for d, skip in zip(self.dec, reversed(skips[:-1])):
            x = F.interpolate(x, size=skip.shape[-2:], mode="bilinear", align_corners=False)
            x = d(torch.cat([x, skip], 1))
        return self.head(x)


def class_weights(rows):
    counts = np.array([sum(int(r[c]) for r in rows) for c in CLASSES], dtype=np.float64)
    present = counts > 0
    freq = counts / counts.sum()
    w = np.zeros(len(CLASSES))
    w[present] = np.sqrt(np.median(freq[present]) / freq[present])  # square-root median-frequency balancing
    return torch.tensor(np.clip(w, 0.0, 5.0), dtype=torch.float32), counts


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("dataset")
    ap.add_argument("out")
    ap.add_argument("--epochs", type=int, default=12)
    ap.add_argument("--batch", type=int, default=16)
    ap.add_argument("--size", type=int, default=96, help="training crop size, pixels")
    ap.add_argument("--export-size", type=int, default=128, help="the ONNX input size (the view is resized to it)")
    ap.add_argument("--lr", type=float, default=3e-3)
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--device", default="cpu")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--max-minutes", type=float, default=0, help="stop after this long (0 = no limit)")
    ap.add_argument("--init", default="", help="start from this checkpoint (a previous run's checkpoint.pt)")
    a = ap.parse_args()

    random.seed(a.seed)
    np.random.seed(a.seed)
    torch.manual_seed(a.seed)
    torch.set_num_threads(a.threads)
    os.makedirs(a.out, exist_ok=True)
    with open(os.path.join(a.dataset, "manifest.csv")) as f:
        rows = [r for r in csv.DictReader(f) if r["split"] == "train"]
    with open(os.path.join(a.dataset, "manifest.csv"), "rb") as f:
        manifest_sha = hashlib.sha256(f.read()).hexdigest()
    weights, counts = class_weights(rows)
    print(f"{len(rows)} training images; labelled pixels per class:",
          {c: int(n) for c, n in zip(CLASSES, counts)}, flush=True)
    data = torch.utils.data.DataLoader(Dataset(a.dataset, rows, a.size, True), batch_size=a.batch, shuffle=True,
                                       num_workers=0, drop_last=True)
    model = UNet()
    if a.init:
        model.load_state_dict(torch.load(a.init, map_location="cpu"))
    model = model.to(a.device)
    params = sum(p.numel() for p in model.parameters())
    opt = torch.optim.AdamW(model.parameters(), lr=a.lr, weight_decay=1e-4)
    steps = a.epochs * len(data)
    sched = torch.optim.lr_scheduler.OneCycleLR(opt, max_lr=a.lr, total_steps=max(steps, 1), pct_start=0.1)
    loss_fn = nn.CrossEntropyLoss(weight=weights.to(a.device), ignore_index=255)
    log = []
    start = time.time()
    stopped_early = False
    for epoch in range(a.epochs):
        model.train()
        total, n = 0.0, 0
        for rgb, label in data:
            rgb, label = rgb.to(a.device), label.to(a.device)
            loss = loss_fn(model(rgb), label)
            opt.zero_grad()
            loss.backward()
            opt.step()
            sched.step()
            total += loss.item()
            n += 1
            if a.max_minutes and time.time() - start > 60 * a.max_minutes:
                stopped_early = True
                break
        log.append({"epoch": epoch + 1, "steps": n, "loss": total / max(n, 1), "seconds": time.time() - start})
        print(f"epoch {epoch + 1}: {n} steps, loss {total / max(n, 1):.4f} ({time.time() - start:.0f} s)", flush=True)
        torch.save(model.state_dict(), os.path.join(a.out, "checkpoint.pt"))
        if stopped_early:
            break

    model.eval().cpu()
    onnx_path = os.path.join(a.out, "g2p-materials.onnx")
    torch.onnx.export(model, torch.zeros(1, 3, a.export_size, a.export_size), onnx_path, input_names=["pixels"],
                      output_names=["logits"], opset_version=11)
    card = {"format": "g2p-onnx-model-card", "version": 1, "model": "g2p-materials.onnx",
            "input": {"width": a.export_size, "height": a.export_size, "channel_order": "RGB", "scale": 1 / 255,
                      "mean": MEAN, "std": STD, "name": "pixels"},
            "output": {"kind": "logits", "name": "logits"},
            "classes": CLASSES,
            "trained_on": "sweethome3d-furniture: BlendSwap-CC-0, BlendSwap-CC-BY, Scopia (docs/training.md)"}
    with open(os.path.join(a.out, "g2p-materials.json"), "w") as f:
        json.dump(card, f, indent=2)
        f.write("\n")
    with open(os.path.join(a.out, "training.json"), "w") as f:
        json.dump({"settings": vars(a), "parameters": params, "images": len(rows), "manifest_sha256": manifest_sha,
                   "class_weights": dict(zip(CLASSES, weights.tolist())), "epochs": log,
                   "stopped_early": stopped_early, "torch": torch.__version__}, f, indent=2)
        f.write("\n")
    print(f"{params} parameters -> {onnx_path}", flush=True)


if __name__ == "__main__":
    main()
