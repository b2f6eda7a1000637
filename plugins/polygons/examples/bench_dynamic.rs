//! The polygons plugin loaded at run time against the same plugin linked
//! statically (docs/PERFORMANCE.md, "Plugins loaded at run time"): the angular
//! deposit of `plugins/polygons/scenes/deposit.toml` (700 random polygons of 5–7
//! sides in a box of walls), run `steps` steps from the same start with each
//! registry in turn (static, dynamic, static, dynamic, … `rounds` times); the mean
//! time per step of detection and of NLGS over the second half of each run (the
//! settled, dense part), and a check that both give bitwise the same bodies.
//!
//!     cargo build --release -p nscdd-polygons --examples
//!     target/release/examples/bench_dynamic [steps] [rounds] [library]
//!
//! (`library` defaults to the `libnscdd_polygons.so` cargo built beside the
//! example: build the example and the library in one command.)
use nscdd::dim::D2;
use nscdd::registry::Registry;
use nscdd::scene::Scene;
use std::path::PathBuf;

/// Runs the scene: (mean detection time, mean NLGS time per step over the second
/// half, sweeps there, the bodies' final positions as bits).
fn run(text: &str, reg: &Registry, steps: usize) -> (f64, f64, u64, Vec<[u64; 2]>) {
    let mut s = Scene::<D2>::load_str(text, "deposit.toml", reg).expect("the deposit scene");
    let (mut detect, mut nlgs, mut sweeps) = (0.0, 0.0, 0);
    for k in 0..steps {
        let rep = s.world.step().expect("no divergence");
        if k >= steps / 2 {
            detect += rep.times.detect;
            nlgs += rep.times.nlgs;
            sweeps += rep.solve.sweeps as u64;
        }
    }
    let n = (steps - steps / 2) as f64;
    let bits = s.world.bodies.pos.iter().map(|p| p.map(f64::to_bits)).collect();
    (detect / n, nlgs / n, sweeps, bits)
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let steps: usize = args.get(1).and_then(|a| a.parse().ok()).unwrap_or(2000);
    let rounds: usize = args.get(2).and_then(|a| a.parse().ok()).unwrap_or(2);
    let Some(lib) = args
        .get(3)
        .map(PathBuf::from)
        .or_else(|| nscdd::plugin::built_library("nscdd_polygons"))
    else {
        eprintln!("libnscdd_polygons is not built: cargo build --release -p nscdd-polygons --examples");
        std::process::exit(2);
    };
    let scene = include_str!("../scenes/deposit.toml");
    let text: String = scene
        .lines()
        .filter(|l| !l.starts_with("[[plugins]]") && !l.starts_with("library"))
        .collect::<Vec<_>>()
        .join("\n");

    let mut linked = nscdd_rigid_disks::registry();
    linked.add_plugin(&nscdd_polygons::PolygonsPlugin);
    let mut loaded = nscdd_rigid_disks::registry();
    if let Err(e) = nscdd::plugin::load(&lib, &mut loaded) {
        eprintln!("{e}");
        std::process::exit(2);
    }
    println!("700 polygons, {steps} steps of 0.5 ms; means over steps {}–{steps}", steps / 2 + 1);
    let (mut best_s, mut best_d) = ((f64::INFINITY, f64::INFINITY), (f64::INFINITY, f64::INFINITY));
    let mut reference = None;
    for r in 0..rounds {
        for (name, reg) in [("linked", &linked), ("loaded", &loaded)] {
            let (d, n, sweeps, bits) = run(&text, reg, steps);
            println!(
                "round {r} {name}: detection {:.1} µs/step, NLGS {:.1} µs/step ({sweeps} sweeps)",
                d * 1e6,
                n * 1e6
            );
            let best = if name == "linked" { &mut best_s } else { &mut best_d };
            *best = (best.0.min(d), best.1.min(n));
            match &reference {
                None => reference = Some(bits),
                Some(b) => assert!(*b == bits, "{name}: the bodies differ from the first run"),
            }
        }
    }
    println!(
        "best of {rounds}: detection loaded/linked {:.3}, NLGS loaded/linked {:.3} (bodies bitwise equal)",
        best_d.0 / best_s.0,
        best_d.1 / best_s.1
    );
}
