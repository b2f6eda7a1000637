//! What NSCDD needs from a family of bodies: the dimension lives here, in one small
//! trait, so that the partition, the subdomains, the gluing, the schemes, the
//! threads and the transport are written once for 2D and 3D rigid bodies (and,
//! later, for deformable ones). A family gives its generalized velocity type `V`
//! (one per body, `[f64; 3]` = (v_x, v_y, ω) in 2D, `[f64; 6]` = (v, ω) in 3D), its
//! contact set, the copies' M̂_E⁻¹ and the operations of DESIGN.md §3: one NLGS sweep,
//! M̂_E⁻¹ applied to an impulse, M̂_E applied to a velocity increment (the gluing).

use crate::dim::{Dim, Vector, D2, D3};
use crate::engine::{Diverged, StepReport};
use crate::model::{ContactKey, Contacts};
use crate::norms::Sums;
use crate::solver::nlgs;
use crate::world::World;

/// A body family as NSCDD sees it (see the module docs).
pub trait Family: Sized + Send + Sync + Default + Clone + std::fmt::Debug + 'static {
    /// Generalized velocity (and impulse) of one body.
    type V: Copy + Default + Send + Sync + std::fmt::Debug + PartialEq + AsRef<[f64]> + AsMut<[f64]>;
    /// M̂⁻¹ of one body (as the solver stores it).
    type InvMass: Copy + Default + Send + Sync + std::fmt::Debug;
    type Contacts: Default + Clone + std::fmt::Debug + Send + Sync;
    type World;
    /// Space dimension (2 or 3): the first `SPACE` components of `V` are translations.
    const SPACE: usize;

    fn len(c: &Self::Contacts) -> usize;
    fn reserve(c: &mut Self::Contacts, n: usize);
    /// Appends contact `a` of `src` with local body ids `li`, `lj`.
    fn push_contact(dst: &mut Self::Contacts, src: &Self::Contacts, a: usize, li: u32, lj: u32);
    fn bodies(c: &Self::Contacts, a: usize) -> [u32; 2];
    fn key(c: &Self::Contacts, a: usize) -> ContactKey;
    /// Contact point (z = 0 in 2D).
    fn point(c: &Self::Contacts, a: usize) -> [f64; 3];
    /// dst.r[ga] = src.r[la].
    fn copy_r(dst: &mut Self::Contacts, ga: usize, src: &Self::Contacts, la: usize);
    /// The impulse of contact `a` (local frame: normal first), for the exchange
    /// between processes.
    fn r(c: &Self::Contacts, a: usize) -> &[f64];
    fn r_mut(c: &mut Self::Contacts, a: usize) -> &mut [f64];
    /// W_αα (and its precomputed data) from the copies' M̂_E⁻¹, for the contacts
    /// touching a copy marked in `split` (M̂_E⁻¹ = m M̂⁻¹ with m ≥ 2); the others
    /// keep the world's block, which their copies' M̂_E⁻¹ = M̂⁻¹ would give again
    /// bit for bit.
    fn copy_delassus(c: &mut Self::Contacts, inv: &[Self::InvMass], split: &[bool]);
    /// V += M̂⁻¹ H r for every contact with r ≠ 0, in storage order.
    fn warm_start(c: &Self::Contacts, vel: &mut [Self::V], inv: &[Self::InvMass]);
    /// One NLGS sweep (a check pass when `sums` is given).
    fn sweep(c: &mut Self::Contacts, vel: &mut [Self::V], inv: &[Self::InvMass], order: &[u32], omega: f64, sums: Option<&mut Sums>);
    /// Friction coefficient of contact `a` (its Coulomb cone |r_t| ≤ μ r_n).
    fn mu(c: &Self::Contacts, a: usize) -> f64;
    /// Sets the impulse of contact `a` to `r`, the two bodies' velocities following
    /// (V += M̂⁻¹ H Δr).
    fn set_r(c: &mut Self::Contacts, a: usize, r: &[f64], vel: &mut [Self::V], inv: &[Self::InvMass]);
    /// M̂_E⁻¹ = m M̂⁻¹ (partition of unity over m copies).
    fn scale_inv(inv: Self::InvMass, m: f64) -> Self::InvMass;
    /// v += M̂_E⁻¹ f.
    fn apply_impulse(v: &mut Self::V, inv: &Self::InvMass, f: &Self::V);
    /// The gluing increment of a copy: it moves by `dv` on its free degrees of
    /// freedom and its interface impulse grows by M̂_E dv.
    fn glue(v: &mut Self::V, f_gamma: &mut Self::V, inv: &Self::InvMass, dv: &Self::V);

    /// Bodies in the scene: NSCDD's body ids g are the scene's global ids
    /// (`crate::model::ids`), 0..n_bodies, of which a world may hold a part.
    fn n_bodies(w: &Self::World) -> usize;
    /// The global id of the world's slot `k`, and the slot of global id `g` if
    /// the world holds it.
    fn global(w: &Self::World, k: usize) -> usize;
    fn slot(w: &Self::World, g: usize) -> Option<usize>;
    /// The slot of body `g`, which the world holds: every body NSCDD steps, glues
    /// or exchanges is held (one that is not is a broken invariant: a panic).
    fn held_slot(w: &Self::World, g: usize) -> usize {
        Self::slot(w, g).expect(HELD)
    }
    fn movable(w: &Self::World, g: usize) -> bool;
    fn inv_mass(w: &Self::World, g: usize) -> Self::InvMass;
    /// ρ² = I/m of body g (0 when undefined): the weight of rotations in the gluing
    /// norm |V|² = |v|² + ρ² |ω|².
    fn rho2(w: &Self::World, g: usize) -> f64;
    fn contacts(w: &Self::World) -> &Self::Contacts;
    fn contacts_mut(w: &mut Self::World) -> &mut Self::Contacts;
    /// The held bodies' velocities into `out`, by slot ([`Family::slot`]: as many
    /// as the world holds).
    fn velocities(w: &Self::World, out: &mut Vec<Self::V>);
    fn set_vel(w: &mut Self::World, g: usize, v: Self::V);
    /// The held bodies' velocities swapped with `v` (by slot, as many; another
    /// length, as empty: nothing).
    fn swap_velocities(w: &mut Self::World, v: &mut [Self::V]);
    /// The global ids of contact `a` of the world's contacts.
    fn contact_bodies(w: &Self::World, a: usize) -> [u32; 2];
    /// The step's visiting order of the contacts (empty: storage order).
    fn order(w: &Self::World) -> &[u32];
    /// Steps completed (the step being computed, during a step).
    fn step(w: &Self::World) -> u64;
    /// Natural-map residual of the world's contact problem.
    fn residual(w: &Self::World) -> f64;
    /// Its squared sums (‖F(r)‖², ‖q‖²), to add an attached family's.
    fn residual_parts(w: &Self::World) -> (f64, f64);
    /// The squared sums over the contacts `which` (one subdomain's), in that order.
    fn residual_parts_in(w: &Self::World, which: &[u32]) -> (f64, f64);
    /// Adds the contacts' Σ ±H r to `out` (indexed by the contacts' body ids).
    fn add_reactions(c: &Self::Contacts, out: &mut [Self::V]);
    /// Sets the world's per-body reactions from `r` (by slot), and the bodies
    /// whose reactions are observed (ascending: outputs and drives read them).
    fn set_reactions(w: &mut Self::World, r: Vec<Self::V>);
    fn observed(w: &Self::World) -> Vec<u32>;
    /// Whether body g is a grain (a free disk or sphere: the coordination numbers'
    /// population), and whether the world's outputs need the coordination numbers.
    fn is_grain(w: &Self::World, g: usize) -> bool;
    fn wants_coordination(w: &Self::World) -> bool;
    /// The inner box of a 3D box sample's bulk measures (`World3::bulk_box`, the
    /// history's margin of 4 grain sizes), and a body's position.
    fn bulk_box(w: &Self::World) -> Option<([f64; 3], [f64; 3])>;
    fn position(w: &Self::World, g: usize) -> [f64; 3];
    /// Body g's terms of the history's sums over bodies: its kinetic energy and
    /// m g·x when impulses can move it, and a 3D grain's volume inside the bulk box.
    fn body_energies(w: &Self::World, g: usize) -> Option<(f64, f64)>;
    fn grain_in_box(w: &Self::World, g: usize, lo: [f64; 3], hi: [f64; 3]) -> f64;
    /// Contacts held per rank ([`super::local`]): the next detection's region, the
    /// raw contacts kept after it (by key and point), the bodies' boxes (by slot;
    /// first `N` coordinates, the rest 0), and the other processes' last contacts for the warm
    /// start (records of [`Family::prev_record`]).
    fn set_region(w: &mut Self::World, region: Option<crate::detect::Region>);
    fn alert(w: &Self::World) -> f64;
    fn retain_raw(w: &mut Self::World, keep: &mut dyn FnMut(ContactKey, [f64; 3]) -> bool);
    /// Keeps the world's contacts `a` (the last step's) for which `keep(a)` holds.
    fn retain_contacts(w: &mut Self::World, keep: &mut dyn FnMut(usize) -> bool);
    fn body_boxes(w: &Self::World, out: &mut Vec<[[f64; 3]; 2]>);
    /// Bodies owned per rank ([`super::owned`]): the bodies this process steps
    /// (ascending; `None`: every body it holds), whether a body is stepped by
    /// every process (fixed, driven or unbounded), and a body's record as
    /// `BODY_RECORD` numbers: its moving state (position, orientation, velocity),
    /// then its static data (a body a process lacks enters with it); setting a
    /// record sets the moving state of a body the world holds.
    fn set_active(w: &mut Self::World, active: Option<Vec<u32>>);
    fn active(w: &Self::World) -> Option<&[u32]>;
    /// The bodies the world holds (ascending global ids; `None`: 0..n_bodies).
    fn held(w: &Self::World) -> Option<&[u32]>;
    /// The bodies this process steps: the active ones, else the held ones
    /// (ascending; `None`: 0..n_bodies).
    fn stepped(w: &Self::World) -> Option<&[u32]> {
        Self::active(w).or(Self::held(w))
    }
    fn everywhere(w: &Self::World, g: usize) -> bool;
    const BODY_RECORD: usize;
    fn body_record(w: &Self::World, g: usize, out: &mut Vec<f64>);
    fn set_body_record(w: &mut Self::World, g: usize, x: &[f64]);
    /// Compact arrays ([`crate::world::held`]): the world admits the bodies of
    /// `entering` (global id, [`Family::body_record`]: it carries their static
    /// data) it does not hold.
    fn admit(w: &mut Self::World, entering: &[(u32, &[f64])]);
    /// The world keeps only the bodies `keep` (ascending global ids; every body of
    /// its contacts, drives and box walls among them).
    fn hold(w: &mut Self::World, keep: &[u32]);
    /// The whole scene's grains (held or not).
    fn n_grains(w: &Self::World) -> usize;
    /// What rank 0 writes of a body another rank holds (`OUTPUT_RECORD` numbers).
    const OUTPUT_RECORD: usize;
    fn output_record(w: &Self::World, g: usize, out: &mut Vec<f64>);
    /// During a step (a distributed repartition): a body's record with V⁻ for its
    /// velocity, then V_free (`STEP_RECORD` numbers), and back (M̂⁻¹ refreshed as
    /// the free velocity stage does; returns V_free).
    const STEP_RECORD: usize;
    fn step_record(w: &Self::World, g: usize, v_free: &Self::V, out: &mut Vec<f64>);
    fn set_step_record(w: &mut Self::World, g: usize, x: &[f64]) -> Self::V;
    /// Contact a's warm-start record: key (3), r, point, bond (1).
    fn prev_record(c: &Self::Contacts, a: usize, out: &mut Vec<f64>);
    const PREV_RECORD: usize;
    fn set_extra_prev(w: &mut Self::World, records: &[f64]);
    /// Detects again in `region`, keeps the raw contacts `keep` accepts and builds
    /// them with the same warm starts as the step's first build and those of
    /// `more_prev` ([`Family::prev_record`]s; one already held is not repeated),
    /// the velocities back at `v_free` (by slot; a distributed repartition: the
    /// contacts move to their new ranks).
    fn redetect(
        w: &mut Self::World,
        region: crate::detect::Region,
        keep: &mut dyn FnMut(ContactKey, [f64; 3]) -> bool,
        v_free_more_prev: (&[Self::V], &[f64]),
    );
    fn solver(w: &Self::World) -> &crate::solver::SolverSettings;
    /// One step of the world with NSCDD as its contact stage.
    fn step_with(w: &mut Self::World, stage: &mut super::Stage<'_, '_, Self>) -> Result<StepReport, Diverged>;
}

/// The NSCDD family of the rigid bodies of dimension D: every operation is the
/// dimension's ([`Dim`]) or the generic contact set's and NLGS's.
#[derive(Clone, Copy, Debug, Default)]
pub struct Rigid<D: Dim>(std::marker::PhantomData<D>);

/// 2D rigid bodies ([`crate::world::World2`]).
pub type Rigid2 = Rigid<D2>;
/// 3D rigid bodies ([`crate::world::World3`]).
pub type Rigid3 = Rigid<D3>;

impl<D: Dim> Family for Rigid<D> {
    type V = D::Twist;
    type InvMass = D::InvMass;
    type Contacts = Contacts<D>;
    type World = World<D>;
    const SPACE: usize = D::N;

    fn len(c: &Self::Contacts) -> usize {
        c.len()
    }
    fn reserve(c: &mut Self::Contacts, n: usize) {
        c.reserve(n);
    }
    fn push_contact(dst: &mut Self::Contacts, src: &Self::Contacts, a: usize, li: u32, lj: u32) {
        dst.push_from(src, a, li, lj);
    }
    fn bodies(c: &Self::Contacts, a: usize) -> [u32; 2] {
        c.bodies[a]
    }
    fn key(c: &Self::Contacts, a: usize) -> ContactKey {
        c.key[a]
    }
    fn point(c: &Self::Contacts, a: usize) -> [f64; 3] {
        c.point3(a)
    }
    fn copy_r(dst: &mut Self::Contacts, ga: usize, src: &Self::Contacts, la: usize) {
        dst.r[ga] = src.r[la];
    }
    fn r(c: &Self::Contacts, a: usize) -> &[f64] {
        c.r[a].as_ref()
    }
    fn r_mut(c: &mut Self::Contacts, a: usize) -> &mut [f64] {
        c.r[a].as_mut()
    }
    fn copy_delassus(c: &mut Self::Contacts, inv: &[Self::InvMass], split: &[bool]) {
        c.refresh_delassus_of(inv, |[i, j]| split[i as usize] || split[j as usize]);
    }
    fn warm_start(c: &Self::Contacts, vel: &mut [Self::V], inv: &[Self::InvMass]) {
        c.apply_all(vel, inv);
    }
    /// A sweep, then with `sums` LMGC90's non-updating check pass (as the
    /// one-domain NLGS: one subdomain is the plain engine, bitwise).
    fn sweep(c: &mut Self::Contacts, vel: &mut [Self::V], inv: &[Self::InvMass], order: &[u32], omega: f64, sums: Option<&mut Sums>) {
        nlgs::sweep(c, vel, inv, order, omega, None);
        if let Some(s) = sums {
            nlgs::check_pass(c, vel, inv, order, s);
        }
    }
    fn mu(c: &Self::Contacts, a: usize) -> f64 {
        c.target[a].mu
    }
    fn set_r(c: &mut Self::Contacts, a: usize, r: &[f64], vel: &mut [Self::V], inv: &[Self::InvMass]) {
        c.set_r(a, r, vel, inv);
    }
    fn scale_inv(im: Self::InvMass, m: f64) -> Self::InvMass {
        D::scale_inv(&im, m)
    }
    fn apply_impulse(v: &mut Self::V, im: &Self::InvMass, f: &Self::V) {
        D::apply_inv(v, im, f);
    }
    fn glue(v: &mut Self::V, f: &mut Self::V, im: &Self::InvMass, dv: &Self::V) {
        D::glue(v, f, im, dv);
    }
    fn n_bodies(w: &Self::World) -> usize {
        w.ids.n_global(w.bodies.len())
    }
    fn global(w: &Self::World, k: usize) -> usize {
        w.ids.global(k as u32) as usize
    }
    fn slot(w: &Self::World, g: usize) -> Option<usize> {
        w.ids.slot(g as u32).map(|k| k as usize)
    }
    /// (static: known of a body the world does not hold)
    fn movable(w: &Self::World, g: usize) -> bool {
        w.movable_rho2(g as u32).0
    }
    fn inv_mass(w: &Self::World, g: usize) -> Self::InvMass {
        w.bodies.inv_mass[slot(w, g)]
    }
    fn rho2(w: &Self::World, g: usize) -> f64 {
        w.movable_rho2(g as u32).1
    }
    fn contacts(w: &Self::World) -> &Self::Contacts {
        &w.contacts
    }
    fn contacts_mut(w: &mut Self::World) -> &mut Self::Contacts {
        &mut w.contacts
    }
    fn velocities(w: &Self::World, out: &mut Vec<Self::V>) {
        out.clear();
        out.extend_from_slice(&w.bodies.vel);
    }
    fn swap_velocities(w: &mut Self::World, v: &mut [Self::V]) {
        debug_assert!(v.is_empty() || v.len() == w.bodies.vel.len(), "velocities by slot");
        if v.len() == w.bodies.vel.len() {
            w.bodies.vel.swap_with_slice(v);
        }
    }
    /// (a body the world does not hold is not stepped here: nothing to write)
    fn set_vel(w: &mut Self::World, g: usize, v: Self::V) {
        if let Some(k) = w.ids.slot(g as u32) {
            w.bodies.vel[k as usize] = v;
        }
    }
    fn contact_bodies(w: &Self::World, a: usize) -> [u32; 2] {
        w.contacts.bodies[a].map(|k| w.ids.global(k))
    }
    fn order(w: &Self::World) -> &[u32] {
        &w.scratch.order
    }
    fn step(w: &Self::World) -> u64 {
        w.step
    }
    fn residual(w: &Self::World) -> f64 {
        nlgs::residual(&w.contacts, &w.bodies.vel)
    }
    fn solver(w: &Self::World) -> &crate::solver::SolverSettings {
        &w.solver
    }
    fn residual_parts(w: &Self::World) -> (f64, f64) {
        nlgs::residual_parts(&w.contacts, &w.bodies.vel)
    }
    fn residual_parts_in(w: &Self::World, which: &[u32]) -> (f64, f64) {
        nlgs::residual_parts_of(&w.contacts, &w.bodies.vel, which.iter().map(|&a| a as usize))
    }
    fn add_reactions(c: &Self::Contacts, out: &mut [Self::V]) {
        crate::step::add_reactions(c, out);
    }
    fn set_reactions(w: &mut Self::World, r: Vec<Self::V>) {
        w.reaction = r;
    }
    fn observed(w: &Self::World) -> Vec<u32> {
        w.observed().into_iter().map(|k| w.ids.global(k)).collect()
    }
    fn is_grain(w: &Self::World, g: usize) -> bool {
        w.ids.slot(g as u32).is_some_and(|k| w.is_grain(k as usize))
    }
    fn wants_coordination(w: &Self::World) -> bool {
        w.box_walls.is_some()
    }
    fn bulk_box(w: &Self::World) -> Option<([f64; 3], [f64; 3])> {
        let w3 = (w as &dyn std::any::Any).downcast_ref::<crate::world::World3>()?;
        w3.bulk_box(4.0 * w3.max_grain_size())
    }
    fn body_energies(w: &Self::World, g: usize) -> Option<(f64, f64)> {
        w.body_energies(slot(w, g))
    }
    fn grain_in_box(w: &Self::World, g: usize, lo: [f64; 3], hi: [f64; 3]) -> f64 {
        (w as &dyn std::any::Any)
            .downcast_ref::<crate::world::World3>()
            .map_or(0.0, |w3| w3.grain_in_box(slot(w, g), lo, hi))
    }
    fn position(w: &Self::World, g: usize) -> [f64; 3] {
        let mut p = [0.0; 3];
        p[..D::N].copy_from_slice(w.bodies.pos[slot(w, g)].as_ref());
        p
    }
    /// (the region's pairs, in global ids, go to the detector in slots)
    fn set_region(w: &mut Self::World, region: Option<crate::detect::Region>) {
        w.scratch.region = region.map(|r| in_slots(&w.ids, r));
    }
    fn alert(w: &Self::World) -> f64 {
        w.alert
    }
    fn retain_contacts(w: &mut Self::World, keep: &mut dyn FnMut(usize) -> bool) {
        w.contacts.retain(keep);
    }
    fn retain_raw(w: &mut Self::World, keep: &mut dyn FnMut(ContactKey, [f64; 3]) -> bool) {
        let ids = &w.ids;
        w.scratch.raw.retain(|rc| {
            let mut p = [0.0; 3];
            p[..D::N].copy_from_slice(rc.point.as_ref());
            keep(
                ContactKey {
                    i: ids.global(rc.i),
                    j: ids.global(rc.j),
                    feature: rc.feature,
                },
                p,
            )
        });
    }
    /// (by slot; only the active bodies' boxes are recomputed)
    fn body_boxes(w: &Self::World, out: &mut Vec<[[f64; 3]; 2]>) {
        let b = &w.bodies;
        out.resize(b.len(), [[0.0; 3]; 2]);
        crate::step::each_body(b.len(), w.scratch.active.as_deref(), |k| {
            let s = b.shape[k];
            out[k] = w.shapes[s.kind as usize].aabb(s.index, b.pos[k], b.rot[k]).corners3();
        });
    }
    fn set_active(w: &mut Self::World, active: Option<Vec<u32>>) {
        let s = &mut w.scratch;
        if w.ids.is_identity() {
            s.active = active;
        } else {
            let ids = &w.ids;
            let slots = active.as_ref().map(|a| a.iter().map(|&g| ids.slot(g).expect(HELD)).collect());
            (s.active, s.active_global) = (slots, active);
        }
    }
    fn active(w: &Self::World) -> Option<&[u32]> {
        match w.ids.is_identity() {
            true => w.scratch.active.as_deref(),
            false => w.scratch.active_global.as_deref(),
        }
    }
    fn held(w: &Self::World) -> Option<&[u32]> {
        w.ids.held()
    }
    fn everywhere(w: &Self::World, g: usize) -> bool {
        let Some(k) = w.ids.slot(g as u32).map(|k| k as usize) else {
            return false;
        };
        !w.bodies.movable(k) || w.drives.iter().any(|d| d.body as usize == k) || !w.aabb(k).is_bounded()
    }
    const BODY_RECORD: usize = World::<D>::BODY_RECORD;
    fn body_record(w: &Self::World, g: usize, out: &mut Vec<f64>) {
        w.body_record(slot(w, g), out);
    }
    fn set_body_record(w: &mut Self::World, g: usize, x: &[f64]) {
        w.set_moving(slot(w, g), x);
    }
    fn admit(w: &mut Self::World, entering: &[(u32, &[f64])]) {
        w.admit(entering);
    }
    const OUTPUT_RECORD: usize = World::<D>::OUTPUT_RECORD;
    fn output_record(w: &Self::World, g: usize, out: &mut Vec<f64>) {
        w.output_record(slot(w, g), out);
    }
    fn hold(w: &mut Self::World, keep: &[u32]) {
        w.hold(keep);
    }
    fn n_grains(w: &Self::World) -> usize {
        w.grain_sums().0
    }
    const STEP_RECORD: usize = Self::BODY_RECORD + D::DOF;
    /// (the body's record with V⁻ for its velocity, then V_free)
    fn step_record(w: &Self::World, g: usize, v_free: &Self::V, out: &mut Vec<f64>) {
        let (k, at) = (slot(w, g), out.len() + World::<D>::MOVING_RECORD - D::DOF);
        w.body_record(k, out);
        out[at..at + D::DOF].copy_from_slice(w.scratch.v_begin[k].as_ref());
        out.extend_from_slice(v_free.as_ref());
    }
    fn set_step_record(w: &mut Self::World, g: usize, x: &[f64]) -> Self::V {
        Self::set_body_record(w, g, &x[..Self::BODY_RECORD]);
        let g = slot(w, g);
        let (n, dof) = (Self::BODY_RECORD, D::DOF);
        w.scratch.v_begin[g] = w.bodies.vel[g];
        w.bodies.vel[g].as_mut().copy_from_slice(&x[n..n + dof]);
        // as the free velocity stage does (an isotropic body's M̂⁻¹ never changes)
        if w.bodies.free[g] != 0 && !D::isotropic(&w.bodies.inertia[g]) {
            w.bodies.refresh_inverse(g);
        }
        w.bodies.vel[g]
    }
    const PREV_RECORD: usize = 4 + 2 * D::N;
    fn prev_record(c: &Self::Contacts, a: usize, out: &mut Vec<f64>) {
        let k = c.key[a];
        out.extend([f64::from(k.i), f64::from(k.j), f64::from(k.feature)]);
        out.extend_from_slice(c.r[a].as_ref());
        out.extend_from_slice(c.point[a].as_ref());
        out.push(c.joint[a].bonded() as u8 as f64);
    }
    fn redetect(
        w: &mut Self::World,
        region: crate::detect::Region,
        keep: &mut dyn FnMut(ContactKey, [f64; 3]) -> bool,
        (v_free, more_prev): (&[Self::V], &[f64]),
    ) {
        w.bodies.vel.copy_from_slice(v_free);
        let s = &mut w.scratch;
        if !more_prev.is_empty() {
            s.prev_keys.extend(prev_contacts::<D>(more_prev));
            s.prev_keys.sort_unstable_by_key(|x| x.key);
            // a contact both exchanges brought: the same record twice
            s.prev_keys.dedup_by(|a, b| a.key == b.key && a.point == b.point);
        }
        s.detector.detect_among(
            (&w.bodies, s.active.as_deref()),
            &w.shapes,
            &w.detectors,
            w.alert,
            Some(&in_slots(&w.ids, region)),
            &mut s.raw,
        );
        Self::retain_raw(w, keep);
        crate::engine::build_from_raw(w);
    }
    fn set_extra_prev(w: &mut Self::World, records: &[f64]) {
        w.scratch.extra_prev.clear();
        w.scratch.extra_prev.extend(prev_contacts::<D>(records));
    }
    fn step_with(w: &mut Self::World, stage: &mut super::Stage<'_, '_, Self>) -> Result<StepReport, Diverged> {
        w.step_with(stage)
    }
}

/// What NSCDD asks of a world body it holds.
const HELD: &str = "NSCDD asks only for the bodies the world holds";

/// The slot of body `g` (a global id) in `w`.
#[inline]
fn slot<D: Dim>(w: &World<D>, g: usize) -> usize {
    w.ids.slot(g as u32).expect(HELD) as usize
}

/// `r` with its pairs of global ids as pairs of slots (the detector's ids; a pair
/// with a body the world does not hold cannot be detected and is left out).
fn in_slots(ids: &crate::model::BodyIds, mut r: crate::detect::Region) -> crate::detect::Region {
    if !ids.is_identity() {
        r.pairs = r.pairs.iter().filter_map(|&[i, j]| Some([ids.slot(i)?, ids.slot(j)?])).collect();
    }
    r
}

/// The warm starts of [`Family::prev_record`]s.
fn prev_contacts<D: Dim>(records: &[f64]) -> impl Iterator<Item = crate::world::PrevContact<D>> + '_ {
    let n = D::N;
    records.chunks_exact(4 + 2 * n).map(move |x| crate::world::PrevContact {
        key: ContactKey {
            i: x[0] as u32,
            j: x[1] as u32,
            feature: x[2] as u32,
        },
        r: D::Local::from_fn(|k| x[3 + k]),
        point: D::Point::from_fn(|k| x[3 + n + k]),
        bonded: x[3 + 2 * n] != 0.0,
    })
}

pub use crate::dim::d3::InvMass3;
