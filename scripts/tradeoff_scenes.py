"""The scenes of the speed/accuracy study (scripts/tradeoff_study.py) beside the 2D biaxial
test of scripts/study_common.py: the 3D triaxial test of scripts/make_triaxial3d.py and an
in-plane pushover of a dry brick wall (polyhedra, masonry).

Each builder returns the TOML text for one stage ("prepare": the state every run restarts
from; "load": the measured part) with the solver settings of one configuration.
"""
import os
import re
import sys

sys.path.insert(0, os.path.dirname(__file__))
import make_triaxial3d  # noqa: E402

TRIAX_TC = 0.6  # end of the isotropic compaction (make_triaxial3d's Tc)
TRIAX_RATE = 0.5  # axial strain rate of the loading (1/s)
WALL_T0 = 0.05  # the pusher starts moving (the wall has settled under its weight)
WALL_V = 0.05  # pusher velocity (m/s)


def solver_block(tol, method, max_sweeps, norm="Quad", ordering="stored"):
    m = "" if method == "nlgs" else f'method = "{method}"\n'
    m += "" if ordering == "stored" else f'ordering = "{ordering}"\n'
    return f'[solver]\ntolerance = {tol}\nnorm = "{norm}"\nmax_sweeps = {max_sweeps}\n{m}'


def decomposition_block(dec, axes):
    """`dec` like "2x2" or "2x2x1" (None or all ones: no decomposition); axes: "xy" or "xyz"."""
    if not dec:
        return ""
    parts, sw = dec.split("/s") if "/s" in dec else (dec, "1")
    counts = [int(v) for v in parts.split("x")]
    if all(c == 1 for c in counts):
        return ""
    lines = [f"n{a} = {c}" for a, c in zip(axes, counts)] + [f"sweeps_per_gluing = {sw}"]
    return "[decomposition]\n" + "\n".join(lines) + "\n"


def triaxial_scene(stage, eps1, tol=1e-4, method="nlgs", max_sweeps=2000, dec=None, ordering="stored", n=1000):
    """1000 spheres: compaction to TRIAX_TC ("prepare"), then axial loading to eps1."""
    L = 0.13 * (n / 1000.0) ** (1.0 / 3.0)
    text = make_triaxial3d.scene(n=n, L=L, H0=0.097 * L / 0.13, tol=tol, maxsw=max_sweeps, every=0)
    dur = TRIAX_TC if stage == "prepare" else TRIAX_TC + eps1 / TRIAX_RATE + 1e-6
    text = re.sub(r"duration = .*", f"duration = {dur:.6f}", text)
    text = re.sub(r"\[solver\]\n(.*\n){3}", solver_block(tol, method, max_sweeps, ordering=ordering), text)
    text = text.replace("[output]\n", "[output]\nvtk = false\n")
    return text + "\n" + decomposition_block(dec, "xyz")


def wall_scene(stage, duration, tol=1.666e-4, method="nlgs", max_sweeps=2000, dec=None, ordering="stored", courses=10, bricks=6):
    """A running-bond wall (courses x bricks of 0.2 x 0.1 x 0.05 m) on a fixed slab, pushed
    in its plane near the top by a rigid plate moving at WALL_V from WALL_T0 on."""
    top = courses * 0.05
    dur = WALL_T0 if stage == "prepare" else duration
    return f"""dimension = 3
gravity = [0.0, 0.0, -9.81]
[time]
step = 1e-3
theta = 0.5
duration = {dur:.6f}
{solver_block(tol, method, max_sweeps, norm="QM/16", ordering=ordering)}
[detection]
alert = 0.002
[output]
every = 0
vtk = false
[[materials]]
name = "brick"
density = 1800.0
[[materials]]
name = "base"
density = 2400.0
[[materials]]
name = "steel"
density = 7800.0
[[laws]]
materials = ["brick", "brick"]
friction = 0.6
[[laws]]
materials = ["brick", "base"]
friction = 0.6
[[laws]]
materials = ["brick", "steel"]
friction = 0.3
[[laws]]
materials = ["base", "base"]
law = "none"
[[laws]]
materials = ["steel", "base"]
law = "none"
[[laws]]
materials = ["steel", "steel"]
law = "none"
[[bodies]]
name = "pusher"
shape = "polyhedron"
material = "steel"
vertices = [{", ".join(f"[{x}, {y}, {z}]" for x in (-0.02, 0.02) for y in (-0.06, 0.06) for z in (-0.1, 0.1))}]
position = [-0.0205, 0.05, {top - 0.1}]
drive = {{ x = [ {{ velocity = 0.0, until = {WALL_T0} }}, {{ velocity = {WALL_V} }} ], y = {{ velocity = 0.0 }}, z = {{ velocity = 0.0 }}, rx = {{ velocity = 0.0 }}, ry = {{ velocity = 0.0 }}, rz = {{ velocity = 0.0 }} }}
[[generate]]
kind = "brick_wall"
material = "brick"
base_material = "base"
brick = [0.2, 0.1, 0.05]
courses = {courses}
bricks = {bricks}
{decomposition_block(dec, "xyz")}"""
