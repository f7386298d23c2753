#!/usr/bin/env python3
"""Spinning disk study (issue 25, item 3): the scene.toml disk (plane strain steel, 4 mm in
radius, 50 000 rad/s) over one full turn, at 1, 0.5 and 0.25 mm cells (4, 8 and 16 cells in
radius), with every explicit scheme (USF, USL, MUSL, APIC) on both shape functions (grid.shape
"linear" and "bspline"). For each run, from its 17 frames:

- the angular momentum about the centre, sum m x cross v, its largest relative change over the
  turn and at its end; for APIC also with the affine part APIC carries, m (B_yx - B_xy) with
  B = C D, D = diag(h^2 xi (1 - xi)) on multilinear weights (xi the particle's place in its
  cell) and D = h^2 / 4 I on quadratic B-splines (Jiang et al. 2015);
- the largest in-plane principal stress magnitude over the particles and frames, against the
  steady (centripetal) solution's largest stress (plane strain, at the centre):
  sigma_c = (3 - 2 nu) / (8 (1 - nu)) rho omega^2 R^2 = 134.6 MPa.

Each disk starts unstressed ("rest": the centrifugal load comes on as a step, and an elastic
disk overshoots its steady state); APIC and MUSL on B-splines also start in the steady state
("steady": steady.toml's stress field), where whatever stress the run adds is spurious.

Usage: study.py BIN [OUT]   (BIN: the CMake build directory; OUT: default ./study)
Writes OUT/table.md and OUT/table.csv and prints the table."""
import csv
import io
import json
import math
import os
import subprocess
import sys

BIN = os.path.abspath(sys.argv[1] if len(sys.argv) > 1 else "../../build")
OUT = sys.argv[2] if len(sys.argv) > 2 else "study"
HERE = os.path.dirname(os.path.abspath(__file__))
PREP, RUN, POST = (f"{BIN}/mpm-{t}/mpm-{t}" for t in ("prep", "run", "post"))
W, R, RHO, NU = 50000.0, 4e-3, 7850.0, 0.3
ORIGIN = -8e-3  # the domain's lower corner in x and y (scene.toml)
SIGMA_C = (3 - 2 * NU) / (8 * (1 - NU)) * RHO * W * W * R * R


def frame(stream, k):
    out = subprocess.run([POST, "particles", stream, "--frame", str(k)],
                         capture_output=True, text=True).stdout
    rows = [l for l in out.splitlines() if not l.startswith("#")]
    return list(csv.DictReader(io.StringIO("\n".join(rows))))


def measure(rows, h, shape):
    """(sum m x cross v, the same with APIC's affine part, largest principal stress)."""
    L = La = smax = 0.0
    for p in rows:
        m, x, y = float(p["m"]), float(p["x_0"]), float(p["x_1"])
        l = m * (x * float(p["v_1"]) - y * float(p["v_0"]))
        L += l
        La += l
        if "C_1" in p:  # column-major 2 x 2: C_1 = dv_y/dx, C_2 = dv_x/dy
            if shape == "bspline":
                Dxx = Dyy = h * h / 4
            else:
                fx, fy = ((x - ORIGIN) / h) % 1.0, ((y - ORIGIN) / h) % 1.0
                Dxx, Dyy = h * h * fx * (1 - fx), h * h * fy * (1 - fy)
            La += m * (float(p["C_1"]) * Dxx - float(p["C_2"]) * Dyy)
        sxx, syy, sxy = float(p["sigma_0"]), float(p["sigma_1"]), float(p["sigma_5"])
        c, q = 0.5 * (sxx + syy), math.hypot(0.5 * (sxx - syy), sxy)
        smax = max(smax, abs(c) + q)
    return L, La, smax


def run(h, scheme, shape, start="rest"):
    stream = f"{OUT}/disk_{h}_{scheme}_{shape}_{start}.mpm"
    scene = "scene.toml" if start == "rest" else "steady.toml"
    p = subprocess.run(f"{PREP} {HERE}/{scene} -q --set grid.cell_size='{h} mm' "
                       f"--set solver.scheme={scheme} --set grid.shape={shape} | "
                       f"{RUN} --threads 1 --progress none "
                       f"-o {stream}", shell=True, capture_output=True, text=True)
    status = "completed" if p.returncode == 0 else p.stderr.strip().splitlines()[0][:60]
    summary = json.loads(subprocess.run([POST, "summary", stream, "--json"],
                                        capture_output=True, text=True).stdout)
    frames = len(summary["frames"])
    L0, La0, _ = measure(frame(stream, 0), h * 1e-3, shape)
    drift = drift_a = s_max = end = end_a = 0.0
    for k in range(1, frames):
        L, La, s = measure(frame(stream, k), h * 1e-3, shape)
        drift, drift_a = max(drift, abs(L / L0 - 1)), max(drift_a, abs(La / La0 - 1))
        s_max = max(s_max, s)
        end, end_a = L / L0 - 1, La / La0 - 1
    return dict(cells=int(round(4 / h)), shape=shape, scheme=scheme, start=start,
                drift=drift, end=end,
                drift_affine=drift_a if scheme == "APIC" else float("nan"),
                end_affine=end_a if scheme == "APIC" else float("nan"),
                stress=s_max / SIGMA_C, frames=frames - 1, run=status)


def main():
    os.makedirs(OUT, exist_ok=True)
    rows = []
    head = ("| cells in radius | shape | scheme | start | max abs(L/L0 - 1) | at the end | with the affine part "
            "(APIC): max | at the end | max stress / sigma_c | frames | run |")
    lines = [head, "|---:|---|---|---|---:|---:|---:|---:|---:|---:|---|"]
    for h in (1, 0.5, 0.25):
        cases = [(sh, sc, "rest") for sh in ("linear", "bspline")
                 for sc in ("USF", "USL", "MUSL", "APIC")]
        cases += [("bspline", "MUSL", "steady"), ("bspline", "APIC", "steady")]
        for shape, scheme, start in cases:
            r = run(h, scheme, shape, start)
            rows.append(r)
            lines.append(f"| {r['cells']} | {shape} | {scheme} | {start} | {r['drift']:.3g} | {r['end']:.3g} | "
                         f"{r['drift_affine']:.3g} | {r['end_affine']:.3g} | {r['stress']:.3g} | "
                         f"{r['frames']} | {r['run']} |")
            print(lines[-1], flush=True)
    text = "\n".join(lines) + "\n"
    open(f"{OUT}/table.md", "w").write(text)
    with open(f"{OUT}/table.csv", "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    print(text)


if __name__ == "__main__":
    main()
