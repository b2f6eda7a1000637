//! Struct-of-arrays storage of the 2D contact set of one time step.

use serde::{Deserialize, Serialize};

/// Identity of a contact between steps: the two bodies and a feature index (for
/// shapes that touch at several points). Used to carry impulses over (warm start).
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
pub struct ContactKey {
    pub i: u32,
    pub j: u32,
    pub feature: u32,
}

/// 2D contacts. Hot fields for the NLGS sweep come first; one `Vec` per field.
#[derive(Clone, Debug, Default, Serialize, Deserialize)]
pub struct Contacts2 {
    /// Candidate body.
    pub i: Vec<u32>,
    /// Antagonist body.
    pub j: Vec<u32>,
    /// Unit normal n (from j towards i); t = (−n_y, n_x).
    pub n: Vec<[f64; 2]>,
    /// Lever arms of body i: (d_i × n, d_i × t).
    pub arm_i: Vec<[f64; 2]>,
    /// Lever arms of body j: (d_j × n, d_j × t).
    pub arm_j: Vec<[f64; 2]>,
    /// Diagonal Delassus block W_αα = [W_nn, W_nt, W_tt].
    pub w: Vec<[f64; 3]>,
    /// [`super::coulomb::precompute`] of (W_αα, μ): inverses reused by every sweep.
    pub w_pre: Vec<[f64; 5]>,
    /// Target normal velocity ū of the law: u_n ≥ ū ⊥ r_n ≥ 0.
    pub u_target: Vec<f64>,
    /// Friction coefficient μ.
    pub mu: Vec<f64>,
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
        self.i.len()
    }
    pub fn is_empty(&self) -> bool {
        self.i.is_empty()
    }
    pub fn clear(&mut self) {
        self.i.clear();
        self.j.clear();
        self.n.clear();
        self.arm_i.clear();
        self.arm_j.clear();
        self.w.clear();
        self.w_pre.clear();
        self.u_target.clear();
        self.mu.clear();
        self.r.clear();
        self.u_free.clear();
        self.gap.clear();
        self.point.clear();
        self.key.clear();
    }

    /// Local velocity u_α = H_iᵀ V_i − H_jᵀ V_j from body velocities.
    #[inline(always)]
    pub fn local_velocity(&self, a: usize, vel: &[[f64; 3]]) -> [f64; 2] {
        let n = self.n[a];
        let (vi, vj) = (vel[self.i[a] as usize], vel[self.j[a] as usize]);
        let (ai, aj) = (self.arm_i[a], self.arm_j[a]);
        let un = n[0] * (vi[0] - vj[0]) + n[1] * (vi[1] - vj[1]) + ai[0] * vi[2] - aj[0] * vj[2];
        let ut = -n[1] * (vi[0] - vj[0]) + n[0] * (vi[1] - vj[1]) + ai[1] * vi[2] - aj[1] * vj[2];
        [un, ut]
    }

    /// Applies the impulse increment `dr` of contact α to its bodies: V += M̂⁻¹ H Δr.
    #[inline(always)]
    pub fn apply(&self, a: usize, dr: [f64; 2], vel: &mut [[f64; 3]], inv_mass: &[[f64; 3]]) {
        let n = self.n[a];
        let px = dr[0] * n[0] - dr[1] * n[1];
        let py = dr[0] * n[1] + dr[1] * n[0];
        let (i, j) = (self.i[a] as usize, self.j[a] as usize);
        let (ai, aj) = (self.arm_i[a], self.arm_j[a]);
        let mi = inv_mass[i];
        let vi = &mut vel[i];
        vi[0] += mi[0] * px;
        vi[1] += mi[1] * py;
        vi[2] += mi[2] * (ai[0] * dr[0] + ai[1] * dr[1]);
        let mj = inv_mass[j];
        let vj = &mut vel[j];
        vj[0] -= mj[0] * px;
        vj[1] -= mj[1] * py;
        vj[2] -= mj[2] * (aj[0] * dr[0] + aj[1] * dr[1]);
    }

    /// W_αα from the frame, the arms and the bodies' M̂⁻¹.
    pub fn delassus(n: [f64; 2], ai: [f64; 2], aj: [f64; 2], mi: [f64; 3], mj: [f64; 3]) -> [f64; 3] {
        let t = [-n[1], n[0]];
        let mut w = [0.0; 3];
        for (a, m) in [(ai, mi), (aj, mj)] {
            w[0] += m[0] * n[0] * n[0] + m[1] * n[1] * n[1] + m[2] * a[0] * a[0];
            w[1] += m[0] * n[0] * t[0] + m[1] * n[1] * t[1] + m[2] * a[0] * a[1];
            w[2] += m[0] * t[0] * t[0] + m[1] * t[1] * t[1] + m[2] * a[1] * a[1];
        }
        w
    }
}
