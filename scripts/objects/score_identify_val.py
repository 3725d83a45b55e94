#!/usr/bin/python3
"""Identification on the sweethome3d validation models, names removed: for choosing (#48).

    /usr/bin/python3 scripts/objects/score_identify_val.py [--g2p BIN] [--json FILE] [-- EXTRA g2p identify FLAGS]

The 58 validation models of data/mass-ranges/val.json (data/sh3d, unpacked from Debian's
sweethome3d-furniture as docs/training.md says). The truth is the kind the catalogue's name
names in the object table (ObjectTable::match, through `g2p identify --object NAME --json`), or
the hand-read kind of TRUTH below where the catalogue's words mislead the matcher; models whose
name names no kind are listed and left out. Each model runs `g2p identify MODEL --anonymize-names
--json` (no file, node or material names: what the views alone say) with the EXTRA flags, and
the script prints top-1 and top-3 (the first three candidates) over the models with a truth.
This set is for choosing; the generated set (scripts/generated_set/score_identify.py) and the
held-out libraries are for judging.
"""
import argparse
import json
import os
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))

# Catalogue names whose words the matcher reads as another kind, read by a person.
TRUTH = {
    "Knife stand": "",  # a block that holds knives: no kind
    "Wall type B plug": "",  # a wall socket: no kind ("plug" is WordNet's fire plug)
    "Square type B plug": "",
    "Double window 4 panes": "window",
    "Indoor bike": "exercise bike",
    "Rigged fan": "fan",
    "Yamaha YZR R6": "motorcycle",
    "Toilets unit": "toilet",
    "Small oven": "oven",
}


def identify(g2p, args):
    done = subprocess.run([g2p, "identify"] + args + ["--json"], capture_output=True, text=True)
    if done.returncode != 0:
        return None, (done.stderr.strip().splitlines() or ["exit %d" % done.returncode])[-1]
    return json.loads(done.stdout), ""


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--g2p", default=os.path.join(ROOT, "build", "bin", "g2p"))
    ap.add_argument("--json")
    ap.add_argument("extra", nargs="*")
    a = ap.parse_args(argv)
    with open(os.path.join(ROOT, "data", "mass-ranges", "val.json")) as f:
        models = json.load(f)["models"]
    rows, no_kind = [], []
    for key, m in sorted(models.items()):
        path = os.path.join(ROOT, "data", "sh3d", key)
        truth = TRUTH.get(m["name"])
        if truth is None:  # "" in TRUTH: no kind
            named, _ = identify(a.g2p, [path, "--object", m["name"], "--identifier", "object"])
            truth = named["kind"] if named else None
        if not truth or truth == "unknown":
            no_kind.append(m["name"])
            continue
        got, err = identify(a.g2p, [path, "--anonymize-names"] + a.extra)
        cands = [c["kind"] for c in got["candidates"]][:3] if got else []
        kind = got["kind"] if got else "error: " + err
        rows.append({"key": key, "name": m["name"], "truth": truth, "kind": kind,
                     "confidence": got["confidence"] if got else 0.0, "top3": cands,
                     "top1_ok": kind == truth, "top3_ok": truth in cands})
        print("%-28s %-18s -> %-18s %3.0f%%  %s" % (m["name"][:28], truth[:18], kind[:18],
                                                  100 * rows[-1]["confidence"], "ok" if kind == truth else ""),
              flush=True)
    n = len(rows)
    summary = {"models": n, "no_kind": no_kind, "top1": sum(r["top1_ok"] for r in rows),
               "top3": sum(r["top3_ok"] for r in rows),
               "known": sum(r["kind"] != "unknown" for r in rows),
               "wrong_confident": sum(1 for r in rows if not r["top1_ok"] and r["confidence"] >= 0.6)}
    print(json.dumps(summary, indent=1))
    if a.json:
        with open(a.json, "w") as f:
            json.dump({"summary": summary, "rows": rows}, f, indent=1)


if __name__ == "__main__":
    sys.exit(main())
