//! Restart from a saved state: a run stopped at step k and continued from its
//! `final.json` (or its `checkpoint.json`) ends bitwise where the uninterrupted run
//! ends; a decomposed run can continue a one-domain one. Bad restart files are input
//! errors naming the key.

use std::path::PathBuf;

/// A frictional pile settling in a box, with a wall driven down from t = 0.05 s so
/// that the box height (ε1's reference) is part of the state.
fn scene(steps: u64, extra: &str) -> String {
    format!(
        r#"
[time]
step = 1e-3
steps = {steps}
[solver]
tolerance = 1e-5
[output]
vtk = false
box = {{ left = "left", right = "right", bottom = "floor", top = "lid", strain_from = 0.05 }}
{extra}
[[materials]]
name = "m"
density = 1000.0
[[laws]]
materials = ["m", "m"]
friction = 0.4
[[bodies]]
name = "floor"
shape = "wall"
material = "m"
position = [0.1, -0.005]
length = 0.3
thickness = 0.01
fixed = true
[[bodies]]
name = "left"
shape = "wall"
material = "m"
position = [-0.005, 0.1]
rotation = 1.5707963267948966
length = 0.3
thickness = 0.01
fixed = true
[[bodies]]
name = "right"
shape = "wall"
material = "m"
position = [0.205, 0.1]
rotation = 1.5707963267948966
length = 0.3
thickness = 0.01
fixed = true
[[bodies]]
name = "lid"
shape = "wall"
material = "m"
position = [0.1, 0.2]
length = 0.19
thickness = 0.01
drive.x = {{ velocity = 0.0 }}
drive.rot = {{ velocity = 0.0 }}
drive.y = {{ velocity = {{ ramp = [0.05, 0.0, 0.06, -0.2] }} }}
[[generate]]
kind = "disk_deposit"
material = "m"
count = 90
radius_min = 0.007
radius_max = 0.01
box = [0.0, 0.0, 0.2, 0.19]
seed = 3
"#
    )
}

/// Panics at the first differing line of two texts.
fn same(a: &str, b: &str, what: &str) {
    for (k, (x, y)) in a.lines().zip(b.lines()).enumerate() {
        assert_eq!(x, y, "{what}: line {} differs", k + 1);
    }
    assert_eq!(a.lines().count(), b.lines().count(), "{what}: line counts");
}

fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("nscdd-restart-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    d
}

fn run(text: &str, restart: Option<&std::path::Path>, dir: &std::path::Path) -> String {
    let reg = nscdd_rigid_disks::registry();
    let mut s = nscdd::scene::load_str(text, "restart.toml", &reg).unwrap();
    if let Some(p) = restart {
        nscdd::scene::restart(&mut s.world, p).unwrap();
    }
    nscdd::run::run(&mut s, &reg, dir, |_, _| {}).unwrap();
    std::fs::read_to_string(dir.join("final.json")).unwrap()
}

#[test]
fn continued_run_is_bitwise_the_uninterrupted_one() {
    let (a, b, c) = (tmp("whole"), tmp("first"), tmp("second"));
    let whole = run(&scene(120, ""), None, &a);
    let _ = run(&scene(70, ""), None, &b);
    let cont = run(&scene(120, ""), Some(&b.join("final.json")), &c);
    same(&whole, &cont, "restart at step 70 must continue bitwise");
    // the continued history starts at step 71 and carries ε1 on
    let hist = std::fs::read_to_string(c.join("history.csv")).unwrap();
    let first: Vec<&str> = hist.lines().nth(1).unwrap().split(',').collect();
    assert_eq!(first[0], "71");
    let whole_hist = std::fs::read_to_string(a.join("history.csv")).unwrap();
    let head: Vec<&str> = hist.lines().next().unwrap().split(',').collect();
    let untimed = |line: &str| -> Vec<String> {
        line.split(',')
            .zip(&head)
            .filter(|(_, h)| !h.starts_with("t_"))
            .map(|(v, _)| v.to_string())
            .collect()
    };
    for k in 1..=50 {
        let (w, r) = (whole_hist.lines().nth(70 + k).unwrap(), hist.lines().nth(k).unwrap());
        assert_eq!(untimed(w), untimed(r), "history row of step {}", 70 + k);
    }
    for d in [a, b, c] {
        let _ = std::fs::remove_dir_all(d);
    }
}

#[test]
fn checkpoint_restarts_and_decomposed_run_continues() {
    let (a, b, c) = (tmp("ckpt"), tmp("ckpt-cont"), tmp("ckpt-dd"));
    let whole = run(&scene(100, "checkpoint_every = 40"), None, &a);
    let fin: serde_json::Value = serde_json::from_str(&whole).unwrap();
    assert!(fin["box_h0"].as_f64().unwrap() > 0.18);
    let ck: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(a.join("checkpoint.json")).unwrap()).unwrap();
    assert_eq!(ck["step"], 80, "the last checkpoint before the end");
    let cont = run(&scene(100, ""), Some(&a.join("checkpoint.json")), &b);
    same(&whole, &cont, "restart from the checkpoint");
    // a 2x2 decomposition continues the one-domain state: same end within tolerance
    let dd = run(&scene(100, "[decomposition]\nnx = 2\nny = 2"), Some(&a.join("checkpoint.json")), &c);
    let dd: serde_json::Value = serde_json::from_str(&dd).unwrap();
    assert_eq!(dd["step"], 100);
    let (p, q) = (fin["bodies"].as_array().unwrap(), dd["bodies"].as_array().unwrap());
    let mut dmax: f64 = 0.0;
    for (x, y) in p.iter().zip(q) {
        for k in 0..2 {
            dmax = dmax.max((x["position"][k].as_f64().unwrap() - y["position"][k].as_f64().unwrap()).abs());
        }
    }
    // 20 steps of a tolerance-1e-5 solve: positions agree far below a radius (7 mm)
    assert!(dmax < 1e-4, "decomposed continuation deviates by {dmax} m");
    for d in [a, b, c] {
        let _ = std::fs::remove_dir_all(d);
    }
}

#[test]
fn bad_restart_files_name_the_key() {
    let reg = nscdd_rigid_disks::registry();
    let dir = tmp("bad");
    let _ = run(&scene(30, ""), None, &dir);
    let good = std::fs::read_to_string(dir.join("final.json")).unwrap();
    let load = |text: &str, steps: u64| {
        let mut s = nscdd::scene::load_str(&scene(steps, ""), "restart.toml", &reg).unwrap();
        nscdd::scene::restart::restart_str(&mut s.world, text, "state.json").unwrap_err()
    };
    let e = load("{ not json", 60);
    assert!(e.to_string().starts_with("state.json:1: not a saved state"), "{e}");
    let e = load(&good, 30);
    assert_eq!(e.key, "step", "{e}");
    assert!(e.message.contains("nothing left to run"), "{e}");
    let e = load(&good.replacen("\"kind\": \"disk\"", "\"kind\": \"wall\"", 1), 60);
    assert!(e.key.ends_with("].kind") && e.line.is_some(), "{e}");
    let e = load(&good.replacen("\"time\": 0.03", "\"time\": 0.5", 1), 60);
    assert_eq!(e.key, "time", "{e}");
    // a scene with another body count
    let mut other = nscdd::scene::load_str(&scene(60, "").replace("count = 90", "count = 80"), "o.toml", &reg).unwrap();
    let e = nscdd::scene::restart::restart_str(&mut other.world, &good, "state.json").unwrap_err();
    assert_eq!(e.key, "bodies", "{e}");
    let _ = std::fs::remove_dir_all(dir);
}
