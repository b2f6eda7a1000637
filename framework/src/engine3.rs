//! One Moreau–Jean time step of a 3D world, one stage per function, as in 2D
//! ([`crate::engine`]):
//!
//! ```text
//! V_free = V⁻ + h M̂⁻¹ F̂        F̂: gravity, imposed forces at t_i + θh, and the
//!                               gyroscopic torque −ω⁻ × (I_w ω⁻) (zero for spheres)
//! M̂ (V⁺ − V_free) = H r          r: contact impulses (NLGS, solver::nlgs)
//! x⁺ = x⁻ + h ((1 − θ) v⁻ + θ v⁺)
//! q⁺ = exp(½ h ω_θ) ⊗ q⁻,       ω_θ = (1 − θ) ω⁻ + θ ω⁺   (world-frame ω)
//! ```
//!
//! The orientation update is the θ-method's increment h ω_θ applied as an exact
//! rotation (unit quaternion, renormalised), so orientations stay orthonormal
//! whatever the step. Degrees of freedom driven by velocity take V⁺ = v(t_i+1) and
//! are removed from M̂⁻¹ (rotations: the world inertia restricted to the free axes).

use crate::dim::coulomb3 as coulomb;
use crate::dim::joint::Joint;
use crate::dim::{Dim, Vector, D3};
use crate::drive::Imposed;
use crate::engine::{ContactStage, Diverged, Nlgs, StageTimes, StepReport};
use crate::law::target_velocity;
use crate::model::{ContactKey, Target};
use crate::rigid3d::bodies::cross;
use crate::solver::nlgs::{self, make_order};

use crate::solver::SolveReport;
use crate::world3::World3;
use std::time::Instant;

impl ContactStage<World3> for Nlgs {
    fn solve(&mut self, w: &mut World3) -> SolveReport {
        let b = &mut w.bodies;
        nlgs::solve(&mut w.contacts, &mut b.vel, &b.inv_mass, &w.scratch.order, &w.solver)
    }
}

impl World3 {
    /// Advances the scene by one step, contacts solved by NLGS.
    pub fn step(&mut self) -> Result<StepReport, Diverged> {
        self.step_with(&mut Nlgs)
    }

    /// Advances the scene by one step with the given contact-solve stage (NLGS or
    /// NSCDD, `crate::dd::Nscdd3`).
    pub fn step_with(&mut self, stage: &mut impl ContactStage<World3>) -> Result<StepReport, Diverged> {
        let mut rep = StepReport::default();
        let t0 = Instant::now();
        free_velocity(self);
        self.scratch
            .detector
            .detect(&self.bodies, &self.shapes, &self.detectors, self.alert, &mut self.scratch.raw);
        let t1 = Instant::now();
        stage.after_free_velocity(self);
        build_contacts(self);
        make_order(&mut self.scratch.order, self.contacts.len(), &self.solver, self.step);
        stage.prepare(self);
        let t2 = Instant::now();
        rep.solve = stage.solve(self);
        update_joints(self);
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

/// V_free = V⁻ + h M̂⁻¹ F̂ with the drives applied; keeps V⁻.
pub fn free_velocity(w: &mut World3) {
    let h = w.time.h;
    let (t_end, t_theta) = (w.t + h, w.t + w.time.theta * h);
    let b = &mut w.bodies;
    w.scratch.v_begin.clear();
    w.scratch.v_begin.extend_from_slice(&b.vel);
    // free degrees of freedom at the end of the step; M̂⁻¹ where it can change
    for d in &w.drives {
        crate::step::drive_free_dofs(b, d.body as usize, &d.dof, t_end);
    }
    for k in 0..b.len() {
        if b.free[k] != 0 && !D3::isotropic(&b.inertia[k]) {
            b.refresh_inverse(k);
        }
    }
    let g = w.gravity;
    for k in 0..b.len() {
        if b.free[k] == 0 {
            continue;
        }
        let (im, ii) = (b.inv_mass[k].m, b.inv_mass[k].i);
        let m = b.mass[k];
        let iw = if D3::isotropic(&b.inertia[k]) {
            [0.0; 6]
        } else {
            b.world_inertia(k)
        };
        let v = &mut b.vel[k];
        for a in 0..3 {
            v[a] += h * im[a] * m * g[a];
        }
        if !D3::isotropic(&b.inertia[k]) {
            // gyroscopic torque −ω × (I_w ω), explicit
            let om = [v[3], v[4], v[5]];
            let l = coulomb::mul(&iw, om);
            let tq = cross(om, l);
            let dw = coulomb::mul(&ii, [-h * tq[0], -h * tq[1], -h * tq[2]]);
            for a in 0..3 {
                v[3 + a] += dw[a];
            }
        }
    }
    // pressure drives: σ × the current face area of the box sample
    let faces = w.box_walls.as_ref().map(|bw| bw.walls);
    let extent = w.box_extent();
    let reaction = &w.reaction;
    let b = &mut w.bodies;
    for d in &w.drives {
        let k = d.body as usize;
        for dof in 0..6 {
            let Some(drv) = &d.dof[dof] else { continue };
            match drv.at(t_end) {
                Imposed::Velocity(v) => b.vel[k][dof] = v,
                Imposed::Servo(sigma, gain, vmax) => {
                    // the stress the grains exerted on the wall over the last step
                    if let (Some(f), Some(e)) = (faces, extent) {
                        if let Some(wall) = f.iter().position(|&x| x as usize == k).filter(|wl| wl / 2 == dof) {
                            let l = [e[1] - e[0], e[3] - e[2], e[5] - e[4]];
                            let area = l[(dof + 1) % 3] * l[(dof + 2) % 3];
                            let sign = if wall % 2 == 0 { 1.0 } else { -1.0 };
                            let measured = -sign * reaction.get(k).map_or(0.0, |r| r[dof]) / (h * area);
                            b.vel[k][dof] = sign * (gain * (sigma - measured)).clamp(-vmax, vmax);
                        }
                    }
                }
                _ => {
                    let imposed = match drv.at(t_theta) {
                        Imposed::Pressure(sigma) => match (faces, extent) {
                            (Some(f), Some(e)) => match f.iter().position(|&x| x as usize == k) {
                                Some(wall) if wall / 2 == dof => {
                                    let l = [e[1] - e[0], e[3] - e[2], e[5] - e[4]];
                                    let area = l[(dof + 1) % 3] * l[(dof + 2) % 3];
                                    let sign = if wall % 2 == 0 { 1.0 } else { -1.0 };
                                    Imposed::Force(sign * sigma * area)
                                }
                                _ => Imposed::Free,
                            },
                            _ => Imposed::Free,
                        },
                        other => other,
                    };
                    if let Imposed::Force(f) = imposed {
                        if dof < 3 {
                            b.vel[k][dof] += h * f / b.mass[k];
                        } else {
                            // an imposed moment about a world axis, through I_w⁻¹
                            let mut tq = [0.0; 3];
                            tq[dof - 3] = h * f;
                            let dw = coulomb::mul(&b.inv_mass[k].i, tq);
                            for a in 0..3 {
                                b.vel[k][3 + a] += dw[a];
                            }
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
fn continued(prev: &[PrevContact], p: usize, key: ContactKey, point: [f64; 3], alert: f64) -> Option<usize> {
    let same = |k: usize| prev[k].key.i == key.i && prev[k].key.j == key.j;
    let (mut lo, mut hi) = (p, p);
    while lo > 0 && same(lo - 1) {
        lo -= 1;
    }
    while hi < prev.len() && same(hi) {
        hi += 1;
    }
    let d2 = |k: usize| dist2(prev[k].point, point);
    (lo..hi)
        .filter(|&k| d2(k) <= alert * alert)
        .min_by(|&a, &b| d2(a).total_cmp(&d2(b)))
}

fn dist2(a: [f64; 3], b: [f64; 3]) -> f64 {
    (0..3).map(|c| (a[c] - b[c]).powi(2)).sum()
}

/// A contact of the last step, as the next step's warm start and bonds read it.
#[derive(Clone, Copy, Debug)]
pub(crate) struct PrevContact {
    pub key: ContactKey,
    pub r: [f64; 3],
    pub bonded: bool,
    pub point: [f64; 3],
}

/// This step's contact set: frames, W_αα, ū and the warm start, applied at once.
pub fn build_contacts(w: &mut World3) {
    let (h, theta) = (w.time.h, w.time.theta);
    let s = &mut w.scratch;
    s.prev_keys.clear();
    let old = &w.contacts;
    s.prev_keys.extend((0..old.len()).map(|a| PrevContact {
        key: old.key[a],
        r: old.r[a],
        bonded: old.joint[a].bonded(),
        point: old.point[a],
    }));
    s.prev_keys.sort_unstable_by_key(|x| x.key);
    let c = &mut s.next;
    c.clear();
    let b = &w.bodies;
    let nm = w.materials.len();
    for rc in &s.raw {
        let (i, j) = (rc.i as usize, rc.j as usize);
        let frame = D3::frame(&rc.point, &rc.normal, &b.pos[i], &b.pos[j]);
        let wb = D3::delassus(&frame, &b.inv_mass[i], &b.inv_mass[j]);
        if !(wb[0] > 0.0) {
            continue;
        }
        let Some(law) = w.laws[b.material[i] as usize * nm + b.material[j] as usize] else {
            continue;
        };
        let u_begin = D3::local_velocity(&frame, &s.v_begin[i], &s.v_begin[j]);
        let u_free = D3::local_velocity(&frame, &b.vel[i], &b.vel[j]);
        let key = ContactKey {
            i: rc.i,
            j: rc.j,
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
            Some(p) if dist2(s.prev_keys[p].point, rc.point) <= w.alert * w.alert => Some(p),
            _ => continued(&s.prev_keys, at, key, rc.point, w.alert),
        };
        let r = near.or(exact).map_or([0.0; 3], |p| s.prev_keys[p].r);
        let bonded = match near {
            Some(p) => s.prev_keys[p].bonded,
            // bonds are made at the first step only
            None => w.step == 0 && rc.gap <= law.bond_gap,
        };
        let joint = if bonded && law.is_cohesive() && rc.area > 0.0 {
            Joint::of(law.cohesion, law.tensile, law.mu, rc.area, h)
        } else {
            Joint::default()
        };
        c.bodies.push([rc.i, rc.j]);
        c.frame.push(frame);
        c.block.push(D3::block(wb, law.mu));
        c.target.push(Target {
            u_target: target_velocity(rc.gap, u_begin[0], u_free[0], h, theta, law.e),
            mu: law.mu,
        });
        c.r.push(r);
        c.u_free.push(u_free);
        c.gap.push(rc.gap);
        c.point.push(rc.point);
        c.key.push(key);
        c.joint.push(joint);
    }
    std::mem::swap(&mut w.contacts, &mut s.next);
    w.contacts.apply_all(&mut w.bodies.vel, &w.bodies.inv_mass);
}

/// Failure of bonded joints on the converged impulses: a joint whose strength is
/// exceeded loses its bond for good (`dim::joint`). "Exceeded" means by more
/// than 100 × the solver tolerance (at most 2 %): the impulses of a converged NLGS
/// are accurate to a few tolerances, and a smaller overload makes the joint slip,
/// so its slip velocity, hence the excess, grows until it fails a few steps later.
pub fn update_joints(w: &mut World3) {
    let tol = (100.0 * w.solver.tolerance).clamp(1e-9, 0.02);
    let c = &mut w.contacts;
    for a in 0..c.len() {
        let jt = c.joint[a];
        if !jt.bonded() {
            continue;
        }
        let u = c.local_velocity(a, &w.bodies.vel);
        let wr = D3::w_mul(&c.block[a], &c.r[a]);
        let u0 = u.sub(&wr);
        let t = c.target[a];
        if !D3::joint_holds(&c.block[a], &c.r[a], &u0, t.u_target, t.mu, &jt, tol) {
            c.joint[a] = Joint::default();
        }
    }
}

/// Positions and orientations, the reactions, and the divergence check.
pub fn update_positions(w: &mut World3) -> Result<(), Diverged> {
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
            w.box_h0 = w.box_extent().map(|e| e[5] - e[4]);
        }
    }
    Ok(())
}
