//! A continuum region alone (its band far from any grain, docs/CONTINUUM.md):
//! Drucker–Prager flow and friction hardening, driven and loaded sides, an
//! initial stress, rollers.
mod common;

use common::continuum::Run;
use common::registry;
use nscdd::scene::Scene;
use nscdd_fem_deformable::continuum::Continuum2;

/// A block of the continuum alone (its band far above), held at its base, under
/// gravity, 1 m wide and 0.5 m high.
fn block_scene(plastic: &str) -> String {
    format!(
        r#"
[time]
step = 2e-3
theta = 1.0
steps = 1
[[materials]]
name = "ground"
density = 1600.0
[[continuum]]
material = "ground"
young = 1e6
poisson = 0.3
fix = ["bottom"]
mesh = {{ rectangle = {{ origin = [0.0, 0.0], size = [1.0, 0.5], cells = [20, 10] }} }}
band = {{ normal = [0.0, 1.0], continuum = 10.0, discrete = 11.0 }}
{plastic}
"#
    )
}

/// The scene `text` run 100 steps, and its region's largest displacement.
fn run_still(text: &str) -> (Run, f64) {
    let mut r = Run::new(text);
    for _ in 0..100 {
        r.step();
    }
    let u = r.cont().bodies[0].u.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    (r, u)
}

/// The load error of the block scene with `extra`.
fn refused(extra: &str) -> nscdd::error::InputError {
    Scene::<nscdd::dim::D2>::load_str(&block_scene(extra), "t.toml", &registry())
        .err()
        .expect("refused")
}

fn largest_horizontal(c: &Continuum2) -> f64 {
    c.bodies[0].u.iter().step_by(2).fold(0.0f64, |m, x| m.max(x.abs()))
}

#[test]
fn a_cohesionless_block_flows_where_an_elastic_one_stands() {
    let run = |plastic: &str, steps: usize| {
        let mut r = Run::new(&block_scene(plastic));
        let mut u = vec![];
        for _ in 0..steps {
            r.step();
            u.push(largest_horizontal(r.cont()));
        }
        (r, u)
    };
    let (el, ue) = run("", 300);
    let (dp, ud) = run("plastic = { friction = 30.0 }", 300);
    let (coh, uc) = run("plastic = { friction = 30.0, cohesion = 1e6 }", 300);
    println!(
        "largest horizontal displacement after 0.2, 0.4, 0.6 s: elastic {:.2e} {:.2e} {:.2e}, cohesionless {:.2e} {:.2e} {:.2e}",
        ue[99], ue[199], ue[299], ud[99], ud[199], ud[299]
    );
    // the elastic block (and the strongly cohesive one: bitwise the same, f_p = 0) stands
    assert_eq!(ue, uc);
    // (its oscillation about the static state, ≈ 6e-4 m, decays)
    let late = ue[200..].iter().fold(0.0f64, |m, &x| m.max(x));
    assert!(late < 1e-3, "the elastic block must stand: {late:e}");
    assert_eq!(coh.cont().plastic[0].as_ref().unwrap().yielding, 0);
    // the cohesionless one keeps spreading, far past the elastic displacement
    let p = dp.cont().plastic[0].as_ref().unwrap();
    assert!(p.yielding > 0);
    assert!(ud[299] > 50.0 * late && ud[299] > ud[199] * 1.2, "{:?}", &ud[199..]);
    // every cell's stress lies on or inside the cone
    for s in &p.sigma {
        let pr = (s[0][0] + s[1][1] + s[2][2]) / 3.0;
        let j2: f64 = 0.5
            * (0..3)
                .flat_map(|a| (0..3).map(move |b| (a, b)))
                .map(|(a, b)| (s[a][b] - if a == b { pr } else { 0.0 }).powi(2))
                .sum::<f64>();
        let f = j2.sqrt() + p.eta * pr - p.xi * p.cohesion;
        assert!(f <= 1e-9 * (pr.abs() + 1.0), "f = {f}");
    }
    let _ = el;
}

/// Friction hardening: hardened from the start it is the perfectly plastic block;
/// from a lower angle it yields more, each cell on the cone of its own κ; κ is
/// saved, so a restart continues bitwise.
#[test]
fn a_hardening_block_mobilizes_its_friction_and_restarts_with_it() {
    let run = |plastic: &str, steps: usize| {
        let mut r = Run::new(&block_scene(plastic));
        for _ in 0..steps {
            r.step();
        }
        r
    };
    let pp = run("plastic = { friction = 30.0 }", 150);
    let same = run(
        "plastic = { friction = 30.0, initial_friction = 30.0, hardening_strain = 0.01 }",
        150,
    );
    let scale = largest_horizontal(pp.cont());
    let diff = pp.cont().bodies[0]
        .u
        .iter()
        .zip(&same.cont().bodies[0].u)
        .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
    assert!(diff < 1e-8 * scale, "{diff:e} against {scale:e}");
    let soft = "plastic = { friction = 30.0, initial_friction = 10.0, hardening_strain = 0.05 }";
    let h = run(soft, 150);
    let p = h.cont().plastic[0].as_ref().unwrap();
    let hard = p.hardening.unwrap();
    println!(
        "largest horizontal displacement at 0.3 s: perfectly plastic {scale:.3e}, hardening {:.3e}",
        largest_horizontal(h.cont())
    );
    assert!(largest_horizontal(h.cont()) > 1.1 * scale);
    assert!(p.kappa.iter().any(|&k| k > 0.0) && p.kappa.iter().all(|&k| k >= 0.0));
    for (s, &k) in p.sigma.iter().zip(&p.kappa) {
        let sin = hard.sin0 + (hard.sin_peak - hard.sin0) * k / (k + hard.kappa_h);
        let t = sin.asin().tan();
        let den = (9.0 + 12.0 * t * t).sqrt();
        let pr = (s[0][0] + s[1][1] + s[2][2]) / 3.0;
        let j2: f64 = 0.5
            * (0..3)
                .flat_map(|a| (0..3).map(move |b| (a, b)))
                .map(|(a, b)| (s[a][b] - if a == b { pr } else { 0.0 }).powi(2))
                .sum::<f64>();
        let f = j2.sqrt() + 3.0 * t / den * pr;
        assert!(f <= 1e-8 * (pr.abs() + 1.0), "f = {f}");
    }
    // a restart at step 75 continues bitwise
    let mut a = run(soft, 75);
    let state = a.s.families[0].save_state();
    let mut b = Run::new(&block_scene(soft));
    b.s.families[0].load_state(&state).unwrap();
    for _ in 0..75 {
        a.step();
        b.step();
    }
    assert_eq!(a.cont().bodies[0].u, h.cont().bodies[0].u);
    assert_eq!(b.cont().bodies[0].u, h.cont().bodies[0].u);
    assert_eq!(b.cont().plastic[0].as_ref().unwrap().kappa, p.kappa);
}

/// Sides: a traction adds its resultant to F_ext, a driven side moves at its
/// velocity, and the driven sides' reactions balance the weight once at rest.
#[test]
fn driven_and_loaded_sides() {
    let text = block_scene("").replace(
        "fix = [\"bottom\"]",
        "drive = { bottom = [0.0, 0.0], top = [0.0, -0.002] }\nload = { left = [2000.0, 0.0], right = [-2000.0, 0.0] }\nrayleigh = [60.0, 0.0]",
    );
    let mut r = Run::new(&text);
    {
        let b = &r.cont().bodies[0];
        let left: f64 = (0..b.mesh.n_nodes())
            .filter(|&k| b.mesh.node(k)[0] < 1e-9)
            .map(|k| b.f_ext[2 * k])
            .sum();
        // 2 kPa on a 0.5 m side, its held corner nodes' shares included
        assert!((left - 2000.0 * 0.5).abs() < 1e-9, "{left}");
    }
    for _ in 0..400 {
        r.step();
    }
    let c = r.cont();
    let b = &c.bodies[0];
    let top = b.mesh.n_nodes() - 1;
    assert!((b.u[2 * top + 1] + 0.002 * 0.8).abs() < 1e-12, "the top moved {}", b.u[2 * top + 1]);
    let weight: f64 = -b.f_ext.iter().skip(1).step_by(2).sum::<f64>();
    let bottom = nscdd_fem_deformable::continuum::sides::reaction(b, &c.driven[0][0]);
    let top = nscdd_fem_deformable::continuum::sides::reaction(b, &c.driven[0][1]);
    // the mass-proportional damping's drag on the free nodes, α M V (the block is
    // being compressed: its nodes move down)
    let mut cv = vec![0.0; b.n_dofs()];
    b.mul_add(60.0, 0.0, &b.v, &mut cv);
    let drag: f64 = (1..b.n_dofs()).step_by(2).filter(|&i| !b.fixed[i]).map(|i| cv[i]).sum();
    println!("weight {weight:.2} N/m, drag {drag:.2}, reactions bottom {bottom:?}, top {top:?}");
    assert!((bottom[1] + top[1] - weight - drag).abs() < 1e-3 * weight, "vertical balance");
    assert!((bottom[0] + top[0]).abs() < 1e-3 * weight, "horizontal balance");
    // compressed: the top pushes down on the block
    assert!(top[1] < 0.0);
}

/// A side loaded, then driven from `drive_from` (every driven side of the entry
/// starts then): at the switch it is held, its traction taken off F_ext, and its
/// reaction takes over the load it carried.
#[test]
fn a_side_loaded_then_driven() {
    let text = block_scene("").replace(
        "fix = [\"bottom\"]",
        "fix = [\"bottom\"]\ndrive = { top = [0.0, 0.0] }\ndrive_from = 0.4\nload = { top = [0.0, -2000.0] }\nrayleigh = [60.0, 0.0]",
    );
    let mut r = Run::new(&text);
    for _ in 0..199 {
        r.step();
    }
    // t = 0.398 s: the top is still free under its load
    assert!(!r.cont().driven[0][0].held);
    for _ in 0..201 {
        r.step();
    }
    let c = r.cont();
    let b = &c.bodies[0];
    assert!(c.driven[0][0].held);
    let top_r = nscdd_fem_deformable::continuum::sides::reaction(b, &c.driven[0][0]);
    println!("reaction of the held top {top_r:?}");
    // the held top now carries the 2 kPa × 1 m it was loaded with (the block near rest)
    assert!((top_r[1] + 2000.0).abs() < 0.05 * 2000.0, "{top_r:?}");
    assert!(top_r[0].abs() < 0.01 * 2000.0);
}

/// `initial_stress`: a block under an isotropic 10 kPa on its four sides stands
/// still when it starts at that stress (elastic or Drucker–Prager, which then
/// never yields: σ_zz = ν (σ_xx + σ_yy) keeps it inside the cone), and is
/// compressed by σ/E without it.
#[test]
fn an_initial_stress_balances_the_sides_loads() {
    let loads = "load = { left = [1e4, 0.0], right = [-1e4, 0.0], top = [0.0, -1e4], bottom = [0.0, 1e4] }";
    let run = |extra: &str| {
        run_still(&format!(
            "gravity = [0.0, 0.0]\n{}",
            block_scene(&format!("{loads}\n{extra}")).replace("fix = [\"bottom\"]\n", "")
        ))
    };
    let (_, free) = run("");
    let (_, held) = run("initial_stress = [-1e4, -1e4, 0.0]");
    let (dp, held_dp) = run("initial_stress = [-1e4, -1e4, 0.0]\nplastic = { friction = 16.5, dilatancy = 4.0 }");
    println!("largest displacement: no initial stress {free:.3e}, elastic {held:.3e}, Drucker–Prager {held_dp:.3e}");
    // σ/E = 1e-2 (ν = 0.3 in plane strain: ε = (1 + ν)(1 − 2ν) σ / E = 5.2e-3) over 0.5 m
    assert!(free > 1e-3);
    assert!(held < 1e-12 && held_dp < 1e-12, "{held:e} {held_dp:e}");
    assert_eq!(dp.cont().plastic[0].as_ref().unwrap().yielding, 0);
    // refused where it cannot apply
    assert_eq!(refused("initial_stress = [1.0, 2.0]").key, "continuum[0].initial_stress");
    assert_eq!(
        refused("initial_stress = [-1.0, -1.0, 0.0]\nplane = \"stress\"").key,
        "continuum[0].initial_stress"
    );
}

/// A geostatic `initial_stress` (`{ k0, surcharge }`): a block on a fixed base
/// between rollers, under gravity and a top load equal to the surcharge, stands
/// still when it starts at σ_v = −(q + ρ g d), σ_h = K0 σ_v, where it sags by
/// ≈ (ρ g H²/2 + q H)/M_oed without; the same with Drucker–Prager (φ = 30°, inside
/// its cone at K0 = 0.6, a plastic state at ν/(1 − ν) = 0.43); refused without
/// gravity or with a bad key.
#[test]
fn a_geostatic_initial_stress_holds_a_ground_under_its_weight() {
    let sides = "drive = { left = [0.0, \"free\"], right = [0.0, \"free\"] }";
    let run = |extra: &str| run_still(&block_scene(&format!("{sides}\nload = {{ top = [0.0, -5000.0] }}\n{extra}")));
    let (_, free) = run("");
    let (_, held) = run("initial_stress = { surcharge = 5000.0 }");
    let (dp, held_dp) = run("initial_stress = { surcharge = 5000.0, k0 = 0.6 }\nplastic = { friction = 30.0, dilatancy = 4.0 }");
    let (_, wrong) = run("initial_stress = { surcharge = 0.0 }");
    println!(
        "largest displacement: none {free:.3e}, geostatic {held:.3e}, Drucker–Prager {held_dp:.3e}, without the surcharge {wrong:.3e}"
    );
    // M_oed = E (1 − ν)/((1 + ν)(1 − 2ν)) = 1.35 MPa: the static sag 1.5e-3 (weight)
    // + 1.9e-3 m (the 5 kPa); the linear σ0, constant a cell, is in equilibrium with
    // the cells' weight to rounding (4e-19 m)
    assert!(free > 2e-3, "{free:e}");
    assert!(held < 1e-12 && held_dp < 1e-12, "{held:e} {held_dp:e}");
    assert!(wrong > 0.3 * free, "{wrong:e}");
    assert_eq!(dp.cont().plastic[0].as_ref().unwrap().yielding, 0);
    for (text, needle) in [
        ("initial_stress = { k0 = -1.0 }", "`k0`"),
        ("initial_stress = { surcharge = -1.0 }", "`surcharge`"),
        ("initial_stress = { depth = 1.0 }", "`depth`"),
        ("initial_stress = { k0 = 1e308, surcharge = 1e308 }", "too large"),
    ] {
        let e = refused(text);
        assert_eq!(e.key, "continuum[0].initial_stress", "{text}");
        assert!(e.message.contains(needle) && e.line.is_some(), "{text}: {e:?}");
    }
    let weightless = format!("gravity = [0.0, 0.0]\n{}", block_scene("initial_stress = { k0 = 0.5 }"));
    let e = Scene::<nscdd::dim::D2>::load_str(&weightless, "t.toml", &registry())
        .err()
        .expect("refused");
    assert_eq!(e.key, "continuum[0].initial_stress");
    assert!(e.message.contains("gravity"), "{}", e.message);
}

/// A drive's `"free"` component: the block squeezed between frictionless platens
/// (`["free", v]`) spreads sideways freely (no horizontal reaction), where held
/// platens hold it.
#[test]
fn free_components_of_a_drive_make_rollers() {
    let run = |drive: &str| {
        let text = format!("gravity = [0.0, 0.0]\n{}", block_scene("").replace("fix = [\"bottom\"]", drive));
        let mut r = Run::new(&text);
        for _ in 0..200 {
            r.step();
        }
        let c = r.cont();
        let b = &c.bodies[0];
        // the bottom-left and bottom-right corners' horizontal displacements
        let corner = |x: f64| {
            (0..b.mesh.n_nodes())
                .find(|&k| b.mesh.node(k)[1] < 1e-9 && (b.mesh.node(k)[0] - x).abs() < 1e-9)
                .unwrap()
        };
        let spread = b.u[2 * corner(1.0)] - b.u[2 * corner(0.0)];
        let r = nscdd_fem_deformable::continuum::sides::reaction(b, &c.driven[0][0]);
        (spread, r)
    };
    let (rolled, r_rolled) = run("drive = { bottom = [\"free\", 0.0], top = [\"free\", -0.002] }");
    let (held, _) = run("drive = { bottom = [0.0, 0.0], top = [0.0, -0.002] }");
    println!("bottom spread: rollers {rolled:.3e} m, held {held:.3e} m; rollers' bottom reaction {r_rolled:?}");
    // the held base does not spread; on rollers it does (plane strain Poisson:
    // ν/(1 − ν) of the 0.8 mm squeeze over 0.5 m, times the 1 m width, at rest
    // (θ = 1 damps the squeeze's vibration) to 2 %)
    assert!(held.abs() < 1e-12, "{held:e}");
    let poisson = 0.3 / 0.7 * 0.0008 / 0.5 * 1.0;
    assert!((rolled - poisson).abs() < 0.02 * poisson, "{rolled:e} vs {poisson:e}");
    assert_eq!(r_rolled[0], 0.0);
    assert!(r_rolled[1] > 0.0);
    assert_eq!(refused("drive = { top = [\"free\", \"free\"] }").key, "continuum[0].drive");
}
