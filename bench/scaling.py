#!/usr/bin/env python3
"""The scaling model of docs/performance.md: parallel efficiency of mpm-run's slab
decomposition at 8, 64 and 512 ranks for the V4 large model and a 10^9-particle plate, from the
communication measured on this machine (bench/ranks.py, mpm-run --stats under mpirun) and a
network's latency and bandwidth.

A step of a rank holding N / P particles between two cuts costs

    T(P) = t_p N / P                                   compute (one thread a rank)
         + 2 cuts x 2 exchanges x (alpha + b S / beta)  shared nodes (MUSL: p2g 7, remap 3 doubles)
         + c (alpha log2 P + 8 w P / beta)               rank-ordered sums (Allgather of w doubles)
         + 2 cuts x m x e / beta                         particles crossing a cut (per step)

and E(P) = t_p N / (P T(P)). A slab must stay at least 3 cells thick (its window's node planes
at both cuts must not meet), so P <= layers / 3 along the slab axis; beyond, the model says
"no slab decomposition" (a 2D or 3D decomposition would be needed, and is not built).

Usage: scaling.py [--alpha-us 2] [--beta-GBs 10]   (defaults: a cluster network, not measured)
"""
import argparse
import math

# Measured on this machine (2026-11-26; commands in docs/performance.md).
T_P_NS = 107.5  # ns per particle-step, one thread: V3 model 3 (bench/ranks.py, 1 x 1: 9.30 M/s)
B_NODE = 80.0  # bytes per shared node and step: MUSL sends 7 doubles after p2g, 3 after remap
C_COLLECTIVES = 7  # sums, minima and flags a step (two kernels x sum and min, face forces,
W_SUM = 13  # signal, checkpoint; --stats: 10.2 messages a step); doubles in the largest
E_PARTICLE = 134.0  # bytes a particle carries when it crosses a cut (its columns)
MIGRATION = 2e-5  # particles crossing a cut per step, per particle of the rank (Taylor, V3: ~2e-5)
# Shared nodes per cut: V4 coarse deck (2.12 mm cells) measured 17 840 under 2 ranks, slabs
# along x; the large model's 1 mm cells have (2.12 / 1)^2 times the nodes in a plane.
S_V4_COARSE, H_V4_COARSE = 17840, 2.12

CASES = {
    # name: particles, cells along the slab axis, shared nodes per cut
    "V4 large (13.5 M particles, 1 mm cells, slabs along x)":
        (13.54e6, 250, S_V4_COARSE * (H_V4_COARSE / 1.0) ** 2),
    "10^9-particle plate (1 m x 1 m x 15 mm, 0.5 mm cells, 8 a cell)":
        (0.96e9, 2000, 3 * 2001 * 31),
}


def step_time(n, p, s, alpha, beta):
    compute = T_P_NS * 1e-9 * n / p
    if p == 1:
        return compute, 0.0
    nodes = 2 * 2 * (alpha + B_NODE * s / beta)
    sums = C_COLLECTIVES * (alpha * math.ceil(math.log2(p)) + 8 * W_SUM * p / beta)
    migrate = 2 * MIGRATION * (n / p) * E_PARTICLE / beta
    return compute, nodes + sums + migrate


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--alpha-us", type=float, default=2.0, help="latency, us (default: a cluster)")
    ap.add_argument("--beta-GBs", type=float, default=10.0, help="bandwidth, GB/s")
    a = ap.parse_args()
    alpha, beta = a.alpha_us * 1e-6, a.beta_GBs * 1e9
    print(f"latency {a.alpha_us} us, bandwidth {a.beta_GBs} GB/s, t_p {T_P_NS} ns/particle-step\n")
    print("| model | ranks | particles a rank | slab cells | shared nodes a cut | compute ms/step "
          "| communication ms/step | efficiency |")
    print("|---|---|---|---|---|---|---|---|")
    for name, (n, layers, s) in CASES.items():
        for p in (8, 64, 512):
            if layers / p < 3:
                print(f"| {name} | {p} | {n / p:.3g} | {layers / p:.2g} | {s:.3g} | - | - | "
                      "no slab decomposition: slabs under 3 cells |")
                continue
            comp, comm = step_time(n, p, s, alpha, beta)
            print(f"| {name} | {p} | {n / p:.3g} | {layers / p:.3g} | {s:.3g} | {comp * 1e3:.3g} "
                  f"| {comm * 1e3:.3g} | {comp / (comp + comm):.3f} |")


if __name__ == "__main__":
    main()
