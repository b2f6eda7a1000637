//! Storage of the 2D contact set of one time step: one `Vec` per field, a field being
//! what one stage reads together (the bodies of a contact, its frame, its Delassus
//! block, its law targets, its impulse), so that an NLGS sweep streams five arrays.
//! Measured: grouping the hot data this way instead of one `Vec` per scalar made the
//! sweep 1.75× faster (docs/PERFORMANCE.md).

use serde::{Deserialize, Serialize};

/// Identity of a contact between steps: the two bodies and a feature index (for
/// shapes that touch at several points). Used to carry impulses over (warm start).
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
pub struct ContactKey {
    pub i: u32,
    pub j: u32,
    pub feature: u32,
}

/// The local frame of a contact: the unit normal n (from the antagonist j towards the
/// candidate i; t = (−n_y, n_x)) and the lever arms (d × n, d × t) of both bodies,
/// d = p − x_b.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
#[repr(C)]
pub struct Frame2 {
    pub n: [f64; 2],
    pub arm_i: [f64; 2],
    pub arm_j: [f64; 2],
}

/// The diagonal Delassus block W_αα = [W_nn, W_nt, W_tt] and its
/// [`super::coulomb::precompute`]d inverses, reused by every sweep.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
#[repr(C)]
pub struct Block2 {
    pub w: [f64; 3],
    pub pre: [f64; 5],
}

/// What the law asks of a contact: the target normal velocity ū (u_n ≥ ū ⊥ r_n ≥ 0)
/// and the friction coefficient μ.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
#[repr(C)]
pub struct Target {
    pub u_target: f64,
    pub mu: f64,
}

/// 2D contacts, indexed by dense ids. The first five fields are the NLGS sweep's.
#[derive(Clone, Debug, Default, Serialize, Deserialize)]
pub struct Contacts2 {
    /// (candidate i, antagonist j).
    pub bodies: Vec<[u32; 2]>,
    pub frame: Vec<Frame2>,
    pub block: Vec<Block2>,
    pub target: Vec<Target>,
    /// Impulse r = (r_n, r_t).
    pub r: Vec<[f64; 2]>,
    /// Local free velocity u_free = Hᵀ V_free.
    pub u_free: Vec<[f64; 2]>,
    /// Gap at the start of the step.
    pub gap: Vec<f64>,
    /// Contact point.
    pub point: Vec<[f64; 2]>,
    pub key: Vec<ContactKey>,
}

impl Contacts2 {
    pub fn len(&self) -> usize {
        self.bodies.len()
    }
    pub fn is_empty(&self) -> bool {
        self.bodies.is_empty()
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
    }

    /// Room for `n` more contacts in every field.
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
    }

    /// Appends contact `a` of `other` with its bodies renamed (i, j).
    pub fn push_from(&mut self, other: &Contacts2, a: usize, i: u32, j: u32) {
        self.bodies.push([i, j]);
        self.frame.push(other.frame[a]);
        self.block.push(other.block[a]);
        self.target.push(other.target[a]);
        self.r.push(other.r[a]);
        self.u_free.push(other.u_free[a]);
        self.gap.push(other.gap[a]);
        self.point.push(other.point[a]);
        self.key.push(other.key[a]);
    }

    /// Local velocity u_α = H_iᵀ V_i − H_jᵀ V_j from body velocities.
    #[inline(always)]
    pub fn local_velocity(&self, a: usize, vel: &[[f64; 3]]) -> [f64; 2] {
        let [i, j] = self.bodies[a];
        local_velocity(&self.frame[a], vel[i as usize], vel[j as usize])
    }

    /// Applies the impulse increment `dr` of contact α to its bodies: V += M̂⁻¹ H Δr.
    #[inline(always)]
    pub fn apply(&self, a: usize, dr: [f64; 2], vel: &mut [[f64; 3]], inv_mass: &[[f64; 3]]) {
        let [i, j] = self.bodies[a];
        apply(&self.frame[a], dr, i as usize, j as usize, vel, inv_mass);
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
