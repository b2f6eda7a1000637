//! The deformable bodies of a 3D world as a contact stage of its time step: the
//! 3D counterpart of [`crate::stage2`], with the same steps (free velocities and
//! detection after the rigid free velocity; node sets, G blocks, W_αα, targets
//! and warm start after the rigid contact set; one NLGS sweep over the rigid
//! contacts (the framework's, unchanged) then over the deformable ones, sums
//! merged; V⁺ by one solve per body touched; u⁺ by [`crate::stage2::update_bodies`]).
//! The local problem of a contact is the framework's 3D Coulomb solver
//! ([`nscdd::dim::coulomb3`]).

use crate::body::FeBody;
use crate::contact3::*;
use crate::stage2::{free_velocities, law_output, node_target, FeTimes};
use nscdd::dim::coulomb3 as coulomb;
use nscdd::dim::d3::{tangents, Block3};
use nscdd::engine::{ContactStage, Diverged};
use nscdd::model::Target;
use nscdd::norms::{natural_map_sq, project_cone, Sums};
use nscdd::solver::SolveReport;
use nscdd::solver::{nlgs, relax};
use nscdd::world::World3;
use std::time::Instant;

/// Node k's velocity at the beginning of the step.
fn vb3(b: &FeBody, k: u32) -> [f64; 3] {
    std::array::from_fn(|q| b.v_begin[3 * k as usize + q])
}

/// An antagonist side: the side, its local velocities at the beginning of the step
/// and free, its material.
type AntaSide3 = (Anta3, [f64; 3], [f64; 3], u16);

/// The deformable bodies of a 3D scene and their contacts.
#[derive(Default)]
pub struct Deformables3 {
    pub bodies: Vec<FeBody>,
    /// The step's contacts, every one (one process's list). Stepped in part on MPI
    /// ranks, only the keys, sides, frames, points and impulses are the step's for
    /// the contacts solved elsewhere; their W_αα, u_free and targets are the
    /// build's before the partition, without solves (never read there: the
    /// residual reads each rank's own contacts, [`crate::solved::Solved`]).
    pub contacts: FeContacts3,
    pub sets: Vec<NodeSet3>,
    pub alert: f64,
    pub times: FeTimes,
    pub(crate) raw: Vec<RawFe3>,
    prev: Vec<(FeKey, [f64; 3])>,
    /// A failure inside the step (a refactorization), reported after it.
    pub error: Option<String>,
    /// V_free of the rigid antagonists of the step's contacts, by body (sorted): the
    /// world's warm start moves the bodies before the contacts are built.
    rigid_free: Vec<(u32, [f64; 6])>,
    /// The VTK frames written, (t, frame) ([`crate::family`]).
    pub frames: Vec<(f64, u32)>,
    /// The bodies this MPI rank steps ([`crate::stepped`]).
    pub stepped: crate::stepped::Stepped,
    /// The contacts this MPI rank solves, stepped in part ([`crate::solved::Solved`]).
    pub solved: crate::solved::Solved<FeContacts3>,
    /// Every rank's contacts on rank 0 for the saved state, gathered on MPI ranks
    /// ([`crate::whole::gather_contacts`]).
    pub gathered: Option<Vec<(crate::nodes::FeKey, [f64; 3])>>,
    /// The last step's impulses of the contacts this rank may solve, on MPI ranks
    /// ([`crate::warm`]).
    pub warm: crate::warm::Warm<3>,
    /// (this rank, ranks) of a run on MPI ranks, from the load.
    pub ranks: Option<(u32, u32)>,
}

/// The rigid bodies' M̂⁻¹ as the sweep reads them.
pub type RigidInv<'a> = &'a [nscdd::dim::d3::InvMass3];

impl Deformables3 {
    pub fn new(bodies: Vec<FeBody>, alert: f64) -> Self {
        let n = bodies.len();
        Deformables3 {
            bodies,
            sets: vec![NodeSet3::default(); n],
            alert,
            ..Default::default()
        }
    }

    /// Detection and the free velocities (factoring M̂ first if h or θ changed):
    /// the one-domain stage.
    pub fn begin_step(&mut self, w: &World3) -> Result<(), String> {
        self.detect_step(w, None);
        self.free_step(w)
    }

    /// Detection (with `own`, in this rank's cells only: [`nscdd::dd::OwnCells`]),
    /// and the V_free of the rigid antagonists.
    pub fn detect_step(&mut self, w: &World3, own: Option<&nscdd::dd::OwnCells<'_>>) {
        let t = Instant::now();
        let held = crate::near::held_for(&self.stepped.near, own.is_some());
        detect(w, &self.bodies, self.alert, own, held, &mut self.raw);
        let rigid = self.raw.iter_mut().filter_map(|rc| match &mut rc.anta {
            RawAnta3::Rigid(j) => Some(j),
            _ => None,
        });
        crate::family::rigid_by_global(w, rigid, &mut self.rigid_free);
        // (in key order: the order of the family's contacts, whatever order
        // detection finds them in; those that cannot move dropped, every one kept
        // built: the family's contacts)
        let bodies = &self.bodies;
        self.raw.retain(|rc| crate::contact3::kept(w, bodies, rc));
        self.raw.sort_by_key(|rc| rc.key());
        self.times.detect = t.elapsed().as_secs_f64();
    }

    /// The free velocities of the bodies this rank steps ([`crate::stepped`]).
    pub fn free_step(&mut self, w: &World3) -> Result<(), String> {
        let detect = self.times.detect;
        self.times = free_velocities(&mut self.bodies, w.time.h, w.time.theta, self.stepped.masks())?;
        self.times.detect = detect;
        Ok(())
    }

    /// Builds the node sets, their G blocks and the contacts (frames, W_αα, ū, warm
    /// start), from the raw contacts of [`Self::begin_step`].
    pub fn build(&mut self, w: &mut World3) {
        self.build_contacts(w);
        self.warm_start(w);
    }

    /// [`Self::build`] but the warm start: the contact list (the same whatever
    /// bodies this rank steps) and, for the bodies it steps ([`crate::stepped`]),
    /// G, W_αα, u_free and the targets.
    pub fn build_contacts(&mut self, w: &World3) {
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
    pub fn build_list(&mut self, w: &World3) {
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
            let body = &self.bodies[bi];
            let (cand, vbi) = match rc.cand {
                RawCand3::Node(node) => {
                    let k = set.nodes.binary_search(&node).unwrap() as u32;
                    (FeSide3::node(rc.body, k), vb3(body, node))
                }
                RawCand3::Face { nodes: f, w: wts, .. } => {
                    let k = f.map(|x| set.nodes.binary_search(&x).unwrap() as u32);
                    let mut v = [0.0; 3];
                    for (q, &node) in f.iter().enumerate() {
                        let vn = vb3(body, node);
                        for c in 0..3 {
                            v[c] += wts[q] * vn[c];
                        }
                    }
                    (FeSide3 { body: rc.body, k, w: wts }, v)
                }
            };
            let (t1, t2) = tangents(rc.n);
            let basis: Basis = [rc.n, t1, t2];
            let ub_i = local(&basis, vbi);
            let uf_i = local(&basis, set.side_velocity(&cand));
            let mut wb = project(&basis, &set.side_block(&cand));
            // (W_αα > 0: a contact of two fixed sides was dropped at detection)
            let (anta, ub_j, uf_j, mat_j) = self.antagonist(w, rc, &basis, v_begin, &mut wb);
            // (a law for every contact kept by detection, [`crate::contact3::kept`])
            let Some(law) = w.law(body.material, mat_j) else { continue };
            let u_begin: [f64; 3] = std::array::from_fn(|q| ub_i[q] - ub_j[q]);
            let u_free: [f64; 3] = std::array::from_fn(|q| uf_i[q] - uf_j[q]);
            let lo = law_output(law, rc.gap, u_begin[0], u_free[0], (h, theta, w.step));
            let key = rc.key();
            let r = match self.prev.binary_search_by_key(&key, |x| x.0) {
                Ok(p) => self.prev[p].1,
                Err(_) if from_warm => self.warm.r_of(&key),
                Err(_) => [0.0; 3],
            };
            self.solved.at.push(i as u32);
            c.cand.push(cand);
            c.anta.push(anta);
            c.frame.push(basis);
            c.block.push(Block3 {
                w: wb,
                pre: coulomb::precompute(&wb),
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
            match rc.cand {
                RawCand3::Node(k) => nodes[rc.body as usize].push(k),
                RawCand3::Face { nodes: f, .. } => nodes[rc.body as usize].extend(f),
            }
            if let RawAnta3::Face { body, nodes: f, .. } = rc.anta {
                nodes[body as usize].extend(f);
            }
        }
        for ns in nodes.iter_mut() {
            ns.sort_unstable();
            ns.dedup();
        }
        // stepped in part: a body stepped here whose contacts other ranks solve
        // too, from the contacts solved here and the nodes the others asked for
        let raw = self.raw.iter().enumerate().flat_map(|(i, rc)| {
            let cand = match rc.cand {
                RawCand3::Node(k) => [k; 3].map(|k| (i, rc.body, k)),
                RawCand3::Face { nodes: f, .. } => f.map(|k| (i, rc.body, k)),
            };
            let anta = match rc.anta {
                RawAnta3::Face { body, nodes: f, .. } => f.map(|k| Some((i, body, k))),
                _ => [None; 3],
            };
            cand.into_iter().chain(anta.into_iter().flatten())
        });
        crate::solved::shared_nodes(&self.stepped, &self.solved, raw, &mut nodes);
        crate::nodes::fill_sets(&mut self.bodies, &mut self.sets, &nodes, self.stepped.mask());
    }

    /// The antagonist side of a raw contact: the side, its local velocities at the
    /// beginning of the step and free, its material; adds its
    /// share of W_αα to `wb`.
    fn antagonist(&self, w: &World3, rc: &RawFe3, basis: &Basis, v_begin: &[[f64; 6]], wb: &mut [f64; 6]) -> AntaSide3 {
        let basis = *basis;
        match rc.anta {
            RawAnta3::Rigid(g) => {
                let ju = crate::family::slot(w, g);
                let x = w.bodies.pos[ju];
                let d = [rc.point[0] - x[0], rc.point[1] - x[1], rc.point[2] - x[2]];
                let wr = rigid_delassus(&basis, d, w.bodies.inv_mass[ju].m, &w.bodies.inv_mass[ju].i);
                for q in 0..6 {
                    wb[q] += wr[q];
                }
                (
                    Anta3::Rigid { body: g, d },
                    rigid_local(&basis, d, &v_begin[ju]),
                    rigid_local(&basis, d, &free_of(&self.rigid_free, g)),
                    w.bodies.material[ju],
                )
            }
            RawAnta3::Face {
                body: ob,
                nodes: f,
                w: wts,
                ..
            } => {
                let os = &self.sets[ob as usize];
                let kk = f.map(|x| os.nodes.binary_search(&x).unwrap() as u32);
                let side = FeSide3 { body: ob, k: kk, w: wts };
                let wo = project(&basis, &os.side_block(&side));
                for q in 0..6 {
                    wb[q] += wo[q];
                }
                let other = &self.bodies[ob as usize];
                let mut vbeg = [0.0; 3];
                for (q, &node) in f.iter().enumerate() {
                    let v = vb3(other, node);
                    for c in 0..3 {
                        vbeg[c] += wts[q] * v[c];
                    }
                }
                (
                    Anta3::Fe(side),
                    local(&basis, vbeg),
                    local(&basis, os.side_velocity(&side)),
                    other.material,
                )
            }
        }
    }

    /// Warm start: the kept impulses applied to the node sets and rigid bodies (by
    /// their slots: on MPI ranks the world holds a part).
    fn warm_start(&mut self, w: &mut World3) {
        let c = &self.contacts;
        for a in 0..c.len() {
            let r = c.r[a];
            if r != [0.0; 3] {
                let anta = c.anta[a].rigid_at(|g| crate::family::slot(w, g));
                let inv: RigidInv<'_> = &w.bodies.inv_mass;
                apply(&mut self.sets, &mut w.bodies.vel, inv, c.cand[a], anta, &c.frame[a], r);
            }
        }
    }

    /// V⁺ of the deformable bodies from their free velocity and the impulses.
    pub fn finish_velocities(&mut self) {
        let c = &self.contacts;
        let impulses = (0..c.len()).map(|a| {
            let anta = c.anta[a].fe();
            (c.cand[a], anta, global(&c.frame[a], c.r[a]))
        });
        crate::nodes::velocities_after(&mut self.bodies, &self.sets, impulses, self.stepped.mask());
    }

    /// u⁺ = u⁻ + h((1 − θ)V⁻ + θV⁺).
    pub fn update(&mut self, h: f64, theta: f64, step: u64) -> Result<(), Diverged> {
        crate::stage2::update_stepped(&mut self.bodies, h, theta, step, self.stepped.masks())
    }

    /// Natural-map residual ‖F(r)‖/‖q‖ of the whole step's problem (rigid and
    /// deformable contacts).
    pub fn residual(&self, w: &World3) -> f64 {
        let (f1, q1) = nlgs::residual_parts(&w.contacts, &w.bodies.vel);
        let (f2, q2) = self.residual_parts(&w.bodies.vel, |g| crate::family::slot(w, g));
        nlgs::residual_of(f1 + f2, q1 + q2)
    }

    /// (‖F(r)‖², ‖q‖²) of the deformable contacts.
    /// `at(g)`: the index in `vel` of the rigid body of global id g.
    pub fn residual_parts(&self, vel: &[[f64; 6]], at: impl Fn(u32) -> usize) -> (f64, f64) {
        self.residual_parts_of(vel, at, 0..self.contacts.len())
    }

    /// [`Self::residual_parts`] of the contacts `contacts` only (the family's
    /// indices; stepped in part, those solved here: [`crate::solved::Solved`]).
    pub fn residual_parts_of(&self, vel: &[[f64; 6]], at: impl Fn(u32) -> usize, contacts: impl Iterator<Item = usize>) -> (f64, f64) {
        let part = self.stepped.solved().is_some();
        let (mut f2, mut q2) = (0.0, 0.0);
        for a in contacts {
            let Some((c, a)) = self.solved.place(&self.contacts, part, a) else {
                continue;
            };
            let t = c.target[a];
            let anta = c.anta[a].rigid_at(&at);
            let mut u = local_velocity(&self.sets, vel, c.cand[a], anta, &c.frame[a]);
            u[0] -= t.u_target;
            f2 += natural_map_sq(&c.r[a], &u, t.mu);
            let q = [c.u_free[a][0] - t.u_target, c.u_free[a][1], c.u_free[a][2]];
            q2 += q[0] * q[0] + q[1] * q[1] + q[2] * q[2];
        }
        (f2, q2)
    }
}

/// u_α of a deformable contact from the current velocities.
#[inline(always)]
pub fn local_velocity(sets: &[NodeSet3], vel: &[[f64; 6]], cand: FeSide3, anta: Anta3, b: &Basis) -> [f64; 3] {
    let ui = local(b, sets[cand.body as usize].side_velocity(&cand));
    let uj = match anta {
        Anta3::Rigid { body, d } => rigid_local(b, d, &vel[body as usize]),
        Anta3::Fe(s) => local(b, sets[s.body as usize].side_velocity(&s)),
    };
    [ui[0] - uj[0], ui[1] - uj[1], ui[2] - uj[2]]
}

/// Applies the impulse increment Δr of a deformable contact to both sides.
#[inline(always)]
pub fn apply(sets: &mut [NodeSet3], vel: &mut [[f64; 6]], inv: RigidInv<'_>, cand: FeSide3, anta: Anta3, b: &Basis, dr: [f64; 3]) {
    let p = global(b, dr);
    sets[cand.body as usize].apply_side(&cand, p);
    match anta {
        Anta3::Rigid { body, d } => {
            let j = body as usize;
            rigid_apply(b, d, dr, &mut vel[j], inv[j].m, &inv[j].i)
        }
        Anta3::Fe(s) => sets[s.body as usize].apply_side(&s, p.map(|x| -x)),
    }
}

/// One NLGS sweep over the deformable contacts (storage order), as the rigid
/// sweep: u0 = u − W_αα r, local solve, relaxation, update of both sides.
pub fn sweep(c: &mut FeContacts3, sets: &mut [NodeSet3], vel: &mut [[f64; 6]], inv: RigidInv<'_>, omega: f64, mut sums: Option<&mut Sums>) {
    for a in 0..c.len() {
        let (cand, anta, b) = (c.cand[a], c.anta[a], c.frame[a]);
        let u = local_velocity(sets, vel, cand, anta, &b);
        let r = c.r[a];
        let blk = c.block[a];
        let wr_old = coulomb::mul(&blk.w, r);
        let u0 = [u[0] - wr_old[0], u[1] - wr_old[1], u[2] - wr_old[2]];
        let t = c.target[a];
        let mut rn = coulomb::solve_pre_warm(&blk.w, &blk.pre, u0, t.u_target, t.mu, r);
        if omega != 1.0 {
            relax(&r, &mut rn, omega, |z| project_cone(z, t.mu));
        }
        let dr = [rn[0] - r[0], rn[1] - r[1], rn[2] - r[2]];
        if let Some(s) = sums.as_deref_mut() {
            let wr = coulomb::mul(&blk.w, rn);
            let du = [wr[0] - wr_old[0], wr[1] - wr_old[1], wr[2] - wr_old[2]];
            s.add(&r, &rn, &du, &wr_old, &wr);
        }
        if dr != [0.0; 3] {
            c.r[a] = rn;
            apply(sets, vel, inv, cand, anta, &b, dr);
        }
    }
}

impl ContactStage<World3> for Deformables3 {
    fn after_free_velocity(&mut self, w: &World3) {
        if let Err(e) = self.begin_step(w) {
            self.error = Some(e);
        }
    }
    fn prepare(&mut self, w: &mut World3) {
        self.build(w);
    }
    fn solve(&mut self, w: &mut World3) -> SolveReport {
        let t0 = Instant::now();
        let s = w.solver.clone();
        let order: Vec<u32> = <nscdd::dd::Rigid3 as nscdd::dd::Family>::order(w).to_vec();
        let mut report = if w.contacts.is_empty() && self.contacts.is_empty() {
            SolveReport {
                converged: true,
                ..Default::default()
            }
        } else {
            s.run_sweeps(|mut sm| {
                let b = &mut w.bodies;
                nlgs::sweep(&mut w.contacts, &mut b.vel, &b.inv_mass, &order, s.relaxation, sm.as_deref_mut());
                let inv: RigidInv<'_> = &b.inv_mass;
                sweep(&mut self.contacts, &mut self.sets, &mut b.vel, inv, s.relaxation, sm);
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
fn free_of(free: &[(u32, [f64; 6])], j: u32) -> [f64; 6] {
    let k = free.binary_search_by_key(&j, |x| x.0);
    k.map_or([0.0; 6], |k| free[k].1)
}
