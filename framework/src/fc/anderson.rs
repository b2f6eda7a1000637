//! Anderson acceleration of NLGS on an assembled problem (`solve-fc --method
//! anderson`): the sweep of the Delassus blocks ([`super::nlgs::Blocks::sweep`]) as
//! the map G, mixed by [`crate::solver::anderson::Mixer`] (the method and its
//! safeguard are described there; the engine's stage drives the same mixing with
//! the world's own sweeps). One iteration = one sweep; the stopping test is checked
//! every `check_every` iterations on the mixed impulses. A solve that does not
//! converge returns the last iterate or the sweep output with the least ‖G(r) − r‖
//! seen, whichever has the lower natural-map residual.
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
use crate::solver::anderson::{InOrder, Mixer};

/// Anderson-accelerated NLGS from `r`; returns (sweeps, converged).
pub(crate) fn solve<const D: usize>(l: &Local<D>, r: &mut Vec<[f64; D]>, opts: &FcOptions) -> (u32, bool) {
    let nc = l.len();
    let mut mixer = Mixer::new(D * nc);
    let mut g: Vec<[f64; D]> = r.clone();
    let mut u = vec![[0.0; D]; nc];
    // the sweep output with the least ‖f‖ (where an unconverged solve ends)
    let (mut best, mut best_f) = (r.clone(), f64::INFINITY);
    let (iterations, converged) = crate::solver::check_loop(opts.max_sweeps, opts.check_every, |check| {
        g.copy_from_slice(r);
        l.b.sweep(&l.q, &l.mu, &mut g, opts.relaxation);
        let mixing = mixer.step(r.as_flattened(), g.as_flattened(), &mut InOrder);
        if mixer.f_norm() < best_f {
            best_f = mixer.f_norm();
            best.copy_from_slice(&g);
        }
        match mixing {
            None => r.copy_from_slice(&g),
            Some(gamma) => {
                let gf = g.as_flattened();
                for (a, ra) in r.iter_mut().enumerate() {
                    let z: [f64; D] = std::array::from_fn(|x| mixer.mixed(&gamma, gf, D * a + x));
                    let p = project_cone(&z, l.mu[a]);
                    ra.copy_from_slice(&p[..D]);
                }
            }
        }
        check && l.stop(r, &mut u, opts)
    });
    if !converged && best_f.is_finite() && l.residual(&best, &mut u) < l.residual(r, &mut u) {
        r.copy_from_slice(&best);
    }
    (iterations, converged)
}
