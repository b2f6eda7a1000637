//! A contact law written outside the framework, registered by a plugin: the
//! framework's law interface (`nscdd::law::Law`) is all it needs. The toy law
//! keeps a standoff δ between surfaces (a frictionless Signorini condition on
//! g − δ); a disk dropped on a floor comes to rest at the gap δ, which no field of
//! the built-in laws can express.

use nscdd::dim::joint::Joint;
use nscdd::law::{target_velocity, Law, LawDef, LawInput, LawStep};
use nscdd::model::Target;
use nscdd::registry::{Plugin, Registry};
use std::sync::Arc;

#[derive(Debug)]
struct Standoff {
    delta: f64,
}

impl Law for Standoff {
    fn contacts(&self, step: &LawStep, inputs: &[LawInput], target: &mut [Target], _joint: &mut [Joint]) {
        for (c, t) in inputs.iter().zip(target) {
            let g = c.gap - self.delta;
            *t = Target {
                u_target: target_velocity(g, c.un_begin, c.un_free, step.h, step.theta, 0.0),
                mu: 0.0,
            };
        }
    }
}

struct StandoffPlugin;

impl Plugin for StandoffPlugin {
    fn name(&self) -> &'static str {
        "standoff"
    }
    fn build(&self, reg: &mut Registry) {
        reg.add_law(LawDef {
            name: "standoff",
            parse: |t| {
                nscdd::params::only_keys(t, &["gap"])?;
                let delta = nscdd::params::number(t, "gap", None)?;
                if !(delta >= 0.0) {
                    return Err(nscdd::params::ParamError::new("gap", format!("must be ≥ 0 (m), got {delta}")));
                }
                Ok(Arc::new(Standoff { delta }))
            },
        });
    }
}

const SCENE: &str = r#"
[time]
step = 1e-3
steps = 600
[solver]
tolerance = 1e-10
max_sweeps = 100
[detection]
alert = 0.05
[[materials]]
name = "m"
density = 1000.0
[[laws]]
materials = ["m", "m"]
law = "standoff"
gap = GAP
[[bodies]]
shape = "wall"
material = "m"
position = [0.0, -0.01]
length = 1.0
thickness = 0.02
fixed = true
[[bodies]]
shape = "disk"
material = "m"
position = [0.0, 0.14]
radius = 0.1
"#;

#[test]
fn a_plugin_law_keeps_its_standoff_gap() {
    let mut reg = nscdd_rigid_disks::registry();
    reg.add_plugin(&StandoffPlugin);
    let delta = 0.01;
    let text = SCENE.replace("GAP", &delta.to_string());
    let mut s = nscdd::scene::load_str(&text, "standoff.toml", &reg).unwrap_or_else(|e| panic!("{e}"));
    for _ in 0..600 {
        let rep = s.world.step().unwrap();
        assert!(rep.solve.converged);
    }
    let b = &s.world.bodies;
    let gap = b.pos[1][1] - 0.1;
    // at rest on the standoff, up to the Moreau–Jean scheme's impact error: a
    // plastic impact (ū = 0) stops the velocity within the step, the position
    // moving by at most h (1 − θ) |v⁻| past the contact, v⁻ = √(2 g 0.03) the
    // landing speed (a built-in law would stop the disk at gap 0 within the same
    // bound, 13× smaller than δ)
    let bound = 1e-3 * 0.5 * (2.0 * 9.81 * 0.03f64).sqrt();
    println!("rest gap {gap:.6e}, δ = {delta}, bound {bound:.3e}");
    assert!((gap - delta).abs() <= bound, "rest gap {gap} vs δ = {delta} ± {bound}");
    assert!(b.vel[1][1].abs() < 1e-9, "vertical velocity {}", b.vel[1][1]);
    // a standoff law given a negative gap is refused at load time, naming the key
    let err = nscdd::scene::load_str(&SCENE.replace("GAP", "-1.0"), "standoff.toml", &reg)
        .err()
        .expect("refused");
    assert_eq!(err.key, "laws[0].gap", "{err}");
}
