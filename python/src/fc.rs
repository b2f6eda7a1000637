//! `solve_fc` (the package wraps `_solve_fc_coo`): one frictional contact problem
//! from NumPy arrays, solved by the framework's `fc` solvers.

use numpy::{PyArray1, PyReadonlyArray1};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;

/// Solves u = W r + q with Coulomb's law of friction coefficients mu per contact
/// (dim = 2 or 3 unknowns each, normal first). W: a dense (n, n) array or a scipy
/// sparse matrix (given as its COO rows, cols, vals: see the package wrapper).
/// Returns a dict: r, u, sweeps, converged, residual (natural map), norms.
#[pyfunction]
#[pyo3(signature = (rows, cols, vals, q, mu, *, method="nlgs", tol=1e-8, max_sweeps=100_000, norm="natural", check_every=1, relaxation=1.0, r0=None))]
#[allow(clippy::too_many_arguments)]
pub fn _solve_fc_coo<'py>(
    py: Python<'py>,
    rows: PyReadonlyArray1<'py, i64>,
    cols: PyReadonlyArray1<'py, i64>,
    vals: PyReadonlyArray1<'py, f64>,
    q: PyReadonlyArray1<'py, f64>,
    mu: PyReadonlyArray1<'py, f64>,
    method: &str,
    tol: f64,
    max_sweeps: u32,
    norm: &str,
    check_every: u32,
    relaxation: f64,
    r0: Option<PyReadonlyArray1<'py, f64>>,
) -> PyResult<Bound<'py, PyDict>> {
    use nscdd::fc::{CooMatrix, FcNorm, FcOptions, FcProblem};
    let q = q.as_slice()?.to_vec();
    let mu = mu.as_slice()?.to_vec();
    let nc = mu.len();
    if nc == 0 || q.len() % nc != 0 || !(2..=3).contains(&(q.len() / nc)) {
        return Err(PyValueError::new_err(format!(
            "q has {} values for {nc} contacts: 2 or 3 per contact",
            q.len()
        )));
    }
    let idx = |a: PyReadonlyArray1<'py, i64>| -> PyResult<Vec<usize>> {
        a.as_slice()?
            .iter()
            .map(|&x| usize::try_from(x).map_err(|_| PyValueError::new_err("negative index in W")))
            .collect()
    };
    let w = CooMatrix {
        n: q.len(),
        rows: idx(rows)?,
        cols: idx(cols)?,
        vals: vals.as_slice()?.to_vec(),
    };
    let p = FcProblem {
        dim: q.len() / nc,
        nc,
        w,
        q,
        mu,
        meta: None,
    };
    p.validate().map_err(|(k, m)| PyValueError::new_err(format!("{k}: {m}")))?;
    let method = nscdd::solver::Method::parse(method)
        .ok_or_else(|| PyValueError::new_err(format!("unknown method `{method}`: nlgs, anderson or newton")))?;
    let norm = FcNorm::parse(norm).ok_or_else(|| PyValueError::new_err(format!("unknown norm `{norm}`: natural, Quad, Maxm or QM/16")))?;
    if !(tol > 0.0) || max_sweeps == 0 || check_every == 0 {
        return Err(PyValueError::new_err("tol > 0, max_sweeps ≥ 1 and check_every ≥ 1"));
    }
    if !(relaxation > 0.0 && relaxation < 2.0) || (method == nscdd::solver::Method::Newton && relaxation != 1.0) {
        return Err(PyValueError::new_err(format!(
            "relaxation: ω must lie in (0, 2) (and be 1 with newton), got {relaxation}"
        )));
    }
    let opts = FcOptions {
        tol,
        max_sweeps,
        check_every,
        norm,
        method,
        relaxation,
    };
    let r0 = r0.map(|r| r.as_slice().map(|s| s.to_vec())).transpose()?;
    if r0.as_ref().is_some_and(|r| r.len() != p.q.len()) {
        return Err(PyValueError::new_err("r0 has not the length of q"));
    }
    let sol = py.detach(|| p.solve_from(r0.as_deref(), &opts));
    let d = PyDict::new(py);
    d.set_item("r", PyArray1::from_vec(py, sol.r))?;
    d.set_item("u", PyArray1::from_vec(py, sol.u))?;
    d.set_item("sweeps", sol.sweeps)?;
    d.set_item("converged", sol.converged)?;
    d.set_item("residual", sol.residual)?;
    d.set_item("seconds", sol.solve_seconds)?;
    let norms = serde_json::to_string(&sol.norms).unwrap_or_default();
    d.set_item("norms", py.import("json")?.call_method1("loads", (norms,))?)?;
    Ok(d)
}
