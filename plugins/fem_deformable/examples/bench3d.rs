//! Benchmark of the deformable stages (docs/PERFORMANCE.md, "Deformable bodies"):
//! a 3D foundation block of 25 × 25 × 11 = 6 875 nodes (linear tetrahedra, fixed
//! base) under a 12 × 12 layer of 144 rigid spheres, one domain. Prints the load (assembly by scikit-fem,
//! symbolic and numeric factorization) and the mean time per step of each stage.
//!
//!     PYO3_PYTHON=venv/bin/python NSCDD_PYTHON_ENV=venv \
//!       cargo run --release -p nscdd-fem-deformable --example bench3d [steps]
use std::time::Instant;

fn main() {
    let steps: usize = std::env::args().nth(1).and_then(|s| s.parse().ok()).unwrap_or(20);
    let text = r#"
dimension = 3
[time]
step = 1e-3
theta = 0.5
steps = 1
[solver]
tolerance = 1e-4
max_sweeps = 20000
[detection]
alert = 0.005
[[materials]]
name = "soil"
density = 2000.0
[[materials]]
name = "stone"
density = 2500.0
[[laws]]
materials = ["soil", "stone"]
friction = 0.5
[[laws]]
materials = ["stone", "stone"]
friction = 0.3
[[generate]]
kind = "sphere_lattice"
material = "stone"
radius = 0.02
spacing = 0.075
origin = [0.08, 0.08, 0.5205]
nx = 12
ny = 12
nz = 1
[[deformable]]
material = "soil"
young = 1e7
poisson = 0.3
fix = ["bottom"]
mesh = { box = { origin = [0.0, 0.0, 0.0], size = [1.0, 1.0, 0.5], cells = [24, 24, 10] } }
"#;
    let mut reg = nscdd::registry::Registry::new();
    reg.add_plugin(&nscdd_spheres::SpheresPlugin);
    let t0 = Instant::now();
    let mut s = nscdd_fem_deformable::scene::load3_str(text, "bench3d", std::path::Path::new("."), &reg).unwrap();
    let load = t0.elapsed().as_secs_f64();
    let b = &s.fe.bodies[0];
    println!(
        "nodes {}, dofs {}, nnz(M̂) {}, load (Python start, mesh, scikit-fem assembly, symbolic + numeric Cholesky) {load:.3} s",
        b.mesh.n_nodes(),
        b.n_dofs(),
        b.nnz()
    );
    let t = Instant::now();
    s.fe.bodies[0].factorize(2e-3, 0.5).unwrap();
    println!("numeric refactorization (h changed) {:.4} s", t.elapsed().as_secs_f64());
    s.fe.bodies[0].factorize(1e-3, 0.5).unwrap();
    let mut acc = nscdd_fem_deformable::stage2::FeTimes::default();
    let (mut contacts, mut sweeps, mut total) = (0, 0, 0.0);
    for k in 0..steps {
        let t = Instant::now();
        let rep = s.step().unwrap();
        let dt = t.elapsed().as_secs_f64();
        let f = s.fe.times;
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
        contacts += s.fe.contacts.len();
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
