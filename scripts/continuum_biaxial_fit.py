#!/usr/bin/env python3
"""Identify the continuum's hardening law on the all-discrete biaxial test
(docs/CONTINUUM.md, "Within the discrete scatter"): for each parameter set, the
hybrid test on every seed's compacted sample, and the RMS distance of each
hybrid's sin φ(ε1) to the mean of the discrete seeds' curves.

Usage: continuum_biaxial_fit.py RUN_DIR SEEDS PHI0,KAPPA_H,PHI,E[,PSI] ...

RUN_DIR holds a `scripts/continuum_biaxial.py RUN_DIR --seeds SEEDS ...` run (its
compacted samples `compact_K/final.json` and discrete tests `disc_K/`); SEEDS
its seeds, comma-separated. Each parameter set: the regions' initial friction
angle PHI0 (°), hardening strain KAPPA_H, friction angle PHI (°), Young's modulus
E (Pa) and dilatancy PSI (°, default 4), with `grain_share = 0.25`. Prints per
set the hybrids' RMS distances (least, largest, mean), the hybrids' mean curve's
distance and its bias (hybrid mean − discrete mean) at ε1 = 0.5, 1.5, … 9.5 %.
The hybrids run two at a time. Needs what continuum_biaxial.py needs.
"""
import importlib.util
import os
import subprocess
import sys
from concurrent.futures import ThreadPoolExecutor

HERE = os.path.dirname(os.path.abspath(__file__))
spec = importlib.util.spec_from_file_location("cb", os.path.join(HERE, "continuum_biaxial.py"))
cb = importlib.util.module_from_spec(spec)
spec.loader.exec_module(cb)


def hybrid(run_dir, tag, seed, young):
    s, w, h, _ = cb.hybrid_scene(os.path.join(run_dir, f"compact_{seed}", "final.json"), young)
    d = os.path.join(run_dir, "fit", f"{tag}_{seed}")
    open(d + ".toml", "w").write(s)
    r = subprocess.run([cb.NSCDD, "run", d + ".toml", "--out", d, "--quiet"], capture_output=True, text=True)
    if r.returncode != 0:
        sys.exit(f"{d}.toml: {r.stderr}")
    return cb.hybrid_curve(os.path.join(d, "history.csv"), w, h)


def main():
    if len(sys.argv) < 4:
        sys.exit(__doc__)
    run_dir, seeds = sys.argv[1], [int(x) for x in sys.argv[2].split(",")]
    os.makedirs(os.path.join(run_dir, "fit"), exist_ok=True)
    mean = cb.mean_curve([cb.discrete_curve(os.path.join(run_dir, f"disc_{k}", "history.csv")) for k in seeds])
    cb.SHARE = 0.25
    for arg in sys.argv[3:]:
        v = [float(x) for x in arg.split(",")]
        cb.HARD, cb.PHI = (v[0], v[1]), v[2]
        cb.PSI = v[4] if len(v) > 4 else 4.0
        tag = arg.replace(",", "_")
        with ThreadPoolExecutor(2) as ex:
            curves = list(ex.map(lambda k: hybrid(run_dir, tag, k, v[3]), seeds))
        d = [cb.rms(c, mean) for c in curves]
        hm = cb.mean_curve(curves)
        bias = " ".join(f"{hm[i][1] - mean[i][1]:+.3f}" for i in range(0, len(cb.EPS), 2))
        print(f"{arg}: RMS {min(d):.4f}–{max(d):.4f}, mean {sum(d) / len(d):.4f}; "
              f"mean curve {cb.rms(hm, mean):.4f}; bias {bias}", flush=True)


if __name__ == "__main__":
    main()
