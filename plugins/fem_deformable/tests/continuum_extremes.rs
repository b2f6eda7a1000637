//! Continuum regions at the extremes (docs/CONTINUUM.md): continuum stiffness
//! 10⁻² … 10² of the reference, band widths of 1 to 10 grain diameters, θ = ½ and 1:
//! every state stays finite, the total energy never grows, and a step that does not
//! converge says so.
use nscdd::dd::{DdConfig, NscddOf, Rigid2};
use nscdd::dim::D2;
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

/// Disks (radius 0.02, diameter d = 0.04) touching in columns 0.1 apart over a
/// band of `width` diameters on a foundation held at its base (E = `young`).
fn scene(young: f64, width: f64, theta: f64) -> String {
    let band = 0.04 * width;
    let mut s = format!(
        "[time]\nstep = 1e-3\ntheta = {theta}\nsteps = 1\n[solver]\ntolerance = 1e-4\nmax_sweeps = 3000\n\
         [[materials]]\nname = \"grain\"\ndensity = 2600.0\n[[materials]]\nname = \"ground\"\ndensity = 2000.0\n\
         [[laws]]\nmaterials = [\"grain\", \"grain\"]\nfriction = 0.5\n"
    );
    let rows = (band / 0.04).ceil() as usize + 3;
    for j in 0..rows {
        for i in 0..8 {
            let (x, y) = (0.06 + 0.1 * i as f64, 0.02 + 0.04 * j as f64);
            let _ = writeln!(
                s,
                "[[bodies]]\nshape = \"disk\"\nmaterial = \"grain\"\nradius = 0.02\nposition = [{x}, {y}]"
            );
        }
    }
    let cells_y = ((0.3 + band) / 0.04).round() as i64;
    let _ = write!(
        s,
        "[[continuum]]\nmaterial = \"ground\"\nyoung = {young}\npoisson = 0.3\nfix = [\"bottom\"]\n\
         mesh = {{ rectangle = {{ origin = [0.0, -0.3], size = [0.8, {}], cells = [16, {cells_y}] }} }}\n\
         band = {{ normal = [0.0, 1.0], continuum = 0.0, discrete = {band} }}\n",
        0.3 + band
    );
    s
}

/// Kinetic + gravity potential of the grains (their band shares) and kinetic +
/// elastic + load potential of the region.
fn energy(s: &Scene<D2>) -> f64 {
    let (k, p) = s.world.energies();
    let c = s.families[0].as_any().downcast_ref::<Continuum2>().unwrap();
    let b = &c.bodies[0];
    k + p + b.kinetic_energy() + b.elastic_energy() + b.load_potential()
}

#[test]
fn extreme_stiffness_band_width_and_theta_stay_finite_and_dissipative() {
    let mut report = String::new();
    for young in [1e4, 1e6, 1e8] {
        for width in [1.0, 3.0, 10.0] {
            for theta in [0.5, 1.0] {
                let mut s = Scene::<D2>::load_str(&scene(young, width, theta), "x.toml", &registry()).unwrap_or_else(|e| panic!("{e}"));
                let mut dd: Option<NscddOf<Rigid2>> = Some(DdConfig::default().solver_of());
                let e0 = energy(&s);
                let (mut peak, mut unconverged) = (e0, 0);
                for _ in 0..60 {
                    let mut fams: Vec<&mut dyn SceneFamily<D2>> = s.families.iter_mut().map(|f| &mut **f).collect();
                    let (rep, _) = nscdd::family::step(&mut s.world, &mut fams, dd.as_mut())
                        .unwrap_or_else(|d| panic!("E {young}, width {width}, θ {theta}: {d:?}"));
                    unconverged += usize::from(!rep.solve.converged);
                    peak = peak.max(energy(&s));
                }
                let e = energy(&s);
                assert!(e.is_finite() && s.world.bodies.pos.iter().all(|p| p[0].is_finite() && p[1].is_finite()));
                // the energy never exceeds its start by more than the solver's
                // tolerance can give (1e-3 of the system's potential scale)
                let scale = e0.abs().max(1.0);
                let _ = writeln!(
                    report,
                    "E {young:e} width {width} θ {theta}: energy {e0:.4} → {e:.4} (peak {peak:.4}), unconverged steps {unconverged}"
                );
                assert!(
                    peak <= e0 + 1e-3 * scale,
                    "E {young}, width {width}, θ {theta}: energy grew {e0} → {peak}"
                );
            }
        }
    }
    println!("{report}");
}

/// One sweep allowed: the step says it did not converge.
#[test]
fn non_convergence_is_reported() {
    let text = scene(1e8, 10.0, 1.0).replace("max_sweeps = 3000", "max_sweeps = 1");
    let mut s = Scene::<D2>::load_str(&text, "x.toml", &registry()).unwrap();
    let mut dd: Option<NscddOf<Rigid2>> = Some(DdConfig::default().solver_of());
    let mut fams: Vec<&mut dyn SceneFamily<D2>> = s.families.iter_mut().map(|f| &mut **f).collect();
    let (rep, _) = nscdd::family::step(&mut s.world, &mut fams, dd.as_mut()).unwrap();
    assert!(!rep.solve.converged, "{:?}", rep.solve);
}
