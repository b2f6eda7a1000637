"""Writes the seed's 3D NSCDD benchmark scene (examples/scenes/triaxial55k.toml is its output).

    python3 scripts/make_seed_triaxial.py OUT.toml [N] [--decomposition 2x2x1] [--steps 500]

The seed's run (DESIGN.md; its slides, "3D NSCDD simulation using MPI library"): an
isotropic triaxial compaction of 55 000 spheres, 500 steps of h = 1e-2 s, the walls
pushed by F0 = 60 kN, repartition every 10 steps, output every 250 steps, QM/16 at
1.66e-4. The seed does not give the grains; here: radii uniform in [4, 6] cm (density
2600, mu = 0.3 between grains, frictionless walls, no gravity), placed at random
without overlap in a cube of solid fraction 0.25 (side 4.9 m for 55 000), six rigid
box walls each pushed inward by a constant 60 kN (the other degrees of freedom held).
theta = 1: the walls reach the grains at about 1 m/s.
"""
import argparse


def scene(n=55000, dec=(2, 2, 1), steps=500, f0=6.0e4, rmin=0.04, rmax=0.06, phi0=0.25, seed=1, max_sweeps=1000):
    r3 = (rmax ** 4 - rmin ** 4) / (4.0 * (rmax - rmin))  # <r^3> for uniform radii
    vol = n * 4.0 / 3.0 * 3.141592653589793 * r3 / phi0
    L = vol ** (1.0 / 3.0)
    t = 0.1  # wall half-thickness
    big = 0.75 * L + 0.2
    walls = []
    for axis, names in enumerate([("xmin", "xmax"), ("ymin", "ymax"), ("zmin", "zmax")]):
        for sgn, name in zip((1, -1), names):
            pos = [L / 2] * 3
            pos[axis] = -t if sgn > 0 else L + t
            he = [big] * 3
            he[axis] = t
            drv = []
            for k, dof in enumerate("xyz"):
                drv.append(f"{dof} = {{ force = {sgn * f0:.6g} }}" if k == axis else f"{dof} = {{ velocity = 0.0 }}")
            drv += [f"{d} = {{ velocity = 0.0 }}" for d in ("rx", "ry", "rz")]
            walls.append(
                f'[[bodies]]\nname = "{name}"\nshape = "box"\nmaterial = "wall"\nhalf_extents = [{he[0]:.6g}, {he[1]:.6g}, {he[2]:.6g}]\n'
                f"position = [{pos[0]:.6g}, {pos[1]:.6g}, {pos[2]:.6g}]\ndrive = {{ {', '.join(drv)} }}\n")
    nx, ny, nz = dec
    ddec = "" if dec == (1, 1, 1) else f"[decomposition]\nnx = {nx}\nny = {ny}\nnz = {nz}\nrepartition_every = 10\n"
    return f"""# The seed's 3D NSCDD benchmark: isotropic triaxial compaction of {n} spheres,
# {steps} steps of h = 1e-2 s, six walls pushed by F0 = {f0:g} N, QM/16 at 1.66e-4,
# repartition every 10 steps, output every 250 steps (written by
# scripts/make_seed_triaxial.py; the seed: 7068 s on 1 process, 1454 s on 8, 2012).
#   cargo run --release -- run examples/scenes/triaxial55k.toml --out out/t55k
#   mpirun -n 2 target/release/nscdd run examples/scenes/triaxial55k.toml --out out/t55k  (feature mpi)
dimension = 3
gravity = [0.0, 0.0, 0.0]

[time]
step = 0.01
theta = 1.0
steps = {steps}

[solver]
norm = "QM/16"
tolerance = 1.66e-4
max_sweeps = {max_sweeps}

[detection]
alert = 0.01

[output]
every = 250

{ddec}
[[materials]]
name = "grain"
density = 2600.0

[[materials]]
name = "wall"
density = 2600.0

[[laws]]
materials = ["grain", "grain"]
friction = 0.3

[[laws]]
materials = ["grain", "wall"]
law = "frictionless"

[[laws]]
materials = ["wall", "wall"]
law = "none"

""" + "\n".join(walls) + f"""
[[generate]]
kind = "sphere_packing"
material = "grain"
count = {n}
radius_min = {rmin}
radius_max = {rmax}
box = [0.0, 0.0, 0.0, {L:.6g}, {L:.6g}, {L:.6g}]
seed = {seed}
"""


if __name__ == "__main__":
    ap = argparse.ArgumentParser()
    ap.add_argument("out")
    ap.add_argument("n", type=int, nargs="?", default=55000)
    ap.add_argument("--decomposition", default="2x2x1")
    ap.add_argument("--steps", type=int, default=500)
    a = ap.parse_args()
    dec = tuple(int(v) for v in a.decomposition.split("x"))
    open(a.out, "w").write(scene(a.n, dec, a.steps))
