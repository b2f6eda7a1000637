//! NSCDD with polyhedra: a running-bond wall (dry, and bonded by mortar joints) on
//! 2 × 1 × 2 subdomains reaches the one-domain solution to the solver's accuracy,
//! bitwise the same with 1 or 2 threads; the interface multipliers glue the
//! multi-point face contacts and the joints cut by the interfaces.
use nscdd::dd::{DdSettings, Nscdd3};
use nscdd::scene::Scene3;
use nscdd::world::World3;

fn wall(law: &str) -> World3 {
    let text = format!(
        r#"dimension = 3
gravity = [0.0, 0.0, -9.81]
[time]
step = 1e-3
theta = 0.5
steps = 1
[solver]
tolerance = 1e-6
max_sweeps = 50000
[detection]
alert = 0.002
[[materials]]
name = "brick"
density = 1800.0
[[materials]]
name = "base"
density = 2400.0
[[laws]]
materials = ["brick", "brick"]
{law}
[[laws]]
materials = ["brick", "base"]
friction = 0.6
[[laws]]
materials = ["base", "base"]
law = "none"
[[generate]]
kind = "brick_wall"
material = "brick"
base_material = "base"
brick = [0.2, 0.1, 0.05]
courses = 6
bricks = 5
"#
    );
    match Scene3::load_str(&text, "wall.toml", &nscdd_polyhedra::registry()) {
        Ok(s) => s.world,
        Err(e) => panic!("{e}"),
    }
}

fn run_dd(w: &mut World3, threads: usize, steps: usize) {
    let mut dd = Nscdd3::new(DdSettings {
        nx: 2,
        ny: 1,
        nz: 2,
        threads,
        ..Default::default()
    });
    for _ in 0..steps {
        let r = w.step_with(&mut dd).expect("the wall stands");
        assert!(r.solve.converged, "NSCDD did not converge at step {}", w.step);
    }
}

fn check(law: &str, bonded: bool) {
    let steps = 20;
    let mut one = wall(law);
    for _ in 0..steps {
        assert!(one.step().unwrap().solve.converged);
    }
    let mut a = wall(law);
    run_dd(&mut a, 1, steps);
    let mut b = wall(law);
    run_dd(&mut b, 2, steps);
    assert_eq!(a.bodies.pos, b.bodies.pos, "bitwise the same whatever the thread count");
    assert_eq!(a.contacts.r, b.contacts.r);
    let dx = (0..one.bodies.len())
        .map(|k| {
            (0..3)
                .map(|c| (a.bodies.pos[k][c] - one.bodies.pos[k][c]).abs())
                .fold(0.0, f64::max)
        })
        .fold(0.0, f64::max);
    println!("{law}: NSCDD vs one domain, largest position difference {dx:.2e} m");
    assert!(dx < 1e-7, "NSCDD differs from one domain by {dx} m");
    let bonds = |w: &World3| w.contacts.joint.iter().filter(|j| j.bonded()).count();
    if bonded {
        // mortar far stronger than the wall's weight: every bed and head joint holds
        let joints = (0..one.contacts.len()).filter(|&k| !one.contacts.bodies[k].contains(&0)).count();
        assert!(joints > 0 && bonds(&one) == joints, "{} of {joints} joints bonded", bonds(&one));
        assert_eq!(bonds(&a), bonds(&one));
    }
    // the wall carries its weight onto the base
    let weight: f64 = (1..a.bodies.len()).map(|k| a.bodies.mass[k]).sum::<f64>() * 9.81;
    let base: f64 = -a.reaction[0][2] / 1e-3;
    assert!((base - weight).abs() < 1e-4 * weight, "base carries {base} N of {weight} N");
}

#[test]
fn dry_wall_on_2x1x2_subdomains() {
    check("friction = 0.6", false);
}

#[test]
fn bonded_wall_on_2x1x2_subdomains() {
    check(
        "law = \"mohr_coulomb\"\nfriction = 0.6\ncohesion = 2e5\ntensile_strength = 1e5",
        true,
    );
}
