//! Subdomains by model (DESIGN.md §3, "model coupling"): the rigid contacts in some
//! subdomains, the contacts touching deformable bodies in others, glued through the
//! bodies they share by the same multiplier stage as the geometric NSCDD.
//!
//! With `[decomposition] by_model = true, nx, ny`, a contact belongs to subdomain
//! (model, cell): model 0 for rigid–rigid contacts, 1 for contacts of deformable
//! nodes; cell on the nx × ny grid of the contact points' bounding box. A body
//! touched by m subdomains has m copies, each with M̂/m and F̂/m (partition of
//! unity; for a deformable body M̂/m = (M + h²θ²K)/m, so its copy's G blocks are m G).
//!
//! Gluing (exact per body, copies of equal M̂_E go to their mean, see
//! `nscdd::dd::gluing`): a rigid copy gets ΔF_Γ,k = M̂_E (V̄ − V_k). A deformable
//! copy's velocity field is V_free + m M̂⁻¹ b_k with b_k = F_Γ,k + H_k r_k (forces at
//! its contact nodes), so M̂_E [V] = b_k − b_l: the gluing sets every b_k to the mean
//! b̄ with ΔF_Γ,k = b̄ − b_k, and the copy's contact nodes move by m G ΔF_Γ,k: no
//! solve. Iteration per step: { one NLGS sweep in every subdomain; gluing } until
//! the merged check sums meet the criterion and egluing / QuadWR < tol (egluing of
//! deformable copies over their contact nodes). After it, V⁺ of a rigid body is the
//! mean of its copies and a deformable body's V⁺ comes from Σ H r as in one domain.
//! Subdomains are swept one after the other in one thread (the threads and MPI
//! coordinators of `nscdd::dd` serve rigid families only so far); F_Γ starts from
//! zero at every step (the impulses r are warm-started).

use crate::contact2::*;
use crate::stage2::{self, Deformables2};
use nscdd::dim::coulomb2 as coulomb;
use nscdd::dim::d2::Block2;
use nscdd::engine::ContactStage;
use nscdd::model::Contacts2;
use nscdd::norms::{Norms, Sums};
use nscdd::solver::SolveReport;
use nscdd::world::World2;

/// Settings of the subdomains by model.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ByModel {
    pub nx: usize,
    pub ny: usize,
}

impl ByModel {
    /// From the scene's `[decomposition]` (validated by the framework).
    pub fn from_config(d: Option<&nscdd::dd::DdConfig>) -> Option<ByModel> {
        let d = d.filter(|d| d.by_model)?;
        Some(ByModel {
            nx: d.dd.nx as usize,
            ny: d.dd.ny as usize,
        })
    }
}

/// One subdomain: its copies and its contacts in local ids.
#[derive(Default)]
struct Sub {
    rigid: Vec<u32>,
    vel: Vec<[f64; 3]>,
    inv: Vec<[f64; 3]>,
    contacts: Contacts2,
    gidx: Vec<u32>,
    fe: Vec<u32>,
    sets: Vec<NodeSet>,
    /// b_k = F_Γ,k + H_k r_k of each deformable copy (2 per node of its set).
    fgam: Vec<Vec<f64>>,
    fec: FeContacts2,
    fe_gidx: Vec<u32>,
}

/// The NSCDD stage by model (module docs); wraps the one-domain deformable stage.
pub struct Coupled<'a> {
    pub fe: &'a mut Deformables2,
    pub by: ByModel,
    /// Relative gluing residual of the last check pass.
    pub egluing: f64,
}

impl ContactStage<World2> for Coupled<'_> {
    fn after_free_velocity(&mut self, w: &World2) {
        self.fe.after_free_velocity(w);
    }
    fn prepare(&mut self, w: &mut World2) {
        self.fe.build(w);
    }
    fn solve(&mut self, w: &mut World2) -> SolveReport {
        let (mut subs, ifaces_r, ifaces_f) = self.split(w);
        let s = w.solver.clone();
        let mut report = SolveReport::default();
        let none = w.contacts.is_empty() && self.fe.contacts.is_empty();
        let egluing = &mut self.egluing;
        if !none {
            (report.sweeps, report.converged) = nscdd::solver::check_loop(s.max_sweeps, s.check_every, |check| {
                let mut sums = Sums::default();
                for sd in subs.iter_mut() {
                    let mut part = Sums::default();
                    let mut sm = check.then_some(&mut part);
                    nscdd::solver::nlgs::sweep(&mut sd.contacts, &mut sd.vel, &sd.inv, &[], s.relaxation, sm.as_deref_mut());
                    stage2::sweep(&mut sd.fec, &mut sd.sets, &mut sd.vel, &sd.inv, s.relaxation, sm);
                    sums.merge(&part);
                }
                let (jump2, links, v2, copies) = glue(&mut subs, &ifaces_r, &ifaces_f, w);
                if !check {
                    return false;
                }
                report.norms = Norms::from_sums(&sums, s.tolerance);
                let eg = if links == 0 { 0.0 } else { jump2.sqrt() / links as f64 };
                // QuadWR, or the RMS velocity of the interface copies when the
                // impulses vanish (as `nscdd::dd::gluing`)
                let quad_wr = if sums.nactif > 0 {
                    (sums.sum_wrwr / sums.nactif as f64).sqrt()
                } else {
                    0.0
                };
                let rms = if copies > 0 { (v2 / copies as f64).sqrt() } else { 0.0 };
                let scale = if sums.sum_wrwr > nscdd::norms::VANISHING { quad_wr } else { rms };
                *egluing = if scale > 0.0 { eg / scale } else { eg };
                report.norms.converged(s.norm) && *egluing < s.tolerance
            });
        }
        if none {
            report.converged = true;
        }
        // back to the world: impulses, rigid velocities (mean of the copies)
        let mut acc = vec![([0.0f64; 3], 0u32); w.bodies.len()];
        for sd in &subs {
            for (l, &g) in sd.gidx.iter().enumerate() {
                w.contacts.r[g as usize] = sd.contacts.r[l];
            }
            for (l, &g) in sd.fe_gidx.iter().enumerate() {
                self.fe.contacts.r[g as usize] = sd.fec.r[l];
            }
            for (l, &b) in sd.rigid.iter().enumerate() {
                let a = &mut acc[b as usize];
                for q in 0..3 {
                    a.0[q] += sd.vel[l][q];
                }
                a.1 += 1;
            }
        }
        for (b, (v, m)) in acc.into_iter().enumerate() {
            if m > 0 {
                w.bodies.vel[b] = v.map(|x| x / m as f64);
            }
        }
        self.fe.finish_velocities();
        // the deformable sets hold the one-domain velocities again for the residual
        for (bi, set) in self.fe.sets.iter_mut().enumerate() {
            let b = &self.fe.bodies[bi];
            for (kk, &nd) in set.nodes.iter().enumerate() {
                set.v[kk] = [b.v[2 * nd as usize], b.v[2 * nd as usize + 1]];
            }
        }
        report.residual = self.fe.residual(w);
        report
    }
}

/// Interface body: its copies (subdomain, local index).
type Iface = Vec<(u32, u32)>;

impl Coupled<'_> {
    /// Assigns the contacts to subdomains and builds the copies.
    fn split(&mut self, w: &World2) -> (Vec<Sub>, Vec<(u32, Iface)>, Vec<(u32, Iface)>) {
        let fe = &*self.fe;
        let (nx, ny) = (self.by.nx, self.by.ny);
        let mut lo = [f64::INFINITY; 2];
        let mut hi = [f64::NEG_INFINITY; 2];
        for p in w.contacts.point.iter().chain(&fe.contacts.point) {
            for d in 0..2 {
                lo[d] = lo[d].min(p[d]);
                hi[d] = hi[d].max(p[d]);
            }
        }
        let cell = |p: [f64; 2]| {
            let f = |d: usize, n: usize| {
                let span = hi[d] - lo[d];
                if span > 0.0 {
                    (((p[d] - lo[d]) / span * n as f64) as usize).min(n - 1)
                } else {
                    0
                }
            };
            f(0, nx) + nx * f(1, ny)
        };
        let nc = nx * ny;
        let mut subs: Vec<Sub> = (0..2 * nc).map(|_| Sub::default()).collect();
        let nb = w.bodies.len();
        // local ids of rigid bodies / deformable bodies per subdomain
        let mut rloc: Vec<Vec<(u32, u32)>> = vec![vec![]; nb];
        let mut floc: Vec<Vec<(u32, u32)>> = vec![vec![]; fe.bodies.len()];
        let rid = |sd: &mut Sub, rloc: &mut Vec<Vec<(u32, u32)>>, e: u32, b: u32| -> u32 {
            if let Some(&(_, l)) = rloc[b as usize].iter().find(|x| x.0 == e) {
                return l;
            }
            let l = sd.rigid.len() as u32;
            sd.rigid.push(b);
            rloc[b as usize].push((e, l));
            l
        };
        let fid = |sd: &mut Sub, floc: &mut Vec<Vec<(u32, u32)>>, e: u32, b: u32| -> u32 {
            if let Some(&(_, l)) = floc[b as usize].iter().find(|x| x.0 == e) {
                return l;
            }
            let l = sd.fe.len() as u32;
            sd.fe.push(b);
            floc[b as usize].push((e, l));
            l
        };
        for a in 0..w.contacts.len() {
            let e = cell(w.contacts.point[a]) as u32;
            let sd = &mut subs[e as usize];
            let [i, j] = w.contacts.bodies[a];
            let li = rid(sd, &mut rloc, e, i);
            let lj = rid(sd, &mut rloc, e, j);
            sd.contacts.push_from(&w.contacts, a, li, lj);
            sd.gidx.push(a as u32);
        }
        let c = &fe.contacts;
        for a in 0..c.len() {
            let e = (nc + cell(c.point[a])) as u32;
            let sd = &mut subs[e as usize];
            let mut cand = c.cand[a];
            cand.body = fid(sd, &mut floc, e, cand.body);
            let anta = match c.anta[a] {
                Anta::Rigid { body, arm } => Anta::Rigid {
                    body: rid(sd, &mut rloc, e, body),
                    arm,
                },
                Anta::Fe(mut s) => {
                    s.body = fid(sd, &mut floc, e, s.body);
                    Anta::Fe(s)
                }
            };
            sd.fec.push_from(c, a, cand, anta);
            sd.fe_gidx.push(a as u32);
        }
        // copies: partition of unity, velocities from V_free (the world's bodies hold
        // V_free plus the warm start; the warm start is re-applied per subdomain)
        for sd in subs.iter_mut() {
            for &b in &sd.rigid {
                let m = rloc[b as usize].len() as f64;
                sd.inv.push(w.bodies.inv_mass[b as usize].map(|x| x * m));
            }
            for &b in &sd.fe {
                let m = floc[b as usize].len() as f64;
                let mut set = fe.sets[b as usize].clone();
                let body = &fe.bodies[b as usize];
                for (kk, &nd) in set.nodes.iter().enumerate() {
                    set.v[kk] = [body.v_free[2 * nd as usize], body.v_free[2 * nd as usize + 1]];
                }
                for g in &mut set.g {
                    *g *= m;
                }
                sd.fgam.push(vec![0.0; 2 * set.nodes.len()]);
                sd.sets.push(set);
            }
        }
        // rigid velocities: V_free = the world's velocity minus its warm-start share
        let mut vfree = w.bodies.vel.clone();
        {
            let cc = &w.contacts;
            for a in 0..cc.len() {
                if cc.r[a] != [0.0, 0.0] {
                    cc.apply(a, &[-cc.r[a][0], -cc.r[a][1]], &mut vfree, &w.bodies.inv_mass);
                }
            }
            for a in 0..c.len() {
                if let Anta::Rigid { body, arm } = c.anta[a] {
                    let r = c.r[a];
                    let b = body as usize;
                    rigid_apply(c.frame[a], arm, [-r[0], -r[1]], &mut vfree[b], w.bodies.inv_mass[b]);
                }
            }
        }
        for sd in subs.iter_mut() {
            sd.vel = sd.rigid.iter().map(|&b| vfree[b as usize]).collect();
            <nscdd::dd::Rigid2 as nscdd::dd::Family>::copy_delassus(&mut sd.contacts, &sd.inv);
            for a in 0..sd.fec.len() {
                let (cand, anta, n) = (sd.fec.cand[a], sd.fec.anta[a], sd.fec.frame[a]);
                let mut wb = sd.sets[cand.body as usize].delassus(&cand, n);
                let wo = match anta {
                    Anta::Rigid { body, arm } => rigid_delassus(n, arm, sd.inv[body as usize]),
                    Anta::Fe(s) => sd.sets[s.body as usize].delassus(&s, n),
                };
                for q in 0..3 {
                    wb[q] += wo[q];
                }
                sd.fec.block[a] = Block2 {
                    w: wb,
                    pre: coulomb::precompute(wb, sd.fec.target[a].mu),
                };
            }
            // warm start inside the subdomain
            for a in 0..sd.contacts.len() {
                let r = sd.contacts.r[a];
                if r != [0.0, 0.0] {
                    sd.contacts.apply(a, &r, &mut sd.vel, &sd.inv);
                }
            }
            for a in 0..sd.fec.len() {
                let r = sd.fec.r[a];
                if r != [0.0, 0.0] {
                    stage2::apply(
                        &mut sd.sets,
                        &mut sd.vel,
                        &sd.inv,
                        sd.fec.cand[a],
                        sd.fec.anta[a],
                        sd.fec.frame[a],
                        r,
                    );
                }
            }
        }
        let ifr: Vec<(u32, Iface)> = rloc
            .into_iter()
            .enumerate()
            .filter(|(_, v)| v.len() > 1)
            .map(|(b, v)| (b as u32, v))
            .collect();
        let iff: Vec<(u32, Iface)> = floc
            .into_iter()
            .enumerate()
            .filter(|(_, v)| v.len() > 1)
            .map(|(b, v)| (b as u32, v))
            .collect();
        (subs, ifr, iff)
    }
}

/// The gluing of every interface body (module docs); returns (Σ|[V]|²/m, links,
/// Σ|V_copy|², copies) before the update.
fn glue(subs: &mut [Sub], ifr: &[(u32, Iface)], iff: &[(u32, Iface)], w: &World2) -> (f64, u64, f64, u64) {
    let (mut jump2, mut links, mut v2, mut ncopies) = (0.0, 0u64, 0.0, 0u64);
    for (b, copies) in ifr {
        let m = copies.len() as f64;
        let (mass, inertia) = (w.bodies.mass[*b as usize], w.bodies.inertia[*b as usize]);
        let rho2 = if mass > 0.0 { inertia / mass } else { 0.0 };
        let mut mean = [0.0; 3];
        let mut prev: Option<[f64; 3]> = None;
        for &(e, l) in copies {
            let v = subs[e as usize].vel[l as usize];
            v2 += v[0] * v[0] + v[1] * v[1] + rho2 * v[2] * v[2];
            ncopies += 1;
            if let Some(p) = prev {
                let d = [v[0] - p[0], v[1] - p[1], v[2] - p[2]];
                jump2 += (d[0] * d[0] + d[1] * d[1] + rho2 * d[2] * d[2]) / m;
                links += 1;
            }
            prev = Some(v);
            for q in 0..3 {
                mean[q] += v[q] / m;
            }
        }
        for &(e, l) in copies {
            let sd = &mut subs[e as usize];
            let (inv, v) = (sd.inv[l as usize], &mut sd.vel[l as usize]);
            // free dofs move to the mean; driven ones (M̂⁻¹ = 0) stay
            for q in 0..3 {
                if inv[q] != 0.0 {
                    v[q] = mean[q];
                }
            }
        }
    }
    for (_, copies) in iff {
        let m = copies.len() as f64;
        // b_k = F_Γ,k + H_k r_k at the set's nodes
        let mut bk: Vec<Vec<f64>> = Vec::with_capacity(copies.len());
        for &(e, l) in copies {
            let sd = &subs[e as usize];
            let mut f = sd.fgam[l as usize].clone();
            for a in 0..sd.fec.len() {
                let p = global(sd.fec.frame[a], sd.fec.r[a]);
                let mut add = |s: &FeSide, sign: f64| {
                    if s.body == l {
                        for q in 0..2 {
                            let kk = s.k[q] as usize;
                            f[2 * kk] += sign * s.w[q] * p[0];
                            f[2 * kk + 1] += sign * s.w[q] * p[1];
                        }
                    }
                };
                add(&sd.fec.cand[a], 1.0);
                if let Anta::Fe(s) = &sd.fec.anta[a] {
                    add(s, -1.0);
                }
            }
            bk.push(f);
        }
        let n = bk[0].len();
        let mean: Vec<f64> = (0..n).map(|i| bk.iter().map(|f| f[i]).sum::<f64>() / m).collect();
        let mut prev: Option<Vec<[f64; 2]>> = None;
        for (c, &(e, l)) in copies.iter().enumerate() {
            let sd = &mut subs[e as usize];
            let set = &mut sd.sets[l as usize];
            let v = set.v.clone();
            v2 += v.iter().map(|a| a[0] * a[0] + a[1] * a[1]).sum::<f64>() / v.len().max(1) as f64;
            ncopies += 1;
            if let Some(p) = &prev {
                let nn = v.len().max(1) as f64;
                let s: f64 = v.iter().zip(p).map(|(a, b)| (a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2)).sum();
                jump2 += s / nn / m;
                links += 1;
            }
            prev = Some(v);
            let d: Vec<f64> = (0..n).map(|i| mean[i] - bk[c][i]).collect();
            for kk in 0..set.nodes.len() {
                let p = [d[2 * kk], d[2 * kk + 1]];
                if p != [0.0, 0.0] {
                    set.apply(kk, p);
                }
            }
            let fg = &mut sd.fgam[l as usize];
            for i in 0..n {
                fg[i] += d[i];
            }
        }
    }
    (jump2, links, v2, ncopies)
}
