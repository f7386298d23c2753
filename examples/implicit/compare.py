#!/usr/bin/env python3
"""Compare histories and particle dumps of implicit runs with the explicit run of the same scene.

  compare.py load REF.csv RUN.csv [--bins 0.5]   load-deflection (platen travel, mm; load kN):
      mean load in deflection bins for each, relative RMS difference, final-bin loads
  compare.py sxx PARTICLES.csv                   mean, min, max of sigma_xx over the material
  compare.py radius PARTICLES.csv                largest radius of the material, mm
  compare.py energy RUN.csv                      initial and final total energy, dissipation

CSV inputs come from `mpm-post history` and `mpm-post particles`.
"""
import csv
import math
import sys


def read(path):
    with open(path) as f:
        rows = [r for r in csv.reader(l for l in f if not l.startswith('#'))]
    head = rows[0]
    return [{k: float(v) for k, v in zip(head, r)} for r in rows[1:]]


def binned_load(rows, width_mm, force='force_platen_y', speed=1.0):
    """Mean load (kN) of the history rows whose platen travel (mm) falls in each bin; the
    rows are time-weighted by their step. The last bin is closed at the end of the run."""
    bins, end = {}, rows[-1]['time'] * speed * 1e3
    for r in rows[1:]:
        d = r['time'] * speed * 1e3
        k = min(int(d / width_mm), int(end / width_mm - 1e-9))
        s = bins.setdefault(k, [0.0, 0.0])
        s[0] += r['dt'] * r[force] / 1e3  # kN: the material pushes the platen up (+y)
        s[1] += r['dt']
    return {k: s[0] / s[1] for k, s in bins.items() if s[1] > 0}


def load(ref_path, run_path, width=0.5):
    ref, run = binned_load(read(ref_path), width), binned_load(read(run_path), width)
    keys = sorted(k for k in ref if k in run and ref[k] > 0)
    num = sum((run[k] - ref[k]) ** 2 for k in keys)
    den = sum(ref[k] ** 2 for k in keys)
    last = keys[-1]
    print(f"rms_rel={math.sqrt(num / den):.4f} final_bin_mm={last * width:.2f}-{(last + 1) * width:.2f} "
          f"ref_kN={ref[last]:.1f} run_kN={run[last]:.1f} final_rel={run[last] / ref[last] - 1:+.4f}")


def material(rows):
    return [r for r in rows if r.get('material', 0) != 255]


def sxx(path):
    s = [r['sigma_0'] for r in material(read(path))]
    print(f"mean={sum(s) / len(s):.4f} min={min(s):.4f} max={max(s):.4f} n={len(s)}")


def radius(path):
    print(f"r_max_mm={max(r['x_0'] for r in material(read(path))) * 1e3:.3f}")


def energy(path):
    rows = read(path)
    e0, e1 = rows[0]['total'], rows[-1]['total']
    print(f"E0={e0:.6g} E_end={e1:.6g} dissipated={1 - e1 / e0:.4f}")


if __name__ == '__main__':
    cmd, args = sys.argv[1], sys.argv[2:]
    if cmd == 'load':
        width = float(args[args.index('--bins') + 1]) if '--bins' in args else 0.5
        load(args[0], args[1], width)
    else:
        {'sxx': sxx, 'radius': radius, 'energy': energy}[cmd](args[0])
