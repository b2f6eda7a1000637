//! The attached families' contacts held per rank ([`super::local`]): a family
//! detects in this rank's cells ([`Attached::after_free_velocity_own`]; on a
//! repartition step in the old cells, then again in the new ones), or detects
//! whole and keeps its own ([`Attached::keep_own`]).

use super::attach::Attached;
use super::cells::{cells_of, CellIndex};
use super::family::Family;
use super::partition::Grid;

/// A cell's box `[lo, hi]`.
type CellBox = [[f64; 3]; 2];

impl<D: Family> super::NscddOf<D> {
    /// With contacts held per rank: each family told which of its contact points
    /// are this rank's (the cells of its subdomains in the step's grid, the new
    /// one after a repartition, [`Attached::keep_own`]); a family that detected
    /// in the old cells of a repartition step detects again in the new ones
    /// ([`Attached::after_free_velocity_own`]); the points read again if one keeps
    /// only those. `fam_total` keeps the families' count for a step with every
    /// contact on every rank (the one-process rule); the points detected and
    /// held counted in `ranks.json` (`family_detected`, `family_contacts`).
    pub(super) fn keep_own(&mut self, w: &mut D::World, fams: &mut [&mut dyn Attached<D>]) {
        self.fam_total = self.fam_points.len();
        let detected = self.fam_points.len() as u64;
        // (every rank's cells of the step's grid: a repartition step's new cells, and
        // the families' next detection's)
        let grid = self.local.new_grid.as_ref().map(|g| &g.0);
        let cells = (0..fams.len()).map(|f| self.family_cells(f, grid)).collect();
        self.fam_cells = cells;
        let again = self.keep_own_points(w, fams);
        if let Some(rs) = self.ranks.as_mut() {
            rs.totals.family_detected += detected + again;
            rs.totals.family_contacts += self.fam_points.len() as u64;
        }
    }

    /// [`Self::keep_own`]'s calls, with contacts held per rank; the contacts
    /// detected again.
    fn keep_own_points(&mut self, w: &mut D::World, fams: &mut [&mut dyn Attached<D>]) -> u64 {
        if !self.local.now {
            return 0;
        }
        let new_grid = self.local.new_grid.as_ref().map(|g| &g.0);
        let mut kept = false;
        // (detected again as at the free velocity: the world's velocities V_free,
        // not yet warm-started)
        let redetect = new_grid.is_some() && self.fam_own.contains(&true);
        let mut v = match redetect {
            true => std::mem::take(&mut self.v_free),
            false => Vec::new(),
        };
        D::swap_velocities(w, &mut v);
        for (f, fam) in fams.iter_mut().enumerate() {
            // (what each rank lacks of the family in its new cells sent to it first)
            let index = self.fam_cells.get(f).and_then(Option::as_ref).filter(|_| redetect);
            if let (Some(index), Some(rs)) = (index, self.ranks.as_mut()) {
                let rank = (rs.cluster.rank(), rs.cluster.size());
                super::attach::with_cells(index, rank, |c| super::with_rounds(rs, |r| fam.new_cells(c, r)));
            }
            let Some((boxes, own)) = self.own_cells(f, new_grid) else {
                continue;
            };
            match (self.fam_own.get(f) == Some(&true), new_grid.is_some()) {
                // (detected in the step's cells: its own already)
                (true, false) => {}
                (true, true) => {
                    let found = fam.after_free_velocity_own(w, &super::OwnCells { boxes: &boxes, of: &own });
                    debug_assert!(found, "a family that detects in a rank's cells does so again");
                    kept = true;
                }
                (false, _) => kept |= fam.keep_own(&own),
            }
        }
        D::swap_velocities(w, &mut v);
        if redetect {
            self.v_free = v;
        }
        if kept {
            self.family_points(fams);
        }
        // (the second detection's contacts: the points read again)
        match redetect {
            true => (self.fam_ranges.iter().zip(&self.fam_own))
                .filter(|x| *x.1)
                .map(|x| x.0.len() as u64)
                .sum(),
            false => 0,
        }
    }

    /// Whether a family may detect in each rank's cells this step: contacts held
    /// per rank, the decentralized scheme only (its limited shells take a family's
    /// copies by routing, `RankState::route_family_copies`; the centralized one's
    /// whole shells need every rank to copy the same bodies, which the reach gives).
    fn cells_per_rank(&self) -> bool {
        self.ranks.is_some() && self.local.now && self.settings.scheme == super::Scheme::Decentralized
    }

    /// Every rank's cells of family f in the step's grid (`grid`, after a
    /// repartition, else the last one), when it detected in this rank's cells
    /// this step ([`Attached::after_free_velocity_own`]).
    fn family_cells(&self, f: usize, grid: Option<&Grid>) -> Option<CellIndex> {
        let (Some(rs), Some(grid)) = (self.ranks.as_ref(), grid.or(self.grid.as_ref())) else {
            return None;
        };
        if !self.cells_per_rank() || self.fam_own.get(f) != Some(&true) {
            return None;
        }
        let base = if self.by_model { (f + 1) * grid.len() } else { 0 };
        Some(CellIndex::new(grid, rs.rank_of.get(base..base + grid.len())?))
    }

    /// With contacts held per rank: family f's own cells' boxes
    /// ([`super::OwnCells::boxes`]) with the test of a point, in the step's grid
    /// (`grid`, after a repartition), else the last one (the step's, or on a
    /// repartition step the old regions), for its detection in the rank's cells
    /// ([`Attached::after_free_velocity_own`]).
    pub(super) fn own_cells<'a>(&'a self, f: usize, grid: Option<&'a Grid>) -> Option<(Vec<CellBox>, impl Fn([f64; 3]) -> bool + 'a)> {
        let (Some(rs), Some(grid), true) = (self.ranks.as_ref(), grid.or(self.grid.as_ref()), self.cells_per_rank()) else {
            return None;
        };
        let base = if self.by_model { (f + 1) * grid.len() } else { 0 };
        let me = rs.cluster.rank();
        let boxes = cells_of(grid, rs.rank_of.get(base..)?, me);
        Some((boxes, move |p| rs.rank_of.get(base + grid.cell_of(p) as usize) == Some(&me)))
    }
}
