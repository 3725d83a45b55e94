#!/usr/bin/python3
"""Writes the attribution file of the models a training set used.

    python3 tools/training/attribution.py DATASET SH3D_DIR OUT.md

DATASET is a g2p_make_dataset folder (its manifest.csv lists every image with its library, model and
split) or a g2p_make_kind_dataset folder (views.csv: the kind classifier's renders, splits train and val); SH3D_DIR holds the unpacked libraries of Debian's sweethome3d-furniture package, each with its
PluginFurnitureCatalog.properties (name#N, model#N, creator#N). The licences are those of the package's
debian/copyright: BlendSwap-CC-0 CC0, BlendSwap-CC-BY and Scopia CC-BY 3.0, KatorLegaz and Reallusion
CC-BY 3.0 US.
"""
import csv
import os
import sys

LICENCES = {
    "BlendSwap-CC-0": "CC0 1.0 (public domain dedication)",
    "BlendSwap-CC-BY": "CC BY 3.0",
    "Scopia": "CC BY 3.0 (Scopia Visual Interfaces Systems, s.l.)",
    "KatorLegaz": "CC BY 3.0 US (Andrew Kator & Jennifer Legaz)",
    "Reallusion": "CC BY 3.0 US (Reallusion)",
}


def catalog(path):
    """model path (as in the zip, without the leading slash) -> (name, creator)."""
    entries = {}
    with open(path, encoding="latin-1") as f:
        for line in f:
            if "=" not in line or "#" not in line.split("=", 1)[0]:
                continue
            key, value = line.rstrip("\n").split("=", 1)
            field, index = key.split("#", 1)
            entries.setdefault(index, {})[field] = value.strip()
    return {e["model"].lstrip("/"): (e.get("name", ""), e.get("creator", "")) for e in entries.values() if "model" in e}


def main():
    if len(sys.argv) != 4:
        sys.exit(__doc__)
    dataset, sh3d, out = sys.argv[1:]
    used = {}
    kinds = os.path.exists(os.path.join(dataset, "views.csv"))
    with open(os.path.join(dataset, "views.csv" if kinds else "manifest.csv"), encoding="utf-8") as f:
        for row in csv.DictReader(f):
            library = row["model"].split("/", 1)[0] if kinds else row["library"]
            used.setdefault((row["split"], library, row["model"]), 0)
            used[(row["split"], library, row["model"])] += 1
    catalogs = {}
    if kinds:
        lines = ["# Models the kind classifier saw", "",
                 "Rendered from Debian's `sweethome3d-furniture` package (1.8-1) by `g2p_make_kind_dataset`",
                 "(docs/kind-classifier.md). The classifier's head was trained on the `train` split only; the `val`",
                 "split chose among candidates. Licences per library as in the package's debian/copyright.", ""]
    else:
        lines = ["# Models the segmentation network saw", "",
                 "Rendered from Debian's `sweethome3d-furniture` package (1.8-1) by `g2p_make_dataset`",
                 "(docs/training.md). The network was trained on the `train` split only; the `test` split is the",
                 "held-out evaluation set. Licences per library as in the package's debian/copyright.", ""]
    for split in ("train", "val") if kinds else ("train", "test"):
        lines += [f"## {split}", "", "| library | licence | model | name | creator | images |", "|---|---|---|---|---|---|"]
        for (s, library, model), images in sorted(used.items()):
            if s != split:
                continue
            if library not in catalogs:
                catalogs[library] = catalog(os.path.join(sh3d, library, "PluginFurnitureCatalog.properties"))
            relative = model.split("/", 1)[1]
            name, creator = catalogs[library].get(relative, ("", ""))
            lines.append(f"| {library} | {LICENCES.get(library, '?')} | {relative} | {name} | {creator} | {images} |")
        lines.append("")
    with open(out, "w") as f:
        f.write("\n".join(lines))


if __name__ == "__main__":
    main()
