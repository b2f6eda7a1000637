//! Semismooth Newton on the Alart–Curnier function (`[solver] method = "newton"`).
//!
//! For contact α with u = W r + q, ρ_α = D / tr W_αα and s = r_n − ρ u_n:
//!
//! ```text
//! Φ_n = r_n − max(0, s)
//! Φ_t = r_t − P_{B(μ max(0, s))}(r_t − ρ u_t)      (projection on the disk of radius μ max(0, s))
//! ```
//!
//! Φ(r) = 0 is the Signorini–Coulomb problem (Alart & Curnier 1991). An element of
//! its generalized Jacobian is `J = A + B W` with A, B block diagonal (D × D per
//! contact: [`jacobian`]). W of a dense sample is singular (more contact unknowns
//! than body velocities), so J is singular on sticking contacts; the step solves the
//! proximally regularized system
//!
//! ```text
//! (A + B (W + η I)) Δ = −Φ(r),     η_α = ε / ρ_α
//! ```
//!
//! which is Newton's step on the proximal problem (W + ηI, q − η r) whose Φ equals
//! the original one at r. ε starts at 10⁻², is divided by 10 after a full step and
//! multiplied by 10 after a damped or failed one (as Levenberg–Marquardt's
//! damping), within [`EPS_MIN`, `EPS_MAX`]: near the solution full steps are taken
//! and ε vanishes, so the convergence becomes superlinear. The sparse LU of faer factors it (symbolic
//! analysis once, the block pattern of W). Globalization: an Armijo line search on
//! ½‖Φ‖² (halving t down to 2⁻²⁰); a step that fails it or a factorization that
//! fails, or Newton creeping (the merit not halved in [`STRIKES`] steps), sends the
//! iterate back to its best one for a block of NLGS sweeps (`solve`). One
//! iteration = one Newton step (with its fallback block, if any); the stopping
//! test is checked every iteration.
//!
//! ```
//! use nscdd::fc::{CooMatrix, FcOptions, FcProblem};
//! use nscdd::solver::Method;
//! // a block on a floor, two contacts, pushed sideways: it slides (μ = 0.3)
//! let trip = [(0, 0, 2.0), (1, 1, 2.0), (2, 2, 2.0), (3, 3, 2.0), (0, 2, 1.0), (2, 0, 1.0), (1, 3, 1.0), (3, 1, 1.0)];
//! let p = FcProblem { dim: 2, nc: 2, w: CooMatrix::from_triplets(4, &trip), q: vec![-1.0, 1.0, -1.0, 1.0], mu: vec![0.3; 2], meta: None };
//! let s = p.solve(&FcOptions { method: Method::Newton, ..FcOptions::natural(1e-12) });
//! assert!(s.converged && s.residual < 1e-12, "{s:?}");
//! assert!((s.r[0] + s.r[2] - 2.0 / 3.0).abs() < 1e-12 && (s.r[1] + s.r[3] + 0.2).abs() < 1e-12);
//! ```

use super::solve::Local;
use super::FcOptions;
use faer::prelude::*;
use faer::sparse::linalg::solvers::{Lu, SymbolicLu};
use faer::sparse::{Pair, SparseColMat, SymbolicSparseColMat};

/// NLGS sweeps of the first fallback block (see the module doc), and the most of one.
pub const FALLBACK: usize = 5;
pub const FALLBACK_MAX: usize = 320;
/// Newton steps in a row that do not halve the merit before a fallback.
pub const STRIKES: u32 = 3;
/// The regularization ε of the first step, and after a fallback.
pub const EPS_START: f64 = 1e-2;
/// Bounds of the regularization ε.
pub const EPS_MIN: f64 = 1e-14;
pub const EPS_MAX: f64 = 1.0;

/// Φ of one contact and its Jacobian blocks: dΦ = A dr + B du.
#[allow(clippy::needless_range_loop)]
pub fn jacobian<const D: usize>(r: &[f64; D], u: &[f64; D], mu: f64, rho: f64) -> ([f64; D], [[f64; D]; D], [[f64; D]; D]) {
    let (mut phi, mut a, mut b) = ([0.0; D], [[0.0; D]; D], [[0.0; D]; D]);
    let s = r[0] - rho * u[0];
    let active = s > 0.0;
    // normal: Φ_n = r_n − max(0, s)
    if active {
        phi[0] = rho * u[0];
        b[0][0] = rho;
    } else {
        phi[0] = r[0];
        a[0][0] = 1.0;
    }
    // tangent: v = r_t − ρ u_t, radius R = μ max(0, s)
    let radius = if active { mu * s } else { 0.0 };
    let mut v = [0.0; D];
    for k in 1..D {
        v[k] = r[k] - rho * u[k];
    }
    let vn = v.iter().map(|x| x * x).sum::<f64>().sqrt();
    if vn <= radius {
        // sticking: Φ_t = ρ u_t
        for k in 1..D {
            phi[k] = rho * u[k];
            b[k][k] = rho;
        }
        return (phi, a, b);
    }
    // sliding (or separated, radius 0): Φ_t = r_t − R v̂,
    // dΦ_t = dr_t − Q dv − v̂ dR,  Q = (R/|v|)(I − v̂ v̂ᵀ),  dv = dr_t − ρ du_t,  dR = μ (dr_n − ρ du_n) if active
    let c = radius / vn;
    for k in 1..D {
        let vk = v[k] / vn;
        phi[k] = r[k] - radius * vk;
        for l in 1..D {
            let q = c * (if k == l { 1.0 } else { 0.0 } - vk * v[l] / vn);
            a[k][l] = if k == l { 1.0 } else { 0.0 } - q;
            b[k][l] = rho * q;
        }
        if active {
            a[k][0] = -mu * vk;
            b[k][0] = rho * mu * vk;
        }
    }
    (phi, a, b)
}

/// The sparse pattern of J (the block pattern of W, row α: its diagonal block then
/// its off-diagonal ones) and its symbolic LU.
struct Pattern {
    sym: SymbolicSparseColMat<usize>,
    order: faer::sparse::Argsort<usize>,
    lu: SymbolicLu<usize>,
}

impl Pattern {
    fn new<const D: usize>(l: &Local<D>) -> Option<Self> {
        let b = &l.b;
        let mut pairs = Vec::with_capacity(D * D * (l.len() + b.col.len()));
        for a in 0..l.len() {
            let cols = std::iter::once(a).chain(b.col[b.ptr[a]..b.ptr[a + 1]].iter().map(|&c| c as usize));
            for c in cols {
                for x in 0..D {
                    for y in 0..D {
                        pairs.push(Pair::new(D * a + x, D * c + y));
                    }
                }
            }
        }
        let n = D * l.len();
        let (sym, order) = SymbolicSparseColMat::try_new_from_indices(n, n, &pairs).ok()?;
        let lu = SymbolicLu::try_new(sym.as_ref()).ok()?;
        Some(Pattern { sym, order, lu })
    }
}

/// Fills J's values (in the pattern's order) and −Φ; returns ½‖Φ‖².
fn assemble<const D: usize>(l: &Local<D>, r: &[[f64; D]], u: &[[f64; D]], rho: &[f64], eps: f64, vals: &mut Vec<f64>, rhs: &mut [f64]) {
    let b = &l.b;
    vals.clear();
    for a in 0..l.len() {
        let (phi, ja, jb) = jacobian(&r[a], &u[a], l.mu[a], rho[a]);
        for x in 0..D {
            rhs[D * a + x] = -phi[x];
        }
        // the diagonal block: A + B (W_αα + η I), η = ε/ρ
        let wd = &b.diag[a];
        for x in 0..D {
            for y in 0..D {
                let bw: f64 = (0..D).map(|k| jb[x][k] * wd[k][y]).sum();
                vals.push(ja[x][y] + bw + eps / rho[a] * jb[x][y]);
            }
        }
        for k in b.ptr[a]..b.ptr[a + 1] {
            let m = &b.blk[k];
            for x in 0..D {
                for y in 0..D {
                    vals.push((0..D).map(|z| jb[x][z] * m[z][y]).sum());
                }
            }
        }
    }
}

/// ½‖Φ(r)‖² with u = W r + q given.
fn merit<const D: usize>(l: &Local<D>, r: &[[f64; D]], u: &[[f64; D]], rho: &[f64]) -> f64 {
    (0..l.len())
        .map(|a| jacobian(&r[a], &u[a], l.mu[a], rho[a]).0.iter().map(|x| x * x).sum::<f64>())
        .sum::<f64>()
        * 0.5
}

/// The regularized Newton direction, or None when the factorization fails.
fn direction<const D: usize>(pat: &Pattern, vals: &[f64], rhs: &[f64]) -> Option<Vec<f64>> {
    let j = SparseColMat::new_from_argsort(pat.sym.clone(), &pat.order, vals).ok()?;
    let lu = Lu::try_new_with_symbolic(pat.lu.clone(), j.as_ref()).ok()?;
    let mut x = Mat::from_fn(rhs.len(), 1, |i, _| rhs[i]);
    lu.solve_in_place(x.as_mut());
    let d: Vec<f64> = (0..rhs.len()).map(|i| x[(i, 0)]).collect();
    d.iter().all(|v| v.is_finite()).then_some(d)
}

/// The scratch of the line search.
struct Work<const D: usize> {
    u: Vec<[f64; D]>,
    ut: Vec<[f64; D]>,
    wd: Vec<[f64; D]>,
    /// Zeros: W Δ is the velocity of Δ with q = 0.
    zero: Vec<[f64; D]>,
    trial: Vec<[f64; D]>,
    vals: Vec<f64>,
    rhs: Vec<f64>,
}

/// One regularized Newton step from `r` with an Armijo line search on ½‖Φ‖²:
/// the step length taken, or None (r unchanged) when the factorization or the
/// line search fails.
fn step<const D: usize>(l: &Local<D>, pat: &Pattern, r: &mut [[f64; D]], rho: &[f64], eps: f64, w: &mut Work<D>) -> Option<(f64, f64)> {
    let nc = l.len();
    l.b.velocity(&l.q, r, &mut w.u);
    let theta = merit(l, r, &w.u, rho);
    assemble(l, r, &w.u, rho, eps, &mut w.vals, &mut w.rhs);
    let d = super::solve::blocks::<D>(&direction::<D>(pat, &w.vals, &w.rhs)?);
    // W Δ: u along the step is u + t W Δ
    l.b.velocity(&w.zero, &d, &mut w.wd);
    let mut t = 1.0;
    for _ in 0..=20 {
        for a in 0..nc {
            for x in 0..D {
                w.trial[a][x] = r[a][x] + t * d[a][x];
                w.ut[a][x] = w.u[a][x] + t * w.wd[a][x];
            }
        }
        let m = merit(l, &w.trial, &w.ut, rho);
        if m <= (1.0 - 1e-4 * t) * theta {
            r.copy_from_slice(&w.trial);
            return Some((t, m));
        }
        t *= 0.5;
    }
    None
}

/// Semismooth Newton from `r`; returns (iterations, converged).
///
/// Safeguard: the iterate with the least merit ½‖Φ‖² is kept; after a failed
/// step, or [`STRIKES`] steps in a row that do not halve that merit (a creeping,
/// heavily damped Newton, as on samples where many contacts change status), the
/// iterate returns to it and takes a block of NLGS sweeps ([`FALLBACK`], doubled
/// at each fallback up to [`FALLBACK_MAX`]), then Newton resumes.
pub(crate) fn solve<const D: usize>(l: &Local<D>, r: &mut Vec<[f64; D]>, opts: &FcOptions) -> (u32, bool) {
    let nc = l.len();
    let rho: Vec<f64> = l.b.diag.iter().map(|w| D as f64 / (0..D).map(|k| w[k][k]).sum::<f64>()).collect();
    let pat = Pattern::new(l);
    let mut w = Work {
        u: vec![[0.0; D]; nc],
        ut: vec![[0.0; D]; nc],
        wd: vec![[0.0; D]; nc],
        zero: vec![[0.0; D]; nc],
        trial: r.clone(),
        vals: Vec::new(),
        rhs: vec![0.0; D * nc],
    };
    let mut eps: f64 = EPS_START;
    l.b.velocity(&l.q, r, &mut w.u);
    let mut best = (merit(l, r, &w.u, &rho), r.clone());
    let (mut strikes, mut block) = (0, FALLBACK);
    crate::solver::check_loop(opts.max_sweeps, 1, |_| {
        let accepted = pat.as_ref().and_then(|p| step(l, p, r, &rho, eps, &mut w));
        // Levenberg–Marquardt-like: less regularization after a full step, more
        // after a damped or failed one
        eps = match accepted {
            Some((t, _)) if t == 1.0 => (0.1 * eps).max(EPS_MIN),
            _ => (10.0 * eps).min(EPS_MAX),
        };
        let theta = accepted.map_or(f64::INFINITY, |(_, m)| m);
        strikes = if theta < 0.5 * best.0 { 0 } else { strikes + 1 };
        if theta < best.0 {
            best.0 = theta;
            best.1.copy_from_slice(r);
        }
        if accepted.is_none() || strikes >= STRIKES {
            r.copy_from_slice(&best.1);
            for _ in 0..block {
                l.b.sweep(&l.q, &l.mu, r, 1.0);
            }
            block = (2 * block).min(FALLBACK_MAX);
            l.b.velocity(&l.q, r, &mut w.u);
            best.0 = merit(l, r, &w.u, &rho);
            best.1.copy_from_slice(r);
            (strikes, eps) = (0, EPS_START);
        }
        l.stop(r, &mut w.u, opts)
    })
}
