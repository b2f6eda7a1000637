//! The grid of subdomains over the contact points' bounding box: uniform cells, or
//! cells whose cuts along each axis split the contact points evenly (`[decomposition]
//! grid = "balanced"`).
//!
//! Balanced cuts come from a histogram per axis of [`BINS_PER_CELL`] bins a cell over
//! the bounds: the k-th cut of an axis with n cells is the first bin edge where the
//! cumulative count reaches k/n of the points. Counts are integers and the bounds are
//! exact once merged by min and max, so ranks that each count their own contacts and
//! add the histograms get the grid of one process, bit for bit. Along each axis
//! separately: with one axis cut (1 × 1 × 2: the median height of a pile) the cells
//! hold equal shares up to a bin; with several, a product of balanced marginals.
//!
//! ```
//! use nscdd::dd::Grid;
//! // points crowded at the bottom: the uniform cut is at mid-height, the balanced
//! // one at the points' median
//! let pts: Vec<[f64; 3]> = (0..100).map(|k| [0.5, if k < 90 { 0.001 * k as f64 } else { 1.0 }, 0.0]).collect();
//! let (lo, hi) = Grid::bounds(pts.iter().copied());
//! let uniform = Grid::from_bounds(lo, hi, 1, 2, 1);
//! let hist = Grid::histogram(lo, hi, [1, 2, 1], pts.iter().copied());
//! let balanced = Grid::balanced(lo, hi, 1, 2, 1, &hist);
//! let count = |g: &Grid| pts.iter().filter(|&&p| g.cell_of(p) == 0).count();
//! assert_eq!(count(&uniform), 90);
//! // (up to a bin of the histogram: 1/128 of the height, 8 of the points here)
//! assert!((count(&balanced) as i64 - 50).abs() <= 8);
//! ```

/// Histogram bins per cell along an axis ([`Grid::histogram`]).
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
    /// The interior cuts of each axis (n − 1 increasing positions), or none: uniform
    /// cells (states written before balanced grids have none).
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

    /// The grid whose cuts split `points` evenly along each axis (module docs).
    pub fn balanced_over(points: impl Iterator<Item = [f64; 3]> + Clone, nx: u32, ny: u32, nz: u32) -> Grid {
        let (lo, hi) = Grid::bounds(points.clone());
        let hist = Grid::histogram(lo, hi, [nx, ny, nz], points);
        Grid::balanced(lo, hi, nx, ny, nz, &hist)
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

    /// The bins of each axis' histogram: [`BINS_PER_CELL`] per cell, none along an
    /// axis of one cell.
    fn bins(n: [u32; 3]) -> [usize; 3] {
        n.map(|k| if k > 1 { k as usize * BINS_PER_CELL } else { 0 })
    }

    /// The histograms of the finite `points` over the bounds `[lo, hi]`, axis after
    /// axis (counts as f64: exact, and added over ranks as they are).
    pub fn histogram(lo: [f64; 3], hi: [f64; 3], n: [u32; 3], points: impl Iterator<Item = [f64; 3]>) -> Vec<f64> {
        let b = Grid::bins(n);
        let mut h = vec![0.0; b.iter().sum()];
        for p in points.filter(|p| p.iter().all(|x| x.is_finite())) {
            let mut at = 0;
            for d in 0..3 {
                if b[d] > 0 {
                    let w = hi[d] - lo[d];
                    let k = if w > 0.0 {
                        ((p[d] - lo[d]) / w * b[d] as f64).floor().max(0.0) as usize
                    } else {
                        0
                    };
                    h[at + k.min(b[d] - 1)] += 1.0;
                }
                at += b[d];
            }
        }
        h
    }

    /// The grid over `[lo, hi]` whose cuts split the counts of `hist` (the added
    /// [`Grid::histogram`]s of the points) evenly along each axis.
    pub fn balanced(lo: [f64; 3], hi: [f64; 3], nx: u32, ny: u32, nz: u32, hist: &[f64]) -> Grid {
        let mut g = Grid::from_bounds(lo, hi, nx, ny, nz);
        let n = [g.nx, g.ny, g.nz];
        let b = Grid::bins(n);
        let mut at = 0;
        for d in 0..3 {
            let h = &hist[at..at + b[d]];
            at += b[d];
            let total: f64 = h.iter().sum();
            if b[d] == 0 || total == 0.0 || !(g.cell[d] > 0.0) {
                continue;
            }
            let width = g.cell[d] * n[d] as f64 / b[d] as f64;
            let (mut acc, mut bin, mut prev) = (0.0, 0, 0);
            for k in 1..n[d] {
                let share = total * k as f64 / n[d] as f64;
                while bin < b[d] && acc < share {
                    acc += h[bin];
                    bin += 1;
                }
                // at least one bin a cell, so that cuts increase strictly
                let edge = bin.max(prev + 1).min(b[d] - (n[d] - k) as usize);
                prev = edge;
                g.cuts[d].push(g.origin[d] + edge as f64 * width);
            }
        }
        g
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

    /// The lower bound of cell k along axis d (k in 1..n: an interior cut).
    pub fn cut(&self, d: usize, k: u32) -> f64 {
        match self.cuts[d].get(k as usize - 1) {
            Some(&c) => c,
            None => self.origin[d] + k as f64 * self.cell[d],
        }
    }

    /// The cell index of coordinate x along axis d, unclamped above for uniform cells
    /// (the cells' own count then bounds it), NaN for NaN.
    pub fn axis_index(&self, d: usize, x: f64) -> f64 {
        if self.cuts[d].is_empty() {
            ((x - self.origin[d]) / self.cell[d]).floor()
        } else if x.is_nan() {
            f64::NAN
        } else if x < self.origin[d] {
            -1.0
        } else {
            self.cuts[d].partition_point(|&c| c <= x) as f64
        }
    }

    /// Subdomain id `cx + nx (cy + ny cz)` of a point.
    pub fn cell_of(&self, p: [f64; 3]) -> u32 {
        let c = |d: usize, n: u32| {
            // a flat box (or NaN) puts every point in the first cell
            if self.flat(d) {
                return 0;
            }
            let k = self.axis_index(d, p[d]);
            if k >= 0.0 {
                (k as u32).min(n - 1)
            } else {
                0
            }
        };
        c(0, self.nx) + self.nx * (c(1, self.ny) + self.ny * c(2, self.nz))
    }
}
