#!/usr/bin/env python3
"""The footing of examples/scenes/footing.toml against its all-discrete reference
(docs/CONTINUUM.md): load–penetration curves, the scatter, times.

Usage: continuum_footing.py OUT_DIR [--shallow] [--seeds 3,5,...] [--jobs N] [--tag T]
    [--young E] [--hardening PHI0 KAPPA_H PHI | --friction PHI] [--grain-share S]
    [--coupling node|grain] [--geostatic Q | --stress-free] [--tolerance T] [--disc-tolerance T]
    [--depth D --disc-footing Y --duration T] [--extend T] [--plot]

For each seed (default 3 and 5) writes OUT_DIR/{T,disc}_sSEED.toml (T: `hyb` unless
`--tag`): the example (1300 grains in a 0.6 m layer over the continuum, 3.5 s) and its
all-discrete reference (2420 grains down to y = -0.5 m on a floor, the footing 0.03 m
lower: that layer settles more). Runs them (target/release/nscdd, built with the
`fem` feature) N at a time; a run whose OUT_DIR/NAME.toml is unchanged and whose
OUT_DIR/NAME/history.csv exists is not run again (the all-discrete references serve
every variant). Prints each one's time, sweeps, the footing force at 5, 10 and 15 mm
of penetration and its mean over 0–10, 10–30, 30–50 and 10–50 mm, and, with more
than two seeds, the scatter: each discrete seed's RMS distance (smoothed force at
every millimetre up to 50 mm) to the mean of the other seeds, each hybrid's to the
mean of every discrete seed, and the probability that a hybrid lies farther than a
discrete seed (Mann–Whitney's U / n1 n2: 0.5 when the two lists are alike).
`--extend T`: runs short of 50 mm by their end are continued (a restart from
their final.json) to T s, so that no seed drops out of the comparison: the seeds
touched last are those whose footing comes down into a hollow of the deposit's
surface, embedded in the grains beside it and so the strongest (docs/CONTINUUM.md,
"The layer at rest and the seeds left out").
`--plot`: docs/continuum_footing.png (needs matplotlib: scripts/biaxial_study.sh
installs it in .venv-docs).

`--shallow`: the layout until 2026-11-26, a 0.3 m layer (650 grains; all-discrete
1770), 2 s, 15 mm (plot docs/continuum_footing_shallow.png). The hybrid's
foundation: `--young`, `--hardening` (initial friction angle, hardening strain,
friction angle) or `--friction` (perfectly plastic), `--grain-share`,
`--coupling`, `--geostatic` (or `--stress-free`: the runs before 2026-11-27, tags
`hyb` and `hybt3`) and `--tolerance` (the solver's, for the hybrid only:
the all-discrete references keep 1.666e-4) replace the example's;
`--disc-tolerance T` runs the all-discrete references at T (their names then end
in _tolT). `--depth D`: the foundation D m deep (the example: 0.5) in both runs,
the all-discrete footing at `--disc-footing` (0.615: its layer settles more), both
run `--duration` s (3.5); the references are then named discD_fY_tT_sSEED;
`--plot` then writes OUT_DIR/continuum_footing.png (also with `--geostatic` or
either tolerance).
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


def shallow(text):
    """The example (a 0.6 m layer over the band) with a 0.3 m layer, as it was until
    2026-11-26 (650 grains; all-discrete 1770), 2 s."""
    text = text.replace("count = 1300", "count = 650").replace("box = [0.0, 0.0, 1.0, 0.61]", "box = [0.0, 0.0, 1.0, 0.31]")
    text = text.replace("position = [0.5, 0.645]", "position = [0.5, 0.345]")
    for x in ("-0.01", "1.01"):
        text = text.replace(f"position = [{x}, 0.4]\nrotation = 1.5707963267948966\nlength = 0.8", f"position = [{x}, 0.25]\nrotation = 1.5707963267948966\nlength = 0.5")
    return text.replace("duration = 3.5", "duration = 2.0")


def deepen(text, disc):
    """The example's layout (a 0.6 m layer) from the shallow hybrid or all-discrete
    scene text."""
    text = text.replace("count = 650", "count = 1300").replace("box = [0.0, 0.0, 1.0, 0.31]", "box = [0.0, 0.0, 1.0, 0.61]")
    text = text.replace("count = 1770", "count = 2420").replace("box = [0.0, -0.5, 1.0, 0.31]", "box = [0.0, -0.5, 1.0, 0.61]")
    text = text.replace("position = [0.5, 0.345]", "position = [0.5, 0.615]" if disc else "position = [0.5, 0.645]")
    for x in ("-0.01", "1.01"):
        text = text.replace(f"position = [{x}, 0.25]\nrotation = 1.5707963267948966\nlength = 0.5", f"position = [{x}, 0.4]\nrotation = 1.5707963267948966\nlength = 0.8")
        text = text.replace(f"position = [{x}, -0.1]\nrotation = 1.5707963267948966\nlength = 1.0", f"position = [{x}, 0.15]\nrotation = 1.5707963267948966\nlength = 1.3")
    return text.replace("duration = 2.0", "duration = 3.5")


def foundation(text, disc, depth, footing, duration):
    """The example's layout (from [`deepen`]) over a foundation `depth` m deep (the
    example: 0.5): the continuum's mesh (cells of 5 cm) or the all-discrete grains
    (as many a square metre as in the example's reference) down to y = -depth; the
    all-discrete footing at `footing` (that layer settles more, the deeper the
    more), both run for `duration` s."""
    n = round((depth + 0.1) / 0.05)
    text = text.replace(
        "mesh = { rectangle = { origin = [0.0, -0.5], size = [1.0, 0.6], cells = [20, 12] } }",
        f"mesh = {{ rectangle = {{ origin = [0.0, {-depth}], size = [1.0, {depth + 0.1:.4g}], cells = [20, {n}] }} }}",
    )
    text = text.replace("count = 2420", f"count = {round(2420 * (0.61 + depth) / 1.11)}")
    text = text.replace("box = [0.0, -0.5, 1.0, 0.61]", f"box = [0.0, {-depth}, 1.0, 0.61]")
    text = text.replace("position = [0.5, -0.51]", f"position = [0.5, {-depth - 0.01:.4g}]")
    for x in ("-0.01", "1.01"):
        text = text.replace(
            f"position = [{x}, 0.15]\nrotation = 1.5707963267948966\nlength = 1.3",
            f"position = [{x}, {(0.8 - depth) / 2:.4g}]\nrotation = 1.5707963267948966\nlength = {0.8 + depth:.4g}",
        )
    if disc:
        text = text.replace("position = [0.5, 0.615]", f"position = [0.5, {footing}]")
    return text.replace("duration = 3.5", f"duration = {duration}")


def mean_force(p, r, lo, hi):
    """The raw footing force's mean over penetrations lo..hi mm (`p`, `r`: [`curve`]'s)."""
    fy = [float(x["footing_fy"]) for x in r]
    first = len(r) - len(p)
    v = [fy[first + i] for i, x in enumerate(p) if lo <= x <= hi]
    return f"{sum(v) / len(v):.0f}" if v else "-"


def curve(d):
    r = list(csv.DictReader(open(os.path.join(d, "history.csv"))))
    if os.path.exists(os.path.join(d + "_ext", "history.csv")):  # continued (`--extend`)
        last = int(r[-1]["step"])
        r += [x for x in csv.DictReader(open(os.path.join(d + "_ext", "history.csv"))) if int(x["step"]) > last]
    fy = [float(x["footing_fy"]) for x in r]
    y = [float(x["footing_y"]) for x in r]
    first = next((i for i, f in enumerate(fy) if f > 1), len(r))  # never touched: empty
    sm = lambda i: sum(fy[max(0, i - 25) : i + 26]) / len(fy[max(0, i - 25) : i + 26])
    return [(y[first] - y[i]) * 1000 for i in range(first, len(r))], [sm(i) for i in range(first, len(r))], r


def opt(name, n=1, default=None):
    """The `n` values after `--name` on the command line, or `default`."""
    if name not in sys.argv:
        return default
    i = sys.argv.index(name)
    v = sys.argv[i + 1 : i + 1 + n]
    return v if n > 1 else v[0]


def stress_free(text):
    """The scene with its foundation started stress-free (its `initial_stress` line
    removed; the example until 2026-11-27)."""
    return re.sub(r"(?m)^initial_stress = .*\n?", "", text)


def hybrid_variant(text):
    """The hybrid's foundation with the command line's law, if any: `--young E`,
    `--hardening PHI0 KAPPA_H PHI` or `--friction PHI` (perfectly plastic),
    `--grain-share S`, `--coupling node|grain`, `--geostatic Q` (the foundation
    starts at its geostatic stress under a surcharge of Q Pa; the example's: 1e4),
    `--stress-free` (it starts stress-free, as the example did until 2026-11-27),
    `--tolerance T` (the solver's tolerance, QM/16: the example's 1.666e-4)."""
    young, hard, phi, share = opt("--young"), opt("--hardening", 3), opt("--friction"), opt("--grain-share")
    coupling, geostatic, tol = opt("--coupling"), opt("--geostatic"), opt("--tolerance")
    if tol:
        text = re.sub(r"(?m)^tolerance = .*$", f"tolerance = {float(tol):g}", text)
    if geostatic or "--stress-free" in sys.argv:
        text = stress_free(text)
    if geostatic:
        text = re.sub(r"(?m)^(band = .*)$", rf"\1\ninitial_stress = {{ surcharge = {geostatic} }}", text, count=1)
    if coupling:
        text = re.sub(r"(?m)^(band = .*)$", rf'\1\ncoupling = "{coupling}"', text, count=1)
    if young:
        text = re.sub(r"(?m)^young = .*$", f"young = {young}", text)
    if hard:
        phi0, kh, phi = hard
        law = f"plastic = {{ friction = {phi}, initial_friction = {phi0}, hardening_strain = {kh}, dilatancy = 4.0 }}"
        text = re.sub(r"(?m)^plastic = .*$", law, text)
    elif phi:
        text = re.sub(r"(?m)^plastic = .*$", f"plastic = {{ friction = {phi}, dilatancy = 4.0 }}", text)
    if share:
        text = re.sub(r"(?m)^(band = .*discrete = 0\.1)(, grain_share = [0-9.e-]+)? }$", rf"\1, grain_share = {share} }}", text)
    return text


def resampled(p, f, top):
    """The smoothed force at every whole millimetre of penetration from 1 to `top`."""
    out, k = [], 0
    for mm in range(1, top + 1):
        while k < len(p) and p[k] < mm:
            k += 1
        if k >= len(p):
            return None
        out.append(f[k])
    return out


def rms(a, b):
    return (sum((x - y) ** 2 for x, y in zip(a, b)) / len(a)) ** 0.5


def mean_curve(cs):
    return [sum(v) / len(v) for v in zip(*cs)]


def mean_se(v):
    """The mean of `v` and its standard error."""
    m = sum(v) / len(v)
    return m, (sum((x - m) ** 2 for x in v) / (len(v) - 1) / len(v)) ** 0.5 if len(v) > 1 else 0.0


def run_all(jobs, todo, env):
    """Runs `todo` ([(name, path, out, extra arguments)]), `jobs` at a time; returns
    {name: wall}."""
    walls, running = {}, []
    nscdd = os.path.join(ROOT, "target/release/nscdd")

    def reap(limit):
        while len(running) > limit:
            for r in running:
                if r[1].poll() is not None:
                    if r[1].returncode != 0:
                        sys.exit(f"{r[0]} failed ({r[1].returncode})")
                    walls[r[0]] = time.time() - r[2]
                    running.remove(r)
                    break
            else:
                time.sleep(0.2)

    for name, path, dest, extra in todo:
        reap(jobs - 1)
        running.append((name, subprocess.Popen([nscdd, "run", path, "--out", dest, "--quiet", *extra], env=env), time.time()))
    reap(0)
    return walls


def extend(out, names, top, until, jobs, env):
    """`--extend T`: each run whose footing is not `top` mm deep by its end is
    continued from its final.json to T s (OUT_DIR/NAME_ext, its own scene file with
    that duration; a restart continues bitwise as the longer run would), and its
    curve reads both histories. Without it the seeds touched last (the footing
    embedded in a hollow of the surface: the strongest) drop out of the comparison
    over 1–`top` mm."""
    todo = []
    for name in names:
        d = os.path.join(out, name)
        p, f, r = curve(d)
        if (p and p[-1] >= top) or float(r[-1]["time"]) >= until - 1e-9:
            continue
        text = re.sub(r"(?m)^duration = .*$", f"duration = {until:g}", open(d + ".toml").read())
        path = d + "_ext.toml"
        if os.path.exists(os.path.join(d + "_ext", "history.csv")) and os.path.exists(path) and open(path).read() == text:
            continue
        open(path, "w").write(text)
        todo.append((name + "_ext", path, d + "_ext", ["--restart", os.path.join(d, "final.json")]))
    for name, wall in run_all(jobs, todo, env).items():
        print(f"{name}: continued to {until:g} s in {wall:.1f} s")


def main():
    deep = "--shallow" not in sys.argv
    out = sys.argv[1] if len(sys.argv) > 1 and not sys.argv[1].startswith("--") else "out/footing_study"
    seeds = [int(x) for x in opt("--seeds", default="3,5").split(",")]
    jobs = int(opt("--jobs", default="1"))
    tag = opt("--tag", default="hyb")
    depth = opt("--depth")
    if depth and not deep:
        sys.exit("--depth applies to the example's layout, not with --shallow")
    if not depth and (opt("--disc-footing") or opt("--duration")):
        sys.exit("--disc-footing and --duration go with --depth")
    # (the reference's name says its depth, footing and duration: runs of other
    # settings do not overwrite it)
    if depth:
        depth = f"{float(depth):g}"
        disc_name = f"disc{depth}_f{float(opt('--disc-footing', default='0.615')):g}_t{float(opt('--duration', default='3.5')):g}"
    else:
        disc_name = "disc"
    disc_tol = opt("--disc-tolerance")
    if disc_tol:
        disc_name += f"_tol{float(disc_tol):g}"
    os.makedirs(out, exist_ok=True)
    src = shallow(open(os.path.join(ROOT, "examples/scenes/footing.toml")).read())
    if not deep:  # (that layout started its foundation stress-free)
        src = stress_free(src)
    env = dict(os.environ, NSCDD_PYTHON_ENV=os.environ.get("NSCDD_PYTHON_ENV", os.path.join(ROOT, "venv")))
    todo, names = [], []
    for seed in seeds:
        for kind, text in ((tag, hybrid_variant(src)), (disc_name, discrete(src))):
            # (the shallow layout first, deepened: the all-discrete files stay those of
            # the runs recorded in docs/CONTINUUM.md)
            if deep:
                text = deepen(text, kind != tag)
            if depth:
                text = foundation(text, kind != tag, float(depth), opt("--disc-footing", default="0.615"), opt("--duration", default="3.5"))
            name = f"{kind}_s{seed}"
            names.append(name)
            dest = os.path.join(out, name)
            path = os.path.join(out, name + ".toml")
            text = re.sub(r"(?m)^seed = 3$", f"seed = {seed}", text)
            if disc_tol and kind != tag:
                text = re.sub(r"(?m)^tolerance = .*$", f"tolerance = {float(disc_tol):g}", text)
            same = lambda t: [x for x in t.splitlines() if not x.startswith("#")]
            if os.path.exists(os.path.join(dest, "history.csv")) and os.path.exists(path) and same(open(path).read()) == same(text):
                continue  # run once: the all-discrete reference serves every variant
            open(path, "w").write(text)
            todo.append((name, path, dest, []))
    walls = run_all(jobs, todo, env)
    curves, top = {}, 50 if deep else 15
    if opt("--extend"):
        extend(out, names, top, float(opt("--extend")), jobs, env)
    for name in names:
        p, f, r = curve(os.path.join(out, name))
        curves[name] = (p, f)
        sweeps = sum(int(float(x["sweeps"])) for x in r)
        at = []
        for mm in (5, 10, 15):
            k = next((i for i, x in enumerate(p) if x >= mm), None)
            at.append(f"{f[k]:.0f}" if k is not None else "-")
        means = " / ".join(mean_force(p, r, lo, hi) for lo, hi in ((0, 10), (10, 30), (30, 50), (10, 50)))
        wall = f"{walls[name]:.1f} s" if name in walls else "(earlier run)"
        print(f"{name}: {wall}, {sweeps} sweeps, bodies {r[0]['bodies']}, force at 5/10/15 mm: {' / '.join(at)} N/m, mean over 0-10/10-30/30-50/10-50 mm: {means} N/m")
    # the scatter: each discrete seed's RMS distance (force over 1..top mm) to the
    # mean of the other discrete seeds; each hybrid's to the mean of them all
    disc = {s: resampled(*curves[f"{disc_name}_s{s}"], top) for s in seeds}
    hyb = {s: resampled(*curves[f"{tag}_s{s}"], top) for s in seeds}
    short = [f"{disc_name}_s{s}" for s, c in disc.items() if c is None] + [f"{tag}_s{s}" for s, c in hyb.items() if c is None]
    if short:
        print(f"not {top} mm deep by the end (left out of the scatter): {', '.join(short)}")
    ds = [s for s in seeds if disc[s]]
    if len(ds) > 2:
        loo = [rms(disc[s], mean_curve([disc[t] for t in ds if t != s])) for s in ds]
        print(f"RMS over 1-{top} mm, each discrete seed to the mean of the others: {min(loo):.0f}-{max(loo):.0f}, mean {sum(loo) / len(loo):.0f} N/m")
        m = mean_curve([disc[s] for s in ds])
        d = [rms(hyb[s], m) for s in seeds if hyb[s]]
        if d:
            print(f"RMS over 1-{top} mm, each {tag} to the discrete mean: {min(d):.0f}-{max(d):.0f}, mean {sum(d) / len(d):.0f} N/m")
            print(f"  each discrete seed: {', '.join(f'{s}: {x:.0f}' for s, x in zip(ds, loo))}")
            print(f"  each {tag}: {', '.join(f'{s}: {rms(hyb[s], m):.0f}' for s in seeds if hyb[s])}")
            # Mann–Whitney's U over both lists, as the probability that a hybrid lies
            # farther than a discrete seed (0.5: the same distribution)
            u = sum((x > y) + 0.5 * (x == y) for x in d for y in loo) / (len(d) * len(loo))
            print(f"  P(a {tag} lies farther than a discrete seed) = {u:.2f} (Mann-Whitney U / n1 n2; 0.5: as far)")
            hm = mean_curve([c for c in hyb.values() if c])
            print(f"mean {tag} curve to the discrete mean: {rms(hm, m):.0f} N/m; mean force {sum(hm) / len(hm):.0f} against {sum(m) / len(m):.0f} N/m")
            # each seed's mean force over 1..top mm: the ratio of the two means and
            # its standard error (the seeds independent; first-order propagation)
            fh = [sum(c) / len(c) for c in hyb.values() if c]
            fd = [sum(disc[s]) / len(disc[s]) for s in ds]
            (mh, eh), (md, ed) = mean_se(fh), mean_se(fd)
            ratio = mh / md
            print(f"mean force over 1-{top} mm, each seed's: {tag} {mh:.0f} +- {eh:.0f} ({len(fh)} seeds), discrete {md:.0f} +- {ed:.0f} ({len(fd)}); "
                  f"ratio {ratio:.2f} +- {ratio * ((eh / mh) ** 2 + (ed / md) ** 2) ** 0.5:.2f} (standard errors)")
    if "--plot" not in sys.argv:
        return
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        return
    fig, ax = plt.subplots(figsize=(6.5, 4.2))
    for name, (p, f) in curves.items():
        hy = name.startswith(tag)
        ax.plot(p, f, "r-" if hy else "k-", lw=0.6, alpha=0.45, label=("grains + continuum, each seed" if hy else "all-discrete, each seed") if name.endswith(f"_s{seeds[0]}") else None)
    x = list(range(1, top + 1))
    if len(ds) > 1:
        ax.plot(x, mean_curve([disc[s] for s in ds]), "k-", lw=2.2, label=f"all-discrete, mean of {len(ds)}")
    hs = [c for c in hyb.values() if c]
    if len(hs) > 1:
        ax.plot(x, mean_curve(hs), "r-", lw=2.2, label=f"grains + continuum, mean of {len(hs)}")
    ax.set_xlim(0, top)
    ax.set_ylim(0, 1.05 * max(v for p, f in curves.values() for x, v in zip(p, f) if x <= top))
    ax.set_xlabel("penetration since first contact (mm)")
    ax.set_ylabel("footing force (N/m, mean over 51 steps)")
    ax.legend()
    fig.tight_layout()
    # (the example's own layouts in docs/, a variant's with its runs)
    variant = depth or opt("--geostatic") or "--stress-free" in sys.argv or opt("--tolerance") or disc_tol
    png = os.path.join(out, "continuum_footing.png") if variant else os.path.join(ROOT, "docs/continuum_footing.png" if deep else "docs/continuum_footing_shallow.png")
    fig.savefig(png, dpi=110)


if __name__ == "__main__":
    main()
