//! 3D continuum regions glued to spheres (docs/CONTINUUM.md): the weight carried,
//! a uniform translation, subdomains against one domain, a restart.
use nscdd::dd::{DdConfig, NscddOf, Rigid3};
use nscdd::dim::D3;
use nscdd::family::SceneFamily;
use nscdd::registry::Registry;
use nscdd::scene::Scene;
use nscdd_fem_deformable::continuum::Continuum3;
use std::fmt::Write as _;

fn registry() -> Registry {
    let mut r = Registry::new();
    r.add_plugin(&nscdd_fem_deformable::FemPlugin);
    r.add_plugin(&nscdd_spheres::SpheresPlugin);
    r
}

struct Run {
    s: Scene<D3>,
    dd: Option<NscddOf<Rigid3>>,
}

impl Run {
    fn new(text: &str) -> Run {
        let mut s = Scene::<D3>::load_str(text, "test.toml", &registry()).unwrap_or_else(|e| panic!("{e}"));
        let cfg = s
            .decomposition
            .clone()
            .or(nscdd::family::needs_nscdd(false, &mut s.families).then(DdConfig::default));
        Run {
            dd: cfg.map(|c| c.solver_of()),
            s,
        }
    }
    fn step(&mut self) -> nscdd::engine::StepReport {
        let mut fams: Vec<&mut dyn SceneFamily<D3>> = self.s.families.iter_mut().map(|f| &mut **f).collect();
        nscdd::family::step(&mut self.s.world, &mut fams, self.dd.as_mut()).unwrap().0
    }
    fn cont(&self) -> &Continuum3 {
        self.s.families[0].as_any().downcast_ref::<Continuum3>().unwrap()
    }
}

/// Columns of three touching spheres (radius 0.05, 0.15 apart) in the band of a
/// continuum block held at its base (z ∈ [−0.2, 0.3], band from z = 0 to 0.3).
fn columns(velocity: Option<[f64; 3]>, theta: f64, extra: &str) -> String {
    let gravity = if velocity.is_some() { "gravity = [0.0, 0.0, 0.0]\n" } else { "" };
    let mut s = format!(
        "dimension = 3\n{gravity}[time]\nstep = 2e-3\ntheta = {theta}\nsteps = 1\n[solver]\ntolerance = 1e-8\nmax_sweeps = 100000\n\
         [[materials]]\nname = \"grain\"\ndensity = 2600.0\n[[materials]]\nname = \"ground\"\ndensity = 1600.0\n\
         [[laws]]\nmaterials = [\"grain\", \"grain\"]\nfriction = 0.5\n"
    );
    let v = velocity.unwrap_or([0.0; 3]);
    for k in 0..3 {
        for j in 0..3 {
            for i in 0..3 {
                let (x, y, z) = (0.1 + 0.15 * i as f64, 0.1 + 0.15 * j as f64, 0.05 + 0.1 * k as f64);
                let _ = writeln!(
                    s,
                    "[[bodies]]\nshape = \"sphere\"\nmaterial = \"grain\"\nradius = 0.05\nposition = [{x}, {y}, {z}]\nvelocity = [{}, {}, {}, 0.0, 0.0, 0.0]",
                    v[0], v[1], v[2]
                );
            }
        }
    }
    let fix = if velocity.is_some() {
        String::new()
    } else {
        "fix = [\"bottom\"]".into()
    };
    let vel = velocity
        .map(|v| format!("velocity = [{}, {}, {}]", v[0], v[1], v[2]))
        .unwrap_or_default();
    let _ = write!(
        s,
        "[[continuum]]\nmaterial = \"ground\"\nyoung = 2e6\npoisson = 0.25\n{fix}\n{vel}\n\
         mesh = {{ box = {{ origin = [0.0, 0.0, -0.2], size = [0.5, 0.5, 0.5], cells = [5, 5, 5] }} }}\n\
         band = {{ normal = [0.0, 0.0, 1.0], continuum = 0.0, discrete = 0.3 }}\n{extra}\n"
    );
    s
}

#[test]
fn the_block_carries_the_spheres_weight() {
    let mut r = Run::new(&columns(None, 1.0, "rayleigh = [60.0, 0.0]"));
    assert_eq!(r.cont().band.len(), 27);
    for _ in 0..300 {
        assert!(r.step().solve.converged);
    }
    let c = r.cont();
    let b = &c.bodies[0];
    let g = 9.81;
    let grains: f64 = r.s.world.bodies.mass.iter().sum::<f64>() * g;
    let ground: f64 = b.f_ext.iter().skip(2).step_by(3).map(|f| -f).sum();
    let mut f: Vec<f64> = b.f_ext.iter().map(|x| -x).collect();
    b.mul_add(0.0, 1.0, &b.u, &mut f);
    let reaction: f64 = (0..b.mesh.n_nodes()).filter(|&k| b.fixed[3 * k + 2]).map(|k| f[3 * k + 2]).sum();
    println!("weight {:.3} N, base reaction {reaction:.3} N", grains + ground);
    assert!((reaction - grains - ground).abs() < 1e-3 * (grains + ground));
}

#[test]
fn a_uniform_translation_passes_the_band_with_no_force() {
    let v0 = [0.2, -0.1, 0.3];
    let mut r = Run::new(&columns(Some(v0), 0.5, ""));
    for _ in 0..20 {
        assert!(r.step().solve.converged);
    }
    let lam = r.cont().ties.r.iter().flatten().fold(0.0f64, |m, x| m.max(x.abs()));
    let mv = 2600.0 * 4.0 / 3.0 * std::f64::consts::PI * 0.05f64.powi(3) * 0.374;
    assert!(lam < 1e-9 * mv, "largest tie impulse {lam:e} against m v = {mv:e}");
}

fn run(text: &str, steps: usize) -> (Vec<[f64; 3]>, Vec<f64>) {
    let mut r = Run::new(text);
    for _ in 0..steps {
        assert!(r.step().solve.converged);
    }
    (r.s.world.bodies.pos.clone(), r.cont().bodies[0].u.clone())
}

#[test]
fn subdomains_agree_with_one_domain() {
    let (p0, u0) = run(&columns(None, 0.5, ""), 30);
    let umax = u0.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    for dec in ["[decomposition]\nnx = 2\nny = 2", "[decomposition]\nby_model = true\nnx = 2"] {
        let (p, u) = run(&columns(None, 0.5, dec), 30);
        let dp = p
            .iter()
            .zip(&p0)
            .flat_map(|(a, b)| (0..3).map(move |d| (a[d] - b[d]).abs()))
            .fold(0.0f64, f64::max);
        let du = u.iter().zip(&u0).fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
        println!("{dec:?}: spheres {dp:e} m, block {du:e} m (largest displacement {umax:e})");
        assert!(dp < 1e-3 * umax && du < 1e-3 * umax);
    }
}
