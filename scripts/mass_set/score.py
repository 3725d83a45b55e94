#!/usr/bin/python3
"""Score object mass from `g2p run` on the sweethome3d validation or held-out models (#31).

    /usr/bin/python3 scripts/mass_set/score.py --set val|test --out OUT [--g2p BIN] [--jobs N]
        [--only KEY ...] [--reuse] [--json FILE] [-- EXTRA g2p run FLAGS]
    /usr/bin/python3 scripts/mass_set/score.py --compare A.json B.json

Runs `g2p run data/sh3d/KEY -o OUT/<n> --longest-side L --format mjcf --decomposer hull` for every model of
data/mass-ranges/<set>.json whose `score` is true (L is the catalogue's longest side), with the
EXTRA flags (`--segmenter`, `--refiner`, `--anonymize-names`, `--base-color-only`, ...), and
reads report.json's object mass. It prints per model and overall:
  - in range: the share of objects whose mass lies inside the annotated range;
  - MnRE: min(p/c, c/p) against the range's geometric centre c = sqrt(lo * hi), in the mean
    (1 is perfect; the paper's Table 1 reports it on ABO-500);
  - the median ratio p/c, and how many are too heavy or too light.
A model whose run fails counts as out of range with MnRE 0 and is listed.

--compare pairs two result files model by model and gives the difference B - A in the share in
range and in mean MnRE with a 95 % bootstrap interval (2000 resamples of the models, seed 1), as
`g2p eval compare` does for segmentation.
"""
import argparse
import concurrent.futures
import json
import math
import os
import random
import shutil
import subprocess
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
RANGES = os.path.join(ROOT, "data", "mass-ranges")
ASSETS = os.path.join(ROOT, "data", "sh3d")


def load_set(name):
    path = os.path.join(RANGES, name + ".json")
    models = json.load(open(path))["models"]
    return {k: v for k, v in sorted(models.items()) if v.get("score", True)}


def run_model(g2p, key, entry, out, extra):
    model = os.path.join(ASSETS, key)
    if not os.path.isfile(model):
        raise FileNotFoundError(f"{model}: not found (the sweethome3d libraries go in data/sh3d, docs/training.md)")
    # One format and one hull per part: collision geometry does not change the mass.
    cmd = [g2p, "run", model, "-o", out, "--overwrite", "--quiet", "--format", "mjcf", "--decomposer", "hull",
           "--longest-side", str(entry["longest_side_m"])] + extra
    # A failed run leaves an earlier run's folder in place (--overwrite replaces it only on
    # success): remove it first, so that no old report is scored.
    shutil.rmtree(out, ignore_errors=True)
    start = time.time()
    done = subprocess.run(cmd, capture_output=True, text=True)
    return cmd, done, time.time() - start


def score_model(key, entry, out, failed=False):
    lo, hi = entry["mass_kg"]
    centre = math.sqrt(lo * hi)
    r = {"key": key, "name": entry["name"], "mass_range_kg": [lo, hi], "centre_kg": centre}
    report_path = os.path.join(out, "report.json")
    if failed or not os.path.isfile(report_path):
        r.update({"failed": True, "mass_kg": None, "mass_in_range": False, "ratio": None, "mnre": 0.0})
        return r
    report = json.load(open(report_path))
    mass = float(report["object"]["mass_kg"])
    classes = {}
    for part in report.get("parts", []):
        name = part.get("material", "?")
        classes[name] = classes.get(name, 0.0) + float(part.get("mass_kg", 0.0))
    r.update({"failed": False, "mass_kg": mass, "mass_in_range": lo <= mass <= hi, "ratio": mass / centre,
              "mnre": min(mass / centre, centre / mass) if mass > 0 else 0.0, "mass_by_class_kg": classes})
    return r


def summarise(results):
    n = len(results)
    ratios = sorted(r["ratio"] for r in results if r["ratio"] is not None)
    return {"models": n,
            "mass_in_range": sum(1 for r in results if r["mass_in_range"]),
            "share_in_range": sum(1 for r in results if r["mass_in_range"]) / n if n else 0.0,
            "mean_mnre": sum(r["mnre"] for r in results) / n if n else 0.0,
            "median_ratio": ratios[len(ratios) // 2] if ratios else None,
            "too_heavy": sum(1 for r in results if r["mass_kg"] is not None and r["mass_kg"] > r["mass_range_kg"][1]),
            "too_light": sum(1 for r in results if r["mass_kg"] is not None and r["mass_kg"] < r["mass_range_kg"][0]),
            "failed": [r["key"] for r in results if r["failed"]]}


def compare(path_a, path_b):
    a = {r["key"]: r for r in json.load(open(path_a))["models"]}
    b = {r["key"]: r for r in json.load(open(path_b))["models"]}
    keys = sorted(set(a) & set(b))
    if not keys:
        sys.exit(f"score.py: error: {path_a} and {path_b} share no model")
    d_in = [float(b[k]["mass_in_range"]) - float(a[k]["mass_in_range"]) for k in keys]
    d_mn = [b[k]["mnre"] - a[k]["mnre"] for k in keys]
    rng = random.Random(1)
    boot_in, boot_mn = [], []
    for _ in range(2000):
        idx = [rng.randrange(len(keys)) for _ in keys]
        boot_in.append(sum(d_in[i] for i in idx) / len(idx))
        boot_mn.append(sum(d_mn[i] for i in idx) / len(idx))
    boot_in.sort()
    boot_mn.sort()
    lo, hi = int(0.025 * len(boot_in)), int(0.975 * len(boot_in)) - 1
    mean_in, mean_mn = sum(d_in) / len(keys), sum(d_mn) / len(keys)
    print(f"{len(keys)} models paired ({path_a} -> {path_b})")
    print(f"share in range: {100 * mean_in:+.1f} points (95 %: {100 * boot_in[lo]:+.1f} to {100 * boot_in[hi]:+.1f}); "
          f"{sum(1 for x in d_in if x > 0)} models enter the range, {sum(1 for x in d_in if x < 0)} leave it")
    print(f"mean MnRE: {mean_mn:+.3f} (95 %: {boot_mn[lo]:+.3f} to {boot_mn[hi]:+.3f})")


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--set", choices=["val", "test"], help="data/mass-ranges/<set>.json")
    ap.add_argument("--out", help="folder for the g2p run outputs")
    ap.add_argument("--g2p", default=os.environ.get("G2P", "g2p"), help="the g2p binary")
    ap.add_argument("--jobs", type=int, default=1, help="g2p runs at once")
    ap.add_argument("--only", nargs="*", help="model keys (default: all scored)")
    ap.add_argument("--json", help="write the results here")
    ap.add_argument("--reuse", action="store_true", help="score existing outputs without running g2p")
    ap.add_argument("--compare", nargs=2, metavar=("A.json", "B.json"), help="paired difference B - A")
    ap.add_argument("extra", nargs="*", help="further g2p run flags, after --")
    args = ap.parse_args()
    if args.compare:
        compare(*args.compare)
        return
    if not args.set or not args.out:
        ap.error("--set and --out are required (or --compare A.json B.json)")
    models = load_set(args.set)
    if args.only:
        unknown = [k for k in args.only if k not in models]
        if unknown:
            ap.error(f"--only: not a scored model of {args.set}.json: {', '.join(unknown)}")
        models = {k: models[k] for k in args.only}
    keys = list(models)
    # Folders numbered by place in the whole scored set, so that --reuse --only finds them.
    place = {k: i for i, k in enumerate(load_set(args.set))}
    outs = {k: os.path.join(args.out, f"{place[k]:03d}_" + os.path.basename(os.path.dirname(k))) for k in keys}
    commands, seconds, errors = {}, {}, {}
    if not args.reuse:
        os.makedirs(args.out, exist_ok=True)
        with concurrent.futures.ThreadPoolExecutor(max_workers=max(1, args.jobs)) as pool:
            futures = {pool.submit(run_model, args.g2p, k, models[k], outs[k], args.extra): k for k in keys}
            for f in concurrent.futures.as_completed(futures):
                k = futures[f]
                cmd, done, secs = f.result()
                commands[k], seconds[k] = " ".join(cmd), secs
                if done.returncode != 0:
                    errors[k] = done.stderr.strip()[-500:]
                    print(f"{k}: g2p run failed ({done.returncode}): {errors[k]}", file=sys.stderr)
    results = []
    print("| model | mass kg | range kg | in range | p / c | s |")
    print("|---|---:|---|---|---:|---:|")
    for k in keys:
        r = score_model(k, models[k], outs[k], failed=k in errors)
        r["seconds"] = seconds.get(k, 0.0)
        if k in errors:
            r["error"] = errors[k]
        results.append(r)
        mass = "failed" if r["failed"] else f"{r['mass_kg']:.3g}"
        ratio = "" if r["ratio"] is None else f"{r['ratio']:.2f}"
        print(f"| {r['name']} (`{os.path.basename(k)}`) | {mass} | {r['mass_range_kg'][0]:g}-{r['mass_range_kg'][1]:g} "
              f"| {'yes' if r['mass_in_range'] else 'no'} | {ratio} | {r['seconds']:.0f} |")
    s = summarise(results)
    median = "none" if s["median_ratio"] is None else f"{s['median_ratio']:.2f}"
    print(f"\n{s['models']} models: mass in range {s['mass_in_range']} ({100 * s['share_in_range']:.1f} %), "
          f"mean MnRE {s['mean_mnre']:.3f}, median p/c {median}, too heavy {s['too_heavy']}, "
          f"too light {s['too_light']}, failed {len(s['failed'])}")
    if args.json:
        with open(args.json, "w") as f:
            json.dump({"set": args.set, "flags": args.extra, "commands": commands, "summary": s, "models": results},
                      f, indent=1)
            f.write("\n")


if __name__ == "__main__":
    main()
