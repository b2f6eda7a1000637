//! Helpers shared by the physics tests: loading a scene from text, stepping with a
//! convergence check, relative comparisons, and a small dense LCP solver.
#![allow(dead_code)]

use nscdd::engine::StepReport;
use nscdd::scene::Scene;

/// Standard gravity used by the scenes (the loader's default).
pub const G: f64 = 9.81;

/// Loads a scene from TOML text with the rigid-disks plugin installed.
pub fn scene(text: &str) -> Scene {
    let reg = nscdd_rigid_disks::registry();
    nscdd::scene::load_str(text, "test.toml", &reg).unwrap_or_else(|e| panic!("scene does not load: {e}\n{text}"))
}

/// One step; panics if the run diverges or the contact solve did not converge.
pub fn step(s: &mut Scene) -> StepReport {
    let rep = s.world.step().unwrap_or_else(|e| panic!("{e}"));
    assert!(rep.solve.converged, "step {} did not converge: {:?}", s.world.step, rep.solve);
    rep
}

/// `n` steps (see [`step`]).
pub fn steps(s: &mut Scene, n: usize) {
    for _ in 0..n {
        step(s);
    }
}

/// |measured − expected| ≤ rel · |expected| (or ≤ rel when expected is 0), with
/// both numbers printed (run with `--nocapture` to see them).
#[track_caller]
pub fn assert_rel(what: &str, measured: f64, expected: f64, rel: f64) {
    let err = (measured - expected).abs();
    let scale = if expected == 0.0 { 1.0 } else { expected.abs() };
    println!(
        "{what}: measured {measured:.12e}, expected {expected:.12e}, rel. error {:.3e} (tolerance {rel:.1e})",
        err / scale
    );
    assert!(
        err <= rel * scale,
        "{what}: measured {measured:e}, expected {expected:e}, rel. error {:e} > {rel:e}",
        err / scale
    );
}

/// |measured − expected| ≤ abs.
#[track_caller]
pub fn assert_abs(what: &str, measured: f64, expected: f64, abs: f64) {
    let err = (measured - expected).abs();
    println!("{what}: measured {measured:.12e}, expected {expected:.12e}, abs. error {err:.3e} (tolerance {abs:.1e})");
    assert!(
        err <= abs,
        "{what}: measured {measured:e}, expected {expected:e}, abs. error {err:e} > {abs:e}"
    );
}

/// Mass of a disk of radius r and density ρ per unit depth: ρ π r².
pub fn disk_mass(density: f64, r: f64) -> f64 {
    density * std::f64::consts::PI * r * r
}

/// World-frame impulse on the candidate body i of contact a: r_n n + r_t t.
pub fn impulse_on_i(s: &Scene, a: usize) -> [f64; 2] {
    let c = &s.world.contacts;
    let (n, r) = (c.frame[a].n, c.r[a]);
    [r[0] * n[0] - r[1] * n[1], r[0] * n[1] + r[1] * n[0]]
}

/// Index of the contact between bodies p and q (either order), if any.
pub fn contact_between(s: &Scene, p: u32, q: u32) -> Option<usize> {
    let c = &s.world.contacts;
    (0..c.len()).find(|&a| c.bodies[a] == [p, q] || c.bodies[a] == [q, p])
}

/// Solves A x = b by Gaussian elimination with partial pivoting (small dense).
pub fn dense_solve(mut a: Vec<Vec<f64>>, mut b: Vec<f64>) -> Option<Vec<f64>> {
    let n = b.len();
    for c in 0..n {
        let p = (c..n).max_by(|&x, &y| a[x][c].abs().total_cmp(&a[y][c].abs()))?;
        if a[p][c].abs() < 1e-300 {
            return None;
        }
        a.swap(c, p);
        b.swap(c, p);
        for r in c + 1..n {
            let f = a[r][c] / a[c][c];
            for k in c..n {
                a[r][k] -= f * a[c][k];
            }
            b[r] -= f * b[c];
        }
    }
    let mut x = vec![0.0; n];
    for r in (0..n).rev() {
        let s: f64 = (r + 1..n).map(|k| a[r][k] * x[k]).sum();
        x[r] = (b[r] - s) / a[r][r];
    }
    Some(x)
}

/// The LCP `w = W r + q ≥ 0, r ≥ 0, wᵀ r = 0` by enumeration of the active sets
/// (fine for a handful of contacts): for each set J, solve W_JJ r_J = −q_J and
/// accept the first feasible one. With W symmetric positive definite the solution
/// is unique.
pub fn lcp_enumerate(w: &[Vec<f64>], q: &[f64]) -> Vec<f64> {
    let n = q.len();
    assert!(n <= 16, "enumeration is for small problems");
    let tol = 1e-12 * (1.0 + q.iter().map(|x| x.abs()).fold(0.0, f64::max));
    for mask in 0u32..(1 << n) {
        let act: Vec<usize> = (0..n).filter(|k| mask & (1 << k) != 0).collect();
        let a = act.iter().map(|&i| act.iter().map(|&j| w[i][j]).collect()).collect();
        let b = act.iter().map(|&i| -q[i]).collect();
        let Some(ra) = dense_solve(a, b) else { continue };
        let mut r = vec![0.0; n];
        for (k, &i) in act.iter().enumerate() {
            r[i] = ra[k];
        }
        let ok_r = r.iter().all(|&x| x >= -tol);
        let ok_w = (0..n).all(|i| (0..n).map(|j| w[i][j] * r[j]).sum::<f64>() + q[i] >= -tol);
        if ok_r && ok_w {
            return r;
        }
    }
    panic!("no solution of the LCP found");
}
