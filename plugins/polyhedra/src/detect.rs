//! Narrow phases of convex polyhedra: against polyhedra, planes and spheres.
//!
//! **Polyhedron–polyhedron** (separating axes, then clipping, as box–box contact
//! generators do): the candidate axes are the face normals of both bodies and the
//! cross products of their edges; the axis of largest separation s decides. If
//! s > alert there is no contact. If it is a face normal (faces are preferred over
//! edge axes within 1e-6 of the size, and the antagonist's faces over the
//! candidate's, so that the choice does not flicker between steps), that face is
//! the reference face and the most anti-parallel face of the other body the
//! incident face: the incident polygon is clipped by the side planes of the
//! reference polygon (Sutherland–Hodgman), and each clipped vertex within alert of
//! the reference plane is a contact point, halfway across its gap. Face–face
//! contacts give the corners of the overlap polygon (4 for bricks in a bond),
//! edge–face contacts the 2 ends of the clipped edge; no point is found twice.
//! Otherwise (edge–edge) one point, halfway between the closest points of the two
//! edges. Cost per pair: O(F_a V_b + F_b V_a + E_a E_b (V_a + V_b)) products
//! (bricks: ≈ 2 500 multiply–adds) plus the clipping.
//!
//! **Polyhedron–plane**: every vertex within alert of the plane.
//! **Polyhedron–sphere**: the closest point of the polyhedron's surface to the
//! centre (faces fanned into triangles), or the face of least penetration when
//! the centre is inside.
//!
//! Normals point from the antagonist (second body) to the candidate (first).

use crate::hull::{cross, dot, norm, sub};
use crate::shapes::{unit, world_face, Poly, Polyhedra};
use nscdd::registry3::{DetectCtx3, PairDetector3, RawContact3};
use nscdd::rigid3d::bodies::rotate;
use nscdd_spheres::shapes::{closest_on_triangle, Spheres};

fn polys<'a>(ctx: &'a DetectCtx3<'_>, first: bool) -> &'a Polyhedra {
    let s = if first { ctx.a } else { ctx.b };
    s.as_any().downcast_ref::<Polyhedra>().expect("polyhedron store")
}

/// Separation of the vertex set `v` from the plane (n, point p): min n·(v − p).
fn min_along(v: &[[f64; 3]], n: [f64; 3], p: [f64; 3]) -> f64 {
    v.iter().map(|x| dot(n, sub(*x, p))).fold(f64::INFINITY, f64::min)
}

/// Best face of `a` as a separating plane against the vertices `vb`: (separation, face).
fn best_face(pa: &Poly, wa: &[[f64; 3]], qa: [f64; 4], vb: &[[f64; 3]]) -> (f64, usize) {
    let mut best = (f64::NEG_INFINITY, 0);
    for f in 0..pa.faces.len() {
        let n = rotate(qa, pa.normals[f]);
        let s = min_along(vb, n, wa[pa.faces[f][0] as usize]);
        if s > best.0 {
            best = (s, f);
        }
    }
    best
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
#[allow(clippy::too_many_arguments)]
fn face_contacts(
    reference: &[[f64; 3]],
    n: [f64; 3],
    incident: &[[f64; 3]],
    alert: f64,
    i: u32,
    j: u32,
    flip: bool,
    feature0: u32,
    out: &mut Vec<RawContact3>,
) {
    let mut a = incident.to_vec();
    let mut b = Vec::with_capacity(a.len() + 4);
    let m = reference.len();
    for k in 0..m {
        let (p, q) = (reference[k], reference[(k + 1) % m]);
        let s = cross(sub(q, p), n);
        clip(&a, p, s, &mut b);
        std::mem::swap(&mut a, &mut b);
        if a.is_empty() {
            return;
        }
    }
    // clipping through a corner shared by both polygons yields it twice
    let scale = reference.iter().map(|p| norm(sub(*p, reference[0]))).fold(0.0, f64::max);
    let mut pts: Vec<[f64; 3]> = Vec::with_capacity(a.len());
    for x in &a {
        if pts.iter().all(|p| norm(sub(*p, *x)) > 1e-9 * scale) {
            pts.push(*x);
        }
    }
    // the overlap polygon's area, shared by the points kept
    let keep = reduce4(&pts, n, reference[0]);
    let area = polygon_area(&pts, n) / keep.iter().filter(|&&x| x).count() as f64;
    for (k, x) in pts.iter().enumerate() {
        if !keep[k] {
            continue;
        }
        let gap = dot(sub(*x, reference[0]), n);
        if gap <= alert {
            let point = [x[0] - 0.5 * gap * n[0], x[1] - 0.5 * gap * n[1], x[2] - 0.5 * gap * n[2]];
            let normal = if flip { n.map(|c| -c) } else { n };
            out.push(RawContact3 {
                i,
                j,
                feature: feature0 + k as u32,
                point,
                normal,
                gap,
                area,
            });
        }
    }
}

/// At most 4 corners of an overlap polygon (n: reference normal, p: a point of the
/// reference plane): the deepest, the farthest from it, then on each side of the
/// line through these two the corner farthest from it. They span the polygon but
/// for slivers at cut corners, so the contact keeps its support and its moments
/// without the redundant points that slow NLGS down (8 corners for bricks turned
/// about their common normal).
fn reduce4(pts: &[[f64; 3]], n: [f64; 3], p: [f64; 3]) -> Vec<bool> {
    let m = pts.len();
    let mut keep = vec![m <= 4; m];
    if m <= 4 {
        return keep;
    }
    let depth = |k: usize| dot(sub(pts[k], p), n);
    let a = (0..m).min_by(|&x, &y| depth(x).total_cmp(&depth(y))).unwrap();
    let far = |k: usize| norm(sub(pts[k], pts[a]));
    let b = (0..m).max_by(|&x, &y| far(x).total_cmp(&far(y))).unwrap();
    let side = |k: usize| dot(cross(sub(pts[b], pts[a]), sub(pts[k], pts[a])), n);
    let c = (0..m).max_by(|&x, &y| side(x).total_cmp(&side(y))).unwrap();
    let d = (0..m).min_by(|&x, &y| side(x).total_cmp(&side(y))).unwrap();
    for k in [a, b, c, d] {
        keep[k] = true;
    }
    keep
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
    out: &mut Vec<RawContact3>,
) {
    let (mut wi, mut wj) = (vec![], vec![]);
    pi.world_vertices(xi, qi, &mut wi);
    pj.world_vertices(xj, qj, &mut wj);
    // faces of j separating i's vertices, faces of i separating j's
    let (sj, fj) = best_face(pj, &wj, qj, &wi);
    if sj > alert {
        return;
    }
    let (si, fi) = best_face(pi, &wi, qi, &wj);
    if si > alert {
        return;
    }
    // edge–edge axes
    let size = pi.radius.max(pj.radius);
    let mut se = (f64::NEG_INFINITY, 0usize, 0usize, [0.0; 3]);
    let ci = xi;
    for (ei, e1) in pi.edges.iter().enumerate() {
        let d1 = sub(wi[e1[1] as usize], wi[e1[0] as usize]);
        for (ej, e2) in pj.edges.iter().enumerate() {
            let d2 = sub(wj[e2[1] as usize], wj[e2[0] as usize]);
            let Some(mut ax) = unit(cross(d1, d2)) else { continue };
            if norm(cross(d1, d2)) < 1e-6 * norm(d1) * norm(d2) {
                continue; // parallel edges: covered by the face axes
            }
            // orient from j to i
            if dot(ax, sub(ci, wj[e2[0] as usize])) < 0.0 {
                ax = ax.map(|c| -c);
            }
            let lo_i = wi.iter().map(|v| dot(ax, *v)).fold(f64::INFINITY, f64::min);
            let hi_j = wj.iter().map(|v| dot(ax, *v)).fold(f64::NEG_INFINITY, f64::max);
            let s = lo_i - hi_j;
            if s > alert {
                return;
            }
            if s > se.0 {
                se = (s, ei, ej, ax);
            }
        }
    }
    let tol = 1e-6 * size;
    let mut poly = vec![];
    let mut inc = vec![];
    if sj + tol >= si && sj + tol >= se.0 {
        // reference face of j (antagonist), incident face of i
        let n = world_face(pj, &wj, qj, fj, &mut poly);
        let f_inc = (0..pi.faces.len())
            .min_by(|&a, &b| dot(rotate(qi, pi.normals[a]), n).total_cmp(&dot(rotate(qi, pi.normals[b]), n)))
            .unwrap();
        world_face(pi, &wi, qi, f_inc, &mut inc);
        face_contacts(&poly, n, &inc, alert, i, j, false, (fj as u32) << 8, out);
    } else if si + tol >= se.0 {
        // reference face of i (candidate), incident face of j
        let m = world_face(pi, &wi, qi, fi, &mut poly);
        let f_inc = (0..pj.faces.len())
            .min_by(|&a, &b| dot(rotate(qj, pj.normals[a]), m).total_cmp(&dot(rotate(qj, pj.normals[b]), m)))
            .unwrap();
        world_face(pj, &wj, qj, f_inc, &mut inc);
        face_contacts(&poly, m, &inc, alert, i, j, true, 1 << 15 | (fi as u32) << 8, out);
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

impl PairDetector3 for PolyPoly {
    fn detect(&self, ctx: &DetectCtx3<'_>, pairs: &[[u32; 2]], out: &mut Vec<RawContact3>) {
        let (sa, sb) = (polys(ctx, true), polys(ctx, false));
        let b = ctx.bodies;
        for &[i, j] in pairs {
            let (iu, ju) = (i as usize, j as usize);
            let (pi, pj) = (&sa.shapes[b.shape[iu].index as usize], &sb.shapes[b.shape[ju].index as usize]);
            poly_poly(pi, b.pos[iu], b.quat[iu], pj, b.pos[ju], b.quat[ju], i, j, ctx.alert, out);
        }
    }
}

/// Polyhedron–plane: each vertex within alert of the plane (normal: the plane's z
/// axis). When the face most anti-parallel to the plane lies on it (all its
/// vertices within alert), its vertices share its area.
pub struct PolyPlane;

impl PairDetector3 for PolyPlane {
    fn detect(&self, ctx: &DetectCtx3<'_>, pairs: &[[u32; 2]], out: &mut Vec<RawContact3>) {
        let sa = polys(ctx, true);
        let b = ctx.bodies;
        let mut wv = vec![];
        for &[i, j] in pairs {
            let (iu, ju) = (i as usize, j as usize);
            sa.world_vertices(b.shape[iu].index, b.pos[iu], b.quat[iu], &mut wv);
            let n = rotate(b.quat[ju], [0.0, 0.0, 1.0]);
            let xp = b.pos[ju];
            let p = &sa.shapes[b.shape[iu].index as usize];
            let q = b.quat[iu];
            let f = (0..p.faces.len())
                .min_by(|&x, &y| dot(rotate(q, p.normals[x]), n).total_cmp(&dot(rotate(q, p.normals[y]), n)))
                .expect("a polyhedron has faces");
            let flush = p.faces[f].iter().all(|&v| dot(n, sub(wv[v as usize], xp)) <= ctx.alert);
            let share = if flush {
                let pts: Vec<[f64; 3]> = p.faces[f].iter().map(|&v| wv[v as usize]).collect();
                polygon_area(&pts, n) / pts.len() as f64
            } else {
                0.0
            };
            for (k, &x) in wv.iter().enumerate() {
                let gap = dot(n, sub(x, xp));
                if gap <= ctx.alert {
                    let area = if flush && p.faces[f].contains(&(k as u32)) { share } else { 0.0 };
                    out.push(RawContact3 {
                        i,
                        j,
                        feature: k as u32,
                        point: [x[0] - 0.5 * gap * n[0], x[1] - 0.5 * gap * n[1], x[2] - 0.5 * gap * n[2]],
                        normal: n,
                        gap,
                        area,
                    });
                }
            }
        }
    }
}

/// Polyhedron (candidate) – sphere (antagonist).
pub struct PolySphere;

impl PairDetector3 for PolySphere {
    fn detect(&self, ctx: &DetectCtx3<'_>, pairs: &[[u32; 2]], out: &mut Vec<RawContact3>) {
        let sa = polys(ctx, true);
        let ss = ctx.b.as_any().downcast_ref::<Spheres>().expect("sphere store");
        let b = ctx.bodies;
        let mut wv = vec![];
        for &[i, j] in pairs {
            let (iu, ju) = (i as usize, j as usize);
            let p = &sa.shapes[b.shape[iu].index as usize];
            let r = ss.radius[b.shape[ju].index as usize];
            let c = b.pos[ju];
            sa.world_vertices(b.shape[iu].index, b.pos[iu], b.quat[iu], &mut wv);
            // inside: the face of least penetration
            let mut depth = (f64::NEG_INFINITY, 0);
            for f in 0..p.faces.len() {
                let n = rotate(b.quat[iu], p.normals[f]);
                let s = dot(n, sub(c, wv[p.faces[f][0] as usize]));
                if s > depth.0 {
                    depth = (s, f);
                }
            }
            let (q, n, gap) = if depth.0 <= 0.0 {
                let n = rotate(b.quat[iu], p.normals[depth.1]);
                let q = [c[0] - depth.0 * n[0], c[1] - depth.0 * n[1], c[2] - depth.0 * n[2]];
                (q, n.map(|x| -x), depth.0 - r)
            } else {
                let mut best = (f64::INFINITY, [0.0; 3]);
                for f in &p.faces {
                    for t in 1..f.len() - 1 {
                        let tri = [wv[f[0] as usize], wv[f[t] as usize], wv[f[t + 1] as usize]];
                        let w = closest_on_triangle(c, &tri);
                        let q = [0, 1, 2].map(|k| w[0] * tri[0][k] + w[1] * tri[1][k] + w[2] * tri[2][k]);
                        let d = norm(sub(q, c));
                        if d < best.0 {
                            best = (d, q);
                        }
                    }
                }
                let Some(n) = unit(sub(best.1, c)) else { continue };
                (best.1, n, best.0 - r)
            };
            if gap > ctx.alert {
                continue;
            }
            out.push(RawContact3 {
                i,
                j,
                feature: 0,
                point: [q[0] - 0.5 * gap * n[0], q[1] - 0.5 * gap * n[1], q[2] - 0.5 * gap * n[2]],
                normal: n,
                gap,
                area: 0.0,
            });
        }
    }
}
