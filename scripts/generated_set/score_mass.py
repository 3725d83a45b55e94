#!/usr/bin/python3
"""Score the mass of `g2p run` on the generated set when told the kind, the size, or both (#65).

    /usr/bin/python3 scripts/generated_set/score_mass.py --out OUT [--g2p BIN] [--jobs 2] [--only ID ...]
        [--conditions kind_size,kind,size] [--json FILE] [--reuse] [-- EXTRA g2p run FLAGS]

Each model of data/generated/manifest.json is read from ../shared/generated/ID.glb (a model whose
file is absent is listed and left out) and copied under the file name its generator wrote, so that
the names the identifier sees are the generator's. Conditions:
  - kind_size: --object KIND and the annotated real size (--height or --longest-side);
  - kind:      --object KIND, the file's own size;
  - size:      the real size, the kind from the views.
KIND is the annotated kind, or the first of its alternatives that names a kind of the object table;
a model with neither runs without --object. From each report.json it reads the object's mass and
the kind's median and 90 % interval, and prints, per condition, how many masses lie in the
annotated range (data/generated/objects.json) and how often the interval covers the range's
geometric midpoint. --reuse scores the outputs already in OUT without running g2p.
"""
import argparse
import json
import math
import os
import shutil
import subprocess
import sys
from concurrent.futures import ThreadPoolExecutor

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
SET = os.path.join(ROOT, "data", "generated")
SHARED = os.path.join(os.path.dirname(ROOT), "shared", "generated")


def table_names():
    with open(os.path.join(ROOT, "libg2p", "data", "objects.json")) as f:
        return {k["name"] for k in json.load(f)["kinds"]}


def run(g2p, path, out, kind, size, extra, reuse=False):
    if reuse:
        return read(out)
    cmd = [g2p, "run", path, "-o", out, "--overwrite", "-q"]
    if kind:
        cmd += ["--object", kind]
    if size:
        key, value = next(iter(size.items()))
        cmd += ["--height" if key == "height_m" else "--longest-side", str(value)]
    done = subprocess.run(cmd + extra, capture_output=True, text=True)
    if done.returncode != 0:
        return {"error": (done.stderr.strip().splitlines() or ["exit %d" % done.returncode])[-1]}
    return read(out)


def read(out):
    if not os.path.isfile(os.path.join(out, "report.json")):
        return {"error": "no report.json in " + out}
    with open(os.path.join(out, "report.json")) as f:
        report = json.load(f)
    with open(os.path.join(out, "run.json")) as f:
        ident = json.load(f).get("identification") or {}
    obj = report["object"]
    interval = obj.get("mass_interval_kg") or {}
    return {"mass_kg": obj["mass_kg"], "interval": [interval.get("p05"), interval.get("median"), interval.get("p95")],
            "kind": ident.get("kind", "unknown"), "confidence": ident.get("confidence", 0.0)}


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--out", required=True)
    ap.add_argument("--g2p", default=os.path.join(ROOT, "build", "bin", "g2p"))
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--only", nargs="*")
    ap.add_argument("--json")
    ap.add_argument("--reuse", action="store_true")
    ap.add_argument("--conditions", default="kind_size,kind,size")
    ap.add_argument("extra", nargs="*")
    a = ap.parse_args(argv)
    conditions = a.conditions.split(",")
    with open(os.path.join(SET, "manifest.json")) as f:
        manifest = json.load(f)["models"]
    with open(os.path.join(SET, "objects.json")) as f:
        annotations = json.load(f)["models"]
    names = table_names()
    jobs, rows, missing = [], {}, []
    for entry in manifest:
        mid = entry["id"]
        if a.only and mid not in a.only:
            continue
        path = os.path.join(SHARED, mid + ".glb")
        if not os.path.isfile(path) or mid not in annotations:
            missing.append(mid)
            continue
        ann = annotations[mid]
        named = os.path.join(a.out, "inputs", mid, os.path.basename(entry["source"]["path"]))
        os.makedirs(os.path.dirname(named), exist_ok=True)
        shutil.copyfile(path, named)
        kind = next((w for w in [ann["kind"]] + ann.get("kind_alternatives", []) if w in names), None)
        rows[mid] = {"id": mid, "annotated": ann["kind"], "told": kind, "range": ann["mass_kg"], "runs": {}}
        for cond in conditions:
            jobs.append((mid, cond, named, kind if cond.startswith("kind") else None,
                         ann["real_size"] if cond in ("kind_size", "size") else None))
    with ThreadPoolExecutor(max_workers=max(1, a.jobs)) as pool:
        results = pool.map(lambda j: (j[0], j[1], run(a.g2p, j[2], os.path.join(a.out, j[1], j[0]), j[3], j[4],
                                                      a.extra, a.reuse)), jobs)
        for mid, cond, res in results:
            lo, hi = rows[mid]["range"]
            if "mass_kg" in res:
                res["in_range"] = lo <= res["mass_kg"] <= hi
                p05, _, p95 = res["interval"]
                mid_kg = math.sqrt(lo * hi)
                res["covers"] = p05 is not None and p05 <= mid_kg <= p95
            rows[mid]["runs"][cond] = res
    summary = {"models": len(rows), "missing": missing}
    for cond in conditions:
        ok = [r["runs"][cond] for r in rows.values() if "mass_kg" in r["runs"].get(cond, {})]
        judged = [x for x in ok if x["interval"][0] is not None]
        summary[cond] = {"runs": len(ok), "mass_in_range": sum(x["in_range"] for x in ok),
                         "intervals": len(judged), "interval_covers_midpoint": sum(x["covers"] for x in judged)}
    for r in rows.values():
        runs = r["runs"]
        print("%-26s %-16s %-10s %s" % (r["id"], r["annotated"][:16], "%g-%g" % tuple(r["range"]), "  ".join(
            "%s: %s" % (c, ("%.3g kg %s" % (runs[c]["mass_kg"], "in" if runs[c]["in_range"] else "out"))
                        if "mass_kg" in runs.get(c, {}) else "ERR " + runs.get(c, {}).get("error", "?"))
            for c in conditions)))
    print(json.dumps(summary, indent=1))
    if a.json:
        with open(a.json, "w") as f:
            json.dump({"summary": summary, "rows": list(rows.values())}, f, indent=1)


if __name__ == "__main__":
    sys.exit(main())
