#!/usr/bin/python3
"""Score identification, size and mass of `g2p run` on the generated test set (#48).

    /usr/bin/python3 scripts/generated_set/score_identify.py --out OUT [--g2p BIN] [--only ID ...]
        [--json FILE] [--conditions nosize,size | --identify-only] [-- EXTRA g2p run FLAGS]

Each model of data/generated/manifest.json (read from ../shared/generated; missing ones are listed
and left out) is copied under the file name its generator wrote
(the manifest's source path: sample.glb, mesh.glb, pot.glb), so that the names the identifier sees
are the generator's, not this set's ids. Then `g2p run` runs twice per model:
  - nosize: the file as it is (a normalised mesh may take its identified kind's size);
  - size:   with the annotated real size (--height or --longest-side).
With --identify-only, `g2p identify --json` runs instead, once per condition (nosize unless
--conditions says otherwise; identification only, no mass; the EXTRA flags are g2p identify's).
From each run.json it reads the identification and the mass, and prints per model and overall:
  - identification top-1 and top-3: the identified kind (and the first three candidates) against
    data/generated/objects.json's kind and its acceptable alternatives, over the models whose kind
    the object table holds (a kind name, or a term of one);
  - mass in range: run.json's object.mass_kg inside the annotated range, per condition;
  - size assumed: how often the nosize run took a kind's size, and how far its longest side is
    from the real one (ratio).
"""
import argparse
import json
import os
import shutil
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
SET = os.path.join(ROOT, "data", "generated")


def model_file(entry):
    """The model in ../shared/generated, named by the basename of the manifest's file; None if absent."""
    path = os.path.join(os.path.dirname(ROOT), "shared", "generated", os.path.basename(entry["file"]))
    return path if os.path.isfile(path) else None


def table_kinds():
    with open(os.path.join(ROOT, "libg2p", "data", "objects.json")) as f:
        table = json.load(f)
    names = {k["name"] for k in table["kinds"]}
    term_kind = {}
    for k in table["kinds"]:
        for t in k["terms"]:
            term_kind.setdefault(t, k["name"])
        term_kind[k["name"]] = k["name"]
    return names, term_kind


def accepted(annotation, names):
    """The table kinds that count as right for a model: its kind and alternatives that are kinds' names (a word
    that is only a term of some kind is not enough: WordNet's "still" is also a person's)."""
    words = [annotation["kind"]] + annotation.get("kind_alternatives", [])
    return {w for w in words if w in names}


def size_flags(size):
    """--height or --longest-side with the annotated real size; none without one."""
    if not size:
        return []
    key, value = next(iter(size.items()))
    return ["--height" if key == "height_m" else "--longest-side", str(value)]


def identify(g2p, path, size, extra):
    """`g2p identify --json` alone (--identify-only): the identification, no mass."""
    done = subprocess.run([g2p, "identify", path, "--json"] + size_flags(size) + extra, capture_output=True,
                          text=True)
    if done.returncode != 0:
        return None, done.stderr.strip().splitlines()[-1:] if done.stderr else ["exit %d" % done.returncode]
    return {"identification": json.loads(done.stdout), "object": {"mass_kg": float("nan")}}, []


def run(g2p, path, out, size, extra):
    cmd = [g2p, "run", path, "-o", out, "--overwrite", "-q"] + size_flags(size) + extra
    done = subprocess.run(cmd, capture_output=True, text=True)
    if done.returncode != 0:
        return None, done.stderr.strip().splitlines()[-1:] if done.stderr else ["exit %d" % done.returncode]
    with open(os.path.join(out, "run.json")) as f:
        return json.load(f), []


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--out", required=True)
    ap.add_argument("--g2p", default=os.path.join(ROOT, "build", "bin", "g2p"))
    ap.add_argument("--only", nargs="*")
    ap.add_argument("--json")
    ap.add_argument("--conditions", default=None, help="nosize,size (default; --identify-only: nosize)")
    ap.add_argument("--identify-only", action="store_true",
                    help="run `g2p identify --json` per condition (top-1 and top-3 only, no mass)")
    ap.add_argument("extra", nargs="*")
    a = ap.parse_args(argv)
    conditions = (a.conditions or ("nosize" if a.identify_only else "nosize,size")).split(",")
    with open(os.path.join(SET, "manifest.json")) as f:
        manifest = json.load(f)["models"]
    with open(os.path.join(SET, "objects.json")) as f:
        annotations = json.load(f)["models"]
    names, _ = table_kinds()
    rows, missing = [], []
    for entry in manifest:
        mid = entry["id"]
        if a.only and mid not in a.only:
            continue
        path = model_file(entry)
        if path is None or mid not in annotations:
            missing.append(mid)
            continue
        ann = annotations[mid]
        # The generator's own file name (the manifest's source path), in a folder of its own.
        named = os.path.join(a.out, "inputs", mid, os.path.basename(entry["source"]["path"]))
        os.makedirs(os.path.dirname(named), exist_ok=True)
        shutil.copyfile(path, named)
        right = accepted(ann, names)
        row = {"id": mid, "generator": entry["generator"], "kind": ann["kind"], "in_table": bool(right),
               "range": ann["mass_kg"], "file": os.path.basename(named)}
        for cond in conditions:
            if a.identify_only:
                result, err = identify(a.g2p, named, ann["real_size"] if cond == "size" else None, a.extra)
            else:
                result, err = run(a.g2p, named, os.path.join(a.out, cond, mid),
                                  ann["real_size"] if cond == "size" else None, a.extra)
            if result is None:
                row[cond] = {"error": " ".join(err)}
                continue
            ident = result.get("identification") or {}
            mass = result["object"]["mass_kg"]
            lo, hi = ann["mass_kg"]
            cands = [c["kind"] for c in ident.get("candidates", [])][:3]
            row[cond] = {"kind": ident.get("kind", "unknown"), "confidence": ident.get("confidence", 0.0),
                         "source": ident.get("source", ""), "top3": cands,
                         "size_assumed_m": ident.get("size_assumed_m"), "mass_kg": mass,
                         "in_range": lo <= mass <= hi}
        first = row.get(conditions[0], {})
        row["top1"] = first.get("kind") in right
        row["top3"] = bool(right & set(first.get("top3", [])))
        rows.append(row)
        print("%-24s %-10s %-16s -> %s" % (mid, entry["generator"][:10], ann["kind"][:16], "  ".join(
            "%s: %s %.0f%% %.3g kg %s" % (c, row[c].get("kind", "ERR"), 100 * row[c].get("confidence", 0),
                                          row[c].get("mass_kg", float("nan")),
                                          "in" if row[c].get("in_range") else "out")
            for c in conditions if c in row)), flush=True)
    scored = [r for r in rows if r["in_table"]]
    summary = {"models": len(rows), "kind_in_table": len(scored), "missing": missing,
               "top1": sum(r["top1"] for r in scored), "top3": sum(r["top3"] for r in scored)}
    for cond in conditions:
        ok = [r for r in rows if "error" not in r.get(cond, {"error": 1})]
        summary[cond] = {"runs": len(ok), "mass_in_range": sum(r[cond]["in_range"] for r in ok),
                         "size_assumed": sum(1 for r in ok if r[cond].get("size_assumed_m"))}
    print(json.dumps(summary, indent=1))
    if a.json:
        with open(a.json, "w") as f:
            json.dump({"summary": summary, "rows": rows}, f, indent=1)


if __name__ == "__main__":
    sys.exit(main())
