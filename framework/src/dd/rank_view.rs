//! An attached family stepped in part on each rank (docs/SCALING.md, "Deformable
//! bodies stepped per rank"): with contacts held per rank, between repartitions,
//! the grid and the subdomains' ranks are the last step's, so where each of the
//! step's contacts will be solved is known before the families' free velocities
//! ([`RankView`], given to [`Attached::set_ranks`]). A family that uses it does
//! the work of its contacts' bodies on the ranks solving them only, and after its
//! [`Attached::write_back`] the ranks exchange what each computed
//! ([`Attached::pack_stepped`], one all-gather), so that its state is the same on
//! every rank again before its residual, outputs and position update.

use super::attach::Attached;
use super::family::Family;
use super::grid::Grid;
use super::ranks::RankState;
use super::NscddOf;

/// Where this step's contacts of one attached family are solved: the rank of the
/// subdomain of a contact point ([`Attached::points`]).
#[derive(Clone, Debug)]
pub struct RankView {
    /// This rank and the number of ranks.
    pub rank: u32,
    pub ranks: u32,
    grid: Grid,
    rank_of: Vec<u32>,
    /// The family's first subdomain (by model: its cells' subdomains).
    base: u32,
}

impl RankView {
    /// The rank that will solve a contact at `p` (z = 0 in 2D).
    pub fn rank_of(&self, p: [f64; 3]) -> u32 {
        self.rank_of[(self.base + self.grid.cell_of(p)) as usize]
    }
}

impl<D: Family> NscddOf<D> {
    /// Each family's view of the step (`None` for all: one process, a step on the
    /// whole sample, or a repartition step, whose grid comes after the families'
    /// contacts); the same on every rank.
    pub(super) fn rank_views(&self, families: usize) -> Vec<Option<RankView>> {
        let (Some(rs), Some(grid)) = (self.ranks.as_ref(), self.grid.as_ref()) else {
            return vec![None; families];
        };
        if !self.local.now || self.repartitions() || rs.rank_of.len() != self.local.subdomains(grid) {
            return vec![None; families];
        }
        (0..families)
            .map(|f| {
                Some(RankView {
                    rank: rs.cluster.rank(),
                    ranks: rs.cluster.size(),
                    grid: grid.clone(),
                    rank_of: rs.rank_of.clone(),
                    base: if self.by_model { ((f + 1) * grid.len()) as u32 } else { 0 },
                })
            })
            .collect()
    }
}

/// After the families' write-back: each family stepped in part (`on`) packs what
/// it computed, every rank receives every rank's pack (one all-gather per family;
/// collective: `on` is the same on every rank).
pub(super) fn share_stepped<D: Family>(fams: &mut [&mut dyn Attached<D>], on: &[bool], mut ranks: Option<&mut RankState>) {
    for (fam, _) in fams.iter_mut().zip(on).filter(|x| *x.1) {
        let Some(rs) = ranks.as_deref_mut() else { return };
        let mut mine = Vec::new();
        fam.pack_stepped(&mut mine);
        let (_, all) = rs.all_gather_any(&mine);
        fam.unpack_stepped(&all);
        if let Some((here, n)) = fam.stepped_bodies() {
            rs.totals.family_bodies_stepped += here as u64;
            rs.totals.family_bodies += n as u64;
        }
    }
}

/// No contact on any rank: the families' V⁺ is their V_free (each family stepped
/// in part then shares it, [`share_stepped`]).
pub(super) fn write_back_alone<D: Family>(w: &mut D::World, fams: &mut [&mut dyn Attached<D>], on: &[bool], ranks: Option<&mut RankState>) {
    for fam in fams.iter_mut() {
        fam.write_back(w, &[]);
    }
    share_stepped(fams, on, ranks);
}
