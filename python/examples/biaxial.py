"""The biaxial test of 2000 disks (examples/scenes/biaxial.toml: isotropic
compaction at 10 kPa for 0.3 s, then the top wall pushed at 0.05 m/s), and its
sin φ(ε1) and solid fraction plotted from the history.

    python python/examples/biaxial.py         # ≈ 7 s; writes biaxial.png
"""
# %%
import pathlib

import nscdd

ROOT = pathlib.Path(__file__).resolve().parents[2]
# %% Run the test
sim = nscdd.Simulation(ROOT / "examples" / "scenes" / "biaxial.toml")
sim.run()
h = sim.history()
load = h["time"] >= 0.3  # the loading phase
eps1, sin_phi, nu = h["eps1"][load], h["sin_phi"][load], h["solid_fraction"][load]
print(f"peak sin φ {sin_phi.max():.3f} at ε1 = {100 * eps1[sin_phi.argmax()]:.2f} %")

# %% sin φ(ε1) and the solid fraction
try:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
except ImportError:
    print("matplotlib is not installed: no plot")
    raise SystemExit(0)
fig, (a, b) = plt.subplots(1, 2, figsize=(10, 4))
a.plot(100 * eps1, sin_phi, lw=0.5, alpha=0.5, label="every step")
k = 51  # a centred moving average over 51 steps
smooth = [sin_phi[max(0, i - k // 2) : i + k // 2 + 1].mean() for i in range(len(sin_phi))]
a.plot(100 * eps1, smooth, label="moving average (51 steps)")
a.set_xlabel("ε1 (%)"), a.set_ylabel("sin φ = (σ1 − σ3)/(σ1 + σ3)"), a.legend(), a.grid(alpha=0.3)
b.plot(100 * eps1, nu), b.set_xlabel("ε1 (%)"), b.set_ylabel("solid fraction"), b.grid(alpha=0.3)
fig.tight_layout()
fig.savefig("biaxial.png", dpi=100)
print("biaxial.png")
