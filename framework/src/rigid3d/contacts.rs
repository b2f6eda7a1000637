//! Storage of the 3D contact set of one time step, one `Vec` per group of fields a
//! stage reads together (as in 2D).
//!
//! A contact α between a candidate body i and an antagonist body j has the
//! orthonormal frame `B = [n t1 t2]` (n from j towards i) and the lever arms
//! `d_b = p − x_b` of the contact point p. The local velocity is the relative
//! velocity of the contact point in that frame,
//!
//! ```text
//! u_α = Bᵀ ((v_i + ω_i × d_i) − (v_j + ω_j × d_j)),
//! ```
//!
//! an impulse r acts as `P = B r` at p: `Δv_i = m_i⁻¹ P`, `Δω_i = I_i⁻¹ (d_i × P)`
//! and the opposite on j, and the Delassus block is
//! `W_αα = Bᵀ (K_i + K_j) B` with `K_b = diag(m_b⁻¹) + [d_b]×ᵀ I_b⁻¹ [d_b]×`.

use super::bodies::{cross, dot};
use super::coulomb::{Pre3, Sym3};
use super::joint::Joint;
use crate::rigid2d::contacts::{ContactKey, Target};
use serde::{Deserialize, Serialize};

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

/// 3D contacts, indexed by dense ids. The first five fields are the sweep's.
#[derive(Clone, Debug, Default, Serialize, Deserialize)]
pub struct Contacts3 {
    pub bodies: Vec<[u32; 2]>,
    pub frame: Vec<Frame3>,
    pub block: Vec<Block3>,
    pub target: Vec<Target>,
    /// Impulse r = (r_n, r_t1, r_t2).
    pub r: Vec<[f64; 3]>,
    pub u_free: Vec<[f64; 3]>,
    pub gap: Vec<f64>,
    pub point: Vec<[f64; 3]>,
    pub key: Vec<ContactKey>,
    /// Strengths of bonded joints (zero for other contacts).
    pub joint: Vec<Joint>,
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

/// I⁻¹ v for a symmetric block.
#[inline(always)]
fn sym_mul(w: &Sym3, v: [f64; 3]) -> [f64; 3] {
    super::coulomb::mul(w, v)
}

/// M̂⁻¹ of one 3D rigid body: translational diagonal and rotational block.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct InvMass3 {
    pub m: [f64; 3],
    pub i: Sym3,
}

/// Where a sweep reads the bodies' M̂⁻¹: the world's two arrays ([`Split`]) or a
/// subdomain's copies (`[InvMass3]`). Monomorphized: no dispatch per contact.
pub trait InvMassOf {
    fn inv_m(&self, b: usize) -> [f64; 3];
    fn inv_i(&self, b: usize) -> &Sym3;
}

/// The world's `inv_m` and `inv_i` arrays.
pub struct Split<'a>(pub &'a [[f64; 3]], pub &'a [Sym3]);

impl InvMassOf for Split<'_> {
    #[inline(always)]
    fn inv_m(&self, b: usize) -> [f64; 3] {
        self.0[b]
    }
    #[inline(always)]
    fn inv_i(&self, b: usize) -> &Sym3 {
        &self.1[b]
    }
}

impl InvMassOf for [InvMass3] {
    #[inline(always)]
    fn inv_m(&self, b: usize) -> [f64; 3] {
        self[b].m
    }
    #[inline(always)]
    fn inv_i(&self, b: usize) -> &Sym3 {
        &self[b].i
    }
}

/// Adds the velocity change of an impulse `dr` (local) to both bodies.
#[inline(always)]
pub fn apply(f: &Frame3, dr: [f64; 3], bi: usize, bj: usize, vel: &mut [[f64; 6]], inv_m: &[[f64; 3]], inv_i: &[Sym3]) {
    apply_with(f, dr, bi, bj, vel, &Split(inv_m, inv_i));
}

/// [`apply`] with the masses read through an [`InvMassOf`].
#[inline(always)]
pub fn apply_with<M: InvMassOf + ?Sized>(f: &Frame3, dr: [f64; 3], bi: usize, bj: usize, vel: &mut [[f64; 6]], inv: &M) {
    let b = &f.basis;
    let p = [
        b[0][0] * dr[0] + b[1][0] * dr[1] + b[2][0] * dr[2],
        b[0][1] * dr[0] + b[1][1] * dr[1] + b[2][1] * dr[2],
        b[0][2] * dr[0] + b[1][2] * dr[1] + b[2][2] * dr[2],
    ];
    let (mi, mj) = (inv.inv_m(bi), inv.inv_m(bj));
    let wi = sym_mul(inv.inv_i(bi), cross(f.d_i, p));
    let wj = sym_mul(inv.inv_i(bj), cross(f.d_j, p));
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
        let w = sym_mul(inv_i, cross(d, e));
        let col = cross(w, d);
        for r in 0..3 {
            k[r][c] = col[r];
        }
        k[c][c] += inv_m[c];
    }
    k
}

impl Contacts3 {
    pub fn len(&self) -> usize {
        self.bodies.len()
    }
    pub fn is_empty(&self) -> bool {
        self.bodies.is_empty()
    }
    pub fn reserve(&mut self, n: usize) {
        self.bodies.reserve(n);
        self.frame.reserve(n);
        self.block.reserve(n);
        self.target.reserve(n);
        self.r.reserve(n);
        self.u_free.reserve(n);
        self.gap.reserve(n);
        self.point.reserve(n);
        self.key.reserve(n);
        self.joint.reserve(n);
    }

    /// Appends contact `a` of `other` with its bodies renamed (i, j).
    pub fn push_from(&mut self, other: &Contacts3, a: usize, i: u32, j: u32) {
        self.bodies.push([i, j]);
        self.frame.push(other.frame[a]);
        self.block.push(other.block[a]);
        self.target.push(other.target[a]);
        self.r.push(other.r[a]);
        self.u_free.push(other.u_free[a]);
        self.gap.push(other.gap[a]);
        self.point.push(other.point[a]);
        self.key.push(other.key[a]);
        self.joint.push(other.joint[a]);
    }

    pub fn clear(&mut self) {
        self.bodies.clear();
        self.frame.clear();
        self.block.clear();
        self.target.clear();
        self.r.clear();
        self.u_free.clear();
        self.gap.clear();
        self.point.clear();
        self.key.clear();
        self.joint.clear();
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

    /// Local velocity of contact α from the body velocities.
    #[inline]
    pub fn local_velocity(&self, a: usize, vel: &[[f64; 6]]) -> [f64; 3] {
        let [i, j] = self.bodies[a];
        local_velocity(&self.frame[a], &vel[i as usize], &vel[j as usize])
    }

    /// World impulse B r of contact α.
    pub fn world_impulse(&self, a: usize) -> [f64; 3] {
        let (b, r) = (&self.frame[a].basis, self.r[a]);
        [
            b[0][0] * r[0] + b[1][0] * r[1] + b[2][0] * r[2],
            b[0][1] * r[0] + b[1][1] * r[1] + b[2][1] * r[2],
            b[0][2] * r[0] + b[1][2] * r[1] + b[2][2] * r[2],
        ]
    }
}
