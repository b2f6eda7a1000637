//! Granular validation of the polygons plugin, loaded at run time: the packing
//! fraction and coordination of a frictionless deposit of pentagons against
//! published values, and NSCDD over polygons (with disks and walls) bitwise equal
//! for any number of threads.
mod common;
use common::{halfplane, scene};
use nscdd::dd::{DdSettings, Nscdd};

/// A deposit of `count` regular pentagons (circumradius 10 mm) in a box 0.4 m wide with
/// friction `mu` between grains and none on the walls (half-planes: floor, left,
/// right: bodies 0, 1, 2).
fn deposit(count: usize, mu: f64, h: f64, steps: usize) -> String {
    let mut text = format!(
        r#"[time]
step = {h}
# θ = 1: an impact leaves no overlap ((1 − θ) h v⁻ with θ = 1/2, up to 1 mm here)
theta = 1.0
steps = {steps}
[solver]
tolerance = 1.666e-4
ordering = "shuffled"
seed = 3
[detection]
# the grains fall at up to 3 m/s: 3 mm a step, which the alert distance must
# cover so that no contact is found late (already overlapping)
alert = 0.004
[[materials]]
name = "grain"
density = 2600.0
[[materials]]
name = "ground"
density = 2600.0
[[laws]]
materials = ["grain", "grain"]
friction = {mu}
[[laws]]
materials = ["grain", "ground"]
friction = 0.0
[[laws]]
materials = ["ground", "ground"]
law = "none"
"#
    );
    text += &halfplane([0.0, 0.0], 0.0);
    text += &halfplane([0.0, 0.0], -std::f64::consts::FRAC_PI_2);
    text += &halfplane([0.4, 0.0], std::f64::consts::FRAC_PI_2);
    text += &format!(
        "[[generate]]\nkind = \"polygon_deposit\"\nmaterial = \"grain\"\ncount = {count}\nsides = 5\nradius_min = 0.01\nradius_max = 0.01\nbox = [0.0, 0.0, 0.4, 2.0]\nseed = 7\n"
    );
    text
}

/// The area of a convex polygon inside the rectangle [x0, y0, x1, y1]
/// (Sutherland–Hodgman clipping, then the shoelace formula).
fn area_in(poly: &[[f64; 2]], win: [f64; 4]) -> f64 {
    let mut p = poly.to_vec();
    // each side of the window as (axis, bound, keep below)
    for (k, bound, below) in [(0, win[0], false), (0, win[2], true), (1, win[1], false), (1, win[3], true)] {
        let inside = |q: &[f64; 2]| if below { q[k] <= bound } else { q[k] >= bound };
        let mut out = vec![];
        for m in 0..p.len() {
            let (a, b) = (p[m], p[(m + 1) % p.len()]);
            if inside(&a) {
                out.push(a);
            }
            if inside(&a) != inside(&b) {
                let t = (bound - a[k]) / (b[k] - a[k]);
                out.push([a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])]);
            }
        }
        p = out;
        if p.is_empty() {
            return 0.0;
        }
    }
    0.5 * (0..p.len())
        .map(|m| p[m][0] * p[(m + 1) % p.len()][1] - p[(m + 1) % p.len()][0] * p[m][1])
        .sum::<f64>()
}

#[test]
fn a_frictionless_pentagon_deposit_is_dense_and_isostatic() {
    let (n, h, steps) = (400, 1e-3, 4000);
    let mut s = scene(&deposit(n, 0.0, h, steps));
    for _ in 0..steps {
        s.world.step().unwrap();
    }
    let w = &s.world;
    let grains = 3..w.bodies.len();
    let ke: f64 = grains
        .clone()
        .map(|b| 0.5 * (w.bodies.vel[b][0].powi(2) + w.bodies.vel[b][1].powi(2)))
        .sum();
    let top = grains.clone().map(|b| w.bodies.pos[b][1]).fold(0.0, f64::max);
    // a window 2.5 diameters from the side walls and the free surface, 1.5 from the floor
    let win = [0.05, 0.03, 0.35, top - 0.05];
    let inside = |b: usize| {
        let x = w.bodies.pos[b];
        x[0] > win[0] && x[0] < win[2] && x[1] > win[1] && x[1] < win[3]
    };
    // the grains' area inside the window (their polygons, as drawn, clipped to it)
    let area: f64 = grains
        .clone()
        .map(|b| {
            let shape = w.bodies.shape[b];
            match w.shapes[shape.kind as usize].glyph(shape.index, w.bodies.pos[b], w.bodies.rot[b]) {
                nscdd::registry::Glyph2::Polygon(p) => area_in(&p, win),
                g => panic!("a polygon is drawn as a polygon, not {g:?}"),
            }
        })
        .sum();
    let phi = area / ((win[2] - win[0]) * (win[3] - win[1]));
    // force-bearing contact points per grain (a side-to-side contact counts twice,
    // as its two points), grains with fewer than two (rattlers) left out
    let mut points = vec![0usize; w.bodies.len()];
    let fmax = w.contacts.r.iter().map(|r| r[0]).fold(0.0, f64::max);
    for k in 0..w.contacts.len() {
        if w.contacts.r[k][0] > 1e-9 * fmax {
            for b in w.contacts.bodies[k] {
                points[b as usize] += 1;
            }
        }
    }
    let carrying: Vec<usize> = grains.clone().filter(|&b| inside(b) && points[b] >= 2).collect();
    let zc = carrying.iter().map(|&b| points[b]).sum::<usize>() as f64 / carrying.len() as f64;
    let rattlers = grains.filter(|&b| inside(b)).count() - carrying.len();
    println!(
        "{n} frictionless pentagons after {steps} steps: kinetic energy {ke:.2e} J/kg·m², packing height {top:.3} m, \
         packing fraction {phi:.4} in the window, {zc:.3} contact points per grain ({} grains, {rattlers} rattlers)",
        carrying.len()
    );
    let gmin = w.contacts.gap.iter().fold(0.0f64, |m, g| m.min(*g));
    println!("smallest gap {gmin:.2e} m");
    assert!(ke < 1e-4, "settled: {ke}");
    // Shubin (2025, Rasplavy no. 1, doi:10.31857/S0235010625010025): random
    // packings of regular pentagons compacted without friction jam at 0.838 ± 0.002.
    // Here they are deposited under gravity; the overlaps that velocity-level
    // stepping lets spinning frictionless grains accumulate (smallest gap −3.6 % of
    // the radius) add ≲ 1 %.
    assert!((phi - 0.838).abs() < 0.02, "packing fraction {phi}");
    assert!(gmin > -0.05 * 0.01, "overlaps stay below 5 % of the radius: {gmin}");
    // frictionless rigid polygons are isostatic: 3 constraints per grain, 6 contact
    // points per grain (CEGEO, Saint-Cyr et al. 2012: Zc ≃ 6 counting side-to-side
    // contacts twice)
    assert!((zc - 6.0).abs() < 0.3, "contact points per grain {zc}");
}

/// 120 random convex polygons (5 or 6 sides, irregularity 0.4, μ = 0.4) and 12
/// disks above them, in a box of walls (the disks plugin's `wall`, bodies 0–2),
/// settled 300 steps by NLGS: every detector of the plugin is at work.
fn mixed() -> nscdd::scene::Scene<nscdd::dim::D2> {
    let mut text = String::from(
        r#"[time]
step = 1e-3
steps = 300
[solver]
tolerance = 1.666e-4
[detection]
alert = 0.003
[[materials]]
name = "grain"
density = 2600.0
[[laws]]
materials = ["grain", "grain"]
friction = 0.4
[[bodies]]
shape = "wall"
material = "grain"
position = [0.15, -0.01]
length = 0.34
thickness = 0.02
fixed = true
[[bodies]]
shape = "wall"
material = "grain"
position = [-0.01, 0.25]
rotation = 1.5707963267948966
length = 0.5
thickness = 0.02
fixed = true
[[bodies]]
shape = "wall"
material = "grain"
position = [0.31, 0.25]
rotation = 1.5707963267948966
length = 0.5
thickness = 0.02
fixed = true
[[generate]]
kind = "polygon_deposit"
material = "grain"
count = 120
sides = 5
sides_max = 6
irregularity = 0.4
radius_min = 0.008
radius_max = 0.012
box = [0.0, 0.0, 0.3, 0.3]
seed = 11
"#,
    );
    for k in 0..12 {
        text += &format!(
            "[[bodies]]\nshape = \"disk\"\nmaterial = \"grain\"\nradius = 0.008\nposition = [{}, 0.33]\n",
            0.015 + 0.025 * k as f64
        );
    }
    let mut s = scene(&text);
    for _ in 0..300 {
        s.world.step().unwrap();
    }
    s
}

fn bits<const N: usize>(v: &[[f64; N]]) -> Vec<[u64; N]> {
    v.iter().map(|x| x.map(f64::to_bits)).collect()
}

#[test]
fn nscdd_over_polygons_disks_and_walls_is_bitwise_equal_for_any_thread_count() {
    let settled = mixed();
    let w = &settled.world;
    let kind = |b: u32| w.shapes[w.bodies.shape[b as usize].kind as usize].kind();
    let mut pairs = std::collections::BTreeMap::<(&str, &str), usize>::new();
    for k in 0..w.contacts.len() {
        let [i, j] = w.contacts.bodies[k];
        *pairs.entry((kind(i), kind(j))).or_default() += 1;
    }
    println!("contacts by kinds after settling: {pairs:?}");
    for p in [("polygon", "polygon"), ("polygon", "wall"), ("polygon", "disk")] {
        assert!(pairs.get(&p).copied().unwrap_or(0) > 0, "no {p:?} contact");
    }
    let run = |threads: usize| {
        let mut s = mixed();
        let mut n = Nscdd::new(DdSettings {
            nx: 2,
            ny: 2,
            threads,
            ..Default::default()
        });
        for _ in 0..3 {
            let rep = n.step(&mut s.world).unwrap();
            assert!(rep.solve.converged, "{rep:?}");
            assert!(rep.subdomains == 4 && rep.interface_bodies > 0, "{rep:?}");
        }
        s.world
    };
    let one = run(1);
    for t in [2, 3] {
        let other = run(t);
        assert_eq!(bits(&one.bodies.pos), bits(&other.bodies.pos), "{t} threads: positions");
        assert_eq!(bits(&one.bodies.vel), bits(&other.bodies.vel), "{t} threads: velocities");
        assert_eq!(bits(&one.contacts.r), bits(&other.contacts.r), "{t} threads: impulses");
    }
}
