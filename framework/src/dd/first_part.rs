//! A rank's part of a fresh scene, decided while the scene loads (issue 20): the
//! first step's provisional grid over the movable bodies' centres and its cells'
//! ranks ([`provisional`], the rule of [`super::NscddOf`]'s first step), and the
//! test of a body's box against a rank's cells ([`Halo`], the rule of
//! [`super::owned`]'s halo). The loader ([`crate::scene::part`]) builds on each rank
//! only the bodies of its halo and those every rank steps, which is what the first
//! step would keep of a whole world: no rank ever holds the whole scene.
//!
//! ```text
//! let (grid, rank_of) = provisional(&centres, [2, 2, 1], 4).unwrap();
//! let halo = Halo::new(&grid, &rank_of, 1, 3, alert);   // rank 1, 3D
//! halo.meets(&aabb)                                     // rank 1 holds the body
//! ```

use super::grid::Grid;
use crate::detect::Region;

/// What the loader hands to the first step ([`super::NscddOf::start_from`]): the
/// provisional grid's bounds and shape, and its cells' ranks.
#[derive(Clone, Debug, PartialEq)]
pub struct LoadedPart {
    pub lo: [f64; 3],
    pub hi: [f64; 3],
    pub cells: [u32; 3],
    pub rank_of: Vec<u32>,
}

/// The provisional grid over the movable bodies' `centres` (in id order) and its
/// cells' ranks, balanced by their bodies; `None` without a movable body or with a
/// centre that is not finite.
pub fn provisional(centres: &[[f64; 3]], cells: [u32; 3], ranks: u32) -> Option<LoadedPart> {
    let (lo, hi) = Grid::bounds(centres.iter().copied());
    if centres.is_empty() || (0..3).any(|k| !(lo[k].is_finite() && hi[k].is_finite())) {
        return None;
    }
    let grid = Grid::from_bounds(lo, hi, cells[0], cells[1], cells[2]);
    let owner = centres.iter().map(|&p| grid.cell_of(p));
    let rank_of = super::rank_balance::ranks_by_owner(owner, grid.len(), ranks);
    Some(LoadedPart { lo, hi, cells, rank_of })
}

impl LoadedPart {
    pub fn grid(&self) -> Grid {
        Grid::from_bounds(self.lo, self.hi, self.cells[0], self.cells[1], self.cells[2])
    }
}

/// Rank `me`'s cells, against which a body's box grown by the alert distance is
/// tested (the halo's own test).
pub struct Halo {
    mine: Region,
    space: usize,
    alert: f64,
}

impl Halo {
    pub fn new(part: &LoadedPart, me: u32, space: usize, alert: f64) -> Halo {
        Halo::of(&part.grid(), &part.rank_of, me, space, alert)
    }

    /// Rank `me`'s cells of `grid` whose ranks are `rank_of`.
    pub fn of(grid: &Grid, rank_of: &[u32], me: u32, space: usize, alert: f64) -> Halo {
        let mine = Region {
            boxes: super::cells::cells_of(grid, rank_of, me),
            pairs: Vec::new(),
        };
        Halo { mine, space, alert }
    }

    /// The boxes `boxes` instead of a rank's cells (a body family's
    /// [`crate::family::FamilyKind::load_boxes`]: every rank holds the bodies near them).
    pub fn around(boxes: Vec<[[f64; 3]; 2]>, space: usize, alert: f64) -> Halo {
        let mine = Region { boxes, pairs: Vec::new() };
        Halo { mine, space, alert }
    }

    /// Whether the box `b` (min, max; the first `space` coordinates) grown by the
    /// alert distance meets this rank's cells.
    pub fn meets(&self, b: &[[f64; 3]; 2]) -> bool {
        let (lo, hi) = Region::grown_box(self.space, &b[0], &b[1], self.alert);
        self.mine.meets(self.space, &lo, &hi)
    }
}
