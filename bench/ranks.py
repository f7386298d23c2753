#!/usr/bin/env python3
"""mpm-run under mpirun (issue 24): the same model run by one process and by two ranks.

  1. Equality: the Taylor bar (V2, examples/taylor-bar) and the V4 coarse deck
     (examples/hypervelocity, sparse grid, particles leaving the domain), each run by one
     process and twice by 2 ranks, one thread each: L and D, or the debris front and width,
     every history column (17 digits) and the particle counts, relative to their scale; and
     whether the two 2-rank streams are the same bytes.
  2. Speed: V3 model 3 (bench/taylor_v3.toml, 0.2 mm cells, ~1.16 million particles), 2 ranks
     x 1 thread against 1 process x 2 threads (and 1 x 1), interleaved REPEAT times: particle-
     steps per second of the time loop (median and range).
  3. Communication: bytes and messages a rank sends per step (mpm-run --stats), and the MPI
     latency and bandwidth between two ranks of this machine (bench/pingpong), the inputs of
     the scaling model in docs/performance.md.

Usage: ranks.py --build BUILD [--repeat 3] [--steps 200] [--skip-equality] [--skip-speed]
"""
import argparse
import json
import os
import re
import statistics
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
MPIRUN = ["mpirun", "--allow-run-as-root", "--oversubscribe", "-np", "2"]
ENV = dict(os.environ, OMP_WAIT_POLICY="passive",
           OMPI_MCA_btl_vader_single_copy_mechanism="none")


def sh(cmd, **kw):
    return subprocess.run(cmd, check=True, capture_output=True, text=True, env=ENV, **kw)


def history(post, stream):
    text = sh([post, "history", stream, "--digits", "17"]).stdout.splitlines()
    names = text[1].split(",")
    rows = [[float(v) for v in line.split(",")] for line in text[2:] if line]
    return names, rows


def group(name):
    """A vector's components share a scale: force_platen_y -> force_platen."""
    return name[:-2] if len(name) > 2 and name[-2] == "_" and name[-1] in "xyz" else name


def history_difference(a, b):
    names, ra = a
    _, rb = b
    if len(ra) != len(rb):
        return float("inf"), "rows"
    scale = {}
    for k, n in enumerate(names):
        scale[group(n)] = max(scale.get(group(n), 0.0), max(abs(r[k]) for r in ra))
    worst, which = 0.0, ""
    for k, n in enumerate(names):
        d = max(abs(x[k] - y[k]) for x, y in zip(ra, rb))
        rel = d / scale[group(n)] if scale[group(n)] > 0 else d
        if rel > worst:
            worst, which = rel, n
    return worst, which


def equality(b, out):
    prep, run, post = (os.path.join(b, t, t) for t in ("mpm-prep", "mpm-run", "mpm-post"))
    cases = [
        ("Taylor bar (V2)", os.path.join(ROOT, "examples/taylor-bar/scene.toml"), [],
         lambda s: sh([post, "taylor", s, "--json"]).stdout, ("L", "D")),
        ("V4 coarse deck", os.path.join(ROOT, "examples/hypervelocity/scene.toml"), [],
         lambda s: sh([post, "debris", s, "--time", "30.6 us", "--json"]).stdout,
         ("front", "width")),
    ]
    print("| model | particles (end) | measure | 1 process | 2 ranks | relative difference |")
    print("|---|---|---|---|---|---|")
    notes = []
    for name, scene, sets, measure, keys in cases:
        model = os.path.join(out, "ranks_model.mpm")
        sh([prep, "-q", scene, "-o", model] + sets)
        streams = {}
        walls = {}
        for tag, cmd in (("one", [run]), ("two0", MPIRUN + [run]), ("two1", MPIRUN + [run])):
            streams[tag] = os.path.join(out, f"ranks_{tag}.mpm")
            t0 = time.time()
            sh(cmd + [model, "--threads", "1", "--progress", "none", "-o", streams[tag]])
            walls[tag] = time.time() - t0
        ma, mb = json.loads(measure(streams["one"])), json.loads(measure(streams["two0"]))
        ha, hb = history(post, streams["one"]), history(post, streams["two0"])
        n_a = int(ha[1][-1][ha[0].index("particles")])
        n_b = int(hb[1][-1][hb[0].index("particles")])
        for k in keys:
            rel = abs(ma[k] - mb[k]) / abs(ma[k])
            print(f"| {name} | {n_a} / {n_b} | {k} (m) | {ma[k]!r} | {mb[k]!r} | {rel:.2e} |")
        hd, col = history_difference(ha, hb)
        same = open(streams["two0"], "rb").read() == open(streams["two1"], "rb").read()
        notes.append(f"{name}: history, largest difference {hd:.2e} of the column's scale "
                     f"({col}); {len(ha[1])} rows; two 2-rank streams "
                     f"{'identical, byte for byte' if same else 'DIFFERENT'}; wall "
                     f"{walls['one']:.1f} s (1 process, 1 thread), {walls['two0']:.1f} and "
                     f"{walls['two1']:.1f} s (2 ranks x 1 thread, with mpirun's start)")
        for s in streams.values():
            os.remove(s)
        os.remove(model)
    print()
    for n in notes:
        print("- " + n)


def loop_rate(text):
    ps = float(re.search(r"particle-steps ([0-9.e+]+),", text).group(1))
    wall = float(re.search(r"wall ([0-9.]+) s \(time loop\)", text).group(1))
    return ps / wall / 1e6, text


def speed(b, out, repeat, steps):
    prep, run = os.path.join(b, "mpm-prep", "mpm-prep"), os.path.join(b, "mpm-run", "mpm-run")
    model = os.path.join(out, "ranks_v3m3.mpm")
    h, half, z = 0.2, 27, 134  # bench.py's model 3
    sh([prep, "-q", os.path.join(HERE, "taylor_v3.toml"), "-o", model,
        "--set", f"grid.cell_size={h} mm",
        "--set", f"grid.domain={{ min = \"{-half * h:.6g} {-half * h:.6g} 0 mm\", "
                 f"max = \"{half * h:.6g} {half * h:.6g} {z * h:.6g} mm\" }}",
        "--set", f"solver.max_steps={steps}", "--set", "output.frames=1"])
    configs = [("1 process x 1 thread", [run], 1), ("1 process x 2 threads", [run], 2),
               ("2 ranks x 1 thread", MPIRUN + [run], 1)]
    rates = {c[0]: [] for c in configs}
    stats = {}
    for _ in range(repeat):
        for name, cmd, t in configs:
            r = sh(cmd + [model, "-o", "/dev/null", "--threads", str(t), "--progress", "none",
                          "--stats"])
            rate, text = loop_rate(r.stderr)
            rates[name].append(rate)
            stats[name] = text
    os.remove(model)
    base = statistics.median(rates["1 process x 1 thread"])
    print(f"\nV3 model 3, {steps} steps, {repeat} interleaved runs each (time loop, output "
          "included):\n")
    print("| configuration | M particle-steps/s (median) | range | against 1 x 1 |")
    print("|---|---|---|---|")
    for name, _, _ in configs:
        v = rates[name]
        print(f"| {name} | {statistics.median(v):.3f} | {min(v):.3f}-{max(v):.3f} | "
              f"{statistics.median(v) / base:.3f} |")
    print("\n2 ranks, --stats of the last run:\n")
    for line in stats["2 ranks x 1 thread"].splitlines():
        if line.startswith("  rank") or line.startswith("ranks") or "ranks_nodes" in line:
            print("    " + line.strip())


def pingpong(b):
    exe = os.path.join(b, "bench", "pingpong")
    if not os.path.exists(exe):
        print("\n(no bench/pingpong in this build: MPM_MPI off)")
        return
    print("\nMPI between 2 ranks of this machine (bench/pingpong):\n")
    print("    " + sh(MPIRUN + [exe]).stdout.strip().replace("\n", "\n    "))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--build", required=True)
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--steps", type=int, default=200)
    ap.add_argument("--skip-equality", action="store_true")
    ap.add_argument("--skip-speed", action="store_true")
    a = ap.parse_args()
    b = os.path.abspath(a.build)
    out = os.path.join(HERE, "out")
    os.makedirs(out, exist_ok=True)
    if not a.skip_equality:
        equality(b, out)
    if not a.skip_speed:
        speed(b, out, a.repeat, a.steps)
    pingpong(b)
    sys.stdout.flush()


if __name__ == "__main__":
    main()
