//! The timing loop of the deformable benchmarks (`examples/bench2d.rs`,
//! `examples/bench3d.rs`; figures in docs/PERFORMANCE.md): a numeric
//! refactorization, then `steps` steps, the first one (all columns of M̂⁻¹
//! solved) apart, and the mean time per step of each stage over the others.

use crate::body::FeBody;
use crate::scene::{FeScene, FeScene2, FeScene3};
use crate::stage2::FeTimes;
use nscdd::engine::{Diverged, StepReport};
use std::time::Instant;

/// Prints the size of the first deformable body and the load time, then times the
/// refactorization and `steps` steps of `s` (h = 1e-3 s, θ = ½).
pub fn bench<S: FeRunnable>(s: &mut S, steps: usize, load_seconds: f64) {
    let b = &s.fe_bodies()[0];
    println!(
        "nodes {}, dofs {}, nnz(M̂) {}, load (Python start, mesh, scikit-fem assembly, symbolic + numeric Cholesky) {load_seconds:.3} s",
        b.mesh.n_nodes(),
        b.n_dofs(),
        b.nnz()
    );
    let t = Instant::now();
    s.fe_bodies_mut()[0].factorize(2e-3, 0.5).expect("refactorization");
    println!("numeric refactorization (h changed) {:.4} s", t.elapsed().as_secs_f64());
    s.fe_bodies_mut()[0].factorize(1e-3, 0.5).expect("refactorization");
    let mut acc = FeTimes::default();
    let (mut contacts, mut sweeps, mut total) = (0, 0, 0.0);
    for k in 0..steps {
        let t = Instant::now();
        let rep = s.step().expect("the benchmark scene does not diverge");
        let dt = t.elapsed().as_secs_f64();
        let f = s.fe_times();
        if k == 0 {
            println!("first step {dt:.4} s: columns {:.4} s ({} solves)", f.columns, f.solves);
            continue;
        }
        total += dt;
        acc.free += f.free;
        acc.detect += f.detect;
        acc.columns += f.columns;
        acc.nlgs += f.nlgs;
        acc.update += f.update;
        acc.solves += f.solves;
        contacts += s.fe_contacts();
        sweeps += rep.solve.sweeps as usize;
    }
    let n = (steps - 1).max(1) as f64;
    println!(
        "per step (mean of {} steps after the first): total {:.4} s | free velocity {:.4} | detection {:.4} | columns + G {:.4} ({:.1} solves) | NLGS {:.4} ({:.0} sweeps) | V⁺ {:.4} | {:.0} deformable contacts",
        steps - 1,
        total / n,
        acc.free / n,
        acc.detect / n,
        acc.columns / n,
        acc.solves as f64 / n,
        acc.nlgs / n,
        sweeps as f64 / n,
        acc.update / n,
        contacts as f64 / n
    );
}

/// What the benchmark loop needs of a scene with deformable bodies (2D or 3D).
pub trait FeRunnable {
    fn step(&mut self) -> Result<StepReport, Diverged>;
    fn fe_bodies(&self) -> &[FeBody];
    fn fe_bodies_mut(&mut self) -> &mut [FeBody];
    fn fe_contacts(&self) -> usize;
    /// Time spent in the deformable stages during the last step.
    fn fe_times(&self) -> FeTimes;
}

macro_rules! runnable {
    ($scene:ty) => {
        impl FeRunnable for $scene {
            fn step(&mut self) -> Result<StepReport, Diverged> {
                FeScene::step(self)
            }
            fn fe_bodies(&self) -> &[FeBody] {
                &self.fe.bodies
            }
            fn fe_bodies_mut(&mut self) -> &mut [FeBody] {
                &mut self.fe.bodies
            }
            fn fe_contacts(&self) -> usize {
                self.fe.contacts.len()
            }
            fn fe_times(&self) -> FeTimes {
                self.fe.times
            }
        }
    };
}

runnable!(FeScene2);
runnable!(FeScene3);
