//! A loaded 3D scene and its state: bodies, shapes, materials, laws, drives and the
//! contact set. Built by [`crate::scene::load3`], advanced by [`crate::engine3`].

use crate::detect3::{Detector3, DetectorTable3};
use crate::drive::DofDrive;
use crate::law::ContactLaw;
use crate::registry3::{RawContact3, ShapeStore3};
use crate::rigid3d::{Bodies3, Contacts3};
use crate::solver::SolverSettings;
use crate::world::{Material, TimeSettings};

/// The drives of one body, per degree of freedom (x, y, z, rx, ry, rz; rotations
/// about the world axes).
#[derive(Clone, Debug, PartialEq)]
pub struct BodyDrive3 {
    pub body: u32,
    pub dof: [Option<DofDrive>; 6],
}

/// The six walls of a box sample (x−, x+, y−, y+, z−, z+), for the solid fraction,
/// the stresses and ε1 (along z) of the history.
#[derive(Clone, Debug, PartialEq)]
pub struct BoxWalls3 {
    pub walls: [u32; 6],
    pub strain_from: f64,
}

/// The 3D scene in memory.
pub struct World3 {
    pub bodies: Bodies3,
    pub names: Vec<Option<String>>,
    pub shapes: Vec<Box<dyn ShapeStore3>>,
    pub materials: Vec<Material>,
    /// Law of each material pair, `laws[ma * nm + mb]`.
    pub laws: Vec<Option<ContactLaw>>,
    pub drives: Vec<BodyDrive3>,
    /// Which bodies are fixed (no degree of freedom ever moves).
    pub fixed: Vec<bool>,
    pub gravity: [f64; 3],
    pub time: TimeSettings,
    pub solver: SolverSettings,
    pub alert: f64,
    pub box_walls: Option<BoxWalls3>,
    /// Box height (z) when ε1 starts.
    pub box_h0: Option<f64>,
    pub detectors: DetectorTable3,
    pub t: f64,
    pub step: u64,
    pub contacts: Contacts3,
    /// Contact impulse resultant per body over the last step (N·s): force, moment.
    pub reaction: Vec<[f64; 6]>,
    pub(crate) scratch: Scratch3,
}

#[derive(Default)]
pub(crate) struct Scratch3 {
    pub detector: Detector3,
    pub raw: Vec<RawContact3>,
    pub v_begin: Vec<[f64; 6]>,
    pub order: Vec<u32>,
    pub prev_keys: Vec<crate::engine3::PrevContact>,
    pub next: Contacts3,
}

impl World3 {
    /// V⁻ of the step being solved (the velocities at its start).
    pub fn velocity_begin(&self) -> &[[f64; 6]] {
        &self.scratch.v_begin
    }
    /// The contact law between two materials (`None`: they do not interact).
    pub fn law(&self, ma: u16, mb: u16) -> Option<crate::law::ContactLaw> {
        self.laws[ma as usize * self.materials.len() + mb as usize]
    }
    pub fn kind_name(&self, b: usize) -> &'static str {
        self.shapes[self.bodies.shape[b].kind as usize].kind()
    }
    pub fn body_label(&self, b: usize) -> String {
        match &self.names[b] {
            Some(n) => format!("body {b} (`{n}`, {})", self.kind_name(b)),
            None => format!("body {b} ({})", self.kind_name(b)),
        }
    }
    /// Number of contacts carrying a normal impulse, per body.
    fn loaded_contacts(&self) -> Vec<u32> {
        let mut count = vec![0u32; self.bodies.len()];
        let c = &self.contacts;
        for a in 0..c.len() {
            if c.r[a][0] > 0.0 {
                for b in c.bodies[a] {
                    count[b as usize] += 1;
                }
            }
        }
        count
    }

    /// Whether body b is a grain (a movable body of a grain shape).
    pub fn is_grain(&self, b: usize) -> bool {
        let s = self.bodies.shape[b];
        self.shapes[s.kind as usize].is_grain() && !self.fixed[b] && !self.drives.iter().any(|d| d.body as usize == b)
    }
    /// Inner box [x0, x1, y0, y1, z0, z1] of the box sample from its walls' boxes.
    pub fn box_extent(&self) -> Option<[f64; 6]> {
        let bw = self.box_walls.as_ref()?;
        let bb = |b: u32| {
            let s = self.bodies.shape[b as usize];
            self.shapes[s.kind as usize].aabb(s.index, self.bodies.pos[b as usize], self.bodies.rot[b as usize])
        };
        let w = bw.walls;
        Some([
            bb(w[0]).max[0],
            bb(w[1]).min[0],
            bb(w[2]).max[1],
            bb(w[3]).min[1],
            bb(w[4]).max[2],
            bb(w[5]).min[2],
        ])
    }
    /// Σ grain volumes / box volume.
    pub fn solid_fraction(&self) -> Option<f64> {
        let e = self.box_extent()?;
        let v: f64 = (0..self.bodies.len())
            .filter(|&b| self.is_grain(b))
            .map(|b| self.bodies.volume[b])
            .sum();
        Some(v / ((e[1] - e[0]) * (e[3] - e[2]) * (e[5] - e[4])))
    }
    /// Mean stresses on the box walls (σ_xx, σ_yy, σ_zz), compression positive, from
    /// the last step's reactions (impulse / h over the wall area).
    pub fn box_stresses(&self) -> Option<[f64; 3]> {
        let e = self.box_extent()?;
        let bw = self.box_walls.as_ref()?;
        let h = self.time.h;
        let f = |b: u32, k: usize| self.reaction.get(b as usize).map_or(0.0, |r| r[k]) / h;
        let (lx, ly, lz) = (e[1] - e[0], e[3] - e[2], e[5] - e[4]);
        let w = bw.walls;
        Some([
            0.5 * (f(w[1], 0) - f(w[0], 0)) / (ly * lz),
            0.5 * (f(w[3], 1) - f(w[2], 1)) / (lx * lz),
            0.5 * (f(w[5], 2) - f(w[4], 2)) / (lx * ly),
        ])
    }
    /// Coordination numbers over the grains: `z` = 2 N_c / N_g with N_c the
    /// grain–grain contacts carrying a normal impulse, and `z_m`, the same without the
    /// rattlers (grains with fewer than 2 loaded contacts, walls included), counting
    /// grain–grain contacts between non-rattlers and the non-rattlers' wall contacts
    /// once.
    pub fn coordination(&self) -> (f64, f64) {
        let n = self.bodies.len();
        let grain: Vec<bool> = (0..n).map(|b| self.is_grain(b)).collect();
        let count = self.loaded_contacts();
        let c = &self.contacts;
        let ng = grain.iter().filter(|&&g| g).count();
        let mut ngg = 0usize;
        let (mut sum_m, mut n_m) = (0usize, 0usize);
        for a in 0..c.len() {
            if c.r[a][0] > 0.0 {
                let [i, j] = c.bodies[a];
                let (i, j) = (i as usize, j as usize);
                if grain[i] && grain[j] {
                    ngg += 1;
                }
            }
        }
        for b in 0..n {
            if grain[b] && count[b] >= 2 {
                n_m += 1;
                sum_m += count[b] as usize;
            }
        }
        let z = if ng > 0 { 2.0 * ngg as f64 / ng as f64 } else { 0.0 };
        let z_m = if n_m > 0 { sum_m as f64 / n_m as f64 } else { 0.0 };
        (z, z_m)
    }
    /// Measures away from the walls of a box sample, in the inner box shrunk by
    /// `margin` on every side (walls order the grains next to them, so the whole-box
    /// solid fraction of a sample of a few thousand grains is well below its bulk
    /// value): the solid fraction (the volume of the grain parts inside the inner box,
    /// each grain taken as the sphere of its volume: [`sphere_in_box`]) and the
    /// coordination number of the grains whose centres lie in
    /// it, rattlers excluded (grains with fewer than 2 loaded contacts, walls
    /// counted): `(nu_bulk, z_bulk, rattler fraction)`.
    pub fn bulk_measures(&self, margin: f64) -> Option<(f64, f64, f64)> {
        let e = self.box_extent()?;
        let lo = [e[0] + margin, e[2] + margin, e[4] + margin];
        let hi = [e[1] - margin, e[3] - margin, e[5] - margin];
        if (0..3).any(|k| hi[k] <= lo[k]) {
            return None;
        }
        let n = self.bodies.len();
        let count = self.loaded_contacts();
        let (mut vol, mut zsum, mut nz, mut ninner, mut rattlers) = (0.0, 0u64, 0u64, 0u64, 0u64);
        for b in 0..n {
            if !self.is_grain(b) {
                continue;
            }
            let x = self.bodies.pos[b];
            let v = self.bodies.volume[b];
            // equivalent radius of the grain's volume
            let r = (3.0 * v / (4.0 * std::f64::consts::PI)).cbrt();
            vol += sphere_in_box(x, r, lo, hi);
            if (0..3).all(|k| x[k] > lo[k] && x[k] < hi[k]) {
                ninner += 1;
                if count[b] >= 2 {
                    zsum += count[b] as u64;
                    nz += 1;
                } else {
                    rattlers += 1;
                }
            }
        }
        let v_in = (hi[0] - lo[0]) * (hi[1] - lo[1]) * (hi[2] - lo[2]);
        let z = if nz > 0 { zsum as f64 / nz as f64 } else { 0.0 };
        let rf = if ninner > 0 { rattlers as f64 / ninner as f64 } else { 0.0 };
        Some((vol / v_in, z, rf))
    }

    /// The largest grain size (radius of a sphere), for the bulk margin.
    pub fn max_grain_size(&self) -> f64 {
        (0..self.bodies.len())
            .filter(|&b| self.is_grain(b))
            .map(|b| {
                let s = self.bodies.shape[b];
                self.shapes[s.kind as usize].size(s.index)
            })
            .fold(0.0, f64::max)
    }

    /// Kinetic energy and gravity potential of the movable bodies.
    pub fn energies(&self) -> (f64, f64) {
        let (mut ek, mut ep) = (0.0, 0.0);
        let b = &self.bodies;
        for k in 0..b.len() {
            if !b.movable(k) {
                continue;
            }
            let v = b.vel[k];
            let m = b.mass[k];
            let iw = b.world_inertia(k);
            let w = [v[3], v[4], v[5]];
            let iwv = crate::dim::coulomb3::mul(&iw, w);
            ek += 0.5 * m * (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]) + 0.5 * (w[0] * iwv[0] + w[1] * iwv[1] + w[2] * iwv[2]);
            let x = b.pos[k];
            ep -= m * (self.gravity[0] * x[0] + self.gravity[1] * x[1] + self.gravity[2] * x[2]);
        }
        (ek, ep)
    }
}

/// Volume of the part of the sphere (centre c, radius r) inside the box [lo, hi]:
/// exact when at most one face cuts it (the sphere minus a cap of height h,
/// π h² (3r − h)/3), by a 40 × 40 midpoint quadrature of the slices' chord lengths
/// otherwise (relative error about 1e-4 of the sphere's volume, on the few spheres
/// at the box's edges).
pub fn sphere_in_box(c: [f64; 3], r: f64, lo: [f64; 3], hi: [f64; 3]) -> f64 {
    let v = 4.0 / 3.0 * std::f64::consts::PI * r * r * r;
    let mut cuts = 0;
    let mut cap = 0.0;
    for k in 0..3 {
        if c[k] + r <= lo[k] || c[k] - r >= hi[k] {
            return 0.0;
        }
        for d in [c[k] - lo[k], hi[k] - c[k]] {
            if d < r {
                cuts += 1;
                let h = r - d;
                cap += std::f64::consts::PI * h * h * (3.0 * r - h) / 3.0;
            }
        }
    }
    if cuts <= 1 {
        return v - cap;
    }
    const N: usize = 40;
    let (z0, z1) = (lo[2].max(c[2] - r), hi[2].min(c[2] + r));
    let dz = (z1 - z0) / N as f64;
    let mut total = 0.0;
    for iz in 0..N {
        let z = z0 + (iz as f64 + 0.5) * dz;
        let rho2 = r * r - (z - c[2]) * (z - c[2]);
        if rho2 <= 0.0 {
            continue;
        }
        let rho = rho2.sqrt();
        let (x0, x1) = (lo[0].max(c[0] - rho), hi[0].min(c[0] + rho));
        if x1 <= x0 {
            continue;
        }
        let dx = (x1 - x0) / N as f64;
        let mut area = 0.0;
        for ix in 0..N {
            let x = x0 + (ix as f64 + 0.5) * dx;
            let e2 = rho2 - (x - c[0]) * (x - c[0]);
            if e2 > 0.0 {
                let e = e2.sqrt();
                area += (hi[1].min(c[1] + e) - lo[1].max(c[1] - e)).max(0.0);
            }
        }
        total += area * dx;
    }
    total * dz
}

#[cfg(test)]
mod tests {
    use super::sphere_in_box;
    #[test]
    fn sphere_box_volumes() {
        let v = 4.0 / 3.0 * std::f64::consts::PI;
        let big = [10.0; 3];
        assert_eq!(sphere_in_box([0.0; 3], 1.0, [-10.0; 3], big), v);
        // half, quarter and eighth spheres
        assert!((sphere_in_box([0.0; 3], 1.0, [0.0, -10.0, -10.0], big) - v / 2.0).abs() < 1e-12);
        assert!((sphere_in_box([0.0; 3], 1.0, [0.0, 0.0, -10.0], big) - v / 4.0).abs() < 2e-4 * v);
        assert!((sphere_in_box([0.0; 3], 1.0, [0.0, 0.0, 0.0], big) - v / 8.0).abs() < 2e-4 * v);
        assert_eq!(sphere_in_box([0.0; 3], 1.0, [2.0, -10.0, -10.0], big), 0.0);
    }
}
