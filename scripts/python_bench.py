#!/usr/bin/env python3
"""The Python module against the command line (docs/PERFORMANCE.md, issue 22).

Usage: venv/bin/python scripts/python_bench.py [SCENE] [--repeat N]

Runs SCENE (default examples/scenes/deposit.toml) N times (default 3) with
`target/release/nscdd run SCENE --out DIR --quiet` and with
`nscdd.Simulation(SCENE, out=DIR).run(progress=False)`, alternated, and prints the
wall times (best and mean); then the cost of stepping from Python: the same
scene's first 500 steps by `sim.step()` one at a time against `sim.run(500)`, as
microseconds per step.
"""
import os
import statistics
import subprocess
import sys
import tempfile
import time

import nscdd

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def main():
    argv = sys.argv[1:]
    repeat = 3
    if "--repeat" in argv:
        i = argv.index("--repeat")
        repeat = int(argv[i + 1])
        del argv[i : i + 2]
    scene = argv[0] if argv else os.path.join(ROOT, "examples", "scenes", "deposit.toml")
    cli_bin = os.path.join(ROOT, "target", "release", "nscdd")
    cli, py = [], []
    with tempfile.TemporaryDirectory() as tmp:
        for i in range(repeat):
            t = time.perf_counter()
            subprocess.run([cli_bin, "run", scene, "--out", os.path.join(tmp, f"cli{i}"), "--quiet"], check=True, capture_output=True)
            cli.append(time.perf_counter() - t)
            t = time.perf_counter()
            nscdd.Simulation(scene, out=os.path.join(tmp, f"py{i}")).run(progress=False)
            py.append(time.perf_counter() - t)
            same = open(os.path.join(tmp, f"cli{i}", "final.json"), "rb").read() == open(os.path.join(tmp, f"py{i}", "final.json"), "rb").read()
            print(f"run {i}: CLI {cli[-1]:.3f} s, Python {py[-1]:.3f} s, final.json the same: {same}", flush=True)
    print(f"CLI    best {min(cli):.3f} s, mean {statistics.mean(cli):.3f} s")
    print(f"Python best {min(py):.3f} s, mean {statistics.mean(py):.3f} s ({100 * (min(py) / min(cli) - 1):+.1f} % best to best)")
    n = 500
    one, many = [], []
    for _ in range(repeat):
        sim = nscdd.Simulation(scene)
        t = time.perf_counter()
        for _ in range(n):
            sim.step()
        one.append(time.perf_counter() - t)
        sim = nscdd.Simulation(scene)
        t = time.perf_counter()
        sim.run(n, progress=False)
        many.append(time.perf_counter() - t)
    print(f"{n} steps: sim.step() {min(one):.3f} s, sim.run({n}) {min(many):.3f} s: {1e6 * (min(one) - min(many)) / n:.1f} µs per step() call")


if __name__ == "__main__":
    main()
