//! Subdomains by model against one domain, and stability at the extremes.
mod common;
use common::*;

/// Disks resting on a deformable foundation block (fixed at its base): two stacks
/// of two disks; the lower disks touch the block (deformable contacts) and the
/// upper disks (rigid contacts).
fn foundation(decomposition: &str, tol: f64) -> String {
    format!(
        r#"
[time]
step = 1e-3
theta = 0.5
steps = 1
[solver]
tolerance = {tol}
max_sweeps = 100000
[detection]
alert = 0.01
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
[[bodies]]
shape = "disk"
material = "stone"
radius = 0.1
position = [0.3, 0.6]
[[bodies]]
shape = "disk"
material = "stone"
radius = 0.1
position = [0.3, 0.8]
[[bodies]]
shape = "disk"
material = "stone"
radius = 0.1
position = [1.7, 0.6]
[[bodies]]
shape = "disk"
material = "stone"
radius = 0.1
position = [1.71, 0.8]
[[deformable]]
material = "soil"
young = 1e6
poisson = 0.3
fix = ["bottom"]
mesh = {{ rectangle = {{ origin = [0.0, 0.0], size = [2.0, 0.5], cells = [20, 5] }} }}
{decomposition}
"#
    )
}

fn run(text: &str, steps: usize) -> (Vec<[f64; 2]>, Vec<f64>) {
    let mut s = scene(text);
    for _ in 0..steps {
        let rep = s.step().unwrap();
        assert!(rep.solve.converged, "{:?}", rep.solve);
    }
    (s.world.bodies.pos.clone(), s.fe.bodies[0].u.clone())
}

#[test]
fn by_model_subdomains_agree_with_one_domain() {
    let tol = 1e-8;
    let (p0, u0) = run(&foundation("", tol), 60);
    let umax = u0.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    println!("one domain: disks {p0:?}, umax {umax:e}");
    assert!(umax > 1e-5, "the block must deform: {umax}");
    for dec in [
        "[decomposition]\nby_model = true",
        "[decomposition]\nby_model = true\nnx = 2",
        "[decomposition]\nnx = 2",
        "[decomposition]\nby_model = true\nnx = 2\nscheme = \"centralized\"",
        "[decomposition]\nby_model = true\nnx = 2\nsweeps_per_gluing = 3\nrepartition_every = 5",
    ] {
        let mut s = scene(&foundation(dec, tol));
        let mut ifaces = 0;
        for _ in 0..60 {
            assert!(s.step().unwrap().solve.converged);
            ifaces = ifaces.max(s.world.contacts.len());
        }
        let (p1, u1) = (s.world.bodies.pos.clone(), s.fe.bodies[0].u.clone());
        let dp = p0
            .iter()
            .zip(&p1)
            .map(|(a, b)| (a[0] - b[0]).hypot(a[1] - b[1]))
            .fold(0.0, f64::max);
        let du = u0.iter().zip(&u1).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
        println!("{dec:?}: max |Δx| of disks {dp:.3e} m, of the block {du:.3e} m (largest displacement {umax:.3e} m)");
        assert!(ifaces > 0);
        assert!(
            dp < 1e-3 * umax && du < 1e-3 * umax,
            "by model differs from one domain: {dp:e}, {du:e}"
        );
    }
}

/// A block dropped on a floor, for the extremes: E, h, ν and θ.
fn drop(young: f64, step: f64, nu: f64, theta: f64, max_sweeps: u32) -> (Vec<f64>, bool) {
    let text = format!(
        r#"
[time]
step = {step}
theta = {theta}
steps = 1
[solver]
tolerance = 1e-5
max_sweeps = {max_sweeps}
[detection]
alert = 0.01
[[materials]]
name = "m"
density = 1000.0
[[materials]]
name = "g"
density = 1.0
[[laws]]
materials = ["m", "g"]
friction = 0.3
[[bodies]]
shape = "halfplane"
material = "g"
position = [0.0, 0.0]
fixed = true
[[deformable]]
material = "m"
young = {young}
poisson = {nu}
velocity = [0.1, -0.5]
mesh = {{ rectangle = {{ origin = [0.0, 0.001], size = [0.4, 0.2], cells = [8, 4] }} }}
"#
    );
    let mut s = scene(&text);
    let mut e = vec![fe_energy(&s)];
    let mut all = true;
    for _ in 0..40 {
        let rep = s.step().unwrap();
        all &= rep.solve.converged;
        e.push(fe_energy(&s));
    }
    (e, all)
}

#[test]
fn extremes_stay_finite_and_do_not_gain_energy() {
    for young in [1e3, 1e6, 1e9, 1e12] {
        for theta in [0.5, 0.75, 1.0] {
            let (e, conv) = drop(young, 1e-3, 0.3, theta, 100000);
            assert!(conv, "E {young} θ {theta}: unconverged");
            assert!(e.iter().all(|x| x.is_finite()), "E {young}: non-finite energy");
            let scale = e[0].abs().max(1e-12);
            assert!(
                e.iter().all(|&x| x <= e[0] + 1e-6 * scale),
                "E {young} θ {theta}: energy grew {e:?}"
            );
        }
    }
    for step in [1e-6, 1e-4, 1e-2] {
        let (e, conv) = drop(1e7, step, 0.49, 0.5, 100000);
        assert!(conv, "h {step}: unconverged");
        let scale = e[0].abs().max(1e-12);
        assert!(
            e.iter().all(|&x| x.is_finite() && x <= e[0] + 1e-6 * scale),
            "h {step} ν 0.49: {e:?}"
        );
    }
}

#[test]
fn non_convergence_is_reported() {
    let (_, conv) = drop(1e7, 1e-2, 0.3, 0.5, 1);
    assert!(!conv, "one sweep cannot meet 1e-5 with a block landing on its base");
}

/// The framework's run loop with the deformable family: a run stopped at step 20
/// (its final.json, with the family's state) and restarted to step 40 ends bitwise
/// where the uninterrupted run does, in one domain and by model on 2 subdomains; a
/// checkpoint is written with the family's state.
#[test]
fn restart_continues_bitwise() {
    let reg = registry();
    let dir = std::env::temp_dir().join(format!("nscdd-fe-restart-{}", std::process::id()));
    for (k, dec) in ["", "[decomposition]\nby_model = true\nnx = 2"].into_iter().enumerate() {
        let text = |steps: u32, every: u32| {
            foundation(dec, 1e-8).replace("steps = 1", &format!("steps = {steps}"))
                + &format!("[output]\nvtk = false\ncheckpoint_every = {every}\n")
        };
        let run = |t: &str, out: &str, from: Option<&std::path::Path>| {
            let mut s = nscdd::scene::Scene::<nscdd::dim::D2>::load_str(t, "t.toml", &reg).unwrap();
            if let Some(f) = from {
                nscdd::scene::restart_scene(&mut s, f).unwrap();
            }
            nscdd::run::run(&mut s, &reg, &dir.join(format!("{k}{out}")), |_, _| {}).unwrap();
            std::fs::read_to_string(dir.join(format!("{k}{out}")).join("final.json")).unwrap()
        };
        let whole = run(&text(40, 10), "whole", None);
        assert!(whole.contains("\"families\""), "the family's state is saved");
        let ck = std::fs::read_to_string(dir.join(format!("{k}whole")).join("checkpoint.json")).unwrap();
        assert!(ck.contains("\"displacement\""), "the checkpoint holds the family's state");
        run(&text(20, 0), "first", None);
        let second = run(&text(40, 0), "second", Some(&dir.join(format!("{k}first")).join("final.json")));
        assert!(second == whole, "restart of `{dec}` is not bitwise");
    }
    // a state of a scene without deformable bodies: refused, naming the key
    let mut s = nscdd::scene::Scene::<nscdd::dim::D2>::load_str(&foundation("", 1e-8), "t.toml", &reg).unwrap();
    let rigid = dir.join("rigid.json");
    std::fs::write(&rigid, nscdd::output::final_json(&s.world)).unwrap();
    let e = nscdd::scene::restart_scene(&mut s, &rigid).unwrap_err();
    assert_eq!(e.key, "families.deformable", "{e}");
    std::fs::remove_dir_all(&dir).ok();
}

/// The coupled scene on 1 and 2 threads: bitwise the same (subdomains are swept
/// and glued in parallel, every reduction in subdomain order).
#[test]
fn coupled_threads_are_bitwise_identical() {
    let run = |threads: u32| {
        let dec = format!("[decomposition]\nby_model = true\nnx = 2\nthreads = {threads}");
        let mut s = scene(&foundation(&dec, 1e-8));
        let mut sweeps = Vec::new();
        for _ in 0..30 {
            sweeps.push(s.step().unwrap().solve.sweeps);
        }
        (
            s.world.bodies.pos.clone(),
            s.world.bodies.vel.clone(),
            s.fe.bodies[0].u.clone(),
            sweeps,
        )
    };
    let (a, b) = (run(1), run(2));
    assert_eq!(a, b);
}

/// The local problem of a coupled step (`nscdd export-fc`): the world's contacts and
/// the deformable ones, W = Hᵀ M̂⁻¹ H with the blocks G among the soil's contact
/// nodes and the couplings through the disks they share. At the impulses the step
/// found, its natural-map residual is the step's own (the same W and q the solve
/// used), W is symmetric, and the deformable contacts' diagonal blocks are the
/// solve's W_αα.
#[test]
fn exported_coupled_problem_is_the_solved_one() {
    let reg = registry();
    let mut s = nscdd::scene::Scene::<nscdd::dim::D2>::load_str(&foundation("", 1e-10), "t.toml", &reg).unwrap();
    let mut res = 0.0;
    for _ in 0..5 {
        let mut fams: Vec<&mut dyn nscdd::family::SceneFamily<nscdd::dim::D2>> = s.families.iter_mut().map(|f| &mut **f).collect();
        let (r, _) = nscdd::family::step(&mut s.world, &mut fams, None).unwrap();
        res = r.solve.residual;
    }
    let p = nscdd::family::local_problem(&s.world, &s.families).unwrap();
    let fe = nscdd_fem_deformable::family::of::<nscdd::dim::D2, nscdd_fem_deformable::stage2::Deformables2>(&s.families).unwrap();
    let (nw, nf) = (s.world.contacts.len(), fe.contacts.len());
    assert!(nw > 0 && nf > 0, "rigid {nw} and deformable {nf} contacts");
    assert_eq!(p.nc, nw + nf);
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
    // symmetric, and the deformable diagonal blocks are the solve's
    let mut w = std::collections::BTreeMap::new();
    for k in 0..p.w.rows.len() {
        *w.entry((p.w.rows[k], p.w.cols[k])).or_insert(0.0) += p.w.vals[k];
    }
    for (&(i, j), v) in &w {
        let t = w.get(&(j, i)).copied().unwrap_or(0.0);
        assert!((v - t).abs() <= 1e-12 * v.abs().max(1.0), "W[{i},{j}] = {v}, W[{j},{i}] = {t}");
    }
    for a in 0..nf {
        let k = 2 * (nw + a);
        let b = fe.contacts.block[a].w;
        let e = [w[&(k, k)], w[&(k, k + 1)], w[&(k + 1, k + 1)]];
        for q in 0..3 {
            assert!(
                (e[q] - b[q]).abs() <= 1e-12 * b[0].abs(),
                "contact {a}: W_αα {e:?}, the solve's {b:?}"
            );
        }
    }
}

/// A block fixed at its base, which lies within the alert distance of a fixed
/// floor, under a disk: the base's contacts with the floor cannot move (both
/// sides fixed) and are dropped at detection, so the block's node set holds the
/// disk's contact nodes only (the set a rank stepping the block fills from its
/// own contacts, whatever rank detects the base's).
#[test]
fn contacts_of_two_fixed_sides_are_dropped_at_detection() {
    let text = r#"
[time]
step = 1e-3
steps = 1
[solver]
tolerance = 1e-8
max_sweeps = 10000
[detection]
alert = 0.01
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
friction = 0.5
[[bodies]]
shape = "halfplane"
material = "stone"
position = [0.0, 0.0]
fixed = true
[[bodies]]
shape = "disk"
material = "stone"
radius = 0.1
position = [0.5, 0.6005]
[[deformable]]
material = "soil"
young = 1e6
poisson = 0.3
fix = ["bottom"]
mesh = { rectangle = { origin = [0.0, 0.001], size = [1.0, 0.5], cells = [10, 5] } }
"#;
    let mut s = scene(text);
    let rep = s.step().unwrap();
    assert!(rep.solve.converged);
    let body = &s.fe.bodies[0];
    let y = |k: u32| body.mesh.x0[2 * k as usize + 1];
    let nodes = &s.fe.sets[0].nodes;
    assert!(!nodes.is_empty(), "the disk's contact nodes");
    assert!(nodes.iter().all(|&k| y(k) > 0.4), "only the top's nodes: {nodes:?}");
    assert_eq!(s.fe.contacts.len(), nodes.len());
}
