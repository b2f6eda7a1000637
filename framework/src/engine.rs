//! One Moreau–Jean time step, one stage per function.
//!
//! Over [t_i, t_i+1] with step h and θ ∈ [½, 1] (DESIGN.md §2), for rigid bodies
//! (M̂ = M):
//!
//! ```text
//! V_free = V⁻ + M̂⁻¹ h F̂                 F̂: gravity + imposed forces at t_i + θh
//! M̂ (V⁺ − V_free) = H r                  r: contact impulses (NLGS)
//! q⁺ = q⁻ + h ((1 − θ) V⁻ + θ V⁺)
//! ```
//!
//! Degrees of freedom driven by velocity take V⁺ = v(t_i+1) and have M̂⁻¹ = 0.
//! Stages: [`free_velocity`], detection ([`crate::detect`]), [`build_contacts`]
//! (frames, Delassus blocks W_αα, law targets ū and warm start), NLGS
//! ([`crate::solver::nlgs`]) and [`update_positions`].

use crate::dim::{Dim, D2};
use crate::drive::Imposed;
use crate::law::target_velocity;
use crate::model::{ContactKey, Target};
use crate::solver::nlgs;
use crate::solver::SolveReport;
use crate::world::World2;
use std::time::Instant;

/// Wall-clock seconds spent in each stage of a step.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize)]
pub struct StageTimes {
    pub detect: f64,
    pub delassus: f64,
    pub nlgs: f64,
    pub update: f64,
}

/// What one step did.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct StepReport {
    pub solve: SolveReport,
    pub contacts: usize,
    pub times: StageTimes,
}

pub use crate::step::Diverged;

/// The contact-solve stage of a step of a world `W`, between the construction of
/// the contact set and the position update: the one-domain NLGS ([`Nlgs`]) or NSCDD
/// (`crate::dd::NscddOf`). The rest of the step is the same for both
/// ([`World2::step_with`], `World3::step_with`).
pub trait ContactStage<W> {
    /// After the free velocity (the bodies hold V_free), before the contact set is
    /// built and the warm-start impulses are applied.
    fn after_free_velocity(&mut self, _w: &W) {}
    /// After the contact set and the visiting order are built (timed with the
    /// Delassus stage).
    fn prepare(&mut self, _w: &mut W) {}
    /// Solves the contact problem: V⁺ in the bodies' velocities, r in the contacts.
    fn solve(&mut self, w: &mut W) -> SolveReport;
}

/// The one-domain NLGS stage.
pub struct Nlgs;

impl ContactStage<World2> for Nlgs {
    fn solve(&mut self, w: &mut World2) -> SolveReport {
        nlgs::solve(&mut w.contacts, &mut w.bodies.vel, &w.bodies.inv_mass, &w.scratch.order, &w.solver)
    }
}

impl World2 {
    /// Advances the scene by one step, contacts solved by NLGS.
    pub fn step(&mut self) -> Result<StepReport, Diverged> {
        self.step_with(&mut Nlgs)
    }

    /// Advances the scene by one step with the given contact-solve stage.
    pub fn step_with(&mut self, stage: &mut impl ContactStage<World2>) -> Result<StepReport, Diverged> {
        let mut rep = StepReport::default();
        let t0 = Instant::now();
        free_velocity(self);
        self.scratch
            .detector
            .detect(&self.bodies, &self.shapes, &self.detectors, self.alert, &mut self.scratch.raw);
        let t1 = Instant::now();
        stage.after_free_velocity(self);
        build_contacts(self);
        nlgs::make_order(&mut self.scratch.order, self.contacts.len(), &self.solver, self.step);
        stage.prepare(self);
        let t2 = Instant::now();
        rep.solve = stage.solve(self);
        let t3 = Instant::now();
        update_positions(self)?;
        let t4 = Instant::now();
        rep.contacts = self.contacts.len();
        rep.times = StageTimes {
            detect: (t1 - t0).as_secs_f64(),
            delassus: (t2 - t1).as_secs_f64(),
            nlgs: (t3 - t2).as_secs_f64(),
            update: (t4 - t3).as_secs_f64(),
        };
        Ok(rep)
    }
}

/// V_free = V⁻ + h M̂⁻¹ F̂, with the drives applied; keeps V⁻ in the scratch.
pub fn free_velocity(w: &mut World2) {
    let h = w.time.h;
    let (t_end, t_theta) = (w.t + h, w.t + w.time.theta * h);
    let b = &mut w.bodies;
    w.scratch.v_begin.clear();
    w.scratch.v_begin.extend_from_slice(&b.vel);
    for d in &w.drives {
        crate::step::drive_free_dofs(b, d.body as usize, &d.dof, t_end);
    }
    let g = w.gravity;
    for k in 0..b.len() {
        let im = b.inv_mass[k];
        let v = &mut b.vel[k];
        v[0] += h * im[0] * b.mass[k] * g[0];
        v[1] += h * im[1] * b.mass[k] * g[1];
    }
    for d in &w.drives {
        let k = d.body as usize;
        for dof in 0..3 {
            let Some(drv) = &d.dof[dof] else { continue };
            match drv.at(t_end) {
                Imposed::Velocity(v) => b.vel[k][dof] = v,
                _ => {
                    if let Imposed::Force(f) = drv.at(t_theta) {
                        let m = if dof < 2 { b.mass[k] } else { b.inertia[k] };
                        b.vel[k][dof] += h * f / m;
                    }
                }
            }
        }
    }
}

/// Builds this step's contact set from the raw contacts: lever arms, W_αα, ū, and
/// the impulses of persisting contacts (warm start), which are applied at once to
/// the free velocities.
pub fn build_contacts(w: &mut World2) {
    let (h, theta) = (w.time.h, w.time.theta);
    let s = &mut w.scratch;
    s.prev_keys.clear();
    s.prev_keys.extend(w.contacts.key.iter().copied().zip(w.contacts.r.iter().copied()));
    s.prev_keys.sort_unstable_by_key(|x| x.0);
    let c = &mut s.next;
    c.clear();
    let b = &w.bodies;
    for rc in &s.raw {
        let (i, j) = (rc.i as usize, rc.j as usize);
        let frame = D2::frame(&rc.point, &rc.normal, &b.pos[i], &b.pos[j]);
        let wb = D2::delassus(&frame, &b.inv_mass[i], &b.inv_mass[j]);
        if !(wb[0] > 0.0) {
            continue;
        }
        let Some(law) = w.laws[b.material[i] as usize * w.materials.len() + b.material[j] as usize] else {
            continue;
        };
        let u_begin = D2::local_velocity(&frame, &s.v_begin[i], &s.v_begin[j]);
        let u_free = D2::local_velocity(&frame, &b.vel[i], &b.vel[j]);
        let key = ContactKey {
            i: rc.i,
            j: rc.j,
            feature: rc.feature,
        };
        let r = match s.prev_keys.binary_search_by_key(&key, |x| x.0) {
            Ok(p) => s.prev_keys[p].1,
            Err(_) => [0.0, 0.0],
        };
        c.bodies.push([rc.i, rc.j]);
        c.frame.push(frame);
        c.block.push(D2::block(wb, law.mu));
        c.target.push(Target {
            u_target: target_velocity(rc.gap, u_begin[0], u_free[0], h, theta, law.e),
            mu: law.mu,
        });
        c.r.push(r);
        c.u_free.push(u_free);
        c.gap.push(rc.gap);
        c.point.push(rc.point);
        c.key.push(key);
        c.joint.push(Default::default());
    }
    std::mem::swap(&mut w.contacts, &mut s.next);
    w.contacts.apply_all(&mut w.bodies.vel, &w.bodies.inv_mass);
}

/// q⁺ = q⁻ + h((1 − θ)V⁻ + θV⁺); the per-body reactions; the divergence check.
pub fn update_positions(w: &mut World2) -> Result<(), Diverged> {
    let (h, theta) = (w.time.h, w.time.theta);
    let b = &mut w.bodies;
    if let Err(k) = crate::step::integrate(b, &w.scratch.v_begin, h, theta) {
        return Err(Diverged::non_finite(w.step + 1, k, w.body_label(k), &w.bodies));
    }
    crate::step::reactions(&w.contacts, w.bodies.len(), &mut w.reaction);
    w.step += 1;
    w.t = w.step as f64 * h;
    if let (Some(bw), None) = (&w.box_walls, w.box_h0) {
        if w.t >= bw.strain_from {
            w.box_h0 = w.box_extent().map(|e| e[3] - e[2]);
        }
    }
    Ok(())
}
