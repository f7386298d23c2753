#!/usr/bin/env python3
"""Side-by-side speed of two builds on the Taylor deck of issue 23 (examples/taylor-bar: 0.76 mm
cells, 21 172 particles, MUSL, --set solver.cfl=0.8, one thread, frames written to a file):
each build REPEAT times, interleaved (A, B, A, B, ...) so that drifts of a shared machine hit
both alike; per kernel the median ns per particle-step of each and their ratio, and the bar's
final L and D from each build (mpm-post taylor), which a change for speed must leave alone.

Usage: ab.py --build BUILD --base BASE_BUILD [--repeat N] [--threads 1] [--cfl 0.8]
"""
import argparse, json, os, statistics, subprocess, tempfile

from bench import parse_stats, run

HERE = os.path.dirname(os.path.abspath(__file__))
SCENE = os.path.join(HERE, "..", "examples", "taylor-bar", "scene.toml")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--build", required=True, help="the build measured")
    ap.add_argument("--base", required=True, help="the build it is measured against")
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--threads", default="1")
    ap.add_argument("--cfl", default="0.8")
    a = ap.parse_args()
    builds = {"base": os.path.abspath(a.base), "build": os.path.abspath(a.build)}
    with tempfile.TemporaryDirectory() as tmp:
        model = os.path.join(tmp, "taylor.model")
        run([f"{builds['build']}/mpm-prep/mpm-prep", "-q", SCENE, "-o", model])
        runs = {k: [] for k in builds}
        shape = {}
        for rep in range(a.repeat):
            for k, b in builds.items():
                out = os.path.join(tmp, f"{k}.mpm")
                r = run([f"{b}/mpm-run/mpm-run", model, "-o", out, "--threads", a.threads,
                         "--set", f"solver.cfl={a.cfl}", "--stats", "--progress", "none"])
                runs[k].append(parse_stats(r.stderr))
                if rep == 0:
                    t = run([f"{builds['build']}/mpm-post/mpm-post", "taylor", out, "--json"])
                    shape[k] = json.loads(t.stdout)
    kernels = list(runs["build"][0]["kernels"])
    print(f"Taylor deck ({runs['build'][0]['particles']} particles, {runs['build'][0]['steps']} steps, "
          f"cfl {a.cfl}, {a.threads} thread(s)); medians of {a.repeat} interleaved runs, ns per particle-step")
    print("| kernel | base | build | build / base |")
    print("|---|---|---|---|")
    for k in kernels + ["total"]:
        med = {}
        for name, rs in runs.items():
            if k == "total":
                med[name] = statistics.median(1e9 * r["total_seconds"] / r["particle_steps"] for r in rs)
            else:
                med[name] = statistics.median(r["kernels"][k]["ns_per_particle_step"] for r in rs)
        ratio = med["build"] / med["base"] if med["base"] > 0 else float("nan")
        print(f"| {k} | {med['base']:.1f} | {med['build']:.1f} | {ratio:.3f} |")
    print()
    for q in ("L", "D"):
        base, new = shape["base"][q], shape["build"][q]
        print(f"{q}: base {1e3 * base:.6f} mm, build {1e3 * new:.6f} mm, relative change {(new - base) / base:+.2e}")


if __name__ == "__main__":
    main()
