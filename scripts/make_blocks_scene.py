#!/usr/bin/env python3
"""Writes a scene of deformable blocks side by side on a floor under layers of
disks (docs/SCALING.md, "Deformable bodies stepped per rank"): the benchmark of
deformable bodies stepped per rank.

    python3 scripts/make_blocks_scene.py > blocks16.toml
    mpirun --oversubscribe -n 2 target/release/nscdd run blocks16.toml --out out/blocks16

Options: --blocks N (16), --cells NX NY per block (40 20), --steps (600),
--subdomains (8), --repartition-every (10). With --dim 3: boxes of 0.2 × 0.2 ×
0.1 m (--cells NX NY NZ, 12 12 6 by default) held at their bottom, under two
layers of spheres.
"""
import argparse

p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
p.add_argument("--blocks", type=int, default=16)
p.add_argument("--cells", type=int, nargs="+", default=None)
p.add_argument("--dim", type=int, choices=[2, 3], default=2)
p.add_argument("--steps", type=int, default=600)
p.add_argument("--subdomains", type=int, default=8)
p.add_argument("--repartition-every", type=int, default=10)
a = p.parse_args()
a.cells = a.cells or ([40, 20] if a.dim == 2 else [12, 12, 6])
if len(a.cells) != a.dim:
    p.error(f"--cells takes {a.dim} numbers in {a.dim}D")

pitch = 0.21  # a block is 0.2 m wide, 1 cm apart
width = a.blocks * pitch
if a.dim == 3:
    print("dimension = 3")
print(f"""[time]
step = 1e-3
theta = 0.5
steps = {a.steps}

[solver]
tolerance = 1e-5
max_sweeps = 20000

[detection]
alert = 0.005

[output]
every = 30
vtk = false

[decomposition]
nx = {a.subdomains}
repartition_every = {a.repartition_every}

[[materials]]
name = "soil"
density = 2000.0

[[materials]]
name = "stone"
density = 2500.0

[[laws]]
materials = ["soil", "stone"]
friction = 0.5

[[laws]]
materials = ["stone", "stone"]
friction = 0.3

[[laws]]
materials = ["soil", "soil"]
friction = 0.4
""")
if a.dim == 3:
    print(f"""[[generate]]
kind = "sphere_lattice"
material = "stone"
radius = 0.02
origin = [0.05, 0.05, 0.123]
nx = {round(width / 0.042)}
ny = 4
nz = 2
spacing = 0.042
""")
else:
    print(f"""[[bodies]]
name = "floor"
shape = "wall"
material = "stone"
position = [{width / 2 + 0.02:g}, -0.01]
length = {width + 0.24:g}
thickness = 0.02
fixed = true

[[generate]]
kind = "square_lattice"
material = "stone"
radius = 0.02
origin = [0.05, 0.123]
nx = {round(width / 0.042)}
ny = 4
spacing = 0.042
""")
for i in range(a.blocks):
    x = 0.01 + i * pitch
    if a.dim == 3:
        fix = 'fix = ["bottom"]\n'
        mesh = f"box = {{ origin = [{x:.3f}, 0.0, 0.001], size = [0.2, 0.2, 0.1], cells = [{a.cells[0]}, {a.cells[1]}, {a.cells[2]}] }}"
    else:
        fix = ""
        mesh = f"rectangle = {{ origin = [{x:.3f}, 0.001], size = [0.2, 0.1], cells = [{a.cells[0]}, {a.cells[1]}] }}"
    print(f"""[[deformable]]
name = "b{i}"
material = "soil"
young = 2e6
poisson = 0.3
{fix}mesh = {{ {mesh} }}
""")
