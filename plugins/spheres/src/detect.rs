//! Narrow phases: sphere–sphere, sphere–plane and sphere–box. Each reports one
//! contact point, halfway across the gap, with the normal from the antagonist (the
//! second body) towards the candidate sphere.

use crate::shapes::{Boxes, Planes, Spheres};
use nscdd::dim::d3::dot;
use nscdd::dim::rotation::{rotate, rotate_inv};
use nscdd::dim::D3;
use nscdd::registry::{DetectCtx, PairDetector, RawContact3};

fn spheres<'a>(ctx: &'a DetectCtx<'_, D3>, first: bool) -> &'a Spheres {
    let s = if first { ctx.a } else { ctx.b };
    s.as_any().downcast_ref::<Spheres>().expect("sphere store")
}

/// Sphere–sphere: gap = |x_i − x_j| − r_i − r_j.
pub struct SphereSphere;

impl PairDetector<D3> for SphereSphere {
    fn detect(&self, ctx: &DetectCtx<'_, D3>, pairs: &[[u32; 2]], out: &mut Vec<RawContact3>) {
        let (sa, sb) = (spheres(ctx, true), spheres(ctx, false));
        let b = ctx.bodies;
        for &[i, j] in pairs {
            let (ri, rj) = (
                sa.radius[b.shape[i as usize].index as usize],
                sb.radius[b.shape[j as usize].index as usize],
            );
            let (xi, xj) = (b.pos[i as usize], b.pos[j as usize]);
            let d = [xi[0] - xj[0], xi[1] - xj[1], xi[2] - xj[2]];
            let dist = dot(d, d).sqrt();
            let gap = dist - ri - rj;
            if gap > ctx.alert || dist == 0.0 {
                continue;
            }
            let n = [d[0] / dist, d[1] / dist, d[2] / dist];
            let s = rj + 0.5 * gap;
            out.push(RawContact3 {
                i,
                j,
                feature: 0,
                point: [xj[0] + s * n[0], xj[1] + s * n[1], xj[2] + s * n[2]],
                normal: n,
                gap,
                area: 0.0,
            });
        }
    }
}

/// Sphere–plane: gap = n·(x_s − x_p) − r, n the plane's z axis.
pub struct SpherePlane;

impl PairDetector<D3> for SpherePlane {
    fn detect(&self, ctx: &DetectCtx<'_, D3>, pairs: &[[u32; 2]], out: &mut Vec<RawContact3>) {
        let sa = spheres(ctx, true);
        let _ = ctx.b.as_any().downcast_ref::<Planes>().expect("plane store");
        let b = ctx.bodies;
        for &[i, j] in pairs {
            let r = sa.radius[b.shape[i as usize].index as usize];
            let (xs, xp) = (b.pos[i as usize], b.pos[j as usize]);
            let n = rotate(b.rot[j as usize], [0.0, 0.0, 1.0]);
            let gap = dot(n, [xs[0] - xp[0], xs[1] - xp[1], xs[2] - xp[2]]) - r;
            if gap > ctx.alert {
                continue;
            }
            let s = r + 0.5 * gap;
            out.push(RawContact3 {
                i,
                j,
                feature: 0,
                point: [xs[0] - s * n[0], xs[1] - s * n[1], xs[2] - s * n[2]],
                normal: n,
                gap,
                area: 0.0,
            });
        }
    }
}

/// Sphere–box: the closest point of the box to the sphere's centre; a centre inside
/// the box is pushed out through the nearest face.
pub struct SphereBox;

impl PairDetector<D3> for SphereBox {
    fn detect(&self, ctx: &DetectCtx<'_, D3>, pairs: &[[u32; 2]], out: &mut Vec<RawContact3>) {
        let sa = spheres(ctx, true);
        let bx = ctx.b.as_any().downcast_ref::<Boxes>().expect("box store");
        let b = ctx.bodies;
        for &[i, j] in pairs {
            let r = sa.radius[b.shape[i as usize].index as usize];
            let h = bx.half[b.shape[j as usize].index as usize];
            let (xs, xb, q) = (b.pos[i as usize], b.pos[j as usize], b.rot[j as usize]);
            let c = rotate_inv(q, [xs[0] - xb[0], xs[1] - xb[1], xs[2] - xb[2]]);
            let cl = [c[0].clamp(-h[0], h[0]), c[1].clamp(-h[1], h[1]), c[2].clamp(-h[2], h[2])];
            let d = [c[0] - cl[0], c[1] - cl[1], c[2] - cl[2]];
            let dist = dot(d, d).sqrt();
            let (nl, gap) = if dist > 0.0 {
                ([d[0] / dist, d[1] / dist, d[2] / dist], dist - r)
            } else {
                // inside: the face of least penetration
                let mut k = 0;
                let mut pen = f64::INFINITY;
                for a in 0..3 {
                    let p = h[a] - c[a].abs();
                    if p < pen {
                        pen = p;
                        k = a;
                    }
                }
                let mut nl = [0.0; 3];
                nl[k] = if c[k] >= 0.0 { 1.0 } else { -1.0 };
                (nl, -pen - r)
            };
            if gap > ctx.alert {
                continue;
            }
            let n = rotate(q, nl);
            let s = r + 0.5 * gap;
            out.push(RawContact3 {
                i,
                j,
                feature: 0,
                point: [xs[0] - s * n[0], xs[1] - s * n[1], xs[2] - s * n[2]],
                normal: n,
                gap,
                area: 0.0,
            });
        }
    }
}
