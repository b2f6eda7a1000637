//! Shape stores: spheres, planes (half-spaces) and boxes (rectangular cuboids).

use nscdd::params::{array, only_keys, positive};
use nscdd::registry::ParamError;
use nscdd::registry3::{Aabb3, Glyph3, MassProps3, ShapeStore3};
use nscdd::rigid3d::bodies::rotate;
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

impl ShapeStore3 for Spheres {
    fn kind(&self) -> &'static str {
        Self::KIND
    }
    store_basics!(|s: &Self| s.radius.len());
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
        Glyph3::Sphere(self.radius[s as usize])
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

impl ShapeStore3 for Planes {
    fn kind(&self) -> &'static str {
        Self::KIND
    }
    store_basics!(|s: &Self| s.display.len());
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

impl ShapeStore3 for Boxes {
    fn kind(&self) -> &'static str {
        Self::KIND
    }
    store_basics!(|s: &Self| s.half.len());
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
