#!/usr/bin/env python3
"""Marks the validation models of a training run as split "val" in a copy of a dataset's labels.json, so that
`g2p eval seg --truth OUT --split val` scores exactly the models train.py held out for validation (the same
draw as data.validation_split: whole models of the training rows, `share` of them, random.Random(seed)).
Needs no torch.

    python3 tools/training/val_labels.py MANIFEST.csv[.gz] data/dataset/labels.json data/dataset/labels_val.json \
        [--share 0.1] [--seed 1]
"""
import argparse
import csv
import gzip
import json
import random


def validation_models(manifest, share, seed):
    opener = gzip.open if manifest.endswith(".gz") else open
    with opener(manifest, "rt") as f:
        models = sorted({r["model"] for r in csv.DictReader(f) if r["split"] == "train"})
    return sorted(random.Random(seed).sample(models, int(round(share * len(models))))) if share > 0 else []


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("manifest")
    p.add_argument("labels")
    p.add_argument("out")
    p.add_argument("--share", type=float, default=0.1)
    p.add_argument("--seed", type=int, default=1)
    a = p.parse_args()
    with open(a.labels) as f:
        labels = json.load(f)
    held = validation_models(a.manifest, a.share, a.seed)
    missing = [m for m in held if m not in labels["models"]]
    if missing:
        raise SystemExit(f"{a.labels}: {len(missing)} validation models are missing (for example {missing[0]})")
    for m in held:
        labels["models"][m]["split"] = "val"
    with open(a.out, "w") as f:
        json.dump(labels, f, indent=1)
    print(f"{len(held)} validation models marked in {a.out}")


if __name__ == "__main__":
    main()
