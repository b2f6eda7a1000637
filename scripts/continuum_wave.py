#!/usr/bin/env python3
"""Plots docs/continuum_wave.png from docs/continuum_wave.csv and
docs/continuum_wave_unshared.csv (docs/CONTINUUM.md, waves): the reflected energy
fraction of a pulse crossing the band against the band's width, per mesh size and
coupling, with and without the contacts' stiffness shared.

Make the CSVs with
  cargo test --release -p nscdd-fem-deformable --test continuum_wave wave_study -- --ignored --nocapture
(the lines from `band_d,…` on). Needs matplotlib (scripts/biaxial_study.sh
installs it in .venv-docs).
"""
import csv
import os

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def rows(name):
    with open(os.path.join(ROOT, "docs", name)) as f:
        return [r for r in csv.DictReader(f)]


def main():
    shared, unshared = rows("continuum_wave.csv"), rows("continuum_wave_unshared.csv")
    fig, ax = plt.subplots(1, 2, figsize=(11, 4.2))
    colors = {"1": "tab:blue", "2": "tab:orange", "4": "tab:green"}
    for data, style, label in ((shared, "-", "shared"), (unshared, ":", "not shared")):
        for coupling, a in (("node", ax[0]), ("grain", ax[1])):
            for cell in ("1", "2", "4"):
                pts = [r for r in data if r["coupling"] == coupling and r["cell_d"] == cell and r["q"] == "1"
                       and float(r.get("share") or 0) == 0]
                pts.sort(key=lambda r: float(r["band_d"]))
                a.plot(
                    [float(r["band_d"]) for r in pts],
                    [max(float(r["reflected"]), 1e-7) for r in pts],
                    style,
                    marker="o",
                    color=colors[cell],
                    label=f"cells {cell} d, stiffness {label}",
                )
    for a, coupling in zip(ax, ("node", "grain")):
        a.axhline(0.05, color="k", lw=0.8, ls="--")
        a.text(1.0, 0.055, "target 5 %", fontsize=8)
        a.set_yscale("log")
        a.set_xlabel("band width (grain diameters)")
        a.set_ylabel("reflected energy / pulse energy")
        a.set_title(f"coupling = \"{coupling}\", E = k (matched)")
        a.grid(True, which="both", alpha=0.3)
    ax[0].legend(fontsize=7)
    fig.tight_layout()
    out = os.path.join(ROOT, "docs", "continuum_wave.png")
    fig.savefig(out, dpi=110)
    print(out)


if __name__ == "__main__":
    main()
