#!/usr/bin/env python3
"""The extremes map: small scenes that push each limit of the explicit solver (and the implicit
one where it applies), each run with the USF, USL and MUSL schemes, and a verdict per case from
measured figures:

  ran       exit 0, finite frames, no energy growth beyond solver.energy_growth_limit of its
            scale, no particle faster than the bound of the problem: the energy error is given;
  stopped   exit 3 with a message naming the step, the particle (where one is to blame) and
            the cause; the frames before stay valid;
  refused   exit 2 from mpm-prep or mpm-run with a message (a scene the tools will not run);
  SILENT    exit 0 but a non-finite value in the history or the last frame, energy growth
            beyond the limit unreported, a particle faster than the problem allows, or mass
            removed from a domain that holds every particle of a right answer (non-physical);
  CRASH     any other exit status (a signal, an internal error).

Families (2D plane strain unless said; h the cell size):
  cfl       CFL 0.05 to 4: an elastic bar breathing (velocity field +-100 m/s) and an aluminium
            disk onto a rigid wall at 200 m/s;
  speed     an aluminium disk onto an aluminium plate at 1 m/s to 20 km/s;
  contrast  a bar of two welded halves, the right one's E / r, E r, rho r or rho / r for
            r = 10^0 to 10^6, the left half moving at 1 m/s;
  tiny      tiny nodal masses: one particle at eps h from a cell corner; a plate one particle
            thick at eps h from a cell face, stretched and moved across the cells; the same
            plate onto a wall; eps = 0.5 to 1e-8;
  empty     empty cells inside a body: a square frame round a hole of 1, 2, 4 cells onto a
            wall; a bar stretched to 10%, 100%, 500% (its cells empty as it parts), 1 and 2
            particles per cell;
  ppc       1 to 8 particles per cell, the disk onto the wall;
  long      the breathing bar for a million steps (energy drift), at +-1 and +-100 m/s;
  graded    an elastic block, breathing at +-10 m/s, crossing into and out of a graded grid's
            level-2 box at 100 m/s to 10 km/s;
  implicit  the implicit solver at 1 to 1000 explicit steps: the breathing bar, the disk at
            10 m/s;
  control   three cases the solver stops, with its energy guard switched off: their verdict
            must be SILENT (the map's detectors see what the guard would have caught).
Writes DIR/cases.csv and DIR/map.dat (for map.gp). Usage: extremes.py BUILD_DIR [DIR] [--select
REGEX] [--no-long]"""
import csv
import math
import os
import re
import subprocess
import sys

SCHEMES = ("USF", "USL", "MUSL")
AL = dict(density=2700.0, E=69e9, nu=0.33, A=262e6, B=52.1e6, n=0.41, c0=5350.0, s=1.34,
          gamma0=2.0)
EL = dict(density=5000.0, E=100e9, nu=0.3)


def c_wave(m):
    """Plane-strain dilatational wave speed, m/s."""
    E, nu, rho = m["E"], m["nu"], m["density"]
    return math.sqrt(E * (1 - nu) / ((1 + nu) * (1 - 2 * nu)) / rho)


def material(name, m):
    t = [f"[materials.{name}]", f'density = "{m["density"]:.6g} kg/m^3"',
         f'youngs_modulus = "{m["E"]:.6g} Pa"', f"poisson_ratio = {m['nu']}"]
    if "A" in m:
        t += [f"[materials.{name}.strength]", 'model = "j2"', f'A = "{m["A"]:.6g} Pa"',
              f'B = "{m["B"]:.6g} Pa"', f"n = {m['n']}", f"[materials.{name}.eos]",
              'model = "mie-gruneisen"', f'c0 = "{m["c0"]} m/s"', f"s = {m['s']}",
              f"gamma0 = {m['gamma0']}"]
    return "\n".join(t)


def body(name, mat, shape, extra):
    lines = ["[[bodies]]", f'name = "{name}"', f'material = "{mat}"', f'shape = "{shape}"']
    lines += [f"{k} = {v}" for k, v in extra.items()]
    return "\n".join(lines)


def scene(mats, bodies, h_mm, dom_min, dom_max, end_time, scheme, cfl=0.5, boundary=None,
          extra_grid="", solver_extra="", frames=2, history=None, dim=2):
    b = "\n".join(f'{k} = "{v}"' for k, v in (boundary or {}).items())
    hist = f'history_interval = "{history:.6g} s"' if history else ""
    sch = f'scheme = "{scheme}"' if scheme else ""
    return f"""[scene]
dimension = {dim}
{chr(10).join(mats)}
{chr(10).join(bodies)}
[grid]
cell_size = "{h_mm} mm"
domain = {{ min = "{dom_min} mm", max = "{dom_max} mm" }}
{extra_grid}
[boundary]
{b}
[solver]
{sch}
cfl = {cfl}
end_time = "{end_time:.6g} s"
on_exit = "remove"
{solver_extra}
[output]
frames = {frames}
{hist}
"""


def cases():
    """(family, label, parameter for the map, scheme, scene text, speed bound m/s)."""
    out = []
    bar = lambda: body("bar", "el", "box", {"size": '"8 2 mm"', "translate": '"4 1 mm"',
                                            "velocity_field": '["200*(x - (x_min + x_max)/2)/'
                                            '(x_max - x_min)", "0"]'})
    disk = lambda v, ppc=2: body("disk", "al", "sphere", {"radius": '"2 mm"',
                                                          "translate": '"0 2.01 mm"',
                                                          "velocity": f'"0 {-v} m/s"',
                                                          "particles_per_cell": ppc})
    wall = {"y_min": "slip"}
    c_el = c_wave(EL)
    for s in SCHEMES:
        for cfl in (0.05, 0.1, 0.2, 0.3, 0.5, 0.7, 0.9, 1.0, 1.1, 1.5, 2.0, 3.0, 4.0):
            out.append(("cfl bar", f"cfl {cfl}", cfl, s,
                        scene([material("el", EL)], [bar()], 0.5, "-2 -2", "10 4", 20e-6, s, cfl),
                        200.0))
            out.append(("cfl disk", f"cfl {cfl}", cfl, s,
                        scene([material("al", AL)], [disk(200)], 0.25, "-4 0", "4 5", 10e-6, s, cfl,
                              wall), 400.0))
        for v in (1, 3, 10, 30, 100, 300, 1000, 3000, 6580, 10000, 20000):
            dt = 0.5 * 0.25e-3 / (c_wave(AL) + 2 * v)
            plate = body("plate", "al", "box", {"size": '"12 2 mm"', "translate": '"0 -1 mm"'})
            out.append(("speed", f"{v} m/s", v, s,
                        scene([material("al", AL)], [plate, disk(v)], 0.25, "-16 -16", "16 16",
                              min(8e-6, 1500 * dt), s), 2.0 * v))
        for kind in ("E/r", "E*r", "rho*r", "rho/r"):
            for k in range(7):
                r = 10.0 ** k
                m2 = dict(EL)
                if kind == "E/r":
                    m2["E"] = EL["E"] / r
                elif kind == "E*r":
                    m2["E"] = EL["E"] * r
                elif kind == "rho*r":
                    m2["density"] = EL["density"] * r
                else:
                    m2["density"] = EL["density"] / r
                cmax = max(c_el, c_wave(m2))
                left = body("left", "el", "box", {"size": '"10 2 mm"', "translate": '"5 1 mm"',
                                                  "velocity": '"1 0 m/s"'})
                right = body("right", "soft", "box", {"size": '"10 2 mm"', "translate": '"15 1 mm"'})
                end = min(20e-6, 400 * 0.5 * 0.5e-3 / cmax)
                out.append((f"contrast {kind}", f"r 1e{k}", k, s,
                            scene([material("el", EL), material("soft", m2)], [left, right], 0.5,
                                  "-2 -2", "22 4", end, s), 5.0))
        for eps in (0.5, 0.1, 1e-2, 1e-4, 1e-8):
            one = body("one", "el", "box", {"size": '"0.5 0.5 mm"',
                                            "translate": f'"{2 + eps} {2 + eps} mm"',
                                            "particle_spacing": '"0.5 mm"',
                                            "velocity": '"10 7 m/s"'})
            out.append(("tiny corner", f"eps {eps:g}", eps, s,
                        scene([material("el", EL)], [one], 1.0, "-1 -1", "8 8", 200e-6, s),
                        12.3))
            y = 2 + eps + 0.25  # the plate's particles at y = 2 + eps h (h = 1 mm)
            plate = body("plate", "el", "box", {"size": '"6 0.5 mm"',
                                                "translate": f'"3 {y - 0.25} mm"',
                                                "particle_spacing": '"0.5 mm"',
                                                "velocity_field": '["20*(x - 3e-3)/3e-3", "5"]'})
            out.append(("tiny plate", f"eps {eps:g}", eps, s,
                        scene([material("el", EL)], [plate], 1.0, "-4 -1", "10 8", 200e-6, s),
                        25.0))
            plate = body("plate", "al", "box", {"size": '"6 0.5 mm"',
                                                "translate": f'"3 {0.25 + eps} mm"',
                                                "particle_spacing": '"0.5 mm"',
                                                "velocity": '"0 -50 m/s"'})
            out.append(("tiny onto wall", f"eps {eps:g}", eps, s,
                        scene([material("al", AL)], [plate], 1.0, "-2 0", "8 4", 50e-6, s,
                              boundary=wall), 100.0))
        for hole in (1, 2, 4):  # a square frame, 0.5 mm cells, round a hole of `hole` cells
            a, w = hole * 0.5, 1.0  # hole side and frame width, mm
            outer = a + 2 * w
            parts = [((outer, w), (0, w / 2)), ((outer, w), (0, outer - w / 2)),
                     ((w, a), (-(a + w) / 2, outer / 2)), ((w, a), ((a + w) / 2, outer / 2))]
            bods = [body(f"f{i}", "al", "box", {"size": f'"{sx} {sy} mm"',
                                               "translate": f'"{tx} {ty + 0.01} mm"',
                                               "velocity": '"0 -100 m/s"'})
                    for i, ((sx, sy), (tx, ty)) in enumerate(parts)]
            out.append(("empty hole", f"hole {hole} cells", hole, s,
                        scene([material("al", AL)], bods, 0.5, "-6 0", "6 8", 10e-6, s,
                              boundary=wall), 200.0))
        for strain in (0.1, 1.0, 5.0):
            for ppc in (1, 2):
                end = 20e-6
                rate = strain / end  # 1/s: the ends move apart at rate * 4 mm
                b = body("bar", "el", "box", {"size": '"8 1 mm"', "translate": '"0 0.5 mm"',
                                              "particles_per_cell": ppc,
                                              "velocity_field": f'["{rate:.6g}*x", "0"]'})
                out.append((f"empty stretch ppc{ppc}", f"strain {strain:g}", strain, s,
                            scene([material("el", EL)], [b], 0.5, "-40 -4", "40 4", end, s),
                            2 * rate * 4e-3))
        for ppc in range(1, 9):
            out.append(("ppc", f"{ppc} per cell", ppc, s,
                        scene([material("al", AL)], [disk(200, ppc)], 0.5, "-4 0", "4 5", 10e-6,
                              s, boundary=wall), 400.0))
        for v in (100, 300, 1000, 3000, 10000):  # level 2 over x in [10, 16] mm
            blk = body("block", "el", "box", {"size": '"4 4 mm"', "translate": '"8 5 mm"',
                                              "velocity": f'"{v} 0 m/s"',
                                              "velocity_field": '["20*(x - (x_min + x_max)/2)/'
                                              '(x_max - x_min)", "0"]'})
            lev = '[[grid.levels]]\nlevel = 2\nmin = "10 0 mm"\nmax = "16 10 mm"'
            out.append(("graded crossing", f"{v} m/s", v, s,
                        scene([material("el", EL)], [blk], 0.5, "0 0", "30 10", 12e-3 / v, s,
                              extra_grid=lev), 2.0 * v + 20))
    return out


def implicit_cases():
    out = []
    bar = body("bar", "el", "box", {"size": '"8 2 mm"', "translate": '"4 1 mm"',
                                    "velocity_field": '["200*(x - (x_min + x_max)/2)/'
                                    '(x_max - x_min)", "0"]'})
    disk = body("disk", "al", "sphere", {"radius": '"2 mm"', "translate": '"0 2.01 mm"',
                                         "velocity": '"0 -10 m/s"'})
    for mult in (1, 10, 100, 1000):
        imp = (f"type = \"implicit\"\n[solver.implicit]\ndt_target_multiple = {mult}\n"
               f"dt_initial_multiple = 1\nnewton_tolerance = 1e-4")
        out.append(("implicit bar", f"x{mult}", mult, "implicit",
                    scene([material("el", EL)], [bar], 0.5, "-2 -2", "10 4", 20e-6, None,
                          solver_extra=imp), 200.0))
        out.append(("implicit disk", f"x{mult}", mult, "implicit",
                    scene([material("al", AL)], [disk], 0.5, "-4 0", "4 5", 40e-6, None,
                          boundary={"y_min": "slip"}, solver_extra=imp), 20.0))
    return out


def long_cases():
    """The breathing bar on 1 mm cells, one particle per cell (16 particles), for a million
    steps, at +-1 m/s (the ends move 0.2 um, within their cells: the scheme's own drift) and
    at +-100 m/s (they move across cell faces every half period)."""
    out = []
    dt = 0.5 * 1e-3 / c_wave(EL)  # about the step
    for amp in (1, 100):
        bar = body("bar", "el", "box", {"size": '"8 2 mm"', "translate": '"4 1 mm"',
                                        "particles_per_cell": 1,
                                        "velocity_field": f'["{2 * amp}*(x - (x_min + x_max)/2)/'
                                        '(x_max - x_min)", "0"]'})
        for s in SCHEMES:
            out.append(("long", f"1e6 steps +-{amp} m/s", amp, s,
                        scene([material("el", EL)], [bar], 1.0, "-2 -2", "10 4", 1e6 * dt, s,
                              history=1e6 * dt / 200), 2.0 * amp))
    return out


def control_cases():
    """Controls of the map itself: cases the solver stops, rerun with its energy guard switched
    off (solver.energy_growth_limit = 1e9). Their verdict must be SILENT: the map's own
    detectors see what the guard would have caught."""
    out = []
    guard_off = "energy_growth_limit = 1e9"
    disk = body("disk", "al", "sphere", {"radius": '"2 mm"', "translate": '"0 2.01 mm"',
                                         "velocity": '"0 -200 m/s"'})
    out.append(("control (guard off)", "disk USL", 0, "USL",
                scene([material("al", AL)], [disk], 0.25, "-4 0", "4 5", 10e-6, "USL", 0.5,
                      {"y_min": "slip"}, solver_extra=guard_off), 400.0))
    one = body("one", "el", "box", {"size": '"0.5 0.5 mm"', "translate": '"2 2 mm"',
                                    "particle_spacing": '"0.5 mm"', "velocity": '"10 7 m/s"'})
    out.append(("control (guard off)", "corner USL", 1, "USL",
                scene([material("el", EL)], [one], 1.0, "-1 -1", "8 8", 200e-6, "USL",
                      solver_extra=guard_off), 12.3))
    bar = body("bar", "el", "box", {"size": '"8 2 mm"', "translate": '"4 1 mm"',
                                    "particles_per_cell": 1,
                                    "velocity_field": '["2*(x - (x_min + x_max)/2)/'
                                    '(x_max - x_min)", "0"]'})
    out.append(("control (guard off)", "vibration MUSL", 2, "MUSL",
                scene([material("el", EL)], [bar], 1.0, "-2 -2", "10 4", 2e-3, "MUSL",
                      solver_extra=guard_off, history=1e-5), 2.0))
    return out


def run(bin_dir, text, tag, d):
    """Runs one scene; returns the exit statuses, the message and the result file."""
    path = f"{d}/{tag}.toml"
    open(path, "w").write(text)
    model, result = f"{d}/{tag}.model", f"{d}/{tag}.mpm"
    p = subprocess.run([f"{bin_dir}/mpm-prep/mpm-prep", path, "-q", "-o", model],
                       capture_output=True, text=True)
    if p.returncode != 0:
        return dict(stage="mpm-prep", status=p.returncode, message=p.stderr.strip()[-300:])
    env = dict(os.environ, OMP_WAIT_POLICY="passive")
    r = subprocess.run(["/usr/bin/time", "-f", "%U %S", "-o", f"{d}/{tag}.time",
                        f"{bin_dir}/mpm-run/mpm-run", model, "--threads", "1", "--progress",
                        "none", "-o", result], capture_output=True, text=True, env=env)
    os.remove(model)
    lines = [l for l in r.stderr.strip().splitlines() if "error:" in l]
    try:
        u, s = open(f"{d}/{tag}.time").read().split()[-2:]
        cpu = float(u) + float(s)
    except (OSError, ValueError):
        cpu = float("nan")
    return dict(stage="mpm-run", status=r.returncode, message=(lines[-1] if lines else
                r.stderr.strip()[-300:]), result=result, cpu_s=cpu)


def post(bin_dir, args):
    r = subprocess.run([f"{bin_dir}/mpm-post/mpm-post"] + args, capture_output=True, text=True)
    return r.stdout if r.returncode == 0 else None


def no_figures():
    return dict(steps=0, energy_error=float("nan"), growth=float("nan"), vmax=float("nan"),
                nonfinite=0, removed_mass=0.0, kinetic_end=float("nan"))


def measure(bin_dir, result, bound, limit=0.05):
    """Energy error (of leapfrog_total against its start, over the guard's scale), finite
    frames, the largest particle speed of the last frame against the problem's bound."""
    hist = post(bin_dir, ["history", result])
    lines = [l for l in hist.splitlines() if not l.startswith("#")] if hist else []
    rows = list(csv.DictReader(lines))  # "# units: ..." lines are comments
    f = no_figures()
    if rows:
        e0 = float(rows[0]["leapfrog_total"])
        scale = max([abs(e0)] + [float(r["kinetic"]) for r in rows] +
                    [abs(float(r["external_work"])) for r in rows])
        e = [float(r["leapfrog_total"]) for r in rows]
        f["steps"] = int(rows[-1]["step"])
        f["energy_error"] = (e[-1] - e0) / scale if scale > 0 else 0.0
        f["growth"] = (max(e) - e0) / scale if scale > 0 else 0.0
        f["nonfinite"] += sum(1 for r in rows for v in r.values()
                              if v and re.search(r"nan|inf", v, re.I))
        f["removed_mass"] = float(rows[-1].get("removed_mass") or 0)
        f["kinetic_end"] = float(rows[-1]["kinetic"]) / scale if scale > 0 else 0.0
    parts = post(bin_dir, ["particles", result, "--columns", "x,v,sigma,rho"])
    if parts:
        lines = [l for l in parts.splitlines() if l and not l.startswith("#")]
        head = lines[0].split(",")
        iv = [i for i, name in enumerate(head) if name.startswith("v_")]
        vmax = 0.0
        for l in lines[1:]:
            vals = l.split(",")
            if any(re.search(r"nan|inf", v, re.I) for v in vals):
                f["nonfinite"] += 1
                continue
            vmax = max(vmax, math.sqrt(sum(float(vals[i]) ** 2 for i in iv)))
        f["vmax"] = vmax
    return f


# Families whose domain holds every particle of a right answer: mass removed there left through
# the wall (or the material flew off faster than it can): non-physical.
CONTAINED = ("cfl disk", "ppc", "empty hole", "tiny onto wall", "contrast", "cfl bar", "tiny",
             "empty stretch", "graded", "long", "implicit")


def verdict(r, f, bound, family, limit=0.05):
    if r["stage"] == "mpm-prep" or r["status"] == 2:
        return "refused" if r["status"] == 2 else "CRASH"
    if r["status"] in (3, 5):  # 5: a particle left the domain with on_exit = "stop"
        return "stopped"
    if r["status"] != 0:
        return "CRASH"
    if f["nonfinite"] or f["growth"] > limit or not f["vmax"] <= bound:
        return "SILENT"
    if f["removed_mass"] > 0 and family.startswith(CONTAINED):
        return "SILENT"
    return "ran"


def main():
    args = sys.argv[1:]
    select = None
    if "--select" in args:
        i = args.index("--select")
        select = re.compile(args[i + 1])
        del args[i:i + 2]
    no_long = "--no-long" in args
    args = [a for a in args if a != "--no-long"]
    bin_dir = os.path.abspath(args[0])
    d = os.path.abspath(args[1] if len(args) > 1 else "study")
    os.makedirs(d, exist_ok=True)
    todo = cases() + implicit_cases() + ([] if no_long else long_cases()) + control_cases()
    fields = ["n", "family", "case", "param", "scheme", "verdict", "exit", "steps",
              "energy_error", "energy_growth", "kinetic_end", "vmax", "bound", "removed_mass",
              "cpu_s", "message"]
    out = open(f"{d}/cases.csv", "w", newline="")
    w = csv.DictWriter(out, fieldnames=fields)
    w.writeheader()
    counts = {}
    for n, (fam, label, param, scheme, text, bound) in enumerate(todo):
        if select and not select.search(f"{fam} {label} {scheme}"):
            continue
        tag = f"case_{n:03d}"
        r = run(bin_dir, text, tag, d)
        has_result = r.get("result") and os.path.exists(r["result"])
        f = measure(bin_dir, r["result"], bound) if has_result else no_figures()
        v = verdict(r, f, bound, fam)
        counts[v] = counts.get(v, 0) + 1
        if r.get("result") and os.path.exists(r["result"]):
            os.remove(r["result"])
        for ext in (".time",):
            if os.path.exists(f"{d}/{tag}{ext}"):
                os.remove(f"{d}/{tag}{ext}")
        if v == "ran":
            os.remove(f"{d}/{tag}.toml")  # kept for the others: the case to look at
        w.writerow(dict(n=n, family=fam, case=label, param=param, scheme=scheme, verdict=v,
                        exit=r["status"], steps=f["steps"], energy_error=f"{f['energy_error']:.3g}",
                        energy_growth=f"{f['growth']:.3g}", kinetic_end=f"{f['kinetic_end']:.3g}",
                        vmax=f"{f['vmax']:.4g}",
                        bound=f"{bound:.4g}", removed_mass=f"{f['removed_mass']:.3g}", cpu_s=f"{r.get('cpu_s', float('nan')):.3g}",
                        message=r["message"].replace("\n", " ") if v != "ran" else ""))
        out.flush()
        print(f"{n:3d} {fam:22s} {label:16s} {scheme:8s} {v:8s} E {f['energy_error']:+.2e} "
              f"v {f['vmax']:.3g}/{bound:.3g} {r['message'][:110] if v != 'ran' else ''}",
              file=sys.stderr, flush=True)
    print(counts)


if __name__ == "__main__":
    main()
