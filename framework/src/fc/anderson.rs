//! Anderson acceleration of NLGS (`[solver] method = "anderson"`).
//!
//! NLGS is a fixed-point map r ↦ G(r) (one sweep, [`super::nlgs::Blocks::sweep`]);
//! it converges linearly, slowly on dense frictional samples. Anderson mixing
//! (type II, Walker & Ni 2011) keeps the last m = [`MEMORY`] differences of the
//! sweep's outputs ΔG and of the fixed-point residuals ΔF (f = G(r) − r) and takes
//!
//! ```text
//! γ = argmin ‖f_k − ΔF γ‖,      r_{k+1} = P_K(G(r_k) − ΔG γ)
//! ```
//!
//! P_K projecting each contact's impulse on its Coulomb cone |r_t| ≤ μ r_n. The
//! least-squares problem is solved by its m × m normal equations (the Gram matrix
//! ΔFᵀΔF kept up to date one column a sweep, Tikhonov-regularized by 1e-12 of its
//! trace). Safeguard: when ‖f‖ grows (by more than the factor [`GROWTH`] = 1) from
//! one sweep to the next the history is dropped and the plain sweep G(r_k) is kept, so the method
//! is never worse than NLGS by more than the restarts. One iteration = one sweep;
//! the stopping test is checked every `check_every` iterations on r_{k+1}.
//!
//! ```
//! use nscdd::fc::{CooMatrix, FcNorm, FcOptions, FcProblem};
//! use nscdd::solver::Method;
//! // two contacts on one unit mass pushed down (W = [[1, 1], [1, 1]] in the normal
//! // direction, frictionless): any split of r_n = 1 solves it
//! let trip = [(0, 0, 2.0), (1, 1, 2.0), (2, 2, 2.0), (3, 3, 2.0), (0, 2, 1.0), (2, 0, 1.0)];
//! let p = FcProblem { dim: 2, nc: 2, w: CooMatrix::from_triplets(4, &trip), q: vec![-1.0, 0.0, -1.0, 0.0], mu: vec![0.5; 2], meta: None };
//! let opts = FcOptions { method: Method::Anderson, ..FcOptions::natural(1e-12) };
//! let s = p.solve(&opts);
//! assert!(s.converged && s.residual < 1e-12);
//! assert!((s.r[0] - 1.0 / 3.0).abs() < 1e-12 && (s.r[2] - 1.0 / 3.0).abs() < 1e-12);
//! ```

use super::solve::Local;
use super::FcOptions;
use crate::norms::project_cone;

/// Differences kept (m).
pub const MEMORY: usize = 5;
/// Growth of ‖f‖ from one sweep to the next that drops the history.
pub const GROWTH: f64 = 1.0;

/// aᵀb with four partial sums (a single chain of additions is latency-bound).
fn dot(a: &[f64], b: &[f64]) -> f64 {
    let (ca, cb) = (a.chunks_exact(4), b.chunks_exact(4));
    let tail: f64 = ca.remainder().iter().zip(cb.remainder()).map(|(x, y)| x * y).sum();
    let mut acc = [0.0; 4];
    for (x, y) in ca.zip(cb) {
        for k in 0..4 {
            acc[k] += x[k] * y[k];
        }
    }
    (acc[0] + acc[1]) + (acc[2] + acc[3]) + tail
}

/// The last m differences ΔF, ΔG and the Gram matrix ΔFᵀΔF.
struct History {
    df: Vec<Vec<f64>>,
    dg: Vec<Vec<f64>>,
    gram: [[f64; MEMORY]; MEMORY],
    count: usize,
    next: usize,
}

impl History {
    fn new(n: usize) -> Self {
        History {
            df: vec![vec![0.0; n]; MEMORY],
            dg: vec![vec![0.0; n]; MEMORY],
            gram: [[0.0; MEMORY]; MEMORY],
            count: 0,
            next: 0,
        }
    }

    /// Stores Δf = f − f_prev, Δg = g − g_prev in the oldest slot.
    fn push(&mut self, f: &[f64], f_prev: &[f64], g: &[f64], g_prev: &[f64]) {
        let s = self.next;
        for k in 0..f.len() {
            self.df[s][k] = f[k] - f_prev[k];
            self.dg[s][k] = g[k] - g_prev[k];
        }
        self.count = (self.count + 1).min(MEMORY);
        self.next = (s + 1) % MEMORY;
        for j in 0..self.count {
            let v = dot(&self.df[s], &self.df[j]);
            self.gram[s][j] = v;
            self.gram[j][s] = v;
        }
    }

    /// γ = argmin ‖f − ΔF γ‖ (normal equations, Cholesky); None when singular.
    fn coefficients(&self, f: &[f64]) -> Option<[f64; MEMORY]> {
        let m = self.count;
        let trace: f64 = (0..m).map(|i| self.gram[i][i]).sum();
        let mut a = self.gram;
        let mut g = [0.0; MEMORY];
        for i in 0..m {
            a[i][i] += 1e-12 * trace;
            g[i] = dot(&self.df[i], f);
        }
        // Cholesky a = L Lᵀ in place (lower triangle)
        for j in 0..m {
            let d = a[j][j] - (0..j).map(|k| a[j][k] * a[j][k]).sum::<f64>();
            if !(d > 0.0) {
                return None;
            }
            a[j][j] = d.sqrt();
            for i in j + 1..m {
                a[i][j] = (a[i][j] - (0..j).map(|k| a[i][k] * a[j][k]).sum::<f64>()) / a[j][j];
            }
        }
        for i in 0..m {
            g[i] = (g[i] - (0..i).map(|k| a[i][k] * g[k]).sum::<f64>()) / a[i][i];
        }
        for i in (0..m).rev() {
            g[i] = (g[i] - (i + 1..m).map(|k| a[k][i] * g[k]).sum::<f64>()) / a[i][i];
        }
        g.iter().all(|x| x.is_finite()).then_some(g)
    }
}

/// Anderson-accelerated NLGS from `r`; returns (sweeps, converged).
pub(crate) fn solve<const D: usize>(l: &Local<D>, r: &mut Vec<[f64; D]>, opts: &FcOptions) -> (u32, bool) {
    let (nc, n) = (l.len(), D * l.len());
    let mut h = History::new(n);
    let mut g: Vec<[f64; D]> = r.clone();
    let (mut f, mut f_prev, mut g_prev) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
    let mut u = vec![[0.0; D]; nc];
    let mut f_norm_prev = f64::INFINITY;
    let mut first = true;
    crate::solver::check_loop(opts.max_sweeps, opts.check_every, |check| {
        g.copy_from_slice(r);
        l.b.sweep(&l.q, &l.mu, &mut g);
        let (x, gf) = (r.as_flattened(), g.as_flattened());
        for k in 0..n {
            f[k] = gf[k] - x[k];
        }
        let f_norm = dot(&f, &f).sqrt();
        if !first && f_norm > GROWTH * f_norm_prev {
            h.count = 0;
        } else if !first {
            h.push(&f, &f_prev, gf, &g_prev);
        }
        first = false;
        f_prev.copy_from_slice(&f);
        g_prev.copy_from_slice(gf);
        f_norm_prev = f_norm;
        match h.coefficients(&f).filter(|_| h.count > 0) {
            None => r.copy_from_slice(&g),
            Some(gamma) => {
                for (a, ra) in r.iter_mut().enumerate() {
                    let mut z = g[a];
                    for (j, gj) in gamma.iter().enumerate().take(h.count) {
                        for x in 0..D {
                            z[x] -= gj * h.dg[j][D * a + x];
                        }
                    }
                    let p = project_cone(&z, l.mu[a]);
                    ra.copy_from_slice(&p[..D]);
                }
            }
        }
        check && l.stop(r, &mut u, opts)
    })
}
