#!/usr/bin/env python3
"""Why a kernel sits where it does against the roofline: instructions per particle-step of each
kernel of the explicit step (valgrind's callgrind, which counts them without the hardware
counters this kind of machine lacks), its time on the same binary and the core's clock
(mpm-roofline): the instructions per cycle at which it runs, and how many instructions a
particle-step would have to take for the kernel to reach half its flop roof at that rate.

valgrind 3.19 does not run AVX-512 code, so the binary measured is an AVX2 build
(-march=x86-64-v3) of the same source, made in OUT/build-avx2 when missing (about 10 minutes
on one core; ccache makes rebuilds cheap); the AVX-512 build's kernel times are printed beside
it. The deck is issue 23's Taylor bar (0.76 mm, cfl 0.8, one thread).

Usage: instructions.py --build BUILD [--steps N] [--repeat N]
"""
import argparse, json, os, re, shutil, statistics, subprocess, sys

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
OUT = os.path.join(HERE, "out")

# The kernel timers and the functions whose inclusive instruction counts they time.
KERNELS = {
    "sort": r"SolverCore<mpm::UniformGrid<3> >::sort_particles\(\)",
    "p2g": r"ExplicitSolver<mpm::UniformGrid<3> >::scatter_to_grid<7, false>\(\)",
    "g2p_remap": r"ExplicitSolver<mpm::UniformGrid<3> >::gather_from_grid<\(mpm::ExplicitSolver<mpm::UniformGrid<3> >::G2pMode\)2, false>\(\)",
    "stress_move": r"ExplicitSolver<mpm::UniformGrid<3> >::update_stress\(",
}
# Flops per particle-step, as bench.py counts them (KERNELS there).
sys.path.insert(0, HERE)
from bench import KERNELS as WORK  # noqa: E402


def run(cmd, **kw):
    return subprocess.run(cmd, check=True, capture_output=True, text=True, **kw)


def stats(text):
    """ns per particle-step of each kernel, and the particle-steps, from mpm-run --stats."""
    ns = {m.group(1): float(m.group(2))
          for m in re.finditer(r"^(\w+)\s+\d+\s+[\d.]+\s+[\d.]+%\s+([\d.]+)$", text, re.M)}
    steps = float(re.search(r"particle-steps ([\d.e+]+)", text).group(1))
    return ns, steps


def avx2_build(path):
    runner = os.path.join(path, "mpm-run", "mpm-run")
    if not os.path.exists(os.path.join(path, "CMakeCache.txt")):
        flags = ["-DCMAKE_BUILD_TYPE=Release", "-DMPM_NATIVE=OFF", "-DCMAKE_CXX_FLAGS=-march=x86-64-v3",
                 "-DMPM_BUILD_TESTS=OFF"]
        if shutil.which("ccache"):
            flags += ["-DCMAKE_CXX_COMPILER_LAUNCHER=ccache", "-DCMAKE_C_COMPILER_LAUNCHER=ccache"]
        print(f"configuring the AVX2 build in {path}", flush=True)
        run(["cmake", "-S", ROOT, "-B", path] + flags)
    print("building it (mpm-run)", flush=True)
    run(["cmake", "--build", path, "-j", str(os.cpu_count() or 1), "--target", "mpm-run"])
    return runner


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--build", required=True, help="the (AVX-512, native) build directory")
    ap.add_argument("--avx2", default=os.path.join(OUT, "build-avx2"), help="AVX2 build directory")
    ap.add_argument("--steps", type=int, default=0, help="steps under callgrind (0: the whole run)")
    ap.add_argument("--repeat", type=int, default=3, help="native runs of each build (median)")
    a = ap.parse_args()
    if not shutil.which("valgrind"):
        sys.exit("instructions.py: valgrind is not installed (apt-get install valgrind)")
    os.makedirs(OUT, exist_ok=True)
    build = os.path.abspath(a.build)
    prep, native = os.path.join(build, "mpm-prep", "mpm-prep"), os.path.join(build, "mpm-run", "mpm-run")
    avx2 = avx2_build(os.path.abspath(a.avx2))
    clock = json.loads(run([os.path.join(build, "bench", "mpm-roofline"), "--json"]).stdout)
    ghz, peak = clock["clock_GHz"], clock["fma_GFLOPs"]["1"]
    model = os.path.join(OUT, "taylor_deck.mpm")
    run([prep, "-q", os.path.join(ROOT, "examples", "taylor-bar", "scene.toml"), "-o", model])
    deck = ["--threads", "1", "--set", "solver.cfl=0.8", "--progress", "none", "--stats"]

    times = {"native": [], "avx2": []}
    for _ in range(a.repeat):  # interleaved
        for name, exe in (("native", native), ("avx2", avx2)):
            times[name].append(stats(run([exe, model, "-o", os.devnull] + deck).stderr)[0])
    med = {name: {k: statistics.median(r[k] for r in rs) for k in KERNELS}
           for name, rs in times.items()}

    cg = os.path.join(OUT, "callgrind.out")
    extra = ["--set", f"solver.max_steps={a.steps}"] if a.steps else []
    print("running the AVX2 build under callgrind (about 50 times its own time)", flush=True)
    r = run(["valgrind", "--tool=callgrind", f"--callgrind-out-file={cg}", avx2, model, "-o",
             os.devnull] + deck + extra)
    _, particle_steps = stats(r.stderr)
    ann = run(["callgrind_annotate", "--inclusive=yes", cg]).stdout
    instr = {}
    for k, pattern in KERNELS.items():
        counts = [int(m.group(1).replace(",", "")) for m in
                  re.finditer(r"^\s*([\d,]+) \([\s\d.]+%\)\s+\S*:\S*" + pattern, ann, re.M)]
        instr[k] = max(counts) / particle_steps if counts else float("nan")

    print(f"\nTaylor deck, one thread; core clock {ghz:.2f} GHz, FMA peak {peak:.1f} GFLOP/s; "
          f"instructions of the AVX2 build under callgrind ({particle_steps:.4g} particle-steps), "
          f"times medians of {a.repeat} interleaved runs")
    print("| kernel | AVX-512 ns/particle-step | AVX2 ns/particle-step | AVX2 instructions/particle-step "
          "| instructions/cycle | flops/particle-step | instructions for half the flop roof at that rate |")
    print("|---|---|---|---|---|---|---|")
    rows = []
    for k in KERNELS:
        ns2, ipc = med["avx2"][k], instr[k] / (med["avx2"][k] * ghz)
        flops = WORK.get(k, {}).get("flops")
        # Half the roof: flops / (peak / 2) seconds, at the measured instructions per cycle.
        half = f"{flops / (0.5 * peak) * ghz * ipc:.0f}" if flops else "-"
        rows.append(dict(kernel=k, native_ns=med["native"][k], avx2_ns=ns2, instructions=instr[k],
                         ipc=ipc, flops=flops))
        print(f"| {k} | {med['native'][k]:.1f} | {ns2:.1f} | {instr[k]:.0f} | {ipc:.2f} | "
              f"{flops or '-'} | {half} |")
    with open(os.path.join(OUT, "instructions.json"), "w") as f:
        json.dump(dict(clock_GHz=ghz, fma_GFLOPs=peak, particle_steps=particle_steps, kernels=rows), f,
                  indent=1)
    print(f"\nJSON: {os.path.join(OUT, 'instructions.json')}")


if __name__ == "__main__":
    main()
