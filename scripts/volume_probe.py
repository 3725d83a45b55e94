#!/usr/bin/env python3
"""The volume probe of docs/properties.md (#50): closed boards, plates and rods
from 1 to 50 mm thick and three open surfaces, written as OBJ files, each run
through `g2p run --unit m --save-intermediates`, and a Markdown table of the
closed part against the true volume and the independent estimate.

    scripts/volume_probe.py [--g2p build/bin/g2p] [--work /tmp/g2p_volume_probe]
"""
import argparse
import json
import math
import os
import subprocess


def box(sx, sy, sz):
    v = [(x * sx / 2, y * sy / 2, z * sz / 2) for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)]
    quads = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]
    return v, [t for a, b, c, d in quads for t in ((a, b, c), (a, c, d))]


def ring(n, r, z):
    return [(r * math.cos(2 * math.pi * i / n), r * math.sin(2 * math.pi * i / n), z) for i in range(n)]


def rod(r, length, n=32):
    v = ring(n, r, -length / 2) + ring(n, r, length / 2) + [(0, 0, -length / 2), (0, 0, length / 2)]
    f = []
    for i in range(n):
        j = (i + 1) % n
        f += [(i, j, j + n), (i, j + n, i + n), (2 * n, j, i), (2 * n + 1, i + n, j + n)]
    return v, f


def pot_without_bottom(outer, inner, height, n=48):
    """A thick-walled pot whose bottom ring face is missing: open."""
    v = ring(n, outer, 0) + ring(n, outer, height) + ring(n, inner, 0) + ring(n, inner, height)
    f = []
    for i in range(n):
        j = (i + 1) % n
        f += [(i, j, j + n), (i, j + n, i + n)]  # outer wall
        f += [(2 * n + i, 3 * n + j, 2 * n + j), (2 * n + i, 3 * n + i, 3 * n + j)]  # inner wall
        f += [(n + i, n + j, 3 * n + j), (n + i, 3 * n + j, 3 * n + i)]  # top rim
    return v, f


def shapes():
    """(file stem, material word, geometry, true volume in m^3 or None)."""
    out = []
    for t in (1, 2, 5, 10, 20, 50):
        out.append((f"oak_board_{t}mm", "oak", box(0.6, 0.3, t / 1000), 0.6 * 0.3 * t / 1000))
    out.append(("steel_plate_1mm", "steel", box(0.2, 0.2, 0.001), 0.2 * 0.2 * 0.001))
    for d, length in ((8, 1.0), (50, 0.5)):
        r = d / 2000
        polygon = 0.5 * 32 * r * r * math.sin(2 * math.pi / 32)  # the 32-gon's area
        out.append((f"steel_rod_{d}mm", "steel", rod(r, length), polygon * length))
    v, f = box(0.6, 0.3, 0.002)
    out.append(("oak_board_2mm_faces_only", "oak", (v, [t for t in f if len({v[i][2] for i in t}) == 1]),
                0.6 * 0.3 * 0.002))
    out.append(("oak_sheet_single", "oak", ([(-0.3, -0.15, 0), (0.3, -0.15, 0), (0.3, 0.15, 0), (-0.3, 0.15, 0)],
                                            [(0, 1, 2), (0, 2, 3)]), None))
    area = 0.5 * 48 * math.sin(2 * math.pi / 48) * (0.05 ** 2 - 0.045 ** 2)
    out.append(("ceramic_pot_without_bottom", "ceramic", pot_without_bottom(0.05, 0.045, 0.1), area * 0.1))
    return out


def write_obj(path, material, geometry):
    v, f = geometry
    stem = os.path.splitext(path)[0]
    with open(path, "w") as o:
        o.write(f"mtllib {os.path.basename(stem)}.mtl\nusemtl {material}\n")
        o.writelines("v %.9g %.9g %.9g\n" % p for p in v)
        o.writelines("f %d %d %d\n" % (a + 1, b + 1, c + 1) for a, b, c in f)
    with open(stem + ".mtl", "w") as o:
        o.write(f"newmtl {material}\nKd 0.6 0.5 0.4\n")


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--g2p", default="build/bin/g2p")
    ap.add_argument("--work", default="/tmp/g2p_volume_probe")
    a = ap.parse_args()
    os.makedirs(a.work, exist_ok=True)
    print("| input | true volume (cm³) | estimate (cm³) | closed part (cm³) | difference | triangles in / out | "
          "backend | completion_ok | warnings | mass (kg) |")
    print("|---|---:|---:|---:|---:|---:|---|---|---:|---:|")
    for stem, material, geometry, truth in shapes():
        model = os.path.join(a.work, stem + ".obj")
        out = os.path.join(a.work, stem)
        write_obj(model, material, geometry)
        run = subprocess.run([a.g2p, "run", model, "--unit", "m", "-o", out, "--overwrite", "--save-intermediates"],
                             capture_output=True, text=True)
        if run.returncode != 0:
            print(f"| {stem} | g2p run failed: {run.stderr.strip().splitlines()[-1]} |")
            continue
        completion = json.load(open(os.path.join(out, "completed", "completion.json")))
        report = json.load(open(os.path.join(out, "report.json")))
        warnings = json.load(open(os.path.join(out, "run.json")))["warnings"]
        parts = completion["parts"]
        # One part: its own estimate and difference; several (a board's two
        # faces): the parts together against the object's estimate.
        estimate = parts[0]["input_volume_m3"] if len(parts) == 1 else completion["input_volume_m3"]
        volume = sum(p["checks"]["volume_m3"] for p in parts)
        diff = parts[0]["volume_difference"] if len(parts) == 1 else (
            None if estimate <= 0 else volume / estimate - 1)
        backends = "+".join(sorted({p["backend"] for p in parts}))
        ok = all(p["ok"] for p in parts)
        print(f"| {stem} ({len(parts)} part{'s' if len(parts) > 1 else ''}) | "
              f"{'-' if truth is None else '%.4g' % (truth * 1e6)} | "
              f"{'none' if estimate < 0 else '%.4g' % (estimate * 1e6)} | {volume * 1e6:.4g} | "
              f"{'not judged' if diff is None else '%+.1f %%' % (diff * 100)} | "
              f"{len(geometry[1])} / {sum(p['triangles'] for p in parts):,} | "
              f"{backends} | {'true' if ok else 'false'} | {len(warnings)} | {report['object']['mass_kg']:.4g} |")


if __name__ == "__main__":
    main()
