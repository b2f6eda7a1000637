"""A parameter sweep: the peak friction angle of a biaxial sample against the
grains' friction coefficient μ, one process per value (the runs are independent;
each steps with the GIL released, but processes use every core whatever the GIL).

    python python/examples/mu_sweep.py [--workers 2] [--quick]

Each run loads examples/scenes/biaxial.toml as a dict (tomllib), changes the
grain–grain law's friction and the sample's seed stays the same, so only μ
differs. --quick: the loading stops at ε1 ≈ 2 % (the mobilized sin φ there).
"""
# %%
import concurrent.futures
import pathlib
import sys
import tomllib

import nscdd

ROOT = pathlib.Path(__file__).resolve().parents[2]


# %% One run per friction coefficient
def scene(mu, quick):
    s = tomllib.loads((ROOT / "examples" / "scenes" / "biaxial.toml").read_text())
    for law in s["laws"]:
        if law["materials"] == ["grain", "grain"]:
            law["friction"] = mu
    if quick:
        s["time"]["duration"] = 0.5  # loading to ε1 ≈ 2 %
    return s


def peak(mu, quick=False):
    sim = nscdd.Simulation(scene(mu, quick))
    sim.run(progress=False)
    h = sim.history()
    load = h["time"] >= 0.3
    s = h["sin_phi"][load]
    k = 51
    smooth = [s[max(0, i - k // 2) : i + k // 2 + 1].mean() for i in range(len(s))]
    return mu, max(smooth)


# %% The sweep, in parallel processes
if __name__ == "__main__":
    workers = int(sys.argv[sys.argv.index("--workers") + 1]) if "--workers" in sys.argv else 2
    quick = "--quick" in sys.argv
    mus = [0.1, 0.2, 0.3, 0.4, 0.5, 0.7]
    with concurrent.futures.ProcessPoolExecutor(workers) as pool:
        results = sorted(pool.map(peak, mus, [quick] * len(mus)))
    for mu, s in results:
        print(f"μ = {mu:.1f}: peak sin φ = {s:.3f}")
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        print("matplotlib is not installed: no plot")
    raise SystemExit(0)
    fig, ax = plt.subplots(figsize=(5, 4))
    ax.plot(*zip(*results), "o-")
    ax.set_xlabel("grain friction μ"), ax.set_ylabel("peak sin φ (51-step average)"), ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig("mu_sweep.png", dpi=100)
    print("mu_sweep.png")
