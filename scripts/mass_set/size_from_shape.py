#!/usr/bin/python3
"""How well does an object's shape tell its real size? A validation diagnostic for #31, item 3.

    /usr/bin/python3 scripts/mass_set/size_from_shape.py [--labels data/dataset/labels_val.json]

Issue #31 asks `g2p run` to state the size it assumes for a normalised mesh "where the recognised
object allows". This measures what a recogniser built from the training catalogue could give:
every sweethome3d model of the `train` split is a row (its catalogue entry's longest side, the
real size Sweet Home 3D gives it; its mesh's proportions; the classes of its ground-truth labels),
and each `val` model's longest side is predicted as the median of its k nearest training rows.
Only the train and val splits are read; the held-out (`test`) models are skipped.

Features, all independent of the mesh's scale: the middle and shortest side of the bounding box
over the longest; log(surface area / longest side^2) (a flat panel, a box, a wire frame); and,
in the second half of the table, which of the 11 material classes the model's true labels hold
(an upper bound for what a segmenter's classes could add). Baselines: every object 1 m long (what
a generator's normalised mesh says) and the training median.

Printed per predictor: the median factor |log(predicted / true)| as a ratio, and the share of
validation models within 1.5 and 2 times their real size. Mass goes with the cube of size for
solid parts, so a size within 1.5 times is a mass within 3.4 times.
"""
import argparse
import json
import os
import re
import sys

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
CLASSES = ["Wood", "Metal", "Plastic", "Fabric", "Glass", "Ceramic", "Stone", "Leather", "Rubber", "Organic", "Paper"]


def catalogue(sh3d):
    """(library, model path in lower case) -> the catalogue entry's fields."""
    out = {}
    for lib in sorted(os.listdir(sh3d)):
        path = os.path.join(sh3d, lib, "PluginFurnitureCatalog.properties")
        if not os.path.exists(path):
            continue
        entries = {}
        for line in open(path, encoding="latin-1"):
            m = re.match(r"(\w+)#(\d+)=(.*)", line.strip())
            if m:
                entries.setdefault(int(m.group(2)), {})[m.group(1)] = m.group(3)
        for e in entries.values():
            if "model" in e and "width" in e:
                out[(lib, e["model"].strip("/").lower())] = e
    return out


def entry_for(cat, key):
    lib, rest = key.split("/")[0], "/".join(key.split("/")[1:]).lower()
    for (l, m), e in cat.items():
        if l == lib and (m == rest or m.endswith(rest) or rest.endswith(m)):
            return e
    return None


def shape(path):
    """Sorted side ratios and log(area / longest^2) of an OBJ."""
    v, f = [], []
    for line in open(path, errors="ignore"):
        if line.startswith("v "):
            v.append([float(x) for x in line.split()[1:4]])
        elif line.startswith("f "):
            idx = [int(t.split("/")[0]) for t in line.split()[1:]]
            idx = [i - 1 if i > 0 else len(v) + i for i in idx]
            f.extend((idx[0], idx[j], idx[j + 1]) for j in range(1, len(idx) - 1))
    v, f = np.array(v), np.array(f)
    sides = np.sort(v.max(0) - v.min(0))[::-1]
    area = 0.5 * np.linalg.norm(np.cross(v[f[:, 1]] - v[f[:, 0]], v[f[:, 2]] - v[f[:, 0]]), axis=1).sum()
    return [sides[1] / sides[0], sides[2] / sides[0], np.log(area / sides[0] ** 2)]


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--labels", default=os.path.join(ROOT, "data", "dataset", "labels_val.json"))
    ap.add_argument("--sh3d", default=os.path.join(ROOT, "data", "sh3d"))
    args = ap.parse_args()
    cat = catalogue(args.sh3d)
    rows = {"train": [], "val": []}
    for key, model in json.load(open(args.labels))["models"].items():
        if model.get("split") not in rows:
            continue  # the held-out models are not read
        e = entry_for(cat, key)
        if e is None:
            print("no catalogue entry: " + key, file=sys.stderr)
            continue
        longest = max(float(e["width"]), float(e["depth"]), float(e["height"])) / 100.0
        classes = set(model["labels"].values())
        rows[model["split"]].append((longest, shape(os.path.join(args.sh3d, key)), classes))
    train, val = rows["train"], rows["val"]
    y_train = np.log([r[0] for r in train])
    y_val = np.log([r[0] for r in val])
    print(f"{len(train)} training and {len(val)} validation models")

    def report(name, predicted):
        err = np.abs(predicted - y_val)
        print(f"| {name} | x{np.exp(np.median(err)):.2f} | {np.mean(err < np.log(1.5)) * 100:.0f} % "
              f"| {np.mean(err < np.log(2)) * 100:.0f} % |")

    print("| predictor | median factor | within 1.5x | within 2x |\n|---|---:|---:|---:|")
    report("every object 1 m", np.zeros(len(val)))
    report("the training median", np.full(len(val), np.median(y_train)))
    for with_classes in (False, True):

        def features(r):
            x = [r[1][0], r[1][1], 0.3 * r[1][2]]
            return np.array(x + ([0.3 * (c in r[2]) for c in CLASSES] if with_classes else []))

        x_train = np.array([features(r) for r in train])
        x_val = np.array([features(r) for r in val])
        dist = ((x_val[:, None, :] - x_train[None]) ** 2).sum(-1)
        for k in (3, 7, 15):
            nearest = np.argsort(dist, axis=1)[:, :k]
            what = "shape and true classes" if with_classes else "shape"
            report(f"{k} nearest by {what}", np.median(y_train[nearest], axis=1))


if __name__ == "__main__":
    main()
