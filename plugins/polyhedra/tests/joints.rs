//! Bonded mortar joints (law `mohr_coulomb`): a joint holds a load 2 % below its
//! strength and fails 2 % above it, in tension (a hanging block: σ_t A against m g)
//! and in shear (a flat block on a tilted base: c A + μ N against the downhill pull);
//! bonds are made at the first step only and survive a restart. The first two
//! also with over-relaxed sweeps (`relaxation = 1.2`: the relaxed impulse is
//! projected on the joint's admissible set).
use nscdd::output::final_json;
use nscdd::scene::restart::restart_str;
use nscdd::scene::Scene3;
use nscdd::world::World3;
use nscdd_polyhedra::generate::box_points;

const G: f64 = 9.81;
const RHO: f64 = 2000.0;

fn world(text: &str) -> World3 {
    match Scene3::load_str(text, "test.toml", &nscdd_polyhedra::registry()) {
        Ok(Scene3 { world, .. }) => world,
        Err(e) => panic!("{e}"),
    }
}

fn block(name: &str, lo: [f64; 3], hi: [f64; 3], fixed: bool) -> String {
    let c = [0, 1, 2].map(|k| 0.5 * (lo[k] + hi[k]));
    let v: Vec<String> = box_points(lo, hi)
        .iter()
        .map(|p| format!("[{}, {}, {}]", p[0] - c[0], p[1] - c[1], p[2] - c[2]))
        .collect();
    format!(
        "[[bodies]]\nname = \"{name}\"\nshape = \"polyhedron\"\nmaterial = \"stone\"\nposition = [{}, {}, {}]\nfixed = {fixed}\nvertices = [{}]\n",
        c[0],
        c[1],
        c[2],
        v.join(", ")
    )
}

fn scene(gravity: [f64; 3], law: &str, bodies: &str) -> String {
    scene_relaxed(gravity, law, bodies, 1.0)
}

fn scene_relaxed(gravity: [f64; 3], law: &str, bodies: &str, omega: f64) -> String {
    format!(
        r#"dimension = 3
gravity = [{}, {}, {}]
[time]
step = 1e-3
theta = 0.5
steps = 200
[solver]
tolerance = 1e-6
max_sweeps = 20000
relaxation = {omega:?}
[detection]
alert = 0.002
[[materials]]
name = "stone"
density = {RHO}
[[laws]]
materials = ["stone", "stone"]
{law}
{bodies}"#,
        gravity[0], gravity[1], gravity[2]
    )
}

fn run(w: &mut World3, steps: usize) {
    for _ in 0..steps {
        let rep = w.step().unwrap();
        assert!(rep.solve.converged, "NLGS did not converge at step {}", w.step);
    }
}

fn bonds(w: &World3) -> usize {
    w.contacts.joint.iter().filter(|j| j.bonded()).count()
}

/// A 0.4 m cube hanging under a fixed block by a joint of area 0.16 m², tensile
/// strength `ratio` × m g / A; sweeps relaxed by `omega`.
fn hanging(ratio: f64, omega: f64) -> World3 {
    let (a, m) = (0.16, RHO * 0.064);
    let sigma = ratio * m * G / a;
    let law = format!("law = \"mohr_coulomb\"\nfriction = 0.6\ncohesion = 1e5\ntensile_strength = {sigma}");
    let bodies = block("ceiling", [-0.3, -0.3, 1.0], [0.3, 0.3, 1.2], true) + &block("block", [-0.2, -0.2, 0.6], [0.2, 0.2, 1.0], false);
    world(&scene_relaxed([0.0, 0.0, -G], &law, &bodies, omega))
}

#[test]
fn a_joint_holds_in_tension_below_its_strength_and_fails_above() {
    for omega in [1.0, 1.2] {
        tension(omega);
    }
}

fn tension(omega: f64) {
    let mut w = hanging(1.02, omega);
    assert_eq!(bonds(&w), 0);
    run(&mut w, 200);
    assert_eq!(bonds(&w), 4, "the four corners of the joint stay bonded");
    let dz = w.bodies.pos[1][2] - 0.8;
    assert!(dz.abs() < 1e-9, "held block moved {dz:e} m");
    // the joint carries the weight in tension
    let f: f64 = (0..w.contacts.len()).map(|a| w.contacts.r[a][0]).sum::<f64>() / 1e-3;
    let weight = RHO * 0.064 * G;
    assert!((f.abs() - weight).abs() < 1e-6 * weight, "carried {f} N of {weight} N");

    let mut w = hanging(0.98, omega);
    run(&mut w, 200);
    assert_eq!(bonds(&w), 0);
    // broken at the first step, it falls freely: ½ g t² (t = 0.2 s), less the
    // first step spent opening against the joint
    let drop = 0.8 - w.bodies.pos[1][2];
    let free = 0.5 * G * 0.2 * 0.2;
    assert!(drop > 0.97 * free && drop <= free * (1.0 + 1e-9), "drop {drop} vs {free}");
}

/// A 1 × 1 × 0.1 m slab bonded on a fixed base, gravity tilted by α = 40° (μ = 0.5
/// < tan α): it holds iff c A + μ m g cos α ≥ m g sin α; cohesion `ratio` × the
/// critical value; sweeps relaxed by `omega`.
fn sheared(ratio: f64, omega: f64) -> World3 {
    let alpha = 40f64.to_radians();
    let (mu, m, a) = (0.5, RHO * 0.1, 1.0);
    let c = ratio * m * G * (alpha.sin() - mu * alpha.cos()) / a;
    let law = format!("law = \"mohr_coulomb\"\nfriction = {mu}\ncohesion = {c}");
    let bodies = block("base", [-1.0, -1.0, -0.2], [1.0, 1.0, 0.0], true) + &block("slab", [-0.5, -0.5, 0.0], [0.5, 0.5, 0.1], false);
    world(&scene_relaxed([G * alpha.sin(), 0.0, -G * alpha.cos()], &law, &bodies, omega))
}

#[test]
fn a_joint_holds_in_shear_below_its_strength_and_slides_above() {
    for omega in [1.0, 1.2] {
        shear(omega);
    }
}

fn shear(omega: f64) {
    let mut w = sheared(1.02, omega);
    run(&mut w, 200);
    assert_eq!(bonds(&w), 4);
    let dx = w.bodies.pos[1][0];
    assert!(dx.abs() < 1e-9, "held slab moved {dx:e} m");

    let mut w = sheared(0.98, omega);
    run(&mut w, 200);
    assert_eq!(bonds(&w), 0);
    // then Coulomb sliding: x = ½ g (sin α − μ cos α) t², less the first step
    let alpha = 40f64.to_radians();
    let slide = 0.5 * G * (alpha.sin() - 0.5 * alpha.cos()) * 0.2 * 0.2;
    let dx = w.bodies.pos[1][0];
    assert!(dx > 0.95 * slide && dx <= slide * (1.0 + 1e-6), "slid {dx} vs {slide}");
}

#[test]
fn bonds_are_made_at_the_first_step_only_and_survive_a_restart() {
    // a block dropped from 5 mm lands on the base: its new contacts carry no bond
    let law = "law = \"mohr_coulomb\"\nfriction = 0.6\ncohesion = 1e5";
    let bodies = block("base", [-0.5, -0.5, -0.2], [0.5, 0.5, 0.0], true) + &block("block", [-0.2, -0.2, 0.005], [0.2, 0.2, 0.205], false);
    let mut w = world(&scene([0.0, 0.0, -G], law, &bodies));
    run(&mut w, 100);
    assert!(w.contacts.len() >= 4 && bonds(&w) == 0);

    // a restart keeps the bonds: 20 steps in one go equal 10 + 10 through final.json
    let text = scene(
        [0.0, 0.0, -G],
        law,
        &(block("base", [-0.5, -0.5, -0.2], [0.5, 0.5, 0.0], true) + &block("block", [-0.2, -0.2, 0.0], [0.2, 0.2, 0.2], false)),
    );
    let mut a = world(&text);
    run(&mut a, 20);
    let mut b = world(&text);
    run(&mut b, 10);
    let saved = final_json(&b);
    assert!(saved.contains("\"bonded\": true"));
    let mut c = world(&text);
    restart_str(&mut c, &saved, "final.json").unwrap();
    run(&mut c, 10);
    assert_eq!(bonds(&c), 4);
    assert_eq!(a.bodies.pos, c.bodies.pos);
    assert_eq!(a.contacts.r, c.contacts.r);
}

#[test]
fn mortar_joint_input_errors_name_the_key() {
    let bodies = block("block", [0.0; 3], [1.0; 3], false);
    for (law, key) in [
        ("law = \"mohr_coulomb\"\nfriction = 0.0\ncohesion = 1e5", "friction"),
        (
            "law = \"mohr_coulomb\"\nfriction = 0.5\ncohesion = 1e5\ntensile_strength = 3e5",
            "tensile_strength",
        ),
        ("law = \"mohr_coulomb\"\nfriction = 0.5\ncohesion = -1.0", "cohesion"),
        ("law = \"mohr_coulomb\"\nfriction = 0.5", "cohesion"),
        (
            "law = \"mohr_coulomb\"\nfriction = 0.5\ncohesion = 1.0\nrestitution = 0.5",
            "restitution",
        ),
    ] {
        let e = Scene3::load_str(&scene([0.0, 0.0, -G], law, &bodies), "t.toml", &nscdd_polyhedra::registry())
            .err()
            .expect(law);
        assert!(e.key.ends_with(key), "{law}: {e}");
        assert!(e.line.is_some(), "{e}");
    }
    // 2D scenes have no joints of faces
    let text = "[time]\nstep = 1e-3\nsteps = 1\n[[materials]]\nname = \"m\"\ndensity = 1.0\n[[laws]]\nmaterials = [\"m\", \"m\"]\nlaw = \"mohr_coulomb\"\nfriction = 0.5\ncohesion = 1.0\n[[bodies]]\nshape = \"disk\"\nradius = 1.0\nmaterial = \"m\"\nposition = [0.0, 0.0]\n";
    let e = nscdd::scene::load_str(text, "t.toml", &nscdd_rigid_disks::registry())
        .err()
        .expect("2D refuses");
    assert!(e.key.ends_with("law") && e.message.contains("3D"), "{e}");
}

/// Largest displacement after 0.3 s and the bonds left of a bonded semicircular
/// arch of t/R = 0.09 (a dry one collapses: masonry.rs) with mortar of cohesion c.
fn bonded_arch(c: f64) -> (f64, usize, usize) {
    let text = format!(
        r#"dimension = 3
gravity = [0.0, 0.0, -9.81]
[time]
step = 1e-3
theta = 0.5
steps = 300
[solver]
tolerance = 1e-5
max_sweeps = 20000
[detection]
alert = 0.002
[[materials]]
name = "stone"
density = 2000.0
[[laws]]
materials = ["stone", "stone"]
law = "mohr_coulomb"
friction = 1.0
cohesion = {c}
[[generate]]
kind = "arch"
material = "stone"
support_material = "stone"
radius = 1.0
thickness = 0.09
depth = 0.2
voussoirs = 24
"#
    );
    let mut w = world(&text);
    let x0 = w.bodies.pos.clone();
    w.step().unwrap();
    let first = bonds(&w);
    for _ in 1..300 {
        w.step().unwrap();
    }
    let d = (0..w.bodies.len())
        .map(|b| (0..3).map(|k| (w.bodies.pos[b][k] - x0[b][k]).powi(2)).sum::<f64>().sqrt())
        .fold(0.0, f64::max);
    (d, first, bonds(&w))
}

#[test]
fn mortar_holds_an_arch_too_thin_to_stand_dry() {
    // the joints of the thin arch need tension at the hinges of its mechanism:
    // mortar of 100 kPa (tension c/μ) holds them all; 10 Pa lets it collapse
    let (d, first, last) = bonded_arch(1e5);
    println!("c = 100 kPa: {d:.2e} m, {last} of {first} bonds");
    assert!(first == 4 * 25 && last == first, "{last} of {first} bonds");
    assert!(d < 1e-5, "moved {d} m");
    let (d, first, last) = bonded_arch(10.0);
    println!("c = 10 Pa: {d:.2e} m, {last} of {first} bonds");
    assert!(last < first && d > 1e-2, "moved {d} m, {last} of {first} bonds");
}
