//! The contact solver: settings, the per-step report, the one convergence-check loop
//! ([`SolverSettings::run_sweeps`]) and NLGS ([`nlgs`]), for every dimension.

pub mod anderson;
pub mod nlgs;

use crate::norms::{Criterion, Norms, Sums};
use serde::{Deserialize, Serialize};

/// Order in which an NLGS sweep visits the contacts.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Ordering {
    /// As stored (detection order).
    Stored,
    /// Reversed storage order.
    Reversed,
    /// A random permutation drawn once per step from `seed` and the step number
    /// (NSCDD: one per subdomain, also from its id; `nlgs::make_order_of`).
    Shuffled,
    /// LMGC90's "quick scramble": a new random permutation before every block of
    /// `check_every` sweeps (one-domain NLGS).
    Scrambled,
    /// By the contact points' coordinate along [`SolverSettings::sort_direction`]
    /// (by default against gravity: from the bottom up), ties in storage order:
    /// a sweep then carries a change across the sample along that direction in one
    /// pass (on LMGC90's biaxial test, 22 % fewer sweeps than LMGC90's quick
    /// scramble; docs/PERFORMANCE.md).
    Sorted,
}

/// The contact solver of a step (`[solver] method`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Method {
    /// Non-linear Gauss–Seidel over the bodies ([`nlgs`]): LMGC90's solver.
    #[default]
    Nlgs,
    /// NLGS sweeps accelerated by Anderson mixing over the assembled Delassus
    /// operator W ([`crate::fc::anderson`]).
    Anderson,
    /// Semismooth Newton on the Alart–Curnier function over the assembled W,
    /// regularized by a proximal term, with a line search and NLGS sweeps where a
    /// step fails ([`crate::fc::newton`]): fast local convergence, for tight
    /// tolerances.
    Newton,
}

impl Method {
    /// The method named `s` (as in `[solver] method`).
    pub fn parse(s: &str) -> Option<Self> {
        [Method::Nlgs, Method::Anderson, Method::Newton].into_iter().find(|m| m.name() == s)
    }

    pub fn name(self) -> &'static str {
        match self {
            Method::Nlgs => "nlgs",
            Method::Anderson => "anderson",
            Method::Newton => "newton",
        }
    }
}

/// Contact solver settings (scene section `[solver]`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct SolverSettings {
    /// Tolerance `tol` of the LMGC90 norms.
    pub tolerance: f64,
    /// `"Quad"`, `"Maxm"` or `"QM/16"`.
    pub norm: Criterion,
    pub max_sweeps: u32,
    /// A check pass every `check_every` sweeps.
    pub check_every: u32,
    /// Relaxation ω in (0, 2) ([`relax`]): under-relaxed below 1, over-relaxed
    /// (projected) above.
    pub relaxation: f64,
    pub ordering: Ordering,
    /// The direction along which `sorted` visits the contacts (D numbers; none:
    /// along the last axis, y in 2D and z in 3D). For `sorted`, the scene loader
    /// makes it a unit vector and, when the key is absent and the scene has gravity,
    /// sets it against gravity; it refuses it with another ordering.
    pub sort_direction: Option<Vec<f64>>,
    pub seed: u64,
    /// `nlgs` (default), `anderson` or `newton`.
    pub method: Method,
}

/// A contact's relaxed update, r_loc ← r + ω (r_loc − r), from its impulse `r` and
/// its local solution `r_loc` (overwritten). With ω ∈ (0, 1] the result stays in
/// the contact's convex admissible set (a mean of two of its points); with ω ∈
/// (1, 2) it is projected on it (`project`: the Coulomb cone, or a joint's set),
/// the projected over-relaxation of NLGS. Both keep NLGS's fixed points: at
/// r = r_loc the update gives r. `project` is called only when ω > 1.
#[inline(always)]
pub fn relax(r: &[f64], r_loc: &mut [f64], omega: f64, project: impl FnOnce(&[f64]) -> [f64; 3]) {
    for (x, &y) in r_loc.iter_mut().zip(r) {
        *x = omega * *x + (1.0 - omega) * y;
    }
    if omega > 1.0 {
        let p = project(r_loc);
        let n = r_loc.len();
        r_loc.copy_from_slice(&p[..n]);
    }
}

impl Default for SolverSettings {
    fn default() -> Self {
        SolverSettings {
            tolerance: 1.666e-4,
            norm: Criterion::QuadMax16,
            max_sweeps: 1000,
            check_every: 10,
            relaxation: 1.0,
            ordering: Ordering::Stored,
            sort_direction: None,
            seed: 0,
            method: Method::Nlgs,
        }
    }
}

impl SolverSettings {
    /// The direction of `sorted` in a space of `space` dimensions as three
    /// coordinates: [`SolverSettings::sort_direction`], or the last axis.
    pub fn sort_axis(&self, space: usize) -> [f64; 3] {
        let mut d = [0.0; 3];
        match self.sort_direction.as_deref() {
            Some(v) => v.iter().take(3).enumerate().for_each(|(i, &x)| d[i] = x),
            None => d[space.clamp(1, 3) - 1] = 1.0,
        }
        d
    }
    /// The NLGS loop: `sweep` does one sweep over the contacts, accumulating the
    /// check sums when it gets them (every `check_every` sweeps and at the last
    /// one); the loop stops when the criterion holds or after `max_sweeps`. The
    /// residual is left to the caller.
    pub fn run_sweeps(&self, mut sweep: impl FnMut(Option<&mut Sums>)) -> SolveReport {
        let mut report = SolveReport::default();
        let mut overflow = false;
        (report.sweeps, report.converged) = check_loop(self.max_sweeps, self.check_every, |check| {
            if !check {
                sweep(None);
                return false;
            }
            let mut sums = Sums::default();
            sweep(Some(&mut sums));
            report.norms = Norms::from_sums(&sums, self.tolerance);
            // an overflow stops the sweeps, unconverged
            overflow = !sums.is_finite();
            overflow || report.norms.converged(self.norm)
        });
        report.converged &= !overflow;
        report
    }
}

/// The one convergence-check loop, shared by the one-domain NLGS
/// ([`SolverSettings::run_sweeps`]), the NSCDD stages on threads and on MPI ranks,
/// and the deformable bodies' stages: at most `max` iterations (a sweep, or a
/// stage of sweeps and gluing), a check every `every` iterations and at the last
/// one. `iterate(check)` runs one iteration and, when `check` is set, says whether
/// the criterion holds (its answer is ignored otherwise). Returns the iterations
/// run and whether the criterion held.
///
/// ```
/// let mut seen = vec![];
/// let (n, ok) = nscdd::solver::check_loop(10, 3, |check| { seen.push(check); check && seen.len() == 6 });
/// assert_eq!((n, ok), (6, true));
/// assert_eq!(seen, [false, false, true, false, false, true]);
/// ```
pub fn check_loop(max: u32, every: u32, mut iterate: impl FnMut(bool) -> bool) -> (u32, bool) {
    let k = every.max(1);
    let mut n = 0;
    while n < max {
        n += 1;
        let check = n % k == 0 || n == max;
        if iterate(check) && check {
            return (n, true);
        }
    }
    (n, false)
}

/// What one contact solve did.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct SolveReport {
    pub sweeps: u32,
    pub converged: bool,
    /// Norms of the last check pass.
    pub norms: Norms,
    /// Natural-map residual ‖F(r)‖/‖q‖ after the solve.
    pub residual: f64,
}

#[cfg(test)]
mod tests {
    use super::relax;
    use crate::norms::project_cone;

    /// Under-relaxation is the plain mean; over-relaxation lands in the cone, on
    /// the projection of the extrapolated point; r_loc = r stays r (to rounding) for
    /// any ω.
    #[test]
    fn relax_means_below_one_and_projects_above() {
        let mu = 0.5;
        let (r, loc) = ([1.0, 0.4, 0.0], [2.0, -0.9, 0.3]);
        let mut x = loc;
        relax(&r, &mut x, 0.5, |_| unreachable!("no projection below 1"));
        assert_eq!(x, [1.5, -0.25, 0.15]);
        let mut x = loc;
        relax(&r, &mut x, 1.5, |z| project_cone(z, mu));
        // extrapolated (2.5, −1.55, 0.45): outside the cone, projected on its surface
        let t = (x[1] * x[1] + x[2] * x[2]).sqrt();
        assert!((t - mu * x[0]).abs() < 1e-12 && x[0] > 0.0, "{x:?}");
        let e: [f64; 3] = std::array::from_fn(|k| 1.5 * loc[k] + (1.0 - 1.5) * r[k]);
        assert_eq!(x, project_cone(&e, mu));
        for omega in [0.3, 1.0, 1.2, 1.9] {
            let mut x = r;
            relax(&r, &mut x, omega, |z| project_cone(z, mu));
            assert!((0..3).all(|k| (x[k] - r[k]).abs() <= 1e-15), "ω = {omega}: {x:?}");
        }
        // 2D: the third component is not touched
        let mut x = [0.5, 0.1];
        relax(&[0.2, 0.0], &mut x, 1.8, |z| project_cone(z, mu));
        assert!(x[1].abs() <= mu * x[0] + 1e-15, "{x:?}");
    }
}
