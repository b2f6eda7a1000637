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
    reg.add_plugin(&nscdd_fem_deformable::FemPlugin);
    reg.add_plugin(&nscdd_spheres::SpheresPlugin);
    let t0 = Instant::now();
    let mut s = nscdd_fem_deformable::scene::load3_str(text, "bench3d", &reg).unwrap();
    nscdd_fem_deformable::bench::bench(&mut s, steps, t0.elapsed().as_secs_f64());
}
