//! Continuum regions glued to grains (docs/CONTINUUM.md): patch tests, the
//! partition of unity of the band's mass, subdomains against one domain.
mod common;

use common::continuum::Run;
use nscdd_fem_deformable::continuum::Continuum2;
use std::fmt::Write as _;

/// Disks of radius 0.02 on a lattice of spacing 0.05 (no contacts), x ∈ [0.05, 0.95],
/// y ∈ [y0, y1], each with the velocity `vel(x, y)`; a continuum region below
/// (mesh y ∈ [−0.4, 0.2], band from y = 0 (continuum) to 0.2 (discrete)).
fn lattice_scene(vel: &dyn Fn(f64, f64) -> [f64; 2], young: f64, extra: &str) -> String {
    let mut s = String::from(
        r#"
gravity = [0.0, 0.0]
[time]
step = 1e-3
theta = 0.5
steps = 1
[solver]
tolerance = 1e-10
max_sweeps = 10000
[[materials]]
name = "grain"
density = 2600.0
[[materials]]
name = "ground"
density = 1600.0
[[laws]]
materials = ["grain", "grain"]
friction = 0.5
"#,
    );
    for j in 0..8 {
        for i in 0..19 {
            let (x, y) = (0.05 + 0.05 * i as f64, 0.01 + 0.05 * j as f64);
            let v = vel(x, y);
            let _ = writeln!(
                s,
                "[[bodies]]\nshape = \"disk\"\nmaterial = \"grain\"\nradius = 0.02\nposition = [{x}, {y}]\nvelocity = [{}, {}, 0.0]",
                v[0], v[1]
            );
        }
    }
    let _ = write!(
        s,
        r#"
[[continuum]]
material = "ground"
young = {young}
poisson = 0.25
mesh = {{ rectangle = {{ origin = [0.0, -0.4], size = [1.0, 0.6], cells = [10, 12] }} }}
band = {{ normal = [0.0, 1.0], continuum = 0.0, discrete = 0.2 }}
{extra}
"#
    );
    s
}

#[test]
fn the_band_ties_its_grains_and_shares_their_mass() {
    let r = Run::new(&lattice_scene(&|_, _| [0.0, 0.0], 1e6, ""));
    let c = r.cont();
    // rows y = 0.01 … 0.16 lie in the band (0 < y < 0.2): 4 rows of 19
    assert_eq!(c.band.len(), 4 * 19);
    let m = 2600.0 * std::f64::consts::PI * 0.02 * 0.02;
    for &(g, w) in &c.band {
        let y = r.s.world.bodies.pos[g as usize][1];
        let wp = y / 0.2;
        assert!((w - wp).abs() < 1e-12);
        assert!((r.s.world.bodies.mass[g as usize] - wp * m).abs() < 1e-12 * m);
    }
    // one tie per band node holding grains (each grain to its cell's node of the
    // largest weight), the grains' sets disjoint and their c adding up to 1
    assert!(c.ties.len() > 20 && c.ties.len() <= 5 * 11, "{} ties", c.ties.len());
    let mut seen: Vec<u32> = c.ties.grain.clone();
    seen.sort_unstable();
    seen.dedup();
    assert_eq!(seen.len(), c.ties.grain.len());
    assert_eq!(seen.len(), c.band.len());
    for a in 0..c.ties.len() {
        let s: f64 = c.ties.c[c.ties.grains(a)].iter().sum();
        let b: f64 = c.ties.b[c.ties.nodes(a)].iter().sum();
        assert!((s - 1.0).abs() < 1e-12 && (b - 1.0).abs() < 1e-12);
    }
}

/// `band.grain_share = 0.25`: a band grain keeps at least a quarter of its mass
/// (w_p = max(y/0.2, 0.25)), the continuum's weight is at most 0.75 inside the
/// band (its cells' weights too: the partition of unity holds), 1 beyond it; a
/// uniform translation still passes with no force; a share outside [0, 1) is
/// refused naming the key.
#[test]
fn a_grain_share_keeps_a_least_share_of_the_band_grains_mass() {
    let v0 = [0.3, -0.1];
    let text = lattice_scene(&|_, _| v0, 1e6, &format!("velocity = [{}, {}]", v0[0], v0[1]))
        .replace("discrete = 0.2 }", "discrete = 0.2, grain_share = 0.25 }");
    let mut r = Run::new(&text);
    let c = r.cont();
    let m = 2600.0 * std::f64::consts::PI * 0.02 * 0.02;
    assert_eq!(c.band.len(), 4 * 19);
    for &(g, w) in &c.band {
        let y = r.s.world.bodies.pos[g as usize][1];
        let wp = (y / 0.2).max(0.25);
        assert!((w - wp).abs() < 1e-12, "y {y}: share {w}");
        assert!((r.s.world.bodies.mass[g as usize] - wp * m).abs() < 1e-12 * m);
        assert!((c.bands[0].alpha(&[0.5, y]) + wp - 1.0).abs() < 1e-12);
    }
    assert_eq!(c.bands[0].alpha(&[0.5, -0.1]), 1.0);
    assert_eq!(c.bands[0].alpha(&[0.5, 0.01]), 0.75);
    for _ in 0..20 {
        assert!(r.step().solve.converged);
    }
    let c = r.cont();
    let lam = c.ties.r.iter().flatten().fold(0.0f64, |m, x| m.max(x.abs()));
    assert!(lam < 1e-9 * m * 0.3, "largest tie impulse {lam:e}");
    for share in ["1.0", "-0.1"] {
        let bad = text.replace("grain_share = 0.25", &format!("grain_share = {share}"));
        let e = nscdd::scene::Scene::<nscdd::dim::D2>::load_str(&bad, "bad.toml", &common::registry())
            .err()
            .expect("refused");
        assert_eq!(e.key, "continuum[0].band", "{e}");
        assert!(e.to_string().contains("grain_share"), "{e}");
    }
}

#[test]
fn a_uniform_translation_passes_the_band_with_no_force() {
    let v0 = [0.3, -0.1];
    let mut r = Run::new(&lattice_scene(&|_, _| v0, 1e6, &format!("velocity = [{}, {}]", v0[0], v0[1])));
    let x0: Vec<[f64; 2]> = r.s.world.bodies.pos.clone();
    for _ in 0..50 {
        let rep = r.step();
        assert!(rep.solve.converged);
    }
    let c = r.cont();
    let lam = c.ties.r.iter().flatten().fold(0.0f64, |m, x| m.max(x.abs()));
    // against a grain's momentum m|v0| ≈ 1 N·s (per unit depth): rounding (K of a
    // uniform translation is 0 up to E·u·ε)
    let mv = 2600.0 * std::f64::consts::PI * 0.02 * 0.02 * (v0[0] * v0[0] + v0[1] * v0[1]).sqrt();
    assert!(lam < 1e-9 * mv, "largest tie impulse {lam:e} against m v = {mv:e}");
    let t = 50.0 * 1e-3;
    for (g, p) in r.s.world.bodies.pos.iter().enumerate() {
        for d in 0..2 {
            assert!((p[d] - x0[g][d] - v0[d] * t).abs() < 1e-11, "grain {g}");
        }
    }
    for (k, u) in c.bodies[0].u.chunks_exact(2).enumerate() {
        assert!(
            (u[0] - v0[0] * t).abs() < 1e-11 && (u[1] - v0[1] * t).abs() < 1e-11,
            "node {k}: {u:?}"
        );
    }
}

#[test]
fn a_uniform_strain_rate_passes_the_band_with_no_force() {
    // v = L x (shear and stretch), the continuum without stress yet (E small: the
    // step's h²θ²K is 1e-12 of M): the ties must hold with no impulse, the
    // grains and the material points following the affine field
    let l = [[0.2, 0.5], [-0.1, -0.3]];
    let vel = move |x: f64, y: f64| [l[0][0] * x + l[0][1] * y, l[1][0] * x + l[1][1] * y];
    let text = lattice_scene(&vel, 1e-3, "");
    let mut r = Run::new(&text);
    // the region's nodes start on the same field
    {
        let c = r.s.families[0].as_any_mut().downcast_mut::<Continuum2>().unwrap();
        let b = &mut c.bodies[0];
        for k in 0..b.mesh.n_nodes() {
            let x = b.mesh.node(k).to_vec();
            let v = vel(x[0], x[1]);
            b.v[2 * k] = v[0];
            b.v[2 * k + 1] = v[1];
        }
    }
    let rep = r.step();
    assert!(rep.solve.converged);
    let c = r.cont();
    let m = 2600.0 * std::f64::consts::PI * 0.02 * 0.02;
    let vmax = 0.5;
    let lam = c.ties.r.iter().flatten().fold(0.0f64, |a, x| a.max(x.abs()));
    assert!(lam < 1e-9 * m * vmax, "largest tie impulse {lam:e} against m v = {:e}", m * vmax);
    for &g in &c.ties.grain {
        let p = r.s.world.bodies.pos[g as usize];
        let v = r.s.world.bodies.vel[g as usize];
        // the grain moved with the field: V⁺ = V⁻ (no force), x⁺ = x⁻ + h V
        let x0 = [p[0] - 1e-3 * v[0], p[1] - 1e-3 * v[1]];
        let want = vel(x0[0], x0[1]);
        assert!(
            (v[0] - want[0]).abs() < 1e-9 && (v[1] - want[1]).abs() < 1e-9,
            "grain {g}: {v:?} vs {want:?}"
        );
    }
}

/// The time, solver, materials and law of the gravity scenes below.
fn header(theta: f64, tol: f64) -> String {
    format!(
        "[time]\nstep = 2e-3\ntheta = {theta}\nsteps = 1\n[solver]\ntolerance = {tol}\nmax_sweeps = 100000\n\
         [[materials]]\nname = \"grain\"\ndensity = 2600.0\n[[materials]]\nname = \"ground\"\ndensity = 1600.0\n\
         [[laws]]\nmaterials = [\"grain\", \"grain\"]\nfriction = 0.5\n"
    )
}

/// The foundation under them: 1 × 0.6 m held at its base, the band 0 < y < 0.2.
fn foundation(young: f64, extra: &str) -> String {
    format!(
        "[[continuum]]\nmaterial = \"ground\"\nyoung = {young}\npoisson = 0.25\nfix = [\"bottom\"]\n\
         mesh = {{ rectangle = {{ origin = [0.0, -0.4], size = [1.0, 0.6], cells = [10, 12] }} }}\n\
         band = {{ normal = [0.0, 1.0], continuum = 0.0, discrete = 0.2 }}\n{extra}\n"
    )
}

/// Columns of four touching disks (radius 0.025, 0.1 apart) in the band of a
/// continuum foundation held at its base, under gravity, all tied.
fn columns_scene(theta: f64, extra: &str) -> String {
    let mut s = header(theta, 1e-8);
    for j in 0..4 {
        for i in 0..10 {
            let (x, y) = (0.05 + 0.1 * i as f64, 0.025 + 0.05 * j as f64);
            let _ = writeln!(
                s,
                "[[bodies]]\nshape = \"disk\"\nmaterial = \"grain\"\nradius = 0.025\nposition = [{x}, {y}]"
            );
        }
    }
    s + &foundation(2e6, extra)
}

/// A hexagonal packing of touching disks (radius 0.025) on a continuum foundation
/// held at its base, under gravity: rows 0–4 in the band (tied), rows 5–7 above it,
/// each one grain shorter at both ends (every grain rests on two).
fn hex_scene(theta: f64, young: f64, tol: f64) -> String {
    let mut s = header(theta, tol).replace("max_sweeps = 100000", "max_sweeps = 20000");
    let dy = 0.05 * 3f64.sqrt() / 2.0;
    for j in 0..8usize {
        let odd = j % 2;
        let trim = j.saturating_sub(4);
        for i in trim..(19 - odd - trim) {
            let (x, y) = (0.05 + 0.025 * odd as f64 + 0.05 * i as f64, 0.025 + dy * j as f64);
            let _ = writeln!(
                s,
                "[[bodies]]\nshape = \"disk\"\nmaterial = \"grain\"\nradius = 0.025\nposition = [{x}, {y}]"
            );
        }
    }
    s + &foundation(young, "")
}

/// Σ of the vertical reactions at the region's held nodes: (K u − F_ext)_y there
/// (the static balance of the held degrees of freedom).
fn base_reaction(c: &Continuum2) -> f64 {
    let b = &c.bodies[0];
    let mut f: Vec<f64> = b.f_ext.iter().map(|x| -x).collect();
    b.mul_add(0.0, 1.0, &b.u, &mut f);
    (0..b.mesh.n_nodes()).filter(|&k| b.fixed[2 * k + 1]).map(|k| f[2 * k + 1]).sum()
}

#[test]
fn the_foundation_carries_the_grains_weight() {
    let mut r = Run::new(&columns_scene(1.0, "rayleigh = [60.0, 0.0]"));
    for _ in 0..400 {
        let rep = r.step();
        assert!(rep.solve.converged);
    }
    let c = r.cont();
    let g = 9.81;
    let grains: f64 = r.s.world.bodies.mass.iter().sum::<f64>() * g;
    let ground = c.bodies[0].f_ext.iter().skip(1).step_by(2).map(|f| -f).sum::<f64>();
    let weight = grains + ground;
    let reaction = base_reaction(c);
    println!("weight {weight:.3} N (grains {grains:.3}, ground {ground:.3}), base reaction {reaction:.3} N");
    assert!((reaction - weight).abs() < 1e-3 * weight, "reaction {reaction} vs weight {weight}");
    // the ties hold the band's grains on their material points
    let t = &c.ties;
    let gap = (0..t.len()).fold(0.0f64, |m, a| {
        let b = &c.bodies[0];
        let mut x = [0.0; 2];
        for i in t.grains(a) {
            let p = r.s.world.bodies.pos[t.grain[i] as usize];
            x[0] += t.c[i] * p[0];
            x[1] += t.c[i] * p[1];
        }
        for j in t.nodes(a) {
            let p = b.position(c.sets[0].nodes[t.node[j] as usize] as usize);
            x[0] -= t.b[j] * p[0];
            x[1] -= t.b[j] * p[1];
        }
        m.max(x[0].abs()).max(x[1].abs())
    });
    assert!(gap < 1e-9, "largest tie gap {gap:e} m");
}

fn final_positions(text: &str, steps: usize) -> (Vec<[f64; 2]>, Vec<f64>, u64) {
    let mut r = Run::new(text);
    let mut sweeps = 0;
    for _ in 0..steps {
        let rep = r.step();
        assert!(rep.solve.converged, "{:?}", rep.solve);
        sweeps += rep.solve.sweeps as u64;
    }
    (r.s.world.bodies.pos.clone(), r.cont().bodies[0].u.clone(), sweeps)
}

#[test]
fn subdomains_agree_with_one_domain() {
    let (p0, u0, _) = final_positions(&columns_scene(0.5, ""), 40);
    let umax = u0.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    assert!(umax > 1e-6, "the foundation must deform: {umax}");
    for dec in [
        "[decomposition]\nnx = 2",
        "[decomposition]\nby_model = true",
        "[decomposition]\nby_model = true\nnx = 2\nny = 2",
    ] {
        let (p, u, _) = final_positions(&columns_scene(0.5, dec), 40);
        let dp = p
            .iter()
            .zip(&p0)
            .fold(0.0f64, |m, (a, b)| m.max((a[0] - b[0]).abs()).max((a[1] - b[1]).abs()));
        let du = u.iter().zip(&u0).fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
        println!("{dec:?}: grains {dp:e} m, foundation {du:e} m (largest displacement {umax:e})");
        assert!(dp < 1e-3 * umax && du < 1e-3 * umax, "{dec}: {dp:e}, {du:e}");
    }
}

#[test]
fn threads_are_bitwise_identical() {
    let run = |threads: u32| {
        final_positions(
            &columns_scene(0.5, &format!("[decomposition]\nby_model = true\nnx = 2\nthreads = {threads}")),
            20,
        )
    };
    let (p1, u1, s1) = run(1);
    let (p2, u2, s2) = run(2);
    assert_eq!(s1, s2);
    assert!(p1 == p2 && u1 == u2, "threads changed the result");
}

/// A dense (hexagonal) packing half in the band, half above it: NLGS converges at
/// the usual tolerance in all but at most one of 30 steps (the rigid grains'
/// contacts and the ties are redundant, and NLGS cycles on some steps: measured 1
/// unconverged step in 100, at step 29; the same packing on a deformable body
/// through contacts fails 5 of 30 steps, docs/CONTINUUM.md), and the failure is
/// reported.
#[test]
fn a_dense_packing_on_the_band_converges() {
    let text = hex_scene(0.5, 2e6, 1.666e-4);
    let mut r = Run::new(&text);
    let mut failed = vec![];
    for k in 0..30 {
        let rep = r.step();
        println!("step {k}: {} sweeps", rep.solve.sweeps);
        if !rep.solve.converged {
            assert_eq!(rep.solve.sweeps, 20000, "a failure is reported after the cap");
            failed.push(k);
        }
    }
    assert!(failed.len() <= 1, "unconverged steps {failed:?}");
}
