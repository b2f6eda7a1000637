//! `nscdd bench nlgs3`: 3D NLGS throughput, contact updates per second on one
//! thread, on a dense packing of spheres (a cubic lattice of touching spheres resting
//! on a floor in a box of planes under gravity, μ = 0.3, settled for 5 steps so that
//! the contacts carry load), timing plain sweeps of the solver's hot loop.

use nscdd::registry::Registry;
use nscdd::solver::nlgs;
use std::time::Instant;

fn lattice3(n: usize) -> String {
    let k = (n as f64).cbrt().ceil().max(2.0) as usize;
    let r = 0.01;
    let l = 2.0 * r * k as f64;
    let plane = |name: &str, pos: [f64; 3], rot: [f64; 3]| {
        format!(
            "[[bodies]]\nname = \"{name}\"\nshape = \"plane\"\nmaterial = \"g\"\nposition = {pos:?}\nrotation = {rot:?}\nfixed = true\n"
        )
    };
    let h = std::f64::consts::FRAC_PI_2;
    format!(
        r#"dimension = 3
[time]
step = 1e-3
steps = 1
[solver]
tolerance = 1e-4
max_sweeps = 200
[[materials]]
name = "g"
density = 1000.0
[[laws]]
materials = ["g", "g"]
friction = 0.3
{}{}{}{}{}
[[generate]]
kind = "sphere_lattice"
material = "g"
nx = {k}
ny = {k}
nz = {k}
radius = {r}
origin = [{r}, {r}, {r}]
"#,
        plane("floor", [0.0, 0.0, 0.0], [0.0, 0.0, 0.0]),
        plane("x0", [0.0, 0.0, 0.0], [0.0, h, 0.0]),
        plane("x1", [l, 0.0, 0.0], [0.0, -h, 0.0]),
        plane("y0", [0.0, 0.0, 0.0], [-h, 0.0, 0.0]),
        plane("y1", [0.0, l, 0.0], [h, 0.0, 0.0]),
    )
}

/// 3D NLGS contact updates per second on one thread.
pub fn nlgs3(reg: &Registry, n: usize, sweeps: usize) {
    let mut s = nscdd::scene::Scene3::load_str(&lattice3(n), "bench-lattice3", reg).expect("bench scene");
    let w = &mut s.world;
    for _ in 0..5 {
        w.step().expect("bench step");
    }
    let c = &mut w.contacts;
    let mut vel = w.bodies.vel.clone();
    let t = Instant::now();
    for _ in 0..sweeps {
        nlgs::sweep(c, &mut vel, &w.bodies.inv_mass, &[], 1.0, None);
    }
    let dt = t.elapsed().as_secs_f64();
    let updates = (c.len() * sweeps) as f64;
    println!(
        "{{\"bench\":\"nlgs3\",\"bodies\":{},\"contacts\":{},\"sweeps\":{},\"seconds\":{:.4},\"updates_per_second\":{:.4e},\"ns_per_update\":{:.2}}}",
        w.bodies.len(),
        c.len(),
        sweeps,
        dt,
        updates / dt,
        1e9 * dt / updates
    );
}
