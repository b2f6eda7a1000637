//! Generators of disk samples: a polydisperse random deposit in a box and square
//! and triangular lattices. All take `material`; random ones take `seed` and give
//! the same sample for the same seed on every machine (ChaCha8).

use crate::shapes::Disks;
use nscdd::dim::D2;
use nscdd::model::ShapeRef;
use nscdd::params::{array, count, number, only_keys, positive};
use nscdd::registry::{Generator, ParamError};
use nscdd::scene::builder::SceneBuilder2;
use rand::{RngExt, SeedableRng};

fn add_disk(out: &mut SceneBuilder2<'_>, kind: u16, material: u16, r: f64, x: [f64; 2]) {
    let store = out.store_mut::<Disks>(kind).expect("disk store");
    store.radius.push(r);
    let index = store.radius.len() as u32 - 1;
    out.add_body(ShapeRef { kind, index }, material, x, 0.0, [0.0; 3]);
}

/// `disk_deposit`: `count` disks with radii uniform in [`radius_min`, `radius_max`]
/// deposited one by one into `box = [x0, y0, x1, y1]` by the geometric
/// drop-and-roll rule (Visscher & Bolsterli 1972): each disk falls straight down at a
/// random abscissa until it touches the floor y0 or a disk already placed, then rolls
/// down over that disk until it rests on two disks that straddle it, on the floor or
/// against a side of the box (and falls again if it rolls past a disk's equator).
/// The sample is dense but not in static equilibrium; let it settle under gravity,
/// or compact it with walls. Fails if the box cannot hold `count` disks.
pub struct DiskDeposit;

/// Placed disks, binned by columns of width 2 `rmax` for neighbour queries.
struct Deposit {
    x0: f64,
    y0: f64,
    x1: f64,
    cw: f64,
    rmax: f64,
    cols: Vec<Vec<usize>>,
    placed: Vec<([f64; 2], f64)>,
}

impl Deposit {
    fn col(&self, x: f64) -> usize {
        (((x - self.x0) / self.cw).floor().max(0.0) as usize).min(self.cols.len() - 1)
    }
    /// Indices of the placed disks whose centres lie within `reach` of abscissa x.
    fn near(&self, x: f64, reach: f64) -> impl Iterator<Item = usize> + '_ {
        let (c0, c1) = (self.col(x - reach), self.col(x + reach));
        self.cols[c0..=c1].iter().flatten().copied()
    }
    /// Falls from c down to the first support: (resting centre, supporting disk).
    fn fall(&self, c: [f64; 2], r: f64) -> ([f64; 2], Option<usize>) {
        let mut best = (self.y0 + r, None);
        for q in self.near(c[0], r + self.rmax) {
            let (p, rq) = self.placed[q];
            let (dx, s) = (c[0] - p[0], r + rq);
            if dx.abs() < s {
                let y = p[1] + (s * s - dx * dx).sqrt();
                if y <= c[1] + 1e-12 * s && y > best.0 {
                    best = (y, Some(q));
                }
            }
        }
        ([c[0], best.0], best.1)
    }
    /// Drops a disk of radius r at abscissa x and lets it roll to rest.
    fn settle(&self, x: f64, r: f64, tie: f64) -> [f64; 2] {
        let (mut c, mut support) = self.fall([x, f64::INFINITY], r);
        for _ in 0..200 {
            let Some(j) = support else { return c };
            let (pj, rj) = self.placed[j];
            let big_r = r + rj;
            let (dx, dy) = (c[0] - pj[0], c[1] - pj[1]);
            if dy < 0.0 {
                return c; // held from the side under an overhang
            }
            let dir = if dx > 0.0 {
                1.0
            } else if dx < 0.0 {
                -1.0
            } else {
                tie
            };
            let th0 = dx.atan2(dy) * dir; // angle from the vertical, positive downhill
            let pos = |th: f64| [pj[0] + dir * big_r * th.sin(), pj[1] + big_r * th.cos()];
            // first event along the arc th0 → π/2: a disk, a side, the floor
            let mut ev: (f64, Option<usize>) = (std::f64::consts::FRAC_PI_2, None);
            let side = if dir > 0.0 { self.x1 - r - pj[0] } else { pj[0] - (self.x0 + r) };
            if side / big_r < 1.0 {
                let th = (side / big_r).max(-1.0).asin();
                if th > th0 && th < ev.0 {
                    ev = (th, Some(usize::MAX));
                }
            }
            let fl = (self.y0 + r - pj[1]) / big_r;
            if (0.0..1.0).contains(&fl) {
                let th = fl.acos();
                if th > th0 && th < ev.0 {
                    ev = (th, Some(usize::MAX));
                }
            }
            for k in self.near(pj[0], big_r + r + self.rmax) {
                if k == j {
                    continue;
                }
                let (pk, rk) = self.placed[k];
                let s = r + rk;
                let d = ((pk[0] - pj[0]).powi(2) + (pk[1] - pj[1]).powi(2)).sqrt();
                if d > big_r + s || d < (big_r - s).abs() || d == 0.0 {
                    continue;
                }
                let a = (big_r * big_r - s * s + d * d) / (2.0 * d);
                let h = (big_r * big_r - a * a).max(0.0).sqrt();
                let e = [(pk[0] - pj[0]) / d, (pk[1] - pj[1]) / d];
                for sg in [1.0, -1.0] {
                    let q = [a * e[0] - sg * h * e[1], a * e[1] + sg * h * e[0]];
                    let th = (q[0] * dir).atan2(q[1]);
                    if th > th0 + 1e-9 && th < ev.0 {
                        ev = (th, Some(k));
                    }
                }
            }
            c = pos(ev.0);
            match ev.1 {
                None => {
                    // past the equator: fall again
                    c[0] += dir * 1e-9 * big_r;
                    (c, support) = self.fall(c, r);
                }
                Some(usize::MAX) => return c,
                Some(k) => {
                    let pk = self.placed[k].0;
                    if (pj[0] - c[0]) * (pk[0] - c[0]) <= 0.0 {
                        return c; // two supports straddle it
                    }
                    support = Some(k);
                }
            }
        }
        c
    }
}

impl Generator<D2> for DiskDeposit {
    fn generate(&self, p: &toml::Table, out: &mut SceneBuilder2<'_>) -> Result<(), ParamError> {
        only_keys(p, &["material", "count", "radius_min", "radius_max", "box", "seed"])?;
        let material = out.material_param(p, "material")?;
        let n = count(p, "count", None)? as usize;
        let rmin = positive(p, "radius_min", None)?;
        let rmax = positive(p, "radius_max", Some(rmin))?;
        if rmax < rmin {
            return Err(ParamError::new("radius_max", "must be ≥ radius_min"));
        }
        let [x0, y0, x1, y1] = array::<4>(p, "box", None)?;
        if x1 - x0 < 2.0 * rmax || y1 <= y0 {
            return Err(ParamError::new(
                "box",
                "the box [x0, y0, x1, y1] must be wider than a disk and have y1 > y0",
            ));
        }
        let seed = count(p, "seed", Some(0))?;
        let cw = 2.0 * rmax;
        let ncol = ((x1 - x0) / cw).ceil() + 1.0;
        out.reserve("count", n as f64, 0.0)?;
        out.reserve("box", 0.0, ncol * std::mem::size_of::<Vec<usize>>() as f64)?;
        let ncol = ncol as usize;
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
        let Some(kind) = out.kind(Disks::KIND) else {
            return Err(ParamError::new("kind", "the disk shape kind is not installed"));
        };
        let mut dep = Deposit {
            x0,
            y0,
            x1,
            cw,
            rmax,
            cols: vec![vec![]; ncol],
            placed: Vec::with_capacity(n),
        };
        for k in 0..n {
            let r = if rmax > rmin { rng.random_range(rmin..rmax) } else { rmin };
            let x = rng.random_range((x0 + r)..=(x1 - r));
            let tie = if rng.random::<bool>() { 1.0 } else { -1.0 };
            let c = dep.settle(x, r, tie);
            if c[1] + r > y1 {
                return Err(ParamError::new(
                    "count",
                    format!("the box holds only {k} of the {n} disks asked: make it taller"),
                ));
            }
            let col = dep.col(c[0]);
            dep.cols[col].push(dep.placed.len());
            dep.placed.push((c, r));
        }
        for (x, r) in dep.placed {
            add_disk(out, kind, material, r, x);
        }
        Ok(())
    }
}

fn lattice(p: &toml::Table, out: &mut SceneBuilder2<'_>, triangular: bool) -> Result<(), ParamError> {
    only_keys(p, &["material", "nx", "ny", "radius", "spacing", "origin"])?;
    let material = out.material_param(p, "material")?;
    let (nx, ny) = (count(p, "nx", None)?, count(p, "ny", None)?);
    out.reserve("nx", nx as f64 * ny as f64, 0.0)?;
    let r = positive(p, "radius", None)?;
    let s = number(p, "spacing", Some(2.0 * r))?;
    if s < 2.0 * r * (1.0 - 1e-12) {
        return Err(ParamError::new("spacing", format!("must be ≥ 2 × radius = {}", 2.0 * r)));
    }
    let o = array::<2>(p, "origin", Some([0.0, 0.0]))?;
    let kind = out.kind(Disks::KIND).expect("plugin shape");
    let dy = if triangular { s * 3f64.sqrt() / 2.0 } else { s };
    for iy in 0..ny {
        let shift = if triangular && iy % 2 == 1 { 0.5 * s } else { 0.0 };
        for ix in 0..nx {
            add_disk(out, kind, material, r, [o[0] + shift + ix as f64 * s, o[1] + iy as f64 * dy]);
        }
    }
    Ok(())
}

/// `square_lattice`: `nx` × `ny` disks of `radius`, centres `spacing` apart
/// (default 2 × radius: touching), the first at `origin`.
pub struct SquareLattice;
impl Generator<D2> for SquareLattice {
    fn generate(&self, p: &toml::Table, out: &mut SceneBuilder2<'_>) -> Result<(), ParamError> {
        lattice(p, out, false)
    }
}

/// `triangular_lattice`: rows of `nx` disks, every other row shifted by half a
/// spacing, rows spacing·√3/2 apart (touching by default: the densest packing).
pub struct TriangularLattice;
impl Generator<D2> for TriangularLattice {
    fn generate(&self, p: &toml::Table, out: &mut SceneBuilder2<'_>) -> Result<(), ParamError> {
        lattice(p, out, true)
    }
}
