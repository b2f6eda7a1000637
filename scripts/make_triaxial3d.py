"""Writes a 3D triaxial scene like examples/scenes/triaxial3d.toml (which it made).

    python3 scripts/make_triaxial3d.py OUT.toml [N] [MU]

N spheres (default 1000; the box side scales with N^(1/3)), grain friction MU
(default 0.3). See the scene's header for the loading program.
"""
def scene(n=1000, mu=0.3, p=1e4, Tc=0.6, rate=0.5, eps1=0.15, h=5e-4, L=0.13, rmin=0.004, rmax=0.006, seed=1, tol=1e-4, maxsw=2000, theta=1.0, every=50, H0=0.097, wall_density=2600.0, gain=1e-5, vmax=0.1, Ts=0.2):
    t=0.005; big=L*0.75+0.02
    v=rate*H0
    dur=Tc+eps1/rate
    walls=[]
    for axis,(name0,name1) in enumerate([("xmin","xmax"),("ymin","ymax"),("zmin","zmax")]):
        for sgn,name in [(1,name0),(-1,name1)]:
            pos=[L/2,L/2,L/2]; pos[axis]= (0 - t) if sgn>0 else (L + t)
            he=[big,big,big]; he[axis]=t
            dofs=["x","y","z"]
            drv=[]
            for k in range(3):
                if k==axis:
                    servo=f'servo = {{ pressure = {p}, gain = {gain}, max_velocity = {vmax} }}, until = {Ts}'
                    press=f'pressure = {p}'
                    if name=="zmax":
                        drv.append(f'{dofs[k]} = [ {{ {servo} }}, {{ {press}, until = {Tc} }}, {{ velocity = {-v:.6g} }} ]')
                    elif name=="zmin":
                        drv.append(f'{dofs[k]} = [ {{ {servo} }}, {{ {press}, until = {Tc} }}, {{ velocity = 0.0 }} ]')
                    else:
                        drv.append(f'{dofs[k]} = [ {{ {servo} }}, {{ {press} }} ]')
                else: drv.append(f'{dofs[k]} = {{ velocity = 0.0 }}')
            drv += ['rx = { velocity = 0.0 }','ry = { velocity = 0.0 }','rz = { velocity = 0.0 }']
            walls.append(f'[[bodies]]\nname = "{name}"\nshape = "box"\nmaterial = "wall"\nhalf_extents = {he}\nposition = {pos}\ndrive = {{ {", ".join(drv)} }}\n')
    return f'''# Isotropic compaction of {n} polydisperse spheres by pressure-driven walls, then
# triaxial loading: the top wall moves down at a constant axial strain rate
# ({rate} /s) while the lateral walls keep the confining pressure ({p:g} Pa).
# Compaction: the six walls are servo-controlled (they move in at a velocity
# proportional to the pressure deficit, at most max_velocity) until t = {Ts} s, then
# pressure-driven; at t = {Tc} s the bottom wall stops, the top wall moves down.
# history.csv holds q/p, the solid fraction and the coordination numbers against
# eps1 (columns q_over_p, solid_fraction, nu_bulk, z, z_bulk, eps1);
# scripts/triaxial_plot.py draws them. theta = 1: a fast compaction makes impacts,
# and with theta < 1 the velocity-level impact law lets each one deepen an overlap
# by h (1 - theta) |u_n| (docs/EXTREMES.md).
dimension = 3
gravity = [0.0, 0.0, 0.0]

[time]
step = {h}
theta = {theta}
duration = {dur:.6g}

[solver]
tolerance = {tol}
norm = "Quad"
max_sweeps = {maxsw}

[detection]
alert = 0.0005

[output]
every = {every}
box3 = {{ xmin = "xmin", xmax = "xmax", ymin = "ymin", ymax = "ymax", zmin = "zmin", zmax = "zmax", strain_from = {Tc} }}

[[materials]]
name = "grain"
density = 2600.0

[[materials]]
name = "wall"
density = {wall_density}

[[laws]]
materials = ["grain", "grain"]
friction = {mu}

[[laws]]
materials = ["grain", "wall"]
law = "frictionless"

[[laws]]
materials = ["wall", "wall"]
law = "none"

''' + "\n".join(walls) + f'''
[[generate]]
kind = "sphere_packing"
material = "grain"
count = {n}
radius_min = {rmin}
radius_max = {rmax}
box = [0.0, 0.0, 0.0, {L}, {L}, {L}]
seed = {seed}
'''
if __name__ == "__main__":
    import sys
    n = int(sys.argv[2]) if len(sys.argv) > 2 else 1000
    mu = float(sys.argv[3]) if len(sys.argv) > 3 else 0.3
    L = 0.13 * (n / 1000.0) ** (1.0 / 3.0)
    open(sys.argv[1], "w").write(scene(n=n, mu=mu, L=L, H0=0.097 * L / 0.13))
