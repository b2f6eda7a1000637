//! Shape stores: spheres, planes (half-spaces) and boxes (rectangular cuboids).

use nscdd::dim::rotation::{rotate, rotate_inv};
use nscdd::dim::D3;
use nscdd::params::{array, only_keys, positive};
use nscdd::registry::ParamError;
use nscdd::registry::{Aabb3, FaceContact3, Glyph3, MassProps3, PointContact3, ShapeStore};
use std::any::Any;
use std::f64::consts::PI;

macro_rules! store_basics {
    ($len:expr) => {
        fn len(&self) -> usize {
            $len(self)
        }
        fn as_any(&self) -> &dyn Any {
            self
        }
        fn as_any_mut(&mut self) -> &mut dyn Any {
            self
        }
    };
}

/// Spheres: key `radius` (m).
#[derive(Default, Clone, Debug)]
pub struct Spheres {
    pub radius: Vec<f64>,
}

impl Spheres {
    pub const KIND: &'static str = "sphere";
}

impl ShapeStore<D3> for Spheres {
    fn kind(&self) -> &'static str {
        Self::KIND
    }
    store_basics!(|s: &Self| s.radius.len());
    /// Gap |p − c| − r along the radius through p.
    fn point_contact(&self, s: u32, x: [f64; 3], _q: [f64; 4], p: [f64; 3], _hint: [f64; 3]) -> Option<PointContact3> {
        let r = self.radius[s as usize];
        let d = [p[0] - x[0], p[1] - x[1], p[2] - x[2]];
        let l = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
        if l == 0.0 {
            return None;
        }
        let n = [d[0] / l, d[1] / l, d[2] / l];
        Some(PointContact3 {
            gap: l - r,
            normal: n,
            point: [x[0] + r * n[0], x[1] + r * n[1], x[2] + r * n[2]],
        })
    }
    fn meets_faces(&self) -> bool {
        true
    }
    /// The triangle's closest point to the centre c: gap |q − c| − r.
    fn face_contact(&self, s: u32, x: [f64; 3], _q: [f64; 4], tri: &[[f64; 3]]) -> Option<FaceContact3> {
        let r = self.radius[s as usize];
        let [a, b, c] = tri else { return None };
        let bary = closest_on_triangle(x, &[*a, *b, *c]);
        let q: [f64; 3] = std::array::from_fn(|c| bary[0] * tri[0][c] + bary[1] * tri[1][c] + bary[2] * tri[2][c]);
        let d = [q[0] - x[0], q[1] - x[1], q[2] - x[2]];
        let l = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
        if l == 0.0 {
            return None;
        }
        let n = [d[0] / l, d[1] / l, d[2] / l];
        Some(FaceContact3 {
            gap: l - r,
            normal: n,
            point: [x[0] + r * n[0], x[1] + r * n[1], x[2] + r * n[2]],
            bary,
        })
    }
    fn push_params(&mut self, p: &toml::Table) -> Result<u32, ParamError> {
        only_keys(p, &["radius"])?;
        self.radius.push(positive(p, "radius", None)?);
        Ok(self.radius.len() as u32 - 1)
    }
    fn aabb(&self, s: u32, x: [f64; 3], _q: [f64; 4]) -> Aabb3 {
        let r = self.radius[s as usize];
        Aabb3 {
            min: [x[0] - r, x[1] - r, x[2] - r],
            max: [x[0] + r, x[1] + r, x[2] + r],
        }
    }
    /// Volume 4/3 π r³, inertia 2/5 m r².
    fn mass_properties(&self, s: u32, density: f64) -> MassProps3 {
        let r = self.radius[s as usize];
        let volume = 4.0 / 3.0 * PI * r * r * r;
        let mass = density * volume;
        let i = 0.4 * mass * r * r;
        MassProps3 {
            volume,
            mass,
            inertia: [i; 3],
        }
    }
    fn size(&self, s: u32) -> f64 {
        self.radius[s as usize]
    }
    fn glyph(&self, s: u32, _x: [f64; 3], _q: [f64; 4]) -> Glyph3 {
        Glyph3::Ball(self.radius[s as usize])
    }
    fn describe(&self, s: u32) -> serde_json::Value {
        serde_json::json!({ "radius": self.radius[s as usize] })
    }
}

/// Planes: half-spaces whose boundary passes through the body's position, outward
/// normal = the body's z axis (rotate with `rotation`). Optional `display_size` (m)
/// for the VTK square. A plane has no finite mass: it is a nominal ρ × 1 m³ body,
/// to be fixed or driven by velocity.
#[derive(Default, Clone, Debug)]
pub struct Planes {
    pub display: Vec<f64>,
}

impl Planes {
    pub const KIND: &'static str = "plane";
}

impl ShapeStore<D3> for Planes {
    fn kind(&self) -> &'static str {
        Self::KIND
    }
    store_basics!(|s: &Self| s.display.len());
    /// Signed distance to the plane through x with normal q·e_z.
    fn point_contact(&self, _s: u32, x: [f64; 3], q: [f64; 4], p: [f64; 3], _hint: [f64; 3]) -> Option<PointContact3> {
        let n = rotate(q, [0.0, 0.0, 1.0]);
        let gap = (p[0] - x[0]) * n[0] + (p[1] - x[1]) * n[1] + (p[2] - x[2]) * n[2];
        Some(PointContact3 {
            gap,
            normal: n,
            point: [p[0] - gap * n[0], p[1] - gap * n[1], p[2] - gap * n[2]],
        })
    }
    fn push_params(&mut self, p: &toml::Table) -> Result<u32, ParamError> {
        only_keys(p, &["display_size"])?;
        self.display.push(positive(p, "display_size", Some(1.0))?);
        Ok(self.display.len() as u32 - 1)
    }
    fn aabb(&self, _s: u32, x: [f64; 3], q: [f64; 4]) -> Aabb3 {
        // axis-aligned planes bound one side; others are unbounded
        let n = rotate(q, [0.0, 0.0, 1.0]);
        let mut a = Aabb3 {
            min: [f64::NEG_INFINITY; 3],
            max: [f64::INFINITY; 3],
        };
        for k in 0..3 {
            let others = (0..3).filter(|&j| j != k).all(|j| n[j].abs() < 1e-12);
            if others {
                if n[k] > 0.0 {
                    a.max[k] = x[k];
                } else {
                    a.min[k] = x[k];
                }
            }
        }
        a
    }
    fn mass_properties(&self, _s: u32, density: f64) -> MassProps3 {
        MassProps3 {
            volume: 0.0,
            mass: density,
            inertia: [density / 6.0; 3],
        }
    }
    fn size(&self, _s: u32) -> f64 {
        f64::INFINITY
    }
    fn glyph(&self, s: u32, x: [f64; 3], q: [f64; 4]) -> Glyph3 {
        let h = 0.5 * self.display[s as usize];
        let corner = |a: f64, b: f64| {
            let v = rotate(q, [a * h, b * h, 0.0]);
            [x[0] + v[0], x[1] + v[1], x[2] + v[2]]
        };
        Glyph3::Faces(vec![vec![
            corner(-1.0, -1.0),
            corner(1.0, -1.0),
            corner(1.0, 1.0),
            corner(-1.0, 1.0),
        ]])
    }
    fn describe(&self, _s: u32) -> serde_json::Value {
        serde_json::json!({})
    }
    fn is_grain(&self) -> bool {
        false
    }
}

/// Boxes (rectangular cuboids): key `half_extents` = [a, b, c] (m) along the body
/// axes. Walls of a sample cell are thin boxes.
#[derive(Default, Clone, Debug)]
pub struct Boxes {
    pub half: Vec<[f64; 3]>,
}

impl Boxes {
    pub const KIND: &'static str = "box";
}

impl ShapeStore<D3> for Boxes {
    fn kind(&self) -> &'static str {
        Self::KIND
    }
    store_basics!(|s: &Self| s.half.len());
    /// Outside: the distance to the closest surface point. Inside or on the
    /// surface: the face of least penetration (its outward normal, gap minus the
    /// depth), among faces within 1e-9 of it the one facing `hint`.
    fn point_contact(&self, s: u32, x: [f64; 3], q: [f64; 4], p: [f64; 3], hint: [f64; 3]) -> Option<PointContact3> {
        let h = self.half[s as usize];
        let pl = rotate_inv(q, [p[0] - x[0], p[1] - x[1], p[2] - x[2]]);
        let hl = rotate_inv(q, hint);
        let c = [pl[0].clamp(-h[0], h[0]), pl[1].clamp(-h[1], h[1]), pl[2].clamp(-h[2], h[2])];
        let d = [pl[0] - c[0], pl[1] - c[1], pl[2] - c[2]];
        let l = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
        let (gap, nl, cl) = if l > 0.0 {
            (l, [d[0] / l, d[1] / l, d[2] / l], c)
        } else {
            let depth = |a: usize| h[a] - pl[a].abs();
            let sign = |a: usize| if pl[a] >= 0.0 { 1.0 } else { -1.0 };
            let least = (0..3).map(depth).fold(f64::INFINITY, f64::min);
            let tol = 1e-9 * h.iter().fold(0.0f64, |m, x| m.max(*x));
            // ties (a point on an edge): the face most opposed to the hint
            let k = (0..3)
                .filter(|&a| depth(a) <= least + tol)
                .min_by(|&a, &b| (sign(a) * hl[a]).total_cmp(&(sign(b) * hl[b])))
                .unwrap_or(2);
            let sgn = sign(k);
            let mut n = [0.0; 3];
            n[k] = sgn;
            let mut cp = pl;
            cp[k] = sgn * h[k];
            (pl[k].abs() - h[k], n, cp)
        };
        let n = rotate(q, nl);
        let cw = rotate(q, cl);
        Some(PointContact3 {
            gap,
            normal: n,
            point: [x[0] + cw[0], x[1] + cw[1], x[2] + cw[2]],
        })
    }
    fn push_params(&mut self, p: &toml::Table) -> Result<u32, ParamError> {
        only_keys(p, &["half_extents"])?;
        let h = array::<3>(p, "half_extents", None)?;
        if h.iter().any(|x| !(*x > 0.0 && x.is_finite())) {
            return Err(ParamError::new("half_extents", format!("must be 3 positive numbers, got {h:?}")));
        }
        self.half.push(h);
        Ok(self.half.len() as u32 - 1)
    }
    fn aabb(&self, s: u32, x: [f64; 3], q: [f64; 4]) -> Aabb3 {
        let h = self.half[s as usize];
        let mut e = [0.0; 3];
        for (k, hk) in h.iter().enumerate() {
            let mut axis = [0.0; 3];
            axis[k] = *hk;
            let v = rotate(q, axis);
            for j in 0..3 {
                e[j] += v[j].abs();
            }
        }
        Aabb3 {
            min: [x[0] - e[0], x[1] - e[1], x[2] - e[2]],
            max: [x[0] + e[0], x[1] + e[1], x[2] + e[2]],
        }
    }
    /// Volume 8abc, principal inertia m/3 (b² + c², a² + c², a² + b²).
    fn mass_properties(&self, s: u32, density: f64) -> MassProps3 {
        let [a, b, c] = self.half[s as usize];
        let volume = 8.0 * a * b * c;
        let m = density * volume;
        MassProps3 {
            volume,
            mass: m,
            inertia: [m / 3.0 * (b * b + c * c), m / 3.0 * (a * a + c * c), m / 3.0 * (a * a + b * b)],
        }
    }
    fn size(&self, s: u32) -> f64 {
        let h = self.half[s as usize];
        h[0].min(h[1]).min(h[2])
    }
    fn glyph(&self, s: u32, x: [f64; 3], q: [f64; 4]) -> Glyph3 {
        let h = self.half[s as usize];
        let v = |i: f64, j: f64, k: f64| {
            let p = rotate(q, [i * h[0], j * h[1], k * h[2]]);
            [x[0] + p[0], x[1] + p[1], x[2] + p[2]]
        };
        let faces = vec![
            vec![v(-1., -1., -1.), v(-1., 1., -1.), v(1., 1., -1.), v(1., -1., -1.)],
            vec![v(-1., -1., 1.), v(1., -1., 1.), v(1., 1., 1.), v(-1., 1., 1.)],
            vec![v(-1., -1., -1.), v(1., -1., -1.), v(1., -1., 1.), v(-1., -1., 1.)],
            vec![v(-1., 1., -1.), v(-1., 1., 1.), v(1., 1., 1.), v(1., 1., -1.)],
            vec![v(-1., -1., -1.), v(-1., -1., 1.), v(-1., 1., 1.), v(-1., 1., -1.)],
            vec![v(1., -1., -1.), v(1., 1., -1.), v(1., 1., 1.), v(1., -1., 1.)],
        ];
        Glyph3::Faces(faces)
    }
    fn describe(&self, s: u32) -> serde_json::Value {
        serde_json::json!({ "half_extents": self.half[s as usize] })
    }
    fn is_grain(&self) -> bool {
        false
    }
}

/// Barycentric weights of the point of triangle (a, b, c) closest to p (by the
/// Voronoi regions of its vertices, edges and face).
pub fn closest_on_triangle(p: [f64; 3], t: &[[f64; 3]; 3]) -> [f64; 3] {
    let sub = |u: [f64; 3], v: [f64; 3]| [u[0] - v[0], u[1] - v[1], u[2] - v[2]];
    let dot = |u: [f64; 3], v: [f64; 3]| u[0] * v[0] + u[1] * v[1] + u[2] * v[2];
    let (a, b, c) = (t[0], t[1], t[2]);
    let (ab, ac, ap) = (sub(b, a), sub(c, a), sub(p, a));
    let (d1, d2) = (dot(ab, ap), dot(ac, ap));
    if d1 <= 0.0 && d2 <= 0.0 {
        return [1.0, 0.0, 0.0];
    }
    let bp = sub(p, b);
    let (d3, d4) = (dot(ab, bp), dot(ac, bp));
    if d3 >= 0.0 && d4 <= d3 {
        return [0.0, 1.0, 0.0];
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        let v = d1 / (d1 - d3);
        return [1.0 - v, v, 0.0];
    }
    let cp = sub(p, c);
    let (d5, d6) = (dot(ab, cp), dot(ac, cp));
    if d6 >= 0.0 && d5 <= d6 {
        return [0.0, 0.0, 1.0];
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        let w = d2 / (d2 - d6);
        return [1.0 - w, 0.0, w];
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        let w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        return [0.0, 1.0 - w, w];
    }
    let denom = 1.0 / (va + vb + vc);
    let (v, w) = (vb * denom, vc * denom);
    [1.0 - v - w, v, w]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn closest_point_regions() {
        let t = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
        let f = closest_on_triangle([0.2, 0.2, 1.0], &t);
        assert!((f[0] - 0.6).abs() < 1e-15 && (f[1] - 0.2).abs() < 1e-15 && (f[2] - 0.2).abs() < 1e-15);
        assert_eq!(closest_on_triangle([-1.0, -1.0, 0.5], &t), [1.0, 0.0, 0.0]);
        assert_eq!(closest_on_triangle([2.0, -0.1, 0.0], &t), [0.0, 1.0, 0.0]);
        let e = closest_on_triangle([0.5, -1.0, 0.3], &t);
        assert!((e[0] - 0.5).abs() < 1e-15 && (e[1] - 0.5).abs() < 1e-15 && e[2] == 0.0);
        let h = closest_on_triangle([1.0, 1.0, 0.0], &t);
        assert!(h[0].abs() < 1e-15 && (h[1] - 0.5).abs() < 1e-15 && (h[2] - 0.5).abs() < 1e-15);
        let s = Spheres { radius: vec![0.5] };
        let fc = s.face_contact(0, [0.25, 0.25, 0.4], [1.0, 0.0, 0.0, 0.0], &t).unwrap();
        assert!((fc.gap + 0.1).abs() < 1e-15 && fc.normal == [0.0, 0.0, -1.0]);
    }
}
