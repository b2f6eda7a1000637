"""nscdd: non-smooth contact dynamics with domain decomposition, from Python.

    import nscdd
    sim = nscdd.Simulation("examples/scenes/deposit.toml", out="out/deposit")
    sim.run()                      # to the scene's end: history.csv, VTK, final.json
    x = sim.positions()            # (n, 2) NumPy array
    h = sim.history()              # dict of arrays (as_frame=True: a pandas DataFrame)

See docs/PYTHON.md for the whole API.
"""

from ._nscdd import RunError, SceneError, Simulation, __version__, _solve_fc_coo

__all__ = ["Simulation", "SceneError", "RunError", "solve_fc", "__version__"]


def solve_fc(W, q, mu, *, method="nlgs", tol=1e-8, max_sweeps=100_000, norm="natural", check_every=1, r0=None, relaxation=1.0):
    """Solves the frictional contact problem u = W r + q, Coulomb's law per contact.

    W: a dense (n, n) array or a scipy.sparse matrix (n = dim × contacts, each
    contact's unknowns normal first); q: (n,); mu: (contacts,) friction
    coefficients. method: "nlgs", "anderson" or "newton"; norm: "natural" (the
    natural-map residual ‖F(r)‖/‖q‖ < tol) or one of LMGC90's "Quad", "Maxm",
    "QM/16"; r0: a warm start; relaxation: ω of the NLGS sweeps (NLGS and
    Anderson's map) in (0, 2), over-relaxed and projected above 1. Returns a dict: r, u, sweeps (iterations),
    converged, residual, seconds, norms.
    """
    import numpy as np

    if hasattr(W, "tocoo"):
        c = W.tocoo()
        rows, cols, vals = c.row, c.col, c.data
    else:
        W = np.asarray(W, dtype=float)
        if W.ndim != 2 or W.shape[0] != W.shape[1]:
            raise ValueError(f"W must be square, got shape {W.shape}")
        rows, cols = np.nonzero(W)
        vals = W[rows, cols]
    return _solve_fc_coo(
        np.ascontiguousarray(rows, dtype=np.int64),
        np.ascontiguousarray(cols, dtype=np.int64),
        np.ascontiguousarray(vals, dtype=float),
        np.ascontiguousarray(q, dtype=float).ravel(),
        np.ascontiguousarray(mu, dtype=float).ravel(),
        method=method,
        tol=tol,
        max_sweeps=max_sweeps,
        norm=norm,
        check_every=check_every,
        relaxation=relaxation,
        r0=None if r0 is None else np.ascontiguousarray(r0, dtype=float).ravel(),
    )
