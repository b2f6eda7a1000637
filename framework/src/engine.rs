//! One Moreau–Jean time step, one stage per function, once for 2D and 3D.
//!
//! Over [t_i, t_i+1] with step h and θ ∈ [½, 1] (DESIGN.md §2), for rigid bodies
//! (M̂ = M):
//!
//! ```text
//! V_free = V⁻ + h M̂⁻¹ F̂        F̂: gravity, imposed forces at t_i + θh, and in 3D
//!                               the gyroscopic torque −ω⁻ × (I_w ω⁻) (zero for spheres)
//! M̂ (V⁺ − V_free) = H r          r: contact impulses (NLGS)
//! q⁺ = q⁻ + h ((1 − θ) V⁻ + θ V⁺)
//! ```
//!
//! In 3D the orientation update applies the θ-method's increment h ω_θ as an exact
//! rotation (unit quaternion, renormalised: `Dim::integrate`). Degrees of freedom
//! driven by velocity take V⁺ = v(t_i+1) and are removed from M̂⁻¹. Stages:
//! [`free_velocity`], detection ([`crate::detect`]), [`build_contacts`] (frames,
//! Delassus blocks W_αα, law targets ū, warm start and bonds), NLGS
//! ([`crate::solver::nlgs`]), [`update_joints`] and [`update_positions`].

use crate::dim::joint::Joint;
use crate::dim::{Dim, Vector};
use crate::drive::Imposed;
use crate::law::{LawInput, LawStep};
use crate::model::{ContactKey, Contacts};
use crate::solver::nlgs;
use crate::solver::SolveReport;
use crate::world::PrevContact;
use crate::world::World;
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
    /// Before detection (after the free velocity): may restrict the detection to a
    /// part of space and add other processes' last contacts to the warm start.
    fn before_detection(&mut self, _w: &mut W) {}
    /// After detection: may keep only the raw contacts this process solves.
    fn after_detection(&mut self, _w: &mut W) {}
    /// After the free velocity (the bodies hold V_free), before the contact set is
    /// built and the warm-start impulses are applied.
    fn after_free_velocity(&mut self, _w: &W) {}
    /// After the contact set and the visiting order are built (timed with the
    /// Delassus stage).
    fn prepare(&mut self, _w: &mut W) {}
    /// Solves the contact problem: V⁺ in the bodies' velocities, r in the contacts.
    fn solve(&mut self, w: &mut W) -> SolveReport;
    /// After the position update of the bodies (`moved`: the first body found with a
    /// non-finite state, if any), before the step is counted: may bring other
    /// processes' bodies up to date and must agree on a divergence with them.
    fn after_integrate(&mut self, _w: &mut W, moved: Result<(), usize>) -> Result<(), usize> {
        moved
    }
    /// Sets the per-body reactions itself (NSCDD: per subdomain, added in subdomain
    /// order) and returns true; false: the engine sums them over the world's contacts.
    fn reactions(&mut self, _w: &mut W) -> bool {
        false
    }
    /// After the position update (the step is done).
    fn after_update(&mut self, _w: &mut W) {}
}

/// The one-domain stage: NLGS, Anderson-accelerated NLGS over the same sweeps
/// ([`crate::solver::anderson`]), or the semismooth Newton method over the
/// assembled Delassus operator ([`crate::fc::solve_world`]).
pub struct Nlgs;

impl<D: Dim> ContactStage<World<D>> for Nlgs {
    fn solve(&mut self, w: &mut World<D>) -> SolveReport {
        match w.solver.method {
            crate::solver::Method::Nlgs => {}
            // the world's own sweeps, mixed
            crate::solver::Method::Anderson => {
                return crate::solver::anderson::solve(&mut w.contacts, &mut w.bodies.vel, &w.bodies.inv_mass, &w.scratch.order, &w.solver)
            }
            // Newton over the assembled W
            crate::solver::Method::Newton => return crate::fc::solve_world(w),
        }
        nlgs::solve(
            &mut w.contacts,
            &mut w.bodies.vel,
            &w.bodies.inv_mass,
            &mut w.scratch.order,
            &w.solver,
        )
    }
}

impl<D: Dim> World<D> {
    /// Advances the scene by one step, contacts solved by NLGS.
    pub fn step(&mut self) -> Result<StepReport, Diverged> {
        self.step_with(&mut Nlgs)
    }

    /// Advances the scene by one step with the given contact-solve stage (NLGS or
    /// NSCDD).
    pub fn step_with<S: ContactStage<World<D>> + ?Sized>(&mut self, stage: &mut S) -> Result<StepReport, Diverged> {
        let mut rep = StepReport::default();
        let t0 = Instant::now();
        free_velocity(self);
        stage.before_detection(self);
        let s = &mut self.scratch;
        s.detector.detect_among(
            (&self.bodies, s.active.as_deref()),
            &self.shapes,
            &self.detectors,
            self.alert,
            s.region.as_ref(),
            &mut s.raw,
        );
        stage.after_detection(self);
        let t1 = Instant::now();
        stage.after_free_velocity(self);
        build_contacts(self);
        let c = &self.contacts;
        nlgs::make_order(&mut self.scratch.order, c.len(), &self.solver, self.step, D::N, |a| c.point3(a));
        stage.prepare(self);
        let t2 = Instant::now();
        rep.solve = stage.solve(self);
        update_joints(self);
        let own_reactions = stage.reactions(self);
        let t3 = Instant::now();
        let moved = integrate(self);
        let moved = stage.after_integrate(self, moved);
        finish_positions(self, !own_reactions, moved)?;
        stage.after_update(self);
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
pub fn free_velocity<D: Dim>(w: &mut World<D>) {
    let h = w.time.h;
    let t_end = w.t + h;
    let b = &mut w.bodies;
    w.scratch.v_begin.clear();
    w.scratch.v_begin.extend_from_slice(&b.vel);
    // free degrees of freedom at the end of the step; M̂⁻¹ where it can change
    for d in &w.drives {
        crate::step::drive_free_dofs(b, d.body as usize, &d.dof[..D::DOF], t_end);
    }
    let only = w.scratch.active.as_deref();
    crate::step::each_body(b.len(), only, |k| {
        if b.free[k] != 0 && !D::isotropic(&b.inertia[k]) {
            b.refresh_inverse(k);
        }
    });
    let g = w.gravity;
    crate::step::each_body(b.len(), only, |k| {
        if b.free[k] != 0 {
            D::free_flight(&mut b.vel[k], b.mass[k], &b.inertia[k], &b.rot[k], &b.inv_mass[k], &g, h);
        }
    });
    apply_drives(w);
}

/// The drives' velocities and forces; pressure and servo drives of box walls act
/// on the current face of the box sample.
fn apply_drives<D: Dim>(w: &mut World<D>) {
    let h = w.time.h;
    let (t_end, t_theta) = (w.t + h, w.t + w.time.theta * h);
    let extent = w.box_extent();
    let (walls, reaction, b) = (w.box_walls.as_ref(), &w.reaction, &mut w.bodies);
    // wall k of the box is wall k/2's axis, lower side (sign +1) for even k
    let wall = |k: usize, dof: usize| walls.and_then(|bw| bw.wall_of(k, D::N)).filter(|wl| wl / 2 == dof);
    let sign = |wl: usize| if wl % 2 == 0 { 1.0 } else { -1.0 };
    for d in &w.drives {
        let k = d.body as usize;
        for dof in 0..D::DOF {
            let Some(drv) = &d.dof[dof] else { continue };
            match drv.at(t_end) {
                Imposed::Velocity(v) => b.vel[k][dof] = v,
                Imposed::Servo(sigma, gain, vmax) => {
                    // the stress the grains exerted on the wall over the last step
                    if let (Some(wl), Some(e)) = (wall(k, dof), &extent) {
                        let area = e.face(dof);
                        let measured = -sign(wl) * reaction.get(k).map_or(0.0, |r| r[dof]) / (h * area);
                        b.vel[k][dof] = sign(wl) * (gain * (sigma - measured)).clamp(-vmax, vmax);
                    }
                }
                _ => {
                    let imposed = match drv.at(t_theta) {
                        Imposed::Pressure(sigma) => match (wall(k, dof), &extent) {
                            (Some(wl), Some(e)) => Imposed::Force(sign(wl) * sigma * e.face(dof)),
                            _ => Imposed::Free,
                        },
                        other => other,
                    };
                    if let Imposed::Force(f) = imposed {
                        if dof < D::N {
                            b.vel[k][dof] += h * f / b.mass[k];
                        } else {
                            D::apply_moment(&mut b.vel[k], &b.inertia[k], &b.inv_mass[k], dof - D::N, h * f);
                        }
                    }
                }
            }
        }
    }
}

/// The last step's contact that a new contact continues: the one with its key, or
/// else the nearest one of the same pair of bodies within the alert distance
/// (multi-point contacts renumber their points when their polygons change a
/// little: the impulse and the bond follow the point). `p`: where the key would be
/// inserted in the sorted `prev`.
fn continued<D: Dim>(prev: &[PrevContact<D>], p: usize, key: ContactKey, point: D::Point, alert: f64) -> Option<usize> {
    let same = |k: usize| prev[k].key.i == key.i && prev[k].key.j == key.j;
    let (mut lo, mut hi) = (p, p);
    while lo > 0 && same(lo - 1) {
        lo -= 1;
    }
    while hi < prev.len() && same(hi) {
        hi += 1;
    }
    let d2 = |k: usize| dist2(&prev[k].point, &point);
    (lo..hi)
        .filter(|&k| d2(k) <= alert * alert)
        .min_by(|&a, &b| d2(a).total_cmp(&d2(b)))
}

fn dist2<P: Vector>(a: &P, b: &P) -> f64 {
    let d = a.sub(b);
    d.dot(&d)
}

/// This step's contact set from the raw contacts: frames, W_αα, ū, the warm start
/// (applied at once to the free velocities) and the bonds of mortar joints.
pub fn build_contacts<D: Dim>(w: &mut World<D>) {
    gather_prev(w);
    build_from_raw(w);
}

/// The last step's contacts (and other processes' in `extra_prev`), sorted by key:
/// the warm starts of [`build_from_raw`].
fn gather_prev<D: Dim>(w: &mut World<D>) {
    let s = &mut w.scratch;
    s.prev_keys.clear();
    let old = &w.contacts;
    s.prev_keys.extend((0..old.len()).map(|a| PrevContact {
        key: old.key[a],
        r: old.r[a],
        bonded: old.joint[a].bonded(),
        point: old.point[a],
    }));
    s.prev_keys.extend_from_slice(&s.extra_prev);
    s.prev_keys.sort_unstable_by_key(|x| x.key);
}

/// The contact set from the raw contacts, warm-started from the gathered previous
/// ones (which a second call in the same step reuses: NSCDD's distributed
/// repartition).
pub(crate) fn build_from_raw<D: Dim>(w: &mut World<D>) {
    let step = LawStep {
        h: w.time.h,
        theta: w.time.theta,
        first: w.step == 0,
    };
    let s = &mut w.scratch;
    let c = &mut s.next;
    c.clear();
    s.laws.clear();
    s.w.clear();
    let b = &w.bodies;
    let nm = w.materials.len();
    for rc in &s.raw {
        let (i, j) = (rc.i as usize, rc.j as usize);
        let frame = D::frame(&rc.point, &rc.normal, &b.pos[i], &b.pos[j]);
        let wb = D::delassus(&frame, &b.inv_mass[i], &b.inv_mass[j]);
        if !(D::w_nn(&wb) > 0.0) {
            continue;
        }
        let slot = b.material[i] as usize * nm + b.material[j] as usize;
        if w.laws[slot].is_none() {
            continue;
        }
        let u_begin = D::local_velocity(&frame, &s.v_begin[i], &s.v_begin[j]);
        let u_free = D::local_velocity(&frame, &b.vel[i], &b.vel[j]);
        let key = ContactKey {
            i: w.ids.global(rc.i),
            j: w.ids.global(rc.j),
            feature: rc.feature,
        };
        // the same key at the same place, else the nearest point of the pair; a
        // key that now names another corner of a polygon, farther than alert, still
        // gives its warm start but never its bond
        let (exact, at) = match s.prev_keys.binary_search_by_key(&key, |x| x.key) {
            Ok(p) => (Some(p), p),
            Err(p) => (None, p),
        };
        let near = match exact {
            Some(p) if dist2(&s.prev_keys[p].point, &rc.point) <= w.alert * w.alert => Some(p),
            _ => continued(&s.prev_keys, at, key, rc.point, w.alert),
        };
        let r = near.or(exact).map_or(D::Local::zero(), |p| s.prev_keys[p].r);
        s.laws.push(
            slot,
            LawInput {
                gap: rc.gap,
                un_begin: u_begin[0],
                un_free: u_free[0],
                area: rc.area,
                was_bonded: near.map(|p| s.prev_keys[p].bonded),
            },
        );
        s.w.push(wb);
        c.bodies.push([rc.i, rc.j]);
        c.frame.push(frame);
        c.r.push(r);
        c.u_free.push(u_free);
        c.gap.push(rc.gap);
        c.point.push(rc.point);
        c.key.push(key);
    }
    // ū, μ and the joints: each law once, on all the contacts of its pairs
    s.laws.run(&w.laws, &step, &mut c.target, &mut c.joint);
    c.compliant = s.laws.compliance(&w.laws, &step, &mut c.compliance);
    if c.compliant && !w.contact_shares.is_empty() {
        share_compliance(&w.contact_shares, c, &mut s.share);
    }
    if c.compliant {
        let blocks = s.w.iter().zip(&c.target).zip(&c.compliance);
        c.block
            .extend(blocks.map(|((wb, t), &cc)| D::block(D::with_compliance(*wb, cc), t.mu)));
    } else {
        c.block.extend(s.w.iter().zip(&c.target).map(|(wb, t)| D::block(*wb, t.mu)));
    }
    std::mem::swap(&mut w.contacts, &mut s.next);
    w.contacts.apply_all(&mut w.bodies.vel, &w.bodies.inv_mass);
}

/// Each compliant contact's c divided by its weight in the world's `shares` (a
/// weight below 10⁻¹² counts as 10⁻¹²: the contact all but vanishes). The shares
/// see the contacts by key (their bodies' global ids: a world holding a part of the
/// scene numbers its bodies by slot).
fn share_compliance<D: Dim>(shares: &[crate::world::ContactShare<D>], c: &mut Contacts<D>, weight: &mut Vec<f64>) {
    weight.clear();
    weight.resize(c.len(), 1.0);
    for share in shares {
        share(&c.key, &c.point, weight);
    }
    for (c, w) in c.compliance.iter_mut().zip(weight.iter()) {
        if *c > 0.0 && *w < 1.0 {
            *c /= w.max(1e-12);
        }
    }
}

/// Failure of bonded joints on the converged impulses: a joint whose strength is
/// exceeded loses its bond for good (`dim::joint`). "Exceeded" means by more
/// than 100 × the solver tolerance (at most 2 %): the impulses of a converged NLGS
/// are accurate to a few tolerances, and a smaller overload makes the joint slip,
/// so its slip velocity, hence the excess, grows until it fails a few steps later.
pub fn update_joints<D: Dim>(w: &mut World<D>) {
    let tol = (100.0 * w.solver.tolerance).clamp(1e-9, 0.02);
    let c = &mut w.contacts;
    for a in 0..c.len() {
        let jt = c.joint[a];
        if !jt.bonded() {
            continue;
        }
        let u = c.local_velocity(a, &w.bodies.vel);
        let wr = D::w_mul(&c.block[a], &c.r[a]);
        let u0 = u.sub(&wr);
        let t = c.target[a];
        if !D::joint_holds(&c.block[a], &c.r[a], &u0, t.u_target, t.mu, &jt, tol) {
            c.joint[a] = Joint::default();
        }
    }
}

/// q⁺ = q⁻ + h((1 − θ)V⁻ + θV⁺); the per-body reactions; the divergence check.
pub fn update_positions<D: Dim>(w: &mut World<D>) -> Result<(), Diverged> {
    update_positions_with(w, true)
}

/// [`update_positions`], the reactions summed over the world's contacts when
/// `reactions` (else the contact stage set them).
fn update_positions_with<D: Dim>(w: &mut World<D>, reactions: bool) -> Result<(), Diverged> {
    let moved = integrate(w);
    finish_positions(w, reactions, moved)
}

/// q⁺ of the bodies the world steps ([`crate::world::World`]'s active bodies).
fn integrate<D: Dim>(w: &mut World<D>) -> Result<(), usize> {
    let (h, theta) = (w.time.h, w.time.theta);
    crate::step::integrate_some(&mut w.bodies, &w.scratch.v_begin, h, theta, w.scratch.active.as_deref())
}

/// After the position update (`moved`: a body found diverging): the divergence
/// error, the reactions (when `reactions`), the step and time counted.
fn finish_positions<D: Dim>(w: &mut World<D>, reactions: bool, moved: Result<(), usize>) -> Result<(), Diverged> {
    if let Err(k) = moved {
        let g = w.ids.global(k as u32);
        return Err(Diverged::non_finite(w.step + 1, (k, g), w.body_label(k), &w.bodies));
    }
    let h = w.time.h;
    if reactions {
        crate::step::reactions(&w.contacts, w.bodies.len(), &mut w.reaction);
    }
    w.step += 1;
    w.t = w.step as f64 * h;
    if let (Some(bw), None) = (&w.box_walls, w.box_h0) {
        if w.t >= bw.strain_from {
            w.box_h0 = w.box_extent().map(|e| e.max[D::N - 1] - e.min[D::N - 1]);
        }
    }
    Ok(())
}
