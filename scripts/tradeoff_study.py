"""Speed/accuracy trade of nscdd: tolerance × solver × decomposition × sweeps per gluing,
on three scenes: the 2000-disk biaxial test (2D grains), the 1000-sphere triaxial test
(3D grains) and the pushover of a dry brick wall (polyhedra, masonry).

Usage (through scripts/tradeoff_study.sh):
    python3 scripts/tradeoff_study.py [--scenes biaxial,triaxial,wall] [--tols 1e-2,...,1e-6]

Each scene is prepared once (the biaxial and triaxial samples compacted, the wall settled
under its weight); every configuration restarts from that state (`nscdd run --restart`)
and runs the measured part. It measures the CPU time of that run (one thread: CPU time
= run time on a quiet machine, little affected by other work), the RMS error of the
scene's two macroscopic curves against a reference run (Anderson at tolerance 1e-7),
and the natural-map residual of every step; it writes docs/tradeoff.csv, one plot per
scene (docs/tradeoff_<scene>.png: CPU time against each error and against the median
residual, Pareto fronts dashed) and docs/TRADEOFF.md (tables and recommendations; the
text after the line `<!-- reading -->` is kept across runs).
"""
import argparse
import csv
import math
import os
import sys

sys.path.insert(0, os.path.dirname(__file__))
import study_common as sc  # noqa: E402
import tradeoff_scenes as ts  # noqa: E402

BIAXIAL_EPS1 = 0.01
TRIAX_EPS1 = 0.05
WALL_DURATION = 0.45


def biaxial(stage, tol=1e-3, method="nlgs", max_sweeps=1000, dec=None, ordering="stored"):
    if stage == "prepare":
        return sc.biaxial_scene(2000, 0.0, tol=1e-3, compact_only=True)
    d = None
    if dec and dec != "1x1":
        parts, sw = dec.split("/s")
        nx, ny = (int(v) for v in parts.split("x"))
        d = {"nx": nx, "ny": ny, "sweeps_per_gluing": int(sw)}
    return sc.biaxial_scene(2000, BIAXIAL_EPS1, tol=tol, max_sweeps=max_sweeps, decomposition=d, ordering=ordering, method=method)


def triaxial(stage, **kw):
    return ts.triaxial_scene(stage, TRIAX_EPS1, **kw)


def wall(stage, **kw):
    return ts.wall_scene(stage, WALL_DURATION, **kw)


# name: (builder, title, x column, start of the measured part (s), curves [(column, label)], decompositions)
SCENES = {
    "biaxial": (biaxial, "2000-disk biaxial test (2D grains)", "eps1", sc.T_COMPACT,
                [("sin_phi", "sin φ(ε1)"), ("solid_fraction", "ν(ε1)")], ["1x1", "2x2/s1", "2x2/s4", "4x4/s4"]),
    "triaxial": (triaxial, "1000-sphere triaxial test (3D grains)", "eps1", ts.TRIAX_TC,
                 [("q_over_p", "q/p(ε1)"), ("solid_fraction", "ν(ε1)")], ["1x1x1", "2x2x1/s1", "2x2x1/s4"]),
    "wall": (wall, "pushover of a 10 × 6 brick wall (polyhedra, masonry)", "time", ts.WALL_T0,
             [("pusher_fx", "pusher force F_x(t)"), ("pusher_fz", "pusher friction F_z(t)")], ["1x1x1", "2x1x1/s1", "2x1x1/s4"]),
}
# Newton's tightest tolerance per scene (its sparse LU of the 3D triaxial sample's
# 10 000 unknowns: 200 steps at 1e-2 take 8 min)
NEWTON_MIN_TOL = {"triaxial": 1e-2}
# iteration budgets per step at equal cost: an Anderson iteration costs about 3 sweeps,
# a Newton iteration (assembly + sparse LU) about as much as 500 sweeps
BUDGET = {"nlgs": 4000, "anderson": 1300, "newton": 25}


def curve(rows, xkey, key, start, width=25):
    rr = [r for r in rows if r["time"] > start + 1e-9]
    return [r[xkey] for r in rr], sc.smooth([r[key] for r in rr], width)


def pareto(points):
    """Indices of the points not dominated in (time, error), both minimised."""
    keep = []
    for i, (t, e) in enumerate(points):
        if not any((t2 <= t and e2 <= e) and (t2 < t or e2 < e) for j, (t2, e2) in enumerate(points) if j != i):
            keep.append(i)
    return sorted(keep, key=lambda i: points[i][0])


def median(xs):
    xs = sorted(xs)
    return xs[len(xs) // 2] if xs else float("nan")


def study(name, a, nscdd):
    build, title, xkey, start, curves, decs = SCENES[name]
    out = os.path.join(a.out, name)
    print(f"[tradeoff] {name}: prepare ...", flush=True)
    sc.run(nscdd, build("prepare"), os.path.join(out, "prepare"))
    restart = ("--restart", os.path.join(out, "prepare", "final.json"))

    def measured(tag, **kw):
        el, hist = sc.run(nscdd, build("load", **kw), os.path.join(out, tag), restart, cpu=True)
        hist = [r for r in hist if r["time"] > start + 1e-9]
        return el, hist

    print(f"[tradeoff] {name}: reference (anderson, tol {a.ref_tol:g}) ...", flush=True)
    _, ref_rows = measured("reference", tol=a.ref_tol, method="anderson", max_sweeps=a.ref_budget)
    ref = [curve(ref_rows, xkey, k, start) for k, _ in curves]
    print(f"[tradeoff] {name}: scatter (nlgs, tol 1e-4, reversed order) ...", flush=True)
    _, s_rows = measured("scatter", tol=1e-4, method="nlgs", max_sweeps=BUDGET["nlgs"], ordering="reversed")
    scatter = [sc.deviation(ref[i], curve(s_rows, xkey, k, start))[0] for i, (k, _) in enumerate(curves)]
    rows = []
    for tol in [float(t) for t in a.tols.split(",")]:
        methods = a.methods.split(",")
        configs = [(m, decs[0]) for m in methods] + [("nlgs", d) for d in decs[1:]]
        if "anderson" in methods:
            configs.append(("anderson", decs[1]))  # Anderson over NSCDD's stages
        for method, dec in configs:
            if method == "newton" and tol < max(a.newton_min_tol, NEWTON_MIN_TOL.get(name, 0.0)):
                continue
            tag = f"tol{tol:g}_{method}_{dec.replace('/', '_')}"
            print(f"[tradeoff] {name}: tol {tol:g}, {method}, {dec} ...", flush=True)
            el, hist = measured(tag, tol=tol, method=method, max_sweeps=BUDGET[method], dec=dec)
            errs = [sc.deviation(ref[i], curve(hist, xkey, k, start))[0] for i, (k, _) in enumerate(curves)]
            row = dict(scene=name, tolerance=tol, solver=method, decomposition=dec.split("/s")[0],
                       sweeps_per_gluing=int(dec.split("/s")[1]) if "/s" in dec else "",
                       cpu_seconds=round(el, 3), err1=errs[0], err2=errs[1],
                       unconverged_steps=sum(1 for r in hist if r["converged"] == 0),
                       mean_iterations=round(sum(r["sweeps"] for r in hist) / len(hist), 1),
                       median_residual=median([r["residual"] for r in hist]),
                       max_residual=max(r["residual"] for r in hist))
            rows.append(row)
            print(f"    {el:.1f} s, errors {errs[0]:.2e} {errs[1]:.2e}, residual {row['median_residual']:.1e}, "
                  f"{row['unconverged_steps']} unconverged", flush=True)
    ref_info = dict(steps=len(ref_rows), converged=sum(1 for r in ref_rows if r["converged"] == 1),
                    median=median([r["residual"] for r in ref_rows]), max=max(r["residual"] for r in ref_rows))
    return rows, scatter, ref_info


def plot(name, rows, a):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    _, title, _, _, curves, _ = SCENES[name]
    fig, axs = plt.subplots(1, 3, figsize=(15, 4.2))
    fronts = {}
    marks = {"nlgs": "o", "anderson": "s", "newton": "^"}
    for ax, key, lab in [(axs[0], "err1", f"RMS error of {curves[0][1]}"), (axs[1], "err2", f"RMS error of {curves[1][1]}"),
                         (axs[2], "median_residual", "median natural-map residual per step")]:
        pts = [(r["cpu_seconds"], r[key]) for r in rows]
        front = pareto(pts)
        fronts[key] = front
        for (solver, dec) in sorted({(r["solver"], r["decomposition"] + (f"/s{r['sweeps_per_gluing']}" if r["sweeps_per_gluing"] else "")) for r in rows}):
            sel = [r for r in rows if r["solver"] == solver and r["decomposition"] + (f"/s{r['sweeps_per_gluing']}" if r["sweeps_per_gluing"] else "") == dec]
            ax.scatter([r["cpu_seconds"] for r in sel], [r[key] for r in sel], marker=marks[solver], s=22, label=f"{solver} {dec}")
        ax.plot([pts[i][0] for i in front], [pts[i][1] for i in front], "k--", lw=1, label="Pareto front")
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel("CPU time of the measured run (s)")
        ax.set_ylabel(lab)
    axs[0].legend(fontsize=7)
    fig.suptitle(title)
    fig.tight_layout()
    fig.savefig(os.path.join(a.docs, f"tradeoff_{name}.png"), dpi=100)
    return fronts


def cheapest(rows, ok):
    sel = [r for r in rows if ok(r)]
    return min(sel, key=lambda r: r["cpu_seconds"]) if sel else None


def describe(r):
    if r is None:
        return "none of the runs"
    dec = r["decomposition"] + (f", {r['sweeps_per_gluing']} sweep(s) per gluing" if r["sweeps_per_gluing"] else "")
    return f"`{r['solver']}`, tolerance {r['tolerance']:g}, {dec} ({r['cpu_seconds']:.1f} s)"


def section(name, rows, scatter, ref_info, fronts, a):
    _, title, _, _, curves, _ = SCENES[name]
    md = [f"## {title}", "", f"![{name}](tradeoff_{name}.png)", "",
          f"Reference: Anderson at tolerance {a.ref_tol:g} (≤ {a.ref_budget} iterations per step): {ref_info['converged']} "
          f"of {ref_info['steps']} steps converged, natural-map residual median {ref_info['median']:.1e} (max {ref_info['max']:.1e}). "
          f"Scatter of the test itself (NLGS at 1e-4 visiting the contacts in reversed order, against the reference): "
          f"{scatter[0]:.2e} on {curves[0][1]}, {scatter[1]:.2e} on {curves[1][1]}.", "",
          f"| tolerance | solver | decomposition | sweeps/gluing | CPU (s) | iterations/step | unconverged | median residual | max residual | err {curves[0][1]} | err {curves[1][1]} | front |",
          "|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for i, r in enumerate(rows):
        on = ", ".join(lab for lab, key in [("1", "err1"), ("2", "err2"), ("res", "median_residual")] if i in fronts[key])
        md.append(f"| {r['tolerance']:g} | {r['solver']} | {r['decomposition']} | {r['sweeps_per_gluing']} | {r['cpu_seconds']:.1f} | "
                  f"{r['mean_iterations']:.0f} | {r['unconverged_steps']} | {r['median_residual']:.1e} | {r['max_residual']:.1e} | "
                  f"{r['err1']:.2e} | {r['err2']:.2e} | {on} |")
    rec = []
    for k in (1.5, 3.0):
        f1, f2 = k * scatter[0], k * scatter[1]
        rec.append((f"both curves within {k:g} × the test's scatter", cheapest(rows, lambda r: r["err1"] <= f1 and r["err2"] <= f2)))
    for target in (1e-4, 1e-5, 1e-6):
        rec.append((f"median residual ≤ {target:g}", cheapest(rows, lambda r, t=target: r["median_residual"] <= t)))
    md += ["", "| goal | cheapest configuration |", "|---|---|"] + [f"| {g} | {describe(r)} |" for g, r in rec]
    return md, rec


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--scenes", default="biaxial,triaxial,wall")
    ap.add_argument("--tols", default="1e-2,1e-3,1e-4,1e-5,1e-6")
    ap.add_argument("--methods", default="nlgs,anderson,newton")
    ap.add_argument("--newton-min-tol", type=float, default=1e-5)
    ap.add_argument("--ref-tol", type=float, default=1e-7)
    ap.add_argument("--ref-budget", type=int, default=3000)
    ap.add_argument("--nscdd", default="target/release/nscdd")
    ap.add_argument("--out", default="out/tradeoff")
    ap.add_argument("--docs", default="docs")
    a = ap.parse_args()
    os.makedirs(a.docs, exist_ok=True)
    all_rows, sections, summary = [], [], []
    for name in a.scenes.split(","):
        rows, scatter, ref_info = study(name, a, a.nscdd)
        fronts = plot(name, rows, a)
        md, rec = section(name, rows, scatter, ref_info, fronts, a)
        sections += md + [""]
        summary += [f"| {SCENES[name][1]} | {g} | {describe(r)} |" for g, r in rec]
        all_rows += rows
    with open(os.path.join(a.docs, "tradeoff.csv"), "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(all_rows[0].keys()))
        w.writeheader()
        w.writerows(all_rows)
    path = os.path.join(a.docs, "TRADEOFF.md")
    reading = ""
    if os.path.exists(path) and "<!-- reading -->" in open(path).read():
        reading = open(path).read().split("<!-- reading -->", 1)[1]
    md = ["# Speed and accuracy: tolerance × solver × decomposition × sweeps per gluing", "",
          "Generated by `scripts/tradeoff_study.sh` (data: `tradeoff.csv`; scenes in `scripts/tradeoff_scenes.py` and "
          "`scripts/study_common.py`). Each scene is prepared once, then every configuration restarts from that state and "
          "runs the measured part: the biaxial test to ε1 = "
          f"{BIAXIAL_EPS1} (norm `Quad`), the triaxial test to ε1 = {TRIAX_EPS1} (`Quad`), the wall pushed for "
          f"{WALL_DURATION - ts.WALL_T0:.2f} s at {ts.WALL_V} m/s (`QM/16`). Time: CPU seconds of the measured run (one thread). "
          "Errors: RMS difference of two macroscopic curves (moving averages over 51 steps) from the reference run. "
          f"Budgets per step: NLGS {BUDGET['nlgs']} sweeps, Anderson {BUDGET['anderson']} iterations (≈ 3 sweeps each), "
          f"Newton {BUDGET['newton']} iterations (Newton only down to tolerance {a.newton_min_tol:g}, "
          f"{NEWTON_MIN_TOL['triaxial']:g} on the triaxial test). Newton runs "
          "undecomposed; Anderson also mixes NSCDD's stages on the first decomposition of each scene.", "",
          "## Recommendation", "", "| scene | goal | cheapest configuration |", "|---|---|---|"] + summary + [""] + sections
    with open(path, "w") as f:
        f.write("\n".join(md) + "\n<!-- reading -->" + (reading or "\n"))
    print("wrote", path)


if __name__ == "__main__":
    main()
