//! FCLIB problems (HDF5), read into the local form [`FcProblem`] (cargo feature
//! `hdf5`, which needs the HDF5 C library: Debian's `libhdf5-dev`).
//!
//! Layout (see `shared/FC_JSON.md`): a local problem is the group `/fclib_local`
//! with `spacedim`, the matrix `W` and `vectors/q`, `vectors/mu`; a global problem is
//! `/fclib_global` with the matrices `M` (ndof × ndof) and `H` (ndof × dim·nc) and
//! `vectors/f`, `vectors/w`, `vectors/mu`, for
//!
//! ```text
//! M v = H r + f,   u = Hᵀ v + w   ⇒   u = W r + q,   W = Hᵀ M⁻¹ H,   q = Hᵀ M⁻¹ f + w.
//! ```
//!
//! The condensation factors M once with faer's sparse Cholesky (symbolic analysis
//! and numeric factorization), solves `M x_j = h_j` for every column of H, keeps the
//! non-zeros of x_j, and forms `W_ij = h_iᵀ x_j` through the rows of H that x_j
//! touches, so that a block-diagonal M (rigid bodies) gives a sparse W.
//!
//! A matrix group holds `m`, `n`, `nz`, `nzmax` and the arrays `p`, `i`, `x`:
//! `nz ≥ 0` triplets (`i` rows, `p` columns), `nz = −1` compressed columns, `nz = −2`
//! compressed rows. Stored `solution` groups are ignored (re-solve them).

use super::{CooMatrix, FcProblem};
use crate::error::InputError;
use faer::prelude::*;
use faer::sparse::{SparseColMat, Triplet};
use faer::Side;
use std::path::Path;

/// A matrix read from a group, as triplets.
struct Coo {
    m: usize,
    n: usize,
    t: Vec<(usize, usize, f64)>,
}

type R<T> = Result<T, (String, String)>;

fn int_vec(g: &hdf5::Group, name: &str, path: &str) -> R<Vec<i64>> {
    let ds = g
        .dataset(name)
        .map_err(|e| (format!("{path}/{name}"), format!("missing dataset: {e}")))?;
    ds.read_raw::<i64>()
        .or_else(|_| ds.read_raw::<i32>().map(|v| v.into_iter().map(i64::from).collect()))
        .map_err(|e| (format!("{path}/{name}"), format!("expected integers: {e}")))
}

fn f64_vec(g: &hdf5::Group, name: &str, path: &str) -> R<Vec<f64>> {
    g.dataset(name)
        .and_then(|d| d.read_raw::<f64>())
        .map_err(|e| (format!("{path}/{name}"), format!("expected a dataset of numbers: {e}")))
}

fn scalar(g: &hdf5::Group, name: &str, path: &str) -> R<i64> {
    int_vec(g, name, path)?
        .first()
        .copied()
        .ok_or_else(|| (format!("{path}/{name}"), "empty dataset".to_string()))
}

fn matrix(g: &hdf5::Group, name: &str, path: &str) -> R<Coo> {
    let path = format!("{path}/{name}");
    let g = g.group(name).map_err(|e| (path.clone(), format!("missing matrix group: {e}")))?;
    let m = scalar(&g, "m", &path)?;
    let n = scalar(&g, "n", &path)?;
    let nz = scalar(&g, "nz", &path)?;
    let p = int_vec(&g, "p", &path)?;
    let i = int_vec(&g, "i", &path)?;
    let x = f64_vec(&g, "x", &path)?;
    if m < 0 || n < 0 {
        return Err((path, format!("negative size {m} × {n}")));
    }
    let (m, n) = (m as usize, n as usize);
    let idx = |v: i64, bound: usize, what: &str| -> R<usize> {
        if v < 0 || v as usize >= bound {
            Err((path.clone(), format!("{what} index {v} out of range 0..{bound}")))
        } else {
            Ok(v as usize)
        }
    };
    let mut t = Vec::new();
    match nz {
        k if k >= 0 => {
            let k = k as usize;
            if i.len() < k || p.len() < k || x.len() < k {
                return Err((path, format!("nz = {k} but the arrays hold fewer entries")));
            }
            for e in 0..k {
                t.push((idx(i[e], m, "row")?, idx(p[e], n, "column")?, x[e]));
            }
        }
        -1 | -2 => {
            let (outer, inner) = if nz == -1 { (n, m) } else { (m, n) };
            if p.len() < outer + 1 {
                return Err((path, format!("p must hold {} pointers", outer + 1)));
            }
            for o in 0..outer {
                let (a, b) = (p[o], p[o + 1]);
                if a < 0 || b < a || b as usize > i.len().min(x.len()) {
                    return Err((path, format!("bad pointers p[{o}..{}] = {a}, {b}", o + 1)));
                }
                for e in a as usize..b as usize {
                    let k = idx(i[e], inner, "index")?;
                    t.push(if nz == -1 { (k, o, x[e]) } else { (o, k, x[e]) });
                }
            }
        }
        k => return Err((path, format!("nz = {k}: expected ≥ 0 (triplets), −1 (CSC) or −2 (CSR)"))),
    }
    if t.iter().any(|e| !e.2.is_finite()) {
        return Err((path, "non-finite entry".into()));
    }
    Ok(Coo { m, n, t })
}

/// Reads an FCLIB file (local or global) as a local problem, validated.
pub fn read(path: &Path) -> Result<FcProblem, InputError> {
    let file = path.display().to_string();
    let err = |(key, message): (String, String)| InputError {
        file: file.clone(),
        line: None,
        key,
        message,
    };
    let f = hdf5::File::open(path).map_err(|e| err((String::new(), format!("cannot open the HDF5 file: {e}"))))?;
    let p = if f.link_exists("fclib_local") {
        local(&f).map_err(err)?
    } else if f.link_exists("fclib_global") {
        global(&f).map_err(err)?
    } else {
        return Err(err((
            String::new(),
            "neither /fclib_local nor /fclib_global: not an FCLIB problem".into(),
        )));
    };
    p.validate().map_err(err)?;
    Ok(p)
}

fn dim_of(g: &hdf5::Group, path: &str) -> R<usize> {
    match scalar(g, "spacedim", path)? {
        d @ (2 | 3) => Ok(d as usize),
        d => Err((format!("{path}/spacedim"), format!("{d}: expected 2 or 3"))),
    }
}

fn local(f: &hdf5::File) -> R<FcProblem> {
    let g = f.group("fclib_local").map_err(|e| ("/fclib_local".into(), e.to_string()))?;
    let dim = dim_of(&g, "/fclib_local")?;
    let w = matrix(&g, "W", "/fclib_local")?;
    let v = g.group("vectors").map_err(|e| ("/fclib_local/vectors".into(), e.to_string()))?;
    let q = f64_vec(&v, "q", "/fclib_local/vectors")?;
    let mu = f64_vec(&v, "mu", "/fclib_local/vectors")?;
    if w.m != w.n {
        return Err(("/fclib_local/W".into(), format!("W is {} × {}: expected square", w.m, w.n)));
    }
    let nc = mu.len();
    // before W is made: its size comes from the file
    if w.n != dim * nc || q.len() != w.n {
        return Err((
            "/fclib_local".into(),
            format!(
                "sizes disagree: {nc} contacts in {dim}D need W of {0} × {0} and q of {0}; W is {1} × {1}, q {2}",
                dim * nc,
                w.n,
                q.len()
            ),
        ));
    }
    Ok(FcProblem {
        dim,
        nc,
        w: CooMatrix::from_triplets(w.n, &w.t),
        q,
        mu,
        meta: Some(serde_json::json!({ "source": "FCLIB local problem" })),
    })
}

fn global(f: &hdf5::File) -> R<FcProblem> {
    let base = "/fclib_global";
    let g = f.group("fclib_global").map_err(|e| (base.into(), e.to_string()))?;
    let dim = dim_of(&g, base)?;
    let m = matrix(&g, "M", base)?;
    let h = matrix(&g, "H", base)?;
    let v = g.group("vectors").map_err(|e| (format!("{base}/vectors"), e.to_string()))?;
    let fv = f64_vec(&v, "f", &format!("{base}/vectors"))?;
    let w = f64_vec(&v, "w", &format!("{base}/vectors"))?;
    let mu = f64_vec(&v, "mu", &format!("{base}/vectors"))?;
    let nd = m.n;
    if m.m != nd || h.m != nd || fv.len() != nd {
        return Err((
            base.into(),
            format!("sizes disagree: M {} × {}, H {} × {}, f {}", m.m, m.n, h.m, h.n, fv.len()),
        ));
    }
    if h.n != dim * mu.len() || w.len() != h.n {
        return Err((
            base.into(),
            format!(
                "sizes disagree: {} contacts in {dim}D need H with {} columns and w of {}; H has {}, w {}",
                mu.len(),
                dim * mu.len(),
                dim * mu.len(),
                h.n,
                w.len()
            ),
        ));
    }
    let (wm, q) = condense(&m, &h, &fv, &w).map_err(|e| (format!("{base}/M"), e))?;
    Ok(FcProblem {
        dim,
        nc: mu.len(),
        w: wm,
        q,
        mu,
        meta: Some(serde_json::json!({ "source": "FCLIB global problem condensed: W = Hᵀ M⁻¹ H, q = Hᵀ M⁻¹ f + w" })),
    })
}

/// W = Hᵀ M⁻¹ H and q = Hᵀ M⁻¹ f + w (see the module docs).
fn condense(m: &Coo, h: &Coo, f: &[f64], w: &[f64]) -> Result<(CooMatrix, Vec<f64>), String> {
    let nd = m.n;
    // the lower triangle of M, whether the file stores it whole or one triangle
    let (lo, up) =
        m.t.iter()
            .fold((0, 0), |(l, u), e| (l + (e.0 > e.1) as usize, u + (e.0 < e.1) as usize));
    let mut trip: Vec<Triplet<usize, usize, f64>> = Vec::with_capacity(m.t.len());
    for &(r, c, v) in &m.t {
        if r >= c {
            trip.push(Triplet::new(r, c, v));
        } else if lo == 0 && up > 0 {
            trip.push(Triplet::new(c, r, v));
        }
    }
    let mat = SparseColMat::<usize, f64>::try_new_from_triplets(nd, nd, &trip).map_err(|e| format!("cannot build M: {e:?}"))?;
    let llt = mat
        .sp_cholesky(Side::Lower)
        .map_err(|e| format!("M is not symmetric positive definite: {e:?}"))?;
    let nu = h.n;
    // H by columns and by rows
    let mut hcol: Vec<Vec<(usize, f64)>> = vec![Vec::new(); nu];
    let mut hrow: Vec<Vec<(usize, f64)>> = vec![Vec::new(); nd];
    for &(r, c, v) in &h.t {
        hcol[c].push((r, v));
        hrow[r].push((c, v));
    }
    let mut wt: Vec<(usize, usize, f64)> = Vec::new();
    let mut x = Mat::<f64>::zeros(nd, 1);
    let mut acc = vec![0.0; nu];
    let mut touched: Vec<usize> = Vec::new();
    for j in 0..nu {
        x.fill(0.0);
        for &(r, v) in &hcol[j] {
            x[(r, 0)] += v;
        }
        llt.solve_in_place(x.as_mut());
        // W_ij = Σ_k H_ki x_k over the rows k where x is non-zero
        for k in 0..nd {
            let xk = x[(k, 0)];
            if xk == 0.0 {
                continue;
            }
            for &(i, hv) in &hrow[k] {
                if acc[i] == 0.0 {
                    touched.push(i);
                }
                acc[i] += hv * xk;
            }
        }
        touched.sort_unstable();
        touched.dedup();
        for &i in &touched {
            if acc[i] != 0.0 {
                wt.push((i, j, acc[i]));
            }
            acc[i] = 0.0;
        }
        touched.clear();
    }
    // q = Hᵀ M⁻¹ f + w
    let mut xf = Mat::<f64>::from_fn(nd, 1, |r, _| f[r]);
    llt.solve_in_place(xf.as_mut());
    let mut q = w.to_vec();
    for &(r, c, v) in &h.t {
        q[c] += v * xf[(r, 0)];
    }
    Ok((CooMatrix::from_triplets(nu, &wt), q))
}
