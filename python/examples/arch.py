"""A masonry arch that collapses: the semicircular arch of
examples/scenes/arch.toml (24 radial voussoirs of convex polyhedra on two
supports) made thinner than its minimum (t/R = 0.09 < 0.1075), run until it has
formed its mechanism, and its hinges drawn: the joints between consecutive
voussoirs that turn (relative rotation), and each voussoir's rotation.

    python python/examples/arch.py            # writes arch.png
"""
# %%
import pathlib
import tomllib

import numpy as np

import nscdd

ROOT = pathlib.Path(__file__).resolve().parents[2]
# %% A thin arch, run until its mechanism forms
s = tomllib.loads((ROOT / "examples" / "scenes" / "arch.toml").read_text())
s["generate"][0]["thickness"] = 0.09
s["time"]["duration"] = 0.25
sim = nscdd.Simulation(s)
x0, rot0 = sim.positions(), sim.rotations()
sim.run()
x, rot = sim.positions(), sim.rotations()


# %% Each voussoir's rotation and the joints that turn
def matrix(v):
    """Rodrigues: the rotation matrix of a rotation vector."""
    t = np.linalg.norm(v)
    if t < 1e-15:
        return np.eye(3)
    k = v / t
    K = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
    return np.eye(3) + np.sin(t) * K + (1 - np.cos(t)) * K @ K


def angle(r):
    return np.degrees(np.arccos(np.clip((np.trace(r) - 1) / 2, -1, 1)))


R = [matrix(v) @ matrix(v0).T for v, v0 in zip(rot, rot0)]  # each block's rotation since the start
turned = np.array([angle(r) for r in R])
drop = x0[:, 2] - x[:, 2]
print(f"largest drop of a voussoir {1000 * drop.max():.1f} mm; largest rotation {turned.max():.2f}°")
# the joints between consecutive voussoirs (by their angle around the arch), and
# each one's relative rotation: the mechanism's hinges are the joints that turn
blocks = [i for i, n in enumerate(sim.names()) if n is None or "support" not in n]
blocks = [i for i in blocks if x0[i, 2] > 0.0]
order = sorted(blocks, key=lambda i: -np.arctan2(x0[i, 2], x0[i, 0]))
joint = [(order[k], order[k + 1]) for k in range(len(order) - 1)]
relative = np.array([angle(R[j] @ R[i].T) for i, j in joint])
hinges = [0.5 * (x[i] + x[j]) for (i, j), a in zip(joint, relative) if a > 0.25 * relative.max()]
print(f"{len(hinges)} hinges (joints turning by more than a quarter of the largest, {relative.max():.2f}°)")

# %% The picture
try:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
except ImportError:
    print("matplotlib is not installed: no picture")
    raise SystemExit(0)
fig, ax = plt.subplots(figsize=(7, 4))
sc = ax.scatter(x[:, 0], x[:, 2], c=turned, cmap="viridis", s=80, label="voussoirs (colour: rotation °)")
ax.scatter(x0[:, 0], x0[:, 2], facecolors="none", edgecolors="0.6", s=80, label="at the start")
if hinges:
    h = np.array(hinges)
    ax.scatter(h[:, 0], h[:, 2], marker="x", color="red", s=60, label="hinges")
fig.colorbar(sc, ax=ax, label="rotation (°)")
ax.set_aspect("equal"), ax.set_xlabel("x (m)"), ax.set_ylabel("z (m)"), ax.legend(fontsize=7)
ax.set_title("an arch of t/R = 0.09 forms its mechanism")
fig.tight_layout()
fig.savefig("arch.png", dpi=100)
print("arch.png")
