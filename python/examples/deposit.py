"""The deposit of 1000 disks in a box (examples/scenes/deposit.toml) run from
Python: a progress bar, the kinetic energy every 100 steps from a callback, the
final packing drawn with matplotlib.

    pip install ./python matplotlib tqdm      # from the repository root
    python python/examples/deposit.py         # writes out/deposit_py/ and deposit.png
"""
# %%
import pathlib

import numpy as np

import nscdd

ROOT = pathlib.Path(__file__).resolve().parents[2]
# %% Run the scene with a callback every 100 steps
sim = nscdd.Simulation(ROOT / "examples" / "scenes" / "deposit.toml", out="out/deposit_py")
energy = []


def kinetic(s):
    v, m = s.velocities(), s.masses()
    energy.append((s.time, 0.5 * float(np.sum(m[:, None] * v**2))))


summary = sim.run(callback=kinetic, every=100)  # to the scene's end: final.json written
print(f"{summary['steps']} steps, {summary['total_sweeps']} sweeps, {summary['wall_seconds']:.2f} s")
h = sim.history()
print(f"solid fraction {h['solid_fraction'][-1]:.3f}, contacts {int(h['contacts'][-1])}")

# %% The packing and the kinetic energy
try:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.collections import PatchCollection
    from matplotlib.patches import Circle
except ImportError:
    print("matplotlib is not installed: no picture")
    raise SystemExit(0)
x, r = sim.positions(), sim.radii()
grains = [i for i, n in enumerate(sim.names()) if n is None]
fig, (a, b) = plt.subplots(1, 2, figsize=(10, 4.5))
a.add_collection(PatchCollection([Circle(x[i], r[i]) for i in grains], facecolor="tan", edgecolor="k", lw=0.2))
a.set_xlim(0, 1), a.set_ylim(0, 1.2), a.set_aspect("equal"), a.set_title("the deposit at its end")
t, e = zip(*energy)
b.semilogy(t, e), b.set_xlabel("t (s)"), b.set_ylabel("kinetic energy (J/m)"), b.grid(alpha=0.3)
fig.tight_layout()
fig.savefig("deposit.png", dpi=100)
print("deposit.png")
