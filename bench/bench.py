#!/usr/bin/env python3
"""Benchmark suite: the V3 Taylor bar (copper, 40 m/s) at the sizes of 000 Table 2, for each
scatter strategy at 1 and 2 threads: particle-steps per second, speed-up, parallel efficiency,
peak memory, bytes per particle (the whole process: particles, grid window, scratch), the
kernel time table; plus the machine's roofline (mpm-roofline) and where each particle kernel
sits against it. Prints tables and writes bench/out/bench.json (--json).

Usage: bench.py --build BUILD [--models 1,2,3] [--strategies ...] [--threads 1,2] [--steps N]
                [--repeat N] [--json NAME]
"""
import argparse, json, os, re, subprocess, sys, time

HERE = os.path.dirname(os.path.abspath(__file__))

# Model sizes of 000 Table 2 (particles), reached with 2 x 2 x 2 particles per cell of the cell
# size below (models 1-3), or with the bar's own particle spacing (model 4); domains keep the
# bar's axis on cell edges (x = y = 0) and the wall at z = 0. Model 4 is the seed's: its Table 2
# counts (8 177 664 cells, 8 302 185 nodes) are a grid of 176 x 176 x 264 cells, 0.1 mm cells
# over 17.6 x 17.6 x 26.4 mm (models 1-3 are 32 x 32 x 48, 48 x 48 x 72 and 88 x 88 x 132 cells
# of that box), and 0.0453 mm spacing gives its particle count to 0.07%.
MODELS = {
    1: {"cell": 0.548, "half": 10, "z": 50, "seed_particles": 56056},
    2: {"cell": 0.335, "half": 16, "z": 80, "seed_particles": 244524},
    3: {"cell": 0.2, "half": 27, "z": 134, "seed_particles": 1155192},
    4: {"cell": 0.1, "half": 88, "z": 264, "spacing": 0.0453, "seed_particles": 12416320},
}
STRATEGIES = ["colored", "lr-slabs", "array-expansion", "patch"]

# Work per particle-step of the particle kernels (3D, MUSL), counted off the code in
# common/mpm/solver/explicit/explicit_solver_impl.hpp and materials/*.cpp: flops (adds, multiplies, divides,
# square roots each 1) and bytes moved (particle columns read and written once per kernel; grid
# traffic of the 8 cached nodes per cell, spread over the ~8 particles of a cell). Estimates to
# about +-30%: the compiler fuses and vectorises, caches absorb some traffic.
# p2g: 186 flops a particle in its cell (locating 9, weights 19, mass 16, momentum 51, V sigma 7,
# edge weights 12, stress by edge 72) and 27 a particle for the bin's flush to its corners
# (2026-11-26, after the edge sums; before them 354). stress_move's count is of the kernel
# before the fused update and the gradient by edges (not recounted).
KERNELS = {
    "p2g": {"flops": 213, "bytes": 141},
    "g2p_remap": {"flops": 147, "bytes": 153},
    "stress_move": {"flops": 580, "bytes": 273},
}


def run(cmd, **kw):
    return subprocess.run(cmd, check=True, capture_output=True, text=True, **kw)


def parse_stats(text):
    out = {"kernels": {}}
    table = False
    for line in text.splitlines():
        if line.startswith("kernel"):
            table = True
            continue
        if table:
            parts = line.split()
            if not parts:
                continue
            if parts[0] == "total":
                out["total_seconds"] = float(parts[1])
                table = False
                continue
            out["kernels"][parts[0]] = {"calls": int(parts[1]), "seconds": float(parts[2]),
                                        "ns_per_particle_step": float(parts[4])}
    m = re.search(r"strategy (\S+), threads (\d+), particles (\d+), steps (\d+), sorts (\d+), "
                  r"particle-steps ([0-9.e+]+), ([0-9.]+) million particle-steps/s", text)
    out.update(strategy=m.group(1), threads=int(m.group(2)), particles=int(m.group(3)),
               steps=int(m.group(4)), sorts=int(m.group(5)), particle_steps=float(m.group(6)),
               mps=float(m.group(7)))
    m = re.search(r"peak memory ([0-9.]+) MB, ([0-9]+) bytes per particle.*particle columns "
                  r"([0-9]+) bytes, grid window ([0-9]+) nodes, solver work arrays ([0-9.]+) MB", text)
    out.update(peak_MB=float(m.group(1)), bytes_per_particle=int(m.group(2)),
               column_bytes=int(m.group(3)), grid_nodes=int(m.group(4)), work_MB=float(m.group(5)))
    return out


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--build", required=True)
    ap.add_argument("--models", default="1,2,3")
    ap.add_argument("--strategies", default=",".join(STRATEGIES))
    ap.add_argument("--threads", default="1,2")
    ap.add_argument("--steps", type=int, default=0, help="steps per run (0: by model size)")
    ap.add_argument("--json", default="bench.json", help="file name of the JSON in bench/out")
    ap.add_argument("--repeat", type=int, default=1,
                    help="runs of each case, interleaved across thread counts; the run of median "
                         "throughput is reported, with the range (shared machines are noisy)")
    a = ap.parse_args()
    b = os.path.abspath(a.build)
    prep, runner, roof = (f"{b}/mpm-prep/mpm-prep", f"{b}/mpm-run/mpm-run", f"{b}/bench/mpm-roofline")
    out_dir = os.path.join(HERE, "out")
    os.makedirs(out_dir, exist_ok=True)
    threads = [int(t) for t in a.threads.split(",")]

    roofline = json.loads(run([roof, "--json"]).stdout)
    print("Machine roofline (mpm-roofline, medians):")
    print(f"  {'threads':>8} {'triad GB/s':>12} {'FMA GFLOP/s':>12}")
    for t in ("1", "2"):
        print(f"  {t:>8} {roofline['triad_GBs'][t]:>12.2f} {roofline['fma_GFLOPs'][t]:>12.2f}")

    results = []
    for mk in [int(m) for m in a.models.split(",")]:
        m = MODELS[mk]
        h = m["cell"]
        half = m["half"] * h
        model = os.path.join(out_dir, f"model{mk}.mpm")
        steps = a.steps or {1: 400, 2: 250, 3: 120, 4: 10}[mk]
        run([prep, "-q", os.path.join(HERE, "taylor_v3.toml"), "-o", model,
             "--set", f"grid.cell_size={h} mm",
             "--set", f"grid.domain={{ min = \"{-half:.6g} {-half:.6g} 0 mm\", max = \"{half:.6g} {half:.6g} {m['z'] * h:.6g} mm\" }}",
             "--set", f"solver.max_steps={steps}", "--set", "output.frames=1"]
            + (["--set", f"bodies.bar.particle_spacing={m['spacing']} mm"] if "spacing" in m else []))
        for st in a.strategies.split(","):
            runs = {t: [] for t in threads}
            for rep in range(a.repeat):  # 1, 2, 1, 2, ...: drifts of the machine hit both alike
                for t in threads:
                    t0 = time.time()
                    r = run([runner, model, "-o", "/dev/null", "--threads", str(t), "--strategy", st,
                             "--stats", "--progress", "none"])
                    s = parse_stats(r.stderr)
                    s.update(model=mk, seed_particles=m["seed_particles"], wall=time.time() - t0)
                    runs[t].append(s)
            for t in threads:
                ordered = sorted(runs[t], key=lambda r: r["mps"])
                s = ordered[(len(ordered) - 1) // 2]  # the median (lower one of an even count)
                s.update(repeats=len(ordered), mps_min=ordered[0]["mps"], mps_max=ordered[-1]["mps"])
                results.append(s)
                spread = (f" (of {len(ordered)}: {ordered[0]['mps']:.3f}-{ordered[-1]['mps']:.3f})"
                          if len(ordered) > 1 else "")
                print(f"  model {mk} {st:16s} {t} thread(s): {s['mps']:7.3f} M particle-steps/s{spread}, "
                      f"{s['bytes_per_particle']} B/particle", flush=True)

    # Speed-up and efficiency against the same model and strategy at 1 thread.
    for s in results:
        one = [r for r in results if r["model"] == s["model"] and r["strategy"] == s["strategy"] and r["threads"] == 1]
        if one:
            s["speedup"] = s["mps"] / one[0]["mps"]
            s["efficiency"] = s["speedup"] / s["threads"]
    print()
    print("| model | particles (seed) | strategy | threads | steps | M particle-steps/s (median) | range | speed-up | efficiency | peak MB | B/particle |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    for s in results:
        print(f"| {s['model']} | {s['particles']} ({s['seed_particles']}) | {s['strategy']} | {s['threads']} | {s['steps']} | "
              f"{s['mps']:.3f} | {s['mps_min']:.2f}-{s['mps_max']:.2f} ({s['repeats']}) | "
              f"{s.get('speedup', float('nan')):.3f} | {s.get('efficiency', float('nan')):.3f} | "
              f"{s['peak_MB']:.1f} | {s['bytes_per_particle']} |")

    # Roofline position of the particle kernels (default strategy, largest model measured).
    print()
    print("Kernels against the roofline (default strategy; flops and bytes per particle-step counted off the code):")
    print("| model | threads | kernel | ns/particle-step | flop/B | GFLOP/s | GB/s | roofline bound GFLOP/s | share of bound |")
    print("|---|---|---|---|---|---|---|---|---|")
    for s in results:
        if s["strategy"] != "colored":
            continue
        t = str(s["threads"])
        for k, w in KERNELS.items():
            if k not in s["kernels"]:
                continue
            ns = s["kernels"][k]["ns_per_particle_step"]
            gf = w["flops"] / ns  # flops per ns = GFLOP/s
            gb = w["bytes"] / ns
            ai = w["flops"] / w["bytes"]
            bound = min(roofline["fma_GFLOPs"][t], ai * roofline["triad_GBs"][t])
            s.setdefault("roofline", {})[k] = {"GFLOPs": gf, "GBs": gb, "intensity": ai, "bound": bound}
            print(f"| {s['model']} | {t} | {k} | {ns:.1f} | {ai:.2f} | {gf:.2f} | {gb:.2f} | {bound:.1f} | {100 * gf / bound:.1f}% |")

    with open(os.path.join(out_dir, a.json), "w") as f:
        json.dump({"roofline": roofline, "kernel_work": KERNELS, "runs": results}, f, indent=1)
    print(f"\nJSON: {os.path.join(out_dir, a.json)}")
    for s in results:
        if s["strategy"] == "colored":
            print(f"\nkernel times, model {s['model']}, {s['threads']} thread(s), colored:")
            for k, v in s["kernels"].items():
                print(f"  {k:20s} {v['calls']:8d} calls {v['seconds']:10.3f} s {v['ns_per_particle_step']:9.1f} ns/particle-step")


if __name__ == "__main__":
    main()
