#!/usr/bin/env python3
"""Time to a natural-map residual for every solver method on FCLIB files.

    python3 scripts/bench_fc.py [--tol 1e-8] [--repeat 15] [--inner 1] [--check-every 1,10]
                                [--methods nlgs,anderson,newton,nlgs:1.2,...] [FILES...]

Runs `target/release/nscdd solve-fc` (built with `--features nscdd-cli/hdf5`) on each
file (default: ../shared/data/fclib/*.hdf5 or tests/data/fclib/*.hdf5) for each
method and check period, `--repeat` times, and prints the best `solve_seconds`
(assembly of the blocks and the solve, measured inside nscdd) with the iterations
and the residual reached, and each method's speedup over NLGS. `--inner N` solves N
times inside each process (`solve-fc --repeat N`): the first solve of a process
also pays for its first touches of memory (≈ 0.08 ms on the smallest file).
`--methods`: the methods to time, each `method` or `method:ω` (`solve-fc
--relaxation ω`); the speedups are over the first.
"""
import argparse, glob, json, os, subprocess, sys

def run(exe, f, method, tol, every, max_it, inner):
    method, _, omega = method.partition(":")
    out = subprocess.run(
        [exe, "solve-fc", "--method", method, "--tol", str(tol), "--check-every", str(every), "--max-sweeps", str(max_it),
         "--repeat", str(inner), "--relaxation", omega or "1", f],
        capture_output=True, text=True, check=True,
    ).stdout
    return json.loads(out.splitlines()[0])


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("files", nargs="*")
    ap.add_argument("--tol", type=float, default=1e-8)
    ap.add_argument("--repeat", type=int, default=15)
    ap.add_argument("--check-every", default="1,10")
    ap.add_argument("--inner", type=int, default=1)
    ap.add_argument("--max-sweeps", type=int, default=200000)
    ap.add_argument("--methods", default="nlgs,anderson,newton")
    a = ap.parse_args()
    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    exe = os.path.join(root, "target/release/nscdd")
    files = a.files or sorted(glob.glob(os.path.join(root, "../shared/data/fclib/*.hdf5"))) or sorted(
        glob.glob(os.path.join(root, "tests/data/fclib/*.hdf5")))
    print(f"| file | contacts | check every | method | iterations | residual | best time (ms) | speedup over the first |")
    print("|---|---|---|---|---|---|---|---|")
    for f in files:
        for every in [int(x) for x in a.check_every.split(",")]:
            base = None
            for m in a.methods.split(","):
                runs = [run(exe, f, m, a.tol, every, a.max_sweeps, a.inner) for _ in range(a.repeat)]
                best = min(r["solve_seconds"] for r in runs)
                r = runs[0]
                base = base or best
                ok = "" if r["converged"] else " (not converged)"
                print(f"| {os.path.basename(f)} | {len(r['r']) // 3} | {every} | {m} | {r['sweeps']}{ok} | "
                      f"{r['residual']:.1e} | {1e3 * best:.3f} | {base / best:.2f} |")
            sys.stdout.flush()


if __name__ == "__main__":
    main()
