#!/usr/bin/env python3
"""The footing of examples/scenes/footing.toml against its all-discrete reference
(docs/CONTINUUM.md): load–penetration curves and times.

Usage: continuum_footing.py OUT_DIR [--deep]
Writes OUT_DIR/{hyb,disc}_s{3,5}.toml, runs them (target/release/nscdd, built with
the `fem` feature) one after the other, prints each one's time, sweeps, the footing
force at 5, 10 and 15 mm of penetration and its mean over 0–10, 10–30, 30–50 and
10–50 mm, and plots docs/continuum_footing.png (needs matplotlib:
scripts/biaxial_study.sh installs it in .venv-docs). `--deep`: a 0.6 m layer of
grains above the band (1300 grains; all-discrete 2420 down to -0.5 m), the footing
0.3 m higher (0.03 m lower in the all-discrete run, whose layer settles more),
3.5 s; plots docs/continuum_footing_deep.png.
"""
import csv
import os
import re
import subprocess
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def discrete(text):
    """The all-discrete reference: grains down to y = -0.5 (a floor, taller side
    walls, 1770 grains), no continuum."""
    text = text.replace(
        'name = "left"\nshape = "wall"\nmaterial = "steel"\nposition = [-0.01, 0.25]\nrotation = 1.5707963267948966\nlength = 0.5',
        'name = "left"\nshape = "wall"\nmaterial = "steel"\nposition = [-0.01, -0.1]\nrotation = 1.5707963267948966\nlength = 1.0',
    )
    text = text.replace(
        'name = "right"\nshape = "wall"\nmaterial = "steel"\nposition = [1.01, 0.25]\nrotation = 1.5707963267948966\nlength = 0.5',
        'name = "right"\nshape = "wall"\nmaterial = "steel"\nposition = [1.01, -0.1]\nrotation = 1.5707963267948966\nlength = 1.0',
    )
    text = text.replace(
        "[[bodies]]\nname = \"left\"",
        '[[bodies]]\nname = "floor"\nshape = "wall"\nmaterial = "steel"\nposition = [0.5, -0.51]\nlength = 1.04\nthickness = 0.02\nfixed = true\n\n[[bodies]]\nname = "left"',
    )
    text = text.replace("count = 650", "count = 1770").replace("box = [0.0, 0.0, 1.0, 0.31]", "box = [0.0, -0.5, 1.0, 0.31]")
    return text[: text.index("[[continuum]]")]


def deepen(text, disc):
    """The `--deep` variant of the hybrid or all-discrete scene text."""
    text = text.replace("count = 650", "count = 1300").replace("box = [0.0, 0.0, 1.0, 0.31]", "box = [0.0, 0.0, 1.0, 0.61]")
    text = text.replace("count = 1770", "count = 2420").replace("box = [0.0, -0.5, 1.0, 0.31]", "box = [0.0, -0.5, 1.0, 0.61]")
    text = text.replace("position = [0.5, 0.345]", "position = [0.5, 0.615]" if disc else "position = [0.5, 0.645]")
    for x in ("-0.01", "1.01"):
        text = text.replace(f"position = [{x}, 0.25]\nrotation = 1.5707963267948966\nlength = 0.5", f"position = [{x}, 0.4]\nrotation = 1.5707963267948966\nlength = 0.8")
        text = text.replace(f"position = [{x}, -0.1]\nrotation = 1.5707963267948966\nlength = 1.0", f"position = [{x}, 0.15]\nrotation = 1.5707963267948966\nlength = 1.3")
    return text.replace("duration = 2.0", "duration = 3.5")


def mean_force(d, lo, hi):
    p, _, r = curve(d)
    fy = [float(x["footing_fy"]) for x in r]
    first = len(r) - len(p)
    v = [fy[first + i] for i, x in enumerate(p) if lo <= x <= hi]
    return f"{sum(v) / len(v):.0f}" if v else "-"


def curve(d):
    r = list(csv.DictReader(open(os.path.join(d, "history.csv"))))
    fy = [float(x["footing_fy"]) for x in r]
    y = [float(x["footing_y"]) for x in r]
    first = next(i for i, f in enumerate(fy) if f > 1)
    sm = lambda i: sum(fy[max(0, i - 25) : i + 26]) / len(fy[max(0, i - 25) : i + 26])
    return [(y[first] - y[i]) * 1000 for i in range(first, len(r))], [sm(i) for i in range(first, len(r))], r


def main():
    deep = "--deep" in sys.argv
    args = [a for a in sys.argv[1:] if a != "--deep"]
    out = args[0] if args else "out/footing_study"
    os.makedirs(out, exist_ok=True)
    src = open(os.path.join(ROOT, "examples/scenes/footing.toml")).read()
    env = dict(os.environ, NSCDD_PYTHON_ENV=os.environ.get("NSCDD_PYTHON_ENV", os.path.join(ROOT, "venv")))
    runs = []
    for seed in (3, 5):
        for kind, text in (("hyb", src), ("disc", discrete(src))):
            if deep:
                text = deepen(text, kind == "disc")
            name = f"{kind}_s{seed}"
            path = os.path.join(out, name + ".toml")
            open(path, "w").write(re.sub(r"(?m)^seed = 3$", f"seed = {seed}", text))
            t0 = time.time()
            subprocess.run([os.path.join(ROOT, "target/release/nscdd"), "run", path, "--out", os.path.join(out, name), "--quiet"], env=env, check=True)
            runs.append((name, time.time() - t0))
    curves = {}
    for name, wall in runs:
        p, f, r = curve(os.path.join(out, name))
        curves[name] = (p, f)
        sweeps = sum(int(float(x["sweeps"])) for x in r)
        at = []
        for mm in (5, 10, 15):
            k = next((i for i, x in enumerate(p) if x >= mm), None)
            at.append(f"{f[k]:.0f}" if k is not None else "-")
        means = " / ".join(mean_force(os.path.join(out, name), lo, hi) for lo, hi in ((0, 10), (10, 30), (30, 50), (10, 50)))
        print(f"{name}: {wall:.1f} s, {sweeps} sweeps, bodies {r[0]['bodies']}, force at 5/10/15 mm: {' / '.join(at)} N/m, mean over 0-10/10-30/30-50/10-50 mm: {means} N/m")
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        return
    fig, ax = plt.subplots(figsize=(6, 4))
    style = {"disc_s3": ("k-", "all-discrete, seed 3"), "disc_s5": ("k--", "all-discrete, seed 5"), "hyb_s3": ("r-", "grains + continuum, seed 3"), "hyb_s5": ("r--", "grains + continuum, seed 5")}
    for name, (p, f) in curves.items():
        st, lab = style[name]
        ax.plot(p, f, st, label=lab)
    ax.set_xlabel("penetration since first contact (mm)")
    ax.set_ylabel("footing force (N/m, mean over 51 steps)")
    ax.legend()
    fig.tight_layout()
    fig.savefig(os.path.join(ROOT, "docs/continuum_footing_deep.png" if deep else "docs/continuum_footing.png"), dpi=110)


if __name__ == "__main__":
    main()
