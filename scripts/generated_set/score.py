#!/usr/bin/python3
"""Score `g2p run` on the generated test set (#31) against its committed annotations.

    /usr/bin/python3 scripts/generated_set/score.py --out OUT [--segmenter NAME] [--no-size]
        [--g2p BIN] [--only ID ...] [--json FILE] [-- EXTRA g2p run FLAGS]

Runs `g2p run MODEL -o OUT/<id>` per model (with the annotated real size as --height or
--longest-side unless --no-size), reads OUT/<id>/faces.csv and report.json, and prints per model
and overall:
  - accuracy: share of annotated faces (not `ignore`) whose predicted class equals the
    annotation, unweighted and weighted by face area;
  - classes: the classes predicted on at least 1 % of the model's area, against the classes
    annotated (the target of #31: more than one predicted wherever more than one is annotated);
  - mass: report.json's object.mass_kg against the annotated range: in range or not, and the
    ratio to the range's centre (MnRE = min(p/c, c/p) in the mean).
Faces are matched by faces.csv's `source_face`; the script checks that its face areas agree
with the GLB's (after the size scale) before scoring.
"""
import argparse
import csv
import json
import os
import subprocess
import sys
import time

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import annotate  # noqa: E402
import glb  # noqa: E402

MIN_SHARE = 0.01  # a predicted class counts when it covers at least this share of the area


def run_model(g2p, entry, annotation, out, segmenter, use_size, extra):
    cmd = [g2p, "run", annotate.model_path(entry), "-o", out]
    if segmenter:
        cmd += ["--segmenter", segmenter]
    if use_size:
        size = annotation["size"]
        if "height_m" in size:
            cmd += ["--height", str(size["height_m"])]
        else:
            cmd += ["--longest-side", str(size["longest_side_m"])]
    cmd += extra
    start = time.time()
    done = subprocess.run(cmd, capture_output=True, text=True)
    if done.returncode != 0:
        raise RuntimeError(f"{entry['id']}: g2p run failed ({done.returncode}): {done.stderr[-2000:]}")
    return cmd, time.time() - start


def score_model(entry, annotation, out):
    model = glb.Model(annotate.model_path(entry))
    truth = np.array(annotate.load_labels(annotation["id"]))
    rows = list(csv.DictReader(open(os.path.join(out, "faces.csv"))))
    if len(rows) != len(truth):
        raise RuntimeError(f"{entry['id']}: faces.csv has {len(rows)} faces, the GLB {len(truth)}")
    order = np.array([int(r["source_face"]) for r in rows])
    pred = np.empty(len(truth), dtype=object)
    area = np.empty(len(truth))
    pred[order] = [r["label"] for r in rows]
    area[order] = [float(r["area_m2"]) for r in rows]
    # faces.csv's areas are after the size scale: compare shapes, not values
    mine = model.face_areas()
    if np.corrcoef(mine, area)[0, 1] < 0.999:
        raise RuntimeError(f"{entry['id']}: faces.csv's face order does not match the GLB's")
    keep = truth != "ignore"
    hit = pred[keep] == truth[keep]
    acc = float(hit.mean())
    acc_area = float(area[keep][hit].sum() / area[keep].sum())
    share = {c: float(area[pred == c].sum() / area.sum()) for c in sorted(set(pred))}
    predicted = sorted(c for c, s in share.items() if s >= MIN_SHARE)
    annotated = sorted(set(truth[keep]))
    report = json.load(open(os.path.join(out, "report.json")))
    mass = float(report["object"]["mass_kg"])
    lo, hi = annotation["mass_kg"]
    centre = (lo + hi) / 2
    return {"id": entry["id"], "faces": int(len(truth)), "annotated_faces": int(keep.sum()),
            "accuracy": acc, "accuracy_area": acc_area, "predicted_share": share,
            "predicted_classes": predicted, "annotated_classes": annotated,
            "multi_class_ok": (len(predicted) > 1) if len(annotated) > 1 else None,
            "mass_kg": mass, "mass_range_kg": [lo, hi], "mass_in_range": lo <= mass <= hi,
            "mass_ratio_to_centre": mass / centre, "mnre": min(mass / centre, centre / mass),
            "size": report["object"].get("size", {})}


def summarise(results):
    n = len(results)
    multi = [r for r in results if r["multi_class_ok"] is not None]
    return {"models": n,
            "mean_accuracy": float(np.mean([r["accuracy"] for r in results])),
            "mean_accuracy_area": float(np.mean([r["accuracy_area"] for r in results])),
            "pooled_accuracy": float(sum(r["accuracy"] * r["annotated_faces"] for r in results)
                                     / sum(r["annotated_faces"] for r in results)),
            "multi_class_models": len(multi),
            "multi_class_ok": sum(1 for r in multi if r["multi_class_ok"]),
            "single_class_predictions": sum(1 for r in results if len(r["predicted_classes"]) == 1),
            "mass_in_range": sum(1 for r in results if r["mass_in_range"]),
            "mean_mnre": float(np.mean([r["mnre"] for r in results]))}


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", required=True, help="folder for the g2p run outputs")
    ap.add_argument("--segmenter", help="passed to g2p run --segmenter (default: g2p's default)")
    ap.add_argument("--no-size", action="store_true", help="do not give the annotated real size")
    ap.add_argument("--g2p", default=os.environ.get("G2P", "g2p"), help="the g2p binary")
    ap.add_argument("--only", nargs="*", help="model ids (default: all)")
    ap.add_argument("--json", help="write the results here")
    ap.add_argument("--reuse", action="store_true", help="score existing outputs without running g2p")
    ap.add_argument("extra", nargs="*", help="further g2p run flags, after --")
    args = ap.parse_args()
    manifest = {m["id"]: m for m in json.load(open(os.path.join(annotate.SET, "manifest.json")))["models"]}
    annotations = json.load(open(os.path.join(annotate.SET, "annotations.json")))["models"]
    results, commands = [], []
    print("| model | faces | accuracy % (faces) | accuracy % (area) | predicted classes | annotated | mass kg | range kg | in range | ratio to centre | s |")
    print("|---|---:|---:|---:|---|---|---:|---|---|---:|---:|")
    for annotation in annotations:
        if args.only and annotation["id"] not in args.only:
            continue
        entry = manifest[annotation["id"]]
        out = os.path.join(args.out, annotation["id"])
        seconds = 0.0
        if not args.reuse:
            cmd, seconds = run_model(args.g2p, entry, annotation, out, args.segmenter,
                                     not args.no_size, args.extra)
            commands.append(" ".join(cmd))
        r = score_model(entry, annotation, out)
        r["seconds"] = seconds
        results.append(r)
        print(f"| `{r['id']}` | {r['faces']} | {100 * r['accuracy']:.1f} | {100 * r['accuracy_area']:.1f} "
              f"| {', '.join(r['predicted_classes'])} | {', '.join(r['annotated_classes'])} "
              f"| {r['mass_kg']:.3g} | {r['mass_range_kg'][0]}-{r['mass_range_kg'][1]} "
              f"| {'yes' if r['mass_in_range'] else 'no'} | {r['mass_ratio_to_centre']:.2f} | {seconds:.0f} |",
              flush=True)
    s = summarise(results)
    print(f"\nmean accuracy {100 * s['mean_accuracy']:.1f} % of faces, {100 * s['mean_accuracy_area']:.1f} % "
          f"of area (pooled over faces {100 * s['pooled_accuracy']:.1f} %); more than one class on "
          f"{s['multi_class_ok']} of {s['multi_class_models']} models annotated with several; one class "
          f"predicted on {s['single_class_predictions']} of {s['models']}; mass in range "
          f"{s['mass_in_range']} of {s['models']}, mean MnRE to the range centre {s['mean_mnre']:.2f}")
    if args.json:
        with open(args.json, "w") as f:
            json.dump({"segmenter": args.segmenter or "default", "size_given": not args.no_size,
                       "commands": commands, "summary": s, "models": results}, f, indent=1)
            f.write("\n")


if __name__ == "__main__":
    main()
