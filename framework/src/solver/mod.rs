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
    /// Relaxation ω in (0, 1].
    pub relaxation: f64,
    pub ordering: Ordering,
    pub seed: u64,
    /// `nlgs` (default), `anderson` or `newton`.
    pub method: Method,
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
            seed: 0,
            method: Method::Nlgs,
        }
    }
}

impl SolverSettings {
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
