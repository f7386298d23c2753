#!/usr/bin/env python3
"""Table and plot data of the graded Taylor bar study (graded.sh): L, D, particles, cost."""
import json
import re
import sys

study = sys.argv[1] if len(sys.argv) > 1 else "study"
cases = [("uniform_019", "uniform 0.19 mm"), ("graded", "graded 0.38 / 0.19 mm"),
         ("uniform_038", "uniform 0.38 mm")]
exp_L, exp_D = 16.2, 13.5  # Johnson & Holmquist 1988
seed = {"uniform_019": "16.21, 13.28, 9488 s", "uniform_038": "16.29, 13.14, 963 s",
        "graded": "16.28, 13.28, 5966 s"}  # 004 Table 3 (CPU s, 2011 machine)
rows = {}
for case, label in cases:
    t = json.load(open(f"{study}/taylor_{case}.json"))
    log = open(f"{study}/run_{case}.log").read()
    prep = open(f"{study}/prep_{case}.log").read()
    t0, t1 = map(float, open(f"{study}/wall_{case}.txt").read().split())
    steps = int(re.search(r"steps (\d+), sorts", log).group(1))
    rate = float(re.search(r"([0-9.]+) million particle-steps/s", log).group(1))
    start = int(re.search(r"^  total\s+(\d+)", prep, re.M).group(1))
    split = re.search(r"(\d+) particles split", log)
    rows[case] = dict(label=label, L=t["L"] * 1e3, D=t["D"] * 1e3, start=start,
                      end=t["particles"], steps=steps, wall=t1 - t0, rate=rate,
                      split=int(split.group(1)) if split else 0)
ref = rows["uniform_019"]
with open(f"{study}/graded_table.md", "w") as f:
    f.write("| grid | particles start | particles end | split | steps | L mm | D mm | L vs uniform 0.19 | "
            "D vs uniform 0.19 | L vs exp | D vs exp | wall s | wall / uniform 0.19 | "
            "Mparticle-steps/s | seed 004 Table 3: L, D, CPU |\n")
    f.write("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n")
    for case, _ in cases:
        r = rows[case]
        pct = lambda a, b: f"{100 * (a / b - 1):+.2f}%"
        f.write(f"| {r['label']} | {r['start']} | {r['end']} | {r['split']} | {r['steps']} | "
                f"{r['L']:.3f} | {r['D']:.3f} | {pct(r['L'], ref['L'])} | {pct(r['D'], ref['D'])} | "
                f"{pct(r['L'], exp_L)} | {pct(r['D'], exp_D)} | {r['wall']:.1f} | "
                f"{r['wall'] / ref['wall']:.2f} | {r['rate']:.2f} | {seed[case]} |\n")
    f.write("\nL and D on particle centres (mpm-post taylor --json). Experiment: L = 16.2 mm, "
            "D = 13.5 mm. wall: mpm-run alone, one run after the other on the same machine.\n")
with open(f"{study}/cost_error.dat", "w") as f:
    f.write("# wall_s L_err_exp_pct D_err_exp_pct L_err_ref_pct D_err_ref_pct label\n")
    for case, _ in cases:
        r = rows[case]
        f.write(f"{r['wall']:.2f} {abs(100 * (r['L'] / exp_L - 1)):.4f} {abs(100 * (r['D'] / exp_D - 1)):.4f} "
                f"{abs(100 * (r['L'] / ref['L'] - 1)):.4f} {abs(100 * (r['D'] / ref['D'] - 1)):.4f} "
                f"\"{r['label']}\"\n")
