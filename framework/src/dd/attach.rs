//! The subdomain interface of a body family attached to the world's rigid bodies
//! (DESIGN.md §3, "model coupling"): finite-element bodies today, continuum regions
//! and researchers' families next. The NSCDD coordinator ([`super::NscddOf`]:
//! partition, gluing schemes, thread team) is written against these two traits and
//! names no family.
//!
//! A family ([`Attached`]) owns its bodies and, each step, its contacts (with one
//! another and with the world's rigid bodies). NSCDD gives each of its contacts a
//! subdomain (by geometry, and by model with `by_model = true`: the family's
//! contacts in subdomains of their own), and the family splits them into one
//! [`LocalPart`] per subdomain: the local problem of E restricted to the family's
//! contacts. A part works on
//!
//! - the subdomain's copies of the world's rigid bodies (V_E and M̂_E⁻¹ = m M̂⁻¹, the
//!   slices the coordinator passes to every call: rigid contacts and every family's
//!   contacts of E see the same copies), and
//! - its own copies of the family's *entities* (for a deformable body: its contact
//!   nodes; each entity copy in E has M̂_E = M̂/m, m the number of subdomains holding
//!   a copy, so that Σ_E M̂_E = M̂).
//!
//! An entity held by m ≥ 2 subdomains is an interface entity: A_ΓE picks its
//! [`EntityInfo::dofs`] values from the copy ([`LocalPart::entity_velocity`],
//! A_ΓE V_E), and the one gluing code ([`super::gluing`]) solves its chain,
//! ΔV_k = y_k − y_{k−1} with y = L⁻¹ [V], which the part applies as
//! V_E += M̂_E⁻¹ A_ΓEᵀ ΔF_Γ = ΔV_k on the entity ([`LocalPart::glue_entity`]).
//! Copies of equal M̂_E go to their mean, so the family never forms M̂_E itself: its
//! F_Γ is implied (Σ_k ΔF_Γ,k = M̂_E Σ_k ΔV_k = 0); the end-of-step velocity
//! V⁺ = V_free + M̂⁻¹ Σ_E H_E r_E is the family's ([`Attached::write_back`]).
//!
//! *Warm start of F_Γ.* Every interface entity is glued once before the first sweep
//! of a step (it is `fresh`): its copies start at their mean, V_free + M̂⁻¹ Σ_E H_E r_E
//! with the warm-start impulses, i.e. with F_Γ,E = (1/m) Σ_E' H_E' r_E' − H_E r_E. A
//! kept F_Γ (the rigid copies' [`super::FGammaStore`]) starts the copies at
//! V_free + M̂_E⁻¹ (F_Γ,E + H_E r_E), the same point up to the last step's gluing
//! residual when the contacts persist: with copies of equal M̂_E the two are the same
//! warm start, and the glued one also holds when contacts appear, vanish or change
//! subdomain. Keeping a deformable copy's F_Γ itself would need a solve with its
//! block G per copy and step (F_Γ = (m G)⁻¹ A_ΓE (V_E − V_free) − H_E r_E, on a node
//! set that changes every step) for no gain; measured in docs/PERFORMANCE.md.
//!
//! Calls are per step, per subdomain and sweep, never per contact: a part's
//! [`LocalPart::sweep`] visits all its contacts in the family's own code.

use super::family::Family;
pub use super::rank_solved::{Rounds, SolvedOn};
use super::subdomain::SubdomainSolver;
use crate::norms::Sums;
use std::any::Any;

/// The gluing norm of an interface entity: |V|² = w (Σ_{i<space} v_i² + ρ² Σ_{i≥space} v_i²),
/// in (m/s)² (a rigid body: space = 2 or 3, ρ² = I/m, w = 1; n deformable nodes:
/// space = dofs, ρ² = 0, w = 1/n, the mean over the nodes).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EntityInfo {
    /// Values of one copy (A_ΓE's rows).
    pub dofs: u32,
    /// The first `space` values are translational velocities.
    pub space: u32,
    pub rho2: f64,
    pub weight: f64,
}

/// One family's part of one subdomain (module docs). `vel`/`inv`: the subdomain's
/// copies of the world's rigid bodies, by local id.
pub trait LocalPart<F: Family>: Any + Send {
    /// Contacts of the part.
    fn len(&self) -> usize;
    fn is_empty(&self) -> bool {
        self.len() == 0
    }
    /// The family's ids of its entity copies, by local entity index.
    fn entities(&self) -> &[u32];
    /// Builds what depends on the multiplicities: the entity copies' M̂_E = M̂/m
    /// (`mult` per local entity), W_αα of its contacts from them and the rigid copies'
    /// `inv`, the entity copies' free velocities.
    fn prepare(&mut self, inv: &[F::InvMass], mult: &[u32]);
    /// Warm start: V_E += M̂_E⁻¹ H_E r for its contacts, on both sides (after the
    /// rigid contacts' warm start, in the family's storage order).
    fn warm_start(&mut self, vel: &mut [F::V], inv: &[F::InvMass]);
    /// One NLGS sweep over its contacts; a check pass adds to `sums`.
    fn sweep(&mut self, vel: &mut [F::V], inv: &[F::InvMass], omega: f64, sums: Option<&mut Sums>);
    /// A_ΓE V_E of local entity `e`, appended to `out`.
    fn entity_velocity(&self, e: usize, out: &mut Vec<f64>);
    /// The gluing increment of local entity `e`: its copy moves by `dv`.
    fn glue_entity(&mut self, e: usize, dv: &[f64]);
    /// The part's results after the iteration as numbers (its contacts' impulses, and
    /// whatever else its family's [`Attached::write_back`] reads), appended to `out`:
    /// on several MPI ranks, the rank that solved the subdomain sends them to the
    /// others, which [`Self::unpack`] them into their own (unsolved) copy of the part.
    fn pack(&self, out: &mut Vec<f64>);
    /// The number of values [`Self::pack`] appends.
    fn packed_len(&self) -> usize;
    /// Puts results [`Self::pack`]ed by another rank's copy of the part back.
    fn unpack(&mut self, values: &[f64]);
    fn as_any(&self) -> &dyn Any;
}

/// The cells of this rank's subdomains of a family on a step that keeps the last
/// grid ([`Attached::after_free_velocity_own`]).
pub struct OwnCells<'a> {
    /// Their boxes `[lo, hi]` (z = 0 in 2D; the grid's edge cells unbounded,
    /// closed: a point on a shared face may be another rank's), for skipping what
    /// meets none of them.
    pub boxes: &'a [[[f64; 3]; 2]],
    /// Whether the point p (z = 0 in 2D) lies in one of them: the exact test,
    /// [`Attached::keep_own`]'s.
    pub of: &'a dyn Fn([f64; 3]) -> bool,
}

impl OwnCells<'_> {
    /// Whether the box `[lo, hi]` (first `n` coordinates) meets one of the boxes.
    pub fn meets(&self, n: usize, lo: &[f64], hi: &[f64]) -> bool {
        crate::detect::boxes_meet(self.boxes, n, lo, hi)
    }
}

/// `f(n, lo, hi, g)`: `g` called with the rank of every cell whose box meets
/// `[lo, hi]` ([`RankCells::meeting`]).
pub type Meeting<'m> = dyn Fn(usize, &[f64], &[f64], &mut dyn FnMut(u32)) + 'm;

/// Which families are stepped in part this step, and every rank's cells of the
/// next detection of those detecting in each rank's cells.
pub(super) type SteppedOn<'a> = (&'a [bool], &'a [Option<super::cells::CellIndex>]);

/// Every rank's cells of a family's subdomains in a step's grid (edge cells
/// unbounded, each grown by 10⁻⁶ of a cell, as [`OwnCells`]' boxes): which ranks
/// detect where ([`Attached::share_stepped`], [`Attached::new_cells`]).
pub struct RankCells<'a> {
    /// `meeting(n, lo, hi, f)` calls `f` with the rank of every cell whose box
    /// meets `[lo, hi]` (first `n` coordinates; a rank once per cell, so maybe
    /// several times).
    pub meeting: &'a Meeting<'a>,
    /// This rank and the number of ranks.
    pub rank: u32,
    pub ranks: u32,
}

impl RankCells<'_> {
    /// [`Self::meeting`].
    pub fn ranks_meeting(&self, n: usize, lo: &[f64], hi: &[f64], mut f: impl FnMut(u32)) {
        (self.meeting)(n, lo, hi, &mut f);
    }
}

/// Runs `f` with the [`RankCells`] of `index` (this rank `rank` of `ranks`).
pub(super) fn with_cells<R>(index: &super::cells::CellIndex, (rank, ranks): (u32, u32), f: impl FnOnce(&RankCells<'_>) -> R) -> R {
    let meeting = |n: usize, lo: &[f64], hi: &[f64], g: &mut dyn FnMut(u32)| index.ranks_meeting(n, lo, hi, g);
    f(&RankCells {
        meeting: &meeting,
        rank,
        ranks,
    })
}

/// A body family beside the world's rigid bodies, solved by the NSCDD stage (module
/// docs). The step calls, in order: [`Self::after_free_velocity`], [`Self::build`],
/// [`Self::points`], [`Self::split`] (then the parts' `prepare` and `warm_start`),
/// sweeps and gluings, [`Self::write_back`], [`Self::residual_parts`].
pub trait Attached<F: Family> {
    /// After the world's free velocity: the family's own V_free (and detection).
    fn after_free_velocity(&mut self, w: &F::World);
    /// The step's contacts (frames, targets ū, μ, warm-start impulses).
    fn build(&mut self, w: &mut F::World);
    /// Contact points of its contacts (z = 0 in 2D), appended to `out`: the
    /// partition's input.
    fn points(&self, out: &mut Vec<[f64; 3]>);
    /// Entities of the family (their ids are 0..n).
    fn n_entities(&self) -> usize;
    fn entity(&self, e: u32) -> EntityInfo;
    /// One part per subdomain owning some of its contacts (`owner[a]`, one per
    /// contact of [`Self::points`]), as (subdomain, part) in ascending subdomain order.
    /// `copy(sub, body)` gives the local id of the subdomain's copy of world body
    /// `body`, making it on first call.
    fn split(&self, w: &F::World, owner: &[u32], copy: &mut dyn FnMut(u32, u32) -> u32) -> Vec<(u32, Box<dyn LocalPart<F>>)>;
    /// After the iteration (the copies glued): the contacts' impulses from the parts
    /// `(subdomain, part)`, and the family's V⁺.
    fn write_back(&mut self, w: &mut F::World, parts: &[(u32, &dyn LocalPart<F>)]);
    /// (‖F(r)‖², ‖q‖²) of its contacts for the natural-map residual, from the written-back
    /// state and the world's velocities.
    fn residual_parts(&self, w: &F::World) -> (f64, f64);
    /// [`Self::residual_parts`] of the contacts `contacts` ([`Self::points`] order,
    /// ascending: those of one subdomain), after the step's results are shared
    /// ([`Self::share_stepped`]). A family that gives them has its sums taken per
    /// subdomain, by the rank solving it, and added in subdomain order with the
    /// rigid contacts' of the subdomain (so on ranks only a subdomain's rank reads
    /// its contacts' results). `None` (the default): its sums are taken whole, after
    /// the subdomains'.
    fn residual_parts_in(&self, _w: &F::World, _contacts: &[u32]) -> Option<(f64, f64)> {
        None
    }
    /// On MPI ranks with bodies held per rank ([`super::local`], [`super::owned`]):
    /// world bodies the family reads or its contacts touch, for the whole run
    /// (ascending global ids; those it may touch as it moves come from
    /// [`Self::reach`]), which every rank then holds and steps as it does a
    /// fixed or driven body (bitwise the same state wherever it is held), so that
    /// the family, held whole on every rank, builds the same contacts everywhere
    /// (a family detecting in each rank's cells, [`Self::after_free_velocity_own`],
    /// needs only the rank's halo).
    /// It reads a world body through its slot ([`Family::held_slot`]). `None` (the
    /// default): the family may touch any world body, and its scenes run on ranks
    /// with every body and contact held on every rank.
    fn held_everywhere(&self) -> Option<Vec<u32>> {
        None
    }
    /// With bodies held per rank, besides [`Self::held_everywhere`] (which must then
    /// be `Some`, maybe empty): boxes `[lo, hi]` (z = 0 in 2D) holding every point at
    /// which the family's next detection may touch a world body, appended to `out`.
    /// Every world body whose box, grown by the alert distance, meets one of them is
    /// held and stepped by every rank for the next step, as [`Self::held_everywhere`]'s
    /// are. Called when the mode is decided (before the first step, also in one
    /// process) and after each step's [`Self::write_back`] of a step held per rank
    /// (the family's positions not yet updated: the boxes must cover that update),
    /// the same boxes on every rank; not after a step in which the family detected
    /// in the rank's cells ([`Self::after_free_velocity_own`]): its rigid
    /// antagonists are then in the rank's halo. The default: none.
    fn reach(&self, _w: &F::World, _out: &mut Vec<[[f64; 3]; 2]>) {}
    /// Each step of the NSCDD stage, after the partition and before [`Self::split`]:
    /// where its contacts ([`Self::points`] order) are solved ([`SolvedOn`]; `None`
    /// in one process, where all are solved). A family may leave to this call the
    /// numbers only a solved contact needs (its bodies' free velocities, W_αα,
    /// u_free): its contact list and points must not depend on them. A family that
    /// then does on this rank only the work of the contacts solved here (and of its
    /// bodies without contact, shared among the ranks) returns true: it exchanges
    /// in this call, through [`SolvedOn::rounds`], what one rank computed for
    /// another's contacts (a deformable body's columns of M̂⁻¹ at its contact nodes,
    /// from the one rank stepping it), and after its [`Self::write_back`] the
    /// results ([`Self::share_stepped`]), before [`Self::residual_parts`]. It still gives
    /// every contact and a part for every subdomain, the same on every rank (their
    /// order and packed results are those of one process); the parts of other
    /// ranks' subdomains are never prepared nor swept here (they may be shells,
    /// receiving only what [`LocalPart::pack`] sends). The default: false (the
    /// family is stepped whole on every rank).
    fn solved_on(&mut self, _w: &F::World, _on: Option<&SolvedOn<'_>>) -> bool {
        false
    }
    /// After [`Self::write_back`] of a step [`Self::solved_on`] returned true for,
    /// on every rank (collective): the family's rounds that finish the step (the
    /// deformable bodies: the impulses of a body's contacts solved elsewhere to the
    /// rank stepping it, its V⁺ computed there and sent at its boundary to the
    /// ranks that read it), after which what the family's residual and position
    /// update read on each rank is what one process reads there. `next`: every rank's cells in which the family's next
    /// detection runs when it detects in each rank's cells
    /// ([`Self::after_free_velocity_own`], this step's grid, decentralized scheme),
    /// so that a rank needs only what reaches its cells; `None`: the next detection
    /// may read the family whole on every rank.
    fn share_stepped(&mut self, _rounds: &dyn Rounds, _next: Option<&RankCells<'_>>) {}
    /// On a repartition step, for a family that detected in this rank's cells of
    /// the last grid ([`Self::after_free_velocity_own`]), before it detects again
    /// in the new ones (collective): every rank's new cells, so that what a rank
    /// now needs there of the family and lacks is sent to it. The default: nothing.
    fn new_cells(&mut self, _cells: &RankCells<'_>, _rounds: &dyn Rounds) {}
    /// On MPI ranks, before the outputs read the family's state (an output frame, a
    /// saved state): what rank 0 lacks of it, sent there (collective: every rank
    /// calls it; a family stepped in part may hold on a rank only what its next
    /// steps read of the bodies it does not step). The default: nothing (the state
    /// is the same on every rank).
    fn gather_whole(&mut self, _rounds: &dyn Rounds) {}
    /// With `output.vtk` on MPI ranks: whether every rank writes the family's
    /// frame files of what it holds whole (its `write_frame` called on every rank,
    /// without [`Self::gather_whole`] before it; rank 0 alone writes the series).
    /// The default: false (rank 0 writes the frames, after the gather).
    fn frames_per_rank(&self) -> bool {
        false
    }
    /// On MPI ranks with contacts held per rank ([`super::local`]), each step after
    /// [`Self::build`] and [`Self::points`] (and after a repartition's new grid):
    /// `own(p)` says whether a contact point p lies in a cell of this rank's
    /// subdomains of the family (edge cells unbounded), whose contacts this rank
    /// solves. A family that then keeps only those contacts (its list, points,
    /// [`Self::solved_on`] and [`Self::split`] cover them only, as a rank's rigid
    /// contacts) returns true, and the framework reads its points again. Its
    /// contacts' subdomains are the cells of their points, so no other rank
    /// needs them. The default: false (every contact kept on every rank).
    fn keep_own(&mut self, _own: &dyn Fn([f64; 3]) -> bool) -> bool {
        false
    }
    /// On MPI ranks with contacts held per rank, in place of
    /// [`Self::after_free_velocity`]: the same, with detection limited to the
    /// contacts whose point ([`Self::points`]) lies in this rank's cells of the
    /// last grid ([`OwnCells`]). A family that does so returns true: it must find
    /// exactly the contacts of its whole detection that [`Self::keep_own`] would
    /// keep, in the same order. On a repartition step the framework merges every
    /// rank's points into the new grid, then calls it again with the new grid's
    /// cells, after [`Self::build`] and [`Self::points`] (so it must be repeatable,
    /// and leave the family as its build would: detection again, in other cells,
    /// the world's velocities back at V_free for it), and the second call's
    /// contacts are the step's; with the decentralized scheme only; on other
    /// steps [`Self::keep_own`] is not called. The default: false, and [`Self::after_free_velocity`] is called
    /// (whole detection, the same on every rank, then [`Self::keep_own`]).
    fn after_free_velocity_own(&mut self, _w: &F::World, _own: &OwnCells<'_>) -> bool {
        false
    }
    /// (its bodies stepped here, its bodies) in a step stepped in part (`ranks.json`).
    fn stepped_bodies(&self) -> Option<(usize, usize)> {
        None
    }
    /// In a step stepped in part: its bodies whose data only a rank stepping them
    /// needs (a deformable body's M, K and factors) this rank holds (`ranks.json`).
    fn built_bodies(&self) -> Option<usize> {
        None
    }
    /// After [`Self::share_stepped`]: its bodies whose state this rank holds
    /// current for its next detection (`ranks.json`; `None`: every body).
    fn near_bodies(&self) -> Option<usize> {
        None
    }
}

/// The world bodies that `fams` read or touch ([`Attached::held_everywhere`]),
/// ascending and once each; `None` if a family may touch any world body.
pub fn held_everywhere<F: Family>(fams: &[&dyn Attached<F>]) -> Option<Vec<u32>> {
    let mut all = Vec::new();
    for f in fams {
        all.extend(f.held_everywhere()?);
    }
    all.sort_unstable();
    all.dedup();
    Some(all)
}

/// The world bodies attached families touch on MPI ranks with bodies held per rank:
/// those every rank holds and steps ([`Attached::held_everywhere`]).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Touched {
    /// Named bodies (ascending, once each).
    pub ids: Vec<u32>,
    /// The families' [`Attached::reach`] boxes: the bodies near them.
    pub reach: Vec<[[f64; 3]; 2]>,
    /// The number of families (their subdomains by model).
    pub families: usize,
}

/// What `fams` touch ([`Touched`]); `None` if a family may touch any world body.
pub fn touched<F: Family>(w: &F::World, fams: &[&dyn Attached<F>]) -> Option<Touched> {
    let ids = held_everywhere(fams)?;
    let mut reach = Vec::new();
    reach_of(w, fams, &mut reach);
    Some(Touched {
        ids,
        reach,
        families: fams.len(),
    })
}

/// The boxes of `fams`' [`Attached::reach`], into `out` (cleared first).
pub fn reach_of<F: Family>(w: &F::World, fams: &[&dyn Attached<F>], out: &mut Vec<[[f64; 3]; 2]>) {
    out.clear();
    for f in fams {
        f.reach(w, out);
    }
}

/// The parts of one subdomain, with the family index of each.
#[derive(Default)]
pub struct Parts<F: Family>(pub Vec<(u32, Box<dyn LocalPart<F>>)>);

impl<F: Family> std::fmt::Debug for Parts<F> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let n: Vec<(u32, usize)> = self.0.iter().map(|(k, p)| (*k, p.len())).collect();
        write!(f, "Parts(family, contacts) {n:?}")
    }
}

/// The attached families' results from the subdomains' parts into `w`; returns the
/// natural-map residual of the whole contact problem (rigid and families'), its sums
/// taken per subdomain (the rigid contacts' and each family's of the subdomain, for
/// families giving them: [`Attached::residual_parts_in`]) and added in subdomain
/// order, then the other families' whole. `owner`: each family's contacts'
/// subdomains.
pub(super) fn write_back_families<D: Family>(
    d: &super::partition::Decomposition<D>,
    w: &mut D::World,
    (fams, stepped, owner): (&mut [&mut dyn Attached<D>], SteppedOn<'_>, &[Vec<u32>]),
    mut ranks: Option<&mut super::ranks::RankState>,
) -> f64 {
    for (f, fam) in fams.iter_mut().enumerate() {
        let parts: Vec<(u32, &dyn LocalPart<D>)> = d
            .subs
            .iter()
            .flat_map(|s| s.parts.0.iter().filter(|p| p.0 == f as u32).map(|p| (s.id, &*p.1)))
            .collect();
        fam.write_back(w, &parts);
    }
    super::rank_solved::share_stepped(fams, stepped, ranks.as_deref_mut());
    // each family's contacts by subdomain (ascending), whether it gives its sums per
    // subdomain (the same answer for every call: a property of the family)
    let by_sub: Vec<Vec<(u32, u32)>> = owner.iter().map(|o| by_subdomain(o)).collect();
    let per_sub_fam: Vec<bool> = fams.iter().map(|f| f.residual_parts_in(w, &[]).is_some()).collect();
    // each subdomain's sums, by the rank that holds it, added in subdomain order
    let sums = |s: usize, out: &mut Vec<f64>| {
        let (mut a, mut b) = D::residual_parts_in(w, &d.subs[s].contact_global);
        for (f, fam) in fams.iter().enumerate().filter(|(f, _)| per_sub_fam[*f]) {
            let list = &by_sub[f];
            let lo = list.partition_point(|x| x.0 < s as u32);
            let hi = list.partition_point(|x| x.0 <= s as u32);
            let contacts: Vec<u32> = list[lo..hi].iter().map(|x| x.1).collect();
            let (fa, fb) = fam.residual_parts_in(w, &contacts).unwrap_or_default();
            (a, b) = (a + fa, b + fb);
        }
        out.extend([a, b]);
    };
    let ns = d.subs.len();
    let per_sub = super::rank_reduce::per_subdomain(ranks, ns, 2, sums);
    let (mut f2, mut q2) = (0.0, 0.0);
    for x in per_sub.chunks_exact(2) {
        (f2, q2) = (f2 + x[0], q2 + x[1]);
    }
    for (fam, _) in fams.iter().zip(&per_sub_fam).filter(|x| !*x.1) {
        let (a, b) = fam.residual_parts(w);
        (f2, q2) = (f2 + a, q2 + b);
    }
    crate::solver::nlgs::residual_of(f2, q2)
}

/// (subdomain, contact) of the contacts of `owner` (each contact's subdomain),
/// ascending.
fn by_subdomain(owner: &[u32]) -> Vec<(u32, u32)> {
    let mut v: Vec<(u32, u32)> = owner.iter().enumerate().map(|(a, &s)| (s, a as u32)).collect();
    v.sort_unstable();
    v
}

/// Global impulses and velocities from the subdomains: a body with one copy takes
/// its velocity, an interface body the average of its copies (chain order); an
/// immovable body copied several times takes its copies' velocity (the same in
/// every copy: impulses never move it).
pub fn write_back<D: Family>(d: &super::partition::Decomposition<D>, w: &mut D::World) {
    write_back_held(d, w, None);
}

/// [`write_back`]; with `held` (contacts held per rank, the step's end by
/// requests: the own subdomains and the other ranks' copies received, (subdomain,
/// local body)), only those copies are read (the others' bodies are not stepped
/// here).
pub(super) fn write_back_held<D: Family>(
    d: &super::partition::Decomposition<D>,
    w: &mut D::World,
    held: Option<(&dyn Fn(u32) -> bool, &[(u32, u32)])>,
) {
    let one = |w: &mut D::World, s: &super::Subdomain<D>, l: usize, g: usize| {
        if s.copy_mult[l] == 1 || !D::movable(w, g) {
            D::set_vel(w, g, s.vel[l]);
        }
    };
    for s in d.subs.iter().filter(|s| held.is_none_or(|(own, _)| own(s.id))) {
        let c = D::contacts_mut(w);
        for (la, &ga) in s.contact_global.iter().enumerate() {
            D::copy_r(c, ga as usize, &s.contacts, la);
        }
        for (l, &g) in s.body_global.iter().enumerate() {
            one(w, s, l, g as usize);
        }
    }
    for &(s, l) in held.map_or(&[][..], |(_, got)| got) {
        let s = &d.subs[s as usize];
        one(w, s, l as usize, s.body_global[l as usize] as usize);
    }
    let ifc = &d.iface;
    let mut vc = Vec::new();
    for ib in 0..ifc.n_rigid {
        let r = ifc.copies(ib);
        let m = r.len() as f64;
        let mut v = D::V::default();
        for c in r {
            vc.clear();
            d.subs[ifc.sub[c] as usize].interface_velocity(ifc.slot[c] as usize, &mut vc);
            for (x, y) in v.as_mut().iter_mut().zip(&vc) {
                *x += y;
            }
        }
        for x in v.as_mut() {
            *x /= m;
        }
        D::set_vel(w, ifc.body[ib] as usize, v);
    }
}
