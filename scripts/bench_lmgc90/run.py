"""Side by side: nscdd against compas-lmgc90 (LMGC90's rigid polyhedra, NLGS) on
small masonry scenes.

    /tmp/clvenv/bin/python scripts/bench_lmgc90/run.py [--scenes stack,wall]
        [--nscdd target/release/nscdd] [--repeat 1] [--steps N]
        [--tol T --relax W --gs-it1 A --gs-it2 B]   # patch LMGC90's hard-coded NLGS

Scenes (the same blocks, masses, μ, h, θ and steps in both codes):
- stack: 3 bricks 0.2 × 0.1 × 0.05 m (density 2000, μ 0.5) on a fixed base block
  (the middle brick turned by 0.01 rad about z), h = 1e-3, θ = 0.5, 200 steps: the
  stack test of plugins/polyhedra/tests/masonry.rs with a base block instead of the
  plane (compas-lmgc90 has only polyhedra);
- wall: examples/scenes/wall.toml (generator `brick_wall`: 10 courses, 105 bricks
  0.2 × 0.1 × 0.05 m, density 1800, on a fixed base slab, density 2400, μ 0.6),
  h = 1e-3, θ = 0.5, 200 steps. LMGC90 gets the same blocks, built here as
  plugins/polyhedra/src/generate.rs builds them (checked against nscdd's initial
  centroids).

NLGS settings. compas-lmgc90 0.1.11 hard-codes its solver in the Fortran wrapper
(wrap_lmgc90_compas.f90): norm QM/16, tol 1.666e-4 (a single-precision literal),
relaxation ω = 0.1, blocks of gs_it1 = 50 sweeps + 1 check sweep, at most gs_it2 =
500 blocks, stored Delassus (SDL), no scrambling, STO detection, gravity -9.81 z.
By default nscdd is given the same: `norm = "QM/16"`, the same tol, `relaxation`
= ω, `check_every` = gs_it1 + 1, `max_sweeps` = gs_it2 (gs_it1 + 1). The values are
read from the loaded library (and printed). With --tol/--relax/--gs-it1/--gs-it2
both codes run other settings: LMGC90's module variables are then overwritten in
the process's memory at their addresses in this exact build (checked byte for
byte first; any other build is refused).

Timing: only the stepping loop. nscdd: the sum of history.csv's t_detect,
t_delassus, t_nlgs and t_update columns (scene loading and output excluded), one
thread (no decomposition; RAYON_NUM_THREADS=1). LMGC90: perf_counter around the
loop of `LMGC90Solver.compute_one_step()` (which also copies the bodies and the
contacts into its SimResult); Solver setup and preprocess() excluded;
OMP_NUM_THREADS=1. Both run under `nice -n 10`, one after the other; --repeat R
keeps the fastest of R runs of each.

Displacements: |x_end − x_0| of each movable block's centre of mass, in each code;
Δ(codes): max over blocks of |x_end(nscdd) − x_end(LMGC90)|.
"""
import argparse
import csv
import ctypes
import json
import math
import os
import shutil
import struct
import subprocess
import sys
import tempfile
import time
from collections import Counter
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent.parent

# ---------------------------------------------------------------------------
# geometry
# ---------------------------------------------------------------------------

# faces of box_points' corners (index 4 ix + 2 iy + iz), wound outwards
BOX_FACES = [[0, 1, 3, 2], [4, 6, 7, 5], [0, 4, 5, 1], [2, 3, 7, 6], [0, 2, 6, 4], [1, 5, 7, 3]]


def box_points(lo, hi):
    """The 8 corners of [lo, hi], in the order of generate.rs's box_points."""
    return [[x, y, z] for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])]


def rot_z(p, c, a):
    """p turned by a about the z axis through c."""
    ca, sa = math.cos(a), math.sin(a)
    x, y = p[0] - c[0], p[1] - c[1]
    return [c[0] + ca * x - sa * y, c[1] + sa * x + ca * y, p[2]]


def check_winding(v, faces):
    c = [sum(p[k] for p in v) / len(v) for k in range(3)]
    for f in faces:
        a, b, d = (v[i] for i in f[:3])
        u = [b[k] - a[k] for k in range(3)]
        w = [d[k] - b[k] for k in range(3)]
        n = [u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2], u[0] * w[1] - u[1] * w[0]]
        m = [sum(v[i][k] for i in f) / len(f) - c[k] for k in range(3)]
        assert sum(n[k] * m[k] for k in range(3)) > 0, "a face is wound inwards"


class Block:
    def __init__(self, lo, hi, material, fixed=False, turn_z=0.0):
        self.lo, self.hi, self.material, self.fixed, self.turn_z = lo, hi, material, fixed, turn_z
        self.centre = [0.5 * (lo[k] + hi[k]) for k in range(3)]

    def world_vertices(self):
        return [rot_z(p, self.centre, self.turn_z) for p in box_points(self.lo, self.hi)]


def solver_toml(sv):
    return (
        "[solver]\n"
        f'norm = "{sv["norm"]}"\n'
        f"tolerance = {sv['tol']!r}\n"
        f"relaxation = {sv['relax']!r}\n"
        f"check_every = {sv['gs_it1'] + 1}\n"
        f"max_sweeps = {sv['gs_it2'] * (sv['gs_it1'] + 1)}\n"
        f'ordering = "{sv.get("ordering", "stored")}"\n'
    )


def time_toml(sc, steps):
    return f"[time]\nstep = {sc['h']!r}\ntheta = {sc['theta']!r}\nsteps = {steps}\n"


def stack_scene(steps):
    """plugins/polyhedra/tests/masonry.rs, stack_of_bricks_carries_the_exact_weights,
    on a fixed base block (2L wider, H thick, as the wall's base) instead of a plane."""
    l, w, h = 0.2, 0.1, 0.05
    blocks = [Block([-l, -l, -h], [2 * l, w + l, 0.0], "ground", fixed=True)]
    for k in range(3):
        blocks.append(Block([0.0, 0.0, k * h], [l, w, (k + 1) * h], "stone", turn_z=0.01 if k == 1 else 0.0))
    sc = dict(
        name="stack", h=1e-3, theta=0.5, steps=steps or 200, alert=0.002, mu=0.5,
        densities={"stone": 2000.0, "ground": 2000.0}, blocks=blocks,
    )

    def toml(sv, nsteps):
        t = (
            'dimension = 3\ngravity = [0.0, 0.0, -9.81]\n'
            + time_toml(sc, nsteps)
            + solver_toml(sv)
            + f"[detection]\nalert = {sc['alert']!r}\n"
            + f"[output]\nevery = {max(nsteps, 1)}\nvtk = false\n"
            + '[[materials]]\nname = "stone"\ndensity = 2000.0\n'
            + '[[materials]]\nname = "ground"\ndensity = 2000.0\n'
            + f'[[laws]]\nmaterials = ["stone", "stone"]\nfriction = {sc["mu"]!r}\n'
            + f'[[laws]]\nmaterials = ["stone", "ground"]\nfriction = {sc["mu"]!r}\n'
            + '[[laws]]\nmaterials = ["ground", "ground"]\nlaw = "none"\n'
        )
        for b in blocks:
            c = b.centre
            v = ", ".join(f"[{p[0] - c[0]!r}, {p[1] - c[1]!r}, {p[2] - c[2]!r}]" for p in box_points(b.lo, b.hi))
            t += (
                f'[[bodies]]\nshape = "polyhedron"\nmaterial = "{b.material}"\n'
                f"position = [{c[0]!r}, {c[1]!r}, {c[2]!r}]\nrotation = [0.0, 0.0, {b.turn_z!r}]\n"
                f"vertices = [{v}]\n" + ("fixed = true\n" if b.fixed else "")
            )
        return t

    sc["toml"] = toml
    return sc


def wall_scene(steps):
    """examples/scenes/wall.toml; the blocks as generate.rs's brick_wall makes them
    (base slab first, then course by course, left to right)."""
    l, w, h = 0.2, 0.1, 0.05
    courses, n = 10, 10
    o = [0.0, 0.0, 0.0]
    blocks = [Block([o[0] - l, o[1] - l, o[2] - h], [o[0] + (n + 1.0) * l, o[1] + w + l, o[2]], "base", fixed=True)]
    for c in range(courses):
        z0 = o[2] + c * h
        if c % 2 == 1:
            cuts = [0.0, 0.5 * l] + [(k + 0.5) * l for k in range(1, n)] + [n * l]
        else:
            cuts = [0.0] + [k * l for k in range(1, n)] + [n * l]
        for s0, s1 in zip(cuts, cuts[1:]):
            blocks.append(Block([o[0] + s0, o[1], z0], [o[0] + s1, o[1] + w, z0 + h], "brick"))
    sc = dict(
        name="wall", h=1e-3, theta=0.5, steps=steps or 200, alert=0.002, mu=0.6,
        densities={"brick": 1800.0, "base": 2400.0}, blocks=blocks,
    )

    def toml(sv, nsteps):
        return (
            'dimension = 3\ngravity = [0.0, 0.0, -9.81]\n'
            + time_toml(sc, nsteps)
            + solver_toml(sv)
            + f"[detection]\nalert = {sc['alert']!r}\n"
            + f"[output]\nevery = {max(nsteps, 1)}\nvtk = false\n"
            + '[[materials]]\nname = "brick"\ndensity = 1800.0\n'
            + '[[materials]]\nname = "base"\ndensity = 2400.0\n'
            + f'[[laws]]\nmaterials = ["brick", "brick"]\nfriction = {sc["mu"]!r}\n'
            + f'[[laws]]\nmaterials = ["brick", "base"]\nfriction = {sc["mu"]!r}\n'
            + '[[laws]]\nmaterials = ["base", "base"]\nlaw = "none"\n'
            + '[[generate]]\nkind = "brick_wall"\nmaterial = "brick"\nbase_material = "base"\n'
            + f"brick = [{l!r}, {w!r}, {h!r}]\ncourses = {courses}\nbricks = {n}\n"
        )

    sc["toml"] = toml
    return sc


SCENES = {"stack": stack_scene, "wall": wall_scene}

# ---------------------------------------------------------------------------
# compas-lmgc90: its hard-coded NLGS settings, read (and optionally patched)
# ---------------------------------------------------------------------------

# module variables of wrap_lmgc90_compas in compas_lmgc90 0.1.11's
# _lmgc90.cpython-311-x86_64-linux-gnu.so (virtual addresses of its .data; found
# from the arguments of set_nlgs_parameter / the loop bounds in
# lmgc90_compute_one_step)
LMGC_VARS = {
    "tol": (0x53B850, "d", struct.unpack("d", struct.pack("d", struct.unpack("f", struct.pack("f", 1.666e-4))[0]))[0]),
    "relax": (0x53B860, "d", struct.unpack("f", struct.pack("f", 0.1))[0]),
    "gs_it2": (0x53B8A0, "i", 500),
    "gs_it1": (0x53B8A4, "i", 50),
    "norm": (0x53B885, "5s", b"QM/16"),
    "SDLactif": (0x53B858, "i", 1),
}


def _lmgc90_file():
    from compas_lmgc90 import _lmgc90

    return _lmgc90.__file__


def lmgc_module_base(so_path):
    so_path = os.path.realpath(so_path)
    starts = []
    with open("/proc/self/maps") as f:
        for line in f:
            p = line.split()
            if len(p) >= 6 and os.path.realpath(p[5]) == so_path and int(p[2], 16) == 0:
                starts.append(int(p[0].split("-")[0], 16))
    if not starts:
        raise RuntimeError(f"{so_path} is not mapped")
    return min(starts)


def lmgc_vars(patch=None):
    """The NLGS settings in the loaded library; with `patch` (name → value),
    overwrite them first. Refuses unless every variable holds the value this
    build ships with."""
    from compas_lmgc90 import _lmgc90

    base = lmgc_module_base(_lmgc90.__file__)
    out = {}
    for name, (addr, fmt, shipped) in LMGC_VARS.items():
        size = struct.calcsize(fmt)
        raw = ctypes.string_at(base + addr, size)
        val = struct.unpack(fmt, raw)[0]
        if val != shipped and not (patch and name in patch):
            raise RuntimeError(
                f"compas_lmgc90's {name} at 0x{addr:x} holds {val!r}, not the {shipped!r} of 0.1.11: another build"
            )
        out[name] = val.decode() if isinstance(val, bytes) else val
    for name, val in (patch or {}).items():
        addr, fmt, _ = LMGC_VARS[name]
        ctypes.memmove(base + addr, struct.pack(fmt, val), struct.calcsize(fmt))
        out[name] = val
    return out


def lmgc_worker(spec_path, out_path):
    """Runs one scene in compas-lmgc90 (one process per scene: LMGC90 keeps one
    simulation per process) and writes its results as JSON."""
    import numpy as np
    from compas_lmgc90.solver import Solver

    spec = json.loads(Path(spec_path).read_text())
    sv = lmgc_vars(spec.get("patch"))
    solver = Solver(dt=spec["h"], theta=spec["theta"])
    solver.geometry_from_v_f(
        [{"vertices": b["vertices"], "faces": BOX_FACES} for b in spec["blocks"]],
        density=[b["density"] for b in spec["blocks"]],
    )
    for i, b in enumerate(spec["blocks"]):
        if b["fixed"]:
            for c in ("Vx", "Vy", "Vz", "Rx", "Ry", "Rz"):
                solver.apply_velocity(i, c, 0.0)
    # one law for every pair (the wrapper's see table has a single RBDY3-POLYR pair)
    solver.contact_law(spec["law"], spec["mu"], alert=spec["alert"])
    solver.preprocess()
    x0 = [list(map(float, c)) for c in solver.init_coor]
    lm = solver.lmgc90
    # nlgs_3D's get_nlgs3D_loop(compteur, err1, err2, err3, contacts): the sweeps
    # of the last step (check sweeps not counted) and its number of contacts
    get_loop = ctypes.CDLL(_lmgc90_file())["__nlgs_3d_MOD_get_nlgs3d_loop"]
    it, e1, e2, e3, nc = ctypes.c_int(), ctypes.c_double(), ctypes.c_double(), ctypes.c_double(), ctypes.c_int()
    args = [ctypes.byref(x) for x in (it, e1, e2, e3, nc)]
    gs1 = sv["gs_it1"]
    sweeps, updates, dt = [], 0, 0.0
    for _ in range(spec["steps"]):
        t = time.perf_counter()
        res = lm.compute_one_step()
        dt += time.perf_counter() - t
        get_loop(*args)
        s = it.value + it.value // gs1  # + the check sweep of each block of gs_it1
        sweeps.append(s)
        updates += s * nc.value
    x1 = [list(map(float, np.asarray(c))) for c in res.bodies]
    pairs = Counter(tuple(sorted(p)) for p in res.interaction_bodies)
    rn = [float(r[1]) for r in res.interaction_rloc]
    Path(out_path).write_text(
        json.dumps(
            dict(
                seconds=dt, x0=x0, x1=x1, settings=sv, contacts=len(rn), sweeps=sweeps, updates=updates,
                points_per_pair=dict(Counter(pairs.values())), status=dict(Counter(res.interaction_status)),
            )
        )
    )


# ---------------------------------------------------------------------------
# the two codes
# ---------------------------------------------------------------------------

ENV1 = dict(os.environ, RAYON_NUM_THREADS="1", OMP_NUM_THREADS="1", OPENBLAS_NUM_THREADS="1", MKL_NUM_THREADS="1")


def run_lmgc(sc, sv, patch, workdir):
    spec = dict(
        h=sc["h"], theta=sc["theta"], steps=sc["steps"], alert=sc["alert"], mu=sc["mu"], law="IQS_CLB", patch=patch,
        blocks=[
            dict(vertices=b.world_vertices(), density=sc["densities"][b.material], fixed=b.fixed) for b in sc["blocks"]
        ],
    )
    sp, op = workdir / f"{sc['name']}_lmgc_spec.json", workdir / f"{sc['name']}_lmgc_out.json"
    sp.write_text(json.dumps(spec))
    cmd = ["nice", "-n", "10", sys.executable, str(Path(__file__).resolve()), "--lmgc-worker", str(sp), str(op)]
    # LMGC90 may write files in its working directory: keep them in workdir
    p = subprocess.run(cmd, env=ENV1, cwd=workdir, capture_output=True, text=True)
    if p.returncode != 0:
        sys.exit(f"compas-lmgc90 failed on {sc['name']}:\n{p.stdout[-3000:]}\n{p.stderr[-3000:]}")
    return json.loads(op.read_text())


def run_ours(nscdd, sc, sv, workdir, nsteps):
    d = workdir / f"{sc['name']}_ours_{nsteps}"
    shutil.rmtree(d, ignore_errors=True)
    d.mkdir(parents=True)
    scene = d / "scene.toml"
    scene.write_text(sc["toml"](sv, nsteps))
    out = d / "out"
    cmd = ["nice", "-n", "10", str(nscdd), "run", str(scene), "--out", str(out), "--quiet"]
    t = time.perf_counter()
    p = subprocess.run(cmd, env=ENV1, capture_output=True, text=True)
    wall = time.perf_counter() - t
    if p.returncode != 0:
        sys.exit(f"nscdd failed on {sc['name']} ({' '.join(cmd)}):\n{p.stdout[-3000:]}\n{p.stderr[-3000:]}")
    fin = json.loads((out / "final.json").read_text())
    x = [b["position"] for b in fin["bodies"]]
    loop, sweeps, unconv, updates = 0.0, [], 0, 0
    with open(out / "history.csv") as f:
        for row in csv.DictReader(f):
            loop += sum(float(row[k]) for k in ("t_detect", "t_delassus", "t_nlgs", "t_update"))
            sweeps.append(int(row["sweeps"]))
            updates += int(row["sweeps"]) * int(row["contacts"])
            unconv += row["converged"].strip().lower() not in ("true", "1")
    pairs = Counter(tuple(sorted(c["bodies"])) for c in fin["contacts"])
    return dict(
        seconds=loop, process_seconds=wall, x=x, sweeps=sweeps, updates=updates, unconverged=unconv,
        contacts=len(fin["contacts"]),
        points_per_pair=dict(Counter(pairs.values())), stderr=p.stderr.strip().splitlines()[-1:] if p.stderr else [],
    )


def disp(x0, x1, movable):
    d = [math.dist(x0[i], x1[i]) for i in movable]
    return max(d), sum(d) / len(d)


def fmt_pp(h):
    return " ".join(f"{k}×{v}" for k, v in sorted(((int(k), v) for k, v in h.items())))


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--scenes", default="stack,wall")
    ap.add_argument("--nscdd", default=str(ROOT / "target" / "release" / "nscdd"))
    ap.add_argument("--steps", type=int, default=0, help="override every scene's number of steps")
    ap.add_argument("--repeat", type=int, default=1, help="runs of each code per scene; the fastest is kept")
    ap.add_argument("--tol", type=float, help="NLGS tolerance for both (patches LMGC90)")
    ap.add_argument("--relax", type=float, help="NLGS relaxation ω for both (patches LMGC90)")
    ap.add_argument("--gs-it1", type=int, help="sweeps between checks (LMGC90 gs_it1; nscdd check_every = gs_it1 + 1)")
    ap.add_argument("--gs-it2", type=int, help="check blocks at most (LMGC90 gs_it2)")
    ap.add_argument("--ordering", default="stored", choices=["stored", "reversed", "shuffled"], help="nscdd's sweep order (LMGC90 sweeps in storage order)")
    ap.add_argument("--workdir", help="keep the scenes and outputs here (default: a temporary directory)")
    ap.add_argument("--lmgc-worker", nargs=2, metavar=("SPEC", "OUT"), help=argparse.SUPPRESS)
    a = ap.parse_args()
    if a.lmgc_worker:
        lmgc_worker(*a.lmgc_worker)
        return
    nscdd = Path(a.nscdd)
    if not nscdd.is_file():
        sys.exit(f"{nscdd} is missing: build it (cargo build --release) or give --nscdd")
    shipped = lmgc_vars()  # read in this process: the library's defaults
    patch = {k: v for k, v in (("tol", a.tol), ("relax", a.relax), ("gs_it1", a.gs_it1), ("gs_it2", a.gs_it2)) if v is not None}
    sv = dict(shipped, **patch)
    sv["ordering"] = a.ordering
    tmp = Path(a.workdir) if a.workdir else Path(tempfile.mkdtemp(prefix="bench_lmgc90_"))
    tmp.mkdir(parents=True, exist_ok=True)
    print(
        f"NLGS in both: {sv['norm']} tol {sv['tol']:.4g}, ω {sv['relax']:.3g}, check every {sv['gs_it1'] + 1} sweeps, "
        f"at most {sv['gs_it2'] * (sv['gs_it1'] + 1)} sweeps"
        + (f" (LMGC90 patched: {patch})" if patch else " (compas-lmgc90's hard-coded values)"),
        file=sys.stderr,
    )
    rows, extra = [], []
    for name in a.scenes.split(","):
        sc = SCENES[name](a.steps)
        movable = [i for i, b in enumerate(sc["blocks"]) if not b.fixed]
        # nscdd's initial centroids (a 0-step run): the same blocks in the same order
        x0 = run_ours(nscdd, sc, sv, tmp, 0)["x"]
        assert len(x0) == len(sc["blocks"]), f"{name}: nscdd has {len(x0)} bodies, the script {len(sc['blocks'])}"
        g = max(math.dist(x0[i], b.centre) for i, b in enumerate(sc["blocks"]))
        assert g < 1e-9, f"{name}: nscdd's blocks are not the script's ({g:.3g} m)"
        ours = min((run_ours(nscdd, sc, sv, tmp, sc["steps"]) for _ in range(a.repeat)), key=lambda r: r["seconds"])
        lm = min((run_lmgc(sc, sv, patch, tmp) for _ in range(a.repeat)), key=lambda r: r["seconds"])
        g0 = max(math.dist(x0[i], lm["x0"][i]) for i in range(len(x0)))
        assert g0 < 1e-9, f"{name}: LMGC90's initial centroids differ from nscdd's by {g0:.3g} m"
        mo, ao = disp(x0, ours["x"], movable)
        ml, al = disp(lm["x0"], lm["x1"], movable)
        dd = max(math.dist(ours["x"][i], lm["x1"][i]) for i in movable)
        n = sc["steps"]
        ms_o, ms_l = 1e3 * ours["seconds"] / n, 1e3 * lm["seconds"] / n
        rows.append(
            f"| {name} | {len(movable)} | {n} | {ms_o:.3f} | {ms_l:.3f} | {ms_l / ms_o:.2f} "
            f"| {mo:.3e} | {ao:.3e} | {ml:.3e} | {al:.3e} | {dd:.3e} |"
        )
        cap = sv["gs_it2"] * (sv["gs_it1"] + 1)
        extra.append(
            f"| {name} | {sum(ours['sweeps']) / n:.1f} / {max(ours['sweeps'])} / {ours['unconverged']} "
            f"| {sum(lm['sweeps']) / n:.1f} / {max(lm['sweeps'])} / {sum(s >= cap for s in lm['sweeps'])} "
            f"| {1e9 * ours['seconds'] / max(ours['updates'], 1):.0f} | {1e9 * lm['seconds'] / max(lm['updates'], 1):.0f} "
            f"| {ours['contacts']} ({fmt_pp(ours['points_per_pair'])}) | {lm['contacts']} ({fmt_pp(lm['points_per_pair'])}) "
            f"| {1e3 * ours['process_seconds'] / n:.3f} |"
        )
    print()
    print("| scene | blocks | steps | ms/step nscdd | ms/step LMGC90 | LMGC90/nscdd "
          "| max disp nscdd (m) | mean disp nscdd | max disp LMGC90 | mean disp LMGC90 | max Δ final pos (m) |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    print("\n".join(rows))
    print()
    print("| scene | nscdd sweeps/step: mean / max / unconverged steps | LMGC90: mean / max / steps at cap "
          "| nscdd loop ns per contact·sweep | LMGC90 "
          "| contact points at end, nscdd (points×pairs) | LMGC90 | nscdd whole process ms/step |")
    print("|---|---|---|---|---|---|---|---|")
    print("\n".join(extra))
    print(f"\nscenes and outputs in {tmp}", file=sys.stderr)


if __name__ == "__main__":
    main()
