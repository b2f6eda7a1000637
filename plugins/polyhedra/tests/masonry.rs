//! Masonry validation: stacks carry the exact weights, face–face contacts keep
//! their points under small rotations, a block on an incline fails at
//! α* = arctan(min(μ, b/h)) by the right mechanism, arches stand or collapse.
use nscdd::scene::Scene3;
use nscdd::world::World3;

fn world(text: &str) -> World3 {
    match Scene3::load_str(text, "test.toml", &nscdd_polyhedra::registry()) {
        Ok(Scene3 { world, .. }) => world,
        Err(e) => panic!("{e}"),
    }
}

fn brick(name: &str, lo: [f64; 3], hi: [f64; 3], rot: [f64; 3]) -> String {
    // vertices about the centre; the body placed at the centre, turned by `rot`
    let c = [0, 1, 2].map(|k| 0.5 * (lo[k] + hi[k]));
    let v: Vec<String> = nscdd_polyhedra::generate::box_points(lo, hi)
        .iter()
        .map(|p| format!("[{}, {}, {}]", p[0] - c[0], p[1] - c[1], p[2] - c[2]))
        .collect();
    format!(
        "[[bodies]]\nname = \"{name}\"\nshape = \"polyhedron\"\nmaterial = \"stone\"\nposition = [{}, {}, {}]\nrotation = [{}, {}, {}]\nvertices = [{}]\n",
        c[0],
        c[1],
        c[2],
        rot[0],
        rot[1],
        rot[2],
        v.join(", ")
    )
}

fn head(mu: f64, h: f64, steps: usize, floor_rot: [f64; 3]) -> String {
    format!(
        r#"dimension = 3
gravity = [0.0, 0.0, -9.81]
[time]
step = {h}
theta = 0.5
steps = {steps}
[solver]
tolerance = 1e-6
max_sweeps = 20000
[detection]
alert = 0.002
[[materials]]
name = "stone"
density = 2000.0
[[materials]]
name = "ground"
density = 2000.0
[[laws]]
materials = ["stone", "stone"]
friction = {mu}
[[laws]]
materials = ["stone", "ground"]
friction = {mu}
[[laws]]
materials = ["ground", "ground"]
law = "none"
[[bodies]]
name = "floor"
shape = "plane"
material = "ground"
position = [0.0, 0.0, 0.0]
rotation = [{}, {}, {}]
fixed = true
"#,
        floor_rot[0], floor_rot[1], floor_rot[2]
    )
}

/// Three 0.2 × 0.1 × 0.05 m bricks stacked on the floor (μ = 0.5, h = 1 ms), the
/// middle one turned by `turn` about z; `extra` is added to the scene head.
fn stack(steps: usize, turn: f64, extra: &str) -> String {
    let (l, wd, ht) = (0.2, 0.1, 0.05);
    let mut text = head(0.5, 1e-3, steps, [0.0; 3]) + extra;
    for k in 0..3 {
        let z = k as f64 * ht;
        let rot = if k == 1 { [0.0, 0.0, turn] } else { [0.0; 3] };
        text += &brick(&format!("b{k}"), [0.0, 0.0, z], [l, wd, z + ht], rot);
    }
    text
}

/// Normal impulse / h carried between body a (candidate or antagonist) and b.
fn carried(w: &World3, a: u32, b: u32) -> (f64, usize) {
    let c = &w.contacts;
    let mut f = 0.0;
    let mut n = 0;
    for k in 0..c.len() {
        let [i, j] = c.bodies[k];
        if (i, j) == (a, b) || (i, j) == (b, a) {
            f += c.r[k][0] / w.time.h;
            n += 1;
        }
    }
    (f, n)
}

#[test]
fn stack_of_bricks_carries_the_exact_weights() {
    let (l, wd, ht) = (0.2, 0.1, 0.05);
    // the middle brick turned by 0.01 rad about z: the face contacts keep 4 points
    let mut w = world(&stack(1, 0.01, ""));
    let weight = 2000.0 * l * wd * ht * 9.81;
    for _ in 0..200 {
        assert!(w.step().unwrap().solve.converged);
    }
    for (lower, upper, above) in [(0u32, 1u32, 3.0), (1, 2, 2.0), (2, 3, 1.0)] {
        let (f, n) = carried(&w, lower, upper);
        println!(
            "interface {lower}-{upper}: {n} points carry {f:.6} N (exact {:.6} N)",
            above * weight
        );
        // 4 corners of the overlap polygon, also where the brick turned about its
        // centre cuts every corner of the other's (an octagon)
        assert_eq!(n, 4, "the face–face contact keeps 4 of the overlap polygon's corners");
        assert!((f - above * weight).abs() < 1e-6 * above * weight, "{f} vs {}", above * weight);
    }
    // distinct contact points
    let c = &w.contacts;
    for a in 0..c.len() {
        for b in a + 1..c.len() {
            let d: f64 = (0..3).map(|k| (c.point[a][k] - c.point[b][k]).powi(2)).sum::<f64>().sqrt();
            assert!(d > 1e-6, "contacts {a} and {b} at the same point");
        }
    }
    for b in 1..4 {
        let v = w.bodies.vel[b];
        assert!(v.iter().all(|x| x.abs() < 1e-9), "body {b} moves: {v:?}");
    }
}

/// A block b × h on a plane inclined by α about y. Returns (slide along the
/// slope, rotation angle) after 0.6 s.
fn incline(b: f64, h: f64, mu: f64, alpha_deg: f64) -> (f64, f64) {
    let a = alpha_deg.to_radians();
    let mut text = head(mu, 1e-3, 1, [0.0, a, 0.0]);
    // the block turned by α about y, its base centre on the plane at the origin:
    // centre R·(0, 0, h/2), R e_z = (sin α, 0, cos α)
    let c = [0.5 * h * a.sin(), 0.0, 0.5 * h * a.cos()];
    text += &brick(
        "block",
        [c[0] - 0.5 * b, -0.1, c[2] - 0.5 * h],
        [c[0] + 0.5 * b, 0.1, c[2] + 0.5 * h],
        [0.0, a, 0.0],
    );
    let mut w = world(&text);
    let (x0, q0) = (w.bodies.pos[1], w.bodies.rot[1]);
    for _ in 0..600 {
        w.step().unwrap();
    }
    let x = w.bodies.pos[1];
    let d = ((x[0] - x0[0]).powi(2) + (x[2] - x0[2]).powi(2)).sqrt();
    let q = w.bodies.rot[1];
    let dot = (q[0] * q0[0] + q[1] * q0[1] + q[2] * q0[2] + q[3] * q0[3]).abs().min(1.0);
    (d, 2.0 * dot.acos())
}

#[test]
fn block_on_incline_fails_at_arctan_min_mu_b_over_h() {
    // sliding governs: μ = 0.4 < b/h = 1
    let star = 0.4f64.atan().to_degrees();
    let (d, r) = incline(0.2, 0.2, 0.4, star - 1.0);
    println!("sliding case, α* − 1°: slide {d:.2e} m, rotation {r:.2e}");
    assert!(d < 1e-4 && r < 1e-3);
    let (d, r) = incline(0.2, 0.2, 0.4, star + 1.0);
    println!("sliding case, α* + 1°: slide {d:.2e} m, rotation {r:.2e}");
    assert!(r < 1e-2, "slides without turning");
    let a = (star + 1.0).to_radians();
    let exact = 0.5 * 9.81 * (a.sin() - 0.4 * a.cos()) * 0.6f64.powi(2);
    println!("slide {d:.5} m, ½ g (sin α − μ cos α) t² = {exact:.5} m");
    assert!((d - exact).abs() < 0.02 * exact);
    // overturning governs: b/h = 0.25 < μ = 0.8
    let star = 0.25f64.atan().to_degrees();
    let (d, r) = incline(0.05, 0.2, 0.8, star - 1.0);
    println!("overturning case, α* − 1°: displacement {d:.2e} m, rotation {r:.2e}");
    assert!(d < 1e-4 && r < 1e-3);
    let (d, r) = incline(0.05, 0.2, 0.8, star + 1.0);
    println!("overturning case, α* + 1°: displacement {d:.2e} m, rotation {r:.2e}");
    assert!(r > 0.1, "overturns");
}

/// A block b × h standing on the hinge of a tilting table (a 1 m table turned about
/// the middle of its top face) turned at 0.02 rad/s up to `alpha_deg`, then held
/// for 1 s. The table stops abruptly: the block's centre, h/2 above the hinge, gets
/// a jolt ω h/2 ≤ 2 mm/s, which a block 1° from failure absorbs by slipping
/// v²/(2 g (μ cos α − sin α)) ≈ 1e-5 m. Returns (displacement, rotation) of the
/// block relative to the table.
fn tilting(b: f64, h: f64, mu: f64, alpha_deg: f64) -> (f64, f64) {
    // the scene head without its floor
    let head = head(mu, 2e-3, 1, [0.0; 3]);
    let mut text = head[..head.find("[[bodies]]").unwrap()].to_string();
    text += &format!(
        "[[generate]]\nkind = \"tilting_table\"\nmaterial = \"ground\"\nsize = [1.0, 0.6, 0.1]\nhinge = 0.0\nrate = 0.02\nmax_angle = {alpha_deg}\n"
    );
    text += &brick("block", [-0.5 * b, -0.1, 0.0], [0.5 * b, 0.1, h], [0.0; 3]);
    let mut w = world(&text);
    // body 0: the block, body 1: the generated table
    let rel = |w: &World3| {
        let (qt, qb) = (w.bodies.rot[1], w.bodies.rot[0]);
        let d = [0, 1, 2].map(|k| w.bodies.pos[0][k] - w.bodies.pos[1][k]);
        // the block's pose in the table's frame: Rₜᵀ (x_b − x_t), qₜ⁻¹ q_b
        let qi = [qt[0], -qt[1], -qt[2], -qt[3]];
        (nscdd::dim::rotation::rotate(qi, d), nscdd::dim::rotation::quat_mul(qi, qb))
    };
    let (x0, q0) = rel(&w);
    let qt0 = w.bodies.rot[1];
    let steps = ((alpha_deg.to_radians() / 0.02 + 1.0) / 2e-3).round() as usize;
    for _ in 0..steps {
        w.step().unwrap();
    }
    // the table's rotation since t = 0 (its principal frame need not be the world's)
    let qt = nscdd::dim::rotation::quat_mul(w.bodies.rot[1], [qt0[0], -qt0[1], -qt0[2], -qt0[3]]);
    let tilt = 2.0 * qt[0].abs().min(1.0).acos();
    // drives act at step ends: the tilt stops within rate × h of max_angle
    assert!((tilt - alpha_deg.to_radians()).abs() <= 0.02 * 2e-3, "table at {tilt} rad");
    let (x, q) = rel(&w);
    let d = [0, 1, 2].map(|k| x[k] - x0[k]);
    let dot = (q[0] * q0[0] + q[1] * q0[1] + q[2] * q0[2] + q[3] * q0[3]).abs().min(1.0);
    ((d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt(), 2.0 * dot.acos())
}

#[test]
fn block_on_tilting_table_fails_at_arctan_min_mu_b_over_h() {
    // sliding governs: μ = 0.5 < b/h = 2
    let star = 0.5f64.atan().to_degrees();
    let (d, r) = tilting(0.2, 0.1, 0.5, star - 1.0);
    println!("table, sliding case, α* − 1°: {d:.2e} m, {r:.2e} rad");
    assert!(d < 1e-4 && r < 1e-3);
    let (d, r) = tilting(0.2, 0.1, 0.5, star + 1.0);
    println!("table, sliding case, α* + 1°: {d:.2e} m, {r:.2e} rad");
    assert!(d > 0.02 && r < 1e-2, "slides without turning");
    // overturning governs: b/h = 0.5 < μ = 0.8
    let star = 0.5f64.atan().to_degrees();
    let (d, r) = tilting(0.1, 0.2, 0.8, star - 1.0);
    println!("table, overturning case, α* − 1°: {d:.2e} m, {r:.2e} rad");
    assert!(d < 1e-4 && r < 1e-3);
    let (_, r) = tilting(0.1, 0.2, 0.8, star + 1.0);
    println!("table, overturning case, α* + 1°: {r:.2e} rad");
    assert!(r > 0.2, "overturns");
}

/// An arch of 24 radial voussoirs of thickness ratio t/R (R = 1 m), μ = 1: bodies
/// 0..24 the voussoirs from the right springing (angle 0) to the left, 24 the left
/// support, 25 the right one.
fn arch_world(t_over_r: f64) -> World3 {
    let text = format!(
        r#"dimension = 3
gravity = [0.0, 0.0, -9.81]
[time]
step = 1e-3
theta = 0.5
steps = {steps}
[solver]
tolerance = 1e-5
max_sweeps = 5000
[detection]
alert = 0.002
[[materials]]
name = "stone"
density = 2000.0
[[laws]]
materials = ["stone", "stone"]
friction = 1.0
[[generate]]
kind = "arch"
material = "stone"
support_material = "stone"
radius = 1.0
thickness = {t_over_r}
depth = 0.2
voussoirs = 24
"#,
        steps = 1
    );
    world(&text)
}

fn largest_displacement(w: &World3, x0: &[[f64; 3]]) -> f64 {
    (0..w.bodies.len())
        .map(|b| (0..3).map(|k| (w.bodies.pos[b][k] - x0[b][k]).powi(2)).sum::<f64>().sqrt())
        .fold(0.0, f64::max)
}

/// Largest displacement of the voussoirs of an arch of thickness ratio t/R after
/// `steps` steps of 1 ms.
fn arch(t_over_r: f64, steps: usize) -> f64 {
    let mut w = arch_world(t_over_r);
    let x0 = w.bodies.pos.clone();
    for _ in 0..steps {
        w.step().unwrap();
    }
    largest_displacement(&w, &x0)
}

/// Relative rotations (about y) at the 25 joints of the arch, from the right
/// springing: joint k lies between voussoirs k − 1 and k, at π k / 24.
fn joint_rotations(w: &World3, q0: &[[f64; 4]]) -> Vec<f64> {
    use nscdd::dim::rotation::{quat_mul, to_rotation_vector};
    let theta = |b: usize| {
        let q = q0[b];
        to_rotation_vector(quat_mul(w.bodies.rot[b], [q[0], -q[1], -q[2], -q[3]]))[1]
    };
    let turn = |k: usize| if k == 0 || k == 25 { 0.0 } else { theta(k - 1) };
    (0..25).map(|k| turn(k + 1) - turn(k)).collect()
}

#[test]
fn collapsing_arch_forms_five_hinges() {
    // t/R = 0.09, below the minimum 0.1075 of radial joints: follow the collapse
    // until a voussoir has moved 5 mm, while the segments are still rigid blocks
    let mut w = arch_world(0.09);
    let (x0, q0) = (w.bodies.pos.clone(), w.bodies.rot.clone());
    while largest_displacement(&w, &x0) < 5e-3 {
        w.step().unwrap();
        assert!(w.step < 2000, "the arch does not collapse");
    }
    let rot = joint_rotations(&w, &q0);
    let max = rot.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    // a hinge: a run of adjacent joints turning the same way (the discrete joints
    // share a hinge that falls between them), at its rotation-weighted position
    let mut hinges: Vec<(f64, f64)> = vec![]; // (position in joints, rotation)
    let mut k = 0;
    while k < 25 {
        if rot[k].abs() <= 0.1 * max {
            k += 1;
            continue;
        }
        let (mut sum, mut moment) = (0.0, 0.0);
        let sign = rot[k].signum();
        while k < 25 && rot[k].abs() > 0.1 * max && rot[k].signum() == sign {
            sum += rot[k];
            moment += rot[k] * k as f64;
            k += 1;
        }
        hinges.push((moment / sum, sum));
    }
    let deg = |x: f64| 180.0 * x / 24.0;
    println!(
        "t = {:.3} s: hinges at {:?} degrees from the right springing, rotations {:?}",
        w.t,
        hinges.iter().map(|h| deg(h.0)).collect::<Vec<_>>(),
        hinges.iter().map(|h| h.1).collect::<Vec<_>>()
    );
    assert_eq!(hinges.len(), 5, "a five-hinge mechanism: {rot:?}");
    // symmetric; at the springings, at the crown, and at the haunches 45°–65° from
    // the crown (Heyman: 54.5° at the minimum thickness of radial joints)
    assert!((deg(hinges[2].0) - 90.0).abs() < 1e-6, "crown hinge at {}", deg(hinges[2].0));
    assert!((hinges[0].0 + hinges[4].0 - 24.0).abs() < 1e-3 && (hinges[1].0 + hinges[3].0 - 24.0).abs() < 1e-3);
    assert!(hinges[0].0 < 1.0, "springing hinge at {}°", deg(hinges[0].0));
    let haunch = 90.0 - deg(hinges[1].0);
    assert!((45.0..=65.0).contains(&haunch), "haunch hinge {haunch}° from the crown");
    // alternating senses: intrados and extrados hinges alternate along the arch
    for k in 0..4 {
        assert!(hinges[k].1 * hinges[k + 1].1 < 0.0, "senses {hinges:?}");
    }
}

/// A semicircular arch of radial voussoirs (μ = 1: no sliding) stands at
/// t/R = 0.12 and collapses at t/R = 0.09 (the minimum for radial joints is
/// t/R ≈ 0.1075).
#[test]
fn arch_stands_at_012_and_collapses_at_009() {
    let stand = arch(0.12, 800);
    let fall = arch(0.09, 800);
    println!("largest voussoir displacement after 0.8 s: t/R = 0.12: {stand:.3e} m, t/R = 0.09: {fall:.3e} m");
    assert!(stand < 1e-3, "t/R = 0.12 should stand: {stand}");
    assert!(fall > 2e-2, "t/R = 0.09 should collapse: {fall}");
}

#[test]
fn stack_exports_a_frictional_contact_problem_that_solve_fc_solves() {
    let mut w = world(&stack(1, 0.01, ""));
    for _ in 0..20 {
        w.step().unwrap();
    }
    let p = nscdd::fc::problem_from_world3(&w);
    assert_eq!((p.dim, p.nc), (3, 12), "3 interfaces of 4 points");
    // the engine's impulses solve the exported problem (to the engine's tolerance)
    let r_world: Vec<f64> = w.contacts.r.iter().flatten().copied().collect();
    let res_world = p.natural_residual(&r_world);
    let sol = p.solve(&nscdd::fc::FcOptions::natural(1e-6));
    println!(
        "world r: residual {res_world:.1e}; solve-fc: {} sweeps, residual {:.1e}",
        sol.sweeps, sol.residual
    );
    // (NLGS converges slowly on the redundant 4-point faces in this norm)
    assert!(sol.converged && sol.residual < 1e-6);
    assert!(res_world < 1e-5, "{res_world}");
    // the velocities (unique, unlike the impulses of 4-point faces) agree
    let u_world = p.velocity(&r_world);
    let du = u_world.iter().zip(&sol.u).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
    assert!(du < 1e-6, "local velocities differ by {du}");
}

#[test]
fn outputs_draw_the_blocks_and_their_contact_points() {
    let text = stack(20, 0.0, "[output]\nevery = 10\n");
    let mut s = Scene3::load_str(&text, "stack.toml", &nscdd_polyhedra::registry()).unwrap();
    let dir = std::env::temp_dir().join(format!("nscdd-poly-out-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    nscdd::run::run(&mut s, &nscdd_polyhedra::registry(), &dir, |_, _| {}).unwrap();
    for f in ["points.pvd", "walls.pvd", "vtk/points_000002.vtp", "vtk/walls_000002.vtp"] {
        assert!(dir.join(f).exists(), "{f}");
    }
    let points = std::fs::read_to_string(dir.join("vtk/points_000002.vtp")).unwrap();
    assert!(points.contains("NumberOfPoints=\"12\""), "12 contact points");
    for name in ["\"force\"", "\"f_n\"", "\"bonded\""] {
        assert!(points.contains(name), "{name}");
    }
    // each brick drawn as its 6 faces (the plane as one more polygon)
    let walls = std::fs::read_to_string(dir.join("vtk/walls_000002.vtp")).unwrap();
    assert!(walls.contains("NumberOfPolys=\"19\""), "{}", &walls[..300]);
    let fin: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(dir.join("final.json")).unwrap()).unwrap();
    assert_eq!(fin["bodies"][1]["kind"], "polyhedron");
    assert_eq!(fin["contacts"].as_array().unwrap().len(), 12);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn spheres_rest_on_a_block_face_and_edge() {
    // a fixed 0.4 m cube; a ball on its top face, another on its top edge (x = 0.2),
    // leaning on it from outside: the first rests, the edge holds the second's
    // normal along the line from the edge to its centre
    let r = 0.05;
    let mut text = head(0.5, 1e-3, 1, [0.0; 3]);
    text += "[output]\nevery = 0\n";
    let v: Vec<String> = nscdd_polyhedra::generate::box_points([-0.2, -0.2, -0.2], [0.2, 0.2, 0.2])
        .iter()
        .map(|p| format!("[{}, {}, {}]", p[0], p[1], p[2]))
        .collect();
    text += &format!(
        "[[bodies]]\nname = \"cube\"\nshape = \"polyhedron\"\nmaterial = \"ground\"\nposition = [0.0, 0.0, 0.6]\nfixed = true\nvertices = [{}]\n",
        v.join(", ")
    );
    text += &format!(
        "[[bodies]]\nname = \"top\"\nshape = \"sphere\"\nmaterial = \"stone\"\nradius = {r}\nposition = [0.0, 0.0, {}]\n",
        0.8 + r
    );
    // on the edge at 45°: centre at (0.2, 0, 0.8) + r (1, 0, 1)/√2
    let c = r / 2f64.sqrt();
    text += &format!(
        "[[bodies]]\nname = \"edge\"\nshape = \"sphere\"\nmaterial = \"stone\"\nradius = {r}\nposition = [{}, 0.0, {}]\n",
        0.2 + c,
        0.8 + c
    );
    let mut w = world(&text);
    w.step().unwrap();
    let c_top = (0..w.contacts.len()).find(|&a| w.contacts.bodies[a].contains(&2)).unwrap();
    let c_edge = (0..w.contacts.len()).find(|&a| w.contacts.bodies[a].contains(&3)).unwrap();
    // the normals: vertical on the face, diagonal on the edge
    let n_top = w.contacts.frame[c_top].basis[0];
    let n_edge = w.contacts.frame[c_edge].basis[0];
    let s = 0.5f64.sqrt();
    assert!((n_top[2].abs() - 1.0).abs() < 1e-12, "{n_top:?}");
    assert!(
        (n_edge[0].abs() - s).abs() < 1e-9 && (n_edge[2].abs() - s).abs() < 1e-9,
        "{n_edge:?}"
    );
    assert!(w.contacts.gap[c_top].abs() < 1e-12 && w.contacts.gap[c_edge].abs() < 1e-12);
    for _ in 0..100 {
        w.step().unwrap();
    }
    // the ball on the face is at rest and carries its weight to the cube
    let m = w.bodies.mass[2];
    assert!((w.bodies.pos[2][2] - (0.8 + r)).abs() < 1e-9);
    assert!((w.reaction[2][2] / 1e-3 - m * 9.81).abs() < 1e-6 * m * 9.81);
    // the ball on the edge rolls off outwards (x grows), never into the cube
    assert!(w.bodies.pos[3][0] > 0.2 + c);
    let (d, _) = {
        let p = w.bodies.pos[3];
        let q = [p[0].clamp(-0.2, 0.2), p[1].clamp(-0.2, 0.2), p[2].clamp(0.4, 0.8)];
        (((p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2) + (p[2] - q[2]).powi(2)).sqrt(), q)
    };
    assert!(d > r - 1e-6, "ball centre {d} from the cube");
}

#[test]
fn generator_input_errors_name_the_key() {
    let head = head(0.5, 1e-3, 1, [0.0; 3]);
    for (gen, key) in [
        (
            "kind = \"tilting_table\"\nmaterial = \"ground\"\nsize = [1.0, 0.6, 0.1]\nrate = 0.1\nmax_angle = 95.0",
            "max_angle",
        ),
        (
            "kind = \"tilting_table\"\nmaterial = \"ground\"\nsize = [1.0, 0.6, 0.1]\nrate = 0.1\nmax_angle = 30.0\nhinge = 0.8",
            "hinge",
        ),
        (
            "kind = \"tilting_table\"\nmaterial = \"ground\"\nsize = [1.0, 0.6, 0.1]\nrate = -0.1\nmax_angle = 30.0",
            "rate",
        ),
        (
            "kind = \"tilting_table\"\nmaterial = \"ground\"\nsize = [1.0, 0.6, 0.1]\nrate = 0.1\nmax_angle = 30.0\nstart = -1.0",
            "start",
        ),
        (
            "kind = \"arch\"\nmaterial = \"stone\"\nradius = 1.0\nthickness = 0.1\nvoussoirs = 8\nsupports = \"no\"",
            "supports",
        ),
        (
            "kind = \"arch\"\nmaterial = \"stone\"\nradius = 1.0\nthickness = 0.1\nvoussoirs = 8",
            "support_material",
        ),
        (
            "kind = \"brick_wall\"\nmaterial = \"stone\"\nbrick = [0.2, 0.0, 0.05]\ncourses = 2\nbricks = 2",
            "brick",
        ),
    ] {
        let text = format!("{head}[[generate]]\n{gen}\n");
        let e = Scene3::load_str(&text, "t.toml", &nscdd_polyhedra::registry()).err().expect(gen);
        assert!(e.key.ends_with(key) && e.line.is_some(), "{gen}: {e}");
    }
}
