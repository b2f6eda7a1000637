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
//! one sweep to the next, the plain sweep G(r_k) is kept and the history's count
//! restarts; the slots keep their pairs until new ones overwrite them (slot by slot
//! from where the history stood), so the next mixings use the oldest pairs stored
//! — on the FCLIB files and the biaxial sample at tight tolerances this beats
//! dropping the pairs (docs/PERFORMANCE.md). One iteration
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

/// Sums over the segments of a vector split over processes: each process holds
/// some segments (an NSCDD subdomain's unknowns), and a dot product is the sum, in
/// global segment order, of each segment's own dot product, so that any split of
/// the segments over processes gives bitwise the same numbers.
pub trait Reduce {
    /// `local[s * k + i]`: value i of this process's segment s (k values a
    /// segment); writes into `out[..k]` the sums over every segment of every
    /// process in global segment order ([`sum_in_order`]).
    fn reduce(&mut self, local: &[f64], k: usize, out: &mut [f64]);
}

/// One process holding every segment.
pub struct InOrder;

impl Reduce for InOrder {
    fn reduce(&mut self, local: &[f64], k: usize, out: &mut [f64]) {
        if k > 0 {
            sum_in_order(local.chunks_exact(k), k, out);
        }
    }
}

/// out[i] = p₀[i] + p₁[i] + … over the parts in order (0 without parts).
pub fn sum_in_order<'a>(parts: impl Iterator<Item = &'a [f64]>, k: usize, out: &mut [f64]) {
    out[..k].fill(0.0);
    for (n, p) in parts.enumerate() {
        for i in 0..k {
            out[i] = if n == 0 { p[i] } else { out[i] + p[i] };
        }
    }
}

/// The mixing state: the last m differences ΔF, ΔG, the Gram matrix ΔFᵀΔF, and
/// the previous sweep's f and G; the unknowns split in segments (dot products
/// summed over them by a [`Reduce`]).
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
    /// Segment offsets (one more than the segments; the last: the unknowns).
    seg: Vec<usize>,
    partial: Vec<f64>,
}

impl Mixer {
    /// For n unknowns in one segment.
    pub fn new(n: usize) -> Self {
        let mut m = Mixer {
            df: vec![Vec::new(); MEMORY],
            dg: vec![Vec::new(); MEMORY],
            gram: [[0.0; MEMORY]; MEMORY],
            count: 0,
            next: 0,
            f: Vec::new(),
            f_prev: Vec::new(),
            g_prev: Vec::new(),
            f_norm_prev: f64::INFINITY,
            first: true,
            seg: Vec::new(),
            partial: Vec::new(),
        };
        m.reset(&[0, n]);
        m
    }

    /// Forgets the history, for a new problem whose local unknowns are split at
    /// `offsets` (segment s: `offsets[s]..offsets[s + 1]`); the buffers are kept.
    pub fn reset(&mut self, offsets: &[usize]) {
        let n = offsets.last().copied().unwrap_or(0);
        for v in self.df.iter_mut().chain(self.dg.iter_mut()) {
            v.resize(n, 0.0);
        }
        for v in [&mut self.f, &mut self.f_prev, &mut self.g_prev] {
            v.resize(n, 0.0);
        }
        self.seg.clear();
        self.seg.extend_from_slice(offsets);
        (self.count, self.next, self.f_norm_prev, self.first) = (0, 0, f64::INFINITY, true);
    }

    /// Records a sweep from `x` to `g` = G(x); returns γ (its first `count` values
    /// used), or None when the plain sweep is to be kept. Two reductions: ‖f‖², then
    /// the new Gram row with the right-hand side ΔFᵀf.
    pub fn step(&mut self, x: &[f64], g: &[f64], red: &mut dyn Reduce) -> Option<[f64; MEMORY]> {
        for k in 0..x.len() {
            self.f[k] = g[k] - x[k];
        }
        self.partial.clear();
        for w in self.seg.windows(2) {
            let f = &self.f[w[0]..w[1]];
            self.partial.push(dot(f, f));
        }
        let mut ff = [0.0];
        red.reduce(&self.partial, 1, &mut ff);
        let f_norm = ff[0].sqrt();
        if !self.first && f_norm > GROWTH * self.f_norm_prev {
            // restart the count; the slots keep their pairs until overwritten, so the
            // first mixings after a growth use the oldest pairs stored (measured
            // against refilling from slot 0 and other safeguards: docs/PERFORMANCE.md)
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
        // the newest slot's Gram row and ΔFᵀf, one reduction
        let (m, s) = (self.count, (self.next + MEMORY - 1) % MEMORY);
        self.partial.clear();
        for w in self.seg.windows(2) {
            let r = w[0]..w[1];
            for j in 0..m {
                self.partial.push(dot(&self.df[s][r.clone()], &self.df[j][r.clone()]));
            }
            for i in 0..m {
                self.partial.push(dot(&self.df[i][r.clone()], &self.f[r.clone()]));
            }
        }
        let mut tot = [0.0; 2 * MEMORY];
        red.reduce(&self.partial, 2 * m, &mut tot);
        for j in 0..m {
            self.gram[s][j] = tot[j];
            self.gram[j][s] = tot[j];
        }
        let mut rhs = [0.0; MEMORY];
        rhs[..m].copy_from_slice(&tot[m..2 * m]);
        self.coefficients(rhs)
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
    }

    /// γ = argmin ‖f − ΔF γ‖ from the Gram matrix and `g` = ΔFᵀf (normal
    /// equations, Cholesky); None when singular.
    fn coefficients(&self, mut g: [f64; MEMORY]) -> Option<[f64; MEMORY]> {
        let m = self.count;
        let trace: f64 = (0..m).map(|i| self.gram[i][i]).sum();
        let mut a = self.gram;
        for i in 0..m {
            a[i][i] += 1e-12 * trace;
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
/// sweeps (in the step's visiting `order`, empty: storage order, with the relaxation
/// ω of the settings) as the map G, the mixed impulses applied to
/// the bodies contact by contact (V += M̂⁻¹ H Δr), LMGC90's check pass after every
/// `check_every`-th iteration. No Delassus operator is assembled. A solve that
/// does not converge ends on the last iterate or on the sweep output with the least
/// ‖f‖ seen, whichever has the lower natural-map residual (a mixed iterate of a
/// stagnating history can be far worse than NLGS's).
pub fn solve<D: Dim>(c: &mut Contacts<D>, vel: &mut [D::Twist], inv: &[D::InvMass], order: &[u32], s: &SolverSettings) -> SolveReport {
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
    // x: the impulses before each sweep (kept up to date below, not re-read)
    flat(c, &mut x);
    let mut report = s.run_sweeps(|sums| {
        sweep(c, vel, inv, order, s.relaxation, None);
        flat(c, &mut g);
        let mixing = mixer.step(&x, &g, &mut InOrder);
        if mixer.f_norm() < best_f {
            best_f = mixer.f_norm();
            best.copy_from_slice(&g);
        }
        match mixing {
            None => std::mem::swap(&mut x, &mut g),
            Some(gamma) => {
                mixer.mix_into(&gamma, &g, &mut z);
                for a in 0..c.len() {
                    let p = project_cone(&z[d * a..d * a + d], c.target[a].mu);
                    c.set_r(a, &p, vel, inv);
                    x[d * a..d * a + d].copy_from_slice(c.r[a].as_ref());
                }
            }
        }
        if let Some(sums) = sums {
            check_pass(c, vel, inv, order, sums);
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
            check_pass(c, vel, inv, order, &mut sums);
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
