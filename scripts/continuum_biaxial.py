#!/usr/bin/env python3
"""The biaxial test with continuum outer parts against its all-discrete reference
(docs/CONTINUUM.md): sin φ(ε1) and times.

Usage: continuum_biaxial.py OUT_DIR [--young E ...] [--hardening PHI0 KAPPA_H [PHI]] [--grain-share S] [--seeds 7,11,...] [--example]

For each seed (`--seeds`, default 7 and 11): runs examples/scenes/biaxial.toml (2000 disks, 0.3 s of
isotropic compaction at 10 kPa, then the top wall at 0.05 m/s), and its
compaction alone (0.3 s); builds from the compacted grains the hybrid sample
(`hybrid_scene`): a discrete core 0.2 < y < 0.3 with 5 cm bands on either side
(the grains 0.15 < y < 0.35, about 800), two Drucker–Prager regions below and
above (cells of 2.5 cm, φ = 15.1° (the critical-state angle of
scripts/identify_continuum.py), at the isotropic 10 kPa from the start:
`initial_stress`),
σ3 on the regions' sides (`load`) and on the grains' right walls (the core's at
σ3, the bands' 1 cm segments at (1 − α) σ3: the grains' share), the top side driven down at
0.05 m/s on a frictionless platen (`drive = { top = ["free", -0.05] }`), the
bottom side on a frictionless base. Prints sin φ at ε1 = 0.5 … 9.5 % (means over
±0.25 %), each run's time and sweeps, and the RMS distances: between the
discrete seeds (with more than two, each discrete seed's distance to the mean of
the others: the scatter a hybrid's distance to the mean of all is measured
against) and of each hybrid to the discrete mean; plots
docs/continuum_biaxial.png (matplotlib: scripts/biaxial_study.sh installs it in
.venv-docs). `--young`: the regions' E (Pa; default 4e5 6e5 8e5: E at 1 %, 60 σ3,
E50 of scripts/identify_continuum.py on the two seeds). `--hardening PHI0 KAPPA_H [PHI]`: the regions' friction angle grows from
PHI0 to PHI (default 15.1°) with the plastic shear strain (half-way at
KAPPA_H). `--grain-share S`: the bands' `grain_share` (a band grain keeps at
least the share S of its mass; the continuum's weight is at most 1 − S in the
band). `--seeds`: the deposit seeds (comma-separated; some seeds' deposits do
not fit 2000 disks in the box: the run stops naming the seed's scene).
`--example`: writes examples/scenes/biaxial_continuum.toml (the first seed,
the first `--young`) and stops.
Needs target/release/nscdd built with the `fem` feature and NSCDD_PYTHON_ENV.
"""
import csv
import itertools
import json
import os
import subprocess
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
NSCDD = os.path.join(ROOT, "target", "release", "nscdd")
S3, V = 1e4, 0.05
Y1, Y2, BW, CELL = 0.2, 0.3, 0.05, 0.025
PHI = 15.1
# friction hardening (--hardening PHI0 KAPPA_H [PHI]): None, or (φ0, κ_h)
HARD = None
# the bands' grain_share (--grain-share S)
SHARE = 0.0
# the regions' dilatancy angle ψ (°; scripts/continuum_biaxial_fit.py varies it)
PSI = 4.0


def run(scene, out):
    t = time.time()
    r = subprocess.run([NSCDD, "run", scene, "--out", out], capture_output=True, text=True)
    if r.returncode != 0:
        sys.exit(f"{scene}: {r.stderr}")
    sweeps = sum(int(float(x["sweeps"])) for x in csv.DictReader(open(os.path.join(out, "history.csv"))))
    return time.time() - t, sweeps


def region(name, y0, y1, band_c, band_d, drive, width, young, nu):
    nx, ny = round(width / CELL), max(1, round((y1 - y0) / CELL))
    return f"""
[[continuum]]
name = "{name}"
material = "ground"
young = {young!r}
poisson = {nu!r}
plastic = {plastic()}
initial_stress = [{-S3!r}, {-S3!r}, 0.0]
load = {{ left = [{S3!r}, 0.0], right = [{-S3!r}, 0.0] }}
drive = {drive}
mesh = {{ rectangle = {{ origin = [0.0, {y0!r}], size = [{width!r}, {y1 - y0!r}], cells = [{nx}, {ny}] }} }}
band = {{ normal = [0.0, 1.0], continuum = {band_c!r}, discrete = {band_d!r}{share()} }}
"""


def share():
    return f", grain_share = {SHARE!r}" if SHARE > 0 else ""


def plastic():
    h = "" if HARD is None else f", initial_friction = {HARD[0]!r}, hardening_strain = {HARD[1]!r}"
    return f"{{ friction = {PHI!r}, dilatancy = {PSI!r}{h} }}"


def right_walls(width):
    """The grains' right side: a wall per segment, each pushed by its share of σ3
    (the core at σ3, the bands' 1 cm segments at (1 − α(y_mid)) σ3, α at most
    1 − `grain_share`)."""
    segs = [(Y1, Y2, 1.0)]
    n = round(BW / 0.01)
    for k in range(n):
        a = min((k + 0.5) / n, 1.0 - SHARE)  # α at the segment's middle, from the core outwards
        segs.append((Y1 - (k + 1) * BW / n, Y1 - k * BW / n, 1.0 - a))
        segs.append((Y2 + k * BW / n, Y2 + (k + 1) * BW / n, 1.0 - a))
    out = ""
    for i, (a, b, share) in enumerate(sorted(segs)):
        out += f"""
[[bodies]]
name = "right{i}"
shape = "wall"
material = "wall_v"
position = [{width + 0.01!r}, {0.5 * (a + b)!r}]
rotation = 1.5707963267948966
length = {b - a!r}
thickness = 0.02
drive.y = {{ velocity = 0.0 }}
drive.rot = {{ velocity = 0.0 }}
drive.x = {{ force = {-S3 * share * (b - a)!r} }}
"""
    return out


def hybrid_scene(final, young, nu=0.42, header=""):
    """The hybrid scene from a compacted sample's final.json (module docs)."""
    bodies = json.load(open(final))["bodies"]
    top = next(b for b in bodies if b.get("name") == "top")["position"][1] - 0.01
    width = next(b for b in bodies if b.get("name") == "right")["position"][0] - 0.01
    lo, hi = Y1 - BW, Y2 + BW
    grains = [b for b in bodies if b["kind"] == "disk" and lo + 1e-4 < b["position"][1] < hi - 1e-4]
    s = header + f"""gravity = [0.0, 0.0]

[time]
step = 5e-4
theta = 0.5
duration = 1.0

[solver]
tolerance = 1e-3
norm = "Quad"
max_sweeps = 1000
check_every = 10

[detection]
alert = 5e-4

[output]
every = 100

[[materials]]
name = "grain"
density = 2600.0

[[materials]]
name = "wall_v"
density = 2600.0

# the homogenized medium: solid fraction 0.8 × 2600 kg/m³
[[materials]]
name = "ground"
density = 2080.0

[[laws]]
materials = ["grain", "grain"]
friction = 0.5

[[laws]]
materials = ["grain", "wall_v"]
law = "frictionless"

[[laws]]
materials = ["wall_v", "wall_v"]
law = "none"

[[bodies]]
name = "left"
shape = "wall"
material = "wall_v"
position = [-0.01, {0.5 * (lo + hi)!r}]
rotation = 1.5707963267948966
length = {hi - lo + 0.1!r}
thickness = 0.02
fixed = true

# σ3 on the grains' side: the core's wall at full σ3, the bands' walls (1 cm
# segments) at their share (1 − α) σ3 (the regions carry α σ3 on their sides)
{right_walls(width)}
bodies = [
"""
    s = s.replace("\nbodies = [\n", "\n")
    for g in grains:
        x, y = g["position"]
        s += f'[[bodies]]\nshape = "disk"\nmaterial = "grain"\nradius = {g["shape"]["radius"]!r}\nposition = [{x!r}, {y!r}]\n'
    s += region("bottom_region", 0.0, Y1, Y1 - BW, Y1, '{ bottom = ["free", 0.0] }', width, young, nu)
    s += region("top_region", Y2, top, Y2 + BW, Y2, f'{{ top = ["free", {-V!r}] }}', width, young, nu)
    return s, width, top, len(grains)


def discrete_curve(path):
    rows = list(csv.DictReader(open(path)))
    return [(float(r["eps1"]), float(r["sin_phi"])) for r in rows if float(r["time"]) >= 0.3]


def hybrid_curve(path, width, height):
    out = []
    for r in csv.DictReader(open(path)):
        s1 = -float(r["top_region_top_fy"]) / width
        out.append((V * float(r["time"]) / height, (s1 - S3) / (s1 + S3)))
    return out


def at(c, e, w=0.0025):
    v = [s for (x, s) in c if abs(x - e) <= w]
    return sum(v) / len(v) if v else float("nan")


EPS = [0.005 * k for k in range(1, 20)]


def rms(a, b):
    d = [(at(a, e) - at(b, e)) ** 2 for e in EPS]
    return (sum(d) / len(d)) ** 0.5


def mean_curve(cs):
    """The mean of curves `cs`, at the ε1 of EPS."""
    return [(e, sum(at(c, e) for c in cs) / len(cs)) for e in EPS]


def main():
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    out = sys.argv[1]
    youngs = [float(x) for x in itertools.takewhile(lambda a: not a.startswith("--"), sys.argv[sys.argv.index("--young") + 1 :])] if "--young" in sys.argv else [4e5, 6e5, 8e5]
    if "--hardening" in sys.argv:
        global HARD, PHI
        i = sys.argv.index("--hardening")
        args = [float(x) for x in sys.argv[i + 1 : i + 4] if not x.startswith("--")]
        HARD = (args[0], args[1])
        if len(args) > 2:
            PHI = args[2]
    if "--grain-share" in sys.argv:
        global SHARE
        SHARE = float(sys.argv[sys.argv.index("--grain-share") + 1])
    seeds = [int(x) for x in sys.argv[sys.argv.index("--seeds") + 1].split(",")] if "--seeds" in sys.argv else [7, 11]
    os.makedirs(out, exist_ok=True)
    base = open(os.path.join(ROOT, "examples", "scenes", "biaxial.toml")).read()
    curves, times = {}, {}
    for seed in seeds:
        text = base.replace("seed = 7", f"seed = {seed}")
        comp = os.path.join(out, f"compact_{seed}.toml")
        open(comp, "w").write(text.replace("duration = 1.3", "duration = 0.3"))
        run(comp, os.path.join(out, f"compact_{seed}"))
        final = os.path.join(out, f"compact_{seed}", "final.json")
        if "--example" in sys.argv:
            header = open(os.path.join(ROOT, "scripts", "continuum_biaxial_header.txt")).read()
            s, *_ = hybrid_scene(final, youngs[0], header=header)
            path = os.path.join(ROOT, "examples", "scenes", "biaxial_continuum.toml")
            open(path, "w").write(s)
            print(path)
            return
        disc = os.path.join(out, f"disc_{seed}.toml")
        open(disc, "w").write(text)
        t, sw = run(disc, os.path.join(out, f"disc_{seed}"))
        rows = list(csv.DictReader(open(os.path.join(out, f"disc_{seed}", "history.csv"))))
        load_t = sum(float(r["t_detect"]) + float(r["t_delassus"]) + float(r["t_nlgs"]) + float(r["t_update"]) for r in rows if float(r["time"]) > 0.3)
        curves[f"discrete {seed}"] = discrete_curve(os.path.join(out, f"disc_{seed}", "history.csv"))
        times[f"discrete {seed}"] = (t, sw, load_t)
        for e in youngs:
            s, width, height, n = hybrid_scene(final, e)
            name = f"hyb_{seed}_{e:g}"
            label = f"hybrid {seed} E={e:g}" + ("" if HARD is None else f" φ {HARD[0]:g}→{PHI:g}° κh {HARD[1]:g}")
            open(os.path.join(out, name + ".toml"), "w").write(s)
            t, sw = run(os.path.join(out, name + ".toml"), os.path.join(out, name))
            curves[label] = hybrid_curve(os.path.join(out, name, "history.csv"), width, height)
            times[label] = (t, sw, t)
            print(f"{name}: {n} grains, {t:.1f} s, {sw} sweeps", flush=True)
    names = list(curves)
    print("eps1   " + " ".join(f"{n:>20}" for n in names))
    for e in EPS:
        print(f"{e:.3f}  " + " ".join(f"{at(curves[n], e):20.3f}" for n in names))
    for n in names:
        print(f"{n}: {times[n][0]:.1f} s wall, {times[n][1]} sweeps, loading {times[n][2]:.1f} s")
    disc = [curves[f"discrete {k}"] for k in seeds]
    mean = mean_curve(disc)
    print(f"RMS discrete {seeds[0]} − discrete {seeds[1]}: {rms(disc[0], disc[1]):.4f}")
    if len(seeds) > 2:
        # each seed against the mean of the others: what one more sample deviates by
        for k, c in zip(seeds, disc):
            print(f"RMS discrete {k} − mean of the other discrete seeds: {rms(c, mean_curve([d for d in disc if d is not c])):.4f}")
        for k, c in zip(seeds, disc):
            print(f"RMS discrete {k} − discrete mean: {rms(c, mean):.4f}")
    for n in names:
        if n.startswith("hybrid"):
            print(f"RMS {n} − discrete mean: {rms(curves[n], mean):.4f}")
    plot(curves)


def plot(curves):
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        print("matplotlib missing: no plot")
        return
    fig, ax = plt.subplots(figsize=(7, 4.5))
    x = [100 * e for e in EPS]
    disc = [c for n, c in curves.items() if n.startswith("discrete")]
    hyb = [(n, c) for n, c in curves.items() if n.startswith("hybrid")]
    if len(disc) > 2:
        # many seeds: the discrete seeds' range and mean, each hybrid thin
        lo = [min(at(c, e) for c in disc) for e in EPS]
        hi = [max(at(c, e) for c in disc) for e in EPS]
        ax.fill_between(x, lo, hi, color="C0", alpha=0.2, label=f"discrete, {len(disc)} seeds: range")
        ax.plot(x, [m for _, m in mean_curve(disc)], "-o", color="C0", label="discrete: mean")
        for i, (n, c) in enumerate(hyb):
            ax.plot(x, [at(c, e) for e in EPS], "--", color="C1", lw=0.8, label="hybrid, each seed" if i == 0 else None)
        ax.plot(x, [m for _, m in mean_curve([c for _, c in hyb])], "--.", color="C3", label="hybrid: mean")
    else:
        for n, c in curves.items():
            ax.plot(x, [at(c, e) for e in EPS], "-" if n.startswith("discrete") else "--", marker="o" if n.startswith("discrete") else ".", label=n)
    ax.set_xlabel("ε1 (%)")
    ax.set_ylabel("sin φ (means over ±0.25 %)")
    ax.set_title("biaxial: all discrete (2000 disks) vs continuum outer parts (~800 disks)")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=7, ncol=2)
    fig.tight_layout()
    path = os.path.join(ROOT, "docs", "continuum_biaxial.png")
    fig.savefig(path, dpi=110)
    print(path)


if __name__ == "__main__":
    main()
