#!/usr/bin/env python3
"""Identify a homogenized continuum's parameters from a biaxial test of grains.

Reads the history.csv of a 2D biaxial run with a box sample (`[output] box` with
`strain_from`, e.g. examples/scenes/biaxial.toml: constant lateral pressure σ3, the
top wall driven down) and prints, for the plane-strain continuum of
docs/CONTINUUM.md:

(σ, ε3 and sin φ smoothed over 51 steps.)

- E50 and ν: the secant response up to half the peak deviator q = σ1 − σ3 (the
  usual E50 of soil mechanics). In plane strain with σ3 constant,
  Δσ1 = E/(1 − ν²) Δε1 and Δε3 = −ν/(1 − ν) Δε1, so ν' = −Δε3/Δε1 gives
  ν = ν'/(1 + ν') and E = (1 − ν²) q50/ε1(q50). Rigid grains have no elastic
  modulus: E50 is the apparent stiffness of their rearrangements, proportional to
  the confining pressure (printed as E50/σ3, to scale to another pressure). The
  secant at ε1 = 1 % (E1%/σ3) is also printed: q(ε1) is flat near its peak, so
  E50 moves with the step-to-step noise; the recommendation uses E1%.
- φ: the peak friction angle asin(max sin φ) (Drucker–Prager's `friction`), and
  the critical-state angle (mean over the last fifth of the test).
- ψ: the dilatancy angle at the peak, sin ψ = −ε̇v/(2ε̇1 − ε̇v) (compression
  positive, ε_v = ε1 + ε3), from the slope of ε_v over ε1 around the peak.

Usage: identify_continuum.py RUN/history.csv [RUN2/history.csv ...]
(several runs, e.g. two seeds: each one's values, then their mean and spread).
"""
import csv
import math
import sys


def load(path):
    rows = list(csv.DictReader(open(path)))
    f = lambda r, k: float(r[k])
    # the loading phase: ε1 grows from 0
    start = next(i for i, r in enumerate(rows) if f(r, "eps1") > 0.0)
    base = rows[start - 1] if start > 0 else rows[start]
    w0 = f(base, "right_x") - f(base, "left_x")
    out = []
    for r in rows[start:]:
        e1 = f(r, "eps1")
        e3 = -((f(r, "right_x") - f(r, "left_x")) - w0) / w0
        out.append((e1, e3, f(r, "sigma_yy"), f(r, "sigma_xx"), f(r, "sin_phi")))
    return out


def smooth(d, k=51):
    """Moving average over k steps (the wall forces fluctuate from step to step;
    docs/BIAXIAL.md smooths sin φ the same way)."""
    h = k // 2
    out = []
    for i in range(len(d)):
        w = d[max(0, i - h) : i + h + 1]
        out.append(tuple(sum(x[j] for x in w) / len(w) for j in range(len(d[0]))))
    return out


def identify(path):
    d = smooth(load(path))
    s3 = sum(x[3] for x in d) / len(d)
    q = [x[2] - x[3] for x in d]
    ipk = max(range(len(d)), key=lambda i: q[i])
    # the test starts from an isotropic state (q = 0); the first steps' q (5–7 kPa
    # at 10 kPa) is the inertial transient of the platen's start, which the
    # smoothing would spread into a false offset (it made E 2–3× too low)
    q0 = 0.0
    i50 = next(i for i in range(len(d)) if q[i] - q0 >= 0.5 * (q[ipk] - q0))
    e1, e3 = d[i50][0], d[i50][1]
    nu1 = -e3 / e1
    nu = min(nu1 / (1.0 + nu1), 0.49)
    e50 = (1.0 - nu * nu) * (q[i50] - q0) / e1
    # the secant at ε1 = 1 % (less sensitive to the flat top of q(ε1))
    i1 = next((i for i in range(len(d)) if d[i][0] >= 0.01), len(d) - 1)
    e1pc = (1.0 - nu * nu) * (q[i1] - q0) / d[i1][0]
    sphi = max(x[4] for x in d)
    tail = d[int(0.8 * len(d)):]
    scs = sum(x[4] for x in tail) / len(tail)
    # dilatancy: slope of ε_v over ε1 in a window around the peak
    lo, hi = max(0, ipk - len(d) // 20), min(len(d) - 1, ipk + len(d) // 20)
    dv = (d[hi][0] + d[hi][1]) - (d[lo][0] + d[lo][1])
    d1 = d[hi][0] - d[lo][0]
    rate = dv / d1 if d1 > 0 else 0.0
    spsi = max(0.0, -rate / (2.0 - rate))
    return {
        "sigma3": s3,
        "E50": e50,
        "E50/sigma3": e50 / s3,
        "E1%/sigma3": e1pc / s3,
        "nu": nu,
        "phi_peak": math.degrees(math.asin(sphi)),
        "phi_cs": math.degrees(math.asin(scs)),
        "psi": math.degrees(math.asin(spsi)),
        "eps1_50": e1,
    }


def main():
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    res = []
    for p in sys.argv[1:]:
        r = identify(p)
        res.append(r)
        print(p + ": " + ", ".join(f"{k} = {v:.4g}" for k, v in r.items()))
    if len(res) > 1:
        print("mean (spread):")
        for k in res[0]:
            v = [r[k] for r in res]
            m = sum(v) / len(v)
            print(f"  {k} = {m:.4g} ({max(v) - min(v):.2g})")
    m = {k: sum(r[k] for r in res) / len(res) for k in res[0]}
    print(
        "\n[[continuum]] at a confining pressure σ3 (Pa): young = "
        f"{m['E1%/sigma3']:.3g} × σ3 (secant at ε1 = 1 %), poisson = {m['nu']:.2f}, "
        f"plastic = {{ friction = {m['phi_peak']:.1f}, dilatancy = {m['psi']:.1f} }}"
    )


if __name__ == "__main__":
    main()
