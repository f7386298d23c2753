#!/usr/bin/env python3
"""The crater of examples/sphere-plate read off a section through the particles, to check
`mpm-post crater` against: the particles of the plate in the slab 0 <= y < s next to the mirror
plane y = 0 (s: the particle spacing), mirrored in x = 0, is the section of the whole plate
through the crater's axis x = y = 0. In it, by eye as on a picture: the crater floor is the
shallowest plate centre within two spacings of the axis, the crater wall at the original
surface the innermost centre of the first row (within half a spacing of the original front
centres), less half a spacing for the surface.

usage: section.py PARTICLES_LAST.csv PARTICLES_FIRST.csv SPACING_M CRATER.json
prints both and exits 1 when depth or diameter differ by more than one spacing."""
import csv
import json
import sys


def plate(path):
    with open(path) as f:
        f.readline()  # "# t = ..."
        rows = list(csv.DictReader(f))
    return [(float(r["x_0"]), float(r["x_1"]), float(r["x_2"])) for r in rows if r["body"] == "0"]


last, first, s, crater = sys.argv[1], sys.argv[2], float(sys.argv[3]), sys.argv[4]
front = max(z for _, _, z in plate(first))  # the struck face's centres (impact along -z)
cut = [(abs(x), front - z) for x, y, z in plate(last) if 0 <= y < s]  # (|x|, depth) in the slab
floor = min(d for r, d in cut if r < 2 * s and d >= -0.5 * s)
wall = min(r for r, d in cut if -0.5 * s <= d < 0.5 * s)
depth, diameter = floor, 2 * wall - s
with open(crater) as f:
    c = json.load(f)
print(f"section y = 0:   depth {depth * 1e3:.3f} mm, diameter {diameter * 1e3:.3f} mm")
print(f"mpm-post crater: depth {c['depth'] * 1e3:.3f} mm, diameter {c['diameter'] * 1e3:.3f} mm")
ok = abs(depth - c["depth"]) <= s and abs(diameter - c["diameter"]) <= s
print(f"agree within one particle spacing ({s * 1e3:g} mm): {'yes' if ok else 'NO'}")
sys.exit(0 if ok else 1)
