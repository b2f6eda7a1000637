//! NSCDD as the contact-solve stage of the world's step ([`ContactStage`]): with the
//! step's attached families ([`Stage`]), or alone ([`NscddOf`] itself, one process).

use super::{census, reactions, Attached, Family, NscddOf};
use crate::engine::ContactStage;
use crate::solver::SolveReport;

/// NSCDD with the step's attached families, as the contact-solve stage of the
/// world's `step_with`.
pub struct Stage<'a, 'f, D: Family> {
    pub(super) dd: &'a mut NscddOf<D>,
    pub(super) fams: &'a mut [&'f mut dyn Attached<D>],
}

/// NSCDD as the contact-solve stage of the world's `step_with`: it keeps V_free
/// (the families' after theirs), builds the families' contacts and splits all
/// contacts (timed with the Delassus stage), and runs the NSCDD iteration.
impl<D: Family> ContactStage<D::World> for Stage<'_, '_, D> {
    fn before_detection(&mut self, w: &mut D::World) {
        let eligible = self.dd.held_scene(self.fams.is_empty());
        self.dd.before_detection(w, eligible);
    }
    fn after_detection(&mut self, w: &mut D::World) {
        self.dd.after_detection(w);
    }
    fn after_free_velocity(&mut self, w: &D::World) {
        D::velocities(w, &mut self.dd.v_free);
        // (with contacts held per rank a family may detect in this rank's cells
        // only: the last grid's)
        let mut fam_own = std::mem::take(&mut self.dd.fam_own);
        fam_own.clear();
        for (k, f) in self.fams.iter_mut().enumerate() {
            let own = |(boxes, of): (Vec<_>, _)| f.after_free_velocity_own(w, &super::OwnCells { boxes: &boxes, of: &of });
            fam_own.push(self.dd.own_cells(k, None).is_some_and(own));
            if !fam_own[k] {
                f.after_free_velocity(w);
            }
        }
        self.dd.fam_own = fam_own;
    }
    fn prepare(&mut self, w: &mut D::World) {
        for f in self.fams.iter_mut() {
            f.build(w);
        }
        self.dd.family_points(self.fams);
        self.dd.repartition_local(w);
        self.dd.keep_own(w, self.fams);
        let mut rep = std::mem::take(&mut self.dd.pending);
        self.dd.partition(w, self.fams, &mut rep);
        self.dd.pending = rep;
    }
    fn solve(&mut self, w: &mut D::World) -> SolveReport {
        let mut rep = std::mem::take(&mut self.dd.pending);
        NscddOf::solve(self.dd, w, self.fams, &mut rep);
        let s = rep.solve;
        self.dd.pending = rep;
        s
    }
    /// (the world's slots; NSCDD's global ids inside)
    fn after_integrate(&mut self, w: &mut D::World, moved: Result<(), usize>) -> Result<(), usize> {
        let moved = moved.map_err(|k| D::global(w, k));
        if self.dd.local.now && !self.fams.is_empty() {
            // the families' reach for the next step (their positions not yet updated);
            // none of a family detecting in the rank's cells (decentralized only):
            // its rigid antagonists are in the rank's halo, their copies routed to the
            // limited shells as the rigid contacts' are (`RankState::route_family_copies`)
            let own = &self.dd.fam_own;
            let fams: Vec<&dyn Attached<D>> = (self.fams.iter().enumerate())
                .filter(|(k, _)| own.get(*k) != Some(&true))
                .map(|(_, f)| &**f as &dyn Attached<D>)
                .collect();
            let mut reach = Vec::new();
            super::attach::reach_of(w, &fams, &mut reach);
            self.dd.local.owned.set_reach(reach);
        }
        self.dd.after_integrate(w, moved).map_err(|g| D::held_slot(w, g))
    }
    /// The counts outputs read ([`census`]), on the moved bodies (collective).
    fn after_update(&mut self, w: &mut D::World) {
        if self.dd.last.subs.is_empty() || self.dd.pending.census.is_some() {
            return;
        }
        // contacts held per rank possible (rigid bodies, or families naming the world
        // bodies they touch): the sums over bodies per cell (the first subdomains are
        // the cells)
        let sums = self
            .dd
            .sums_per_subdomain(self.fams.is_empty())
            .then_some(self.dd.grid.as_ref())
            .flatten()
            .map(|grid| census::BodySums { grid });
        let census = census::census(&self.dd.last, w, self.dd.ranks.as_mut(), sums);
        let imbalance = census.imbalance(self.dd.last.subs.len());
        self.dd.pending.imbalance = imbalance;
        // (the next step's repartition is already decided: its state was shared)
        let (repartitioned, steps, next) = (self.dd.pending.repartitioned, self.dd.steps, self.dd.repartitions());
        let factor = self.dd.rebalance.filter(|_| !next);
        self.dd.balance.observe(imbalance, repartitioned, steps, factor);
        self.dd.pending.subdomains = census.subdomains;
        self.dd.pending.census = Some(census);
    }
    /// Per subdomain, in subdomain order ([`reactions`]): the rigid contacts'
    /// (the attached families' contacts add none), also when every rank steps every
    /// body (by model on more ranks than cells: the same sums as one process). With
    /// families that do not name the world bodies they touch, the engine's sum.
    fn reactions(&mut self, w: &mut D::World) -> bool {
        if !self.dd.sums_per_subdomain(self.fams.is_empty()) || self.dd.last.subs.is_empty() {
            return false;
        }
        let observed = D::observed(w);
        reactions::set(&self.dd.last, w, self.dd.ranks.as_mut(), &observed);
        true
    }
}

/// NSCDD without attached families as a contact stage (`world.step_with(&mut dd)`),
/// for one process: on MPI ranks step with [`NscddOf::step`], which also reduces each
/// world to its rank's part and keeps the rank state between steps.
impl<D: Family> ContactStage<D::World> for NscddOf<D> {
    fn before_detection(&mut self, w: &mut D::World) {
        Stage { dd: self, fams: &mut [] }.before_detection(w);
    }
    fn after_detection(&mut self, w: &mut D::World) {
        Stage { dd: self, fams: &mut [] }.after_detection(w);
    }
    fn after_free_velocity(&mut self, w: &D::World) {
        Stage { dd: self, fams: &mut [] }.after_free_velocity(w);
    }
    fn prepare(&mut self, w: &mut D::World) {
        Stage { dd: self, fams: &mut [] }.prepare(w);
    }
    fn solve(&mut self, w: &mut D::World) -> SolveReport {
        Stage { dd: self, fams: &mut [] }.solve(w)
    }
    fn reactions(&mut self, w: &mut D::World) -> bool {
        Stage { dd: self, fams: &mut [] }.reactions(w)
    }
    fn after_update(&mut self, w: &mut D::World) {
        Stage { dd: self, fams: &mut [] }.after_update(w);
    }
    fn after_integrate(&mut self, w: &mut D::World, moved: Result<(), usize>) -> Result<(), usize> {
        Stage { dd: self, fams: &mut [] }.after_integrate(w, moved)
    }
}
