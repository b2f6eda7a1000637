"""Side by side: `nscdd solve-fc` against Siconos' NSGS on the same problems.

    /usr/bin/python3 scripts/siconos_bench.py [--tol 1e-6] PROBLEM.json[.gz] ...

(through scripts/siconos_bench.sh, which installs Debian's python3-siconos and
python3-scipy, builds nscdd with the hdf5 feature, makes the problems and writes
docs/siconos_bench.md). Debian's /usr/bin/python3 is the one that sees Siconos.

For each problem (the JSON exchange format; FCLIB files are converted by
`nscdd solve-fc --export-json`):
- nscdd: `nscdd solve-fc P --tol TOL --check-every 10`: sweeps to the natural-map
  residual ‖F(r)‖/‖q‖ < TOL and the solve time (reading the file excluded);
- Siconos 4.4: `fc2d_driver` / `fc3d_driver` with NSGS (`SICONOS_FRICTION_2D_NSGS`,
  `SICONOS_FRICTION_3D_NSGS`) on W as a Siconos sparse-block matrix (`SBM_from_csparse`), its own stopping test
  disabled (tolerance 0, light error evaluation) and the iteration count n fixed;
  the smallest n whose r reaches ‖F(r)‖/‖q‖ < TOL (computed here, the same formula
  as nscdd's) is found by doubling then bisection; the time per sweep is that of the
  run with that n.
Prints one JSON line per problem: sweeps and seconds of both, time per sweep and the
ratio (Siconos / nscdd).
"""
import argparse
import warnings
import gzip
import json
import subprocess
import sys
import time

import numpy as np
import scipy.sparse as sp
import siconos.numerics as sn


def load(path):
    op = gzip.open if path.endswith(".gz") else open
    with op(path, "rt") as f:
        return json.load(f)


def natural_residual(dim, W, q, mu, r):
    u = W @ r + q
    f2 = 0.0
    R = r.reshape(-1, dim)
    U = u.reshape(-1, dim)
    ut = np.linalg.norm(U[:, 1:], axis=1)
    z = R.copy()
    z[:, 0] = R[:, 0] - (U[:, 0] + mu * ut)
    z[:, 1:] = R[:, 1:] - U[:, 1:]
    # projection on the cones
    zn = z[:, 0]
    zt = np.linalg.norm(z[:, 1:], axis=1)
    p = np.zeros_like(z)
    inside = (zn >= 0) & (zt <= mu * zn)
    polar = (mu * zt <= -zn) & ~inside
    side = ~inside & ~polar
    p[inside] = z[inside]
    a = (zn + mu * zt) / (1.0 + mu * mu)
    p[side, 0] = a[side]
    with np.errstate(invalid="ignore", divide="ignore"):
        scale = np.where(zt > 0, mu * a / np.where(zt > 0, zt, 1.0), 0.0)
    p[side, 1:] = z[side, 1:] * scale[side, None]
    f2 = np.sum((R - p) ** 2)
    qn = np.linalg.norm(q)
    return np.sqrt(f2) / (qn if qn > 0 else 1.0)


def siconos_matrix(dim, W):
    """W as Siconos' sparse-block matrix (the storage its NSGS is written for)."""
    info, sbm = sn.SBM_from_csparse(dim, W)
    assert info == 0, "SBM_from_csparse failed"
    return sn.NumericsMatrix(sbm)


def siconos_run(dim, nc, N, q, mu, n):
    p = sn.FrictionContactProblem(dim, nc, N, q, mu)
    solver = sn.SICONOS_FRICTION_3D_NSGS if dim == 3 else sn.SICONOS_FRICTION_2D_NSGS
    so = sn.SolverOptions(solver)
    so.iparam[sn.SICONOS_IPARAM_MAX_ITER] = n
    so.dparam[sn.SICONOS_DPARAM_TOL] = 0.0
    if dim == 3:
        so.iparam[sn.SICONOS_FRICTION_3D_IPARAM_ERROR_EVALUATION] = sn.SICONOS_FRICTION_3D_NSGS_ERROR_EVALUATION_LIGHT
        so.iparam[sn.SICONOS_FRICTION_3D_IPARAM_ERROR_EVALUATION_FREQUENCY] = 1 << 30
    r = np.zeros(dim * nc)
    u = np.zeros(dim * nc)
    t0 = time.perf_counter()
    if dim == 3:
        sn.fc3d_driver(p, r, u, so)
    else:
        sn.fc2d_driver(p, r, u, so)
    dt = time.perf_counter() - t0
    return r, dt, so.iparam[sn.SICONOS_IPARAM_ITER_DONE]


def main():
    warnings.simplefilter("ignore")
    ap = argparse.ArgumentParser()
    ap.add_argument("problems", nargs="+")
    ap.add_argument("--tol", type=float, default=1e-6)
    ap.add_argument("--nscdd", default="target/release/nscdd")
    ap.add_argument("--max-sweeps", type=int, default=100000)
    a = ap.parse_args()
    for path in a.problems:
        d = load(path)
        dim, nc = d["dim"], d["nc"]
        Wj = d["W"]
        W = sp.csc_matrix((Wj["vals"], (Wj["rows"], Wj["cols"])), shape=(Wj["n"], Wj["n"]))
        W.sum_duplicates()
        W.indices = W.indices.astype(np.int64)
        W.indptr = W.indptr.astype(np.int64)
        q = np.array(d["q"], dtype=float)
        mu = np.array(d["mu"], dtype=float)
        out = subprocess.run(
            [a.nscdd, "solve-fc", path, "--tol", str(a.tol), "--check-every", "10", "--max-sweeps", str(a.max_sweeps)],
            check=True,
            capture_output=True,
            text=True,
        ).stdout
        ours = json.loads(out)
        ours_res = natural_residual(dim, W, q, mu, np.array(ours["r"]))
        # Siconos: the smallest fixed iteration count reaching the residual
        N = siconos_matrix(dim, W)
        lo, hi, runs = 0, 1, {}
        while True:
            r, dt, done = siconos_run(dim, nc, N, q, mu, hi)
            runs[hi] = (natural_residual(dim, W, q, mu, r), dt)
            if runs[hi][0] < a.tol or hi >= a.max_sweeps:
                break
            lo, hi = hi, min(2 * hi, a.max_sweeps)
        while hi - lo > max(1, hi // 50):
            mid = (lo + hi) // 2
            r, dt, done = siconos_run(dim, nc, N, q, mu, mid)
            runs[mid] = (natural_residual(dim, W, q, mu, r), dt)
            if runs[mid][0] < a.tol:
                hi = mid
            else:
                lo = mid
        s_res, s_dt = runs[hi]
        rec = {
            "problem": path.split("/")[-1],
            "dim": dim,
            "contacts": nc,
            "tol": a.tol,
            "nscdd_sweeps": ours["sweeps"],
            "nscdd_seconds": ours["solve_seconds"],
            "nscdd_residual": ours_res,
            "nscdd_converged": ours["converged"],
            "siconos_sweeps": hi,
            "siconos_seconds": s_dt,
            "siconos_residual": s_res,
            "siconos_converged": bool(s_res < a.tol),
            "nscdd_us_per_sweep": 1e6 * ours["solve_seconds"] / max(1, ours["sweeps"]),
            "siconos_us_per_sweep": 1e6 * s_dt / hi,
        }
        rec["time_per_sweep_ratio"] = rec["siconos_us_per_sweep"] / rec["nscdd_us_per_sweep"]
        rec["sweeps_ratio"] = rec["siconos_sweeps"] / max(1, rec["nscdd_sweeps"])
        print(json.dumps(rec), flush=True)


if __name__ == "__main__":
    main()
