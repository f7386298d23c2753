#!/usr/bin/env python3
"""The extremes map from DIR/cases.csv (extremes.py): DIR/map.dat, one square per case (column:
the case's place in its family, row: family and scheme, colour: the verdict, text: the
parameter and the energy error or the exit status), DIR/rows.gp (the row names), and
DIR/summary.md (counts by verdict and family). Usage: map.py DIR"""
import csv
import sys
from collections import Counter, defaultdict

d = sys.argv[1] if len(sys.argv) > 1 else "study"
rows = list(csv.DictReader(open(f"{d}/cases.csv")))
COLOUR = {"ran": 1, "stopped": 2, "refused": 3, "SILENT": 4, "CRASH": 5}
keys = []
for r in rows:
    k = (r["family"], r["scheme"])
    if k not in keys:
        keys.append(k)
col = defaultdict(int)
with open(f"{d}/map.dat", "w") as f:
    for r in rows:
        k = (r["family"], r["scheme"])
        y = len(keys) - 1 - keys.index(k)
        x = col[k]
        col[k] += 1
        e = r["energy_error"]
        if r["verdict"] == "ran":
            txt = f"{100 * float(e):+.1f}%"
        else:
            txt = f"exit {r['exit']}"
        case = r["case"]
        f.write(f'{x} {y} {COLOUR[r["verdict"]]} "{case}" "{txt}"\n')
with open(f"{d}/rows.gp", "w") as f:
    tics = ", ".join(f'"{fam} {s}" {len(keys) - 1 - i}' for i, (fam, s) in enumerate(keys))
    f.write(f"set ytics ({tics})\nset yrange [-0.5:{len(keys) - 0.5}]\n"
            f"set xrange [-0.5:{max(col.values()) - 0.5}]\n")
c = Counter(r["verdict"] for r in rows)
by = defaultdict(Counter)
for r in rows:
    by[r["family"]][r["verdict"]] += 1
lines = [f"{len(rows)} cases: " + ", ".join(f"{v} {c[v]}" for v in COLOUR if c[v]), "",
         "| family | cases | ran | stopped (exit 3) | refused (exit 2) | silent | crash |",
         "|---|---|---|---|---|---|---|"]
for fam, cc in by.items():
    lines.append(f"| {fam} | {sum(cc.values())} | {cc['ran']} | {cc['stopped']} | "
                 f"{cc['refused']} | {cc['SILENT']} | {cc['CRASH']} |")
open(f"{d}/summary.md", "w").write("\n".join(lines) + "\n")
print("\n".join(lines))
