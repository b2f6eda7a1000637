//! The 2D deformable bodies as a body family of the NSCDD stage
//! ([`nscdd::dd::attach`]): subdomains by model and by geometry, glued to the rigid
//! ones through the framework's one gluing code, with its schemes and threads.
//!
//! An entity is a deformable body; its copy in subdomain E holds the body's contact
//! nodes (the union over the step's contacts, the same list in every copy) with
//! M̂_E = M̂/m: the copy's block of M̂_E⁻¹ among those nodes is m G, so that its
//! velocity there is V_E = V_free + m G b_E with b_E = F_Γ,E + H_E r_E. A_ΓE picks
//! the 2 n values of V_E at the n contact nodes; the gluing moves them by ΔV
//! (V_E += m G ΔF_Γ = ΔV): the copies of a body go to their mean, and with Σ_E ΔF_Γ,E
//! = 0 the body's V⁺ = V_free + M̂⁻¹ Σ_E H_E r_E is the one-domain formula
//! ([`Deformables2::finish_velocities`]). A body touched by the contacts of several
//! subdomains is thus duplicated whole (each copy solves with M̂/m), not cut into
//! node sets.

use crate::contact2::*;
use crate::stage2::{self, Deformables2};
use nscdd::dd::{Attached, EntityInfo, LocalPart, OwnCells, Rigid2, SolvedOn};
use nscdd::dim::coulomb2 as coulomb;
use nscdd::dim::d2::Block2;
use nscdd::norms::Sums;
use nscdd::world::World2;
use std::any::Any;

/// The deformable bodies' share of one subdomain.
#[derive(Default)]
pub struct FePart2 {
    /// Deformable body of each local entity.
    fe: Vec<u32>,
    sets: Vec<NodeSet>,
    contacts: FeContacts2,
    /// Index of each local contact in the family's list (stepped in part, the list
    /// of the contacts solved here: [`crate::solved::Solved`]).
    global: Vec<u32>,
    /// A part of another rank's subdomain, stepped in part, of this many
    /// contacts: its entities and its count only (what the gluing reads of it;
    /// its contacts stay on their rank, [`crate::warm`]).
    shell: Option<u32>,
}

impl LocalPart<Rigid2> for FePart2 {
    fn len(&self) -> usize {
        self.shell.map_or(self.global.len(), |n| n as usize)
    }
    fn entities(&self) -> &[u32] {
        &self.fe
    }
    fn prepare(&mut self, inv: &[[f64; 3]], mult: &[u32]) {
        for (set, &m) in self.sets.iter_mut().zip(mult) {
            if m > 1 {
                let m = m as f64;
                set.g.iter_mut().for_each(|g| *g *= m);
            }
        }
        let c = &mut self.contacts;
        for a in 0..c.len() {
            let (cand, anta, n) = (c.cand[a], c.anta[a], c.frame[a]);
            let mut wb = self.sets[cand.body as usize].delassus(&cand, n);
            let wo = match anta {
                Anta::Rigid { body, arm } => rigid_delassus(n, arm, inv[body as usize]),
                Anta::Fe(s) => self.sets[s.body as usize].delassus(&s, n),
            };
            for q in 0..3 {
                wb[q] += wo[q];
            }
            c.block[a] = Block2 {
                w: wb,
                pre: coulomb::precompute(wb, c.target[a].mu),
            };
        }
    }
    fn warm_start(&mut self, vel: &mut [[f64; 3]], inv: &[[f64; 3]]) {
        let c = &self.contacts;
        for a in 0..c.len() {
            let r = c.r[a];
            if r != [0.0, 0.0] {
                stage2::apply(&mut self.sets, vel, inv, c.cand[a], c.anta[a], c.frame[a], r);
            }
        }
    }
    fn sweep(&mut self, vel: &mut [[f64; 3]], inv: &[[f64; 3]], omega: f64, sums: Option<&mut Sums>) {
        stage2::sweep(&mut self.contacts, &mut self.sets, vel, inv, omega, sums);
    }
    fn entity_velocity(&self, e: usize, out: &mut Vec<f64>) {
        out.extend(self.sets[e].v.iter().flatten());
    }
    fn glue_entity(&mut self, e: usize, dv: &[f64]) {
        for (v, d) in self.sets[e].v.iter_mut().zip(dv.chunks_exact(2)) {
            v[0] += d[0];
            v[1] += d[1];
        }
    }
    /// Nothing: a family stepped in part (on MPI ranks, where parts are shared)
    /// needs no number of another rank's contacts (each rank's residual reads its
    /// own subdomains' contacts, the warm starts come from the ranks stepping the
    /// bodies: [`crate::warm`]).
    fn pack(&self, _out: &mut Vec<f64>) {}
    fn packed_len(&self) -> usize {
        0
    }
    fn unpack(&mut self, _values: &[f64]) {}
    fn as_any(&self) -> &dyn Any {
        self
    }
}

impl Attached<Rigid2> for Deformables2 {
    /// Detection only: the free velocities come after the partition
    /// ([`Self::solved_on`]).
    fn after_free_velocity(&mut self, w: &World2) {
        self.detect_step(w, None);
    }
    /// Detection of the contacts of the candidate nodes (or faces) in this rank's
    /// cells only: their points ([`Self::points`]) are the candidates' own.
    fn after_free_velocity_own(&mut self, w: &World2, own: &OwnCells<'_>) -> bool {
        self.detect_step(w, Some(own));
        true
    }
    /// Nothing is built before the partition: the family's contacts are its raw
    /// contacts, kept and sorted by detection ([`crate::solved::Solved`]); no body
    /// stepped yet.
    fn build(&mut self, _w: &mut World2) {
        self.stepped.hold(self.bodies.len());
    }
    /// The bodies of the contacts solved here ([`crate::stepped`]): their free
    /// velocities, and the contacts built again with their numbers.
    fn solved_on(&mut self, w: &World2, on: Option<&SolvedOn<'_>>) -> bool {
        let sides = self.raw.iter().map(|rc| rc.sides()).map(|(c, f, _)| (c.0, f.map(|s| s.0)));
        let part = self.stepped.decide(self.bodies.len(), on, sides, (w.time.h, w.time.theta));
        self.stepped.release(&mut self.bodies, &mut self.sets);
        // the whole states handed over, the nodes of the bodies stepped elsewhere asked
        if let Some(on) = on.filter(|_| part) {
            let (raw, st) = (&self.raw, &mut self.stepped);
            let bw = (&mut self.bodies[..], &mut self.warm);
            self.solved.asked = crate::solved::rounds_before(st, bw, (raw.len(), |a| raw[a].sides()), on);
        }
        // (a large body this rank steps first is assembled here: if that fails, no
        // body is stepped here and the step's end reports it)
        if let Err(e) = self.free_step(w) {
            self.error = Some(e);
            self.stepped.fail();
        }
        // stepped in part, the contacts are built once the other ranks' columns of
        // the bodies not stepped here have come ([`crate::solved::share_columns`])
        match part {
            true => self.fill_step(),
            false => self.build_contacts(w),
        }
        // the other ranks' subdomains, the node counts of the bodies stepped here, the
        // columns of the bodies several ranks solve; then the contacts solved here
        if let Some(on) = on.filter(|_| part) {
            let (raw, st, sw) = (&self.raw, &self.stepped, (&mut self.sets[..], &mut self.warm));
            crate::solved::rounds_after(st, sw, (raw.len(), |a| raw[a].sides()), on, &mut self.solved);
            self.build_list(w);
        }
        part
    }
    fn points(&self, out: &mut Vec<[f64; 3]>) {
        out.extend(self.raw.iter().map(|rc| rc.at3()));
    }
    fn n_entities(&self) -> usize {
        self.bodies.len()
    }
    /// Stepped in part, its contact nodes as the rank stepping it filled them.
    fn entity(&self, e: u32) -> EntityInfo {
        let here = self.sets[e as usize].len();
        let n = self.stepped.solved().and_then(|_| self.solved.set_len(e)).unwrap_or(here);
        debug_assert!(here == 0 || n == here, "body {e}'s contact nodes: {n}, {here} here");
        EntityInfo {
            dofs: 2 * n as u32,
            space: 2 * n as u32,
            rho2: 0.0,
            weight: 1.0 / n.max(1) as f64,
        }
    }
    fn split(&self, w: &World2, owner: &[u32], copy: &mut dyn FnMut(u32, u32) -> u32) -> Vec<(u32, Box<dyn LocalPart<Rigid2>>)> {
        let (c, in_part) = (&self.contacts, self.stepped.solved().is_some());
        // stepped in part: the contacts solved here come from their own list, the
        // other ranks' subdomains are shells made from their ranks' descriptions
        // ([`crate::shells`], [`FePart2::shell`])
        let own = self.stepped.solved();
        let make = |p: &mut FePart2, b: u32| p.push_entity(b, self);
        let pairs = by_subdomain(owner, |a| own.is_none_or(|o| o[a]));
        let mut parts = split_pairs(&pairs, self.bodies.len(), make, |s, part: &mut FePart2, contacts, entity| {
            for &a in contacts {
                let Some((src, l)) = self.solved.place(c, in_part, a as usize) else {
                    continue;
                };
                let mut cand = src.cand[l];
                cand.body = entity(part, cand.body);
                let anta = match src.anta[l] {
                    Anta::Rigid { body, arm } => Anta::Rigid { body: copy(s, body), arm },
                    Anta::Fe(mut side) => {
                        side.body = entity(part, side.body);
                        Anta::Fe(side)
                    }
                };
                part.global.push(l as u32);
                part.contacts.push_from(src, l, cand, anta);
            }
        });
        if own.is_some() {
            let held = |g: u32| w.ids.slot(g).is_some();
            parts.extend(crate::shells::make(&self.solved.shells, held, copy, |fe, n| FePart2 {
                fe,
                shell: Some(n),
                ..Default::default()
            }));
            parts.sort_by_key(|x| x.0);
        }
        parts
            .into_iter()
            .map(|(s, p)| (s, Box::new(p) as Box<dyn LocalPart<Rigid2>>))
            .collect()
    }
    fn write_back(&mut self, _w: &mut World2, parts: &[(u32, &dyn LocalPart<Rigid2>)]) {
        for (_, p) in parts {
            let Some(p) = p.as_any().downcast_ref::<FePart2>() else { continue };
            // (stepped in part, the contacts solved here: `global` indexes their list)
            let list = match self.stepped.solved() {
                Some(_) => &mut self.solved.list,
                None => &mut self.contacts,
            };
            for (l, &g) in p.global.iter().enumerate() {
                list.results_from(g as usize, &p.contacts, l);
            }
        }
        // stepped in part, V⁺ comes once the impulses of the bodies' contacts solved
        // elsewhere have come ([`Self::share_stepped`])
        if self.stepped.solved().is_none() {
            self.finish_velocities();
            // the one-domain sets hold V⁺ at the contact nodes (for the residual)
            crate::nodes::sets_at_velocities(&self.bodies, &mut self.sets);
        }
    }
    fn residual_parts(&self, w: &World2) -> (f64, f64) {
        Deformables2::residual_parts(self, &w.bodies.vel, |g| crate::family::slot(w, g))
    }
    /// Per subdomain: on ranks only the contacts solved here are read.
    fn residual_parts_in(&self, w: &World2, contacts: &[u32]) -> Option<(f64, f64)> {
        let at = |g| crate::family::slot(w, g);
        Some(self.residual_parts_of(&w.bodies.vel, at, contacts.iter().map(|&a| a as usize)))
    }
    /// V⁺ of the bodies stepped here, their contacts' impulses solved elsewhere
    /// received ([`crate::impulses`]), and V⁺ at a body's boundary sent to the
    /// ranks near it ([`crate::near`]).
    fn share_stepped(&mut self, rounds: &dyn nscdd::dd::Rounds, next: Option<&nscdd::dd::RankCells<'_>>) {
        let c = &self.solved.list;
        let own: Vec<_> = (0..c.len())
            .map(|l| (c.cand[l], c.anta[l].fe(), global(c.frame[l], c.r[l]), (c.key[l], c.r[l])))
            .collect();
        let sw = (&mut self.sets[..], &mut self.warm);
        let ba = (&mut self.bodies[..], self.alert);
        crate::impulses::finish(&mut self.stepped, ba, sw, own.into_iter(), (rounds, next));
    }
    /// Its contacts kept per rank: those whose point is this rank's (the
    /// contacts it solves; their nodes alone fill its node sets, the others'
    /// come through the rounds, [`crate::solved`]).
    fn keep_own(&mut self, own: &dyn Fn([f64; 3]) -> bool) -> bool {
        self.raw.retain(|rc| own(rc.at3()));
        true
    }
    crate::family::rank_hooks!(World2);
}

impl FePart2 {
    /// A copy of body `b`: its contact nodes at their free velocity (the family's
    /// set holds it: [`crate::nodes::fill_set`], or the rank stepping the body sent
    /// it, [`crate::solved::unpack_solved`]).
    fn push_entity(&mut self, b: u32, fe: &Deformables2) {
        self.fe.push(b);
        self.sets.push(fe.sets[b as usize].clone());
    }
}

/// The family's contacts grouped by subdomain (ascending; storage order inside):
/// `fill(s, part, contacts, entity)` fills subdomain s's part, `entity(part, b)`
/// giving the local id of body b's copy in it, made by `make(part, b)` on first
/// sight.
pub fn split_by<P: Default>(
    owner: &[u32],
    n_bodies: usize,
    make: impl Fn(&mut P, u32),
    fill: impl FnMut(u32, &mut P, &[u32], &mut dyn FnMut(&mut P, u32) -> u32),
) -> Vec<(u32, P)> {
    split_pairs(&by_subdomain(owner, |_| true), n_bodies, make, fill)
}

/// (subdomain, contact) of the contacts `keep` says, ascending (`owner`: each
/// contact's subdomain).
pub fn by_subdomain(owner: &[u32], keep: impl Fn(usize) -> bool) -> Vec<(u32, u32)> {
    let mut by_sub: Vec<(u32, u32)> = owner
        .iter()
        .enumerate()
        .filter(|x| keep(x.0))
        .map(|(a, &s)| (s, a as u32))
        .collect();
    by_sub.sort_unstable();
    by_sub
}

/// [`split_by`] of the contacts `by_sub` ((subdomain, contact), ascending).
pub fn split_pairs<P: Default>(
    by_sub: &[(u32, u32)],
    n_bodies: usize,
    make: impl Fn(&mut P, u32),
    mut fill: impl FnMut(u32, &mut P, &[u32], &mut dyn FnMut(&mut P, u32) -> u32),
) -> Vec<(u32, P)> {
    let mut out = Vec::new();
    // (subdomain, local id) of each body's last copy made
    let mut seen = vec![(u32::MAX, 0u32); n_bodies];
    let mut contacts = Vec::new();
    let mut p = 0;
    while p < by_sub.len() {
        let s = by_sub[p].0;
        let q = p + by_sub[p..].iter().take_while(|x| x.0 == s).count();
        contacts.clear();
        contacts.extend(by_sub[p..q].iter().map(|x| x.1));
        let mut part = P::default();
        let mut made = 0u32;
        let mut entity = |part: &mut P, b: u32| -> u32 {
            let e = &mut seen[b as usize];
            if e.0 != s {
                *e = (s, made);
                made += 1;
                make(part, b);
            }
            e.1
        };
        fill(s, &mut part, &contacts, &mut entity);
        out.push((s, part));
        p = q;
    }
    out
}
