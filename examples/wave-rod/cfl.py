#!/usr/bin/env python3
"""V1 CFL study (issue 23: the default CFL from accuracy against step): uniform_coarse.toml
(0.5 mm, MUSL) at each CFL number, the L2 error of sigma_xx against the analytic step at 9, 18,
31 and 40 us (analyse.py's measure), steps and time loop; writes DIR/cfl_table.md.
Usage: cfl.py BUILD_DIR DIR [CFL ...]"""
import os
import re
import subprocess
import sys

import analyse

bin_dir, out = sys.argv[1], sys.argv[2]
cfls = [float(c) for c in sys.argv[3:]] or [0.2, 0.3, 0.5, 0.7, 0.8, 0.9, 1.0]
os.makedirs(out, exist_ok=True)
analyse.study = out
rows = []
for cfl in cfls:
    case = f"cfl_{cfl:g}"
    prep = subprocess.run([f"{bin_dir}/mpm-prep/mpm-prep", "uniform_coarse.toml", "--set",
                           f"solver.cfl={cfl:g}"], capture_output=True, check=True)
    run = subprocess.run([f"{bin_dir}/mpm-run/mpm-run", "--stats", "--progress", "none"],
                         input=prep.stdout, capture_output=True)
    post = subprocess.run([f"{bin_dir}/mpm-post/mpm-post", "profile", "-", "--field", "sigma",
                           "--component", "xx", "--time", "9us", "--time", "18us", "--time",
                           "31us", "--time", "40us", "-o", f"{out}/{case}.csv"],
                          input=run.stdout, capture_output=True)
    log = run.stderr.decode()
    steps = re.search(r"steps (\d+)", log)
    wall = re.search(r"wall ([0-9.]+) s", log)
    if run.returncode != 0 or post.returncode != 0:
        last = log.strip().splitlines()[-1] if log.strip() else ""
        rows.append(f"| {cfl:g} | exit {run.returncode}: {last} | | | | | | |")
        continue
    prof = analyse.read(case)
    errs = [analyse.l2(analyse.nearest(prof, t), t) for t in analyse.times]
    mean = sum(errs) / len(errs)
    rows.append(f"| {cfl:g} | {steps.group(1)} | {float(wall.group(1)):.1f} | " +
                " | ".join(f"{100 * e:.2f}%" for e in errs) + f" | {100 * mean:.2f}% |")
with open(f"{out}/cfl_table.md", "w") as f:
    f.write("| cfl | steps | time loop (s) | L2 error 9 us | 18 us | 31 us | 40 us | mean |\n")
    f.write("|---|---|---|---|---|---|---|---|\n")
    f.write("\n".join(rows) + "\n")
print(open(f"{out}/cfl_table.md").read())
