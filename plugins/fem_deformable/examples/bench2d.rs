//! Benchmark of the deformable stages (docs/PERFORMANCE.md, "Deformable bodies"):
//! a foundation block of 141 × 71 = 10 011 nodes (plane strain, fixed base) under a
//! row of 120 rigid disks, one domain. Prints the load (assembly by scikit-fem,
//! symbolic and numeric factorization) and the mean time per step of each stage.
//!
//!     PYO3_PYTHON=venv/bin/python NSCDD_PYTHON_ENV=venv \
//!       cargo run --release -p nscdd-fem-deformable --example bench2d [steps]
use std::time::Instant;

fn main() {
    let steps: usize = std::env::args().nth(1).and_then(|s| s.parse().ok()).unwrap_or(20);
    let text = r#"
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
kind = "square_lattice"
material = "stone"
radius = 0.008
spacing = 0.0166
origin = [0.01, 0.5081]
nx = 120
ny = 1
[[deformable]]
material = "soil"
young = 1e7
poisson = 0.3
fix = ["bottom"]
mesh = { rectangle = { origin = [0.0, 0.0], size = [2.0, 0.5], cells = [140, 70] } }
"#;
    let mut reg = nscdd::registry::Registry::new();
    reg.add_plugin(&nscdd_fem_deformable::FemPlugin);
    reg.add_plugin(&nscdd_rigid_disks::RigidDisks);
    let t0 = Instant::now();
    let mut s = nscdd_fem_deformable::scene::load_str(text, "bench2d", &reg).unwrap();
    nscdd_fem_deformable::bench::bench(&mut s, steps, t0.elapsed().as_secs_f64());
}
