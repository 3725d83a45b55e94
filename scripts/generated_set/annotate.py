#!/usr/bin/python3
"""Expand the rule annotations of the generated test set (#31) into per-face labels.

    /usr/bin/python3 scripts/generated_set/annotate.py [--only ID ...] [--sheet OUT]

Reads data/generated/annotations.json and manifest.json, writes data/generated/labels/<id>.json
(one class per face, run-length coded, in the order of the GLB's index buffers = `source_face`
of faces.csv) and prints the share of faces and area per class. With --sheet, writes OUT/<id>.png:
three orthographic views in normalised coordinates (grid every 0.1, the model's centre lines in
red) of the base colour above and of the labels below, to check the rules against the model.
(`g2p render` cannot show the labels: it does not read per-vertex colours, as of d65ae80.)

Rule format (see data/generated/README.md): every model has a `default` class and an ordered
list of `rules`; a rule is {"class": C, "where": {...}, "why": "..."}; every condition in
`where` must hold; the last matching rule wins. Conditions, all on the face's centroid or
base colour:
  x, y, z      [lo, hi]: position along the file's axis, normalised to [0, 1] over the model's
               bounding box (glTF: y is up; 0 = bottom)
  r            [lo, hi]: horizontal distance from the bounding box's vertical centre line,
               divided by half the box's larger horizontal side
  dist         [cx, cy, cz, lo, hi]: distance of the centroid from the point (cx, cy, cz), given
               in normalised coordinates, in units of the model's longest side
  component    [i, ...]: connected components by size rank (0 = most faces)
  h            [lo, hi]: hue of the base colour in degrees (lo > hi wraps through 0)
  s, v         [lo, hi]: saturation and value of the base colour (HSV, 0..1)
`ignore` is a class: such faces are left out of every score.
"""
import argparse
import colorsys
import json
import os
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


# The model files come from public repositories and are never committed here:
# they are read from ../shared/generated, named by the basename of the
# manifest's `file`.
SHARED = os.path.join(os.path.dirname(ROOT), "shared", "generated")


def model_path(entry):
    """The model file in ../shared/generated (it may be absent)."""
    return os.path.join(SHARED, os.path.basename(entry["file"]))


def features(model):
    p = model.positions[model.faces].mean(axis=1)
    lo, hi = model.positions.min(axis=0), model.positions.max(axis=0)
    n = (p - lo) / np.maximum(hi - lo, 1e-12)
    up = model.up_axis
    horizontal = [a for a in range(3) if a != up]
    centre = (lo + hi) / 2
    half = max((hi - lo)[horizontal]) / 2
    r = np.linalg.norm((p - centre)[:, horizontal], axis=1) / half
    size = hi - lo
    hsv = np.array([colorsys.rgb_to_hsv(*c) for c in np.clip(model.face_rgb, 0, 1)])
    return {"x": n[:, 0], "y": n[:, 1], "z": n[:, 2], "r": r, "h": hsv[:, 0] * 360,
            "s": hsv[:, 1], "v": hsv[:, 2], "_p": p, "_lo": lo, "_size": size}


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
            elif key == "dist":
                centre = feats["_lo"] + np.array(value[:3]) * feats["_size"]
                d = np.linalg.norm(feats["_p"] - centre, axis=1) / feats["_size"].max()
                mask &= (d >= value[3]) & (d <= value[4])
            elif key == "h" and value[0] > value[1]:
                mask &= (feats["h"] >= value[0]) | (feats["h"] <= value[1])
            elif key in feats and not key.startswith("_"):
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


def ortho_views(model, face_colours, px=300):
    """Three orthographic views (front: x-y, side: z-y, top: x-z; normalised coordinates with a
    grid every 0.1) of the faces in the given colours, by splatting 7 points per face."""
    from PIL import Image, ImageDraw
    lo, hi = model.positions.min(axis=0), model.positions.max(axis=0)
    tri = (model.positions[model.faces] - lo) / np.maximum(hi - lo, 1e-12)
    pts = np.concatenate([tri, (tri + np.roll(tri, 1, axis=1)) / 2, tri.mean(axis=1, keepdims=True)], axis=1)
    col = np.repeat(np.asarray(face_colours, dtype=np.uint8), pts.shape[1], axis=0)
    pts = pts.reshape(-1, 3)
    images = []
    for h, v, depth, name in ((0, 1, 2, "front x-y"), (2, 1, 0, "side z-y"), (0, 2, 1, "top x-z")):
        img = np.full((px, px, 3), 235, dtype=np.uint8)
        u = np.clip((pts[:, h] * (px - 1)).astype(int), 0, px - 1)
        w = np.clip(((1 - pts[:, v]) * (px - 1)).astype(int), 0, px - 1)
        order = np.argsort(pts[:, depth])  # far (low) first, near (high) last overwrites
        img[w[order], u[order]] = col[order]
        im = Image.fromarray(img)
        d = ImageDraw.Draw(im)
        for k in range(11):
            t = int(k / 10 * (px - 1))
            d.line([(t, 0), (t, px)], fill=(255, 0, 0) if k == 5 else (170, 170, 170), width=1)
            d.line([(0, t), (px, t)], fill=(255, 0, 0) if k == 5 else (170, 170, 170), width=1)
        d.text((4, 4), name, fill=(0, 0, 0))
        images.append(im)
    return images


def write_sheet(path, model, labels):
    from PIL import Image
    rgb = (np.clip(model.face_rgb, 0, 1) * 255).astype(np.uint8)
    lab = np.array([PALETTE[CLASSES[i]] for i in labels], dtype=np.uint8)
    views = ortho_views(model, rgb) + ortho_views(model, lab)
    sheet = Image.new("RGB", (3 * 300, 2 * 300), "white")
    for i, im in enumerate(views):
        sheet.paste(im, ((i % 3) * 300, (i // 3) * 300))
    sheet.save(path)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--only", nargs="*", help="model ids (default: all)")
    ap.add_argument("--sheet", help="folder for orthographic check sheets (base colour above, labels below)")
    args = ap.parse_args()
    manifest = {m["id"]: m for m in json.load(open(os.path.join(SET, "manifest.json")))["models"]}
    annotations = json.load(open(os.path.join(SET, "annotations.json")))["models"]
    os.makedirs(os.path.join(SET, "labels"), exist_ok=True)
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
        if args.sheet:
            os.makedirs(args.sheet, exist_ok=True)
            write_sheet(os.path.join(args.sheet, annotation["id"] + ".png"), model, labels)


if __name__ == "__main__":
    main()
