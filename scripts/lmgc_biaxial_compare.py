#!/usr/bin/env python3
"""Compares runs of LMGC90's biaxial test (scenes from scripts/lmgc_biaxial.py) with
each other and with LMGC90's iteration counts.

    python3 scripts/lmgc_biaxial_compare.py REF_DIR [OTHER_DIR ...]
    python3 scripts/lmgc_biaxial_compare.py --seeds SEED_DIR,SEED_DIR,... [OTHER_DIR ...]

For each run: mean NLGS sweeps per step (all steps, and per ε1 range as in LMGC90's
README), mean time per step of the stages (history.csv's t_* columns), and the RMS
and max deviation of sin φ(ε1) (centred moving average over 51 steps) and ν(ε1)
from the first run's curves.

With --seeds (runs of the same solver that differ by the seed of their contact
permutations only), the curves are compared with the seeds' mean instead: each
seed by its distance to the mean of the *other* seeds (leave one out: the test's
own scatter), every other run by its distance to the mean of all the seeds.
"""
import csv
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from study_common import deviation, smooth  # noqa: E402

LMGC = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "shared", "data", "lmgc_biaxial", "iterations.csv")
RANGES = [(0.0, 0.005), (0.005, 0.03), (0.03, 0.1), (0.1, 0.2), (0.2, 0.35)]


def number(v):
    """A history value as a float (NaN for an empty or non-numeric one, e.g. a method's name)."""
    try:
        return float(v)
    except ValueError:
        return float("nan")


def rows_of(d):
    with open(os.path.join(d, "history.csv")) as f:
        return [{k: number(v) for k, v in r.items()} for r in csv.DictReader(f)]


def by_range(eps, vals):
    out = []
    for lo, hi in RANGES:
        sel = [v for e, v in zip(eps, vals) if lo <= e < hi]
        out.append(sum(sel) / len(sel) if sel else float("nan"))
    return out


def lmgc():
    steps, eps, it = [], [], []
    prev = 0
    with open(LMGC) as f:
        for r in csv.DictReader(f):
            s = int(r["step"])
            n = s - prev
            prev = s
            steps.append(n)
            eps.append(float(r["eps1"]))
            it.append(float(r["mean_nlgs_iter"]))
    total = sum(n * i for n, i in zip(steps, it)) / sum(steps)
    ranges = []
    for lo, hi in RANGES:
        w = [(n, i) for n, e, i in zip(steps, eps, it) if lo <= e < hi]
        ranges.append(sum(n * i for n, i in w) / sum(n for n, _ in w) if w else float("nan"))
    return total, ranges


def curves(d):
    rows = rows_of(d)
    eps = [r["eps1"] for r in rows]
    return (eps, smooth([r["sin_phi"] for r in rows], 25)), (eps, [r["solid_fraction"] for r in rows])


def mean_curve(cs, npts=400):
    """The mean of curves (x, y) on a common grid of x (linear interpolation)."""
    lo, hi = max(c[0][0] for c in cs), min(c[0][-1] for c in cs)
    grid = [lo + (hi - lo) * i / (npts - 1) for i in range(npts)]

    def at(xs, ys, x):
        import bisect

        k = min(max(bisect.bisect_left(xs, x) - 1, 0), len(xs) - 2)
        a, b = xs[k], xs[k + 1]
        return ys[k] if b == a else ys[k] + (ys[k + 1] - ys[k]) * (x - a) / (b - a)

    return grid, [sum(at(c[0], c[1], x) for c in cs) / len(cs) for x in grid]


def scatter(seeds, others):
    """Distances of sin φ(ε1) and ν(ε1) to the seeds' mean (leave one out for a seed)."""
    cs = {d: curves(d) for d in seeds + others}
    print("| run | RMS dev sin φ from the seeds' mean | max | RMS dev ν | max |")
    print("|---|---|---|---|---|")
    for d in seeds + others:
        pool = [cs[e] for e in seeds if e != d]
        sin_ref, nu_ref = mean_curve([c[0] for c in pool]), mean_curve([c[1] for c in pool])
        a, b = deviation(sin_ref, cs[d][0])
        c, e = deviation(nu_ref, cs[d][1])
        tag = " (seed, leave one out)" if d in seeds else ""
        print(f"| {d}{tag} | {a:.4f} | {b:.4f} | {c:.5f} | {e:.5f} |")


def main():
    args = sys.argv[1:]
    seeds = []
    if args[:1] == ["--seeds"] and len(args) > 1:
        seeds, args = args[1].split(","), args[2:]
    dirs = seeds + args
    if not dirs:
        sys.exit(__doc__)
    if seeds:
        scatter(seeds, args)
        print()
    total, ranges = lmgc()
    head = "| run | steps | sweeps/step | " + " | ".join(f"ε1 {lo}–{hi}" for lo, hi in RANGES) + " | s/step (detect+delassus+nlgs+update) | RMS dev sin φ | max dev sin φ | RMS dev ν | max dev ν |"
    print(head)
    print("|" + "---|" * (head.count("|") - 1))
    print(f"| LMGC90 | 14050 | {total:.1f} | " + " | ".join(f"{x:.0f}" for x in ranges) + " | 0.090 (wall) | | | | |")
    ref = None
    for d in dirs:
        rows = rows_of(d)
        eps = [r["eps1"] for r in rows]
        sw = [r["sweeps"] for r in rows]
        t = sum(r["t_detect"] + r["t_delassus"] + r["t_nlgs"] + r["t_update"] for r in rows) / len(rows)
        sin = (eps, smooth([r["sin_phi"] for r in rows], 25))
        nu = (eps, [r["solid_fraction"] for r in rows])
        if ref is None:
            ref = (sin, nu)
            dev = ("", "", "", "")
        else:
            a, b = deviation(ref[0], sin)
            c, e = deviation(ref[1], nu)
            dev = (f"{a:.4f}", f"{b:.4f}", f"{c:.5f}", f"{e:.5f}")
        print(
            f"| {d} | {len(rows)} | {sum(sw) / len(sw):.1f} | "
            + " | ".join(f"{x:.0f}" for x in by_range(eps, sw))
            + f" | {t:.4f} | "
            + " | ".join(dev)
            + " |"
        )


if __name__ == "__main__":
    main()
