#!/usr/bin/python3
"""Bulk density (mass over closed volume) of everyday objects, measured on a scored set (#65).

    /usr/bin/python3 scripts/mass_set/bulk_density.py --set val --out OUT

OUT is a folder of `scripts/mass_set/score.py --set val --out OUT` (one folder per model, in the
set's order, NNN_name). For every scored model whose parts have a volume, the bulk
density is the geometric centre of its annotated mass range over the sum of its parts' closed
volumes (run.json's parts[].volume_m3, every part the complete stage closed, whether or not its
checks passed: the volumes the properties stage weighs): what a real object of that shape weighs
per cubic metre of its closed outline. Prints the count, the geometric mean, the spread (standard deviation of the
natural log) and the 5, 50 and 95 % quantiles: the prior the kind's mass posterior uses when the
kind is unknown (PosteriorOptions::bulk_density_kg_m3, bulk_density_log_sd).
"""
import argparse
import json
import math
import os
import statistics

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--set", choices=["val", "test"], default="val")
    ap.add_argument("--out", required=True)
    a = ap.parse_args()
    with open(os.path.join(ROOT, "data", "mass-ranges", a.set + ".json")) as f:
        models = json.load(f)["models"]
    folders = {d.split("_", 1)[1]: os.path.join(a.out, d) for d in os.listdir(a.out) if "_" in d}
    logs = []
    for key, m in models.items():
        if not m.get("score", True):
            continue
        name = os.path.splitext(os.path.basename(key))[0]
        run = os.path.join(folders.get(name, ""), "run.json")
        if not os.path.isfile(run):
            continue
        with open(run) as f:
            parts = json.load(f).get("parts", [])
        volume = sum(p.get("volume_m3") or 0.0 for p in parts)
        if volume <= 0:
            continue
        lo, hi = m["mass_kg"]
        logs.append(math.log(math.sqrt(lo * hi) / volume))
    logs.sort()
    q = lambda p: math.exp(logs[min(len(logs) - 1, int(p * len(logs)))])
    print(json.dumps({"models": len(logs), "geometric_mean_kg_m3": math.exp(statistics.fmean(logs)),
                      "log_sd": statistics.pstdev(logs), "p05": q(0.05), "median": q(0.5), "p95": q(0.95)},
                     indent=1))


if __name__ == "__main__":
    main()
