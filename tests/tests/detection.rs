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

/// Detection restricted to a region (what a rank will detect once ranks hold only
/// their part): the whole detection's list restricted, in the same order; every
/// contact whose point is in the region; and the pairs the region names, wherever
/// they are.
#[test]
fn detection_in_a_region_is_the_whole_list_restricted() {
    use nscdd::detect::{Detector, Region};
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(5);
    let mut disks: Vec<_> = (0..1200)
        .map(|_| {
            (
                [rng.random_range(0.0..1.0), rng.random_range(0.0..0.6)],
                rng.random_range(0.004..0.012),
            )
        })
        .collect();
    disks.extend((0..4).map(|_| ([rng.random_range(0.0..1.0), rng.random_range(0.0..0.6)], 0.1)));
    let reg = nscdd_rigid_disks::registry();
    let s = load_str(&scene(&disks, 0.003), "detect.toml", &reg).unwrap_or_else(|e| panic!("{e}"));
    let w = &s.world;
    let key = |c: &nscdd::shape::RawContact<nscdd::dim::D2>| (c.i, c.j, c.feature);
    let mut all = Vec::new();
    Detector::default().detect(&w.bodies, &w.shapes, &w.detectors, w.alert, &mut all);
    assert!(all.len() > 1000, "{}", all.len());
    let inf = f64::INFINITY;
    // two cells of a 2 × 2 grid at x = 0.5, y = 0.3 (edge cells unbounded), and a far pair
    let far = all
        .iter()
        .find(|c| c.point[0] > 0.8 && c.point[1] > 0.5 && c.j > 1)
        .map(|c| [c.i.min(c.j), c.i.max(c.j)]);
    let region = Region {
        boxes: vec![[[-inf, -inf, 0.0], [0.5, 0.3, 0.0]], [[0.5, 0.3, 0.0], [inf, inf, 0.0]]],
        pairs: far.into_iter().collect(),
    };
    let inside = |p: &[f64; 2]| (p[0] <= 0.5 && p[1] <= 0.3) || (p[0] >= 0.5 && p[1] >= 0.3);
    let mut part = Vec::new();
    let mut det = Detector::default();
    det.detect_in(&w.bodies, &w.shapes, &w.detectors, w.alert, Some(&region), &mut part);
    // a subsequence of the whole list, each contact identical
    let mut k = 0;
    for c in &part {
        while k < all.len() && key(&all[k]) != key(c) {
            k += 1;
        }
        assert!(k < all.len(), "{:?} not in the whole list (or out of order)", key(c));
        assert_eq!(&all[k], c);
    }
    // every contact whose point is in the region, and the named pair
    for c in all.iter().filter(|c| inside(&c.point)) {
        assert!(part.iter().any(|x| key(x) == key(c)), "{:?} at {:?} missed", key(c), c.point);
    }
    let far = far.expect("a contact in the far corner");
    assert!(part.iter().any(|c| [c.i.min(c.j), c.i.max(c.j)] == far));
    let kept = part.len() as f64 / all.len() as f64;
    assert!(kept < 0.65, "the region keeps {kept} of the contacts");
    // the same detector again, everywhere: the whole list
    det.detect(&w.bodies, &w.shapes, &w.detectors, w.alert, &mut part);
    assert_eq!(part, all);
}
