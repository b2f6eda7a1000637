//! Generators: a deposit of random convex polygons, a running-bond brick wall and
//! a semicircular arch of radial voussoirs (2D). All take `material`; the random
//! one takes `seed` and gives the same sample for the same seed on every machine
//! (ChaCha8).

use crate::shapes::{regular, Polygons, MAX_VERTICES};
use nscdd::dim::D2;
use nscdd::model::ShapeRef;
use nscdd::params::{array, boolean, count, number, only_keys, positive};
use nscdd::registry::{Generator, ParamError};
use nscdd::scene::builder::SceneBuilder2;
use rand::{RngExt, SeedableRng};
use std::f64::consts::PI;

/// Adds a polygon body whose vertices are `points` about `at` (the body's
/// position becomes the centroid).
pub fn add_polygon(out: &mut SceneBuilder2<'_>, points: &[[f64; 2]], at: [f64; 2], material: u16) -> Result<u32, ParamError> {
    let kind = out
        .kind(Polygons::KIND)
        .ok_or_else(|| ParamError::new("kind", "the polygon shape kind is not installed"))?;
    let store = out
        .store_mut::<Polygons>(kind)
        .ok_or_else(|| ParamError::new("kind", "the polygon store is not this plugin's"))?;
    let index = store.push_points(points).map_err(|m| ParamError::new("kind", m))?;
    Ok(out.add_body(ShapeRef { kind, index }, material, at, 0.0, [0.0; 3]))
}

/// The corners of the rectangle [lo, hi].
pub fn rectangle(lo: [f64; 2], hi: [f64; 2]) -> Vec<[f64; 2]> {
    vec![lo, [hi[0], lo[1]], hi, [lo[0], hi[1]]]
}

/// `polygon_deposit`: `count` convex polygons of `sides` sides (or a number drawn
/// in [`sides`, `sides_max`]) and circumradius uniform in [`radius_min`,
/// `radius_max`], in `box` = [x0, y0, x1, y1]: on a grid of cells 2.1 r_max wide,
/// row after row from the bottom, each turned at random and shifted at random in
/// its cell (no two overlap). `irregularity` ∈ [0, 1) (default 0: regular
/// polygons) moves each vertex's angle by up to ± irregularity × π / n, which gives
/// random convex polygons. Let them fall and settle under gravity (LMGC90's POLYG
/// deposits are built the same way). Fails if the box cannot hold `count`.
pub struct PolygonDeposit;

impl Generator<D2> for PolygonDeposit {
    fn generate(&self, p: &toml::Table, out: &mut SceneBuilder2<'_>) -> Result<(), ParamError> {
        only_keys(
            p,
            &[
                "kind",
                "material",
                "count",
                "sides",
                "sides_max",
                "radius_min",
                "radius_max",
                "box",
                "seed",
                "irregularity",
            ],
        )?;
        let material = out.material_param(p, "material")?;
        let n = count(p, "count", None)? as usize;
        let sides = count(p, "sides", None)? as usize;
        let sides_max = count(p, "sides_max", Some(sides as u64))? as usize;
        if !(3..=MAX_VERTICES).contains(&sides) || !(sides..=MAX_VERTICES).contains(&sides_max) {
            return Err(ParamError::new(
                "sides",
                format!("3 ≤ sides ≤ sides_max ≤ {MAX_VERTICES}, got {sides} and {sides_max}"),
            ));
        }
        let rmin = positive(p, "radius_min", None)?;
        let rmax = positive(p, "radius_max", Some(rmin))?;
        if rmax < rmin {
            return Err(ParamError::new("radius_max", "must be ≥ radius_min"));
        }
        let irr = number(p, "irregularity", Some(0.0))?;
        if !(0.0..1.0).contains(&irr) {
            return Err(ParamError::new("irregularity", format!("must be in [0, 1), got {irr}")));
        }
        let [x0, y0, x1, y1] = array::<4>(p, "box", None)?;
        let cell = 2.1 * rmax;
        let cols = ((x1 - x0) / cell).floor();
        if !(cols >= 1.0) || !(y1 > y0) {
            return Err(ParamError::new(
                "box",
                format!("the box [x0, y0, x1, y1] must be wider than a cell (2.1 radius_max = {cell}) and have y1 > y0"),
            ));
        }
        let rows = ((y1 - y0) / cell).floor();
        if (n as f64) > cols * rows {
            return Err(ParamError::new(
                "count",
                format!("the box holds only {} of the {n} polygons asked: make it taller", cols * rows),
            ));
        }
        out.reserve("count", n as f64, 0.0)?;
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(count(p, "seed", Some(0))?);
        let cols = cols as usize;
        for k in 0..n {
            let r = if rmax > rmin { rng.random_range(rmin..rmax) } else { rmin };
            let m = if sides_max > sides {
                rng.random_range(sides..=sides_max)
            } else {
                sides
            };
            let phase = rng.random_range(0.0..2.0 * PI);
            let mut v = regular(m, r, phase);
            if irr > 0.0 {
                for (q, x) in v.iter_mut().enumerate() {
                    let a = -0.5 * PI - PI / m as f64 + phase + 2.0 * PI * (q as f64 + irr * rng.random_range(-0.5..0.5)) / m as f64;
                    *x = [r * a.cos(), r * a.sin()];
                }
            }
            let slack = 0.5 * cell - r;
            let jitter = [rng.random_range(-slack..=slack), rng.random_range(-slack..=slack)];
            let (row, col) = (k / cols, k % cols);
            let c = [
                x0 + (col as f64 + 0.5) * cell + jitter[0],
                y0 + (row as f64 + 0.5) * cell + jitter[1],
            ];
            add_polygon(out, &v, c, material)?;
        }
        Ok(())
    }
}

/// `brick_wall_2d`: `courses` courses of `bricks` bricks of size `brick` = [L, H]
/// in running bond (odd courses start and end with a half brick), from `origin`
/// (the wall's lower left corner); `base_material` adds a fixed base block under
/// it (2L wider than the wall on each side, H thick).
pub struct BrickWall2d;

impl Generator<D2> for BrickWall2d {
    fn generate(&self, p: &toml::Table, out: &mut SceneBuilder2<'_>) -> Result<(), ParamError> {
        only_keys(p, &["kind", "material", "brick", "courses", "bricks", "origin", "base_material"])?;
        let material = out.material_param(p, "material")?;
        let [l, h] = array::<2>(p, "brick", None)?;
        if !(l > 0.0 && h > 0.0 && l.is_finite() && h.is_finite()) {
            return Err(ParamError::new("brick", "2 positive sizes [L, H]"));
        }
        let (courses, n) = (count(p, "courses", None)?, count(p, "bricks", None)?);
        out.reserve("courses", courses as f64 * (n as f64 + 1.0), 0.0)?;
        let o = array::<2>(p, "origin", Some([0.0; 2]))?;
        if p.contains_key("base_material") {
            let bm = out.material_param(p, "base_material")?;
            let lo = [o[0] - 2.0 * l, o[1] - h];
            let hi = [o[0] + (n as f64 + 2.0) * l, o[1]];
            let b = add_polygon(out, &rectangle(lo, hi), [0.0; 2], bm)?;
            out.set_fixed(b);
        }
        for c in 0..courses {
            let y = o[1] + c as f64 * h;
            let mut cuts = vec![0.0];
            let shift = if c % 2 == 1 { 0.5 * l } else { l };
            let mut x = shift;
            while x < n as f64 * l - 1e-9 * l {
                cuts.push(x);
                x += l;
            }
            cuts.push(n as f64 * l);
            for s in cuts.windows(2) {
                add_polygon(out, &rectangle([o[0] + s[0], y], [o[0] + s[1], y + h]), [0.0; 2], material)?;
            }
        }
        Ok(())
    }
}

/// `arch_2d`: a semicircular arch of `voussoirs` radial voussoirs of mean radius
/// `radius` and `thickness` (t/R is the thickness ratio), centred on `origin` (the
/// springing line at y = origin y), voussoir k spanning the angles
/// [π k/n, π (k + 1)/n] from the right springing; on two fixed supports of
/// `support_material` (blocks under the springers, t thick), or, with
/// `supports = false`, on whatever the scene puts there.
pub struct Arch2d;

impl Generator<D2> for Arch2d {
    fn generate(&self, p: &toml::Table, out: &mut SceneBuilder2<'_>) -> Result<(), ParamError> {
        only_keys(
            p,
            &[
                "kind",
                "material",
                "support_material",
                "radius",
                "thickness",
                "voussoirs",
                "origin",
                "supports",
            ],
        )?;
        let material = out.material_param(p, "material")?;
        let supports = boolean(p, "supports", Some(true))?;
        let r = positive(p, "radius", None)?;
        let t = positive(p, "thickness", None)?;
        if t >= 2.0 * r {
            return Err(ParamError::new("thickness", "must be below twice the radius"));
        }
        let n = count(p, "voussoirs", None)?;
        if n == 0 {
            return Err(ParamError::new("voussoirs", "at least 1"));
        }
        out.reserve("voussoirs", n as f64, 0.0)?;
        let o = array::<2>(p, "origin", Some([0.0; 2]))?;
        let (ri, re) = (r - 0.5 * t, r + 0.5 * t);
        for k in 0..n {
            let mut pts = vec![];
            for a in [k as f64, k as f64 + 1.0].map(|x| PI * x / n as f64) {
                for rr in [ri, re] {
                    pts.push([o[0] + rr * a.cos(), o[1] + rr * a.sin()]);
                }
            }
            add_polygon(out, &pts, [0.0; 2], material)?;
        }
        if supports {
            let sm = out.material_param(p, "support_material")?;
            for (x0, x1) in [(o[0] + ri - t, o[0] + re + t), (o[0] - re - t, o[0] - ri + t)] {
                let b = add_polygon(out, &rectangle([x0, o[1] - t], [x1, o[1]]), [0.0; 2], sm)?;
                out.set_fixed(b);
            }
        }
        Ok(())
    }
}
