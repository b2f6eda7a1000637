//! Continuum regions glued to grains (docs/CONTINUUM.md): patch tests, the
//! partition of unity of the band's mass, subdomains against one domain.
use nscdd::dd::{DdConfig, NscddOf, Rigid2};
use nscdd::family::SceneFamily;
use nscdd::registry::Registry;
use nscdd::scene::Scene;
use nscdd_fem_deformable::continuum::Continuum2;
use std::fmt::Write as _;

fn registry() -> Registry {
    let mut r = Registry::new();
    r.add_plugin(&nscdd_fem_deformable::FemPlugin);
    r.add_plugin(&nscdd_rigid_disks::RigidDisks);
    r
}

/// A scene and its NSCDD stage (one subdomain without a decomposition).
struct Run {
    s: Scene<nscdd::dim::D2>,
    dd: Option<NscddOf<Rigid2>>,
}

impl Run {
    fn new(text: &str) -> Run {
        let mut s = Scene::<nscdd::dim::D2>::load_str(text, "test.toml", &registry()).unwrap_or_else(|e| panic!("{e}"));
        let one = DdConfig::default();
        let cfg = s
            .decomposition
            .clone()
            .or(nscdd::family::needs_nscdd(false, &mut s.families).then_some(one));
        let dd = cfg.map(|c| c.solver_of());
        Run { s, dd }
    }
    fn step(&mut self) -> nscdd::engine::StepReport {
        let mut fams: Vec<&mut dyn SceneFamily<nscdd::dim::D2>> = self.s.families.iter_mut().map(|f| &mut **f).collect();
        nscdd::family::step(&mut self.s.world, &mut fams, self.dd.as_mut()).unwrap().0
    }
    fn cont(&self) -> &Continuum2 {
        self.s.families[0].as_any().downcast_ref::<Continuum2>().unwrap()
    }
}

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
    assert_eq!(c.ties.len(), 4 * 19);
    let m = 2600.0 * std::f64::consts::PI * 0.02 * 0.02;
    for (a, &g) in c.ties.grain.iter().enumerate() {
        let y = r.s.world.bodies.pos[g as usize][1];
        let wp = y / 0.2;
        assert!((c.weight[a] - wp).abs() < 1e-12);
        assert!((r.s.world.bodies.mass[g as usize] - wp * m).abs() < 1e-12 * m);
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
