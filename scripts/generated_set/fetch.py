#!/usr/bin/python3
"""Fetch the models of the generated test set that are not committed (#31).

    /usr/bin/python3 scripts/generated_set/fetch.py [--mirror DIR]

Downloads every manifest entry with "committed": false from its pinned commit on GitHub
(raw.githubusercontent.com) into data/generated/external/, or, with --mirror, reads it from
local bare clones named DIR/<owner>+<name>/repo (`git show COMMIT:PATH`). Every file is checked
against the manifest's sha256; a mismatch is an error. Files already present and matching are
kept. These files are not redistributed with libg2p because their repositories state no licence
that allows it (see data/generated/README.md).
"""
import argparse
import hashlib
import json
import os
import subprocess
import sys
import urllib.request

SET = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", "..", "data", "generated"))


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--mirror", help="folder of bare clones <owner>+<name>/repo")
    args = ap.parse_args()
    manifest = json.load(open(os.path.join(SET, "manifest.json")))
    failed = 0
    for m in manifest["models"]:
        if m["committed"]:
            continue
        dest = os.path.join(SET, m["file"])
        if os.path.exists(dest) and hashlib.sha256(open(dest, "rb").read()).hexdigest() == m["sha256"]:
            print(f"{m['id']}: present")
            continue
        src = m["source"]
        if args.mirror:
            git_dir = os.path.join(args.mirror, src["repo"].replace("/", "+"), "repo")
            data = subprocess.run(["git", "--git-dir", git_dir, "show", f"{src['commit']}:{src['path']}"],
                                  check=True, capture_output=True).stdout
        else:
            with urllib.request.urlopen(src["raw"], timeout=120) as r:
                data = r.read()
        digest = hashlib.sha256(data).hexdigest()
        if digest != m["sha256"]:
            print(f"{m['id']}: sha256 {digest} differs from the manifest's {m['sha256']}", file=sys.stderr)
            failed += 1
            continue
        os.makedirs(os.path.dirname(dest), exist_ok=True)
        open(dest, "wb").write(data)
        print(f"{m['id']}: fetched {len(data)} bytes")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
