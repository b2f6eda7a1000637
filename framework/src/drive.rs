//! Driven degrees of freedom: an imposed velocity or an imposed force, each a
//! function of time, possibly in successive phases (for example a wall pushed by a
//! constant force until t = 1 s, then moved at a constant velocity).
//!
//! Scene syntax for one degree of freedom (`x`, `y` or `rot` in 2D):
//!
//! ```toml
//! drive.y = { velocity = -0.01 }                      # constant
//! drive.x = { force = { ramp = [0.0, 0.0, 1.0, 5e3] } } # f(t) linear from (t0,f0) to (t1,f1), constant outside
//! drive.y = [ { force = -1e4, until = 1.0 }, { velocity = -0.01 } ]  # phases
//! ```

use serde::{Deserialize, Serialize};

/// A scalar function of time.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(untagged)]
pub enum TimeFn {
    Constant(f64),
    Shaped(Shape),
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, rename_all = "lowercase")]
pub enum Shape {
    /// `[t0, v0, t1, v1]`: linear between the two points, constant outside.
    Ramp([f64; 4]),
    /// `[amplitude, frequency (Hz), phase (rad), offset]`.
    Sine([f64; 4]),
    /// Piecewise-linear through `[[t, v], ...]` (sorted by t), constant outside.
    Table(Vec<[f64; 2]>),
}

impl TimeFn {
    pub fn eval(&self, t: f64) -> f64 {
        match self {
            TimeFn::Constant(c) => *c,
            TimeFn::Shaped(Shape::Ramp([t0, v0, t1, v1])) => {
                if t <= *t0 || t1 <= t0 {
                    if t <= *t0 {
                        *v0
                    } else {
                        *v1
                    }
                } else if t >= *t1 {
                    *v1
                } else {
                    v0 + (v1 - v0) * (t - t0) / (t1 - t0)
                }
            }
            TimeFn::Shaped(Shape::Sine([a, f, ph, off])) => off + a * (2.0 * std::f64::consts::PI * f * t + ph).sin(),
            TimeFn::Shaped(Shape::Table(pts)) => {
                if pts.is_empty() {
                    return 0.0;
                }
                let k = pts.partition_point(|p| p[0] <= t);
                if k == 0 {
                    pts[0][1]
                } else if k == pts.len() {
                    pts[k - 1][1]
                } else {
                    let (a, b) = (pts[k - 1], pts[k]);
                    a[1] + (b[1] - a[1]) * (t - a[0]) / (b[0] - a[0])
                }
            }
        }
    }

    /// A message if the function is ill-formed.
    pub fn validate(&self) -> Result<(), String> {
        let finite = |x: &[f64]| x.iter().all(|v| v.is_finite());
        match self {
            TimeFn::Constant(c) if !c.is_finite() => Err("value must be finite".into()),
            TimeFn::Shaped(Shape::Ramp(v)) | TimeFn::Shaped(Shape::Sine(v)) if !finite(v) => Err("values must be finite".into()),
            TimeFn::Shaped(Shape::Table(p)) => {
                if p.iter().any(|x| !finite(x)) {
                    return Err("table values must be finite".into());
                }
                if p.windows(2).any(|w| w[1][0] <= w[0][0]) {
                    return Err("table times must increase strictly".into());
                }
                Ok(())
            }
            _ => Ok(()),
        }
    }
}

/// One phase of a driven degree of freedom.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Phase {
    /// Imposed velocity (m/s or rad/s).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub velocity: Option<TimeFn>,
    /// Imposed force (N or N·m, per unit depth in 2D), added to the loads.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub force: Option<TimeFn>,
    /// Imposed pressure (Pa) on a wall of a 3D box sample (`[output] box3`): a force
    /// σ × the current area of the sample's face, pushing into the sample.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pressure: Option<TimeFn>,
    /// Stress-controlled wall of a 3D box sample: a velocity that closes the gap
    /// between the target pressure and the stress the grains exert on the wall.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub servo: Option<Servo>,
    /// The phase holds for t < until (the last phase holds for ever).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub until: Option<f64>,
}

impl Phase {
    /// A phase imposing the velocity `v(t)` until `until` (for ever if `None`).
    pub fn velocity(v: TimeFn, until: Option<f64>) -> Phase {
        Phase {
            velocity: Some(v),
            force: None,
            pressure: None,
            servo: None,
            until,
        }
    }
}

/// A servo-controlled wall (as DEM codes drive stress-controlled walls): at each step
/// the wall moves into the sample at `v = clamp(gain × (σ_target − σ_wall),
/// −max_velocity, max_velocity)`, σ_wall being the stress the grains exerted on it
/// over the previous step. A quasi-static compaction: the walls never build up
/// momentum, whatever their mass.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Servo {
    /// Target pressure σ_target (Pa).
    pub pressure: TimeFn,
    /// (m/s)/Pa.
    pub gain: f64,
    /// m/s.
    pub max_velocity: f64,
}

/// A driven degree of freedom: one phase or a list of phases.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(untagged)]
pub enum DofDrive {
    One(Phase),
    Phases(Vec<Phase>),
}

/// What a driven degree of freedom imposes at one instant.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Imposed {
    Velocity(f64),
    Force(f64),
    Pressure(f64),
    /// Target pressure, gain, velocity bound.
    Servo(f64, f64, f64),
    Free,
}

impl DofDrive {
    fn phases(&self) -> &[Phase] {
        match self {
            DofDrive::One(p) => std::slice::from_ref(p),
            DofDrive::Phases(v) => v,
        }
    }

    pub fn validate(&self) -> Result<(), String> {
        let ph = self.phases();
        if ph.is_empty() {
            return Err("a drive needs at least one phase".into());
        }
        for (k, p) in ph.iter().enumerate() {
            match (&p.velocity, &p.force, &p.pressure, &p.servo) {
                (Some(f), None, None, None) | (None, Some(f), None, None) | (None, None, Some(f), None) => f.validate()?,
                (None, None, None, Some(sv)) => {
                    sv.pressure.validate()?;
                    if !(sv.gain > 0.0 && sv.gain.is_finite() && sv.max_velocity > 0.0 && sv.max_velocity.is_finite()) {
                        return Err("a servo needs gain > 0 and max_velocity > 0".into());
                    }
                }
                _ => return Err("each phase imposes exactly one of `velocity`, `force`, `pressure` or `servo`".into()),
            }
            if let Some(u) = p.until {
                if !u.is_finite() {
                    return Err("`until` must be finite".into());
                }
                if k > 0 && ph[k - 1].until.is_some_and(|prev| prev >= u) {
                    return Err("phase times `until` must increase".into());
                }
            } else if k + 1 < ph.len() {
                return Err("every phase but the last needs `until`".into());
            }
        }
        Ok(())
    }

    /// What the drive imposes at time t: the velocity is evaluated at t, the force too
    /// (callers pass t_{i+1} for velocities and t_i + θh for forces).
    pub fn at(&self, t: f64) -> Imposed {
        for p in self.phases() {
            if p.until.is_none_or(|u| t < u) {
                return Self::imposed(p, t);
            }
        }
        // after the last phase with `until`, the last phase's function continues
        match self.phases().last() {
            Some(p) => Self::imposed(p, t),
            None => Imposed::Free,
        }
    }

    /// Whether the drive imposes a velocity at time t.
    fn imposed(p: &Phase, t: f64) -> Imposed {
        match (&p.velocity, &p.force, &p.pressure, &p.servo) {
            (Some(v), ..) => Imposed::Velocity(v.eval(t)),
            (_, Some(f), ..) => Imposed::Force(f.eval(t)),
            (_, _, Some(s), _) => Imposed::Pressure(s.eval(t)),
            (_, _, _, Some(sv)) => Imposed::Servo(sv.pressure.eval(t), sv.gain, sv.max_velocity),
            _ => Imposed::Free,
        }
    }

    /// Whether any phase imposes a pressure (or a servo): the body must then be a
    /// wall of a 3D box sample.
    pub fn has_pressure(&self) -> bool {
        self.phases().iter().any(|p| p.pressure.is_some() || p.servo.is_some())
    }

    /// Whether the degree of freedom moves at an imposed velocity at t (velocity and
    /// servo phases): impulses do not move it.
    pub fn is_velocity_at(&self, t: f64) -> bool {
        matches!(self.at(t), Imposed::Velocity(_) | Imposed::Servo(..))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    #[test]
    fn eval() {
        let r = TimeFn::Shaped(Shape::Ramp([0.0, 0.0, 2.0, 4.0]));
        assert_eq!(r.eval(-1.0), 0.0);
        assert_eq!(r.eval(1.0), 2.0);
        assert_eq!(r.eval(3.0), 4.0);
        let t = TimeFn::Shaped(Shape::Table(vec![[0.0, 1.0], [1.0, 3.0]]));
        assert_eq!(t.eval(0.5), 2.0);
        let d = DofDrive::Phases(vec![
            Phase {
                velocity: None,
                force: Some(TimeFn::Constant(5.0)),
                pressure: None,
                servo: None,
                until: Some(1.0),
            },
            Phase {
                velocity: Some(TimeFn::Constant(-1.0)),
                force: None,
                pressure: None,
                servo: None,
                until: None,
            },
        ]);
        assert!(d.validate().is_ok());
        assert_eq!(d.at(0.5), Imposed::Force(5.0));
        assert_eq!(d.at(1.5), Imposed::Velocity(-1.0));
    }
}

/// The drives of one body, per degree of freedom (2D: x, y, rot; 3D: x, y, z, rx,
/// ry, rz, rotations about the world axes; the entries past the dimension's
/// degrees of freedom are `None`).
#[derive(Clone, Debug, PartialEq)]
pub struct BodyDrive {
    pub body: u32,
    pub dof: [Option<DofDrive>; 6],
}
