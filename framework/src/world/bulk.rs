//! What only 3D box samples measure: the bulk solid fraction and coordination
//! away from the walls (spheres cut by the inner box).

use crate::world::World3;

impl World3 {
    /// Measures away from the walls of a box sample, in the inner box shrunk by
    /// `margin` on every side (walls order the grains next to them, so the whole-box
    /// solid fraction of a sample of a few thousand grains is well below its bulk
    /// value): the solid fraction (the volume of the grain parts inside the inner box,
    /// each grain taken as the sphere of its volume: [`sphere_in_box`]) and the
    /// coordination number of the grains whose centres lie in
    /// it, rattlers excluded (grains with fewer than 2 loaded contacts, walls
    /// counted): `(nu_bulk, z_bulk, rattler fraction)`.
    pub fn bulk_measures(&self, margin: f64) -> Option<(f64, f64, f64)> {
        self.bulk_measures_with(margin, None, None)
    }

    /// The inner box of [`World3::bulk_measures`] (None when the margin leaves none).
    pub fn bulk_box(&self, margin: f64) -> Option<([f64; 3], [f64; 3])> {
        let e = self.box_extent()?;
        let lo = e.min.map(|x| x + margin);
        let hi = e.max.map(|x| x - margin);
        (0..3).all(|k| hi[k] > lo[k]).then_some((lo, hi))
    }

    /// The volume of grain b inside the box `[lo, hi]`, the grain taken as the sphere
    /// of its volume ([`sphere_in_box`]).
    pub fn grain_in_box(&self, b: usize, lo: [f64; 3], hi: [f64; 3]) -> f64 {
        let v = self.bodies.volume[b];
        // equivalent radius of the grain's volume
        let r = (3.0 * v / (4.0 * std::f64::consts::PI)).cbrt();
        sphere_in_box(self.bodies.pos[b], r, lo, hi)
    }

    /// [`World3::bulk_measures`], the coordination counts (Σ loaded contacts of the
    /// inner non-rattlers, their number, the inner grains, the inner rattlers) from
    /// `counts` when given (NSCDD's census, added over the subdomains), else from the
    /// world's contacts.
    pub fn bulk_measures_with(&self, margin: f64, counts: Option<[u64; 4]>, vol: Option<f64>) -> Option<(f64, f64, f64)> {
        let (lo, hi) = self.bulk_box(margin)?;
        let n = self.bodies.len();
        let inner = |b: usize| (0..3).all(|k| self.bodies.pos[b][k] > lo[k] && self.bodies.pos[b][k] < hi[k]);
        let vol = vol.unwrap_or_else(|| {
            let mut vol = 0.0;
            for b in (0..n).filter(|&b| self.is_grain(b)) {
                vol += self.grain_in_box(b, lo, hi);
            }
            vol
        });
        let [zsum, nz, ninner, rattlers] = counts.unwrap_or_else(|| {
            let count = self.loaded_contacts();
            let mut c = [0u64; 4];
            for b in (0..n).filter(|&b| self.is_grain(b) && inner(b)) {
                c[2] += 1;
                if count[b] >= 2 {
                    c[0] += count[b] as u64;
                    c[1] += 1;
                } else {
                    c[3] += 1;
                }
            }
            c
        });
        let v_in = (hi[0] - lo[0]) * (hi[1] - lo[1]) * (hi[2] - lo[2]);
        let z = if nz > 0 { zsum as f64 / nz as f64 } else { 0.0 };
        let rf = if ninner > 0 { rattlers as f64 / ninner as f64 } else { 0.0 };
        Some((vol / v_in, z, rf))
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
