//! Anderson acceleration of NLGS (`[solver] method = "anderson"`): the mixing
//! ([`Mixer`]) and the one-domain stage over the world's own sweeps ([`solve`]).
//!
//! NLGS is a fixed-point map r ↦ G(r) (one sweep); it converges linearly, slowly on
//! dense frictional samples. Anderson mixing (type II, Walker & Ni 2011) keeps the
//! last m = [`MEMORY`] differences of the sweep's outputs ΔG and of the fixed-point
//! residuals ΔF (f = G(r) − r) and takes
//!
//! ```text
//! γ = argmin ‖f_k − ΔF γ‖,      r_{k+1} = P_K(G(r_k) − ΔG γ)
//! ```
//!
//! P_K projecting each contact's impulse on its Coulomb cone |r_t| ≤ μ r_n. The
//! least-squares problem is solved by its m × m normal equations (the Gram matrix
//! ΔFᵀΔF kept up to date one column a sweep, Tikhonov-regularized by 1e-12 of its
//! trace). Safeguard: when ‖f‖ grows (by more than the factor [`GROWTH`] = 1) from
//! one sweep to the next the history is dropped and the plain sweep G(r_k) is kept,
//! so the method is never worse than NLGS by more than the restarts. One iteration
//! = one sweep. The same mixing drives the assembled problems of `solve-fc`
//! (`fc::anderson`).

use super::nlgs::{check_pass, residual, sweep};
use super::{SolveReport, SolverSettings};
use crate::dim::{Dim, Vector};
use crate::model::Contacts;
use crate::norms::{project_cone, Norms, Sums};

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

/// The mixing state: the last m differences ΔF, ΔG, the Gram matrix ΔFᵀΔF, and
/// the previous sweep's f and G.
pub struct Mixer {
    df: Vec<Vec<f64>>,
    dg: Vec<Vec<f64>>,
    gram: [[f64; MEMORY]; MEMORY],
    count: usize,
    next: usize,
    f: Vec<f64>,
    f_prev: Vec<f64>,
    g_prev: Vec<f64>,
    f_norm_prev: f64,
    first: bool,
}

impl Mixer {
    /// For n unknowns.
    pub fn new(n: usize) -> Self {
        Mixer {
            df: vec![vec![0.0; n]; MEMORY],
            dg: vec![vec![0.0; n]; MEMORY],
            gram: [[0.0; MEMORY]; MEMORY],
            count: 0,
            next: 0,
            f: vec![0.0; n],
            f_prev: vec![0.0; n],
            g_prev: vec![0.0; n],
            f_norm_prev: f64::INFINITY,
            first: true,
        }
    }

    /// Forgets the history, for a new problem of n unknowns (the buffers kept).
    pub fn reset(&mut self, n: usize) {
        for v in self.df.iter_mut().chain(self.dg.iter_mut()) {
            v.resize(n, 0.0);
        }
        for v in [&mut self.f, &mut self.f_prev, &mut self.g_prev] {
            v.resize(n, 0.0);
        }
        (self.count, self.next, self.f_norm_prev, self.first) = (0, 0, f64::INFINITY, true);
    }

    /// Records a sweep from `x` to `g` = G(x); returns γ (its first `count` values
    /// used), or None when the plain sweep is to be kept.
    pub fn step(&mut self, x: &[f64], g: &[f64]) -> Option<[f64; MEMORY]> {
        for k in 0..x.len() {
            self.f[k] = g[k] - x[k];
        }
        let f_norm = dot(&self.f, &self.f).sqrt();
        if !self.first && f_norm > GROWTH * self.f_norm_prev {
            self.count = 0;
        } else if !self.first {
            self.push(g);
        }
        self.first = false;
        self.f_prev.copy_from_slice(&self.f);
        self.g_prev.copy_from_slice(g);
        self.f_norm_prev = f_norm;
        if self.count == 0 {
            return None;
        }
        self.coefficients()
    }

    /// ‖f‖ = ‖G(x) − x‖ of the last recorded sweep.
    pub fn f_norm(&self) -> f64 {
        self.f_norm_prev
    }

    /// z = G − ΔG γ (the same sums as [`Self::mixed`], vectorized).
    pub fn mix_into(&self, gamma: &[f64; MEMORY], g: &[f64], z: &mut [f64]) {
        z.copy_from_slice(g);
        for (j, gj) in gamma.iter().enumerate().take(self.count) {
            for (zk, dk) in z.iter_mut().zip(&self.dg[j]) {
                *zk -= gj * dk;
            }
        }
    }

    /// Component k of G − ΔG γ.
    #[inline]
    pub fn mixed(&self, gamma: &[f64; MEMORY], g: &[f64], k: usize) -> f64 {
        let mut z = g[k];
        for (j, gj) in gamma.iter().enumerate().take(self.count) {
            z -= gj * self.dg[j][k];
        }
        z
    }

    /// Stores Δf = f − f_prev, Δg = g − g_prev in the oldest slot.
    fn push(&mut self, g: &[f64]) {
        let s = self.next;
        for k in 0..g.len() {
            self.df[s][k] = self.f[k] - self.f_prev[k];
            self.dg[s][k] = g[k] - self.g_prev[k];
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
    fn coefficients(&self) -> Option<[f64; MEMORY]> {
        let m = self.count;
        let trace: f64 = (0..m).map(|i| self.gram[i][i]).sum();
        let mut a = self.gram;
        let mut g = [0.0; MEMORY];
        for i in 0..m {
            a[i][i] += 1e-12 * trace;
            g[i] = dot(&self.df[i], &self.f);
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

/// The one-domain stage with `[solver] method = "anderson"`: the world's own NLGS
/// sweeps (storage order, unrelaxed) as the map G, the mixed impulses applied to
/// the bodies contact by contact (V += M̂⁻¹ H Δr), LMGC90's check pass after every
/// `check_every`-th iteration. No Delassus operator is assembled. A solve that
/// does not converge ends on the last iterate or on the sweep output with the least
/// ‖f‖ seen, whichever has the lower natural-map residual (a mixed iterate of a
/// stagnating history can be far worse than NLGS's).
pub fn solve<D: Dim>(c: &mut Contacts<D>, vel: &mut [D::Twist], inv: &[D::InvMass], s: &SolverSettings) -> SolveReport {
    if c.is_empty() {
        return SolveReport {
            converged: true,
            ..Default::default()
        };
    }
    let d = <D::Local as Vector>::LEN;
    let n = d * c.len();
    let mut mixer = Mixer::new(n);
    let (mut x, mut g, mut z) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
    // the sweep output with the least ‖f‖, and that ‖f‖
    let (mut best, mut best_f) = (vec![0.0; n], f64::INFINITY);
    let flat = |c: &Contacts<D>, out: &mut [f64]| {
        for (a, r) in c.r.iter().enumerate() {
            out[d * a..d * a + d].copy_from_slice(r.as_ref());
        }
    };
    let mut report = s.run_sweeps(|sums| {
        flat(c, &mut x);
        sweep(c, vel, inv, &[], 1.0, None);
        flat(c, &mut g);
        let mixing = mixer.step(&x, &g);
        if mixer.f_norm() < best_f {
            best_f = mixer.f_norm();
            best.copy_from_slice(&g);
        }
        if let Some(gamma) = mixing {
            mixer.mix_into(&gamma, &g, &mut z);
            for a in 0..c.len() {
                let p = project_cone(&z[d * a..d * a + d], c.target[a].mu);
                c.set_r(a, &p, vel, inv);
            }
        }
        if let Some(sums) = sums {
            check_pass(c, vel, inv, &[], 1.0, sums);
        }
    });
    report.residual = residual(c, vel);
    if !report.converged && best_f.is_finite() {
        // the last iterate or the best sweep output, whichever has the lower residual
        flat(c, &mut x);
        set_impulses(c, vel, inv, &best);
        let at_best = residual(c, vel);
        if at_best < report.residual {
            report.residual = at_best;
            let mut sums = Sums::default();
            check_pass(c, vel, inv, &[], 1.0, &mut sums);
            report.norms = Norms::from_sums(&sums, s.tolerance);
        } else {
            set_impulses(c, vel, inv, &x);
        }
    }
    report
}

/// Sets every contact's impulse to `flat` (d values a contact), the velocities
/// following (V += M̂⁻¹ H Δr).
fn set_impulses<D: Dim>(c: &mut Contacts<D>, vel: &mut [D::Twist], inv: &[D::InvMass], flat: &[f64]) {
    let d = <D::Local as Vector>::LEN;
    for a in 0..c.len() {
        c.set_r(a, &flat[d * a..d * a + d], vel, inv);
    }
}
