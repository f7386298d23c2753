#!/usr/bin/env python3
"""The Hugoniot of a Tillotson material against a linear Us-up fit (docs/eos-tillotson.md).

For each particle velocity u_p, finds the density rho on Tillotson's Hugoniot, where
p = p_c(rho, E) with E = p (1/rho0 - 1/rho) / 2 (Rankine-Hugoniot energy from rest), and
u_p^2 = p (1/rho0 - 1/rho), and prints its pressure beside the fit's rho0 (c0 + s u_p) u_p.
Usage: tillotson_hugoniot.py {lead,aluminium}
"""
import sys

SETS = {  # rho0, a, b, A, B, E0; fit c0, s (m/s)
    "lead": dict(rho0=11350.0, a=0.5, b=2.27, A=47.745e9, B=25.544e9, E0=0.942e6, c0=2051.0, s=1.46),
    "aluminium": dict(rho0=2700.0, a=0.5, b=1.63, A=75.2e9, B=65e9, E0=5.0e6, c0=5350.0, s=1.34),
}


def p_compressed(m, rho, E):
    eta = rho / m["rho0"]
    mu = eta - 1
    omega = E / (m["E0"] * eta * eta) + 1
    return (m["a"] + m["b"] / omega) * rho * E + m["A"] * mu + m["B"] * mu * mu


def hugoniot_pressure(m, rho):
    p = 0.0
    for _ in range(300):  # fixed point p = p_c(rho, p (1/rho0 - 1/rho) / 2); converges geometrically
        p = p_compressed(m, rho, 0.5 * p * (1 / m["rho0"] - 1 / rho))
    return p


def state_at(m, up):
    lo, hi = m["rho0"] * (1 + 1e-9), m["rho0"] * 2.5
    for _ in range(80):
        mid = 0.5 * (lo + hi)
        if hugoniot_pressure(m, mid) * (1 / m["rho0"] - 1 / mid) > up * up:
            hi = mid
        else:
            lo = mid
    return hugoniot_pressure(m, lo)


if __name__ == "__main__":
    m = SETS[sys.argv[1] if len(sys.argv) > 1 else "lead"]
    print("u_p km/s | Tillotson GPa | fit GPa | difference")
    for up in (500.0, 1000.0, 2000.0, 3000.0, 3290.0):
        fit = m["rho0"] * (m["c0"] + m["s"] * up) * up
        p = state_at(m, up)
        print(f"{up / 1e3:.2f} | {p / 1e9:.2f} | {fit / 1e9:.2f} | {100 * (p / fit - 1):+.1f}%")
