//! Tests of the 3D one-contact solver ([`super::coulomb3`]).

mod tests {
    use super::super::coulomb3::*;
    use crate::norms::natural_map_sq;

    /// Natural-map residual of a local solution, relative to |u0|.
    fn res(w: &Sym3, u0: [f64; 3], r: [f64; 3], mu: f64) -> f64 {
        let wr = mul(w, r);
        let u = [wr[0] + u0[0], wr[1] + u0[1], wr[2] + u0[2]];
        natural_map_sq(&r, &u, mu).sqrt() / (u0.iter().map(|x| x * x).sum::<f64>().sqrt())
    }

    #[test]
    fn sphere_cases() {
        let w = [2.0, 0.0, 0.0, 7.0, 0.0, 7.0];
        assert_eq!(solve(&w, [1.0, 3.0, 0.0], 0.0, 0.5), [0.0; 3]);
        // stick: |u0_t|/W_tt = 0.1 ≤ μ r_n = 0.5 × 1
        let r = solve(&w, [-2.0, 0.7, 0.0], 0.0, 0.5);
        assert!(r[0] == 1.0 && (r[1] + 0.1).abs() < 1e-16 && r[2] == 0.0, "{r:?}");
        // slide
        let r = solve(&w, [-2.0, 0.0, 70.0], 0.0, 0.5);
        assert_eq!(r, [1.0, 0.0, -0.5]);
        assert!(res(&w, [-2.0, 0.0, 70.0], r, 0.5) < 1e-15);
        // frictionless
        assert_eq!(solve(&w, [-2.0, 5.0, 1.0], 0.0, 0.0), [1.0, 0.0, 0.0]);
    }

    /// Random SPD blocks, random u0 and μ from 0 to 10: every case ends at a
    /// natural-map residual of round-off size.
    #[test]
    fn random_blocks_are_solved_exactly() {
        let mut seed = 12345u64;
        let mut rnd = || {
            seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            ((seed >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
        };
        let mut worst: f64 = 0.0;
        for k in 0..20000 {
            // W = AᵀA + εI
            let a: Vec<f64> = (0..9).map(|_| rnd()).collect();
            let m = |i: usize, j: usize| (0..3).map(|l| a[3 * l + i] * a[3 * l + j]).sum::<f64>() + if i == j { 0.05 } else { 0.0 };
            let mut w = [m(0, 0), m(0, 1), m(0, 2), m(1, 1), m(1, 2), m(2, 2)];
            if k % 3 == 0 {
                // decoupled normal
                w[1] = 0.0;
                w[2] = 0.0;
            }
            let u0 = [rnd(), rnd(), rnd()];
            let mu = [0.0, 0.1, 0.3, 1.0, 10.0][k % 5];
            let r = solve(&w, u0, 0.0, mu);
            let e = res(&w, u0, r, mu);
            worst = worst.max(e);
            assert!(e < 1e-9, "block {w:?}, u0 {u0:?}, μ {mu}: r {r:?}, residual {e}");
        }
        println!("worst relative natural-map residual {worst:e}");
    }

    #[test]
    fn disk_minimiser() {
        // isotropic: projection of −b/a on the circle
        let x = disk_min(2.0, 0.0, 2.0, [4.0, 0.0], 1.0).unwrap();
        assert!((x[0] + 1.0).abs() < 1e-15 && x[1].abs() < 1e-15);
    }
}

mod full_tests {
    use super::super::coulomb3::*;
    use crate::norms::natural_map_sq;

    /// Non-symmetric blocks (SPD plus a 1 % skew part), μ from 0 to 10.
    #[test]
    fn non_symmetric_blocks() {
        let mut seed = 777u64;
        let mut rnd = || {
            seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            ((seed >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
        };
        for k in 0..5000 {
            let a: Vec<f64> = (0..9).map(|_| rnd()).collect();
            let mut w = [[0.0; 3]; 3];
            for i in 0..3 {
                for j in 0..3 {
                    w[i][j] = (0..3).map(|l| a[3 * l + i] * a[3 * l + j]).sum::<f64>() + if i == j { 0.1 } else { 0.0 };
                }
            }
            for (i, j) in [(0, 1), (0, 2), (1, 2)] {
                let s = 0.01 * rnd();
                w[i][j] += s;
                w[j][i] -= s;
            }
            let u0 = [rnd(), rnd(), rnd()];
            let mu = [0.0, 0.2, 0.5, 1.0, 10.0][k % 5];
            let r = solve_full(&w, u0, 0.0, mu);
            let wr = w.mul(r);
            let u = [wr[0] + u0[0], wr[1] + u0[1], wr[2] + u0[2]];
            let e = natural_map_sq(&r, &u, mu).sqrt() / u0.iter().map(|x| x * x).sum::<f64>().sqrt();
            assert!(e < 1e-8, "block {w:?}, u0 {u0:?}, μ {mu}: r {r:?}, residual {e}");
        }
    }
}
