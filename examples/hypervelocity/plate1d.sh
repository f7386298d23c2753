#!/usr/bin/env bash
# V4 on the impact axis in 1D (plate1d.toml): the plate's rear-face velocity after the shock
# has crossed it, at cells from the coarse deck's 2.12 mm down to 0.066 mm, with and without
# the gamma0 E term in expansion, and with lead's Tillotson EOS (docs/eos-tillotson.md),
# against the release isentrope of the same equation of state. Prints markdown tables; each
# run takes seconds.
# Usage: ./plate1d.sh BUILD_DIR   (THREADS=N: mpm-run's threads, default 2; TILLOTSON_ONLY=1)
set -euo pipefail
cd "$(dirname "$0")"
bin=$1
mkdir -p out
python3 - "$bin" "${THREADS:-2}" ${TILLOTSON_ONLY:+--tillotson-only} <<'PY'
import csv, io, math, subprocess, sys
bin, threads = sys.argv[1], sys.argv[2]
rho0, c0, s, g0, v = 11350.0, 2092.0, 1.45, 2.0, 6580.0
# Lead's Tillotson constants (docs/eos-tillotson.md): a, b, A, B, E0, E_iv, E_cv, alpha, beta.
TL = dict(a=0.5, b=2.27, A=47.7e9, B=25.5e9, E0=0.942e6, Eiv=0.264e6, Ecv=1.130e6, al=5.0, be=5.0)
TILLOTSON = ('materials.lead.eos={ model = "tillotson", a = 0.5, b = 2.27, A = "47.7 GPa", '
             'B = "25.5 GPa", E0 = "0.942 MJ/kg", E_iv = "0.264 MJ/kg", E_cv = "1.130 MJ/kg", '
             'alpha = 5, beta = 5 }')


def p_tillotson(rho, e):
    """Tillotson's pressure (docs/eos-tillotson.md), e below zero taken as zero."""
    t, E = TL, max(e, 0.0)
    eta = rho / rho0; mu = eta - 1; w = 1 + E / (t["E0"] * eta * eta)
    pc = (t["a"] + t["b"] / w) * rho * E + t["A"] * mu + t["B"] * mu * mu
    if mu >= 0 or E <= t["Eiv"]:
        return pc
    z = 1 / eta - 1
    pe = t["a"] * rho * E + (t["b"] * rho * E / w + t["A"] * mu * math.exp(-t["be"] * z)) * math.exp(-t["al"] * z * z)
    if E >= t["Ecv"]:
        return pe
    return ((E - t["Eiv"]) * pe + (t["Ecv"] - E) * pc) / (t["Ecv"] - t["Eiv"])


def release_tillotson():
    """Free-surface velocity of the Tillotson lead shocked by the symmetric impact at v:
    u_p + integral of dp / (rho c) = sqrt(-dp dV) down the isentrope de = -p dV (trapezoidal
    in p), from the Hugoniot state (p_c(rho, u_p^2 / 2) = rho0 u_p^2 rho / (rho - rho0)) to
    zero pressure, or to rho0 / 10^6 where hot expanded lead is a gas that never reaches it."""
    up = v / 2; eH = 0.5 * up * up
    lo, hi = rho0 * (1 + 1e-9), 4 * rho0
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        if p_tillotson(mid, eH) < rho0 * up * up * mid / (mid - rho0): lo = mid
        else: hi = mid
    rho, e = lo, eH
    P, u, n = p_tillotson(rho, e), up, 400000
    f = math.exp(math.log(1e-6 * rho0 / rho) / n)
    for _ in range(n):
        r2 = rho * f
        e2 = e - P * (1 / r2 - 1 / rho)
        P2 = p_tillotson(r2, e2)
        e2 = e - 0.5 * (P + P2) * (1 / r2 - 1 / rho)   # trapezoidal corrector
        P2 = p_tillotson(r2, e2)
        u += math.sqrt(max(0.0, (P - max(P2, 0.0)) * (1 / r2 - 1 / rho)))
        if P2 <= 0: break
        rho, e, P = r2, e2, P2
    return u, rho, e

def release(eie):
    """Free-surface velocity u_p + integral of dp / (rho c) down the isentrope from the
    Hugoniot state of a symmetric impact at v, for p = p_H(rho) + g0 rho0 (e - e_H(rho))
    in compression (the code's form) and p = rho0 c0^2 mu (+ g0 rho0 e if eie) in expansion."""
    up = v / 2; Us = c0 + s * up
    def p(rho, e):
        eta = 1 - rho0 / rho
        if eta > 0:
            pH = rho0 * c0**2 * eta / (1 - s * eta)**2
            return pH + g0 * rho0 * (e - 0.5 * pH * eta / rho0)
        return rho0 * c0**2 * (rho / rho0 - 1) + (g0 * rho0 * e if eie else 0.0)
    rho, e = rho0 * Us / (Us - up), 0.5 * up**2
    P, u, n = p(rho, e), up, 400000
    d = (rho - 0.05 * rho0) / n
    for _ in range(n):
        r2 = rho - d
        e2 = e - P * (1 / r2 - 1 / rho)          # de = -p dV along the isentrope
        P2 = p(r2, e2)
        u += math.sqrt(max(0.0, (P - max(P2, 0.0)) * (1 / r2 - 1 / rho)))
        if P2 <= 0: break
        rho, e, P = r2, e2, P2
    return u, rho, e

def measure(cell, eie):
    """eie: True / False (Mie-Grueneisen with / without gamma0 E in expansion), or "tillotson"."""
    name = "tillotson" if eie == "tillotson" else ("with" if eie else "without")
    out = f"out/plate1d_{cell}_{name}.mpm"
    sets = ["--set", f"grid.cell_size={cell} mm", "--set",
            TILLOTSON if eie == "tillotson" else
            f"materials.lead.eos.energy_in_expansion={'true' if eie else 'false'}"]
    prep = subprocess.Popen([f"{bin}/mpm-prep/mpm-prep", "plate1d.toml", *sets],
                            stdout=subprocess.PIPE, stderr=subprocess.DEVNULL)
    run = subprocess.run([f"{bin}/mpm-run/mpm-run", "--progress", "none", "--threads", threads, "-o", out],
                         stdin=prep.stdout, capture_output=True, text=True)
    prep.wait()
    if run.returncode != 0:
        return [l for l in run.stderr.splitlines() if "error" in l][0].split("error: ")[1].split(" (limit")[0]
    csvtext = subprocess.run([f"{bin}/mpm-post/mpm-post", "particles", out, "--frame", "last",
                              "--columns", "x,v,m,body"], capture_output=True, text=True).stdout
    rows = list(csv.DictReader(io.StringIO("\n".join(
        l for l in csvtext.splitlines() if not l.startswith("#")))))
    plate = sorted((float(r["x_0"]), float(r["v_0"]), float(r["m"])) for r in rows if r["body"] == "0")
    M = sum(m for _, _, m in plate)
    # The leading 5% of the plate's mass (a column of particles at 1.06 mm cells).
    acc, lead = 0.0, []
    for x, vx, m in reversed(plate):
        if acc >= 0.05 * M: break
        acc += m; lead.append((vx, m))
    v_lead = sum(vx * m for vx, m in lead) / sum(m for _, m in lead)
    v_mean = sum(vx * m for _, vx, m in plate) / M
    steps = run.stderr.strip().splitlines()[-1] if run.stderr.strip() else ""
    return plate[-1][1], v_lead, v_mean, len(rows)

t_arrive = 6.36e-3 / (c0 + s * v / 2)
CELLS = ("2.12", "1.06", "0.53", "0.265", "0.1325", "0.06625")
if "--tillotson-only" not in sys.argv:
    print("| gamma0 E in expansion | cells | particles | rear particle m/s | leading 5% of plate m/s | plate mean m/s | isentrope free surface m/s | front at 30.6 us at the leading 5%'s speed, mm |")
    print("|---|---|---|---|---|---|---|---|")
    for eie in (False, True):
        u, _, _ = release(eie)
        for cell in CELLS:
            r = measure(cell, eie)
            if isinstance(r, str):
                print(f"| {'with' if eie else 'without'} | {cell} mm | stopped: {r} | | | | {u:.0f} | |")
                continue
            v_rear, v_lead, v_mean, n = r
            print(f"| {'with' if eie else 'without'} | {cell} mm | {n} | {v_rear:.0f} | {v_lead:.0f} | "
                  f"{v_mean:.0f} | {u:.0f} | {v_lead * (30.6e-6 - t_arrive) * 1e3:.0f} |", flush=True)

# Tillotson: the same runs with lead's Tillotson EOS, against its own release isentrope.
u, rho_end, e_end = release_tillotson()
print()
print("| EOS | cells | particles | rear particle m/s | leading 5% of plate m/s | plate mean m/s | isentrope free surface m/s | leading 5% vs isentrope |")
print("|---|---|---|---|---|---|---|---|")
for cell in CELLS:
    r = measure(cell, "tillotson")
    if isinstance(r, str):
        print(f"| tillotson | {cell} mm | stopped: {r} | | | | {u:.0f} | |")
        continue
    v_rear, v_lead, v_mean, n = r
    print(f"| tillotson | {cell} mm | {n} | {v_rear:.0f} | {v_lead:.0f} | {v_mean:.0f} | {u:.0f} | "
          f"{100 * (v_lead / u - 1):+.1f}% |", flush=True)
print(f"\n(Tillotson's isentrope ends at rho = {rho_end:.4g} kg/m^3, e = {e_end / 1e6:.3f} MJ/kg.)")
PY
