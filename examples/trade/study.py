#!/usr/bin/env python3
"""The trade: accuracy against cost for the knobs a user turns, on the Taylor bar (V2, against
the experiment) and the elastic wave rod (V1, against the analytic step).

Each case is mpm-prep SCENE --set ... | mpm-run --threads 1 --stats under /usr/bin/time, then
mpm-post measures it. Per run: the error, wall and CPU seconds of mpm-run, particle-steps (from
mpm-run --stats), peak memory (the largest resident set, from /usr/bin/time). Cheap cases are
repeated and the medians kept. Writes OUT/trade.csv, OUT/<problem>_pareto.dat (for pareto.gp)
and OUT/fronts.md (the settings on the Pareto front, and the cheapest within 1%, 2%, 5%).

Usage: study.py BUILD_DIR [OUT] [--only taylor|rod] [--repeats N] [--select REGEX NAME]
(--select: only the cases whose label matches REGEX, written to OUT/NAME.csv)
Run it niced on a shared machine: the runs use one thread each, one after the other."""
import csv
import json
import math
import os
import re
import statistics
import subprocess
import sys
from collections import defaultdict

HERE = os.path.dirname(os.path.abspath(__file__))

# --- the cases -----------------------------------------------------------------------------

L_EXP, D_EXP = 16.2e-3, 13.5e-3  # Johnson & Holmquist 1988 (docs/references.md, V2)


def taylor_cases():
    """(label, scene, sets, knobs) for the Taylor bar: the axisymmetric model over every knob,
    the 3D model at two cell sizes."""
    out = []

    def add(h, ppc=2, scheme="MUSL", cfl=0.5, graded=False, model="axi", shape="linear"):
        scene = "taylor_axi.toml" if model == "axi" else "../taylor-bar/scene.toml"
        sets = [f"grid.cell_size={h} mm", f"bodies.bar.particles_per_cell={ppc}",
                f"solver.scheme={scheme}", f"solver.cfl={cfl}", "output.frames=1"]
        if shape != "linear":
            sets.append(f"grid.shape={shape}")
        grid = "uniform"
        if graded:  # level 2 (h / 2) over the 3.8 mm next to the wall, out to r = 7.6 mm
            grid = "graded"
            sets.append('grid.levels=[{ level = 2, min = "0 0 mm", max = "7.6 3.8 mm" }]')
            label_h = f"{h}/{h / 2:g}"
        else:
            label_h = f"{h}"
        knobs = dict(model=model, cell_mm=label_h, ppc=ppc, scheme=scheme, cfl=cfl, grid=grid,
                     shape=shape)
        label = f"{model} h={label_h} ppc={ppc} {scheme} cfl={cfl}" + (" graded" if graded else "")
        label += f" {shape}" if shape != "linear" else ""
        out.append((label, scene, sets, knobs))

    for h in (0.76, 0.38, 0.19, 0.095):  # cell size (2 x 2 particles per cell, MUSL, cfl 0.5)
        add(h)
    for k in (12, 15, 25, 30):  # cells between: 2 R0 / k tiles the radius with whole spacings
        add(round(7.6 / k, 6))
    for h in (0.38, 0.19):  # particles per cell, schemes
        for ppc in (1, 3):
            add(h, ppc=ppc)
        for scheme in ("USF", "USL"):
            add(h, scheme=scheme)
    for cfl in (0.1, 0.3, 0.7, 0.9):  # CFL number
        add(0.38, cfl=cfl)
    add(0.19, cfl=0.9)
    add(0.38, graded=True)  # graded against uniform
    add(0.19, graded=True)
    add(0.76, model="3d")  # 3D against axisymmetric
    add(0.38, model="3d")
    for h in (0.76, 0.38):  # B-spline weights, with MUSL and APIC (3D: no axisymmetric B-splines)
        for scheme in ("MUSL", "APIC"):
            add(h, scheme=scheme, model="3d", shape="bspline")
    return out


ROD_E, ROD_RHO, ROD_S0, ROD_L = 100e9, 5000.0, 0.15625e6, 0.1  # Pa, kg/m^3, Pa, m
ROD_TIMES = (9e-6, 18e-6, 31e-6, 40e-6)


def rod_cases():
    """The wave rod, one cell across, over cell size, particles per cell, scheme, CFL and a
    graded grid (level 2 over the middle 40 mm, as V1)."""
    out = []

    def add(h, ppc=2, scheme="MUSL", cfl=0.5, graded=False, shape="linear"):
        s = h / ppc  # particle spacing: the load acts on the last layer of particles
        half = h / 2
        force = ROD_S0 * (h * 1e-3) ** 2
        sets = [f"grid.cell_size={h} mm", f"bodies.rod.particles_per_cell={ppc}",
                f'bodies.rod.size="100 {h} {h} mm"', f'loads.0.force="{force:.9g} 0 0 N"',
                f'loads.0.region={{ min = "{100 - s * 0.999:.6f} {-half} {-half} mm", '
                f'max = "100 {half} {half} mm" }}',
                f'grid.domain={{ min = "0 {-half} {-half} mm", max = "{100 + h} {half} {half} mm" }}',
                f"solver.scheme={scheme}", f"solver.cfl={cfl}"]
        if shape != "linear":
            sets.append(f"grid.shape={shape}")
        grid = "uniform"
        label_h = f"{h}"
        if graded:
            grid = "graded"
            label_h = f"{h}/{h / 2:g}"
            sets.append(f'grid.levels=[{{ level = 2, min = "30 {-half} {-half} mm", '
                        f'max = "70 {half} {half} mm" }}]')
        knobs = dict(model="3d", cell_mm=label_h, ppc=ppc, scheme=scheme, cfl=cfl, grid=grid,
                     shape=shape)
        label = f"h={label_h} ppc={ppc} {scheme} cfl={cfl}" + (" graded" if graded else "")
        label += f" {shape}" if shape != "linear" else ""
        out.append((label, "rod.toml", sets, knobs))

    for h in (1.0, 0.5, 0.25, 0.125, 0.0625):
        add(h)
    for h in (0.5, 0.25):
        for ppc in (1, 3):
            add(h, ppc=ppc)
        for scheme in ("USF", "USL"):
            add(h, scheme=scheme)
    for cfl in (0.1, 0.3, 0.7, 0.9):
        add(0.25, cfl=cfl)
    add(0.125, cfl=0.9)
    add(0.5, graded=True)
    add(0.25, graded=True)
    for h in (0.5, 0.25, 0.125):  # B-spline weights, with MUSL and APIC
        for scheme in ("MUSL", "APIC"):
            add(h, scheme=scheme, shape="bspline")
    return out


# --- running -------------------------------------------------------------------------------


def run_case(bin_dir, scene, sets, tag, out_dir):
    """One run; returns the measured figures (or the failure) and the result file."""
    prep = [f"{bin_dir}/mpm-prep/mpm-prep", os.path.join(HERE, scene)]
    for s in sets:
        prep += ["--set", s]
    model = f"{out_dir}/{tag}.model"
    result = f"{out_dir}/{tag}.mpm"
    with open(model, "wb") as f, open(f"{out_dir}/{tag}.prep.log", "w") as log:
        r = subprocess.run(prep, stdout=f, stderr=log)
    if r.returncode != 0:
        return dict(status=f"mpm-prep exit {r.returncode}"), None
    timing = f"{out_dir}/{tag}.time"
    run = ["/usr/bin/time", "-f", "%e %U %S %M", "-o", timing, f"{bin_dir}/mpm-run/mpm-run",
           model, "--threads", "1", "--stats", "--progress", "none", "-o", result]
    env = dict(os.environ, OMP_WAIT_POLICY="passive")
    with open(f"{out_dir}/{tag}.run.log", "w") as log:
        r = subprocess.run(run, stderr=log, env=env)
    os.remove(model)
    if r.returncode != 0:
        return dict(status=f"mpm-run exit {r.returncode}"), None
    wall, user, sys_, rss = open(timing).read().split()[-4:]
    log = open(f"{out_dir}/{tag}.run.log").read()
    m = re.search(r"particles (\d+), steps (\d+), .*particle-steps ([0-9.e+]+)", log)
    return dict(status="ok", wall_s=float(wall), cpu_s=float(user) + float(sys_),
                peak_mb=int(rss) / 1024, particles=int(m.group(1)), steps=int(m.group(2)),
                particle_steps=float(m.group(3))), result


def post(bin_dir, args):
    return subprocess.run([f"{bin_dir}/mpm-post/mpm-post"] + args, check=True,
                          capture_output=True, text=True).stdout


def taylor_error(bin_dir, result):
    """L and D on the surface (a caliper on the specimen: particle centres plus half a
    spacing at the free end and at each side of the foot; on a graded grid the spacing of the
    level each lies on) against the experiment; error = the larger of the two, in %."""
    s = json.loads(post(bin_dir, ["taylor", result, "--json", "--surface"]))
    c = json.loads(post(bin_dir, ["taylor", result, "--json"]))
    eL, eD = 100 * (s["L"] / L_EXP - 1), 100 * (s["D"] / D_EXP - 1)
    return dict(error_pct=max(abs(eL), abs(eD)), L_mm=s["L"] * 1e3, D_mm=s["D"] * 1e3,
                L_err_pct=eL, D_err_pct=eD, L_centres_mm=c["L"] * 1e3, D_centres_mm=c["D"] * 1e3)


def rod_exact(x, t):
    c = math.sqrt(ROD_E / ROD_RHO)
    s = ROD_S0 if x > ROD_L - c * t else 0.0
    if c * t > ROD_L and x < c * t - ROD_L:
        s += ROD_S0
    return s


def rod_error(bin_dir, result, out_dir, tag):
    """The L1 error of sigma_xx along the rod against the analytic step, relative to the L1
    norm of the exact profile, mean over 9, 18, 31 and 40 us, in %; the L2 error of
    examples/wave-rod beside it (it carries the ringing behind the front and hardly converges)."""
    csv_path = f"{out_dir}/{tag}.csv"
    args = ["profile", result, "--field", "sigma", "--component", "xx", "-o", csv_path]
    for t in ROD_TIMES:
        args += ["--time", f"{t * 1e6:g}us"]
    post(bin_dir, args)
    prof = defaultdict(list)
    with open(csv_path) as f:
        for r in csv.DictReader(f):
            prof[float(r["time"])].append((float(r["s"]), float(r["value"]), float(r["weight"])))
    os.remove(csv_path)
    l1s, l2s = [], []
    for t in ROD_TIMES:
        rows = prof[min(prof, key=lambda k: abs(k - t))]
        num1 = sum(w * abs(v - rod_exact(x, t)) for x, v, w in rows)
        den1 = sum(w * abs(rod_exact(x, t)) for x, v, w in rows)
        num2 = sum(w * (v - rod_exact(x, t)) ** 2 for x, v, w in rows)
        l1s.append(num1 / den1)
        l2s.append(math.sqrt(num2 / sum(w for _, _, w in rows)) / ROD_S0)
    return dict(error_pct=100 * statistics.mean(l1s), L2_pct=100 * statistics.mean(l2s))


FIELDS = ["problem", "label", "model", "cell_mm", "ppc", "scheme", "cfl", "grid", "shape",
          "status",
          "error_pct", "L_mm", "D_mm", "L_err_pct", "D_err_pct", "L_centres_mm", "D_centres_mm",
          "L2_pct", "particles", "steps", "particle_steps", "wall_s", "cpu_s", "peak_mb",
          "repeats", "wall_runs_s", "ns_per_particle_step"]


def main():
    args = sys.argv[1:]
    only, repeats, select, csv_name = None, 3, None, "trade"
    if "--only" in args:
        i = args.index("--only")
        only = args[i + 1]
        del args[i:i + 2]
    if "--repeats" in args:
        i = args.index("--repeats")
        repeats = int(args[i + 1])
        del args[i:i + 2]
    if "--select" in args:  # only the cases whose label matches, into DIR/NAME.csv
        i = args.index("--select")
        select, csv_name = re.compile(args[i + 1]), args[i + 2]
        del args[i:i + 3]
    bin_dir = os.path.abspath(args[0])
    out_dir = os.path.abspath(args[1] if len(args) > 1 else os.path.join(HERE, "study"))
    os.makedirs(out_dir, exist_ok=True)
    problems = [("taylor", taylor_cases()), ("rod", rod_cases())]
    rows = []
    csv_path = f"{out_dir}/{csv_name}.csv"
    for problem, cases in problems:
        if only and problem != only:
            continue
        for n, (label, scene, sets, knobs) in enumerate(cases):
            if select and not select.search(label):
                continue
            tag = f"{problem}_{n:02d}"
            runs = []
            while True:
                fig, result = run_case(bin_dir, scene, sets, tag, out_dir)
                runs.append(fig)
                # Repeat the cheap runs (under 2 s of CPU) for medians of the times.
                if fig["status"] != "ok" or fig["cpu_s"] > 2 or len(runs) >= repeats:
                    break
            row = dict(problem=problem, label=label, **knobs, status=runs[-1]["status"])
            if row["status"] == "ok":
                for k in ("particles", "steps", "particle_steps", "peak_mb"):
                    row[k] = runs[-1][k]
                row["wall_s"] = statistics.median(r["wall_s"] for r in runs)
                row["cpu_s"] = statistics.median(r["cpu_s"] for r in runs)
                row["repeats"] = len(runs)
                row["wall_runs_s"] = " ".join(f"{r['wall_s']:.2f}" for r in runs)
                row["ns_per_particle_step"] = 1e9 * row["cpu_s"] / row["particle_steps"]
                if problem == "taylor":
                    row.update(taylor_error(bin_dir, result))
                else:
                    row.update(rod_error(bin_dir, result, out_dir, tag))
                os.remove(result)
            rows.append(row)
            print(f"{problem} {label}: {row.get('error_pct', float('nan')):.3f}% "
                  f"cpu {row.get('cpu_s', 0):.2f} s wall {row.get('wall_s', 0):.2f} s "
                  f"{row['status']}", file=sys.stderr, flush=True)
            with open(csv_path, "w", newline="") as f:  # rewritten after every case
                w = csv.DictWriter(f, fieldnames=FIELDS, extrasaction="ignore")
                w.writeheader()
                for r in rows:
                    w.writerow({k: (f"{v:.6g}" if isinstance(v, float) else v)
                                for k, v in r.items()})
    print(csv_path)


if __name__ == "__main__":
    main()
