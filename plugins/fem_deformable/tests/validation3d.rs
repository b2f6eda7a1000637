//! 3D deformable bodies (tetrahedra) against analytic answers: a bar striking a
//! rigid plane, a column under its weight, a deformable block on another, rigid
//! spheres and a masonry block on a deformable block; 3D input errors.
use nscdd::registry::Registry;
use nscdd_fem_deformable::scene::{load3_str, FeScene3};

fn registry() -> Registry {
    let mut r = Registry::new();
    r.add_plugin(&nscdd_fem_deformable::FemPlugin);
    r.add_plugin(&nscdd_spheres::SpheresPlugin);
    r.add_plugin(&nscdd_polyhedra::PolyhedraPlugin);
    r
}

fn scene(text: &str) -> FeScene3 {
    match load3_str(text, "test.toml", &registry()) {
        Ok(s) => s,
        Err(e) => panic!("{e}"),
    }
}

/// Σ r_n of the deformable contacts whose antagonist is rigid / deformable.
fn impulses(s: &FeScene3) -> (f64, f64) {
    let c = &s.fe.contacts;
    let (mut rigid, mut fe) = (0.0, 0.0);
    for a in 0..c.len() {
        match c.anta[a] {
            nscdd_fem_deformable::contact3::Anta3::Rigid { .. } => rigid += c.r[a][0],
            nscdd_fem_deformable::contact3::Anta3::Fe(_) => fe += c.r[a][0],
        }
    }
    (rigid, fe)
}

/// Mean z displacement of the nodes of body `b` at reference height z.
fn mean_uz(s: &FeScene3, b: usize, z: f64) -> f64 {
    let body = &s.fe.bodies[b];
    let (mut sum, mut n) = (0.0, 0);
    for k in 0..body.mesh.n_nodes() {
        if (body.mesh.x0[3 * k + 2] - z).abs() < 1e-9 {
            sum += body.u[3 * k + 2];
            n += 1;
        }
    }
    sum / n as f64
}

const HEAD: &str = r#"
dimension = 3
[[materials]]
name = "solid"
density = 1000.0
[[materials]]
name = "ground"
density = 1000.0
[[bodies]]
name = "floor"
shape = "plane"
material = "ground"
position = [0.0, 0.0, 0.0]
fixed = true
"#;

/// A bar (ν = 0: c = √(E/ρ), 1D waves) strikes a rigid plane at v0 along its axis:
/// contact lasts 2L/c and the bar leaves at −v0 (θ = ½).
#[test]
fn bar_impact_3d_lasts_two_l_over_c() {
    let (e, rho, l, v0): (f64, f64, f64, f64) = (1e6, 1000.0, 1.0, 1.0);
    let c = (e / rho).sqrt();
    let nz = 40;
    let h = l / nz as f64 / c;
    let text = format!(
        r#"gravity = [0.0, 0.0, 0.0]
{HEAD}
[time]
step = {h}
theta = 0.5
steps = 1
[solver]
tolerance = 1e-8
max_sweeps = 20000
[detection]
alert = 0.001
[[laws]]
materials = ["solid", "ground"]
law = "frictionless"
[[deformable]]
material = "solid"
young = {e}
poisson = 0.0
velocity = [0.0, 0.0, -{v0}]
mesh = {{ box = {{ origin = [0.0, 0.0, 0.0], size = [0.05, 0.05, {l}], cells = [1, 1, {nz}] }} }}
"#
    );
    let mut s = scene(&text);
    let b0 = &s.fe.bodies[0];
    let (mass, e0) = (b0.mass(), b0.kinetic_energy() + b0.elastic_energy());
    let (mut first, mut last) = (None, None);
    for k in 0..(3.0 * l / c / h) as usize {
        let rep = s.step().unwrap();
        assert!(rep.solve.converged);
        if impulses(&s).0 > 0.0 {
            first.get_or_insert(k);
            last = Some(k);
        }
    }
    let duration = (last.unwrap() - first.unwrap() + 1) as f64 * h;
    let b = &s.fe.bodies[0];
    let mut mv = vec![0.0; b.n_dofs()];
    b.mul_add(1.0, 0.0, &b.v, &mut mv);
    let vz = (0..b.mesh.n_nodes()).map(|k| mv[3 * k + 2]).sum::<f64>() / mass;
    let e1 = b.kinetic_energy() + b.elastic_energy();
    println!(
        "contact {duration:.4e} s (2L/c = {:.4e}), exit velocity {vz:.4}, energy {e1:.5} / {e0:.5}",
        2.0 * l / c
    );
    assert!((duration - 2.0 * l / c).abs() <= 0.05 * 2.0 * l / c, "duration {duration}");
    assert!((vz - v0).abs() < 0.05 * v0, "exit velocity {vz}");
    assert!(e1 <= e0 * (1.0 + 1e-9), "energy grew: {e1} > {e0}");
}

/// A column under its weight on a frictionless plane (ν = 0: σzz = −ρg(H − z),
/// uniform pressure ρgH, top settlement ρgH²/(2E)), brought to rest by θ = 1.
fn column(nz: usize) -> (f64, f64, f64) {
    let (e, rho, g, hgt) = (1e7, 1000.0, 9.81, 1.0);
    let text = format!(
        r#"gravity = [0.0, 0.0, -{g}]
{HEAD}
[time]
step = 0.05
theta = 1.0
steps = 40
[solver]
tolerance = 1e-7
max_sweeps = 20000
[detection]
alert = 0.01
[[laws]]
materials = ["solid", "ground"]
law = "frictionless"
[[deformable]]
material = "solid"
young = {e}
poisson = 0.0
mesh = {{ box = {{ origin = [0.0, 0.0, 0.0], size = [0.5, 0.5, {hgt}], cells = [2, 2, {nz}] }} }}
"#
    );
    let mut s = scene(&text);
    for _ in 0..40 {
        assert!(s.step().unwrap().solve.converged);
    }
    let carried = impulses(&s).0 / 0.05 / (rho * g * 0.25 * hgt);
    (mean_uz(&s, 0, hgt), -rho * g * hgt * hgt / (2.0 * e), carried)
}

#[test]
fn column_3d_settlement_converges_and_floor_carries_the_weight() {
    let mut errs = vec![];
    for nz in [2, 4, 8] {
        let (settle, exact, carried) = column(nz);
        let err = ((settle - exact) / exact).abs();
        println!("nz {nz}: settlement {settle:.5e} (exact {exact:.5e}), error {err:.2e}; floor carries {carried} × weight");
        assert!((carried - 1.0).abs() < 1e-5, "floor carries {carried} × the weight");
        errs.push(err);
    }
    // the answer is quadratic in z with a linear load: linear elements give it
    // exactly at the nodes along the column, so what is left is the rest state
    // reached by the θ = 1 steps and the solver's tolerance, on every mesh
    assert!(errs.iter().all(|&e| e < 1e-3), "{errs:?}");
}

/// A deformable block resting on another (node-to-face): the lower one carries
/// the upper one's weight through their contacts, and the floor both weights;
/// no node of the upper block sinks into the lower one.
#[test]
fn block_on_block_3d_carries_the_weight() {
    let (rho, g) = (1000.0, 9.81);
    let text = format!(
        r#"gravity = [0.0, 0.0, -{g}]
{HEAD}
[time]
step = 0.02
theta = 1.0
steps = 30
[solver]
tolerance = 1e-7
max_sweeps = 20000
[detection]
alert = 0.01
[[laws]]
materials = ["solid", "ground"]
law = "frictionless"
[[laws]]
materials = ["solid", "solid"]
friction = 0.5
[[deformable]]
name = "upper"
material = "solid"
young = 2e7
poisson = 0.25
mesh = {{ box = {{ origin = [0.25, 0.25, 0.4005], size = [0.5, 0.5, 0.3], cells = [4, 4, 2] }} }}
[[deformable]]
name = "lower"
material = "solid"
young = 1e7
poisson = 0.25
mesh = {{ box = {{ origin = [0.0, 0.0, 0.0], size = [1.0, 1.0, 0.4], cells = [3, 3, 2] }} }}
"#
    );
    let mut s = scene(&text);
    let (wu, wl) = (rho * g * 0.5 * 0.5 * 0.3, rho * g * 0.4);
    for _ in 0..30 {
        assert!(s.step().unwrap().solve.converged);
    }
    let (floor, between) = impulses(&s);
    let (floor, between) = (floor / 0.02, between / 0.02);
    println!("between {between} N (upper weight {wu}), floor {floor} N (both {})", wu + wl);
    assert!((between - wu).abs() < 1e-4 * wu);
    assert!((floor - wu - wl).abs() < 1e-4 * (wu + wl));
    // the upper block's base nodes stay on the lower block's top faces
    let c = &s.fe.contacts;
    let gaps: Vec<f64> = (0..c.len())
        .filter(|&a| matches!(c.anta[a], nscdd_fem_deformable::contact3::Anta3::Fe(_)))
        .map(|a| c.gap[a])
        .collect();
    let (lo, hi) = gaps.iter().fold((f64::MAX, f64::MIN), |m, &g| (m.0.min(g), m.1.max(g)));
    println!("{} node-to-face contacts, gaps in [{lo:.3e}, {hi:.3e}]", gaps.len());
    assert_eq!(gaps.len(), 25, "the 5 × 5 base nodes of the upper block");
    assert!(lo > -1e-6 && hi < 1e-6, "gaps in [{lo}, {hi}]");
}

/// Rigid spheres on a coarse deformable block: a small one (radius below the
/// mesh size, meets the closest face point) rests on the flat surface; a large
/// one (meets the nodes) rests on the node under its lowest point (a sphere off
/// a node would roll into the hollow between nodes: it cuts the facets, sag
/// ≈ d²/2R for nodes at d from its lowest point); the block carries both weights.
/// The scene head of the rigid-on-deformable tests: gravity, the floor, h = 0.01 s
/// (θ = 1, 60 steps), tolerance 1e-7, a material `stone` (2 500 kg/m³) with μ = 0.5
/// on the deformable `solid` and no friction on the floor.
fn stone_head() -> String {
    let g = 9.81;
    format!(
        r#"gravity = [0.0, 0.0, -{g}]
{HEAD}
[time]
step = 0.01
theta = 1.0
steps = 60
[solver]
tolerance = 1e-7
max_sweeps = 20000
[detection]
alert = 0.02
[[materials]]
name = "stone"
density = 2500.0
[[laws]]
materials = ["solid", "ground"]
law = "frictionless"
[[laws]]
materials = ["solid", "stone"]
friction = 0.5
[[laws]]
materials = ["ground", "stone"]
law = "frictionless"
"#
    )
}

#[test]
fn spheres_rest_on_a_deformable_block() {
    let g = 9.81;
    let text = format!(
        r#"{}[[laws]]
materials = ["stone", "stone"]
friction = 0.3
[[bodies]]
name = "small"
shape = "sphere"
radius = 0.05
material = "stone"
position = [0.37, 0.41, 0.36]
[[bodies]]
name = "large"
shape = "sphere"
radius = 0.4
material = "stone"
position = [1.5, 0.5, 0.71]
[[deformable]]
material = "solid"
young = 1e8
poisson = 0.3
fix = ["bottom"]
mesh = {{ box = {{ origin = [0.0, 0.0, 0.0], size = [2.0, 1.0, 0.3], cells = [8, 4, 2] }} }}
"#,
        stone_head()
    );
    let mut s = scene(&text);
    for _ in 0..60 {
        assert!(s.step().unwrap().solve.converged);
    }
    let z = |b: usize| s.world.bodies.pos[b][2];
    println!("small sphere centre z = {} (rest 0.35), large {} (rest 0.70)", z(1), z(2));
    assert!((z(1) - 0.35).abs() < 2e-3, "small sphere at {}", z(1));
    assert!(z(2) < 0.70 && z(2) > 0.699, "large sphere at {}", z(2));
    let c = &s.fe.contacts;
    let mut on = [0.0; 3];
    for a in 0..c.len() {
        if let nscdd_fem_deformable::contact3::Anta3::Rigid { body, .. } = c.anta[a] {
            on[body as usize] += c.r[a][0] / 0.01;
        }
    }
    let m = |b: usize| s.world.bodies.mass[b];
    println!("carried: small {} N ({} N), large {} N ({} N)", on[1], m(1) * g, on[2], m(2) * g);
    assert!((on[1] - m(1) * g).abs() < 1e-4 * m(1) * g);
    assert!((on[2] - m(2) * g).abs() < 1e-4 * m(2) * g);
    // one face point for the small sphere; the large one, centred over a node,
    // meets that node (its neighbours are 0.25 m away: d²/2R = 0.08 m above it)
    let count = |b: u32| {
        c.anta
            .iter()
            .filter(|x| matches!(x, nscdd_fem_deformable::contact3::Anta3::Rigid { body, .. } if *body == b))
            .count()
    };
    assert_eq!(count(1), 1);
    assert!(count(2) >= 1, "{}", count(2));
    for a in 0..c.len() {
        if c.r[a][0] > 0.0 {
            assert!(c.gap[a].abs() < 1e-5, "active contact {a} with gap {}", c.gap[a]);
        }
    }
}

/// A 0.4 × 0.4 × 0.2 m block (polyhedron) centred on a deformable block whose mesh
/// (0.1 m) puts 25 nodes under it, 16 of them on its edges: the nodes meet the
/// block's bottom face (on an edge, the face facing the soil's surface), carry its
/// weight, and the block settles level.
#[test]
fn a_masonry_block_rests_level_on_a_deformable_block() {
    let g = 9.81;
    let v: Vec<String> = nscdd_polyhedra::generate::box_points([-0.2, -0.2, -0.1], [0.2, 0.2, 0.1])
        .iter()
        .map(|p| format!("[{}, {}, {}]", p[0], p[1], p[2]))
        .collect();
    let text = format!(
        r#"{}[[bodies]]
name = "block"
shape = "polyhedron"
material = "stone"
position = [0.5, 0.5, 0.4]
vertices = [{}]
[[deformable]]
material = "solid"
young = 1e7
poisson = 0.3
fix = ["bottom"]
mesh = {{ box = {{ origin = [0.0, 0.0, 0.0], size = [1.0, 1.0, 0.3], cells = [10, 10, 3] }} }}
"#,
        stone_head(),
        v.join(", ")
    );
    let mut s = scene(&text);
    for _ in 0..60 {
        assert!(s.step().unwrap().solve.converged);
    }
    let w = &s.world;
    let (rigid, _) = impulses(&s);
    let weight = w.bodies.mass[1] * g;
    let carried = rigid / 0.01;
    let c = &s.fe.contacts;
    let active = (0..c.len()).filter(|&a| c.r[a][0] > 0.0).count();
    let q = w.bodies.rot[1];
    let tilt = 2.0 * (q[1] * q[1] + q[2] * q[2]).sqrt().min(1.0).asin();
    let settle = 0.4 - w.bodies.pos[1][2];
    println!("block: {active} nodes carry {carried} N of {weight} N, settles {settle:e} m, tilt {tilt:e} rad");
    assert!((carried - weight).abs() < 1e-4 * weight);
    assert!(active >= 9, "{active} nodes carry the block");
    // 1D estimate σ h / E = 4.9 kPa × 0.3 m / 1e7 Pa = 1.5e-4 m (the soil spreads
    // the load: less)
    assert!(settle > 0.0 && settle < 1.5e-4, "settlement {settle}");
    // level to 1 % of the settlement across its half-width (the tetrahedra of a box
    // mesh are not symmetric: the soil is not exactly so either)
    assert!(tilt * 0.2 < 0.01 * settle, "tilt {tilt}");
}

fn load_err(extra: &str) -> nscdd::error::InputError {
    let text = format!(
        r#"{HEAD}
[time]
step = 0.01
steps = 1
[[deformable]]
material = "solid"
young = 1e7
poisson = 0.3
{extra}
"#
    );
    match load3_str(&text, "bad.toml", &registry()) {
        Ok(_) => panic!("accepted: {extra}"),
        Err(e) => e,
    }
}

#[test]
fn input_errors_3d_name_the_key() {
    let e = load_err("plane = \"stress\"\nmesh = { box = { origin = [0.0, 0.0, 0.0], size = [1.0, 1.0, 1.0], cells = [1, 1, 1] } }");
    assert_eq!(e.key, "deformable[0].plane", "{e}");
    let e = load_err("mesh = { rectangle = { origin = [0.0, 0.0], size = [1.0, 1.0], cells = [1, 1] } }");
    assert_eq!(e.key, "deformable[0].mesh", "{e}");
    assert!(e.to_string().contains("box"), "{e}");
    let e = load_err("velocity = [1.0, 0.0]\nmesh = { box = { origin = [0.0, 0.0, 0.0], size = [1.0, 1.0, 1.0], cells = [1, 1, 1] } }");
    assert_eq!(e.key, "deformable[0].velocity", "{e}");
    let e = load_err("fix = [\"north\"]\nmesh = { box = { origin = [0.0, 0.0, 0.0], size = [1.0, 1.0, 1.0], cells = [1, 1, 1] } }");
    assert!(e.to_string().contains("front"), "{e}");
    // deformable contacts are rigid: a compliant law on their material is refused
    let e = load_err("mesh = { box = { origin = [0.0, 0.0, 0.0], size = [1.0, 1.0, 1.0], cells = [1, 1, 1] } }\n[[laws]]\nmaterials = [\"solid\", \"ground\"]\nlaw = \"compliant\"\nstiffness = 1e6");
    assert_eq!(e.key, "deformable[0].material", "{e}");
    assert!(e.to_string().contains("compliant"), "{e}");
}

/// Two stacks of two spheres on a deformable block (fixed at its base, resting on
/// the floor): the lower spheres touch the block, the upper ones the lower.
fn stacks(decomposition: &str) -> String {
    format!(
        r#"{}[[laws]]
materials = ["stone", "stone"]
friction = 0.3
[[bodies]]
shape = "sphere"
radius = 0.1
material = "stone"
position = [0.5, 0.5, 0.41]
[[bodies]]
shape = "sphere"
radius = 0.1
material = "stone"
position = [0.5, 0.51, 0.61]
[[bodies]]
shape = "sphere"
radius = 0.1
material = "stone"
position = [1.5, 0.5, 0.41]
[[bodies]]
shape = "sphere"
radius = 0.1
material = "stone"
position = [1.51, 0.5, 0.61]
[[deformable]]
material = "solid"
young = 1e6
poisson = 0.3
fix = ["bottom"]
mesh = {{ box = {{ origin = [0.0, 0.0, 0.0], size = [2.0, 1.0, 0.3], cells = [8, 4, 2] }} }}
{decomposition}
"#,
        stone_head()
    )
}

/// 3D rigid and deformable subdomains glued by the NSCDD stage (by model, by
/// geometry with the block copied in two subdomains, the centralized scheme)
/// agree with one domain to 1e-3 of the block's largest displacement (tolerance
/// 1e-7: the converged solutions differ by the solver's tolerance, not by the
/// decomposition); 1 and 2 threads are bitwise identical.
#[test]
fn coupled_3d_subdomains_agree_with_one_domain() {
    let run = |dec: &str, steps: usize| {
        let mut s = scene(&stacks(dec));
        let mut sweeps = Vec::new();
        for _ in 0..steps {
            let r = s.step().unwrap();
            assert!(r.solve.converged, "{dec}: {:?}", r.solve);
            sweeps.push(r.solve.sweeps);
        }
        (s.world.bodies.pos.clone(), s.fe.bodies[0].u.clone(), sweeps)
    };
    let (p0, u0, _) = run("", 30);
    let umax = u0.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    assert!(umax > 1e-5, "the block must deform: {umax}");
    for dec in [
        "[decomposition]\nby_model = true",
        "[decomposition]\nby_model = true\nnx = 2",
        "[decomposition]\nnx = 2",
        "[decomposition]\nby_model = true\nnx = 2\nscheme = \"centralized\"",
    ] {
        let (p1, u1, _) = run(dec, 30);
        let dp = p0
            .iter()
            .zip(&p1)
            .map(|(a, b)| (0..3).map(|k| (a[k] - b[k]).abs()).fold(0.0, f64::max))
            .fold(0.0, f64::max);
        let du = u0.iter().zip(&u1).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
        println!("{dec:?}: max |Δx| of spheres {dp:.3e} m, of the block {du:.3e} m (largest displacement {umax:.3e} m)");
        assert!(dp < 1e-3 * umax && du < 1e-3 * umax, "{dec}: {dp:e}, {du:e}");
    }
    let one = run("[decomposition]\nby_model = true\nnx = 2\nthreads = 1", 20);
    let two = run("[decomposition]\nby_model = true\nnx = 2\nthreads = 2", 20);
    assert_eq!(one, two);
}

/// The local problem of a coupled 3D step (`nscdd export-fc`): the spheres' contacts
/// and the block's, W with the block's G blocks and the couplings through the
/// spheres. At the impulses the step found, its natural-map residual is the step's.
#[test]
fn exported_coupled_3d_problem_is_the_solved_one() {
    let reg = registry();
    let mut s = nscdd::scene::Scene::<nscdd::dim::D3>::load_str(&stacks(""), "t.toml", &reg).unwrap();
    let mut res = 0.0;
    for _ in 0..10 {
        let mut fams: Vec<&mut dyn nscdd::family::SceneFamily<nscdd::dim::D3>> = s.families.iter_mut().map(|f| &mut **f).collect();
        res = nscdd::family::step(&mut s.world, &mut fams, None).unwrap().0.solve.residual;
    }
    let p = nscdd::family::local_problem(&s.world, &s.families).unwrap();
    let fe = nscdd_fem_deformable::family::of::<nscdd::dim::D3, nscdd_fem_deformable::stage3::Deformables3>(&s.families).unwrap();
    let (nw, nf) = (s.world.contacts.len(), fe.contacts.len());
    assert!(
        nw > 0 && nf > 0 && p.nc == nw + nf,
        "rigid {nw}, deformable {nf}, exported {}",
        p.nc
    );
    let r: Vec<f64> = s
        .world
        .contacts
        .r
        .iter()
        .flatten()
        .chain(fe.contacts.r.iter().flatten())
        .copied()
        .collect();
    let got = p.natural_residual(&r);
    println!("{nw} rigid and {nf} deformable contacts; residual of the exported problem {got:e}, of the step {res:e}");
    assert!(
        (got - res).abs() < 1e-9 + 1e-6 * res,
        "exported problem's residual {got:e}, the step's {res:e}"
    );
}
