//! The grid of subdomains over the contact points' bounding box: uniform cells, or
//! balanced cells (`[decomposition] grid = "balanced"`) that split the contact points
//! evenly by *multi-jagged* cuts (the generalization of recursive coordinate
//! bisection to an nx × ny × nz grid, as in Zoltan2's MJ): the box is cut along x
//! into nx slabs of equal counts, each slab along y into ny rows of equal counts (its
//! own cuts), each row along z into nz cells. A cell is still a box, numbered
//! `cx + nx (cy + ny cz)`.
//!
//! Cuts come from histograms of [`BINS_PER_CELL`] bins a cell over the bounds, one
//! per slab (per row along z): the k-th cut of a slab is the first bin edge where the
//! slab's cumulative count reaches k/n of its points. Counts are integers and the
//! bounds are exact once merged by min and max, so ranks that each count their own
//! contacts and add the histograms (one all-gather per cut axis) get the grid of one
//! process, bit for bit.
//!
//! ```
//! use nscdd::dd::Grid;
//! // points crowded at the bottom: the uniform cut is at mid-height, the balanced
//! // one at the points' median
//! let pts: Vec<[f64; 3]> = (0..100).map(|k| [0.5, if k < 90 { 0.001 * k as f64 } else { 1.0 }, 0.0]).collect();
//! let (lo, hi) = Grid::bounds(pts.iter().copied());
//! let uniform = Grid::from_bounds(lo, hi, 1, 2, 1);
//! let balanced = Grid::balanced_over(pts.iter().copied(), 1, 2, 1);
//! let count = |pts: &[[f64; 3]], g: &Grid, c: u32| pts.iter().filter(|&&p| g.cell_of(p) == c).count();
//! assert_eq!(count(&pts, &uniform, 0), 90);
//! // (up to a bin of the histogram: 1/128 of the height, 8 of the points here)
//! assert!((count(&pts, &balanced, 0) as i64 - 50).abs() <= 8);
//! // 2 × 2: the left half's points low, the right half's high; each half is cut
//! // at its own median height
//! let pts: Vec<[f64; 3]> = (0..400).map(|k| {
//!     let (x, t) = ((k % 2) as f64, (k / 2) as f64 / 200.0);
//!     [x, if k % 2 == 0 { 0.2 * t } else { 0.8 + 0.2 * t }, 0.0]
//! }).collect();
//! let g = Grid::balanced_over(pts.iter().copied(), 2, 2, 1);
//! for c in 0..4 {
//!     let n = count(&pts, &g, c);
//!     assert!((n as i64 - 100).abs() <= 8, "cell {c}: {n}");
//! }
//! ```

/// Histogram bins per cell along an axis ([`Grid::balanced`]).
pub const BINS_PER_CELL: usize = 64;

/// The grid of subdomains over the contact points' bounding box (nz = 1 in 2D,
/// whose points have z = 0).
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Grid {
    pub nx: u32,
    pub ny: u32,
    pub nz: u32,
    pub origin: [f64; 3],
    /// The size of a uniform cell (the bounds over n), per axis.
    pub cell: [f64; 3],
    /// Balanced grids: `cuts[0]` the nx − 1 cuts along x; `cuts[1]` each slab's
    /// ny − 1 cuts along y, slab after slab; `cuts[2]` each row's (cx + nx cy) nz − 1
    /// cuts along z. Empty along an axis: uniform cells (states written before
    /// balanced grids have none).
    #[serde(default, skip_serializing_if = "no_cuts")]
    pub cuts: [Vec<f64>; 3],
}

fn no_cuts(c: &[Vec<f64>; 3]) -> bool {
    c.iter().all(Vec::is_empty)
}

impl Grid {
    pub fn over(points: impl Iterator<Item = [f64; 3]>, nx: u32, ny: u32, nz: u32) -> Grid {
        let (lo, hi) = Grid::bounds(points);
        Grid::from_bounds(lo, hi, nx, ny, nz)
    }

    /// The balanced grid of `points` in one process (module docs).
    pub fn balanced_over(points: impl Iterator<Item = [f64; 3]> + Clone, nx: u32, ny: u32, nz: u32) -> Grid {
        let (lo, hi) = Grid::bounds(points.clone());
        Grid::balanced(lo, hi, [nx, ny, nz], || points.clone(), |h| h)
    }

    /// The bounds of the finite points (lo > hi without any).
    pub fn bounds(points: impl Iterator<Item = [f64; 3]>) -> ([f64; 3], [f64; 3]) {
        let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
        for p in points.filter(|p| p.iter().all(|x| x.is_finite())) {
            for d in 0..3 {
                lo[d] = lo[d].min(p[d]);
                hi[d] = hi[d].max(p[d]);
            }
        }
        (lo, hi)
    }

    /// The grid over the bounds of [`Grid::bounds`] (of points held by several
    /// processes: the bounds are exact once merged by min and max).
    pub fn from_bounds(mut lo: [f64; 3], mut hi: [f64; 3], nx: u32, ny: u32, nz: u32) -> Grid {
        let n = [nx.max(1), ny.max(1), nz.max(1)];
        if lo[0] > hi[0] {
            (lo, hi) = ([0.0; 3], [0.0; 3]);
        }
        Grid {
            nx: n[0],
            ny: n[1],
            nz: n[2],
            origin: lo,
            cell: std::array::from_fn(|d| (hi[d] - lo[d]) / n[d] as f64),
            cuts: Default::default(),
        }
    }

    /// The balanced grid over the bounds `[lo, hi]` (module docs) of the points that
    /// `points()` gives each time it is called; `add` adds a histogram over the
    /// processes (the identity in one process), once per cut axis.
    pub fn balanced<I: Iterator<Item = [f64; 3]>>(
        lo: [f64; 3],
        hi: [f64; 3],
        n: [u32; 3],
        points: impl Fn() -> I,
        mut add: impl FnMut(Vec<f64>) -> Vec<f64>,
    ) -> Grid {
        let mut g = Grid::from_bounds(lo, hi, n[0], n[1], n[2]);
        let n = [g.nx, g.ny, g.nz];
        for d in 0..3 {
            if n[d] < 2 || g.flat(d) {
                continue;
            }
            // one histogram per slab (d = 1) or row (d = 2)
            let (bins, groups) = (n[d] as usize * BINS_PER_CELL, n[..d].iter().product::<u32>() as usize);
            let width = g.cell[d] * n[d] as f64 / bins as f64;
            let mut hist = vec![0.0; groups * bins];
            for p in points().filter(|p| p.iter().all(|x| x.is_finite())) {
                let k = ((p[d] - g.origin[d]) / width).floor().max(0.0) as usize;
                hist[g.group(d, g.index_of(p)) * bins + k.min(bins - 1)] += 1.0;
            }
            let hist = add(hist);
            let mut cuts = Vec::with_capacity(groups * (n[d] as usize - 1));
            for h in hist.chunks_exact(bins) {
                cuts.extend(split(h, n[d]).into_iter().map(|e| g.origin[d] + e as f64 * width));
            }
            g.cuts[d] = cuts;
        }
        g
    }

    /// Along axis d, the slab (d = 1) or row (d = 2) of cell indices `i`: the
    /// histogram and the cuts of axis d that apply there (0 along x).
    fn group(&self, d: usize, i: [u32; 3]) -> usize {
        match d {
            0 => 0,
            1 => i[0] as usize,
            _ => (i[0] + self.nx * i[1]) as usize,
        }
    }

    /// The cuts of axis d in the slab or row of cell indices `i` (empty: uniform).
    fn row(&self, d: usize, i: [u32; 3]) -> &[f64] {
        let c = &self.cuts[d];
        if c.is_empty() {
            return c;
        }
        let m = [self.nx, self.ny, self.nz][d] as usize - 1;
        let g = self.group(d, i);
        &c[g * m..(g + 1) * m]
    }

    pub fn len(&self) -> usize {
        (self.nx * self.ny * self.nz) as usize
    }
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Whether the axis has no extent (or a NaN one): every point in its first cell.
    pub fn flat(&self, d: usize) -> bool {
        self.cell[d].is_nan() || self.cell[d] <= 0.0
    }

    /// The lower bound of cell `i[d]` along axis d (`i[d]` ≥ 1: an interior cut),
    /// in the slab or row of `i`.
    pub fn cut(&self, d: usize, i: [u32; 3]) -> f64 {
        match self.row(d, i).get(i[d] as usize - 1) {
            Some(&c) => c,
            None => self.origin[d] + i[d] as f64 * self.cell[d],
        }
    }

    /// The cell index of coordinate x along axis d in the slab or row of `i`,
    /// unclamped (below 0 or beyond the last cell for uniform cells, −1 below a
    /// balanced axis), NaN for NaN.
    pub fn axis_index(&self, d: usize, i: [u32; 3], x: f64) -> f64 {
        let row = self.row(d, i);
        if row.is_empty() {
            ((x - self.origin[d]) / self.cell[d]).floor()
        } else if x.is_nan() {
            f64::NAN
        } else if x < self.origin[d] {
            -1.0
        } else {
            row.partition_point(|&c| c <= x) as f64
        }
    }

    /// The cell indices (cx, cy, cz) of a point.
    pub fn index_of(&self, p: [f64; 3]) -> [u32; 3] {
        let n = [self.nx, self.ny, self.nz];
        let mut i = [0u32; 3];
        for d in 0..3 {
            // a flat box (or NaN) puts every point in the first cell
            if self.flat(d) {
                continue;
            }
            let k = self.axis_index(d, i, p[d]);
            i[d] = if k >= 0.0 { (k as u32).min(n[d] - 1) } else { 0 };
        }
        i
    }

    /// Subdomain id `cx + nx (cy + ny cz)` of a point.
    pub fn cell_of(&self, p: [f64; 3]) -> u32 {
        let i = self.index_of(p);
        i[0] + self.nx * (i[1] + self.ny * i[2])
    }
}

/// The interior cut edges (in bins) that split the counts `h` into `n` equal shares:
/// the first edge where the cumulative count reaches k/n, at least one bin a cell
/// (uniform edges without counts).
fn split(h: &[f64], n: u32) -> Vec<usize> {
    let (bins, total) = (h.len(), h.iter().sum::<f64>());
    let (mut acc, mut bin, mut prev) = (0.0, 0, 0);
    (1..n)
        .map(|k| {
            let edge = if total == 0.0 {
                k as usize * bins / n as usize
            } else {
                let share = total * k as f64 / n as f64;
                while bin < bins && acc < share {
                    acc += h[bin];
                    bin += 1;
                }
                bin
            };
            let edge = edge.max(prev + 1).min(bins - (n - k) as usize);
            prev = edge;
            edge
        })
        .collect()
}
