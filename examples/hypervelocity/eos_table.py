#!/usr/bin/env python3
"""V4 with both equations of state side by side: one markdown row per run of study.sh
(out/VARIANT.mpm, its logs), the front and width at 30.6 us from the plate's rear face and from
its impact face (maximum, 99.9th and 99.5th percentiles of the cloud's mass), the share of the
cloud's mass whose specific energy is past lead's incipient (0.264 MJ/kg) and complete (1.130
MJ/kg) vaporisation, steps and wall time, and the front chosen in advance (99.5th percentile
from the rear face, docs/eos-tillotson.md) against the experiment's 200 mm.
Usage: eos_table.py BUILD_DIR VARIANT...   (e.g. axi-0.265 till-axi-0.265)
"""
import csv
import io
import json
import re
import subprocess
import sys

E_IV, E_CV = 0.264e6, 1.130e6  # J/kg, docs/eos-tillotson.md


def debris(post, path, face):
    out = subprocess.run([post, "debris", path, "--time", "30.6 us", "--face", face, "--json"],
                         capture_output=True, text=True, check=True).stdout
    return json.loads(out)


def vaporised(post, path, d):
    """Shares of the cloud's mass (behind the rear face) with e past E_iv and past E_cv."""
    text = subprocess.run([post, "particles", path, "--frame", "last", "--columns", "x,m,e"],
                          capture_output=True, text=True, check=True).stdout
    rows = csv.DictReader(io.StringIO("\n".join(l for l in text.splitlines() if not l.startswith("#"))))
    axis = "xyz".index(d["axis"])
    total = iv = cv = 0.0
    for r in rows:
        if d["direction"] * (float(r[f"x_{axis}"]) - d["plane"]) <= 0:
            continue
        m, e = float(r["m"]), float(r["e"])
        total += m
        iv += m if e > E_IV else 0.0
        cv += m if e > E_CV else 0.0
    return iv / total, cv / total


def row(build, variant):
    """The markdown row of a finished run; None when its log shows no finished run."""
    post = f"{build}/mpm-post/mpm-post"
    path = f"out/{variant}.mpm"
    if "(time loop)" not in open(f"out/run_{variant}.log").read():
        return None
    rear, impact = debris(post, path, "rear"), debris(post, path, "impact")
    iv, cv = vaporised(post, path, rear)
    run = open(f"out/run_{variant}.log").read()
    steps = re.search(r"steps (\d+), sorts", run).group(1)
    wall = float(re.search(r"wall ([0-9.]+) s \(time loop\)", run).group(1))
    threads = re.search(r"threads (\d+)", run).group(1)
    eos = "Tillotson" if variant.startswith("till-") else "Mie-Grueneisen"
    mm = lambda v: f"{1e3 * v:.1f}"
    f = rear["front_p99_5"]
    return (f"| {variant} | {eos} | {steps} | {wall:.0f} ({threads}) | "
            f"{mm(rear['front_max'])} / {mm(rear['front_p99_9'])} / **{mm(f)}** | "
            f"{mm(impact['front_max'])} / {mm(impact['front_p99_9'])} / {mm(impact['front_p99_5'])} | "
            f"{mm(rear['width_max'])} / {mm(rear['width_p99_9'])} / {mm(rear['width_p99_5'])} | "
            f"{100 * iv:.0f}% / {100 * cv:.0f}% | {100 * (f / 0.2 - 1):+.1f}% |")


if __name__ == "__main__":
    print("| variant | EOS | steps | wall s (threads) | front from rear face: max / p99.9 / p99.5 mm "
          "| front from impact face: max / p99.9 / p99.5 mm | width: max / p99.9 / p99.5 mm "
          "| cloud mass past E_iv / E_cv | p99.5 rear vs 200 mm |")
    print("|---|---|---|---|---|---|---|---|---|")
    for v in sys.argv[2:]:
        r = row(sys.argv[1], v)
        print(r if r else f"| {v} | (not finished: out/run_{v}.log) |", flush=True)
