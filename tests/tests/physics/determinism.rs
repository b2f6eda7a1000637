//! Determinism: one scene run twice gives bitwise-identical results.

use crate::common::scene;

/// A 200-disk deposit (generator `disk_deposit`) settling in a box with the NLGS
/// order shuffled every step: two runs in the same process give the same
/// `final.json` byte for byte (the shuffle is seeded from `seed` and the step
/// number; detection and storage orders are deterministic).
#[test]
fn deposit_reruns_are_bitwise_identical() {
    let text = r#"
[time]
step = 1e-3
steps = 300
[solver]
tolerance = 1.666e-4
ordering = "shuffled"
seed = 42
[[materials]]
name = "grain"
density = 2600.0
[[materials]]
name = "steel"
density = 7800.0
[[laws]]
materials = ["grain", "grain"]
friction = 0.4
[[laws]]
materials = ["grain", "steel"]
friction = 0.2
[[bodies]]
name = "floor"
shape = "wall"
material = "steel"
position = [0.15, -0.01]
length = 0.34
thickness = 0.02
fixed = true
[[bodies]]
name = "left"
shape = "wall"
material = "steel"
position = [-0.01, 0.3]
rotation = 1.5707963267948966
length = 0.6
thickness = 0.02
fixed = true
[[bodies]]
name = "right"
shape = "wall"
material = "steel"
position = [0.31, 0.3]
rotation = 1.5707963267948966
length = 0.6
thickness = 0.02
fixed = true
[[generate]]
kind = "disk_deposit"
material = "grain"
count = 200
radius_min = 0.008
radius_max = 0.012
box = [0.0, 0.0, 0.3, 0.6]
seed = 5
"#;
    let run = || {
        let mut s = scene(text);
        let mut sweeps = 0u64;
        for _ in 0..s.world.time.steps {
            sweeps += s.world.step().expect("no divergence").solve.sweeps as u64;
        }
        (nscdd::output::final_json(&s.world), s.world.contacts.len(), sweeps)
    };
    let (a, na, sa) = run();
    let (b, _, sb) = run();
    println!("final.json: {} bytes, {na} contacts, {sa} sweeps in all", a.len());
    assert!(na > 200, "the deposit should be in contact, {na} contacts");
    assert_eq!(sa, sb, "same number of NLGS sweeps");
    assert!(a == b, "final.json differs between two runs");
}
