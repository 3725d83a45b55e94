#!/usr/bin/python3
"""Expand the rule annotations of the generated test set (#31) into per-face labels.

    /usr/bin/python3 scripts/generated_set/annotate.py [--only ID ...] [--render OUT]

Reads data/generated/annotations.json and manifest.json, writes data/generated/labels/<id>.json
(one class per face, run-length coded, in the order of the GLB's index buffers = `source_face`
of faces.csv) and prints the share of faces and area per class. With --render, writes a PLY
coloured by class per model and renders it with `g2p render` into OUT/<id>/ for checking
(set G2P to the binary; default /work/main/build/bin/g2p).

Rule format (see data/generated/README.md): every model has a `default` class and an ordered
list of `rules`; a rule is {"class": C, "where": {...}, "why": "..."}; every condition in
`where` must hold; the last matching rule wins. Conditions, all on the face's centroid or
base colour:
  x, y, z      [lo, hi]: position along the file's axis, normalised to [0, 1] over the model's
               bounding box (glTF: y is up; 0 = bottom)
  r            [lo, hi]: horizontal distance from the bounding box's vertical centre line,
               divided by half the box's larger horizontal side
  component    [i, ...]: connected components by size rank (0 = most faces)
  h            [lo, hi]: hue of the base colour in degrees (lo > hi wraps through 0)
  s, v         [lo, hi]: saturation and value of the base colour (HSV, 0..1)
`ignore` is a class: such faces are left out of every score.
"""
import argparse
import colorsys
import json
import os
import subprocess
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import glb  # noqa: E402

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
SET = os.path.join(ROOT, "data", "generated")
CLASSES = ["Wood", "Rubber", "Fabric", "Organic", "Leather", "Metal", "Paper", "Plastic", "Glass",
           "Ceramic", "Stone", "Other", "ignore"]
PALETTE = {"Wood": (150, 90, 40), "Rubber": (30, 30, 30), "Fabric": (200, 60, 160),
           "Organic": (40, 170, 40), "Leather": (120, 60, 20), "Metal": (60, 120, 230),
           "Paper": (240, 240, 200), "Plastic": (240, 200, 0), "Glass": (120, 230, 230),
           "Ceramic": (230, 120, 90), "Stone": (140, 140, 140), "Other": (255, 0, 0),
           "ignore": (255, 255, 255)}


def model_path(entry):
    """The model file: committed under data/generated/, or fetched to external/."""
    return os.path.join(SET, entry["file"])


def features(model):
    p = model.positions[model.faces].mean(axis=1)
    lo, hi = model.positions.min(axis=0), model.positions.max(axis=0)
    n = (p - lo) / np.maximum(hi - lo, 1e-12)
    up = model.up_axis
    horizontal = [a for a in range(3) if a != up]
    centre = (lo + hi) / 2
    half = max((hi - lo)[horizontal]) / 2
    r = np.linalg.norm((p - centre)[:, horizontal], axis=1) / half
    hsv = np.array([colorsys.rgb_to_hsv(*c) for c in np.clip(model.face_rgb, 0, 1)])
    return {"x": n[:, 0], "y": n[:, 1], "z": n[:, 2], "r": r, "h": hsv[:, 0] * 360,
            "s": hsv[:, 1], "v": hsv[:, 2]}


def expand(model, annotation):
    feats = features(model)
    labels = np.full(len(model.faces), CLASSES.index(annotation["default"]), dtype=np.int64)
    components = None
    for rule in annotation.get("rules", []):
        mask = np.ones(len(model.faces), dtype=bool)
        for key, value in rule["where"].items():
            if key == "component":
                if components is None:
                    components = model.components()
                mask &= np.isin(components, value)
            elif key == "h" and value[0] > value[1]:
                mask &= (feats["h"] >= value[0]) | (feats["h"] <= value[1])
            elif key in feats:
                mask &= (feats[key] >= value[0]) & (feats[key] <= value[1])
            else:
                raise ValueError(f"{annotation['id']}: unknown condition {key!r}")
        labels[mask] = CLASSES.index(rule["class"])
    return labels


def rle(labels):
    runs, start = [], 0
    for i in range(1, len(labels) + 1):
        if i == len(labels) or labels[i] != labels[start]:
            runs.append([int(labels[start]), i - start])
            start = i
    return runs


def unrle(runs):
    return np.concatenate([np.full(n, c, dtype=np.int64) for c, n in runs])


def load_labels(model_id):
    doc = json.load(open(os.path.join(SET, "labels", model_id + ".json")))
    return [doc["classes"][i] for i in unrle(doc["runs"])]


def write_ply(path, model, labels):
    p = model.positions[model.faces].reshape(-1, 3).astype(np.float32)
    c = np.repeat(np.array([PALETTE[CLASSES[i]] for i in labels], dtype=np.uint8), 3, axis=0)
    vert = np.zeros(len(p), dtype=[("x", "<f4"), ("y", "<f4"), ("z", "<f4"), ("red", "u1"),
                                   ("green", "u1"), ("blue", "u1")])
    vert["x"], vert["y"], vert["z"] = p[:, 0], p[:, 1], p[:, 2]
    vert["red"], vert["green"], vert["blue"] = c[:, 0], c[:, 1], c[:, 2]
    faces = np.zeros(len(model.faces), dtype=[("n", "u1"), ("i", "<i4", 3)])
    faces["n"] = 3
    faces["i"] = np.arange(len(p)).reshape(-1, 3)
    with open(path, "wb") as f:
        f.write(("ply\nformat binary_little_endian 1.0\nelement vertex %d\nproperty float x\n"
                 "property float y\nproperty float z\nproperty uchar red\nproperty uchar green\n"
                 "property uchar blue\nelement face %d\nproperty list uchar int vertex_indices\n"
                 "end_header\n" % (len(p), len(model.faces))).encode())
        f.write(vert.tobytes())
        f.write(faces.tobytes())


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--only", nargs="*", help="model ids (default: all)")
    ap.add_argument("--render", help="folder for check renders of the labels")
    ap.add_argument("--views", type=int, default=4)
    args = ap.parse_args()
    manifest = {m["id"]: m for m in json.load(open(os.path.join(SET, "manifest.json")))["models"]}
    annotations = json.load(open(os.path.join(SET, "annotations.json")))["models"]
    os.makedirs(os.path.join(SET, "labels"), exist_ok=True)
    g2p = os.environ.get("G2P", "/work/main/build/bin/g2p")
    for annotation in annotations:
        if args.only and annotation["id"] not in args.only:
            continue
        entry = manifest[annotation["id"]]
        model = glb.Model(model_path(entry))
        labels = expand(model, annotation)
        areas = model.face_areas()
        used = sorted(set(labels.tolist()))
        with open(os.path.join(SET, "labels", annotation["id"] + ".json"), "w") as f:
            json.dump({"id": annotation["id"], "faces": int(len(labels)), "classes": CLASSES,
                       "runs": rle(labels)}, f, separators=(",", ":"))
            f.write("\n")
        share = ", ".join(f"{CLASSES[c]} {100 * np.mean(labels == c):.1f}% of faces "
                          f"({100 * areas[labels == c].sum() / areas.sum():.1f}% of area)"
                          for c in used)
        print(f"{annotation['id']}: {len(labels)} faces: {share}")
        if args.render:
            out = os.path.join(args.render, annotation["id"])
            os.makedirs(out, exist_ok=True)
            ply = os.path.join(out, "labels.ply")
            write_ply(ply, model, labels)
            subprocess.run([g2p, "render", ply, "-o", out, "--views", str(args.views), "--layout",
                            "turntable", "--resolution", "320", "--up", "y"],
                           check=True, stdout=subprocess.DEVNULL)


if __name__ == "__main__":
    main()
