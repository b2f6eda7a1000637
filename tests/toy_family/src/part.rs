//! A subdomain's share of the point masses: its copies of the points (velocity
//! V_E, m_E⁻¹ = mult/m) and its contacts, solved by NLGS sweeps against the
//! subdomain's copies of the rigid bodies.

use crate::{PointContact, PointMasses};
use nscdd::dd::{LocalPart, Rigid2};
use nscdd::dim::coulomb2;
use nscdd::dim::d2::{delassus, Frame2};
use nscdd::norms::Sums;
use std::any::Any;
use std::collections::BTreeMap;

/// Local components (n, t) of a world vector; t = (−n_y, n_x).
pub fn local(n: [f64; 2], v: [f64; 2]) -> [f64; 2] {
    [n[0] * v[0] + n[1] * v[1], -n[1] * v[0] + n[0] * v[1]]
}

/// World vector of local components.
pub fn global(n: [f64; 2], r: [f64; 2]) -> [f64; 2] {
    [r[0] * n[0] - r[1] * n[1], r[0] * n[1] + r[1] * n[0]]
}

/// Local velocity of a rigid body's material point at the contact.
pub fn rigid_local(n: [f64; 2], arm: [f64; 2], v: [f64; 3]) -> [f64; 2] {
    let l = local(n, [v[0], v[1]]);
    [l[0] + arm[0] * v[2], l[1] + arm[1] * v[2]]
}

/// One subdomain's point copies and contacts (contact `point`/`body` fields are
/// local ids here).
#[derive(Default)]
pub struct PointPart {
    /// Family id of each local point copy.
    pub ids: Vec<u32>,
    pub v: Vec<[f64; 2]>,
    pub mass: Vec<f64>,
    pub inv_m: Vec<f64>,
    pub contacts: Vec<PointContact>,
    /// W_αα = [W_nn, W_nt, W_tt] of each contact.
    pub w: Vec<[f64; 3]>,
    /// Index of each local contact in the family's contacts.
    pub global: Vec<u32>,
}

impl PointPart {
    /// Both sides of Δr: V_p += m_E⁻¹ H Δr, V_b −= M̂_E⁻¹ H Δr.
    fn apply(&mut self, vel: &mut [[f64; 3]], inv: &[[f64; 3]], c: &PointContact, dr: [f64; 2]) {
        let (p, b) = (c.point as usize, c.body as usize);
        let f = global(c.n, dr);
        self.v[p][0] += self.inv_m[p] * f[0];
        self.v[p][1] += self.inv_m[p] * f[1];
        let (vb, im) = (&mut vel[b], inv[b]);
        vb[0] -= im[0] * f[0];
        vb[1] -= im[1] * f[1];
        vb[2] -= im[2] * (c.arm[0] * dr[0] + c.arm[1] * dr[1]);
    }
}

impl LocalPart<Rigid2> for PointPart {
    fn len(&self) -> usize {
        self.contacts.len()
    }
    fn entities(&self) -> &[u32] {
        &self.ids
    }
    fn prepare(&mut self, inv: &[[f64; 3]], mult: &[u32]) {
        self.inv_m = self.mass.iter().zip(mult).map(|(m, &k)| k as f64 / m).collect();
        self.w = self
            .contacts
            .iter()
            .map(|c| {
                let f = Frame2 {
                    n: c.n,
                    arm_i: [0.0; 2],
                    arm_j: c.arm,
                };
                let im = self.inv_m[c.point as usize];
                delassus(&f, [im, im, 0.0], inv[c.body as usize])
            })
            .collect();
    }
    fn warm_start(&mut self, vel: &mut [[f64; 3]], inv: &[[f64; 3]]) {
        for k in 0..self.contacts.len() {
            let c = self.contacts[k];
            if c.r != [0.0; 2] {
                self.apply(vel, inv, &c, c.r);
            }
        }
    }
    fn sweep(&mut self, vel: &mut [[f64; 3]], inv: &[[f64; 3]], omega: f64, mut sums: Option<&mut Sums>) {
        for k in 0..self.contacts.len() {
            let c = self.contacts[k];
            let (l, rb) = (local(c.n, self.v[c.point as usize]), rigid_local(c.n, c.arm, vel[c.body as usize]));
            let w = self.w[k];
            let r = c.r;
            let wr_old = [w[0] * r[0] + w[1] * r[1], w[1] * r[0] + w[2] * r[1]];
            let u0 = [l[0] - rb[0] - wr_old[0], l[1] - rb[1] - wr_old[1]];
            let mut rn = coulomb2::solve(w, u0, c.u_target, c.mu);
            if omega != 1.0 {
                rn = [omega * rn[0] + (1.0 - omega) * r[0], omega * rn[1] + (1.0 - omega) * r[1]];
            }
            if let Some(s) = sums.as_deref_mut() {
                let wr = [w[0] * rn[0] + w[1] * rn[1], w[1] * rn[0] + w[2] * rn[1]];
                s.add(&r, &rn, &[wr[0] - wr_old[0], wr[1] - wr_old[1]], &wr_old, &wr);
            }
            let dr = [rn[0] - r[0], rn[1] - r[1]];
            if dr != [0.0; 2] {
                self.contacts[k].r = rn;
                self.apply(vel, inv, &c, dr);
            }
        }
    }
    fn entity_velocity(&self, e: usize, out: &mut Vec<f64>) {
        out.extend(self.v[e]);
    }
    fn glue_entity(&mut self, e: usize, dv: &[f64]) {
        self.v[e][0] += dv[0];
        self.v[e][1] += dv[1];
    }
    fn pack(&self, out: &mut Vec<f64>) {
        out.extend(self.contacts.iter().flat_map(|c| c.r));
    }
    fn packed_len(&self) -> usize {
        2 * self.contacts.len()
    }
    fn unpack(&mut self, values: &[f64]) {
        for (c, r) in self.contacts.iter_mut().zip(values.chunks_exact(2)) {
            c.r = [r[0], r[1]];
        }
    }
    fn as_any(&self) -> &dyn Any {
        self
    }
}

/// The family's contacts grouped by subdomain (ascending), each with its copies of
/// the points (at V_free) and of the rigid bodies (`copy`).
pub fn split(f: &PointMasses, owner: &[u32], copy: &mut dyn FnMut(u32, u32) -> u32) -> Vec<(u32, Box<dyn LocalPart<Rigid2>>)> {
    let mut parts: BTreeMap<u32, PointPart> = BTreeMap::new();
    for (a, c) in f.contacts.iter().enumerate() {
        let s = owner[a];
        let part = parts.entry(s).or_default();
        let p = match part.ids.iter().position(|&i| i == c.point) {
            Some(p) => p,
            None => {
                part.ids.push(c.point);
                part.v.push(f.v_free[c.point as usize]);
                part.mass.push(f.mass[c.point as usize]);
                part.ids.len() - 1
            }
        };
        let mut local = *c;
        local.point = p as u32;
        local.body = copy(s, c.body);
        part.contacts.push(local);
        part.global.push(a as u32);
    }
    parts
        .into_iter()
        .map(|(s, p)| (s, Box::new(p) as Box<dyn LocalPart<Rigid2>>))
        .collect()
}
