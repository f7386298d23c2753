#!/usr/bin/env python3
"""Pareto fronts of the trade study: reads DIR/trade*.csv (study.py), writes for each problem
DIR/<problem>_points.dat and DIR/<problem>_front.dat (for pareto.gp) and DIR/fronts.md: the
settings on the front (no other run is both cheaper and more accurate) and the cheapest run
within 1%, 2% and 5%, by CPU time and by particle-steps. Usage: fronts.py DIR"""
import csv
import glob
import sys

d = sys.argv[1] if len(sys.argv) > 1 else "study"
rows = [r for f in sorted(glob.glob(f"{d}/trade*.csv")) for r in csv.DictReader(open(f))
        if r["status"] == "ok"]
for r in rows:
    for k in ("error_pct", "cpu_s", "wall_s", "particle_steps", "peak_mb"):
        r[k] = float(r[k])

TITLES = {"taylor": "Taylor bar V2 (max of |L|, |D| error against the experiment)",
          "rod": "wave rod V1 (L1 error of sigma_xx against the analytic step)"}


def front(pts, cost):
    """The runs no other run beats in both cost and error, cheapest first."""
    out, best = [], float("inf")
    for r in sorted(pts, key=lambda r: (r[cost], r["error_pct"])):
        if r["error_pct"] < best:
            out.append(r)
            best = r["error_pct"]
    return out


def cheapest(pts, cost, target):
    ok = [r for r in pts if r["error_pct"] <= target]
    return min(ok, key=lambda r: r[cost]) if ok else None


def short(r):
    """The label without the default knobs (2 per cell, MUSL, CFL 0.5), for the plots."""
    parts = [p for p in r["label"].split() if p not in ("ppc=2", "MUSL", "cfl=0.5")]
    return "_".join(parts).replace("0.633333", "0.633").replace("0.506667", "0.507").replace(
        "0.253333", "0.253")


md = []
for problem in ("taylor", "rod"):
    pts = [r for r in rows if r["problem"] == problem]
    if not pts:
        continue
    f_cpu = front(pts, "cpu_s")
    f_ps = front(pts, "particle_steps")
    on_front = {id(r) for r in f_cpu}
    with open(f"{d}/{problem}_points.dat", "w") as f:
        f.write("# cpu_s error_pct particle_steps wall_s on_front label\n")
        for r in pts:
            f.write(f"{r['cpu_s']:.4g} {r['error_pct']:.4g} {r['particle_steps']:.4g} "
                    f"{r['wall_s']:.4g} {int(id(r) in on_front)} {short(r)}\n")
    with open(f"{d}/{problem}_front.dat", "w") as f:
        for r in f_cpu:
            f.write(f"{r['cpu_s']:.4g} {r['error_pct']:.4g} {short(r)}\n")
    with open(f"{d}/{problem}_front_ps.dat", "w") as f:
        for r in f_ps:
            f.write(f"{r['particle_steps']:.4g} {r['error_pct']:.4g} {short(r)}\n")
    md.append(f"### {TITLES[problem]}\n")
    md.append("Pareto front by CPU time (one thread):\n")
    md.append("| setting | error % | CPU s | wall s (median) | particle-steps | peak MB |")
    md.append("|---|---|---|---|---|---|")
    for r in f_cpu:
        md.append(f"| {r['label']} | {r['error_pct']:.2f} | {r['cpu_s']:.2f} | {r['wall_s']:.2f} | "
                  f"{r['particle_steps']:.3g} | {r['peak_mb']:.1f} |")
    md.append("\nCheapest run within each target:\n")
    md.append("| target | by CPU time | error % | CPU s | wall s | by particle-steps | error % | "
              "particle-steps |")
    md.append("|---|---|---|---|---|---|---|---|")
    for t in (1.0, 2.0, 5.0):
        a, b = cheapest(pts, "cpu_s", t), cheapest(pts, "particle_steps", t)
        if a is None:
            md.append(f"| {t:g}% | none of the runs | | | | | | |")
            continue
        md.append(f"| {t:g}% | {a['label']} | {a['error_pct']:.2f} | {a['cpu_s']:.2f} | "
                  f"{a['wall_s']:.2f} | {b['label']} | {b['error_pct']:.2f} | "
                  f"{b['particle_steps']:.3g} |")
    md.append("")
open(f"{d}/fronts.md", "w").write("\n".join(md) + "\n")
print("\n".join(md))
