//! Frictional contact problems in local (Delassus) form, read from the JSON exchange
//! format (keys `dim`, `nc`, `W` = {`n`, `rows`, `cols`, `vals`}, `q`, `mu`, optional
//! `meta`; `.gz` files are gzip) and solved by NLGS, Anderson-accelerated NLGS
//! ([`anderson`]) or a semismooth Newton method ([`newton`]) as
//! [`FcOptions::method`] says: the `solve-fc` command, and the one-domain stage
//! of a world whose `[solver] method` is Newton ([`solve_world`]).
//!
//! A problem with `nc` contacts in dimension `dim` (2 or 3) is: find
//! `r, u ∈ ℝ^{dim·nc}` with
//!
//! ```text
//! u = W r + q,     for each contact α:  (u_α, r_α) satisfies Signorini–Coulomb with μ_α
//!   u_n ≥ 0,  r_n ≥ 0,  u_n r_n = 0,   |r_t| ≤ μ r_n,
//!   |r_t| < μ r_n ⇒ u_t = 0,           u_t ≠ 0 ⇒ r_t = −μ r_n u_t/|u_t|
//! ```
//!
//! `W` (symmetric, given as coordinate triplets, duplicates summed) is stored per
//! contact as its diagonal block `W_αα` (symmetrised) and the off-diagonal dim × dim
//! blocks `W_αβ` in compressed rows ([`nlgs`]). One NLGS sweep visits the contacts in
//! storage order and, for α, forms
//!
//! ```text
//! u0_α = q_α + Σ_{β≠α} W_αβ r_β   (= u_α − W_αα r_α),
//! r_α  ← the one-contact solution for (W_αα, u0_α, μ_α)   (dim::coulomb2, dim::coulomb3)
//! ```
//!
//! FCLIB's HDF5 files are read by [`fclib`] (cargo feature `hdf5`).
//!
//! Stopping tests: [`FcNorm::Natural`], the natural-map residual
//! `‖F(r)‖ / ‖q‖ < tol` with `F(r) = r − P_K(r − (u + Φ(u)))`, `Φ(u)_α = (μ_α |u_t,α|, 0)`
//! (divided by 1 when `q = 0`), evaluated every `check_every` sweeps; or
//! [`FcNorm::Lmgc`], LMGC90's norms over a non-updating check pass exactly as
//! [`crate::solver::nlgs`] does (see [`crate::norms`]). Every method stops on the
//! same test; the final residual is always the natural-map one, and the final
//! norms are reported beside it.
//!
//! [`problem_from_world`] writes the local problem of a 2D world's last step: with
//! `H_bᵀ = ±[[n_x, n_y, d_b×n], [t_x, t_y, d_b×t]]` (+ for the candidate body i, − for
//! the antagonist j) and the bodies' `M̂_b⁻¹`, `W_αβ = Σ_{b shared} (±H_bαᵀ) M̂_b⁻¹ (±H_bβ)`
//! and `q_α = (u_free,n − ū, u_free,t)`, ū being the law's target normal velocity.

use crate::error::InputError;
pub mod anderson;
pub mod newton;
pub mod nlgs;
mod solve;
mod world;

#[cfg(feature = "hdf5")]
pub mod fclib;

use crate::norms::{natural_map_sq, Criterion, Norms};
use crate::solver::Method;
use serde::Serialize;
use serde_json::{Map, Value};
use std::io::Read;
use std::path::Path;
pub use world::{problem_from_world, problem_from_world3, problem_of, problem_with, problem_with3, solve_world, FamilyShare};

/// Stopping test of `solve-fc`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum FcNorm {
    /// Natural-map residual ‖F(r)‖/‖q‖ < tol.
    Natural,
    /// One of LMGC90's criteria with tolerance tol.
    Lmgc(Criterion),
}

impl FcNorm {
    /// `"natural"`, or one of LMGC90's criteria (`"Quad"`, `"Maxm"`, `"QM/16"`).
    pub fn parse(name: &str) -> Option<FcNorm> {
        match name {
            "natural" => Some(FcNorm::Natural),
            other => Criterion::parse(other).map(FcNorm::Lmgc),
        }
    }
}

/// Options of `solve-fc`.
#[derive(Clone, Debug, PartialEq)]
pub struct FcOptions {
    pub tol: f64,
    /// At most this many iterations: NLGS or Anderson sweeps, Newton steps.
    pub max_sweeps: u32,
    /// The stopping test every k iterations (Newton: every step).
    pub check_every: u32,
    pub norm: FcNorm,
    pub method: Method,
    /// ω of the NLGS sweeps (NLGS, and Anderson's map): [`crate::solver::relax`].
    pub relaxation: f64,
}

impl FcOptions {
    /// NLGS to the natural-map residual `tol`, checked every sweep, at most 10⁵
    /// sweeps.
    pub fn natural(tol: f64) -> Self {
        FcOptions {
            tol,
            max_sweeps: 100_000,
            check_every: 1,
            norm: FcNorm::Natural,
            method: Method::Nlgs,
            relaxation: 1.0,
        }
    }
}

/// Result of `solve-fc`.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct FcSolution {
    pub r: Vec<f64>,
    pub u: Vec<f64>,
    /// Iterations: sweeps (NLGS, Anderson) or Newton steps.
    pub sweeps: u32,
    pub converged: bool,
    /// ‖F(r)‖/‖q‖ at the end.
    pub residual: f64,
    /// LMGC90's norms of the final r (a non-updating check pass, tolerance `tol`).
    pub norms: Norms,
    pub solve_seconds: f64,
}

/// A sparse matrix in coordinate form (0-based; duplicates are summed).
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct CooMatrix {
    /// Order of the (square) matrix, dim·nc.
    pub n: usize,
    pub rows: Vec<usize>,
    pub cols: Vec<usize>,
    pub vals: Vec<f64>,
}

impl CooMatrix {
    /// An n × n matrix from (row, column, value) triplets.
    pub fn from_triplets(n: usize, trip: &[(usize, usize, f64)]) -> Self {
        CooMatrix {
            n,
            rows: trip.iter().map(|x| x.0).collect(),
            cols: trip.iter().map(|x| x.1).collect(),
            vals: trip.iter().map(|x| x.2).collect(),
        }
    }
}

/// One frictional contact problem `u = W r + q`, as in the JSON exchange format.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct FcProblem {
    pub dim: usize,
    pub nc: usize,
    #[serde(rename = "W")]
    pub w: CooMatrix,
    pub q: Vec<f64>,
    pub mu: Vec<f64>,
    /// Free-form description, kept as read.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub meta: Option<Value>,
}

/// (key, message) of an invalid problem.
type Bad = (String, String);

fn bad(key: impl Into<String>, msg: impl Into<String>) -> Bad {
    (key.into(), msg.into())
}

const TOP_KEYS: [&str; 6] = ["dim", "nc", "W", "q", "mu", "meta"];
const W_KEYS: [&str; 4] = ["n", "rows", "cols", "vals"];

fn type_name(v: &Value) -> &'static str {
    match v {
        Value::Null => "null",
        Value::Bool(_) => "a boolean",
        Value::Number(_) => "a number",
        Value::String(_) => "a string",
        Value::Array(_) => "an array",
        Value::Object(_) => "an object",
    }
}

fn take(obj: &mut Map<String, Value>, key: &str, path: &str) -> Result<Value, Bad> {
    obj.remove(key).ok_or_else(|| bad(path, "missing key"))
}

fn uint(v: &Value, key: &str) -> Result<u64, Bad> {
    match v {
        Value::Number(x) => match x.as_u64() {
            Some(u) => Ok(u),
            None if x.as_i64().is_some() => Err(bad(key, format!("{x} must be ≥ 0"))),
            None => Err(bad(key, format!("{x} must be an integer"))),
        },
        _ => Err(bad(key, format!("expected a non-negative integer, found {}", type_name(v)))),
    }
}

fn array(v: Value, key: &str) -> Result<Vec<Value>, Bad> {
    match v {
        Value::Array(a) => Ok(a),
        other => Err(bad(key, format!("expected an array, found {}", type_name(&other)))),
    }
}

fn uint_array(v: Value, key: &str) -> Result<Vec<usize>, Bad> {
    let a = array(v, key)?;
    let mut out = Vec::with_capacity(a.len());
    for (k, x) in a.iter().enumerate() {
        let u = uint(x, &format!("{key}[{k}]"))?;
        out.push(usize::try_from(u).map_err(|_| bad(format!("{key}[{k}]"), "index too large"))?);
    }
    Ok(out)
}

fn num_array(v: Value, key: &str) -> Result<Vec<f64>, Bad> {
    let a = array(v, key)?;
    let mut out = Vec::with_capacity(a.len());
    for (k, x) in a.iter().enumerate() {
        match x.as_f64() {
            Some(f) if f.is_finite() => out.push(f),
            Some(f) => return Err(bad(format!("{key}[{k}]"), format!("{f} is not finite"))),
            None => return Err(bad(format!("{key}[{k}]"), format!("expected a number, found {}", type_name(x)))),
        }
    }
    Ok(out)
}

impl FcProblem {
    /// Reads a problem file (`.gz`: gzip-compressed) and validates it.
    pub fn read(path: &Path) -> Result<FcProblem, InputError> {
        let file = path.display().to_string();
        let err = |message: String| InputError {
            file: file.clone(),
            line: None,
            key: String::new(),
            message,
        };
        let mut text = String::new();
        let f = std::fs::File::open(path).map_err(|e| err(format!("cannot read the file: {e}")))?;
        let res = if file.ends_with(".gz") {
            flate2::read::GzDecoder::new(f).read_to_string(&mut text)
        } else {
            std::io::BufReader::new(f).read_to_string(&mut text)
        };
        res.map_err(|e| err(format!("cannot read the file: {e}")))?;
        Self::parse(&text, &file)
    }

    /// Parses and validates the JSON text of a problem; `file` names it in errors.
    pub fn parse(text: &str, file: &str) -> Result<FcProblem, InputError> {
        let to_err = |(key, message): Bad| InputError {
            file: file.to_string(),
            line: None,
            key,
            message,
        };
        let v: Value = serde_json::from_str(text).map_err(|e| to_err(bad("", format!("invalid JSON: {e}"))))?;
        let p = Self::from_value(v).map_err(to_err)?;
        p.validate().map_err(to_err)?;
        Ok(p)
    }

    /// Reads the keys and their types; [`FcProblem::validate`] checks the rest.
    fn from_value(v: Value) -> Result<FcProblem, Bad> {
        let Value::Object(mut top) = v else {
            return Err(bad(
                "",
                "the problem must be a JSON object with keys dim, nc, W, q, mu (and optional meta)",
            ));
        };
        if let Some(k) = top.keys().find(|k| !TOP_KEYS.contains(&k.as_str())) {
            return Err(bad(k.clone(), "unknown key; expected dim, nc, W, q, mu or meta"));
        }
        let dim = uint(&take(&mut top, "dim", "dim")?, "dim")?;
        match dim {
            2 | 3 => {}
            d => return Err(bad("dim", format!("{d} must be 2 or 3"))),
        }
        let nc = uint(&take(&mut top, "nc", "nc")?, "nc")?;
        if nc > (u32::MAX / 4) as u64 {
            return Err(bad("nc", format!("{nc} contacts is too many")));
        }
        let Value::Object(mut wm) = take(&mut top, "W", "W")? else {
            return Err(bad("W", "expected an object with keys n, rows, cols, vals"));
        };
        if let Some(k) = wm.keys().find(|k| !W_KEYS.contains(&k.as_str())) {
            return Err(bad(format!("W.{k}"), "unknown key; expected n, rows, cols or vals"));
        }
        let (dim, nc) = (dim as usize, nc as usize);
        let n = match wm.remove("n") {
            Some(x) => uint(&x, "W.n")? as usize,
            None => dim * nc,
        };
        let rows = uint_array(take(&mut wm, "rows", "W.rows")?, "W.rows")?;
        let cols = uint_array(take(&mut wm, "cols", "W.cols")?, "W.cols")?;
        let vals = num_array(take(&mut wm, "vals", "W.vals")?, "W.vals")?;
        let q = num_array(take(&mut top, "q", "q")?, "q")?;
        let mu = num_array(take(&mut top, "mu", "mu")?, "mu")?;
        let meta = top.remove("meta");
        Ok(FcProblem {
            dim,
            nc,
            w: CooMatrix { n, rows, cols, vals },
            q,
            mu,
            meta,
        })
    }

    /// Checks dimensions, lengths, indices, finiteness, μ ≥ 0 and W_nn > 0 per
    /// contact. Errors are (key, message).
    pub fn validate(&self) -> Result<(), (String, String)> {
        match self.dim {
            2 | 3 => {}
            d => return Err(bad("dim", format!("{d} must be 2 or 3"))),
        }
        let n = self
            .nc
            .checked_mul(self.dim)
            .filter(|&n| n <= u32::MAX as usize)
            .ok_or_else(|| bad("nc", "too many contacts"))?;
        if self.q.len() != n {
            return Err(bad("q", format!("has {} values; expected dim·nc = {n}", self.q.len())));
        }
        if self.mu.len() != self.nc {
            return Err(bad("mu", format!("has {} values; expected nc = {}", self.mu.len(), self.nc)));
        }
        let w = &self.w;
        if w.n != n {
            return Err(bad("W.n", format!("{} ≠ dim·nc = {n}", w.n)));
        }
        let nnz = w.rows.len();
        for (key, len) in [("W.cols", w.cols.len()), ("W.vals", w.vals.len())] {
            if len != nnz {
                return Err(bad(
                    key,
                    format!("has {len} entries but W.rows has {nnz}: the coordinate arrays must have equal lengths"),
                ));
            }
        }
        for (key, idx) in [("W.rows", &w.rows), ("W.cols", &w.cols)] {
            if let Some(k) = idx.iter().position(|&i| i >= n) {
                return Err(bad(
                    format!("{key}[{k}]"),
                    format!("index {} out of range: W is {n} × {n} (dim·nc)", idx[k]),
                ));
            }
        }
        if let Some(k) = w.vals.iter().position(|v| !v.is_finite()) {
            return Err(bad(format!("W.vals[{k}]"), format!("{} is not finite", w.vals[k])));
        }
        if let Some(k) = self.q.iter().position(|v| !v.is_finite()) {
            return Err(bad(format!("q[{k}]"), format!("{} is not finite", self.q[k])));
        }
        if let Some(k) = self.mu.iter().position(|m| !(m.is_finite() && *m >= 0.0)) {
            return Err(bad(
                format!("mu[{k}]"),
                format!("{}: a friction coefficient must be finite and ≥ 0", self.mu[k]),
            ));
        }
        let mut wnn = vec![0.0; self.nc];
        for k in 0..nnz {
            if w.rows[k] == w.cols[k] && w.rows[k] % self.dim == 0
            /* normal row */
            {
                wnn[w.rows[k] / self.dim] += w.vals[k];
            }
        }
        if let Some(a) = wnn.iter().position(|&x| !(x > 0.0)) {
            return Err(bad(
                "W",
                format!(
                    "contact {a}: the normal diagonal entry W[{0}][{0}] = {1} must be > 0",
                    self.dim * a,
                    wnn[a]
                ),
            ));
        }
        Ok(())
    }

    /// The problem in the JSON exchange format.
    pub fn to_json(&self) -> String {
        serde_json::to_string(self).expect("plain data")
    }

    /// `W r + q` from the coordinate triplets, as the file defines it.
    pub fn velocity(&self, r: &[f64]) -> Vec<f64> {
        let mut u = self.q.clone();
        for k in 0..self.w.rows.len() {
            u[self.w.rows[k]] += self.w.vals[k] * r[self.w.cols[k]];
        }
        u
    }

    /// Natural-map residual ‖F(r)‖/‖q‖ (‖F(r)‖ when q = 0), with u = W r + q from the
    /// triplets.
    pub fn natural_residual(&self, r: &[f64]) -> f64 {
        let u = self.velocity(r);
        let d = self.dim;
        let f2: f64 = (0..self.nc)
            .map(|a| natural_map_sq(&r[d * a..d * a + d], &u[d * a..d * a + d], self.mu[a]))
            .sum();
        f2.sqrt() / q_scale(&self.q)
    }

    /// Solves the problem by `opts.method` from r = 0.
    ///
    /// # Panics
    /// If the problem is invalid ([`FcProblem::validate`]); [`FcProblem::read`] and
    /// [`FcProblem::parse`] only return valid ones.
    pub fn solve(&self, opts: &FcOptions) -> FcSolution {
        self.solve_from(None, opts)
    }

    /// Solves the problem by `opts.method` from `r0` (warm start, dim·nc values)
    /// or r = 0.
    ///
    /// # Panics
    /// If the problem is invalid or `r0` has the wrong length.
    pub fn solve_from(&self, r0: Option<&[f64]>, opts: &FcOptions) -> FcSolution {
        if let Err((k, m)) = self.validate() {
            panic!("FcProblem::solve on an invalid problem: `{k}`: {m}");
        }
        assert!(r0.is_none_or(|r| r.len() == self.q.len()), "r0 must have dim·nc values");
        match self.dim {
            2 => solve::solve::<2>(self, r0, opts),
            _ => solve::solve::<3>(self, r0, opts),
        }
    }
}

pub(crate) fn q_scale(q: &[f64]) -> f64 {
    let n = q.iter().map(|x| x * x).sum::<f64>().sqrt();
    if n == 0.0 {
        1.0
    } else {
        n
    }
}

/// Reads and solves one problem file.
pub fn solve_file(path: &Path, opts: &FcOptions) -> Result<FcSolution, InputError> {
    let p = read_any(path)?;
    Ok(p.solve(opts))
}

/// Reads a problem file: FCLIB's HDF5 (`.hdf5`, `.h5`; cargo feature `hdf5`) or the
/// JSON exchange format (plain or `.gz`).
pub fn read_any(path: &Path) -> Result<FcProblem, InputError> {
    let name = path.to_string_lossy();
    if name.ends_with(".hdf5") || name.ends_with(".h5") {
        #[cfg(feature = "hdf5")]
        return fclib::read(path);
        #[cfg(not(feature = "hdf5"))]
        return Err(InputError {
            file: name.into_owned(),
            line: None,
            key: String::new(),
            message: "FCLIB HDF5 files need the `hdf5` feature: install Debian's libhdf5-dev and build with `cargo build --release --features hdf5`".into(),
        });
    }
    FcProblem::read(path)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn opts(norm: FcNorm, tol: f64) -> FcOptions {
        FcOptions {
            max_sweeps: 10_000,
            norm,
            ..FcOptions::natural(tol)
        }
    }

    fn problem(nc: usize, trip: &[(usize, usize, f64)], q: &[f64], mu: &[f64]) -> FcProblem {
        FcProblem {
            dim: 2,
            nc,
            w: CooMatrix::from_triplets(2 * nc, trip),
            q: q.to_vec(),
            mu: mu.to_vec(),
            meta: None,
        }
    }

    #[test]
    fn fc_assembly_sums_duplicates_and_symmetrises() {
        let p = problem(
            2,
            &[
                (0, 0, 1.0),
                (0, 0, 0.5),
                (0, 1, 0.2),
                (1, 0, 0.4),
                (1, 1, 2.0),
                (0, 2, -0.1),
                (0, 2, -0.2),
                (3, 1, 0.7),
                (2, 2, 1.0),
                (3, 3, 1.0),
            ],
            &[0.0; 4],
            &[0.1, 0.1],
        );
        let b = nlgs::Blocks::<2>::assemble(&p);
        assert_eq!(b.diag[0], [[1.5, 0.30000000000000004], [0.30000000000000004, 2.0]]);
        assert_eq!(b.diag[1], [[1.0, 0.0], [0.0, 1.0]]);
        assert_eq!(b.ptr, vec![0, 1, 2]);
        assert_eq!(b.col, vec![1, 0]);
        assert_eq!(b.blk[0], [[-0.30000000000000004, 0.0], [0.0, 0.0]]);
        assert_eq!(b.blk[1], [[0.0, 0.0], [0.0, 0.7]]);
    }

    #[test]
    fn fc_one_contact_cases() {
        // W = ½ I (a unit mass pair), μ = 0.5.
        let trip = [(0, 0, 0.5), (1, 1, 0.5)];
        for (q, r) in [
            ([-0.25, 0.0625], [0.5, -0.125]),
            ([-0.25, 1.0], [0.5, -0.25]),
            ([0.1, 1.0], [0.0, 0.0]),
        ] {
            let s = problem(1, &trip, &q, &[0.5]).solve(&opts(FcNorm::Natural, 1e-12));
            assert_eq!(s.r, r.to_vec());
            assert!(s.converged && s.sweeps == 1 && s.residual == 0.0, "{s:?}");
        }
    }

    #[test]
    fn fc_lmgc_norm_and_empty_problem() {
        let p = problem(
            2,
            &[(0, 0, 1.0), (1, 1, 1.0), (2, 2, 2.0), (3, 3, 2.0), (0, 2, -1.0), (2, 0, -1.0)],
            &[-1.0, 0.0, 0.0, 0.0],
            &[0.3, 0.3],
        );
        let s = p.solve(&opts(FcNorm::Lmgc(Criterion::QuadMax16), 1e-10));
        assert!(s.converged && s.residual < 1e-8, "{s:?}");
        let e = problem(0, &[], &[], &[]).solve(&opts(FcNorm::Natural, 1e-8));
        assert!(e.converged && e.sweeps == 0 && e.r.is_empty() && e.residual == 0.0);
    }

    #[test]
    fn fc_json_round_trip_and_gzip() {
        let p = problem(1, &[(0, 0, 0.5), (1, 1, 0.25), (0, 1, 0.1), (1, 0, 0.1)], &[-0.3, 0.1], &[0.4]);
        let text = p.to_json();
        assert_eq!(FcProblem::parse(&text, "x.json").unwrap(), p);
        let path = std::env::temp_dir().join(format!("nscdd_fc_unit_{}.json.gz", std::process::id()));
        let mut enc = flate2::write::GzEncoder::new(std::fs::File::create(&path).unwrap(), flate2::Compression::fast());
        std::io::Write::write_all(&mut enc, text.as_bytes()).unwrap();
        enc.finish().unwrap();
        let s = solve_file(&path, &opts(FcNorm::Natural, 1e-12)).unwrap();
        std::fs::remove_file(&path).ok();
        assert!(s.converged);
        assert_eq!(s.r, p.solve(&opts(FcNorm::Natural, 1e-12)).r);
    }

    #[test]
    fn fc_parse_errors_name_the_key() {
        let key = |t: &str| FcProblem::parse(t, "p.json").unwrap_err().key;
        let ok = r#"{"dim":2,"nc":1,"W":{"n":2,"rows":[0,1],"cols":[0,1],"vals":[1.0,1.0]},"q":[-1,0],"mu":[0.5],"meta":{"a":1}}"#;
        assert!(FcProblem::parse(ok, "p.json").is_ok());
        assert_eq!(key("[1]"), "");
        assert_eq!(key("{"), "");
        assert_eq!(key(&ok.replace("\"meta\"", "\"extra\"")), "extra");
        assert_eq!(key(&ok.replace("\"dim\":2", "\"dim\":4")), "dim");
        assert_eq!(key(&ok.replace("\"nc\":1", "\"nc\":-1")), "nc");
        assert_eq!(key(&ok.replace("\"nc\":1", "\"nc\":1.5")), "nc");
        assert_eq!(key(&ok.replace("\"n\":2", "\"n\":3")), "W.n");
        assert_eq!(key(&ok.replace("\"n\":2", "\"m\":2")), "W.m");
        assert_eq!(key(&ok.replace("[0,1],\"vals\"", "[0],\"vals\"")), "W.cols");
        assert_eq!(key(&ok.replace("\"rows\":[0,1]", "\"rows\":[0,2]")), "W.rows[1]");
        assert_eq!(key(&ok.replace("\"rows\":[0,1]", "\"rows\":[0,\"a\"]")), "W.rows[1]");
        assert_eq!(key(&ok.replace("[1.0,1.0]", "[-1.0,1.0]")), "W");
        assert_eq!(key(&ok.replace("[-1,0]", "[-1]")), "q");
        assert_eq!(key(&ok.replace("[-1,0]", "[-1,null]")), "q[1]");
        assert_eq!(key(&ok.replace("[0.5]", "[-0.5]")), "mu[0]");
        assert_eq!(key(&ok.replace(",\"mu\":[0.5]", "")), "mu");
        // 3D: three values per contact
        assert_eq!(key(&ok.replace("\"dim\":2", "\"dim\":3")), "q");
    }
}
