//! Narrow phases of convex polyhedra: against polyhedra, planes and spheres.
//!
//! **Polyhedron–polyhedron** (separating axes, then clipping, as box–box contact
//! generators do): the candidate axes are the face normals of both bodies and the
//! cross products of those pairs of edges that build a face of the Minkowski
//! difference (their arcs cross on the Gauss map; the other pairs cannot separate
//! and are skipped, as in Gregorius's SAT); the axis of largest separation s
//! decides. If s > alert there is no contact. If it is a face normal (faces are
//! preferred over edge axes within 1e-6 of the size, and the antagonist's faces
//! over the candidate's, so that the choice does not flicker between steps), that
//! face is the reference face and the most anti-parallel face of the other body the
//! incident face: the incident polygon is clipped by the side planes of the
//! reference polygon (Sutherland–Hodgman), and the clipped vertices within alert of
//! the reference plane are the contact points, halfway across their gap. At most 4
//! are kept (the deepest, the farthest from it, the farthest on each side of the
//! line through both: 4 for bricks in a bond, 4 of the 8 corners when one brick is
//! turned on the other); each stands for an equal share of the overlap polygon's
//! area (what bonded joints use). Edge–face contacts give the 2 ends of the clipped
//! edge; no point is found twice. Otherwise (edge–edge) one point, halfway between
//! the closest points of the two edges. Cost per pair: O(F_a V_b + F_b V_a) for the
//! face axes, 4 dot products per edge pair for the Gauss-map test, and the
//! clipping; no allocation (buffers in [`PolyScratch`]). Bricks (8 vertices, 6
//! faces, 12 edges): 1.4–2.0 µs per pair in or near contact, 0.5 µs when a face
//! axis separates (`cargo run --release -p nscdd-polyhedra --example bench_poly`).
//!
//! Polyhedron–plane and polyhedron–sphere: [`crate::detect_plane_sphere`].
//!
//! Normals point from the antagonist (second body) to the candidate (first).

pub use crate::detect_plane_sphere::{closest_surface, PolyPlane, PolySphere};
use crate::hull::{cross, dot, norm, sub};
use crate::shapes::{unit, Poly, Polyhedra};
use nscdd::dim::rotation::rotate;
use nscdd::dim::D3;
use nscdd::registry::{DetectCtx, PairDetector, RawContact3};

pub(crate) fn polys<'a>(ctx: &'a DetectCtx<'_, D3>, first: bool) -> &'a Polyhedra {
    let s = if first { ctx.a } else { ctx.b };
    s.as_any().downcast_ref::<Polyhedra>().expect("polyhedron store")
}

/// Buffers of the polyhedron–polyhedron narrow phase, reused from pair to pair (no
/// allocation per pair once they have grown).
#[derive(Default)]
pub struct PolyScratch {
    wi: Vec<[f64; 3]>,
    wj: Vec<[f64; 3]>,
    ni: Vec<[f64; 3]>,
    nj: Vec<[f64; 3]>,
    reference: Vec<[f64; 3]>,
    a: Vec<[f64; 3]>,
    b: Vec<[f64; 3]>,
    pts: Vec<[f64; 3]>,
    idx: Vec<usize>,
}

/// Best face of a body (vertices `wa`, world normals `na`) as a separating plane
/// against the vertices `vb`: (separation, face).
fn best_face(pa: &Poly, wa: &[[f64; 3]], na: &[[f64; 3]], vb: &[[f64; 3]]) -> (f64, usize) {
    let mut best = (f64::NEG_INFINITY, 0);
    for f in 0..pa.faces.len() {
        let (n, p) = (na[f], wa[pa.faces[f][0] as usize]);
        let s = vb.iter().map(|x| dot(n, sub(*x, p))).fold(f64::INFINITY, f64::min);
        if s > best.0 {
            best = (s, f);
        }
    }
    best
}

/// Whether edges with adjacent face normals (a, b) and, negated, (c, d) build a
/// face of the Minkowski difference: their arcs on the Gauss map cross. Only such
/// edge pairs can give a separating axis (Gregorius, "The separating axis test
/// between convex polyhedra", GDC 2013); the others are skipped.
#[inline]
fn minkowski_face(a: [f64; 3], b: [f64; 3], c: [f64; 3], d: [f64; 3]) -> bool {
    let (bxa, dxc) = (cross(b, a), cross(d, c));
    let (cba, dba) = (dot(c, bxa), dot(d, bxa));
    let (adc, bdc) = (dot(a, dxc), dot(b, dxc));
    cba * dba < 0.0 && adc * bdc < 0.0 && cba * bdc > 0.0
}

/// Clips polygon `poly` by the half-space (x − p)·s ≤ 0.
fn clip(poly: &[[f64; 3]], p: [f64; 3], s: [f64; 3], out: &mut Vec<[f64; 3]>) {
    out.clear();
    let m = poly.len();
    for k in 0..m {
        let (a, b) = (poly[k], poly[(k + 1) % m]);
        let (da, db) = (dot(sub(a, p), s), dot(sub(b, p), s));
        if da <= 0.0 {
            out.push(a);
        }
        if (da < 0.0 && db > 0.0) || (da > 0.0 && db < 0.0) {
            let t = da / (da - db);
            out.push([a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1]), a[2] + t * (b[2] - a[2])]);
        }
    }
}

/// Contact points of an incident face clipped by a reference face (normal n
/// outward of the reference body). `flip`: the reference body is the candidate
/// (normals then point along −n). Pushes contacts with the given bodies.
/// The incident polygon is in `sc.a`, the reference polygon in `sc.reference`.
fn face_contacts(sc: &mut PolyScratch, n: [f64; 3], alert: f64, i: u32, j: u32, flip: bool, feature0: u32, out: &mut Vec<RawContact3>) {
    let PolyScratch {
        reference, a, b, pts, idx, ..
    } = sc;
    let m = reference.len();
    for k in 0..m {
        let (p, q) = (reference[k], reference[(k + 1) % m]);
        let s = cross(sub(q, p), n);
        clip(a, p, s, b);
        std::mem::swap(a, b);
        if a.is_empty() {
            return;
        }
    }
    // clipping through a corner shared by both polygons yields it twice
    let scale = reference.iter().map(|p| norm(sub(*p, reference[0]))).fold(0.0, f64::max);
    pts.clear();
    for x in a.iter() {
        if pts.iter().all(|p| norm(sub(*p, *x)) > 1e-9 * scale) {
            pts.push(*x);
        }
    }
    // clipping along an edge that lies on a side plane (the equal faces of a
    // joint) can put a point anywhere on that edge: drop points on a straight line
    // between their neighbours, they are no corners
    let mut k = 0;
    while pts.len() > 3 && k < pts.len() {
        let m = pts.len();
        let (p0, p1, p2) = (pts[(k + m - 1) % m], pts[k], pts[(k + 1) % m]);
        if norm(cross(sub(p1, p0), sub(p2, p1))) <= 1e-9 * scale * scale {
            pts.remove(k);
        } else {
            k += 1;
        }
    }
    // the corners within alert, at most 4 of them kept; they share the overlap
    // polygon's area
    let gap = |x: &[f64; 3]| dot(sub(*x, reference[0]), n);
    idx.clear();
    idx.extend((0..pts.len()).filter(|&k| gap(&pts[k]) <= alert));
    let (kept, nk) = reduce4(pts, idx, n, reference[0]);
    if nk == 0 {
        return;
    }
    let area = polygon_area(pts, n) / nk as f64;
    let normal = if flip { n.map(|c| -c) } else { n };
    for &k in &kept[..nk] {
        let (x, g) = (pts[k], gap(&pts[k]));
        out.push(RawContact3 {
            i,
            j,
            feature: feature0 + k as u32,
            point: [x[0] - 0.5 * g * n[0], x[1] - 0.5 * g * n[1], x[2] - 0.5 * g * n[2]],
            normal,
            gap: g,
            area,
        });
    }
}

/// At most 4 of the corners `idx` of an overlap polygon (n: reference normal, p: a
/// point of the reference plane), in increasing order, and how many: the deepest,
/// the farthest from it, then on each side of the line through these two the
/// corner farthest from it. They span the polygon but for slivers at cut corners,
/// so the contact keeps its support and its moments without the redundant points
/// that slow NLGS down (8 corners for bricks turned about their common normal).
fn reduce4(pts: &[[f64; 3]], idx: &[usize], n: [f64; 3], p: [f64; 3]) -> ([usize; 4], usize) {
    let mut kept = [0usize; 4];
    if idx.len() <= 4 {
        kept[..idx.len()].copy_from_slice(idx);
        return (kept, idx.len());
    }
    let depth = |k: usize| dot(sub(pts[k], p), n);
    let it = || idx.iter().copied();
    let a = it().min_by(|&x, &y| depth(x).total_cmp(&depth(y))).expect("more than 4");
    let far = |k: usize| norm(sub(pts[k], pts[a]));
    let b = it().max_by(|&x, &y| far(x).total_cmp(&far(y))).expect("more than 4");
    let side = |k: usize| dot(cross(sub(pts[b], pts[a]), sub(pts[k], pts[a])), n);
    let c = it().max_by(|&x, &y| side(x).total_cmp(&side(y))).expect("more than 4");
    let d = it().min_by(|&x, &y| side(x).total_cmp(&side(y))).expect("more than 4");
    let mut nk = 0;
    for k in [a, b, c, d] {
        if !kept[..nk].contains(&k) {
            kept[nk] = k;
            nk += 1;
        }
    }
    kept[..nk].sort_unstable();
    (kept, nk)
}

/// Area of a planar convex polygon (vertices in order) of unit normal n.
pub(crate) fn polygon_area(p: &[[f64; 3]], n: [f64; 3]) -> f64 {
    let m = p.len();
    let mut s = 0.0;
    for k in 1..m.saturating_sub(1) {
        s += dot(cross(sub(p[k], p[0]), sub(p[k + 1], p[0])), n);
    }
    0.5 * s.abs()
}

/// Closest points of segments [p1, q1] and [p2, q2]: (on the first, on the second).
fn closest_segments(p1: [f64; 3], q1: [f64; 3], p2: [f64; 3], q2: [f64; 3]) -> ([f64; 3], [f64; 3]) {
    let (d1, d2, r) = (sub(q1, p1), sub(q2, p2), sub(p1, p2));
    let (a, e, f) = (dot(d1, d1), dot(d2, d2), dot(d2, r));
    let c = dot(d1, r);
    let b = dot(d1, d2);
    let denom = a * e - b * b;
    let mut s = if denom > 1e-300 {
        ((b * f - c * e) / denom).clamp(0.0, 1.0)
    } else {
        0.0
    };
    let mut t = (b * s + f) / e;
    if t < 0.0 {
        t = 0.0;
        s = (-c / a).clamp(0.0, 1.0);
    } else if t > 1.0 {
        t = 1.0;
        s = ((b - c) / a).clamp(0.0, 1.0);
    }
    let at = |p: [f64; 3], d: [f64; 3], u: f64| [p[0] + u * d[0], p[1] + u * d[1], p[2] + u * d[2]];
    (at(p1, d1, s), at(p2, d2, t))
}

/// Contacts between polyhedron i (candidate) and polyhedron j (antagonist), both
/// at their poses.
#[allow(clippy::too_many_arguments)]
pub fn poly_poly(
    pi: &Poly,
    xi: [f64; 3],
    qi: [f64; 4],
    pj: &Poly,
    xj: [f64; 3],
    qj: [f64; 4],
    i: u32,
    j: u32,
    alert: f64,
    sc: &mut PolyScratch,
    out: &mut Vec<RawContact3>,
) {
    pi.world_vertices(xi, qi, &mut sc.wi);
    pj.world_vertices(xj, qj, &mut sc.wj);
    sc.ni.clear();
    sc.ni.extend(pi.normals.iter().map(|n| rotate(qi, *n)));
    sc.nj.clear();
    sc.nj.extend(pj.normals.iter().map(|n| rotate(qj, *n)));
    let (wi, wj, ni, nj) = (&sc.wi, &sc.wj, &sc.ni, &sc.nj);
    // faces of j separating i's vertices, faces of i separating j's
    let (sj, fj) = best_face(pj, wj, nj, wi);
    if sj > alert {
        return;
    }
    let (si, fi) = best_face(pi, wi, ni, wj);
    if si > alert {
        return;
    }
    // edge–edge axes of the pairs that build Minkowski faces
    let size = pi.radius.max(pj.radius);
    let mut se = (f64::NEG_INFINITY, 0usize, 0usize, [0.0; 3]);
    for (ei, e1) in pi.edges.iter().enumerate() {
        let [fa, fb] = pi.edge_faces[ei];
        let (a, b) = (ni[fa as usize], ni[fb as usize]);
        let d1 = sub(wi[e1[1] as usize], wi[e1[0] as usize]);
        for (ej, e2) in pj.edges.iter().enumerate() {
            let [fc, fd] = pj.edge_faces[ej];
            let (c, d) = (nj[fc as usize].map(|x| -x), nj[fd as usize].map(|x| -x));
            if !minkowski_face(a, b, c, d) {
                continue;
            }
            let d2 = sub(wj[e2[1] as usize], wj[e2[0] as usize]);
            let x = cross(d1, d2);
            if norm(x) < 1e-6 * norm(d1) * norm(d2) {
                continue; // parallel edges: covered by the face axes
            }
            let Some(mut ax) = unit(x) else { continue };
            // orient from j to i: the axis points away from j's centre
            if dot(ax, sub(wj[e2[0] as usize], xj)) < 0.0 {
                ax = ax.map(|c| -c);
            }
            // separation of the supporting planes through the two edges
            let s = dot(ax, sub(wi[e1[0] as usize], wj[e2[0] as usize]));
            if s > alert {
                return;
            }
            if s > se.0 {
                se = (s, ei, ej, ax);
            }
        }
    }
    let tol = 1e-6 * size;
    if sj + tol >= si && sj + tol >= se.0 {
        // reference face of j (antagonist), incident face of i
        let n = nj[fj];
        let f_inc = (0..pi.faces.len())
            .min_by(|&a, &b| dot(ni[a], n).total_cmp(&dot(ni[b], n)))
            .expect("faces");
        sc.reference.clear();
        sc.reference.extend(pj.faces[fj].iter().map(|&v| wj[v as usize]));
        sc.a.clear();
        sc.a.extend(pi.faces[f_inc].iter().map(|&v| wi[v as usize]));
        face_contacts(sc, n, alert, i, j, false, (fj as u32) << 8, out);
    } else if si + tol >= se.0 {
        // reference face of i (candidate), incident face of j
        let m = ni[fi];
        let f_inc = (0..pj.faces.len())
            .min_by(|&a, &b| dot(nj[a], m).total_cmp(&dot(nj[b], m)))
            .expect("faces");
        sc.reference.clear();
        sc.reference.extend(pi.faces[fi].iter().map(|&v| wi[v as usize]));
        sc.a.clear();
        sc.a.extend(pj.faces[f_inc].iter().map(|&v| wj[v as usize]));
        face_contacts(sc, m, alert, i, j, true, 1 << 15 | (fi as u32) << 8, out);
    } else {
        let (s, ei, ej, ax) = se;
        let (e1, e2) = (pi.edges[ei], pj.edges[ej]);
        let (a, b) = closest_segments(wi[e1[0] as usize], wi[e1[1] as usize], wj[e2[0] as usize], wj[e2[1] as usize]);
        out.push(RawContact3 {
            i,
            j,
            feature: 1 << 16 | (ei as u32) << 8 | ej as u32,
            point: [0.5 * (a[0] + b[0]), 0.5 * (a[1] + b[1]), 0.5 * (a[2] + b[2])],
            normal: ax,
            gap: s,
            area: 0.0,
        });
    }
}

/// Polyhedron–polyhedron.
pub struct PolyPoly;

impl PairDetector<D3> for PolyPoly {
    fn detect(&self, ctx: &DetectCtx<'_, D3>, pairs: &[[u32; 2]], out: &mut Vec<RawContact3>) {
        let (sa, sb) = (polys(ctx, true), polys(ctx, false));
        let b = ctx.bodies;
        let mut sc = PolyScratch::default();
        for &[i, j] in pairs {
            let (iu, ju) = (i as usize, j as usize);
            let (pi, pj) = (&sa.shapes[b.shape[iu].index as usize], &sb.shapes[b.shape[ju].index as usize]);
            poly_poly(pi, b.pos[iu], b.rot[iu], pj, b.pos[ju], b.rot[ju], i, j, ctx.alert, &mut sc, out);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::generate::box_points;
    use nscdd::dim::rotation::from_rotation_vector;

    /// Separation of two vertex sets by brute force over every face normal and
    /// every cross product of edges; and over the face normals only.
    fn brute_sat(p: &Poly, wi: &[[f64; 3]], qi: [f64; 4], wj: &[[f64; 3]], qj: [f64; 4]) -> (f64, f64) {
        let mut axes: Vec<[f64; 3]> = p.normals.iter().map(|n| rotate(qi, *n)).collect();
        axes.extend(p.normals.iter().map(|n| rotate(qj, *n)));
        for e1 in &p.edges {
            for e2 in &p.edges {
                let x = cross(
                    sub(wi[e1[1] as usize], wi[e1[0] as usize]),
                    sub(wj[e2[1] as usize], wj[e2[0] as usize]),
                );
                if let Some(u) = unit(x) {
                    axes.push(u);
                }
            }
        }
        let sep = |ax: &[f64; 3]| {
            let (lo_i, hi_i) = wi.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
                (a.min(dot(*ax, *v)), b.max(dot(*ax, *v)))
            });
            let (lo_j, hi_j) = wj.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
                (a.min(dot(*ax, *v)), b.max(dot(*ax, *v)))
            });
            (lo_i - hi_j).max(lo_j - hi_i)
        };
        let faces = axes[..2 * p.normals.len()].iter().map(sep).fold(f64::NEG_INFINITY, f64::max);
        (axes.iter().map(sep).fold(f64::NEG_INFINITY, f64::max), faces)
    }

    #[test]
    fn pruned_edge_axes_agree_with_brute_force_separation() {
        let (p, _, _) = Poly::from_points(&box_points([-0.1, -0.05, -0.025], [0.1, 0.05, 0.025])).unwrap();
        let mut seed = 7u64;
        let mut rnd = || {
            seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (seed >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
        };
        let (mut sc, mut out) = (PolyScratch::default(), vec![]);
        let (mut wi, mut wj) = (vec![], vec![]);
        let (mut edge, mut face) = (0, 0);
        for _ in 0..20000 {
            let qi = from_rotation_vector([3.0 * rnd(), 3.0 * rnd(), 3.0 * rnd()]);
            let qj = from_rotation_vector([3.0 * rnd(), 3.0 * rnd(), 3.0 * rnd()]);
            let xj = [0.0; 3];
            let xi = [0.15 * rnd(), 0.15 * rnd(), 0.15 * rnd()];
            p.world_vertices(xi, qi, &mut wi);
            p.world_vertices(xj, qj, &mut wj);
            let (s, s_faces) = brute_sat(&p, &wi, qi, &wj, qj);
            if s < -0.01 {
                continue; // deep overlaps are not contacts of this narrow phase
            }
            out.clear();
            poly_poly(&p, xi, qi, &p, xj, qj, 0, 1, 0.002, &mut sc, &mut out);
            if s > 0.002 + 1e-12 {
                assert!(out.is_empty(), "separated by {s} yet {} contacts", out.len());
                continue;
            }
            if out.is_empty() {
                continue; // a face axis whose clipped points all lie beyond alert
            }
            let g = out.iter().map(|c| c.gap).fold(f64::INFINITY, f64::min);
            let tol = 1e-6 * 0.12 + 1e-12;
            if out[0].feature >> 16 == 1 {
                // the edge axis is the largest separation: none was pruned wrongly
                assert!((g - s).abs() <= 1e-12, "edge gap {g} vs separation {s}");
                edge += 1;
            } else {
                // a face axis within tol of the largest; clipped points never deeper
                assert!(s <= s_faces + tol, "an edge axis separates by {s}, the faces by {s_faces}");
                assert!(g >= s_faces - tol, "face gap {g} below the face separation {s_faces}");
                face += 1;
            }
        }
        assert!(edge > 20 && face > 20, "edge {edge}, face {face}");
    }

    #[test]
    fn polygons_of_many_corners_keep_at_most_4_points() {
        // two pyramids on 63-gon bases, base to base, one turned by half a step:
        // the overlap polygon has 126 corners
        let n = 63;
        let pyramid = |h: f64| {
            let mut v: Vec<[f64; 3]> = (0..n)
                .map(|k| {
                    let a = 2.0 * std::f64::consts::PI * k as f64 / n as f64;
                    [a.cos(), a.sin(), 0.0]
                })
                .collect();
            v.push([0.0, 0.0, h]);
            Poly::from_points(&v).unwrap()
        };
        let (up, cu, qu) = pyramid(0.5);
        let (down, cd, qd) = pyramid(-0.5);
        let (mut sc, mut out) = (PolyScratch::default(), vec![]);
        // each body at its principal frame (centroid on the z axis), the lower one
        // turned about z and 0.1 mm down
        let turn = from_rotation_vector([0.0, 0.0, std::f64::consts::PI / n as f64]);
        let qd = nscdd::dim::rotation::quat_mul(turn, qd);
        poly_poly(&up, cu, qu, &down, [cd[0], cd[1], cd[2] - 1e-4], qd, 0, 1, 0.002, &mut sc, &mut out);
        assert!((1..=4).contains(&out.len()), "{} points", out.len());
        let total: f64 = out.iter().map(|c| c.area).sum();
        assert!((total - std::f64::consts::PI).abs() < 0.01, "overlap area {total}");
    }

    #[test]
    fn points_are_chosen_among_the_corners_within_alert() {
        // an octagon (inside a square reference face) tilted about y: the corners
        // with x < 0.4 lie within alert, the others are lifted beyond it; the 4
        // points kept are all within alert
        let mut sc = PolyScratch::default();
        sc.reference
            .extend([[-1.0, -1.0, 0.0], [1.0, -1.0, 0.0], [1.0, 1.0, 0.0], [-1.0, 1.0, 0.0]]);
        let alert = 0.0014;
        sc.a.extend((0..8).map(|k| {
            let a = std::f64::consts::PI * (k as f64 + 0.5) / 4.0;
            let (x, y) = (0.9 * a.cos(), 0.9 * a.sin());
            [x, y, 0.001 * (x + 1.0)]
        }));
        let within = sc.a.iter().filter(|p| p[2] <= alert).count();
        assert!(within > 4 && within < 8, "{within}");
        let mut out = vec![];
        face_contacts(&mut sc, [0.0, 0.0, 1.0], alert, 0, 1, false, 0, &mut out);
        assert_eq!(out.len(), 4);
        assert!(out.iter().all(|c| c.gap <= alert), "{out:?}");
    }
}
