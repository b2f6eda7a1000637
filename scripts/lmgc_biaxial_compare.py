#!/usr/bin/env python3
"""Compares runs of LMGC90's biaxial test (scenes from scripts/lmgc_biaxial.py) with
each other and with LMGC90's iteration counts.

    python3 scripts/lmgc_biaxial_compare.py REF_DIR [OTHER_DIR ...]

For each run: mean NLGS sweeps per step (all steps, and per ε1 range as in LMGC90's
README), mean time per step of the stages (history.csv's t_* columns), and the RMS
and max deviation of sin φ(ε1) (centred moving average over 51 steps) and ν(ε1)
from the first run's curves.
"""
import csv
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from study_common import deviation, smooth  # noqa: E402

LMGC = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "shared", "data", "lmgc_biaxial", "iterations.csv")
RANGES = [(0.0, 0.005), (0.005, 0.03), (0.03, 0.1), (0.1, 0.2), (0.2, 0.35)]


def rows_of(d):
    with open(os.path.join(d, "history.csv")) as f:
        return [{k: float(v) if v not in ("", "NaN") else float("nan") for k, v in r.items()} for r in csv.DictReader(f)]


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


def main():
    dirs = sys.argv[1:]
    if not dirs:
        sys.exit(__doc__)
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
