//! NSCDD: non-smooth contact domain decomposition (DESIGN.md §3), 2D rigid bodies.
//!
//! One step with [`Nscdd::step`]: free velocity, detection and the contact set as in
//! [`crate::engine`]; then the contact set is split over an nx × ny grid
//! ([`partition`]), each subdomain holding copies of its bodies with M̂_E = M̂/m
//! ([`subdomain`]); then, until convergence,
//!
//! ```text
//! repeat {
//!     every subdomain: `sweeps_per_gluing` NLGS sweeps on its copies (in parallel)
//!     exchange the interface copies' velocities (Transport, scheme)
//!     gluing: ΔF_Γ = L⁻¹ M̂_E [V] per interface body, V_E += M̂_E⁻¹ ΔF_Γ
//!     every `check_every` stages: LMGC90 criterion on the Sums merged over the
//!         subdomains (in subdomain order) ∧ egluing / QuadWR < tol
//! }
//! ```
//!
//! then each interface body's velocity is the average of its copies, and the global
//! velocities and contact impulses are written back, so that `update_positions`,
//! reactions and outputs work unchanged. F_Γ is kept between steps per (body,
//! subdomain) ([`partition::FGammaStore`]); a body whose copies changed is glued
//! once before the first sweep. (With copies of equal M̂_E the exact gluing puts all
//! copies at their mean, so a kept F_Γ starts the copies where that first gluing
//! would: V_free + M̂⁻¹ Σ_E H_E r_E with the warm-start impulses.) Gluing and residual: [`gluing`]; schemes:
//! [`schemes`]; exchange: [`transport`].
//!
//! Counting: a *stage* is `sweeps_per_gluing` sweeps and one gluing; the check
//! period `check_every` and the limit `max_sweeps / sweeps_per_gluing` (rounded up)
//! count stages. With one subdomain and one sweep per stage this is the one-domain
//! NLGS, bitwise: the same sweep on the same data in the same order.
//!
//! Threads ([`team`]): subdomains are split into `threads` contiguous groups swept in
//! parallel by threads kept for the whole step; a subdomain's sweep reads and writes
//! only its own data and every reduction runs in subdomain order, so the result does
//! not depend on the number of threads.

pub mod gluing;
pub mod partition;
pub mod schemes;
pub mod subdomain;
pub mod team;
pub mod transport;

pub use partition::{Decomposition, FGammaStore, Grid, Interface};
pub use schemes::Scheme;
pub use subdomain::{Subdomain2, SubdomainSolver};
pub use transport::{InProcess, Transport, TransportStats};

use crate::engine::{build_contacts, free_velocity, update_positions, Diverged, StageTimes};
use crate::norms::{Norms, Sums, VANISHING};
use crate::rigid2d::nlgs;
use crate::solver::SolveReport;
use crate::world::World2;
use gluing::GluePartial;
use schemes::{glue_stage, GlueBuffers};
use std::time::Instant;

/// NSCDD settings.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct DdSettings {
    /// Grid of subdomains over the contact points' bounding box.
    pub nx: u32,
    pub ny: u32,
    pub scheme: Scheme,
    /// NLGS sweeps per gluing stage (LMGC90: 1).
    pub sweeps_per_gluing: u32,
    /// Threads sweeping the subdomains (1: the calling thread only).
    pub threads: usize,
}

impl Default for DdSettings {
    fn default() -> Self {
        DdSettings {
            nx: 1,
            ny: 1,
            scheme: Scheme::Decentralized,
            sweeps_per_gluing: 1,
            threads: 1,
        }
    }
}

/// What one NSCDD step did.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct DdStepReport {
    /// `sweeps` counts NLGS sweeps (stages × sweeps_per_gluing); `converged` is both
    /// criteria; `norms` those of the merged sums; `residual` the natural-map
    /// residual of the written-back global solution.
    pub solve: SolveReport,
    pub stages: u32,
    pub contacts: usize,
    /// Subdomains that own at least one contact.
    pub subdomains: usize,
    pub interface_bodies: usize,
    pub links: usize,
    pub max_multiplicity: u32,
    /// egluing of the last check (before its gluing) and egluing / QuadWR.
    pub egluing: f64,
    pub egluing_rel: f64,
    /// Messages and values exchanged during the step.
    pub exchange: TransportStats,
    pub times: StageTimes,
}

/// The NSCDD solver state kept between steps.
#[derive(Default)]
pub struct Nscdd {
    pub settings: DdSettings,
    /// F_Γ of the last step's interface copies.
    pub store: FGammaStore,
    /// The last step's decomposition (copies as after the last gluing, before the
    /// averaging).
    pub last: Decomposition,
    transport: InProcess,
    bufs: GlueBuffers,
    v_free: Vec<[f64; 3]>,
}

impl Nscdd {
    pub fn new(settings: DdSettings) -> Self {
        Nscdd {
            settings,
            ..Default::default()
        }
    }

    /// Advances `w` by one step, the contact problem solved by NSCDD.
    pub fn step(&mut self, w: &mut World2) -> Result<DdStepReport, Diverged> {
        let mut rep = DdStepReport::default();
        let t0 = Instant::now();
        free_velocity(w);
        w.scratch
            .detector
            .detect(&w.bodies, &w.shapes, &w.detectors, w.alert, &mut w.scratch.raw);
        let t1 = Instant::now();
        self.v_free.clone_from(&w.bodies.vel);
        build_contacts(w);
        nlgs::make_order(&mut w.scratch.order, w.contacts.len(), &w.solver, w.step);
        let s = &self.settings;
        self.last = partition::decompose(&w.contacts, &w.bodies, &self.v_free, &w.scratch.order, s.nx, s.ny, &self.store);
        let t2 = Instant::now();
        self.solve(w, &mut rep);
        let t3 = Instant::now();
        update_positions(w)?;
        let t4 = Instant::now();
        rep.contacts = w.contacts.len();
        rep.times = StageTimes {
            detect: (t1 - t0).as_secs_f64(),
            delassus: (t2 - t1).as_secs_f64(),
            nlgs: (t3 - t2).as_secs_f64(),
            update: (t4 - t3).as_secs_f64(),
        };
        Ok(rep)
    }

    /// The NSCDD iteration on `self.last`, then the write-back into `w`.
    fn solve(&mut self, w: &mut World2, rep: &mut DdStepReport) {
        let set = self.settings.clone();
        let sv = w.solver.clone();
        let d = &mut self.last;
        self.transport.resize(d.subs.len());
        self.transport.reset_stats();
        rep.subdomains = d.subs.iter().filter(|s| !s.contacts.is_empty()).count();
        rep.interface_bodies = d.iface.len();
        rep.links = d.iface.links();
        rep.max_multiplicity = d.mult.iter().copied().max().unwrap_or(0);
        if w.contacts.is_empty() {
            rep.solve.converged = true;
            self.store.keep(&d.subs);
            return;
        }
        let per = set.sweeps_per_gluing.max(1);
        let max_stages = sv.max_sweeps.div_ceil(per).max(1);
        let k = sv.check_every.max(1);
        let (iface, transport, bufs) = (&d.iface, &mut self.transport, &mut self.bufs);
        let stages = team::with_team(&mut d.subs, set.threads, |team| {
            if iface.fresh.iter().any(|&f| f) {
                team.with_all(|subs| glue_stage(subs, iface, set.scheme, transport, true, bufs));
            }
            let mut stages = 0;
            while stages < max_stages {
                stages += 1;
                let check = stages % k == 0 || stages == max_stages;
                team.sweep(per, sv.relaxation, check);
                let (sums, parts) = team.with_all(|subs| {
                    let parts = if iface.is_empty() {
                        Vec::new()
                    } else {
                        glue_stage(subs, iface, set.scheme, transport, false, bufs)
                    };
                    // reduced in subdomain order
                    let mut sums = Sums::default();
                    if check {
                        for s in subs.iter() {
                            sums.merge(s.sums());
                        }
                    }
                    (sums, parts)
                });
                if check {
                    let mut g = GluePartial::default();
                    for p in &parts {
                        g.merge(p);
                    }
                    rep.solve.norms = Norms::from_sums(&sums, sv.tolerance);
                    let quad_wr = if sums.nactif > 0 && sums.sum_wrwr > VANISHING && sums.sum_wrr > VANISHING {
                        (sums.sum_wrwr / sums.nactif as f64).sqrt()
                    } else {
                        0.0
                    };
                    rep.egluing = g.egluing();
                    rep.egluing_rel = g.relative(quad_wr);
                    if rep.solve.norms.converged(sv.norm) && rep.egluing_rel < sv.tolerance {
                        rep.solve.converged = true;
                        break;
                    }
                }
            }
            stages
        });
        rep.stages = stages;
        rep.solve.sweeps = stages * per;
        rep.exchange = self.transport.stats();
        write_back(d, w);
        self.store.keep(&d.subs);
        rep.solve.residual = nlgs::residual(&w.contacts, &w.bodies.vel);
    }
}

/// Global impulses and velocities from the subdomains: a body with one copy takes
/// its velocity, an interface body the average of its copies (chain order); an
/// immovable body copied several times keeps its first copy's.
pub fn write_back(d: &Decomposition, w: &mut World2) {
    let mut done = vec![false; w.bodies.len()];
    for s in &d.subs {
        for (la, &ga) in s.contact_global.iter().enumerate() {
            w.contacts.r[ga as usize] = s.contacts.r[la];
        }
        for (l, &g) in s.body_global.iter().enumerate() {
            let g = g as usize;
            if !done[g] && (d.mult[g] == 1 || !w.bodies.movable(g)) {
                w.bodies.vel[g] = s.vel[l];
                done[g] = true;
            }
        }
    }
    let ifc = &d.iface;
    for ib in 0..ifc.len() {
        let r = ifc.copies(ib);
        let m = r.len() as f64;
        let mut v = [0.0; 3];
        for c in r {
            let vc = d.subs[ifc.sub[c] as usize].interface_velocity(ifc.slot[c] as usize);
            for k in 0..3 {
                v[k] += vc[k];
            }
        }
        w.bodies.vel[ifc.body[ib] as usize] = [v[0] / m, v[1] / m, v[2] / m];
    }
}

/// One NSCDD step of `w` with a solver state (F_Γ kept in `state` between steps).
pub fn step(w: &mut World2, state: &mut Nscdd) -> Result<DdStepReport, Diverged> {
    state.step(w)
}
