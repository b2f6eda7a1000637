//! Validation of the deformable bodies against analytic answers (issue 6).
mod common;
use common::*;

/// A block W × H on a rigid frictionless floor under its weight, plane strain,
/// brought to rest by implicit Euler (θ = 1) steps much longer than its period.
///
/// The analytic answer (σxx = 0, σyy = −ρg(H − y): uniform pressure ρgH, top
/// settlement ρgH²(1 − ν²)/(2E)) has a flat base only for ν = 0: for ν > 0 its
/// base would bend by ν(1 + ν)ρg x²/(2E), which a flat frictionless floor forbids,
/// and the pressure becomes bell-shaped (measured ±14 % for W/H = 2, ν = 0.3,
/// docs/DEFORMABLE.md). The test takes ν = 0, where the answer is exact.
fn self_weight(cells: usize) -> (f64, f64, Vec<f64>, f64) {
    let (e, nu, rho, g, w, h) = (1e7, 0.0, 1000.0, 9.81, 2.0, 1.0);
    let text = format!(
        r#"
gravity = [0.0, -{g}]
[time]
step = 0.05
theta = 1.0
steps = 40
[solver]
tolerance = 1e-6
max_sweeps = 5000
[detection]
alert = 0.01
[[materials]]
name = "soil"
density = {rho}
[[materials]]
name = "ground"
density = 1000.0
[[laws]]
materials = ["soil", "ground"]
law = "frictionless"
[[bodies]]
name = "floor"
shape = "halfplane"
material = "ground"
position = [0.0, 0.0]
fixed = true
[[deformable]]
material = "soil"
young = {e}
poisson = {nu}
mesh = {{ rectangle = {{ origin = [0.0, 0.0], size = [{w}, {h}], cells = [{}, {cells}] }} }}
"#,
        2 * cells
    );
    let mut s = scene(&text);
    for i in 0..40 {
        let rep = s.step().unwrap();
        assert!(rep.solve.converged, "{:?}", rep.solve);
        if i == 39 {
            let total = normal_impulse(&s) / 0.05 / (rho * g * w * h);
            assert!((total - 1.0).abs() < 1e-6, "the floor carries {total} × the weight");
        }
    }
    let settle = mean_displacement(&s, 0, 1, h, 1);
    let exact = -rho * g * h * h * (1.0 - nu * nu) / (2.0 * e);
    // nodal reactions of the interior base nodes (spacing w / (2 cells)) as pressures
    let dx = w / (2 * cells) as f64;
    let hstep = 0.05;
    let c = &s.fe.contacts;
    let b = &s.fe.bodies[0];
    let mut p = vec![];
    for a in 0..c.len() {
        let node = s.fe.sets[0].nodes[c.cand[a].k[0] as usize] as usize;
        let x = b.mesh.x0[2 * node];
        if x > 1e-9 && x < w - 1e-9 {
            p.push(c.r[a][0] / hstep / dx);
        }
    }
    (settle, exact, p, rho * g * h)
}

#[test]
fn self_weight_block_pressure_and_settlement_converge() {
    let (mut errs, mut devs) = (vec![], vec![]);
    for cells in [2, 4, 8, 16] {
        let (settle, exact, p, p_exact) = self_weight(cells);
        assert!(!p.is_empty());
        println!(
            "cells {cells}: base pressures / ρgH {:?}",
            p.iter().map(|x| x / p_exact).collect::<Vec<_>>()
        );
        let dev = p.iter().map(|pi| (pi - p_exact).abs() / p_exact).fold(0.0, f64::max);
        devs.push(dev);
        let err = ((settle - exact) / exact).abs();
        println!("cells {cells}: settlement {settle:.4e} (exact {exact:.4e}), relative error {err:.3e}");
        errs.push(err);
    }
    println!("settlement errors {errs:?}, largest pressure deviations {devs:?}");
    assert!(
        errs.windows(2).all(|e| e[1] < e[0]),
        "settlement does not converge under refinement: {errs:?}"
    );
    assert!(
        devs.windows(2).all(|e| e[1] < e[0]),
        "base pressure does not converge to ρgH: {devs:?}"
    );
    assert!(errs[3] < 0.01, "finest mesh: settlement off by {:.2} %", 100.0 * errs[3]);
    assert!(devs[3] < 0.02, "finest mesh: base pressure off by {:.2} %", 100.0 * devs[3]);
}
