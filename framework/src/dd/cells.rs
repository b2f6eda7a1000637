//! The grid's cells as the ranks' regions: each cell's box (edge cells unbounded, a
//! flat axis whole, each grown by 10⁻⁶ of a cell), and which ranks' cells a box
//! meets, found among the cells its index range covers (O(1) a box, not O(ranks)):
//! the exact test of [`crate::detect::Region::meets`] on each of those cells.

use super::partition::Grid;

/// The box of cell `c` of `grid` (the region test's own boxes).
pub(super) fn cell_box(grid: &Grid, c: u32) -> [[f64; 3]; 2] {
    let n = [grid.nx, grid.ny, grid.nz];
    let inf = f64::INFINITY;
    let idx = [c % n[0], (c / n[0]) % n[1], c / (n[0] * n[1])];
    let mut b = [[0.0; 3]; 2];
    for d in 0..3 {
        let h = grid.cell[d];
        let flat = grid.flat(d);
        let mut next = idx;
        next[d] += 1;
        b[0][d] = if flat || idx[d] == 0 { -inf } else { grid.cut(d, idx) - 1e-6 * h };
        b[1][d] = if flat || idx[d] + 1 == n[d] {
            inf
        } else {
            grid.cut(d, next) + 1e-6 * h
        };
    }
    b
}

/// The boxes of the cells whose rank is `rank`.
pub(super) fn cells_of(grid: &Grid, rank_of: &[u32], rank: u32) -> Vec<[[f64; 3]; 2]> {
    (0..grid.len() as u32)
        .filter(|&c| rank_of.get(c as usize) == Some(&rank))
        .map(|c| cell_box(grid, c))
        .collect()
}

/// Every cell's box and rank, searched by index range.
pub(super) struct CellIndex {
    grid: Grid,
    boxes: Vec<[[f64; 3]; 2]>,
    rank_of: Vec<u32>,
}

impl CellIndex {
    pub fn new(grid: &Grid, rank_of: &[u32]) -> Self {
        CellIndex {
            grid: grid.clone(),
            boxes: (0..grid.len() as u32).map(|c| cell_box(grid, c)).collect(),
            rank_of: rank_of.to_vec(),
        }
    }

    /// The cell range (per axis, inclusive) that may meet `[lo, hi]` (first `n`
    /// coordinates): the cells of the corners, widened by one cell each way; along
    /// a balanced axis, over every slab (row) the axes before it cover.
    fn range(&self, n: usize, lo: &[f64], hi: &[f64]) -> [[u32; 2]; 3] {
        let g = &self.grid;
        let dims = [g.nx, g.ny, g.nz];
        let mut r = [[0u32; 2]; 3];
        for d in 0..3 {
            if d >= n || g.flat(d) {
                r[d] = [0, dims[d] - 1];
                continue;
            }
            let one = |i: [u32; 3]| {
                let k = |x: f64| g.axis_index(d, i, x);
                let (a, b) = (k(lo[d]), k(hi[d]));
                // NaN or beyond: every cell of the axis
                let a = if a.is_nan() || a < 1.0 {
                    0
                } else {
                    (a as u32 - 1).min(dims[d] - 1)
                };
                let b = if b.is_nan() {
                    dims[d] - 1
                } else {
                    ((b.max(0.0) as u32).saturating_add(1)).min(dims[d] - 1)
                };
                [a, b.max(a)]
            };
            r[d] = if g.cuts[d].is_empty() || d == 0 {
                one([0; 3])
            } else {
                let mut u = [u32::MAX, 0];
                for x in r[0][0]..=r[0][1] {
                    let ys = if d == 2 { r[1][0]..=r[1][1] } else { 0..=0 };
                    for y in ys {
                        let [a, b] = one([x, y, 0]);
                        u = [u[0].min(a), u[1].max(b)];
                    }
                }
                u
            };
        }
        r
    }

    /// Calls `f` with the rank of every cell whose box meets `[lo, hi]` (first `n`
    /// coordinates; a rank once per cell).
    pub fn ranks_meeting(&self, n: usize, lo: &[f64], hi: &[f64], mut f: impl FnMut(u32)) {
        let r = self.range(n, lo, hi);
        let (nx, ny) = (self.grid.nx, self.grid.ny);
        for z in r[2][0]..=r[2][1] {
            for y in r[1][0]..=r[1][1] {
                for x in r[0][0]..=r[0][1] {
                    let c = (x + nx * (y + ny * z)) as usize;
                    let b = &self.boxes[c];
                    if (0..n).all(|k| lo[k] <= b[1][k] && b[0][k] <= hi[k]) {
                        if let Some(&q) = self.rank_of.get(c) {
                            f(q);
                        }
                    }
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::detect::Region;

    /// The index range finds exactly the ranks the plain test over every rank's
    /// cells finds, for boxes inside, across, on and beyond the cells.
    #[test]
    fn the_index_finds_what_the_region_test_finds() {
        the_index_finds_on(&Grid::from_bounds([0.0, -1.0, 0.0], [3.0, 1.0, 2.0], 3, 2, 2));
        // balanced cuts of points crowded towards a corner: each slab and row its own
        let pts = (0..3000).map(|k| {
            let t = k as f64 / 3000.0;
            [3.0 * t * t, -1.0 + 2.0 * (7.0 * t).fract().powi(3), 2.0 * (13.0 * t).fract().sqrt()]
        });
        let g = Grid::balanced_over(pts, 3, 2, 2);
        assert!(g.cuts.iter().all(|c| !c.is_empty()), "{g:?}");
        the_index_finds_on(&g);
    }

    fn the_index_finds_on(grid: &Grid) {
        let grid = grid.clone();
        let rank_of: Vec<u32> = (0..grid.len() as u32).map(|c| (c * 7) % 5).collect();
        let index = CellIndex::new(&grid, &rank_of);
        let regions: Vec<Region> = (0..5)
            .map(|q| Region {
                boxes: cells_of(&grid, &rank_of, q),
                pairs: Vec::new(),
            })
            .collect();
        let mut k = 0u32;
        let mut next = || {
            k = k.wrapping_mul(1_103_515_245).wrapping_add(12_345);
            (k >> 8) as f64 / (1u32 << 24) as f64
        };
        for t in 0..2000 {
            let lo: [f64; 3] = std::array::from_fn(|_| 5.0 * next() - 1.0);
            let size = if t % 3 == 0 { 1e-9 } else { next() };
            let mut hi: [f64; 3] = std::array::from_fn(|d| lo[d] + size);
            if t % 17 == 0 {
                hi[0] = f64::INFINITY;
            }
            for n in [2, 3] {
                let mut found = [false; 5];
                index.ranks_meeting(n, &lo, &hi, |q| found[q as usize] = true);
                for q in 0..5 {
                    assert_eq!(found[q], regions[q].meets(n, &lo, &hi), "{lo:?} {hi:?} rank {q}");
                }
            }
        }
    }
}
