//! Contacts held per rank (docs/SCALING.md, "Owned data per rank"): on MPI ranks,
//! between repartitions, each rank detects, builds and solves only the contacts of
//! its own subdomains, and the world's contact list holds those alone.
//!
//! ```text
//! before detection:  the last step's contacts another rank may meet again (their
//!                    pair's boxes, grown by the alert distance, reach its cells)
//!                    go to those ranks, point to point: their warm starts, and
//!                    their kept subdomains (a contact kept by another rank is its)
//! detection:         the own cells (edge cells unbounded) and the own kept pairs
//! after detection:   a raw contact stays when its owner — its kept subdomain, else
//!                    the cell of its point — is an own subdomain
//! partition:         the other ranks' subdomains as shells: their bodies near this
//!                    rank ([`super::shells`]; the interface and multiplicities of
//!                    those bodies are then those of one process)
//! ```
//!
//! A repartition step detects in the old regions (the exchange above), merges every
//! rank's bounds and counts into the new grid and ranks, sends the last step's
//! contacts the other ranks' new cells may meet to those ranks (their warm starts,
//! point to point) and detects again in the new regions
//! ([`super::NscddOf::repartition_local`]). The first step of a fresh run is such
//! a repartition, its old regions a provisional grid over the bodies' centres
//! ([`super::NscddOf::start_held`]); the first step after a restart starts from
//! the saved grid and kept subdomains, each rank keeping the loaded contacts of
//! its own subdomains. Every decision above is the one a
//! single process takes with all the contacts, so results stay bitwise those of one
//! process.

use super::cells::{cells_of, CellIndex};
use super::family::Family;
use super::partition::{Grid, OwnerOf};
use super::ranks::RankState;
use crate::detect::Region;
use crate::model::ContactKey;

/// The state of the mode across steps.
#[derive(Default)]
pub(super) struct Local {
    /// Whether the world's contacts are this rank's only (the last step ran local).
    pub held: bool,
    /// Whether the step in progress runs local.
    pub now: bool,
    /// The bodies' boxes at the start of the step, by slot (those this rank steps up
    /// to date).
    pub boxes: Vec<[[f64; 3]; 2]>,
    /// With contacts held per rank: each body's subdomain for the outputs
    /// ([`super::shells::body_subdomains`]).
    pub body_sub: Vec<i32>,
    /// The step in progress needs no `body_sub` (no output frame after it).
    pub skip_view: bool,
    /// The step in progress is the first after a restart, its F_Γ store the whole
    /// loaded one (every rank loaded it): if the step re-partitions, the store is
    /// kept instead of routed from the last step's ranks (there was no last step);
    /// like every step, the step's end replaces it by the subdomains' F_Γ
    /// ([`super::NscddOf::start_held`]).
    pub whole_store: bool,
    /// A distributed repartition's grid and number of contacts, for the partition.
    pub new_grid: Option<(Grid, usize)>,
    /// The step in progress holds the other ranks' subdomains as limited shells
    /// ([`super::shells`]; its end then comes by requests, even before a repartition).
    pub limited: bool,
    /// The bodies this rank steps ([`super::owned`]).
    pub owned: super::owned::Owned,
    /// Subdomains per grid cell: 1 (0 before it is decided), by model 1 + the
    /// attached families (a family's subdomain of a cell is solved by the cell's
    /// rank, [`per_model`]; after a step on the whole sample, until the next
    /// repartition, by the rank the balance of all subdomains gave it, which holds
    /// every body the family touches too).
    pub models: usize,
    /// On a repartition step: this rank's contacts of the last step (their
    /// [`Family::prev_record`]s), for the ranks whose new cells they may meet.
    own_prev: Option<Vec<f64>>,
}

/// [`Region::meets_pair`] of two bodies' boxes (the detection's own test).
fn pair_meets(n: usize, a: &[[f64; 3]; 2], b: &[[f64; 3]; 2], alert: f64, region: &Region) -> bool {
    region.meets_pair(n, (&a[0], &a[1]), (&b[0], &b[1]), alert)
}

impl Local {
    /// Before a step's detection (collective): the last step's contacts each other
    /// rank may meet sent to it, and those this rank may meet received into the
    /// warm start; returns the other ranks' kept subdomains of theirs (key, owner),
    /// ranks ascending. (`cells`: every rank's cells)
    pub(super) fn exchange<D: Family>(
        &self,
        rs: &mut RankState,
        w: &mut D::World,
        (owner, cells, alert): (&[u32], &CellIndex, f64),
    ) -> Vec<(ContactKey, u32)> {
        let c = D::contacts(w);
        let mut to = ToRanks::new(rs, D::SPACE);
        let mut rec = Vec::with_capacity(D::PREV_RECORD + 1);
        for (a, &o) in owner.iter().enumerate().take(D::len(c)) {
            if to.aim(cells, self.pair_box::<D>(w, D::contact_bodies(w, a), alert)) {
                rec.clear();
                D::prev_record(c, a, &mut rec);
                rec.push(f64::from(o));
                to.push(&rec);
            }
        }
        let got = to.finish(rs);
        let per = D::PREV_RECORD + 1;
        let (mut prev, mut kept) = (Vec::new(), Vec::new());
        for x in got.iter().flat_map(|m| m.chunks_exact(per)) {
            prev.extend_from_slice(&x[..D::PREV_RECORD]);
            let key = ContactKey {
                i: x[0] as u32,
                j: x[1] as u32,
                feature: x[2] as u32,
            };
            kept.push((key, x[D::PREV_RECORD] as u32));
        }
        D::set_extra_prev(w, &prev);
        kept
    }

    /// The box of the pair (i, j) grown by `alert`: the region's pair test
    /// ([`Region::meets_pair`]).
    fn pair_box<D: Family>(&self, w: &D::World, [i, j]: [u32; 2], alert: f64) -> ([f64; 3], [f64; 3]) {
        let slot = |g: u32| D::held_slot(w, g as usize);
        let (bi, bj) = (&self.boxes[slot(i)], &self.boxes[slot(j)]);
        Region::pair_box(D::SPACE, (&bi[0], &bi[1]), (&bj[0], &bj[1]), alert)
    }
}

/// Records each sent to the other ranks whose cells meet a box, point to point
/// ([`RankState::send_ranks`]): a rank's detection pairs only bodies whose grown
/// boxes meet its cells, so no other rank needs them.
struct ToRanks {
    /// The dimension of space.
    n: usize,
    me: u32,
    out: Vec<Vec<f64>>,
    to: Vec<u32>,
}

impl ToRanks {
    fn new(rs: &RankState, n: usize) -> Self {
        let np = rs.cluster.size() as usize;
        ToRanks {
            n,
            me: rs.cluster.rank(),
            out: vec![Vec::new(); np],
            to: Vec::new(),
        }
    }

    /// Aims at the ranks but this one whose `cells` meet `[lo, hi]` (once each);
    /// whether there is any.
    fn aim(&mut self, cells: &CellIndex, (lo, hi): ([f64; 3], [f64; 3])) -> bool {
        let (me, to) = (self.me, &mut self.to);
        to.clear();
        cells.ranks_meeting(self.n, &lo, &hi, |q| {
            if q != me && !to.contains(&q) {
                to.push(q);
            }
        });
        !to.is_empty()
    }

    /// `rec` to the ranks aimed at last.
    fn push(&mut self, rec: &[f64]) {
        for &q in &self.to {
            self.out[q as usize].extend_from_slice(rec);
        }
    }

    /// Sends (collective); what each other rank sent this one, ranks ascending.
    fn finish(self, rs: &mut RankState) -> Vec<Vec<f64>> {
        rs.send_ranks(self.out).1
    }
}

impl Local {
    /// On a repartition step (collective): this rank's last-step contacts `own`
    /// ([`Family::prev_record`]s) whose pair's grown boxes meet another rank's new
    /// `cells` go to that rank; returns the other ranks' that this one receives
    /// (the warm starts its new cells may need; those of its old cells came before
    /// detection).
    fn prev_for_new_cells<D: Family>(&self, (rs, w): (&mut RankState, &D::World), cells: &CellIndex, own: &[f64]) -> Vec<f64> {
        let (mut to, alert) = (ToRanks::new(rs, D::SPACE), D::alert(w));
        for x in own.chunks_exact(D::PREV_RECORD) {
            if to.aim(cells, self.pair_box::<D>(w, [x[0] as u32, x[1] as u32], alert)) {
                to.push(x);
            }
        }
        to.finish(rs).concat()
    }

    /// The subdomains of `grid` with contacts held per rank.
    pub(super) fn subdomains(&self, grid: &Grid) -> usize {
        grid.len() * self.models.max(1)
    }
}

/// The ranks of the subdomains from those of the grid's cells (`cells`): by model,
/// each family's subdomain of a cell on the cell's rank (`models` subdomains a cell,
/// [`Local::models`]).
pub(super) fn per_model(mut cells: Vec<u32>, models: usize) -> Vec<u32> {
    let n = cells.len();
    for _ in 1..models {
        cells.extend_from_within(..n);
    }
    cells
}

/// The region a rank detects in: its cells, and the pairs of its kept contacts
/// that the cells would miss (their grown boxes' intersection has left them).
pub(super) fn region<D: Family>(
    rs: &RankState,
    grid: &Grid,
    kept: &[(ContactKey, u32)],
    (w, boxes): (&D::World, &[[[f64; 3]; 2]]),
) -> Region {
    let alert = D::alert(w);
    let box_of = |g: u32| D::slot(w, g as usize).and_then(|k| boxes.get(k));
    let me = rs.cluster.rank();
    let cells = Region {
        boxes: cells_of(grid, &rs.rank_of, me),
        pairs: Vec::new(),
    };
    let mut pairs: Vec<[u32; 2]> = kept
        .iter()
        .filter(|e| rs.rank_of.get(e.1 as usize) == Some(&me))
        .filter(|e| match (box_of(e.0.i), box_of(e.0.j)) {
            (Some(a), Some(b)) => !pair_meets(D::SPACE, a, b, alert, &cells),
            _ => false,
        })
        .map(|e| [e.0.i.min(e.0.j), e.0.i.max(e.0.j)])
        .collect();
    pairs.sort_unstable();
    pairs.dedup();
    Region { pairs, ..cells }
}

impl<D: Family> super::NscddOf<D> {
    /// Before a step on ranks (contacts held per rank: rigid bodies, or families
    /// naming the world bodies they touch, [`super::NscddOf::held_ok`]) while no
    /// step has reduced the world (it holds every body, or its part as the scene
    /// was loaded, [`crate::scene::part`]): each world reduced to its rank's part
    /// ([`super::owned`]), on a fresh run's first step ([`Self::start_fresh`]) and
    /// on the first step after a restart ([`Self::start_restarted`]). Nothing
    /// otherwise (after any step on ranks the world holds only its part, or the
    /// ranks are known).
    pub(super) fn start_held(&mut self, w: &mut D::World, eligible: bool) {
        if self.ranks.is_none() || !(eligible && self.local_contacts) || D::active(w).is_some() {
            return;
        }
        if self.grid.is_none() && self.steps == 0 && D::step(w) == 0 {
            self.start_fresh(w);
        } else {
            self.start_restarted(w);
        }
    }

    /// A fresh run's first step: a provisional grid over the movable bodies'
    /// centres, its cells' ranks balanced by their bodies (the same on every rank:
    /// every rank holds the whole scene). The first step re-partitions over its
    /// contacts as every repartition with contacts held per rank does
    /// ([`Self::repartition_local`]): the same grid and ranks as one process, which
    /// never needs every body and contact on a rank.
    fn start_fresh(&mut self, w: &mut D::World) {
        let Some(rs) = self.ranks.as_mut() else { return };
        let s = &self.settings;
        let cells = [s.nx, s.ny, s.nz];
        // the cells' ranks balanced by their bodies, as a repartition by its contacts
        // (computed by the loader when the world holds this rank's part only)
        let part = match self.loaded.take() {
            Some(p) => p,
            None => {
                let centres: Vec<[f64; 3]> = (0..D::n_bodies(w))
                    .filter(|&g| D::movable(w, g))
                    .map(|g| D::position(w, g))
                    .collect();
                let Some(p) = super::first_part::provisional(&centres, cells, rs.cluster.size()) else {
                    return;
                };
                p
            }
        };
        debug_assert_eq!(part.cells, cells, "the loader's grid is the decomposition's");
        let grid = part.grid();
        rs.rank_of = per_model(part.rank_of, self.local.models);
        rs.totals.loaded_bodies = D::held(w).map_or_else(|| D::n_bodies(w), <[u32]>::len) as u64;
        self.local.owned.start_held::<D>(w, rs, &grid);
        self.grid = Some(grid);
    }

    /// The first step after a restart (the saved grid, no ranks yet; every rank
    /// loaded every body and the last step's contacts, or only its own bodies and
    /// contacts when the CLI read the state in part, [`super::RestartPart`] and
    /// [`crate::scene::part::restart_on`]: the same rule): the cells' ranks balanced
    /// by their kept contacts (the same on every rank; results do not depend on
    /// which rank sweeps a subdomain), then each rank keeps the last step's
    /// contacts whose kept subdomain is its own, as if it had stepped them, and its
    /// halo. The loaded F_Γ store stays whole during the step (a superset of what
    /// a rank's store holds; not routed if the step re-partitions: [`super::shells`])
    /// and is replaced at its end, as every step's.
    fn start_restarted(&mut self, w: &mut D::World) {
        let (Some(rs), Some(grid)) = (self.ranks.as_mut(), self.grid.as_ref()) else {
            return;
        };
        if rs.rank_of.len() == self.local.subdomains(grid) || self.grid_empty || self.local.held {
            return;
        }
        // (the saved subdomains lie in the grid: `NscddOf::load_state` checks)
        let kept_owners: Vec<u32> = self.kept.iter().map(|e| e.1).collect();
        rs.assign(&kept_owners, grid.len(), true);
        rs.rank_of = per_model(std::mem::take(&mut rs.rank_of), self.local.models);
        rs.totals.restart_contacts = D::len(D::contacts(w)) as u64;
        rs.totals.loaded_bodies = D::held(w).map_or_else(|| D::n_bodies(w), <[u32]>::len) as u64;
        let owner = super::owner::kept_owners::<D>(D::contacts(w), grid, &self.kept);
        D::retain_contacts(w, &mut |a| rs.is_own(owner[a]));
        self.last.owner = owner.into_iter().filter(|&o| rs.is_own(o)).collect();
        self.kept.retain(|e| rs.is_own(e.1));
        self.local.held = true;
        self.local.whole_store = true;
        self.local.owned.start_held::<D>(w, rs, grid);
    }

    /// Whether this step re-partitions over a new grid.
    pub(super) fn repartitions(&self) -> bool {
        self.repartitions_at(self.steps)
    }

    /// Whether the partition after `steps` steps re-partitions.
    pub(super) fn repartitions_at(&self, steps: u64) -> bool {
        let k = self.repartition_every.max(1) as u64;
        self.grid.is_none() || self.grid_empty || steps.is_multiple_of(k) || self.balance.due == Some(steps)
    }

    /// Before detection: on ranks, with `eligible` (the scene may hold its contacts
    /// per rank, [`super::NscddOf::held_ok`]), the exchange
    /// of the last step's contacts and this step's region (see the module docs).
    pub(super) fn before_detection(&mut self, w: &mut D::World, eligible: bool) {
        let repart = self.repartitions();
        let (Some(rs), Some(grid)) = (self.ranks.as_mut(), self.grid.as_ref()) else {
            self.local.now = false;
            return;
        };
        // (not eligible: families that may touch any body, or by model on more ranks
        // than cells; ranks of the subdomains not known: a restart that could not
        // start per rank; that step runs on the whole sample)
        if !(eligible && self.local_contacts) || rs.rank_of.len() != self.local.subdomains(grid) {
            self.local.now = false;
            rs.local = false;
            D::set_region(w, None);
            debug_assert!(D::active(w).is_none(), "a step on the whole sample needs every body");
            return;
        }
        D::body_boxes(w, &mut self.local.boxes);
        self.local.owned.start::<D>(w, rs, grid);
        if self.local.held {
            let cells = self.local.owned.cells.as_ref().expect("the step's cells (Owned::start)");
            let got = self.local.exchange::<D>(rs, w, (&self.last.owner, cells, D::alert(w)));
            self.kept.extend(got);
            self.kept.sort_unstable_by_key(|e| e.0);
            if repart {
                let c = D::contacts(w);
                let mut own = Vec::with_capacity(D::len(c) * D::PREV_RECORD);
                (0..D::len(c)).for_each(|a| D::prev_record(c, a, &mut own));
                self.local.own_prev = Some(own);
            }
        } else {
            D::set_extra_prev(w, &[]);
        }
        // a repartition detects in the old regions first ([`Self::repartition_local`])
        self.local.now = true;
        rs.local = true;
        let region = region::<D>(rs, grid, &self.kept, (w, &self.local.boxes));
        D::set_region(w, Some(region));
    }

    /// After detection: only the raw contacts of the own subdomains stay.
    pub(super) fn after_detection(&mut self, w: &mut D::World) {
        if !self.local.now {
            return;
        }
        let (Some(rs), Some(grid)) = (self.ranks.as_ref(), self.grid.as_ref()) else {
            return;
        };
        let me = rs.cluster.rank();
        let (kept, rank_of) = (&self.kept, &rs.rank_of);
        let mut owner = OwnerOf::new(kept, grid);
        D::retain_raw(w, &mut |key, p| rank_of.get(owner.of(key, p) as usize) == Some(&me));
    }

    /// A repartition with contacts held per rank (collective): the new grid over the
    /// bounds of every rank's contact points (merged by min and max), the new ranks
    /// by the counts per cell (added), then each rank detects and builds again the
    /// contacts of its new cells, with the same warm starts.
    pub(super) fn repartition_local(&mut self, w: &mut D::World) {
        if !(self.local.now && self.repartitions()) {
            return;
        }
        let Some(rs) = self.ranks.as_mut() else { return };
        let s = &self.settings;
        let c = D::contacts(w);
        let nc = D::len(c);
        // the attached families' contact points: those detected in the rank's
        // cells each rank's own, those detected whole (every rank's, the same)
        // counted once, by rank 0; `total`: the contacts
        let rank0 = rs.cluster.rank() == 0;
        let fam: Vec<[f64; 3]> = (self.fam_ranges.iter().enumerate())
            .filter(|(f, _)| rank0 || self.fam_own.get(*f) == Some(&true))
            .flat_map(|(_, r)| self.fam_points[r.clone()].iter().copied())
            .collect();
        let points = || (0..nc).map(|a| D::point(c, a)).chain(fam.iter().copied());
        let (lo, hi) = Grid::bounds(points());
        let mine: Vec<f64> = lo.iter().chain(&hi).copied().chain([(nc + fam.len()) as f64]).collect();
        let (_, all) = rs.all_gather_any(&mine);
        let (mut glo, mut ghi, mut total) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3], 0usize);
        for x in all.chunks_exact(7) {
            for d in 0..3 {
                glo[d] = glo[d].min(x[d]);
                ghi[d] = ghi[d].max(x[3 + d]);
            }
            total += x[6] as usize;
        }
        let grid = if self.balanced_grid {
            // every rank's histograms of its contact points, added (integers: exact)
            let add = |mine: Vec<f64>| rs.all_sum(&mine);
            Grid::balanced(glo, ghi, [s.nx, s.ny, s.nz], points, add)
        } else {
            Grid::from_bounds(glo, ghi, s.nx, s.ny, s.nz)
        };
        let ns = grid.len();
        let mut loads = vec![0f64; ns];
        for p in points() {
            loads[grid.cell_of(p) as usize] += 1.0;
        }
        let sum: Vec<usize> = rs.all_sum(&loads).into_iter().map(|x| x as usize).collect();
        let new = per_model(super::rank_balance::balanced_ranks(&sum, rs.cluster.size()), self.local.models);
        rs.old_rank_of = std::mem::replace(&mut rs.rank_of, new);
        if D::active(w).is_some() {
            let Local { owned, boxes, .. } = &mut self.local;
            owned.repartition::<D>(w, (rs, &grid), boxes, &mut self.v_free);
        }
        let me = rs.cluster.rank();
        let more_prev = match self.local.own_prev.take() {
            Some(own) => {
                let cells = CellIndex::new(&grid, &rs.rank_of);
                self.local.prev_for_new_cells::<D>((rs, w), &cells, &own)
            }
            None => Vec::new(),
        };
        let region = Region {
            boxes: cells_of(&grid, &rs.rank_of, me),
            pairs: Vec::new(),
        };
        let rank_of = &rs.rank_of;
        D::redetect(
            w,
            region,
            &mut |_, p| rank_of.get(grid.cell_of(p) as usize) == Some(&me),
            (&self.v_free, &more_prev),
        );
        self.local.new_grid = Some((grid, total));
    }

    /// After the position update (collective with contacts held per rank): the
    /// bodies other ranks need sent to them and the next step's bodies
    /// ([`super::owned`]); every rank returns the same divergence.
    pub(super) fn after_integrate(&mut self, w: &mut D::World, moved: Result<(), usize>) -> Result<(), usize> {
        if let Some(rs) = self.ranks.as_mut() {
            rs.totals.bodies_stepped += D::stepped(w).map_or(D::n_bodies(w), |a| a.len()) as u64;
            let held = D::held(w).map_or(D::n_bodies(w), |a| a.len()) as u64;
            rs.totals.bodies_held += held;
            rs.totals.bodies_held_max = rs.totals.bodies_held_max.max(held);
        }
        if !self.local.now {
            return moved;
        }
        let (Some(rs), Some(grid)) = (self.ranks.as_mut(), self.grid.as_ref()) else {
            return moved;
        };
        // a repartition brings the bodies of the new halos itself
        let full_next = rs.rank_of.len() != self.local.subdomains(grid);
        let Local { owned, boxes, .. } = &mut self.local;
        owned.after_integrate::<D>(w, (rs, grid), (boxes, full_next), moved)
    }

    /// After the step: whether the world now holds this rank's contacts only.
    pub(super) fn after_step(&mut self) {
        self.local.held = self.local.now;
        self.local.whole_store = false;
    }

    /// With bodies stepped per rank: which bodies this rank holds and owns (the
    /// cell of their centre is its), the writer of a body's outputs; `None` when
    /// the step had no active set (every rank stepped every body it holds: a full
    /// step, or one that diverged).
    pub(super) fn owned_bodies(&self, w: &D::World) -> Option<Vec<bool>> {
        let mut mine = vec![false; D::n_bodies(w)];
        for g in self.owned_ids(w)? {
            mine[g as usize] = true;
        }
        Some(mine)
    }

    /// [`Self::owned_bodies`] as their ids (ascending).
    fn owned_ids<'a>(&'a self, w: &'a D::World) -> Option<impl Iterator<Item = u32> + 'a> {
        let active = D::active(w)?;
        let (rs, grid) = (self.ranks.as_ref()?, self.grid.as_ref()?);
        let me = rs.cluster.rank();
        let own = move |g: &u32| rs.rank_of.get(grid.cell_of(D::position(w, *g as usize)) as usize) == Some(&me);
        Some(active.iter().copied().filter(own))
    }

    /// With bodies held per rank, the records of the bodies this rank owns (the
    /// writer of their outputs), `[g, record…]` ascending in g
    /// ([`Family::output_record`]), for rank 0's merge of every rank's
    /// ([`super::rank_merge`]); `None` in one process or when every rank holds every
    /// body.
    pub fn own_body_records(&mut self, w: &D::World) -> Option<Vec<f64>> {
        // ascending, as rank 0's merge needs (the active list is)
        let mut ids: Vec<u32> = self.owned_ids(w)?.collect();
        if !ids.is_sorted() {
            ids.sort_unstable();
        }
        let mut out = Vec::new();
        for g in ids {
            out.push(f64::from(g));
            D::output_record(w, g as usize, &mut out);
        }
        let rs = self.ranks.as_mut()?;
        if rs.cluster.rank() != 0 {
            rs.totals.bodies_sent += (out.len() / (1 + D::OUTPUT_RECORD)) as u64;
        }
        Some(out)
    }

    /// Whether the world holds this rank's contacts only (the last step ran with
    /// contacts held per rank): outputs of every contact merge every rank's on rank
    /// 0 ([`super::rank_merge`]).
    pub fn holds_own_contacts(&self) -> bool {
        self.local.held
    }
}
