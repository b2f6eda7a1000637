//! 2D rigid bodies: degrees of freedom (x, y, rotation).
//!
//! A body's twist is `V = (v_x, v_y, ω)` and its iteration matrix
//! `M̂ = diag(m, m, I)`, stored as the diagonal of `M̂⁻¹` (0 on degrees of freedom
//! driven by velocity or fixed). A contact has the frame (n, t), `t = (−n_y, n_x)`;
//! with the lever arm `d_b = p − x_b` of the contact point p,
//!
//! ```text
//! H_bᵀ V_b = ( n·v_b + (d_b × n) ω_b ,  t·v_b + (d_b × t) ω_b ).
//! ```

use super::coulomb2 as coulomb;
use super::joint::Joint;
use super::Dim;
use serde::{Deserialize, Serialize};

/// The plane.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct D2;

/// The local frame of a 2D contact: the unit normal n (from the antagonist j towards
/// the candidate i; t = (−n_y, n_x)) and the lever arms (d × n, d × t) of both
/// bodies, d = p − x_b.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
#[repr(C)]
pub struct Frame2 {
    pub n: [f64; 2],
    pub arm_i: [f64; 2],
    pub arm_j: [f64; 2],
}

/// The diagonal Delassus block W_αα = [W_nn, W_nt, W_tt] and its
/// [`coulomb::precompute`]d inverses, reused by every sweep.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
#[repr(C)]
pub struct Block2 {
    pub w: [f64; 3],
    pub pre: [f64; 5],
}

/// u = H_iᵀ V_i − H_jᵀ V_j for one frame.
#[inline(always)]
pub fn local_velocity(f: &Frame2, vi: [f64; 3], vj: [f64; 3]) -> [f64; 2] {
    let (n, ai, aj) = (f.n, f.arm_i, f.arm_j);
    let dv = [vi[0] - vj[0], vi[1] - vj[1]];
    [
        n[0] * dv[0] + n[1] * dv[1] + ai[0] * vi[2] - aj[0] * vj[2],
        -n[1] * dv[0] + n[0] * dv[1] + ai[1] * vi[2] - aj[1] * vj[2],
    ]
}

/// V_i += M̂_i⁻¹ H_i Δr, V_j −= M̂_j⁻¹ H_j Δr for one frame.
#[inline(always)]
pub fn apply(f: &Frame2, dr: [f64; 2], i: usize, j: usize, vel: &mut [[f64; 3]], inv_mass: &[[f64; 3]]) {
    let n = f.n;
    let px = dr[0] * n[0] - dr[1] * n[1];
    let py = dr[0] * n[1] + dr[1] * n[0];
    let mi = inv_mass[i];
    let v = &mut vel[i];
    v[0] += mi[0] * px;
    v[1] += mi[1] * py;
    v[2] += mi[2] * (f.arm_i[0] * dr[0] + f.arm_i[1] * dr[1]);
    let mj = inv_mass[j];
    let v = &mut vel[j];
    v[0] -= mj[0] * px;
    v[1] -= mj[1] * py;
    v[2] -= mj[2] * (f.arm_j[0] * dr[0] + f.arm_j[1] * dr[1]);
}

/// W_αα from the frame and the bodies' M̂⁻¹.
pub fn delassus(f: &Frame2, mi: [f64; 3], mj: [f64; 3]) -> [f64; 3] {
    let (n, t) = (f.n, [-f.n[1], f.n[0]]);
    let mut w = [0.0; 3];
    for (a, m) in [(f.arm_i, mi), (f.arm_j, mj)] {
        w[0] += m[0] * n[0] * n[0] + m[1] * n[1] * n[1] + m[2] * a[0] * a[0];
        w[1] += m[0] * n[0] * t[0] + m[1] * n[1] * t[1] + m[2] * a[0] * a[1];
        w[2] += m[0] * t[0] * t[0] + m[1] * t[1] * t[1] + m[2] * a[1] * a[1];
    }
    w
}

impl Dim for D2 {
    const N: usize = 2;
    const DOF: usize = 3;
    const NAME: &'static str = "2D";
    type Point = [f64; 2];
    type Rot = f64;
    type Twist = [f64; 3];
    type Local = [f64; 2];
    type Frame = Frame2;
    type W = [f64; 3];
    type Block = Block2;
    type InvMass = [f64; 3];
    type Inertia = f64;
    type RotVec = f64;

    fn rot_identity() -> f64 {
        0.0
    }
    fn rot_from_vec(r: &f64) -> f64 {
        *r
    }
    fn rot_to_vec(r: &f64) -> f64 {
        *r
    }
    fn rotate(r: &f64, p: &[f64; 2]) -> [f64; 2] {
        let (s, c) = r.sin_cos();
        [c * p[0] - s * p[1], s * p[0] + c * p[1]]
    }
    fn rot_mul(a: &f64, b: &f64) -> f64 {
        a + b
    }
    fn normalize_rot(r: f64) -> f64 {
        r
    }
    fn inv_mass(mass: f64, inertia: &f64, _rot: &f64, free: u8) -> [f64; 3] {
        let inv = |k: u8, x: f64| if free & (1 << k) != 0 { 1.0 / x } else { 0.0 };
        [inv(0, mass), inv(1, mass), inv(2, *inertia)]
    }
    const INV_MASS_LEN: usize = 3;
    fn inv_mass_coords(im: &[f64; 3], out: &mut Vec<f64>) {
        out.extend_from_slice(im);
    }
    fn inv_mass_from(x: &[f64]) -> [f64; 3] {
        [x[0], x[1], x[2]]
    }
    fn isotropic(_inertia: &f64) -> bool {
        true
    }
    fn rho2(mass: f64, inertia: &f64) -> f64 {
        if mass > 0.0 && mass.is_finite() && inertia.is_finite() {
            inertia / mass
        } else {
            0.0
        }
    }
    #[inline]
    fn integrate(pos: &mut [f64; 2], rot: &mut f64, v0: &[f64; 3], v1: &[f64; 3], h: f64, theta: f64) {
        let dq: [f64; 3] = std::array::from_fn(|a| h * ((1.0 - theta) * v0[a] + theta * v1[a]));
        pos[0] += dq[0];
        pos[1] += dq[1];
        *rot += dq[2];
    }
    fn kinetic_energy(m: f64, i: &f64, _rot: &f64, v: &[f64; 3]) -> f64 {
        0.5 * (m * v[0] * v[0] + m * v[1] * v[1] + i * v[2] * v[2])
    }
    #[inline]
    fn free_flight(v: &mut [f64; 3], m: f64, _i: &f64, _rot: &f64, im: &[f64; 3], g: &[f64; 2], h: f64) {
        v[0] += h * im[0] * m * g[0];
        v[1] += h * im[1] * m * g[1];
    }
    fn apply_moment(v: &mut [f64; 3], i: &f64, _inv: &[f64; 3], _axis: usize, hm: f64) {
        v[2] += hm / i;
    }
    fn rot_finite(r: &f64) -> bool {
        r.is_finite()
    }

    #[inline]
    fn frame(p: &[f64; 2], n: &[f64; 2], x_i: &[f64; 2], x_j: &[f64; 2]) -> Frame2 {
        let n = *n;
        let t = [-n[1], n[0]];
        let arm = |x: &[f64; 2]| {
            let d = [p[0] - x[0], p[1] - x[1]];
            [d[0] * n[1] - d[1] * n[0], d[0] * t[1] - d[1] * t[0]]
        };
        Frame2 {
            n,
            arm_i: arm(x_i),
            arm_j: arm(x_j),
        }
    }
    fn normal(f: &Frame2) -> [f64; 2] {
        f.n
    }
    fn to_world(f: &Frame2, r: &[f64; 2]) -> [f64; 2] {
        // t = (−n_y, n_x)
        [r[0] * f.n[0] - r[1] * f.n[1], r[0] * f.n[1] + r[1] * f.n[0]]
    }
    #[inline(always)]
    fn local_velocity(f: &Frame2, vi: &[f64; 3], vj: &[f64; 3]) -> [f64; 2] {
        local_velocity(f, *vi, *vj)
    }
    #[inline(always)]
    fn apply(f: &Frame2, dr: &[f64; 2], i: usize, j: usize, vel: &mut [[f64; 3]], inv: &[[f64; 3]]) {
        apply(f, *dr, i, j, vel, inv)
    }
    #[inline]
    fn delassus(f: &Frame2, inv_i: &[f64; 3], inv_j: &[f64; 3]) -> [f64; 3] {
        delassus(f, *inv_i, *inv_j)
    }
    #[inline(always)]
    fn w_nn(w: &[f64; 3]) -> f64 {
        w[0]
    }
    #[inline]
    fn with_compliance(mut w: [f64; 3], c: f64) -> [f64; 3] {
        w[0] += c;
        w
    }
    #[inline]
    fn block(w: [f64; 3], mu: f64) -> Block2 {
        Block2 {
            w,
            pre: coulomb::precompute(w, mu),
        }
    }
    #[inline(always)]
    fn w_mul(b: &Block2, r: &[f64; 2]) -> [f64; 2] {
        let w = b.w;
        [w[0] * r[0] + w[1] * r[1], w[1] * r[0] + w[2] * r[1]]
    }
    #[inline(always)]
    fn solve(b: &Block2, u0: &[f64; 2], u_target: f64, mu: f64, _prev: &[f64; 2]) -> [f64; 2] {
        coulomb::solve_pre(b.w, &b.pre, *u0, u_target, mu)
    }
    fn solve_joint(b: &Block2, u0: &[f64; 2], u_target: f64, mu: f64, j: &Joint, prev: &[f64; 2]) -> [f64; 2] {
        coulomb::solve_joint(b.w, &b.pre, *u0, u_target, mu, j, *prev)
    }
    fn project_joint(z: &[f64], mu: f64, j: &Joint) -> [f64; 3] {
        let p = coulomb::project_joint([z[0], z[1]], mu, j);
        [p[0], p[1], 0.0]
    }
    fn joint_holds(b: &Block2, r: &[f64; 2], u0: &[f64; 2], u_target: f64, mu: f64, j: &Joint, tol: f64) -> bool {
        coulomb::joint_holds(b.w, &b.pre, *r, *u0, u_target, mu, j, tol)
    }
    fn joint_natural_map_sq(r: &[f64; 2], u: &[f64; 2], mu: f64, j: &Joint) -> f64 {
        coulomb::joint_natural_map_sq(*r, *u, mu, j)
    }
    #[inline]
    fn reaction_i(f: &Frame2, r: &[f64; 2]) -> [f64; 3] {
        let n = f.n;
        let p = [r[0] * n[0] - r[1] * n[1], r[0] * n[1] + r[1] * n[0]];
        [p[0], p[1], f.arm_i[0] * r[0] + f.arm_i[1] * r[1]]
    }
    #[inline]
    fn reaction_j(f: &Frame2, r: &[f64; 2]) -> [f64; 3] {
        let n = f.n;
        let p = [r[0] * n[0] - r[1] * n[1], r[0] * n[1] + r[1] * n[0]];
        [p[0], p[1], f.arm_j[0] * r[0] + f.arm_j[1] * r[1]]
    }
    fn scale_inv(im: &[f64; 3], m: f64) -> [f64; 3] {
        [im[0] * m, im[1] * m, im[2] * m]
    }
    fn apply_inv(v: &mut [f64; 3], im: &[f64; 3], f: &[f64; 3]) {
        for d in 0..3 {
            v[d] += im[d] * f[d];
        }
    }
    fn glue(v: &mut [f64; 3], f: &mut [f64; 3], im: &[f64; 3], dv: &[f64; 3]) {
        for d in 0..3 {
            if im[d] != 0.0 {
                v[d] += dv[d];
                f[d] += dv[d] / im[d];
            }
        }
    }
}
