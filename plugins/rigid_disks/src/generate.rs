//! Generators of disk samples: a polydisperse random deposit in a box and square
//! and triangular lattices. All take `material`; random ones take `seed` and give
//! the same sample for the same seed on every machine (ChaCha8).

use crate::shapes::Disks;
use nscdd::params::{array, count, number, only_keys, positive};
use nscdd::registry::{Generator2, ParamError};
use nscdd::rigid2d::bodies::ShapeRef;
use nscdd::scene::builder::SceneBuilder2;
use rand::{RngExt, SeedableRng};

fn add_disk(out: &mut SceneBuilder2<'_>, kind: u16, material: u16, r: f64, x: [f64; 2]) {
    let store = out.store_mut::<Disks>(kind).expect("disk store");
    store.radius.push(r);
    let index = store.radius.len() as u32 - 1;
    out.add_body(ShapeRef { kind, index }, material, x, 0.0, [0.0; 3]);
}

/// `disk_deposit`: `count` disks with radii uniform in [`radius_min`, `radius_max`]
/// dropped one by one at a random abscissa into `box = [x0, y0, x1, y1]`, each
/// falling straight down until it touches the floor y0 or a disk already placed
/// (ballistic deposition). The sample is loose; let it settle under gravity, or
/// compact it with walls. Fails if the box cannot hold `count` disks.
pub struct DiskDeposit;

impl Generator2 for DiskDeposit {
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
            return Err(ParamError::new("box", "the box [x0, y0, x1, y1] must be wider than a disk and have y1 > y0"));
        }
        let seed = count(p, "seed", Some(0))?;
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
        let kind = out.kind(Disks::KIND).expect("plugin shape");
        // columns of width 2 rmax hold the indices of the placed disks
        let cw = 2.0 * rmax;
        let ncol = ((x1 - x0) / cw).ceil() as usize + 1;
        let mut cols: Vec<Vec<usize>> = vec![vec![]; ncol];
        let mut placed: Vec<([f64; 2], f64)> = Vec::with_capacity(n);
        for k in 0..n {
            let r = if rmax > rmin { rng.random_range(rmin..rmax) } else { rmin };
            let x = rng.random_range((x0 + r)..=(x1 - r));
            let mut y = y0 + r;
            let c0 = (((x - r - rmax - x0) / cw).floor().max(0.0) as usize).min(ncol - 1);
            let c1 = (((x + r + rmax - x0) / cw).floor().max(0.0) as usize).min(ncol - 1);
            for col in &cols[c0..=c1] {
                for &q in col {
                    let (c, rq) = placed[q];
                    let dx = x - c[0];
                    let s = r + rq;
                    if dx.abs() < s {
                        y = y.max(c[1] + (s * s - dx * dx).sqrt());
                    }
                }
            }
            if y + r > y1 {
                return Err(ParamError::new("count", format!("the box holds only {k} of the {n} disks asked: make it taller")));
            }
            let col = (((x - x0) / cw).floor().max(0.0) as usize).min(ncol - 1);
            cols[col].push(placed.len());
            placed.push(([x, y], r));
        }
        for (x, r) in placed {
            add_disk(out, kind, material, r, x);
        }
        Ok(())
    }
}

fn lattice(p: &toml::Table, out: &mut SceneBuilder2<'_>, triangular: bool) -> Result<(), ParamError> {
    only_keys(p, &["material", "nx", "ny", "radius", "spacing", "origin"])?;
    let material = out.material_param(p, "material")?;
    let (nx, ny) = (count(p, "nx", None)?, count(p, "ny", None)?);
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
impl Generator2 for SquareLattice {
    fn generate(&self, p: &toml::Table, out: &mut SceneBuilder2<'_>) -> Result<(), ParamError> {
        lattice(p, out, false)
    }
}

/// `triangular_lattice`: rows of `nx` disks, every other row shifted by half a
/// spacing, rows spacing·√3/2 apart (touching by default: the densest packing).
pub struct TriangularLattice;
impl Generator2 for TriangularLattice {
    fn generate(&self, p: &toml::Table, out: &mut SceneBuilder2<'_>) -> Result<(), ParamError> {
        lattice(p, out, true)
    }
}
