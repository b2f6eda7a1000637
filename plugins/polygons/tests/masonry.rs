//! Masonry validation of the polygons plugin, loaded at run time: a block on an
//! incline slides with a = g (sin α − μ cos α) or overturns at α* = atan(b/h) when
//! b/h < μ, a stack of bricks carries the weights above each joint, a
//! semicircular arch of voussoirs stands above its limit thickness and collapses
//! below it.
mod common;
use common::{block, carried, halfplane, head, scene};

const G: f64 = 9.81;

/// A b × h block resting on an incline of angle `alpha` (a half-plane turned by
/// α, the block turned with it, touching): returns the scene after `steps` steps
/// of 1 ms, with the block as body 1.
fn incline(alpha: f64, mu: f64, b: f64, h: f64, steps: usize) -> nscdd::scene::Scene<nscdd::dim::D2> {
    let n = [-alpha.sin(), alpha.cos()];
    let mut text = head(1e-3, steps, mu);
    text += &halfplane([0.0, 0.0], alpha);
    text += &block([0.5 * h * n[0], 0.5 * h * n[1]], [b, h], alpha, "stone");
    let mut s = scene(&text);
    for _ in 0..steps {
        assert!(s.world.step().unwrap().solve.converged);
    }
    s
}

#[test]
fn a_block_slides_down_an_incline_with_a_equal_g_sin_minus_mu_cos() {
    let (alpha, mu) = (30f64.to_radians(), 0.3);
    let s = incline(alpha, mu, 0.2, 0.1, 200);
    let w = &s.world;
    let t = 200.0 * 1e-3;
    let down = [-alpha.cos(), -alpha.sin()];
    let v = w.bodies.vel[1];
    let along = v[0] * down[0] + v[1] * down[1];
    let a = G * (alpha.sin() - mu * alpha.cos());
    println!(
        "α = 30°, μ = 0.3: v = {along:.9} m/s after {t} s, a t = {:.9}; ω = {:.2e}",
        a * t,
        v[2]
    );
    assert!((along - a * t).abs() < 1e-6 * a * t, "sliding velocity {along} vs a t = {}", a * t);
    assert!(v[2].abs() < 1e-6, "the block does not turn: ω = {}", v[2]);
    let (_, points) = carried(w, 1, 0);
    assert_eq!(points, 2, "the block's face rests on two points");
    // μ above tan α: it sticks
    let s = incline(alpha, 0.7, 0.2, 0.1, 200);
    let v = s.world.bodies.vel[1];
    assert!(v[0].abs() + v[1].abs() + v[2].abs() < 1e-6, "sticks: {v:?}");
}

#[test]
fn a_slender_block_overturns_at_atan_b_over_h_before_it_can_slide() {
    // b/h = 0.4 < μ = 0.8: the block tips over its downhill corner once tan α > b/h
    let (b, h, mu): (f64, f64, f64) = (0.1, 0.25, 0.8);
    let star = (b / h).atan();
    let turned = |alpha: f64| {
        let s = incline(alpha, mu, b, h, 400);
        let w = &s.world;
        (w.bodies.rot[1] - alpha, w.bodies.vel[1])
    };
    let (below, vb) = turned(star - 1f64.to_radians());
    let (above, va) = turned(star + 1f64.to_radians());
    println!(
        "α* = {:.2}°: 1° below turned {below:.2e} rad, 1° above {above:.2e} rad (ω {:.3})",
        star.to_degrees(),
        va[2]
    );
    assert!(below.abs() < 1e-6 && vb[2].abs() < 1e-6, "stands 1° below α*: {below}");
    assert!(above.abs() > 0.05, "overturns 1° above α*: {above}");
    // it tips downhill: the slope rises to the right, so about its lower left
    // corner, counter-clockwise
    assert!(above > 0.0);
}

/// A stack of `n` bricks 0.2 × 0.05 on a floor (μ = 0.5): brick k is body k + 1.
#[test]
fn a_stack_of_bricks_carries_k_m_g_at_each_joint() {
    let (l, h, n) = (0.2, 0.05, 4);
    let mut text = head(1e-3, 200, 0.5);
    text += &halfplane([0.0, 0.0], 0.0);
    for k in 0..n {
        // every other brick shifted by a quarter brick
        let x = if k % 2 == 1 { 0.25 * l } else { 0.0 };
        text += &block([x, (k as f64 + 0.5) * h], [l, h], 0.0, "stone");
    }
    let mut s = scene(&text);
    for _ in 0..200 {
        assert!(s.world.step().unwrap().solve.converged);
    }
    let weight = 2000.0 * l * h * G;
    for k in 0..n {
        let (f, points) = carried(&s.world, k, k + 1);
        let above = (n - k) as f64;
        println!(
            "joint under brick {k}: {points} points carry {f:.9} N (exact {:.9} N)",
            above * weight
        );
        assert_eq!(points, 2, "a face-to-face joint has 2 points");
        assert!((f - above * weight).abs() < 1e-6 * above * weight, "{f} vs {}", above * weight);
    }
}

/// Largest displacement of the voussoirs of a 24-voussoir semicircular arch of
/// thickness ratio t/R (R = 1 m, μ = 1: no sliding) after `steps` steps of 1 ms.
fn arch(t_over_r: f64, steps: usize) -> f64 {
    let mut text = head(1e-3, steps, 1.0).replace("tolerance = 1e-6", "tolerance = 1e-5");
    text += &format!(
        "[[generate]]\nkind = \"arch_2d\"\nmaterial = \"stone\"\nsupport_material = \"ground\"\nradius = 1.0\nthickness = {t_over_r}\nvoussoirs = 24\n"
    );
    let mut s = scene(&text);
    let x0 = s.world.bodies.pos.clone();
    for _ in 0..steps {
        s.world.step().unwrap();
    }
    let w = &s.world;
    (0..24)
        .map(|b| ((w.bodies.pos[b][0] - x0[b][0]).powi(2) + (w.bodies.pos[b][1] - x0[b][1]).powi(2)).sqrt())
        .fold(0.0, f64::max)
}

/// Heyman's minimum thickness of a semicircular arch with radial joints is
/// t/R ≈ 0.1075 (a five-hinge mechanism below it).
#[test]
fn an_arch_stands_at_t_over_r_012_and_collapses_at_009() {
    let stand = arch(0.12, 800);
    let fall = arch(0.09, 800);
    println!("largest voussoir displacement after 0.8 s: t/R = 0.12: {stand:.3e} m, t/R = 0.09: {fall:.3e} m");
    assert!(stand < 1e-3, "t/R = 0.12 should stand: {stand}");
    assert!(fall > 2e-2, "t/R = 0.09 should collapse: {fall}");
}
