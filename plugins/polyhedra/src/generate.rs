//! Masonry generators: a running-bond brick wall, a semicircular arch of radial
//! voussoirs on two fixed supports, and a tilting table.

use crate::shapes::Polyhedra;
use nscdd::dim::D3;
use nscdd::drive::{DofDrive, Phase, Shape, TimeFn};
use nscdd::model::ShapeRef;
use nscdd::params::{array, boolean, count, number, only_keys, positive};
use nscdd::registry::Generator;
use nscdd::registry::ParamError;
use nscdd::scene::builder::SceneBuilder3;

/// The 8 corners of a box [lo, hi].
pub fn box_points(lo: [f64; 3], hi: [f64; 3]) -> Vec<[f64; 3]> {
    let mut v = vec![];
    for x in [lo[0], hi[0]] {
        for y in [lo[1], hi[1]] {
            for z in [lo[2], hi[2]] {
                v.push([x, y, z]);
            }
        }
    }
    v
}

/// Adds a polyhedron body from world points (its pose: centroid, principal axes).
pub fn add_points(out: &mut SceneBuilder3<'_>, points: &[[f64; 3]], material: u16, fixed: bool) -> Result<u32, ParamError> {
    let kind = out.kind(Polyhedra::KIND).expect("the plugin registers polyhedra");
    let index = out
        .store_mut::<Polyhedra>(kind)
        .expect("polyhedron store")
        .push_points(points)
        .map_err(|m| ParamError::new("kind", m))?;
    let b = out.add_body(ShapeRef { kind, index }, material, [0.0; 3], [0.0; 3], [0.0; 6]);
    if fixed {
        out.set_fixed(b);
    }
    Ok(b)
}

/// `brick_wall`: `courses` courses of `bricks` bricks of size `brick` = [L, W, H]
/// (x, y, z) in running bond (odd courses start and end with a half brick), from
/// `origin` (the wall's lower front-left corner); `base_material` adds a fixed
/// base slab under it (2L wider than the wall, H thick).
pub struct BrickWall;

impl Generator<D3> for BrickWall {
    fn generate(&self, p: &toml::Table, out: &mut SceneBuilder3<'_>) -> Result<(), ParamError> {
        only_keys(p, &["kind", "material", "brick", "courses", "bricks", "origin", "base_material"])?;
        let material = out.material_param(p, "material")?;
        let [l, w, h] = array::<3>(p, "brick", None)?;
        if ![l, w, h].iter().all(|x| *x > 0.0 && x.is_finite()) {
            return Err(ParamError::new("brick", "3 positive sizes [L, W, H]"));
        }
        let (courses, n) = (count(p, "courses", None)?, count(p, "bricks", None)?);
        out.reserve("courses", courses as f64 * (n as f64 + 1.0), 0.0)?;
        let o = array::<3>(p, "origin", Some([0.0; 3]))?;
        if p.contains_key("base_material") {
            let bm = out.material_param(p, "base_material")?;
            let lo = [o[0] - l, o[1] - l, o[2] - h];
            let hi = [o[0] + (n as f64 + 1.0) * l, o[1] + w + l, o[2]];
            add_points(out, &box_points(lo, hi), bm, true)?;
        }
        for c in 0..courses {
            let z0 = o[2] + c as f64 * h;
            let mut cuts = vec![0.0];
            if c % 2 == 1 {
                cuts.push(0.5 * l);
                for k in 1..n {
                    cuts.push((k as f64 + 0.5) * l);
                }
            } else {
                for k in 1..n {
                    cuts.push(k as f64 * l);
                }
            }
            cuts.push(n as f64 * l);
            for s in cuts.windows(2) {
                let lo = [o[0] + s[0], o[1], z0];
                let hi = [o[0] + s[1], o[1] + w, z0 + h];
                add_points(out, &box_points(lo, hi), material, false)?;
            }
        }
        Ok(())
    }
}

/// `arch`: a semicircular arch of `voussoirs` radial voussoirs of mean radius
/// `radius`, thickness `thickness` (t/R is the thickness ratio) and `depth`
/// (along y), centred on `origin` (the springing line at z = origin z), on two
/// fixed supports of `support_material` (blocks under the springers), or, with
/// `supports = false`, on whatever the scene puts there (piers).
pub struct Arch;

impl Generator<D3> for Arch {
    fn generate(&self, p: &toml::Table, out: &mut SceneBuilder3<'_>) -> Result<(), ParamError> {
        only_keys(
            p,
            &[
                "kind",
                "material",
                "support_material",
                "radius",
                "thickness",
                "depth",
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
        let d = positive(p, "depth", Some(t))?;
        let n = count(p, "voussoirs", None)?;
        out.reserve("voussoirs", n as f64, 0.0)?;
        let o = array::<3>(p, "origin", Some([0.0; 3]))?;
        let (ri, re) = (r - 0.5 * t, r + 0.5 * t);
        for k in 0..n {
            let mut pts = vec![];
            for a in [k as f64, k as f64 + 1.0].map(|x| std::f64::consts::PI * x / n as f64) {
                for rr in [ri, re] {
                    for y in [o[1], o[1] + d] {
                        pts.push([o[0] + rr * a.cos(), y, o[2] + rr * a.sin()]);
                    }
                }
            }
            add_points(out, &pts, material, false)?;
        }
        if !supports {
            return Ok(());
        }
        let sm = out.material_param(p, "support_material")?;
        for side in [-1.0, 1.0] {
            let (x0, x1) = if side > 0.0 {
                (o[0] + ri - t, o[0] + re + t)
            } else {
                (o[0] - re - t, o[0] - ri + t)
            };
            add_points(out, &box_points([x0, o[1] - t, o[2] - t], [x1, o[1] + d + t, o[2]]), sm, true)?;
        }
        Ok(())
    }
}

/// `tilting_table`: a slab of `size` = [Lx, Ly, Lz] whose top face is centred on
/// `origin` at t = 0, turned from t = `start` at the constant rate `rate` (rad/s)
/// about a hinge along y in its top face, at x = origin x + `hinge` (default
/// −Lx/2: the edge), the side x > 0 rising, until the tilt reaches `max_angle` (degrees; drives act at
/// step ends, so the tilt stops within rate × h of it); then it stays.
///
/// Every degree of freedom is driven by velocity: ω_y = −rate, and the centroid
/// c = H + R_y(−θ) d₀ (H on the hinge, d₀ = c(0) − H, θ = rate (t − start)) moves
/// on its circle with `v = rate ρ (−sin(θ + β), 0, cos(θ + β))`, ρ = |d₀|,
/// β = atan2(d₀z, d₀x): sine drives, so the hinge stays in place.
pub struct TiltingTable;

impl Generator<D3> for TiltingTable {
    fn generate(&self, p: &toml::Table, out: &mut SceneBuilder3<'_>) -> Result<(), ParamError> {
        only_keys(p, &["kind", "material", "size", "origin", "hinge", "rate", "max_angle", "start"])?;
        let material = out.material_param(p, "material")?;
        let [lx, ly, lz] = array::<3>(p, "size", None)?;
        if ![lx, ly, lz].iter().all(|x| *x > 0.0) {
            return Err(ParamError::new("size", "3 positive sizes [Lx, Ly, Lz]"));
        }
        let o = array::<3>(p, "origin", Some([0.0; 3]))?;
        let hinge = number(p, "hinge", Some(-0.5 * lx))?;
        if hinge.abs() > 0.5 * lx {
            return Err(ParamError::new(
                "hinge",
                format!("must lie on the table, in [−Lx/2, Lx/2] = ±{}", 0.5 * lx),
            ));
        }
        let rate = positive(p, "rate", None)?;
        let max_angle = positive(p, "max_angle", None)?;
        if max_angle >= 90.0 {
            return Err(ParamError::new("max_angle", format!("must be below 90 degrees, got {max_angle}")));
        }
        let start = number(p, "start", Some(0.0))?;
        if start < 0.0 {
            return Err(ParamError::new("start", format!("must be ≥ 0 (s), got {start}")));
        }
        let lo = [o[0] - 0.5 * lx, o[1] - 0.5 * ly, o[2] - lz];
        let hi = [o[0] + 0.5 * lx, o[1] + 0.5 * ly, o[2]];
        let b = add_points(out, &box_points(lo, hi), material, false)?;
        out.set_name(b, "table");
        let d0 = [-hinge, -0.5 * lz];
        let (rho, beta) = ((d0[0] * d0[0] + d0[1] * d0[1]).sqrt(), d0[1].atan2(d0[0]));
        let stop = start + max_angle.to_radians() / rate;
        let phased = |f: TimeFn| {
            let mut ph = vec![];
            if start > 0.0 {
                ph.push(Phase::velocity(TimeFn::Constant(0.0), Some(start)));
            }
            ph.push(Phase::velocity(f, Some(stop)));
            ph.push(Phase::velocity(TimeFn::Constant(0.0), None));
            Some(DofDrive::Phases(ph))
        };
        let freq = rate / (2.0 * std::f64::consts::PI);
        let ph0 = beta - rate * start;
        let vx = TimeFn::Shaped(Shape::Sine([-rate * rho, freq, ph0, 0.0]));
        let vz = TimeFn::Shaped(Shape::Sine([rate * rho, freq, ph0 + 0.5 * std::f64::consts::PI, 0.0]));
        let wy = TimeFn::Constant(-rate);
        let hold = || Some(DofDrive::One(Phase::velocity(TimeFn::Constant(0.0), None)));
        if start == 0.0 {
            out.set_velocity(b, [vx.eval(0.0), 0.0, vz.eval(0.0), 0.0, -rate, 0.0]);
        }
        out.drive(b, [phased(vx), hold(), phased(vz), hold(), phased(wy), hold()]);
        Ok(())
    }
}
