//! Generators of sphere samples: a polydisperse random packing in a box or a
//! cylinder (random sequential addition), and a cubic lattice. All take `material`;
//! the random one takes `seed` and gives the same sample on every machine (ChaCha8).

use crate::shapes::Spheres;
use nscdd::dim::D3;
use nscdd::model::ShapeRef;
use nscdd::params::{array, count, only_keys, positive};
use nscdd::registry::Generator;
use nscdd::registry::ParamError;
use nscdd::scene::builder::SceneBuilder3;
use rand::{RngExt, SeedableRng};

fn add_sphere(out: &mut SceneBuilder3<'_>, kind: u16, material: u16, r: f64, x: [f64; 3]) {
    let store = out.store_mut::<Spheres>(kind).expect("sphere store");
    store.radius.push(r);
    let index = store.radius.len() as u32 - 1;
    out.add_body(ShapeRef { kind, index }, material, x, [0.0; 3], [0.0; 6]);
}

/// `sphere_packing`: `count` spheres with radii uniform in [`radius_min`,
/// `radius_max`], placed at random without overlap (random sequential addition:
/// each sphere tries up to `attempts` random positions, default 1000) inside
/// `box = [x0, y0, z0, x1, y1, z1]` or `cylinder = [cx, cy, radius, z0, z1]` (axis
/// along z). Loose (solid fraction up to about 0.3): compact it with walls or let it
/// fall. Larger spheres are placed first. Fails, naming `count`, when the region
/// cannot hold the spheres.
pub struct SpherePacking;

impl Generator<D3> for SpherePacking {
    fn generate(&self, p: &toml::Table, out: &mut SceneBuilder3<'_>) -> Result<(), ParamError> {
        only_keys(
            p,
            &[
                "kind",
                "material",
                "count",
                "radius_min",
                "radius_max",
                "box",
                "cylinder",
                "seed",
                "attempts",
            ],
        )?;
        let material = out.material_param(p, "material")?;
        let n = count(p, "count", None)? as usize;
        let rmin = positive(p, "radius_min", None)?;
        let rmax = positive(p, "radius_max", Some(rmin))?;
        if rmax < rmin {
            return Err(ParamError::new("radius_max", format!("must be ≥ radius_min ({rmin}), got {rmax}")));
        }
        let seed = count(p, "seed", Some(0))?;
        let attempts = count(p, "attempts", Some(1000))?.max(1);
        // the region: bounding box and an inside test for a sphere of radius r
        let (lo, hi, cyl) = region(p)?;
        // a grid of cells of size 2 rmax: a sphere's neighbours lie in the 27 cells around it
        let cell = 2.0 * rmax;
        let dims: [f64; 3] = std::array::from_fn(|k| ((hi[k] - lo[k]) / cell).ceil().max(1.0));
        out.reserve("count", n as f64, 0.0)?;
        let region = if p.contains_key("box") { "box" } else { "cylinder" };
        out.reserve(region, 0.0, dims.iter().product::<f64>() * std::mem::size_of::<Vec<u32>>() as f64)?;
        let dims = dims.map(|d| d as usize);
        let kind = out.kind(Spheres::KIND).expect("the plugin registers spheres");
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
        let mut radii: Vec<f64> = (0..n).map(|_| rmin + (rmax - rmin) * rng.random::<f64>()).collect();
        radii.sort_by(|a, b| b.total_cmp(a));
        let cidx = |x: [f64; 3]| -> [usize; 3] { std::array::from_fn(|k| (((x[k] - lo[k]) / cell) as usize).min(dims[k] - 1)) };
        let mut grid: Vec<Vec<u32>> = vec![Vec::new(); dims[0] * dims[1] * dims[2]];
        let mut placed: Vec<([f64; 3], f64)> = Vec::with_capacity(n);
        for (k, &r) in radii.iter().enumerate() {
            let mut ok = None;
            for _ in 0..attempts {
                let x: [f64; 3] = std::array::from_fn(|a| lo[a] + r + (hi[a] - lo[a] - 2.0 * r).max(0.0) * rng.random::<f64>());
                if let Some((cx, cy, cr)) = cyl {
                    let (dx, dy) = (x[0] - cx, x[1] - cy);
                    if (dx * dx + dy * dy).sqrt() > cr - r {
                        continue;
                    }
                }
                let c = cidx(x);
                let mut free = true;
                'n: for z in c[2].saturating_sub(1)..=(c[2] + 1).min(dims[2] - 1) {
                    for y in c[1].saturating_sub(1)..=(c[1] + 1).min(dims[1] - 1) {
                        for xx in c[0].saturating_sub(1)..=(c[0] + 1).min(dims[0] - 1) {
                            for &q in &grid[(z * dims[1] + y) * dims[0] + xx] {
                                let (pq, rq) = placed[q as usize];
                                let d2 = (0..3).map(|a| (x[a] - pq[a]).powi(2)).sum::<f64>();
                                if d2 < (r + rq) * (r + rq) {
                                    free = false;
                                    break 'n;
                                }
                            }
                        }
                    }
                }
                if free {
                    ok = Some(x);
                    break;
                }
            }
            let Some(x) = ok else {
                return Err(ParamError::new(
                    "count",
                    format!("placed only {k} of the {n} spheres asked in {attempts} attempts each: enlarge the region or lower `count`"),
                ));
            };
            let c = cidx(x);
            grid[(c[2] * dims[1] + c[1]) * dims[0] + c[0]].push(placed.len() as u32);
            placed.push((x, r));
        }
        for (x, r) in placed {
            add_sphere(out, kind, material, r, x);
        }
        Ok(())
    }
}

/// The region of a packing: its bounding box and, for a cylinder, (cx, cy, radius).
#[allow(clippy::type_complexity)]
fn region(p: &toml::Table) -> Result<([f64; 3], [f64; 3], Option<(f64, f64, f64)>), ParamError> {
    Ok(match (p.get("box"), p.get("cylinder")) {
        (Some(_), None) => {
            let b = array::<6>(p, "box", None)?;
            if !(b[3] > b[0] && b[4] > b[1] && b[5] > b[2]) {
                return Err(ParamError::new(
                    "box",
                    "expected [x0, y0, z0, x1, y1, z1] with x1 > x0, y1 > y0, z1 > z0",
                ));
            }
            ([b[0], b[1], b[2]], [b[3], b[4], b[5]], None)
        }
        (None, Some(_)) => {
            let c = array::<5>(p, "cylinder", None)?;
            if !(c[2] > 0.0 && c[4] > c[3]) {
                return Err(ParamError::new(
                    "cylinder",
                    "expected [cx, cy, radius, z0, z1] with radius > 0 and z1 > z0",
                ));
            }
            (
                [c[0] - c[2], c[1] - c[2], c[3]],
                [c[0] + c[2], c[1] + c[2], c[4]],
                Some((c[0], c[1], c[2])),
            )
        }
        _ => return Err(ParamError::new("box", "give exactly one of `box` or `cylinder`")),
    })
}

/// `sphere_lattice`: `nx × ny × nz` spheres of `radius` on a cubic lattice of
/// `spacing` (default 2 × radius: touching) from `origin` (the first centre).
pub struct SphereLattice;

impl Generator<D3> for SphereLattice {
    fn generate(&self, p: &toml::Table, out: &mut SceneBuilder3<'_>) -> Result<(), ParamError> {
        only_keys(p, &["kind", "material", "nx", "ny", "nz", "radius", "spacing", "origin"])?;
        let material = out.material_param(p, "material")?;
        let (nx, ny, nz) = (count(p, "nx", None)?, count(p, "ny", Some(1))?, count(p, "nz", Some(1))?);
        out.reserve("nx", nx as f64 * ny as f64 * nz as f64, 0.0)?;
        let r = positive(p, "radius", None)?;
        let s = positive(p, "spacing", Some(2.0 * r))?;
        let o = array::<3>(p, "origin", Some([0.0; 3]))?;
        let kind = out.kind(Spheres::KIND).expect("the plugin registers spheres");
        for k in 0..nz {
            for j in 0..ny {
                for i in 0..nx {
                    add_sphere(
                        out,
                        kind,
                        material,
                        r,
                        [o[0] + i as f64 * s, o[1] + j as f64 * s, o[2] + k as f64 * s],
                    );
                }
            }
        }
        Ok(())
    }
}
