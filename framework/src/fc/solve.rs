//! One driver for every method on an assembled local problem `u = W r + q`: NLGS
//! ([`super::nlgs`]), Anderson-accelerated NLGS ([`super::anderson`]) and the
//! semismooth Newton method ([`super::newton`]). Each starts from the given
//! impulses (warm start) or from r = 0, stops on the same test ([`Local::stop`]:
//! the natural-map residual or one of LMGC90's norms over a non-updating check
//! pass) and reports the same figures: iterations, the final natural-map
//! residual and LMGC90's norms of the final impulses.

use super::nlgs::Blocks;
use super::{anderson, newton, q_scale, FcNorm, FcOptions, FcProblem, FcSolution};
use crate::norms::{natural_map_sq, Norms, Sums};
use crate::solver::Method;
use std::time::Instant;

/// The problem in block form, as every method reads it.
pub(crate) struct Local<const D: usize> {
    pub b: Blocks<D>,
    pub q: Vec<[f64; D]>,
    pub mu: Vec<f64>,
    /// ‖q‖ (1 when q = 0): the residual's scale.
    pub qs: f64,
}

impl<const D: usize> Local<D> {
    pub fn new(p: &FcProblem) -> Self {
        Local {
            b: Blocks::assemble(p),
            q: blocks(&p.q),
            mu: p.mu.clone(),
            qs: q_scale(&p.q),
        }
    }

    pub fn len(&self) -> usize {
        self.q.len()
    }

    /// The natural-map residual ‖F(r)‖/‖q‖; leaves u = W r + q in `u`.
    pub fn residual(&self, r: &[[f64; D]], u: &mut [[f64; D]]) -> f64 {
        self.b.velocity(&self.q, r, u);
        let f2: f64 = (0..r.len()).map(|a| natural_map_sq(&r[a], &u[a], self.mu[a])).sum();
        f2.sqrt() / self.qs
    }

    /// LMGC90's norms of `r` over a non-updating check pass.
    pub fn norms(&self, r: &[[f64; D]], tol: f64) -> Norms {
        let mut sums = Sums::default();
        self.b.check(&self.q, &self.mu, r, &mut sums);
        Norms::from_sums(&sums, tol)
    }

    /// The stopping test of `opts` at `r` (`u`: scratch).
    pub fn stop(&self, r: &[[f64; D]], u: &mut [[f64; D]], opts: &FcOptions) -> bool {
        match opts.norm {
            FcNorm::Natural => self.residual(r, u) < opts.tol,
            FcNorm::Lmgc(c) => self.norms(r, opts.tol).converged(c),
        }
    }
}

/// Flat values as D-blocks.
pub(crate) fn blocks<const D: usize>(x: &[f64]) -> Vec<[f64; D]> {
    x.chunks_exact(D)
        .map(|c| {
            let mut v = [0.0; D];
            v.copy_from_slice(c);
            v
        })
        .collect()
}

/// Solves a validated problem of dimension D by `opts.method`, from `r0` (warm
/// start) or r = 0.
pub fn solve<const D: usize>(p: &FcProblem, r0: Option<&[f64]>, opts: &FcOptions) -> FcSolution {
    let t0 = Instant::now();
    let nc = p.nc;
    let l = Local::<D>::new(p);
    let mut r = r0.map_or_else(|| vec![[0.0; D]; nc], blocks);
    let mut u = vec![[0.0; D]; nc];
    let (sweeps, mut converged) = if nc == 0 {
        (0, true)
    } else {
        match opts.method {
            Method::Nlgs => crate::solver::check_loop(opts.max_sweeps, opts.check_every, |check| {
                l.b.sweep(&l.q, &l.mu, &mut r, opts.relaxation);
                check && l.stop(&r, &mut u, opts)
            }),
            Method::Anderson => anderson::solve(&l, &mut r, opts),
            Method::Newton => newton::solve(&l, &mut r, opts),
        }
    };
    let residual = l.residual(&r, &mut u);
    if opts.max_sweeps == 0 && opts.norm == FcNorm::Natural {
        converged |= residual < opts.tol;
    }
    let norms = l.norms(&r, opts.tol);
    FcSolution {
        r: r.concat(),
        u: u.concat(),
        sweeps,
        converged,
        residual,
        norms,
        solve_seconds: t0.elapsed().as_secs_f64(),
    }
}
