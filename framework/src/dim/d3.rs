//! 3D rigid bodies: six degrees of freedom, orientations as unit quaternions.
//!
//! A body's twist is `V = (v, ω)` with ω in the world frame; `M̂ = diag(m I₃, I_w)`
//! with the world inertia `I_w = R diag(I₁, I₂, I₃) Rᵀ`, seen by the solver as
//! [`InvMass3`] (per-axis translational entries, 0 on driven axes, and `I_w⁻¹`
//! restricted to the free rotational axes). A contact has the orthonormal frame
//! `B = [n t1 t2]` (n from j towards i) and the lever arms `d_b = p − x_b`:
//!
//! ```text
//! u_α = Bᵀ ((v_i + ω_i × d_i) − (v_j + ω_j × d_j)),
//! ```
//!
//! an impulse r acts as `P = B r` at p: `Δv_i = m_i⁻¹ P`, `Δω_i = I_i⁻¹ (d_i × P)`
//! and the opposite on j, and `W_αα = Bᵀ (K_i + K_j) B` with
//! `K_b = diag(m_b⁻¹) + [d_b]×ᵀ I_b⁻¹ [d_b]×`.

use super::coulomb3::{self as coulomb, Pre3, Sym3};
use super::joint::{self, Joint};
use super::rotation::{self, rotation_matrix};
use super::Dim;
use serde::{Deserialize, Serialize};

/// Space.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct D3;

/// The frame of a contact: basis rows n, t1, t2 and the lever arms of both bodies.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
#[repr(C)]
pub struct Frame3 {
    pub basis: [[f64; 3]; 3],
    pub d_i: [f64; 3],
    pub d_j: [f64; 3],
}

/// W_αα and its precomputed data.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
#[repr(C)]
pub struct Block3 {
    pub w: Sym3,
    pub pre: Pre3,
}

/// M̂⁻¹ of one 3D rigid body: translational diagonal and rotational block.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct InvMass3 {
    pub m: [f64; 3],
    pub i: Sym3,
}

#[inline(always)]
pub fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

#[inline(always)]
pub fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
}

/// The tangent vectors (t1, t2) completing a unit normal n, chosen continuously in n
/// away from the switch of the helper axis.
pub fn tangents(n: [f64; 3]) -> ([f64; 3], [f64; 3]) {
    let helper = if n[0].abs() < 0.6 { [1.0, 0.0, 0.0] } else { [0.0, 1.0, 0.0] };
    let t = cross(n, helper);
    let l = dot(t, t).sqrt();
    let t1 = [t[0] / l, t[1] / l, t[2] / l];
    (t1, cross(n, t1))
}

/// Velocity of the point at lever arm d of a body with V = (v, ω).
#[inline(always)]
pub fn point_velocity(v: &[f64; 6], d: [f64; 3]) -> [f64; 3] {
    let w = [v[3], v[4], v[5]];
    let c = cross(w, d);
    [v[0] + c[0], v[1] + c[1], v[2] + c[2]]
}

/// u = Bᵀ (v_p,i − v_p,j).
#[inline(always)]
pub fn local_velocity(f: &Frame3, vi: &[f64; 6], vj: &[f64; 6]) -> [f64; 3] {
    let (a, b) = (point_velocity(vi, f.d_i), point_velocity(vj, f.d_j));
    let dv = [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
    [dot(f.basis[0], dv), dot(f.basis[1], dv), dot(f.basis[2], dv)]
}

/// The world vector B r of a local one.
#[inline(always)]
pub fn to_world(b: &[[f64; 3]; 3], r: [f64; 3]) -> [f64; 3] {
    [
        b[0][0] * r[0] + b[1][0] * r[1] + b[2][0] * r[2],
        b[0][1] * r[0] + b[1][1] * r[1] + b[2][1] * r[2],
        b[0][2] * r[0] + b[1][2] * r[1] + b[2][2] * r[2],
    ]
}

/// Adds the velocity change of an impulse `dr` (local) to both bodies.
#[inline(always)]
pub fn apply(f: &Frame3, dr: [f64; 3], bi: usize, bj: usize, vel: &mut [[f64; 6]], inv: &[InvMass3]) {
    let p = to_world(&f.basis, dr);
    let (ii, ij) = (&inv[bi], &inv[bj]);
    let (mi, mj) = (ii.m, ij.m);
    let wi = coulomb::mul(&ii.i, cross(f.d_i, p));
    let wj = coulomb::mul(&ij.i, cross(f.d_j, p));
    let vi = &mut vel[bi];
    for k in 0..3 {
        vi[k] += mi[k] * p[k];
        vi[3 + k] += wi[k];
    }
    let vj = &mut vel[bj];
    for k in 0..3 {
        vj[k] -= mj[k] * p[k];
        vj[3 + k] -= wj[k];
    }
}

/// K_b = diag(m⁻¹) + [d]×ᵀ I⁻¹ [d]× (symmetric, full).
fn k_matrix(inv_m: [f64; 3], inv_i: &Sym3, d: [f64; 3]) -> [[f64; 3]; 3] {
    let mut k = [[0.0; 3]; 3];
    // column c: [d]×ᵀ I⁻¹ (d × e_c) = −d × (I⁻¹ (d × e_c))
    for c in 0..3 {
        let mut e = [0.0; 3];
        e[c] = 1.0;
        let w = coulomb::mul(inv_i, cross(d, e));
        let col = cross(w, d);
        for r in 0..3 {
            k[r][c] = col[r];
        }
        k[c][c] += inv_m[c];
    }
    k
}

/// The Delassus block W_αα = Bᵀ (K_i + K_j) B.
pub fn delassus(f: &Frame3, mi: [f64; 3], ii: &Sym3, mj: [f64; 3], ij: &Sym3) -> Sym3 {
    let (ki, kj) = (k_matrix(mi, ii, f.d_i), k_matrix(mj, ij, f.d_j));
    let b = &f.basis;
    let e = |a: usize, c: usize| {
        let mut s = 0.0;
        for r in 0..3 {
            for q in 0..3 {
                s += b[a][r] * (ki[r][q] + kj[r][q]) * b[c][q];
            }
        }
        s
    };
    let mut w = [e(0, 0), e(0, 1), e(0, 2), e(1, 1), e(1, 2), e(2, 2)];
    // round-off below the block's scale: keep the exact sphere structure
    let scale = w[0].abs().max(w[3].abs()).max(w[5].abs());
    for x in [1usize, 2, 4] {
        if w[x].abs() <= 1e-15 * scale {
            w[x] = 0.0;
        }
    }
    if (w[3] - w[5]).abs() <= 1e-15 * scale {
        w[5] = w[3];
    }
    w
}

/// World inertia tensor I_w = R diag(I) Rᵀ (upper triangle) of principal moments
/// `i` at orientation q.
pub fn world_inertia(q: &[f64; 4], i: &[f64; 3]) -> Sym3 {
    let r = rotation_matrix(*q);
    let e = |a: usize, c: usize| (0..3).map(|k| r[a][k] * i[k] * r[c][k]).sum::<f64>();
    [e(0, 0), e(0, 1), e(0, 2), e(1, 1), e(1, 2), e(2, 2)]
}

/// M̂⁻¹ from the mass, orientation and free degrees of freedom: `1/m` on free
/// axes, `(I_w restricted to the free rotational axes)⁻¹`, padded with zeros.
pub fn inv_mass(m: f64, inertia: &[f64; 3], q: &[f64; 4], f: u8) -> InvMass3 {
    let mut out = InvMass3::default();
    for k in 0..3 {
        out.m[k] = if f & (1 << k) != 0 { 1.0 / m } else { 0.0 };
    }
    // the free rotational axes, without allocating (this runs every step for
    // bodies whose world inertia turns with them)
    let (mut rot_free, mut nfree) = ([0usize; 3], 0);
    for k in 0..3 {
        if f & (1 << (3 + k)) != 0 {
            rot_free[nfree] = k;
            nfree += 1;
        }
    }
    // an isotropic body's world inertia is its own at any orientation: taken exactly
    // (rotated, it would carry the orientation's rounding, and a restart, which
    // recomputes M̂⁻¹ at the saved orientation, would not continue bitwise)
    let iw = if inertia[0] == inertia[1] && inertia[1] == inertia[2] {
        [inertia[0], 0.0, 0.0, inertia[0], 0.0, inertia[0]]
    } else {
        world_inertia(q, inertia)
    };
    // entry (a, c) of the symmetric tensor stored as [xx, xy, xz, yy, yz, zz]
    const IDX: [[usize; 3]; 3] = [[0, 1, 2], [1, 3, 4], [2, 4, 5]];
    let full = |a: usize, c: usize| iw[IDX[a][c]];
    let mut r = [[0.0; 3]; 3];
    match nfree {
        0 => {}
        1 => {
            let a = rot_free[0];
            r[a][a] = 1.0 / full(a, a);
        }
        2 => {
            let (a, c) = (rot_free[0], rot_free[1]);
            let (p, q, s) = (full(a, a), full(a, c), full(c, c));
            let det = p * s - q * q;
            r[a][a] = s / det;
            r[a][c] = -q / det;
            r[c][a] = -q / det;
            r[c][c] = p / det;
        }
        _ => {
            out.i = coulomb::inverse(&iw).unwrap_or([0.0; 6]);
            return out;
        }
    }
    out.i = [r[0][0], r[0][1], r[0][2], r[1][1], r[1][2], r[2][2]];
    out
}

impl Dim for D3 {
    const N: usize = 3;
    const DOF: usize = 6;
    const NAME: &'static str = "3D";
    type Point = [f64; 3];
    type Rot = [f64; 4];
    type Twist = [f64; 6];
    type Local = [f64; 3];
    type Frame = Frame3;
    type W = Sym3;
    type Block = Block3;
    type InvMass = InvMass3;
    type Inertia = [f64; 3];
    type RotVec = [f64; 3];

    fn rot_identity() -> [f64; 4] {
        [1.0, 0.0, 0.0, 0.0]
    }
    fn rot_from_vec(r: &[f64; 3]) -> [f64; 4] {
        rotation::from_rotation_vector(*r)
    }
    fn rot_to_vec(q: &[f64; 4]) -> [f64; 3] {
        rotation::to_rotation_vector(*q)
    }
    fn rotate(q: &[f64; 4], p: &[f64; 3]) -> [f64; 3] {
        rotation::rotate(*q, *p)
    }
    fn rot_mul(a: &[f64; 4], b: &[f64; 4]) -> [f64; 4] {
        rotation::normalize(rotation::quat_mul(*a, *b))
    }
    fn normalize_rot(q: [f64; 4]) -> [f64; 4] {
        rotation::normalize(q)
    }
    fn inv_mass(mass: f64, inertia: &[f64; 3], rot: &[f64; 4], free: u8) -> InvMass3 {
        inv_mass(mass, inertia, rot, free)
    }
    const INV_MASS_LEN: usize = 9;
    fn inv_mass_coords(im: &InvMass3, out: &mut Vec<f64>) {
        out.extend_from_slice(&im.m);
        out.extend_from_slice(&im.i);
    }
    fn inv_mass_from(x: &[f64]) -> InvMass3 {
        InvMass3 {
            m: [x[0], x[1], x[2]],
            i: [x[3], x[4], x[5], x[6], x[7], x[8]],
        }
    }
    fn isotropic(i: &[f64; 3]) -> bool {
        i[0] == i[1] && i[1] == i[2]
    }
    fn rho2(m: f64, i: &[f64; 3]) -> f64 {
        if m > 0.0 && m.is_finite() && i.iter().all(|x| x.is_finite()) {
            (i[0] + i[1] + i[2]) / (3.0 * m)
        } else {
            0.0
        }
    }
    #[inline]
    fn integrate(pos: &mut [f64; 3], q: &mut [f64; 4], v0: &[f64; 6], v1: &[f64; 6], h: f64, theta: f64) {
        let vm: [f64; 6] = std::array::from_fn(|a| (1.0 - theta) * v0[a] + theta * v1[a]);
        for a in 0..3 {
            pos[a] += h * vm[a];
        }
        let rot = [h * vm[3], h * vm[4], h * vm[5]];
        if rot != [0.0; 3] {
            *q = rotation::normalize(rotation::quat_mul(rotation::from_rotation_vector(rot), *q));
        }
    }
    fn kinetic_energy(m: f64, i: &[f64; 3], q: &[f64; 4], v: &[f64; 6]) -> f64 {
        let iw = world_inertia(q, i);
        let w = [v[3], v[4], v[5]];
        let iwv = coulomb::mul(&iw, w);
        0.5 * m * (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]) + 0.5 * (w[0] * iwv[0] + w[1] * iwv[1] + w[2] * iwv[2])
    }
    #[inline]
    fn free_flight(v: &mut [f64; 6], m: f64, i: &[f64; 3], q: &[f64; 4], inv: &InvMass3, g: &[f64; 3], h: f64) {
        for a in 0..3 {
            v[a] += h * inv.m[a] * m * g[a];
        }
        if !Self::isotropic(i) {
            // gyroscopic torque −ω × (I_w ω), explicit
            let iw = world_inertia(q, i);
            let om = [v[3], v[4], v[5]];
            let l = coulomb::mul(&iw, om);
            let tq = cross(om, l);
            let dw = coulomb::mul(&inv.i, [-h * tq[0], -h * tq[1], -h * tq[2]]);
            for a in 0..3 {
                v[3 + a] += dw[a];
            }
        }
    }
    fn apply_moment(v: &mut [f64; 6], _i: &[f64; 3], inv: &InvMass3, axis: usize, hm: f64) {
        let mut tq = [0.0; 3];
        tq[axis] = hm;
        let dw = coulomb::mul(&inv.i, tq);
        for a in 0..3 {
            v[3 + a] += dw[a];
        }
    }
    fn rot_finite(q: &[f64; 4]) -> bool {
        q.iter().all(|x| x.is_finite())
    }

    #[inline]
    fn frame(p: &[f64; 3], n: &[f64; 3], x_i: &[f64; 3], x_j: &[f64; 3]) -> Frame3 {
        let (t1, t2) = tangents(*n);
        let arm = |x: &[f64; 3]| [p[0] - x[0], p[1] - x[1], p[2] - x[2]];
        Frame3 {
            basis: [*n, t1, t2],
            d_i: arm(x_i),
            d_j: arm(x_j),
        }
    }
    fn normal(f: &Frame3) -> [f64; 3] {
        f.basis[0]
    }
    fn to_world(f: &Frame3, r: &[f64; 3]) -> [f64; 3] {
        to_world(&f.basis, *r)
    }
    #[inline(always)]
    fn local_velocity(f: &Frame3, vi: &[f64; 6], vj: &[f64; 6]) -> [f64; 3] {
        local_velocity(f, vi, vj)
    }
    #[inline(always)]
    fn apply(f: &Frame3, dr: &[f64; 3], i: usize, j: usize, vel: &mut [[f64; 6]], inv: &[InvMass3]) {
        apply(f, *dr, i, j, vel, inv)
    }
    #[inline]
    fn delassus(f: &Frame3, inv_i: &InvMass3, inv_j: &InvMass3) -> Sym3 {
        delassus(f, inv_i.m, &inv_i.i, inv_j.m, &inv_j.i)
    }
    #[inline(always)]
    fn w_nn(w: &Sym3) -> f64 {
        w[0]
    }
    #[inline]
    fn with_compliance(mut w: Sym3, c: f64) -> Sym3 {
        w[0] += c;
        w
    }
    #[inline]
    fn block(w: Sym3, _mu: f64) -> Block3 {
        Block3 {
            w,
            pre: coulomb::precompute(&w),
        }
    }
    #[inline(always)]
    fn w_mul(b: &Block3, r: &[f64; 3]) -> [f64; 3] {
        coulomb::mul(&b.w, *r)
    }
    #[inline(always)]
    fn solve(b: &Block3, u0: &[f64; 3], u_target: f64, mu: f64, prev: &[f64; 3]) -> [f64; 3] {
        coulomb::solve_pre_warm(&b.w, &b.pre, *u0, u_target, mu, *prev)
    }
    fn solve_joint(b: &Block3, u0: &[f64; 3], u_target: f64, mu: f64, j: &Joint, prev: &[f64; 3]) -> [f64; 3] {
        joint::solve(&b.w, &b.pre, *u0, u_target, mu, j, *prev)
    }
    fn project_joint(z: &[f64], mu: f64, j: &Joint) -> [f64; 3] {
        joint::project([z[0], z[1], z[2]], mu, j)
    }
    fn joint_holds(b: &Block3, r: &[f64; 3], u0: &[f64; 3], u_target: f64, mu: f64, j: &Joint, tol: f64) -> bool {
        joint::holds(&b.w, &b.pre, *r, *u0, u_target, mu, j, tol)
    }
    fn joint_natural_map_sq(r: &[f64; 3], u: &[f64; 3], mu: f64, j: &Joint) -> f64 {
        joint::natural_map_sq(*r, *u, mu, j)
    }
    #[inline]
    fn reaction_i(f: &Frame3, r: &[f64; 3]) -> [f64; 6] {
        let p = to_world(&f.basis, *r);
        let m = cross(f.d_i, p);
        [p[0], p[1], p[2], m[0], m[1], m[2]]
    }
    #[inline]
    fn reaction_j(f: &Frame3, r: &[f64; 3]) -> [f64; 6] {
        let p = to_world(&f.basis, *r);
        let m = cross(f.d_j, p);
        [p[0], p[1], p[2], m[0], m[1], m[2]]
    }
    fn scale_inv(im: &InvMass3, m: f64) -> InvMass3 {
        InvMass3 {
            m: im.m.map(|x| x * m),
            i: im.i.map(|x| x * m),
        }
    }
    fn apply_inv(v: &mut [f64; 6], im: &InvMass3, f: &[f64; 6]) {
        for d in 0..3 {
            v[d] += im.m[d] * f[d];
        }
        let w = coulomb::mul(&im.i, [f[3], f[4], f[5]]);
        for d in 0..3 {
            v[3 + d] += w[d];
        }
    }
    fn glue(v: &mut [f64; 6], f: &mut [f64; 6], im: &InvMass3, dv: &[f64; 6]) {
        for d in 0..3 {
            if im.m[d] != 0.0 {
                v[d] += dv[d];
                f[d] += dv[d] / im.m[d];
            }
        }
        // rotations: M̂_E = (I_E⁻¹)⁻¹ on the free axes
        match coulomb::inverse(&im.i) {
            Some(ie) => {
                let df = coulomb::mul(&ie, [dv[3], dv[4], dv[5]]);
                for d in 0..3 {
                    v[3 + d] += dv[3 + d];
                    f[3 + d] += df[d];
                }
            }
            None => {
                // some rotations driven: the free axes (diagonal of I⁻¹ restricted)
                let diag = [im.i[0], im.i[3], im.i[5]];
                for d in 0..3 {
                    if diag[d] != 0.0 {
                        v[3 + d] += dv[3 + d];
                        f[3 + d] += dv[3 + d] / diag[d];
                    }
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    /// An isotropic body's M̂⁻¹ is the same, bit for bit, at any orientation (a
    /// restart recomputes it at the saved one; the run kept the first), and an
    /// anisotropic body's turns with it.
    #[test]
    fn an_isotropic_bodys_inverse_mass_does_not_depend_on_its_orientation() {
        let (h, c, s) = (0.5f64, 0.3f64.cos(), 0.3f64.sin());
        let turned = [c, s * h.sqrt(), 0.0, s * (1.0 - h).sqrt()];
        let at = |i: [f64; 3], q: [f64; 4]| super::inv_mass(2.0, &i, &q, 0b111111);
        let ball = [0.7; 3];
        assert_eq!(at(ball, [1.0, 0.0, 0.0, 0.0]), at(ball, turned));
        let brick = [0.7, 0.4, 0.2];
        assert_ne!(at(brick, [1.0, 0.0, 0.0, 0.0]), at(brick, turned));
    }
}
