//! Narrow phases of convex polyhedra against planes and spheres.
//!
//! **Polyhedron–plane**: every vertex within alert of the plane.
//! **Polyhedron–sphere**: the closest point of the polyhedron's surface to the
//! centre (faces fanned into triangles), or the face of least penetration when
//! the centre is inside.
//!
//! Normals point from the antagonist (second body) to the candidate (first).

use crate::detect::{polygon_area, polys};
use crate::hull::{dot, norm, sub};
use crate::shapes::{unit, Poly};
use nscdd::dim::rotation::rotate;
use nscdd::dim::D3;
use nscdd::registry::{DetectCtx, PairDetector, RawContact3};
use nscdd_spheres::shapes::{closest_on_triangle, Spheres};

/// Polyhedron–plane: each vertex within alert of the plane (normal: the plane's z
/// axis). When the face most anti-parallel to the plane lies on it (all its
/// vertices within alert), its vertices share its area.
pub struct PolyPlane;

impl PairDetector<D3> for PolyPlane {
    fn detect(&self, ctx: &DetectCtx<'_, D3>, pairs: &[[u32; 2]], out: &mut Vec<RawContact3>) {
        let sa = polys(ctx, true);
        let b = ctx.bodies;
        let mut wv = vec![];
        for &[i, j] in pairs {
            let (iu, ju) = (i as usize, j as usize);
            sa.world_vertices(b.shape[iu].index, b.pos[iu], b.rot[iu], &mut wv);
            let n = rotate(b.rot[ju], [0.0, 0.0, 1.0]);
            let xp = b.pos[ju];
            let p = &sa.shapes[b.shape[iu].index as usize];
            let q = b.rot[iu];
            let f = (0..p.faces.len())
                .min_by(|&x, &y| dot(rotate(q, p.normals[x]), n).total_cmp(&dot(rotate(q, p.normals[y]), n)))
                .expect("a polyhedron has faces");
            let flush = p.faces[f].iter().all(|&v| dot(n, sub(wv[v as usize], xp)) <= ctx.alert);
            let share = if flush {
                let mut pts = [[0.0; 3]; 64];
                for (k, &v) in p.faces[f].iter().enumerate() {
                    pts[k] = wv[v as usize];
                }
                polygon_area(&pts[..p.faces[f].len()], n) / p.faces[f].len() as f64
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

/// The point of a polyhedron's surface (world vertices `wv`, orientation q) closest
/// to the point c, the unit outward normal there and the signed distance of c
/// (negative inside: then the face of least penetration; among faces within
/// 1e-9 of the size of it, the one most opposed to `hint`, e.g. the surface normal
/// of a node on an edge). `None` when c lies outside on the surface (no normal).
pub fn closest_surface(p: &Poly, wv: &[[f64; 3]], q: [f64; 4], c: [f64; 3], hint: [f64; 3]) -> Option<([f64; 3], [f64; 3], f64)> {
    let mut depth = f64::NEG_INFINITY;
    let side = |f: usize| dot(rotate(q, p.normals[f]), sub(c, wv[p.faces[f][0] as usize]));
    for f in 0..p.faces.len() {
        depth = depth.max(side(f));
    }
    let tol = 1e-9 * p.radius;
    if depth <= tol {
        let f = (0..p.faces.len())
            .filter(|&f| side(f) >= depth - tol)
            .min_by(|&a, &b| dot(rotate(q, p.normals[a]), hint).total_cmp(&dot(rotate(q, p.normals[b]), hint)))
            .expect("the deepest face");
        let (n, s) = (rotate(q, p.normals[f]), side(f));
        let x = [c[0] - s * n[0], c[1] - s * n[1], c[2] - s * n[2]];
        return Some((x, n, s));
    }
    let mut best = (f64::INFINITY, [0.0; 3]);
    for f in &p.faces {
        for t in 1..f.len() - 1 {
            let tri = [wv[f[0] as usize], wv[f[t] as usize], wv[f[t + 1] as usize]];
            let w = closest_on_triangle(c, &tri);
            let x = [0, 1, 2].map(|k| w[0] * tri[0][k] + w[1] * tri[1][k] + w[2] * tri[2][k]);
            let d = norm(sub(x, c));
            if d < best.0 {
                best = (d, x);
            }
        }
    }
    let n = unit(sub(c, best.1))?;
    Some((best.1, n, best.0))
}

/// Polyhedron (candidate) – sphere (antagonist).
pub struct PolySphere;

impl PairDetector<D3> for PolySphere {
    fn detect(&self, ctx: &DetectCtx<'_, D3>, pairs: &[[u32; 2]], out: &mut Vec<RawContact3>) {
        let sa = polys(ctx, true);
        let ss = ctx.b.as_any().downcast_ref::<Spheres>().expect("sphere store");
        let b = ctx.bodies;
        let mut wv = vec![];
        for &[i, j] in pairs {
            let (iu, ju) = (i as usize, j as usize);
            let p = &sa.shapes[b.shape[iu].index as usize];
            let r = ss.radius[b.shape[ju].index as usize];
            let c = b.pos[ju];
            sa.world_vertices(b.shape[iu].index, b.pos[iu], b.rot[iu], &mut wv);
            let Some((q, outward, d)) = closest_surface(p, &wv, b.rot[iu], c, [0.0; 3]) else {
                continue;
            };
            // the normal from the sphere (antagonist) to the polyhedron
            let (n, gap) = (outward.map(|x| -x), d - r);
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
