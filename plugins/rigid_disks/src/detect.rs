//! Narrow phases: disk–disk, disk–wall, disk–half-plane, wall–wall, wall–half-plane.
//!
//! Every narrow phase returns the gap g (signed distance between the surfaces), the
//! unit normal n from the antagonist j to the candidate i, and the contact point p
//! half-way across the gap. Walls are capsules (points at thickness/2 from their
//! centre segment), so disk–wall and wall–wall reduce to closest points between a
//! point or a segment and a segment.

use crate::shapes::{Disks, HalfPlanes, Walls};
use nalgebra::Vector2;
use nscdd::dim::D2;
use nscdd::registry::{DetectCtx, PairDetector, RawContact2};

type V = Vector2<f64>;

fn v(a: [f64; 2]) -> V {
    V::new(a[0], a[1])
}

/// Contact between two rounded features: closest points `pi` on i and `pj` on j of
/// the cores, with radii `ri`, `rj`. `None` beyond the alert distance.
#[inline]
fn rounded(i: u32, j: u32, feature: u32, pi: V, pj: V, ri: f64, rj: f64, alert: f64) -> Option<RawContact2> {
    let d = pi - pj;
    let dist = d.norm();
    let gap = dist - ri - rj;
    if gap > alert {
        return None;
    }
    let n = if dist > 0.0 { d / dist } else { V::new(0.0, 1.0) };
    let p = pj + n * (rj + 0.5 * gap);
    Some(RawContact2 {
        i,
        j,
        feature,
        point: [p.x, p.y],
        normal: [n.x, n.y],
        gap,
        area: 0.0,
    })
}

/// Closest point of segment [a, b] to q.
#[inline]
fn closest_on_segment(a: V, b: V, q: V) -> V {
    let e = b - a;
    let l2 = e.norm_squared();
    if l2 == 0.0 {
        return a;
    }
    a + e * ((q - a).dot(&e) / l2).clamp(0.0, 1.0)
}

/// Closest points between segments [a, b] and [c, d] (the pair minimising distance).
fn closest_segments(a: V, b: V, c: V, d: V) -> (V, V) {
    let mut best = (a, closest_on_segment(c, d, a));
    let mut bd = (best.0 - best.1).norm_squared();
    for (p, q) in [
        (b, closest_on_segment(c, d, b)),
        (closest_on_segment(a, b, c), c),
        (closest_on_segment(a, b, d), d),
    ] {
        let dd = (p - q).norm_squared();
        if dd < bd {
            bd = dd;
            best = (p, q);
        }
    }
    // crossing segments: the cores intersect, distance 0 at the intersection
    let (r, s) = (b - a, d - c);
    let den = r.perp(&s);
    if den != 0.0 {
        let t = (c - a).perp(&s) / den;
        let u = (c - a).perp(&r) / den;
        if (0.0..=1.0).contains(&t) && (0.0..=1.0).contains(&u) {
            let p = a + r * t;
            return (p, p);
        }
    }
    best
}

pub struct DiskDisk;
impl PairDetector<D2> for DiskDisk {
    fn detect(&self, cx: &DetectCtx<'_, D2>, pairs: &[[u32; 2]], out: &mut Vec<RawContact2>) {
        let disks = cx.a.as_any().downcast_ref::<Disks>().expect("disk store");
        let b = cx.bodies;
        for &[p, q] in pairs {
            let (i, j) = (p.min(q), p.max(q));
            let (si, sj) = (b.shape[i as usize].index, b.shape[j as usize].index);
            if let Some(c) = rounded(
                i,
                j,
                0,
                v(b.pos[i as usize]),
                v(b.pos[j as usize]),
                disks.radius[si as usize],
                disks.radius[sj as usize],
                cx.alert,
            ) {
                out.push(c);
            }
        }
    }
}

pub struct DiskWall;
impl PairDetector<D2> for DiskWall {
    fn detect(&self, cx: &DetectCtx<'_, D2>, pairs: &[[u32; 2]], out: &mut Vec<RawContact2>) {
        let disks = cx.a.as_any().downcast_ref::<Disks>().expect("disk store");
        let walls = cx.b.as_any().downcast_ref::<Walls>().expect("wall store");
        let b = cx.bodies;
        for &[d, w] in pairs {
            let (sd, sw) = (b.shape[d as usize].index, b.shape[w as usize].index);
            let (e0, e1) = walls.ends(sw, b.pos[w as usize], b.rot[w as usize]);
            let x = v(b.pos[d as usize]);
            let q = closest_on_segment(v(e0), v(e1), x);
            if let Some(c) = rounded(
                d,
                w,
                0,
                x,
                q,
                disks.radius[sd as usize],
                0.5 * walls.thickness[sw as usize],
                cx.alert,
            ) {
                out.push(c);
            }
        }
    }
}

pub struct DiskHalfPlane;
impl PairDetector<D2> for DiskHalfPlane {
    fn detect(&self, cx: &DetectCtx<'_, D2>, pairs: &[[u32; 2]], out: &mut Vec<RawContact2>) {
        let disks = cx.a.as_any().downcast_ref::<Disks>().expect("disk store");
        let b = cx.bodies;
        for &[d, h] in pairs {
            let n = v(HalfPlanes::normal(b.rot[h as usize]));
            let x = v(b.pos[d as usize]);
            let r = disks.radius[b.shape[d as usize].index as usize];
            let gap = (x - v(b.pos[h as usize])).dot(&n) - r;
            if gap <= cx.alert {
                let p = x - n * (r + 0.5 * gap);
                out.push(RawContact2 {
                    i: d,
                    j: h,
                    feature: 0,
                    point: [p.x, p.y],
                    normal: [n.x, n.y],
                    gap,
                    area: 0.0,
                });
            }
        }
    }
}

pub struct WallWall;
impl PairDetector<D2> for WallWall {
    fn detect(&self, cx: &DetectCtx<'_, D2>, pairs: &[[u32; 2]], out: &mut Vec<RawContact2>) {
        let walls = cx.a.as_any().downcast_ref::<Walls>().expect("wall store");
        let b = cx.bodies;
        for &[p, q] in pairs {
            let (i, j) = (p.min(q), p.max(q));
            let (si, sj) = (b.shape[i as usize].index, b.shape[j as usize].index);
            let (a0, a1) = walls.ends(si, b.pos[i as usize], b.rot[i as usize]);
            let (c0, c1) = walls.ends(sj, b.pos[j as usize], b.rot[j as usize]);
            let (pi, pj) = closest_segments(v(a0), v(a1), v(c0), v(c1));
            if let Some(c) = rounded(
                i,
                j,
                0,
                pi,
                pj,
                0.5 * walls.thickness[si as usize],
                0.5 * walls.thickness[sj as usize],
                cx.alert,
            ) {
                out.push(c);
            }
        }
    }
}

/// A wall against a half-plane touches by its two rounded ends (features 0 and 1).
pub struct WallHalfPlane;
impl PairDetector<D2> for WallHalfPlane {
    fn detect(&self, cx: &DetectCtx<'_, D2>, pairs: &[[u32; 2]], out: &mut Vec<RawContact2>) {
        let walls = cx.a.as_any().downcast_ref::<Walls>().expect("wall store");
        let b = cx.bodies;
        for &[w, h] in pairs {
            let sw = b.shape[w as usize].index;
            let n = v(HalfPlanes::normal(b.rot[h as usize]));
            let r = 0.5 * walls.thickness[sw as usize];
            let (e0, e1) = walls.ends(sw, b.pos[w as usize], b.rot[w as usize]);
            for (f, e) in [e0, e1].into_iter().enumerate() {
                let x = v(e);
                let gap = (x - v(b.pos[h as usize])).dot(&n) - r;
                if gap <= cx.alert {
                    let p = x - n * (r + 0.5 * gap);
                    out.push(RawContact2 {
                        i: w,
                        j: h,
                        feature: f as u32,
                        point: [p.x, p.y],
                        normal: [n.x, n.y],
                        gap,
                        area: 0.0,
                    });
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    #[test]
    fn segments() {
        let (p, q) = closest_segments(V::new(0.0, 0.0), V::new(1.0, 0.0), V::new(0.5, 1.0), V::new(0.5, 2.0));
        assert_eq!((p, q), (V::new(0.5, 0.0), V::new(0.5, 1.0)));
        let (p, q) = closest_segments(V::new(0.0, 0.0), V::new(1.0, 0.0), V::new(0.5, -1.0), V::new(0.5, 1.0));
        assert_eq!(p, q);
    }
}
