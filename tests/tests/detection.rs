//! The cell-grid broad phase finds exactly the contacts a brute-force search finds,
//! including with radii spread 1:100, long walls and half-planes.

use nscdd::scene::load_str;
use rand::{RngExt, SeedableRng};
use std::collections::BTreeSet;

fn scene(disks: &[([f64; 2], f64)], alert: f64) -> String {
    let mut s = format!(
        "gravity = [0.0, -9.81]\n[time]\nstep = 1e-3\nsteps = 1\n[detection]\nalert = {alert}\noverlap_tolerance = 1e9\n\
         [[materials]]\nname = \"m\"\ndensity = 1000.0\n[[laws]]\nmaterials = [\"m\", \"m\"]\nfriction = 0.3\n\
         [[bodies]]\nshape = \"wall\"\nmaterial = \"m\"\nposition = [0.5, -0.05]\nlength = 1.2\nthickness = 0.1\nfixed = true\n\
         [[bodies]]\nshape = \"halfplane\"\nmaterial = \"m\"\nposition = [1.0, 0.0]\nrotation = 1.5707963267948966\nfixed = true\n"
    );
    for (x, r) in disks {
        s.push_str(&format!(
            "[[bodies]]\nshape = \"disk\"\nmaterial = \"m\"\nposition = [{}, {}]\nradius = {r}\n",
            x[0], x[1]
        ));
    }
    s
}

/// Pairs (i, j) whose gap is below `alert`, by brute force (disks: ids from 2).
fn brute(disks: &[([f64; 2], f64)], alert: f64) -> BTreeSet<(u32, u32)> {
    let mut out = BTreeSet::new();
    for (a, (xa, ra)) in disks.iter().enumerate() {
        let ia = a as u32 + 2;
        if xa[1] - ra - 0.0 <= alert {
            out.insert((ia, 0)); // the wall's top face is y = 0 for 0 ≤ x ≤ 1 (x within the wall)
        }
        // half-plane: x ≤ 1 is solid? rotation π/2 turns the normal to (−1, 0): solid for x ≥ 1
        if (1.0 - xa[0]) - ra <= alert {
            out.insert((ia, 1));
        }
        for (b, (xb, rb)) in disks.iter().enumerate().skip(a + 1) {
            let d = ((xa[0] - xb[0]).powi(2) + (xa[1] - xb[1]).powi(2)).sqrt();
            if d - ra - rb <= alert {
                out.insert((ia, b as u32 + 2));
            }
        }
    }
    out
}

fn detected(text: &str) -> BTreeSet<(u32, u32)> {
    let reg = nscdd_rigid_disks::registry();
    let mut s = load_str(text, "detect.toml", &reg).unwrap_or_else(|e| panic!("{e}"));
    s.world.step().unwrap();
    let c = &s.world.contacts;
    (0..c.len())
        .map(|a| (c.bodies[a][0].max(c.bodies[a][1]), c.bodies[a][0].min(c.bodies[a][1])))
        .map(|(i, j)| if j < 2 { (i, j) } else { (j, i) })
        .collect()
}

fn check(disks: Vec<([f64; 2], f64)>, alert: f64) {
    let want: BTreeSet<(u32, u32)> = brute(&disks, alert)
        .into_iter()
        .map(|(i, j)| if j < 2 { (i, j) } else { (i.min(j), i.max(j)) })
        .collect();
    let got: BTreeSet<(u32, u32)> = detected(&scene(&disks, alert))
        .into_iter()
        .map(|(i, j)| if j < 2 { (i, j) } else { (i.min(j), i.max(j)) })
        .collect();
    assert_eq!(
        got.len(),
        want.len(),
        "missing: {:?}\nextra: {:?}",
        want.difference(&got).take(5).collect::<Vec<_>>(),
        got.difference(&want).take(5).collect::<Vec<_>>()
    );
    assert_eq!(got, want);
}

#[test]
fn grid_matches_brute_force_polydisperse() {
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(3);
    let disks: Vec<_> = (0..1500)
        .map(|_| {
            let r = rng.random_range(0.004..0.012);
            ([rng.random_range(0.0..1.0), rng.random_range(0.0..0.6)], r)
        })
        .collect();
    check(disks, 0.003);
}

#[test]
fn grid_matches_brute_force_radii_spread_1_to_100() {
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(4);
    let mut disks: Vec<_> = (0..800)
        .map(|_| ([rng.random_range(0.0..1.0), rng.random_range(0.0..1.0)], 0.002))
        .collect();
    disks.extend((0..6).map(|_| ([rng.random_range(0.0..1.0), rng.random_range(0.0..1.0)], 0.2)));
    check(disks, 0.001);
}
