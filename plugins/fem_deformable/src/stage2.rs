//! The deformable bodies of a 2D world as a contact stage of its time step
//! ([`nscdd::engine::ContactStage`]): the rigid world steps as usual (free velocity,
//! detection, its own contacts, position update) and this stage adds, around the
//! contact solve, the deformable bodies' free velocities, their node contacts and
//! their share of every NLGS sweep. One sweep visits the rigid contacts (the
//! framework's sweep, unchanged) and then the deformable contacts; the check sums
//! of both are merged, so the criterion is the one of a single problem.
//!
//! After the solve, V⁺ = V_free + M̂⁻¹ Σ_α H_α r_α (one solve per body touched) and
//! u⁺ = u⁻ + h((1 − θ)V⁻ + θV⁺) ([`Deformables2::update`]).

use crate::body::FeBody;
use crate::contact2::*;
pub use crate::nodes::fill_set;
use nscdd::dim::coulomb2 as coulomb;
use nscdd::dim::d2::Block2;
use nscdd::engine::{ContactStage, Diverged};
use nscdd::law::{Law, LawInput, LawOutput, LawStep};
use nscdd::model::Target;
use nscdd::norms::{natural_map_sq, project_cone, Sums};
use nscdd::solver::SolveReport;
use nscdd::solver::{nlgs, relax};
use nscdd::world::World2;
use std::time::Instant;

/// An antagonist side: the side, its local velocities at the beginning of the step
/// and free, its material.
type AntaSide = (Anta, [f64; 2], [f64; 2], u16);

/// Seconds per stage of the deformable part of the last step (the benchmark's
/// split).
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize)]
pub struct FeTimes {
    /// Numeric factorizations of M̂ (when h or θ changed).
    pub factor: f64,
    /// Free velocities (one solve per body).
    pub free: f64,
    pub detect: f64,
    /// Columns of M̂⁻¹ (solves) and the dense blocks G among contact nodes.
    pub columns: f64,
    /// NLGS sweeps (rigid and deformable contacts).
    pub nlgs: f64,
    /// V⁺ (one solve per body in contact) and u⁺.
    pub update: f64,
    /// Column solves done in the step.
    pub solves: u64,
}

/// The deformable bodies of a scene and their contacts (see the module docs).
#[derive(Default)]
pub struct Deformables2 {
    pub bodies: Vec<FeBody>,
    /// The step's contacts, every one (one process's list). Stepped in part on MPI
    /// ranks, only the keys, sides, frames, points and impulses are the step's for
    /// the contacts solved elsewhere; their W_αα, u_free and targets are the
    /// build's before the partition, without solves (never read there: the
    /// residual reads each rank's own contacts, [`crate::solved::Solved`]).
    pub contacts: FeContacts2,
    pub sets: Vec<NodeSet>,
    pub alert: f64,
    pub times: FeTimes,
    pub(crate) raw: Vec<RawFe>,
    prev: Vec<(FeKey, [f64; 2])>,
    /// A failure inside the step (a refactorization), reported after it.
    pub error: Option<String>,
    /// V_free of the rigid antagonists of the step's contacts, by body (sorted): the
    /// world's warm start moves the bodies before the contacts are built.
    rigid_free: Vec<(u32, [f64; 3])>,
    /// The VTK frames written, (t, frame) ([`crate::family`]).
    pub frames: Vec<(f64, u32)>,
    /// The bodies this MPI rank steps ([`crate::stepped`]).
    pub stepped: crate::stepped::Stepped,
    /// The contacts this MPI rank solves, stepped in part ([`crate::solved::Solved`]).
    pub solved: crate::solved::Solved<FeContacts2>,
    /// Every rank's contacts on rank 0 for the saved state, gathered on MPI ranks
    /// ([`crate::whole::gather_contacts`]).
    pub gathered: Option<Vec<(crate::nodes::FeKey, [f64; 2])>>,
    /// The last step's impulses of the contacts this rank may solve, on MPI ranks
    /// ([`crate::warm`]).
    pub warm: crate::warm::Warm<2>,
    /// (this rank, ranks) of a run on MPI ranks, from the load.
    pub ranks: Option<(u32, u32)>,
}

impl Deformables2 {
    pub fn new(bodies: Vec<FeBody>, alert: f64) -> Self {
        let n = bodies.len();
        Deformables2 {
            bodies,
            sets: vec![NodeSet::default(); n],
            alert,
            ..Default::default()
        }
    }

    /// Detection and the free velocities (factoring M̂ first if h or θ changed):
    /// the one-domain stage.
    pub fn begin_step(&mut self, w: &World2) -> Result<(), String> {
        self.detect_step(w, None);
        self.free_step(w)
    }

    /// Detection (with `own`, in this rank's cells only: [`nscdd::dd::OwnCells`]),
    /// and the V_free of the rigid antagonists.
    pub fn detect_step(&mut self, w: &World2, own: Option<&nscdd::dd::OwnCells<'_>>) {
        let t = Instant::now();
        let held = crate::near::held_for(&self.stepped.near, own.is_some());
        detect(w, &self.bodies, self.alert, own, held, &mut self.raw);
        let rigid = self.raw.iter_mut().filter_map(|rc| match &mut rc.anta {
            RawAnta::Rigid(j) => Some(j),
            _ => None,
        });
        crate::family::rigid_by_global(w, rigid, &mut self.rigid_free);
        // (in key order: the order of the family's contacts, whatever order
        // detection finds them in; those that cannot move dropped, every one kept
        // built: the family's contacts)
        let bodies = &self.bodies;
        self.raw.retain(|rc| crate::contact2::kept(w, bodies, rc));
        self.raw.sort_by_key(|rc| rc.key());
        self.times.detect = t.elapsed().as_secs_f64();
    }

    /// The free velocities of the bodies this rank steps ([`crate::stepped`]).
    pub fn free_step(&mut self, w: &World2) -> Result<(), String> {
        let detect = self.times.detect;
        self.times = free_velocities(&mut self.bodies, w.time.h, w.time.theta, self.stepped.masks())?;
        self.times.detect = detect;
        Ok(())
    }

    /// Builds the node sets, their G blocks and the contacts (frames, W_αα, ū, warm
    /// start), from the raw contacts of [`Self::begin_step`].
    pub fn build(&mut self, w: &mut World2) {
        self.build_contacts(w);
        self.warm_start(w);
    }

    /// [`Self::build`] but the warm start: the contact list (the same whatever
    /// bodies this rank steps) and, for the bodies it steps ([`crate::stepped`]),
    /// G, W_αα, u_free and the targets.
    pub fn build_contacts(&mut self, w: &World2) {
        self.fill_step();
        self.build_list(w);
    }

    /// The node sets of the step's contact nodes: G and the free velocities there
    /// of the bodies this rank steps (timed as the columns).
    pub fn fill_step(&mut self) {
        let t0 = Instant::now();
        let solves0: u64 = self.bodies.iter().map(|b| b.solves).sum();
        self.fill_sets();
        let solves1: u64 = self.bodies.iter().map(|b| b.solves).sum();
        self.times.solves = solves1.saturating_sub(solves0);
        self.times.columns = t0.elapsed().as_secs_f64();
    }

    /// [`Self::build_contacts`] after [`Self::fill_step`]: the contacts (frames,
    /// W_αα, ū, warm start), stepped in part only those solved here.
    pub fn build_list(&mut self, w: &World2) {
        let (h, theta) = (w.time.h, w.time.theta);
        // (stepped in part, the contacts solved here start from the impulses kept by
        // the ranks that stepped their bodies: [`crate::warm`])
        let own = self.stepped.solved();
        let from_warm = own.is_some() && !self.warm.from_list;
        self.prev.clear();
        if !from_warm {
            let kr = self.contacts.key.iter().copied().zip(self.contacts.r.iter().copied());
            self.prev.extend(kr);
            self.prev.sort_unstable_by_key(|x| x.0);
        }
        // stepped in part, after the partition: only the contacts solved here, into
        // `solved` (the family's contacts are the raw ones, [`crate::solved::Solved`])
        let mut c = match own {
            None => std::mem::take(&mut self.contacts),
            Some(_) => std::mem::take(&mut self.solved.list),
        };
        c.clear();
        self.solved.at.clear();
        let v_begin = w.velocity_begin();
        for (i, rc) in self.raw.iter().enumerate() {
            if own.is_some_and(|o| !o[i]) {
                continue;
            }
            let bi = rc.body as usize;
            let set = &self.sets[bi];
            let k = set.nodes.binary_search(&rc.node).unwrap() as u32;
            let cand = FeSide {
                body: rc.body,
                k: [k, k],
                w: [1.0, 0.0],
            };
            let n = rc.n;
            let body = &self.bodies[bi];
            let vb_i = local(n, [body.v_begin[2 * rc.node as usize], body.v_begin[2 * rc.node as usize + 1]]);
            let vf_i = local(n, set.v[k as usize]);
            let mut wb = set.delassus(&cand, n);
            // (W_αα > 0: a contact of two fixed sides was dropped at detection)
            let (anta, ub_j, uf_j, mat_j) = self.antagonist(w, rc, n, v_begin, &mut wb);
            // (a law for every contact kept by detection, [`crate::contact2::kept`])
            let Some(law) = w.law(body.material, mat_j) else { continue };
            let u_begin = [vb_i[0] - ub_j[0], vb_i[1] - ub_j[1]];
            let u_free = [vf_i[0] - uf_j[0], vf_i[1] - uf_j[1]];
            let lo = law_output(law, rc.gap, u_begin[0], u_free[0], (h, theta, w.step));
            let key = rc.key();
            let r = match self.prev.binary_search_by_key(&key, |x| x.0) {
                Ok(p) => self.prev[p].1,
                Err(_) if from_warm => self.warm.r_of(&key),
                Err(_) => [0.0, 0.0],
            };
            self.solved.at.push(i as u32);
            c.cand.push(cand);
            c.anta.push(anta);
            c.frame.push(n);
            c.block.push(Block2 {
                w: wb,
                pre: coulomb::precompute(wb, lo.target.mu),
            });
            c.target.push(Target {
                u_target: node_target(rc.gap, u_begin[0], h, theta, lo.target.u_target),
                mu: lo.target.mu,
            });
            c.r.push(r);
            c.u_free.push(u_free);
            c.gap.push(rc.gap);
            c.point.push(rc.point);
            c.key.push(key);
        }
        self.solved.keep(c, &mut self.contacts, own.is_some(), self.raw.len());
    }

    /// The contact nodes of each body (sorted, unique) and their node sets (G blocks,
    /// free velocities).
    fn fill_sets(&mut self) {
        let mut nodes: Vec<Vec<u32>> = vec![vec![]; self.bodies.len()];
        for rc in &self.raw {
            nodes[rc.body as usize].push(rc.node);
            if let RawAnta::Segment { body, a, b, .. } = rc.anta {
                nodes[body as usize].extend([a, b]);
            }
        }
        for ns in nodes.iter_mut() {
            ns.sort_unstable();
            ns.dedup();
        }
        // stepped in part: a body stepped here whose contacts other ranks solve
        // too, from the contacts solved here and the nodes the others asked for
        let raw = self.raw.iter().enumerate().flat_map(|(i, rc)| {
            let anta = match rc.anta {
                RawAnta::Segment { body, a, b, .. } => [Some((i, body, a)), Some((i, body, b))],
                _ => [None, None],
            };
            std::iter::once((i, rc.body, rc.node)).chain(anta.into_iter().flatten())
        });
        crate::solved::shared_nodes(&self.stepped, &self.solved, raw, &mut nodes);
        crate::nodes::fill_sets(&mut self.bodies, &mut self.sets, &nodes, self.stepped.mask());
    }

    /// The antagonist side of a raw contact: the side, its local velocities at the
    /// beginning of the step and free, its material; adds its
    /// share of W_αα to `wb`.
    fn antagonist(&self, w: &World2, rc: &RawFe, n: [f64; 2], v_begin: &[[f64; 3]], wb: &mut [f64; 3]) -> AntaSide {
        match rc.anta {
            RawAnta::Rigid(g) => {
                let ju = crate::family::slot(w, g);
                let arm = rigid_arm(n, rc.point, w.bodies.pos[ju]);
                let wr = rigid_delassus(n, arm, w.bodies.inv_mass[ju]);
                for q in 0..3 {
                    wb[q] += wr[q];
                }
                (
                    Anta::Rigid { body: g, arm },
                    rigid_local(n, arm, v_begin[ju]),
                    rigid_local(n, arm, free_of(&self.rigid_free, g)),
                    w.bodies.material[ju],
                )
            }
            RawAnta::Segment { body: ob, a, b, xi, .. } => {
                let os = &self.sets[ob as usize];
                let ka = os.nodes.binary_search(&a).unwrap() as u32;
                let kb = os.nodes.binary_search(&b).unwrap() as u32;
                let side = FeSide {
                    body: ob,
                    k: [ka, kb],
                    w: [1.0 - xi, xi],
                };
                let wo = os.delassus(&side, n);
                for q in 0..3 {
                    wb[q] += wo[q];
                }
                let other = &self.bodies[ob as usize];
                let vb = |x: u32| [other.v_begin[2 * x as usize], other.v_begin[2 * x as usize + 1]];
                let (va, vbb) = (vb(a), vb(b));
                let vbeg = [(1.0 - xi) * va[0] + xi * vbb[0], (1.0 - xi) * va[1] + xi * vbb[1]];
                (Anta::Fe(side), local(n, vbeg), local(n, os.side_velocity(&side)), other.material)
            }
        }
    }

    /// Warm start: the kept impulses applied to the node sets and rigid bodies (by
    /// their slots: on MPI ranks the world holds a part).
    fn warm_start(&mut self, w: &mut World2) {
        let c = &self.contacts;
        for a in 0..c.len() {
            let r = c.r[a];
            if r != [0.0, 0.0] {
                let anta = c.anta[a].rigid_at(|g| crate::family::slot(w, g));
                apply(
                    &mut self.sets,
                    &mut w.bodies.vel,
                    &w.bodies.inv_mass,
                    c.cand[a],
                    anta,
                    c.frame[a],
                    r,
                );
            }
        }
    }

    /// V⁺ of the deformable bodies from their free velocity and the impulses.
    pub fn finish_velocities(&mut self) {
        let c = &self.contacts;
        let impulses = (0..c.len()).map(|a| {
            let anta = c.anta[a].fe();
            (c.cand[a], anta, global(c.frame[a], c.r[a]))
        });
        crate::nodes::velocities_after(&mut self.bodies, &self.sets, impulses, self.stepped.mask());
    }

    /// u⁺ = u⁻ + h((1 − θ)V⁻ + θV⁺) ([`update_stepped`]: on MPI ranks the
    /// bodies stepped elsewhere at their boundary only).
    pub fn update(&mut self, h: f64, theta: f64, step: u64) -> Result<(), Diverged> {
        update_stepped(&mut self.bodies, h, theta, step, self.stepped.masks())
    }

    /// Natural-map residual ‖F(r)‖/‖q‖ of the whole step's problem: the world's
    /// rigid contacts and the deformable ones, from the current velocities.
    pub fn residual(&self, w: &World2) -> f64 {
        let (f1, q1) = nlgs::residual_parts(&w.contacts, &w.bodies.vel);
        let (f2, q2) = self.residual_parts(&w.bodies.vel, |g| crate::family::slot(w, g));
        nlgs::residual_of(f1 + f2, q1 + q2)
    }

    /// (‖F(r)‖², ‖q‖²) of the deformable contacts (natural map, as the rigid ones).
    /// `at(g)`: the index in `vel` of the rigid body of global id g.
    pub fn residual_parts(&self, vel: &[[f64; 3]], at: impl Fn(u32) -> usize) -> (f64, f64) {
        self.residual_parts_of(vel, at, 0..self.contacts.len())
    }

    /// [`Self::residual_parts`] of the contacts `contacts` only (the family's
    /// indices; stepped in part, those solved here: [`crate::solved::Solved`]).
    pub fn residual_parts_of(&self, vel: &[[f64; 3]], at: impl Fn(u32) -> usize, contacts: impl Iterator<Item = usize>) -> (f64, f64) {
        let part = self.stepped.solved().is_some();
        let (mut f2, mut q2) = (0.0, 0.0);
        for a in contacts {
            let Some((c, a)) = self.solved.place(&self.contacts, part, a) else {
                continue;
            };
            let t = c.target[a];
            let anta = c.anta[a].rigid_at(&at);
            let mut u = local_velocity(&self.sets, vel, c.cand[a], anta, c.frame[a]);
            u[0] -= t.u_target;
            f2 += natural_map_sq(&c.r[a], &u, t.mu);
            let q = [c.u_free[a][0] - t.u_target, c.u_free[a][1]];
            q2 += q[0] * q[0] + q[1] * q[1];
        }
        (f2, q2)
    }
}

/// Factors M̂ of the bodies `stepped` (`None`: all) if h or θ changed or their
/// factors were released (assembling M and K first if they were), then their free
/// velocity (the others keep V⁻ only); the times of both stages.
pub fn free_velocities(bodies: &mut [FeBody], h: f64, theta: f64, (stepped, held): Masks<'_>) -> Result<FeTimes, String> {
    let t0 = Instant::now();
    for (bi, b) in bodies.iter_mut().enumerate() {
        if stepped.is_none_or(|m| m[bi]) {
            b.ensure_matrices()?;
            b.factorize(h, theta)?;
        }
    }
    let t1 = Instant::now();
    for (bi, b) in bodies.iter_mut().enumerate() {
        if stepped.is_none_or(|m| m[bi]) {
            b.free_velocity(h, theta);
        } else if held.is_none_or(|m| m[bi]) {
            // (V⁻ kept; V_free is not needed here: [`crate::stepped`])
            b.v_begin.clone_from(&b.v);
        }
    }
    Ok(FeTimes {
        factor: (t1 - t0).as_secs_f64(),
        free: t1.elapsed().as_secs_f64(),
        ..Default::default()
    })
}

/// u⁺ = u⁻ + h((1 − θ)V⁻ + θV⁺) of every deformable body; the divergence check
/// names the body and node.
pub fn update_bodies(bodies: &mut [FeBody], h: f64, theta: f64, step: u64) -> Result<(), Diverged> {
    update_stepped(bodies, h, theta, step, (None, None))
}

/// The bodies an MPI rank steps and those whose boundary it holds current
/// ([`crate::stepped::Stepped::masks`]; `None`: every body).
pub type Masks<'a> = (Option<&'a [bool]>, Option<&'a [bool]>);

/// [`update_bodies`], at their boundary nodes only for the bodies `stepped` says
/// this MPI rank does not step (`None`: all stepped): all it holds of them is
/// their boundary ([`crate::whole`]); not at all for those `held` says it holds
/// stale ([`crate::near`]).
pub fn update_stepped(bodies: &mut [FeBody], h: f64, theta: f64, step: u64, (stepped, held): Masks<'_>) -> Result<(), Diverged> {
    for (bi, b) in bodies.iter_mut().enumerate() {
        let (d, n) = (b.dim(), b.u.len());
        // u⁺ at dof i, whether u⁺ and V⁺ are finite there
        let at = |b: &mut FeBody, i: usize| {
            b.u[i] = b.u_next(i, h, theta);
            b.u[i].is_finite() && b.v[i].is_finite()
        };
        let mut bad = None;
        if stepped.is_none_or(|m| m[bi]) {
            for i in 0..n {
                if !at(b, i) && bad.is_none() {
                    bad = Some(i);
                }
            }
        } else if held.is_none_or(|m| m[bi]) {
            // (a body stepped elsewhere: its boundary's degrees of freedom; none of
            // one held stale here, [`crate::near`])
            for q in 0..b.mesh.boundary.len() {
                let k = b.mesh.boundary[q] as usize;
                for i in d * k..d * k + d {
                    if !at(b, i) && bad.is_none() {
                        bad = Some(i);
                    }
                }
            }
        }
        if let Some(i) = bad {
            let name = b.name.as_deref().map(|n| format!(" (`{n}`)")).unwrap_or_default();
            return Err(Diverged {
                step,
                body: bi as u32,
                message: format!(
                    "deformable body {bi}{name} has a non-finite state at node {} (displacement {}, velocity {})",
                    i / d,
                    b.u[i],
                    b.v[i]
                ),
            });
        }
    }
    Ok(())
}

/// The law's target ū for a node contact. An open contact (g > 0) may close
/// exactly its gap within the step, ū = −(g + h(1 − θ)u⁻_n)/(hθ), even when the
/// free motion predicts a penetration: the framework's Moreau form would then
/// impose u_n ≥ 0 and hold a node at the distance g from the surface, an error
/// of the order h·u that large steps (quasi-static loading of a stiff body) make
/// visible. Closed contacts (g ≤ 0) take the law's target `closed`.
pub fn node_target(gap: f64, un_begin: f64, h: f64, theta: f64, closed: f64) -> f64 {
    if gap > 0.0 {
        -(gap + h * (1.0 - theta) * un_begin) / (h * theta)
    } else {
        closed
    }
}

/// The law's ū and μ for a node contact (FE contacts are never bonded).
pub fn law_output(law: &dyn Law, gap: f64, un_begin: f64, un_free: f64, (h, theta, step): (f64, f64, u64)) -> LawOutput {
    let input = LawInput {
        gap,
        un_begin,
        un_free,
        area: 0.0,
        was_bonded: None,
    };
    law.contact(
        &LawStep {
            h,
            theta,
            first: step == 0,
        },
        &input,
    )
}

/// u_α of a deformable contact from the current velocities.
#[inline(always)]
pub fn local_velocity(sets: &[NodeSet], vel: &[[f64; 3]], cand: FeSide, anta: Anta, n: [f64; 2]) -> [f64; 2] {
    let ui = local(n, sets[cand.body as usize].side_velocity(&cand));
    let uj = match anta {
        Anta::Rigid { body, arm } => rigid_local(n, arm, vel[body as usize]),
        Anta::Fe(s) => local(n, sets[s.body as usize].side_velocity(&s)),
    };
    [ui[0] - uj[0], ui[1] - uj[1]]
}

/// Applies the impulse increment Δr of a deformable contact to both sides.
#[inline(always)]
pub fn apply(sets: &mut [NodeSet], vel: &mut [[f64; 3]], inv: &[[f64; 3]], cand: FeSide, anta: Anta, n: [f64; 2], dr: [f64; 2]) {
    let p = global(n, dr);
    sets[cand.body as usize].apply_side(&cand, p);
    match anta {
        Anta::Rigid { body, arm } => rigid_apply(n, arm, dr, &mut vel[body as usize], inv[body as usize]),
        Anta::Fe(s) => sets[s.body as usize].apply_side(&s, [-p[0], -p[1]]),
    }
}

/// One NLGS sweep over the deformable contacts (storage order), as the rigid
/// sweep: u0 = u − W_αα r, local solve, relaxation, update of both sides.
pub fn sweep(c: &mut FeContacts2, sets: &mut [NodeSet], vel: &mut [[f64; 3]], inv: &[[f64; 3]], omega: f64, mut sums: Option<&mut Sums>) {
    for a in 0..c.len() {
        let (cand, anta, n) = (c.cand[a], c.anta[a], c.frame[a]);
        let u = local_velocity(sets, vel, cand, anta, n);
        let r = c.r[a];
        let Block2 { w, pre } = c.block[a];
        let wr_old = [w[0] * r[0] + w[1] * r[1], w[1] * r[0] + w[2] * r[1]];
        let u0 = [u[0] - wr_old[0], u[1] - wr_old[1]];
        let t = c.target[a];
        let mut rn = coulomb::solve_pre(w, &pre, u0, t.u_target, t.mu);
        if omega != 1.0 {
            relax(&r, &mut rn, omega, |z| project_cone(z, t.mu));
        }
        let dr = [rn[0] - r[0], rn[1] - r[1]];
        if let Some(s) = sums.as_deref_mut() {
            let wr = [w[0] * rn[0] + w[1] * rn[1], w[1] * rn[0] + w[2] * rn[1]];
            let du = [wr[0] - wr_old[0], wr[1] - wr_old[1]];
            s.add(&r, &rn, &du, &wr_old, &wr);
        }
        if dr != [0.0, 0.0] {
            c.r[a] = rn;
            apply(sets, vel, inv, cand, anta, n, dr);
        }
    }
}

impl ContactStage<World2> for Deformables2 {
    fn after_free_velocity(&mut self, w: &World2) {
        // M̂ is factored at load time for the scene's h and θ: nothing can fail here
        if let Err(e) = self.begin_step(w) {
            self.error = Some(e);
        }
    }
    fn prepare(&mut self, w: &mut World2) {
        self.build(w);
    }
    fn solve(&mut self, w: &mut World2) -> SolveReport {
        let t0 = Instant::now();
        let s = w.solver.clone();
        let order: Vec<u32> = <nscdd::dd::Rigid2 as nscdd::dd::Family>::order(w).to_vec();
        let mut report = if w.contacts.is_empty() && self.contacts.is_empty() {
            SolveReport {
                converged: true,
                ..Default::default()
            }
        } else {
            s.run_sweeps(|mut sm| {
                nlgs::sweep(
                    &mut w.contacts,
                    &mut w.bodies.vel,
                    &w.bodies.inv_mass,
                    &order,
                    s.relaxation,
                    sm.as_deref_mut(),
                );
                sweep(
                    &mut self.contacts,
                    &mut self.sets,
                    &mut w.bodies.vel,
                    &w.bodies.inv_mass,
                    s.relaxation,
                    sm,
                );
            })
        };
        report.residual = self.residual(w);
        let t1 = Instant::now();
        self.finish_velocities();
        self.times.nlgs = (t1 - t0).as_secs_f64();
        self.times.update = t1.elapsed().as_secs_f64();
        report
    }
}

/// V_free of rigid body `j` among the step's antagonists (`free`: sorted by body).
fn free_of(free: &[(u32, [f64; 3])], j: u32) -> [f64; 3] {
    let k = free.binary_search_by_key(&j, |x| x.0);
    k.map_or([0.0; 3], |k| free[k].1)
}
