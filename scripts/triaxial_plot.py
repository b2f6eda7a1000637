"""Plots a 3D triaxial run: q/p, solid fraction and coordination number against eps1.

    python3 scripts/triaxial_plot.py out/triaxial3d [docs/triaxial3d.png]

Reads DIR/history.csv (columns eps1, q_over_p, solid_fraction, nu_bulk, z, z_bulk)
written by `nscdd run examples/scenes/triaxial3d.toml --out DIR`, keeps the loading
phase (eps1 > 0), writes DIR/triaxial.csv (those columns) and the PNG (default
DIR/triaxial.png). Needs matplotlib (scripts/*.sh install it in .venv-docs).
"""
import csv
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

COLS = ["eps1", "q_over_p", "solid_fraction", "nu_bulk", "z", "z_bulk"]


def smooth(xs, width=5):
    out = []
    for i in range(len(xs)):
        a, b = max(0, i - width), min(len(xs), i + width + 1)
        out.append(sum(xs[a:b]) / (b - a))
    return out


def main():
    d = sys.argv[1]
    png = sys.argv[2] if len(sys.argv) > 2 else os.path.join(d, "triaxial.png")
    rows = [r for r in csv.DictReader(open(os.path.join(d, "history.csv"))) if float(r["eps1"]) > 0]
    if not rows:
        sys.exit(f"{d}/history.csv has no loading phase (eps1 > 0)")
    with open(os.path.join(d, "triaxial.csv"), "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(COLS)
        for r in rows:
            w.writerow([r[c] for c in COLS])
    e = [float(r["eps1"]) for r in rows]
    col = lambda c: [float(r[c]) for r in rows]  # noqa: E731
    fig, ax = plt.subplots(1, 3, figsize=(13, 3.8))
    ax[0].plot(e, smooth(col("q_over_p")))
    ax[0].set_ylabel("q / p")
    ax[1].plot(e, col("solid_fraction"), label="whole box")
    ax[1].plot(e, smooth(col("nu_bulk")), label="bulk (4 radii from the walls)")
    ax[1].set_ylabel("solid fraction")
    ax[1].legend(fontsize=8)
    ax[2].plot(e, smooth(col("z")), label="z (grain-grain)")
    ax[2].plot(e, smooth(col("z_bulk")), label="z bulk, no rattlers")
    ax[2].set_ylabel("coordination number")
    ax[2].legend(fontsize=8)
    for a in ax:
        a.set_xlabel("ε1")
    fig.tight_layout()
    fig.savefig(png, dpi=110)
    print("wrote", png, "and", os.path.join(d, "triaxial.csv"))


if __name__ == "__main__":
    main()
