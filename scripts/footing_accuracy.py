#!/usr/bin/env python3
"""How accurate one step of the footing is at each solver tolerance, in the example
(grains over a continuum) and its all-discrete reference (docs/CONTINUUM.md, "The
same tolerance is not the same accuracy").

Usage: footing_accuracy.py OUT_DIR [--seed S] [--from STEP] [--states K] [--every N]
    [--tolerances 1e-3,5e-4,...] [--reference TOL] [--jobs 2] [--scenes A,B,...]

For each of the two scenes of `continuum_footing.py` (seed S, default 3): runs it to
step STEP (default 2600, under the footing), then K times (default 10): from the
state, one step at each tolerance (QM/16, at most 3000 sweeps) and one at the
reference tolerance (default 1e-6, at most 200 000 sweeps); then N steps (default
50) at the example's 1.666e-4 to the next state. A step's error against the
reference's: the footing force |F − F_ref| (N/m) and the RMS of |v − v_ref| over the
grains above the band (y > 0.1 m, the region both scenes have). Prints, per
tolerance, the mean sweeps, NLGS seconds, errors and natural-map residual over the
K states, and the median RMS velocity of the grains above the band in the
reference steps (the scale of the errors). The scenes run side by side with
`--jobs 2` (the default); `--scenes` names those to study, of `hybrid` (the
example), `hybrid-stress-free` (its foundation started stress-free, as until
2026-11-27) and `all-discrete` (default: `hybrid,all-discrete`).
"""
import csv
import json
import os
import re
import statistics as st
import subprocess
import sys
from concurrent.futures import ThreadPoolExecutor

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import continuum_footing as cf  # noqa: E402

NSCDD = os.path.join(cf.ROOT, "target/release/nscdd")


def scene(base, steps, tol, max_sweeps):
    """`base` run to step `steps` at `tol`, outputs only at the end."""
    t = re.sub(r"(?m)^duration = .*$", f"duration = {steps / 1000:.3f}", base)
    t = re.sub(r"(?m)^tolerance = .*$", f"tolerance = {tol:g}", t)
    t = re.sub(r"(?m)^max_sweeps = .*$", f"max_sweeps = {max_sweeps}", t)
    return re.sub(r"(?m)^every = .*$", "every = 1000000", t)


def run(out, name, text, restart, env):
    path = os.path.join(out, name + ".toml")
    open(path, "w").write(text)
    dest = os.path.join(out, name)
    cmd = [NSCDD, "run", path, "--out", dest, "--quiet"] + (["--restart", restart] if restart else [])
    subprocess.run(cmd, env=env, check=True, capture_output=True)
    return list(csv.DictReader(open(os.path.join(dest, "history.csv")))), dest


def velocities(dest):
    d = json.load(open(os.path.join(dest, "final.json")))
    return {b["id"]: b["velocity"][:2] for b in d["bodies"] if b["kind"] == "disk" and b["position"][1] > 0.1}


def verr(v, ref):
    return (sum((v[i][0] - ref[i][0]) ** 2 + (v[i][1] - ref[i][1]) ** 2 for i in ref) / len(ref)) ** 0.5


def study(kind, base, out, start, states, every, tols, reference, env):
    """Rows (tolerance, sweeps, t_nlgs, force error, velocity error, residual), one
    per state and tolerance, and the median RMS velocity of the reference steps."""
    run(out, f"{kind}_start", scene(base, start, 1.666e-4, 3000), None, env)
    state, step, rows, scale = os.path.join(out, f"{kind}_start", "final.json"), start, [], []
    for _ in range(states):
        one = lambda tol, cap: run(out, f"{kind}_one", scene(base, step + 1, tol, cap), state, env)
        r, dest = one(reference, 200000)
        f_ref, v_ref = float(r[0]["footing_fy"]), velocities(dest)
        scale.append(verr(v_ref, {i: (0.0, 0.0) for i in v_ref}))
        for tol in tols:
            r, dest = one(tol, 3000)
            x = r[0]
            rows.append((tol, int(x["sweeps"]), float(x["t_nlgs"]), abs(float(x["footing_fy"]) - f_ref), verr(velocities(dest), v_ref), float(x["residual"])))
        run(out, f"{kind}_chain", scene(base, step + every, 1.666e-4, 3000), state, env)
        state = os.path.join(out, f"{kind}_state{step + every}.json")
        os.replace(os.path.join(out, f"{kind}_chain", "final.json"), state)
        step += every
    return rows, st.median(scale)


def main():
    out = sys.argv[1] if len(sys.argv) > 1 and not sys.argv[1].startswith("--") else "out/footing_accuracy"
    seed = int(cf.opt("--seed", default="3"))
    start, states, every = int(cf.opt("--from", default="2600")), int(cf.opt("--states", default="10")), int(cf.opt("--every", default="50"))
    tols = [float(x) for x in cf.opt("--tolerances", default="1e-3,5e-4,3e-4,1.666e-4,1e-4,5e-5").split(",")]
    reference = float(cf.opt("--reference", default="1e-6"))
    jobs = int(cf.opt("--jobs", default="2"))
    os.makedirs(out, exist_ok=True)
    env = dict(os.environ, NSCDD_PYTHON_ENV=os.environ.get("NSCDD_PYTHON_ENV", os.path.join(cf.ROOT, "venv")))
    src = cf.shallow(open(os.path.join(cf.ROOT, "examples/scenes/footing.toml")).read())
    scenes = {
        "hybrid": cf.deepen(src, False),
        "hybrid-stress-free": cf.stress_free(cf.deepen(src, False)),
        "all-discrete": cf.deepen(cf.discrete(src), True),
    }
    only = cf.opt("--scenes", default="hybrid,all-discrete").split(",")
    if any(k not in scenes for k in only):
        sys.exit(f"--scenes: of {', '.join(scenes)}")
    scenes = {k: re.sub(r"(?m)^seed = 3$", f"seed = {seed}", scenes[k]) for k in only}
    with ThreadPoolExecutor(jobs) as pool:
        got = {k: pool.submit(study, k, t, out, start, states, every, tols, reference, env) for k, t in scenes.items()}
        got = {k: f.result() for k, f in got.items()}
    print(f"seed {seed}, {states} states from step {start} every {every}; reference tolerance {reference:g}")
    print("| scene | tolerance | sweeps | NLGS (ms) | force error, median / mean (N/m) | velocity error, median / mean (mm/s) | natural-map residual, median |")
    print("|---|---|---|---|---|---|---|")
    for k, (rows, scale) in got.items():
        for tol in tols:
            r = [x for x in rows if x[0] == tol]
            f, v = [x[3] for x in r], [x[4] * 1000 for x in r]
            print(
                f"| {k} | {tol:g} | {st.mean(x[1] for x in r):.0f} | {1000 * st.mean(x[2] for x in r):.1f} | "
                f"{st.median(f):.0f} / {st.mean(f):.0f} | {st.median(v):.3f} / {st.mean(v):.3f} | {st.median(x[5] for x in r):.1e} |"
            )
    for k, (rows, scale) in got.items():
        print(f"{k}: RMS velocity of the grains above the band in the reference steps, median {1000 * scale:.1f} mm/s")


if __name__ == "__main__":
    main()
