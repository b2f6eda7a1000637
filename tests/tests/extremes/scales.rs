//! Extremes of scale: time steps from 1e-6 to 1e-1 s, a column of 1000 disks, a
//! large disk on small ones and a polydisperse deposit (radii 1:100). The bounds
//! and the simulation loop are the parent module's.

use super::*;

// ---------------------------------------------------------------------------------
// (4) time steps from 1e-6 to 1e-1 s

/// 4 × 5 disks (r = 1 cm) on a triangular lattice with 4 mm gaps, released in a
/// box: they fall (≤ 10 cm) and settle. 0.1 s simulated (at least 20 steps).
fn falling_pile(h: f64, alert_m: Option<f64>) -> (Scene, Figures, u64) {
    let steps = ((0.1 / h).round() as u64).clamp(20, 100_000);
    let r = 0.01;
    let mut text = header(h, steps, 1.666e-4, 1000, 0.4, 0.0);
    if let Some(a) = alert_m {
        text += &alert(a);
    }
    text += &open_box(0.11, 0.3, 0.01);
    text += &format!("\n[[generate]]\nkind = \"triangular_lattice\"\nmaterial = \"grain\"\nnx = 4\nny = 5\nradius = {r:e}\nspacing = {:e}\norigin = [{:e}, {:e}]\n", 2.4 * r, 1.2 * r, r + 4e-3);
    let (s, f) = simulate(&format!("falling-h{h:e}"), &text, |_, _| {});
    (s, f, steps)
}

#[test]
fn time_steps_from_1e_6_to_1e_1() {
    // a disk falls at most 10 cm: v ≤ √(2 g 0.1) ≈ 1.4 m/s, plus g h in a step
    let v_max = |h: f64| (2.0 * G * 0.1).sqrt() + G * h;
    for h in [1e-6f64, 1e-5, 1e-4, 1e-3, 1e-2, 1e-1] {
        // the default alert (1 mm), then the advised alert ≥ h v_max
        let advised = h * v_max(h);
        for a in [None, Some(advised)] {
            if a.is_some() && advised <= 1e-3 {
                continue; // the default alert (1 mm) already exceeds h v_max
            }
            let (s, f, steps) = falling_pile(h, a);
            let (ek, _) = s.world.energies();
            let out = escaped(&s.world, 0.11);
            let bound = impact_bound(h, v_max(h), f.alert) + creep_bound(steps, h);
            f.print(
                &format!("falling pile of 20, h={h:e}"),
                &format!(
                    "simulated {:.3} s, final kinetic energy {ek:.3e} J, {out} escaped, bound {bound:.2e} m",
                    steps as f64 * h
                ),
            );
            assert!(f.e_end <= f.e0 + 1e-9, "h = {h}: energy created ({} -> {})", f.e0, f.e_end);
            if a.is_some() || h * v_max(h) <= f.alert {
                assert!(f.max_pen < bound, "h = {h}: interpenetration {} > {bound}", f.max_pen);
                assert_eq!(out, 0, "h = {h}: bodies left the box");
            }
        }
    }
}

// ---------------------------------------------------------------------------------
// (5) a column of 1000 disks at rest on a floor

fn column_scene(n: usize, steps: u64, tol: f64, max_sweeps: u32) -> String {
    let r = 0.01;
    header(1e-3, steps, tol, max_sweeps, 0.3, 0.0)
        + &floor_halfplane()
        + &format!(
            "\n[[generate]]\nkind = \"square_lattice\"\nmaterial = \"grain\"\nnx = 1\nny = {n}\nradius = {r:e}\norigin = [0.0, {r:e}]\n"
        )
}

/// Bottom contact force / (n m g) after the last step.
fn bottom_ratio(w: &World2, n: usize) -> f64 {
    let m = w.bodies.mass[1];
    -w.reaction[0][1] / w.time.h / (n as f64 * m * G)
}

#[test]
fn column_of_1000_disks() {
    let (n, h, r) = (1000usize, 1e-3, 0.01);
    // (a) the default criterion (QM/16, tol 1.666e-4), 400 steps
    let steps = 400;
    let mut samples = vec![];
    let mut flagged_by_residual = true;
    let (s, f) = simulate("column", &column_scene(n, steps, 1.666e-4, 20000), |w, rep| {
        let ratio = bottom_ratio(w, n);
        if (ratio - 1.0).abs() > 0.1 && rep.solve.residual < 1e-2 {
            flagged_by_residual = false;
        }
        if [1, 2, 5, 10, 50, 100, 200, 400].contains(&w.step) {
            samples.push(format!(
                "step {}: {} sweeps, converged {}, bottom {:.3}, residual {:.2e}",
                w.step, rep.solve.sweeps, rep.solve.converged, ratio, rep.solve.residual
            ));
        }
    });
    let top_sink = (2 * n - 1) as f64 * r - s.world.bodies.pos[n][1];
    let bound = creep_bound(steps, h);
    f.print(
        "column of 1000, QM/16 tol 1.666e-4",
        &format!("top disk sank {top_sink:.3e} m, bound {bound:.2e} m; {}", samples.join("; ")),
    );
    assert!(f.max_pen < bound, "interpenetration {} > {bound}", f.max_pen);
    // the LMGC norms stop on stagnation: the natural-map residual tells
    assert!(flagged_by_residual, "a bottom force off by > 10 % must show in the residual");

    // (b) one step from rest with an unreachable tolerance: NLGS's slow convergence
    let sweeps = 150_000;
    let (s, f) = simulate("column-one-step", &column_scene(n, 1, 1e-14, sweeps), |_, _| {});
    let ratio = bottom_ratio(&s.world, n);
    f.print(
        "column of 1000, one step, 150000 sweeps",
        &format!("bottom force / (1000 m g) = {ratio:.4}"),
    );
    assert_eq!(f.unconverged, 1, "the step must report that it did not converge");
    assert!(ratio > 0.2 && ratio < 1.0, "bottom ratio {ratio}");

    // (c) sweeps for the bottom force within 1 % in one step, for shorter columns
    let mut needed = vec![];
    for m in [50usize, 100, 200] {
        let mut k = 500u32;
        let (sweeps, ratio) = loop {
            let (s, _) = simulate(&format!("column-{m}"), &column_scene(m, 1, 1e-14, k), |_, _| {});
            let ratio = bottom_ratio(&s.world, m);
            if (ratio - 1.0).abs() < 1e-2 || k > 400_000 {
                break (k, ratio);
            }
            k = (k as f64 * 1.25) as u32;
        };
        needed.push((m, sweeps));
        println!("[extremes] column of {m}, one step: bottom force within 1 % after {sweeps} sweeps (±25 %), ratio {ratio:.4}");
        assert!((ratio - 1.0).abs() < 1e-2);
    }
    let (m, k) = needed[needed.len() - 1];
    let extrapolated = k as f64 * (n as f64 / m as f64).powi(2);
    println!("[extremes] column of 1000, one step: ~{extrapolated:.2e} sweeps needed (n² scaling from n = {m})");
}

// ---------------------------------------------------------------------------------
// (6) radii spread 1:100

#[test]
fn large_disk_on_a_bed_of_small_ones() {
    let (big, small, h, steps) = (0.5, 0.005, 1e-3, 100);
    let mut text = header(h, steps, 1.666e-4, 2000, 0.4, 0.0);
    let width = 1.0;
    text += &open_box(width, 2.0, 0.01);
    let nx = (width / (2.0 * small)).floor() as u32 - 1;
    text += &format!("\n[[generate]]\nkind = \"triangular_lattice\"\nmaterial = \"grain\"\nnx = {nx}\nny = 3\nradius = {small:e}\norigin = [{small:e}, {small:e}]\n");
    let top = small + 2.0 * 3f64.sqrt() * small;
    text += &disk("big", "grain", 0.5 * width, top + small + big, big);
    let (s, f) = simulate("big-on-small", &text, |_, _| {});
    let k = index_of(&s.world, "big");
    let sink = top + small + big - s.world.bodies.pos[k][1];
    let bound = creep_bound(steps, h);
    f.print(
        "radii 1:100, disk R = 0.5 m on 3 rows of r = 5 mm",
        &format!(
            "{} bodies, the big disk sank {sink:.3e} m, bound {bound:.2e} m",
            s.world.bodies.len()
        ),
    );
    assert!(f.max_pen < bound, "interpenetration {} > {bound}", f.max_pen);
}

#[test]
fn polydisperse_deposit_1_to_100() {
    let (h, steps) = (1e-3, 200);
    let mut text = header(h, steps, 1.666e-4, 1000, 0.4, 0.0);
    text += &open_box(1.0, 3.0, 0.01);
    text += "\n[[generate]]\nkind = \"disk_deposit\"\nmaterial = \"grain\"\ncount = 200\nradius_min = 0.001\nradius_max = 0.1\nbox = [0.0, 0.0, 1.0, 3.0]\nseed = 5\n";
    let (s, f) = simulate("polydisperse", &text, |_, _| {});
    let (ek, _) = s.world.energies();
    // disks may roll off a support by up to the largest diameter: v ≤ √(2 g 0.2)
    let bound = impact_bound(h, (2.0 * G * 0.2).sqrt(), f.alert) + creep_bound(steps, h);
    f.print(
        "radii 1:100, deposit of 200 (r 1 mm–10 cm)",
        &format!(
            "final kinetic energy {ek:.3e} J, {} escaped, bound {bound:.2e} m",
            escaped(&s.world, 1.0)
        ),
    );
    assert!(f.max_pen < bound, "interpenetration {} > {bound}", f.max_pen);
    assert_eq!(escaped(&s.world, 1.0), 0);
    assert!(f.e_end <= f.e0 + 1e-9);
}
