#!/usr/bin/env python3
"""Weak scaling of NSCDD on MPI ranks, simulated on this machine by oversubscription
(docs/SCALING.md, issue 20).

For P ranks: a 2D deposit P times as wide as the deposit example (1000 P disks,
walls around it), settled 1500 steps in one process, then `--steps` more steps
restarted from it with `mpirun -n P --oversubscribe nscdd run … --subdomains Px1`
(one strip per rank), re-partitioned every 10 steps (contacts held per rank). Per
rank, from ranks.json: the time in gluing exchanges and reductions (waits included)
and the rest of the run (its own work: sweeps, detection, build, update), the CPU
seconds of every rank (`/usr/bin/time`, loading included), and each rank's CPU
seconds in communication and the rest, its compute CPU (ranks.json, from the start
of the run). With more ranks than cores the ranks share the cores: the wall time
grows with P / cores and time sharing blurs the wall split between own work and
waits; the compute CPU per rank is what weak scaling keeps constant.

Usage: python3 scripts/weak_scaling.py [--ranks 1,2,4,8] [--steps 200] [--out DIR] [--settle-only]
Needs the program built with `--features nscdd-cli/mpi` and OpenMPI. `--settle-only`
writes the settled states alone (to carry them to another machine); the environment's
NSCDD and TIME name the program and GNU time if they are not at their usual paths.
"""
import argparse, json, os, re, subprocess, sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
BIN = os.environ.get("NSCDD", os.path.join(ROOT, "target", "release", "nscdd"))
TIME = os.environ.get("TIME", "/usr/bin/time")
ENV = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1",
           OMPI_MCA_btl_vader_single_copy_mechanism="none")


def scene(p, steps):
    w = float(p)
    text = open(os.path.join(ROOT, "examples", "scenes", "deposit.toml")).read()
    for old, new in [("steps = 2000", f"steps = {steps}"), ("every = 100", "every = 0"),
                     ("position = [0.5, -0.01]\nlength = 1.04", f"position = [{w / 2}, -0.01]\nlength = {w + 0.04}"),
                     ("position = [1.01, 0.6]", f"position = [{w + 0.01}, 0.6]"),
                     ("position = [0.5, 1.25]\nlength = 0.96", f"position = [{w / 2}, 1.25]\nlength = {w - 0.04}"),
                     ("count = 1000", f"count = {1000 * p}"), ("box = [0.0, 0.0, 1.0, 1.2]", f"box = [0.0, 0.0, {w}, 1.2]")]:
        assert old in text, old
        text = text.replace(old, new)
    return text + "\n[decomposition]\nrepartition_every = 10\n"


def run(cmd):
    r = subprocess.run(cmd, capture_output=True, text=True, env=ENV)
    if r.returncode != 0:
        sys.exit(f"failed: {' '.join(cmd)}\n{r.stderr}")
    return r.stderr


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--ranks", default="1,2,4,8")
    ap.add_argument("--steps", type=int, default=200)
    ap.add_argument("--out", default=os.path.join(ROOT, "out", "weak"))
    ap.add_argument("--settle-only", action="store_true")
    a = ap.parse_args()
    os.makedirs(a.out, exist_ok=True)
    for p in [int(x) for x in a.ranks.split(",")]:
        d = os.path.join(a.out, f"p{p}")
        os.makedirs(d, exist_ok=True)
        settle = os.path.join(d, "settle.toml")
        open(settle, "w").write(scene(p, 1500))
        state = os.path.join(d, "settle", "final.json")
        if not os.path.exists(state):
            run([BIN, "run", settle, "--out", os.path.join(d, "settle"), "--quiet", "--subdomains", f"{p}x1"])
        if a.settle_only:
            continue
        timed = os.path.join(d, "timed.toml")
        open(timed, "w").write(scene(p, 1500 + a.steps))
        out = os.path.join(d, "run")
        err = run(["mpirun", "-n", str(p), "--oversubscribe", "--bind-to", "none", TIME, "-f", "cpu %U %S",
                   BIN, "run", timed, "--restart", state, "--out", out, "--quiet", "--subdomains", f"{p}x1"])
        wall = float(re.search(r"sweeps, ([0-9.]+) s", err).group(1))
        cpu = [float(u) + float(s) for u, s in re.findall(r"cpu ([0-9.]+) ([0-9.]+)", err)]
        per = json.load(open(os.path.join(out, "ranks.json")))["per_rank"]
        waits = [r["exchange_seconds"] + r["reduce_seconds"] for r in per]
        own = [wall - x for x in waits]
        compute = [r["compute_cpu_seconds"] for r in per]
        wait_cpu = [r["wait_cpu_seconds"] for r in per]
        print(json.dumps(dict(ranks=p, disks=1000 * p, steps=a.steps, wall=wall,
                              own_mean=sum(own) / p, own_max=max(own), waits_mean=sum(waits) / p,
                              cpu_per_rank=sum(cpu) / len(cpu) if cpu else None,
                              compute_cpu_mean=sum(compute) / p, compute_cpu_max=max(compute),
                              wait_cpu_mean=sum(wait_cpu) / p)), flush=True)


if __name__ == "__main__":
    main()
