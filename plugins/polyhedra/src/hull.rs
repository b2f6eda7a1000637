//! Convex hull of a small point set and the mass properties of the solid.
//!
//! Masonry blocks have a few vertices (8 for a brick or a voussoir), so the hull
//! is found by the plain method: every plane through three points that leaves all
//! points on one side carries a face; the points on that plane, ordered around
//! their centre, are the face's polygon (counter-clockwise seen from outside).
//! O(n⁴) for n points: a limit of 64 vertices keeps it below a millisecond.
//!
//! Mass properties integrate over the tetrahedra (c₀, a, b, c) that join an
//! interior point c₀ to a fan triangulation of each face: volume
//! V = det[a − c₀, b − c₀, c − c₀]/6, first moment V (c₀ + a + b + c)/4, second
//! moment ∫ x xᵀ = V/20 (Σ pᵢ pᵢᵀ + s sᵀ), s = Σ pᵢ over the four corners. The
//! inertia about the centroid c is ρ(tr(C) 𝟙 − C) with C = ∫ x xᵀ − V c cᵀ; its
//! eigenvectors are the principal axes.

/// A convex polyhedron: vertices and faces (index loops, counter-clockwise seen
/// from outside) with their outward unit normals.
#[derive(Clone, Debug, PartialEq)]
pub struct Hull {
    pub vertices: Vec<[f64; 3]>,
    pub faces: Vec<Vec<u32>>,
    pub normals: Vec<[f64; 3]>,
}

pub const MAX_VERTICES: usize = 64;

pub fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
pub fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
pub fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
}
pub fn norm(a: [f64; 3]) -> f64 {
    dot(a, a).sqrt()
}

/// The convex hull of `points` (duplicates and interior points dropped), or why
/// there is none (fewer than 4 points, all coplanar, too many).
pub fn hull(points: &[[f64; 3]]) -> Result<Hull, String> {
    if points.len() > MAX_VERTICES {
        return Err(format!("at most {MAX_VERTICES} vertices, got {}", points.len()));
    }
    if points.iter().flatten().any(|x| !x.is_finite()) {
        return Err("vertices must be finite".into());
    }
    let size = points
        .iter()
        .flat_map(|p| points.iter().map(move |q| norm(sub(*p, *q))))
        .fold(0.0, f64::max);
    if !(size > 0.0) {
        return Err("the vertices span no volume".into());
    }
    let eps = 1e-9 * size;
    let mut pts: Vec<[f64; 3]> = vec![];
    for p in points {
        if pts.iter().all(|q| norm(sub(*p, *q)) > eps) {
            pts.push(*p);
        }
    }
    let n = pts.len();
    let planes = support_planes(&pts, eps, size);
    if planes.len() < 4 {
        return Err("the vertices are coplanar: a polyhedron needs volume".into());
    }
    let mut used = vec![false; n];
    let mut faces = vec![];
    let mut normals = vec![];
    for (nrm, d) in &planes {
        let mut on: Vec<usize> = (0..n).filter(|&v| (dot(*nrm, pts[v]) - d).abs() <= eps).collect();
        let c = on
            .iter()
            .fold([0.0; 3], |s, &v| [s[0] + pts[v][0], s[1] + pts[v][1], s[2] + pts[v][2]]);
        let c = c.map(|x| x / on.len() as f64);
        let u = {
            let a = sub(pts[on[0]], c);
            let l = norm(a);
            [a[0] / l, a[1] / l, a[2] / l]
        };
        let w = cross(*nrm, u);
        on.sort_by(|&a, &b| {
            let (pa, pb) = (sub(pts[a], c), sub(pts[b], c));
            dot(pa, w).atan2(dot(pa, u)).total_cmp(&dot(pb, w).atan2(dot(pb, u)))
        });
        // drop points in the middle of an edge (collinear with their neighbours)
        let m = on.len();
        let keep: Vec<usize> = (0..m)
            .filter(|&q| {
                let (a, b, cc) = (pts[on[(q + m - 1) % m]], pts[on[q]], pts[on[(q + 1) % m]]);
                norm(cross(sub(b, a), sub(cc, b))) > eps * size
            })
            .map(|q| on[q])
            .collect();
        if keep.len() < 3 {
            // round-off: points too close to a plane for their distance to the origin
            return Err("the polyhedron is too flat for its size and position (a face lost its area to round-off)".into());
        }
        for &v in &keep {
            used[v] = true;
        }
        faces.push(keep);
        normals.push(*nrm);
    }
    // renumber the vertices that lie on faces
    let mut map = vec![u32::MAX; n];
    let mut vertices = vec![];
    for v in 0..n {
        if used[v] {
            map[v] = vertices.len() as u32;
            vertices.push(pts[v]);
        }
    }
    let faces = faces
        .into_iter()
        .map(|f: Vec<usize>| f.into_iter().map(|v| map[v]).collect())
        .collect();
    Ok(Hull { vertices, faces, normals })
}

/// The distinct planes through three of `pts` that leave every point on one side
/// (outward normal, offset): the hull's face planes.
fn support_planes(pts: &[[f64; 3]], eps: f64, size: f64) -> Vec<([f64; 3], f64)> {
    let n = pts.len();
    let mut planes: Vec<([f64; 3], f64)> = vec![];
    for i in 0..n {
        for j in i + 1..n {
            for k in j + 1..n {
                let c = cross(sub(pts[j], pts[i]), sub(pts[k], pts[i]));
                let l = norm(c);
                if l <= eps * size {
                    continue;
                }
                let nrm = [c[0] / l, c[1] / l, c[2] / l];
                let d = dot(nrm, pts[i]);
                let (mut above, mut below) = (false, false);
                for p in pts {
                    let s = dot(nrm, *p) - d;
                    above |= s > eps;
                    below |= s < -eps;
                }
                let plane = match (above, below) {
                    (false, _) => (nrm, d),
                    (true, false) => ([-nrm[0], -nrm[1], -nrm[2]], -d),
                    _ => continue,
                };
                if planes
                    .iter()
                    .all(|(m, e)| norm(sub(*m, plane.0)) > 1e-9 || (e - plane.1).abs() > eps)
                {
                    planes.push(plane);
                }
            }
        }
    }
    planes
}

/// Volume, centroid and the second moment C = ∫ (x − c)(x − c)ᵀ dV of a hull.
pub fn moments(h: &Hull) -> (f64, [f64; 3], [[f64; 3]; 3]) {
    let nv = h.vertices.len() as f64;
    let c0 = h
        .vertices
        .iter()
        .fold([0.0; 3], |s, p| [s[0] + p[0], s[1] + p[1], s[2] + p[2]])
        .map(|x| x / nv);
    let (mut vol, mut first, mut second) = (0.0, [0.0; 3], [[0.0; 3]; 3]);
    for f in &h.faces {
        for t in 1..f.len() - 1 {
            let p = [
                c0,
                h.vertices[f[0] as usize],
                h.vertices[f[t] as usize],
                h.vertices[f[t + 1] as usize],
            ];
            let v = dot(sub(p[1], p[0]), cross(sub(p[2], p[0]), sub(p[3], p[0]))) / 6.0;
            let s = [0, 1, 2].map(|k| p.iter().map(|q| q[k]).sum::<f64>());
            vol += v;
            for k in 0..3 {
                first[k] += v * s[k] / 4.0;
                for l in 0..3 {
                    let pp: f64 = p.iter().map(|q| q[k] * q[l]).sum();
                    second[k][l] += v / 20.0 * (pp + s[k] * s[l]);
                }
            }
        }
    }
    let c = first.map(|x| x / vol);
    for k in 0..3 {
        for l in 0..3 {
            second[k][l] -= vol * c[k] * c[l];
        }
    }
    (vol, c, second)
}

/// Principal moments of inertia (per unit density) and the rotation R (columns:
/// principal axes, det R = 1) of a second moment C: I = tr(C) 𝟙 − C = R diag Rᵀ.
pub fn principal(c: &[[f64; 3]; 3]) -> ([f64; 3], [[f64; 3]; 3]) {
    let tr = c[0][0] + c[1][1] + c[2][2];
    let i = nalgebra::Matrix3::from_fn(|r, k| if r == k { tr - c[r][k] } else { -c[r][k] });
    let e = nalgebra::SymmetricEigen::new(i);
    let mut r = e.eigenvectors;
    if r.determinant() < 0.0 {
        r.column_mut(2).neg_mut();
    }
    let m = [0, 1, 2].map(|row| [0, 1, 2].map(|col| r[(row, col)]));
    ([e.eigenvalues[0], e.eigenvalues[1], e.eigenvalues[2]], m)
}

/// Unit quaternion (w, x, y, z) of a rotation matrix.
pub fn quat_of(m: &[[f64; 3]; 3]) -> [f64; 4] {
    let r = nalgebra::Rotation3::from_matrix_unchecked(nalgebra::Matrix3::from_fn(|i, j| m[i][j]));
    let q = nalgebra::UnitQuaternion::from_rotation_matrix(&r);
    [q.w, q.i, q.j, q.k]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cube_hull_and_moments() {
        let mut pts = vec![];
        for x in [0.0, 2.0] {
            for y in [0.0, 1.0] {
                for z in [0.0, 0.5] {
                    pts.push([x, y, z]);
                }
            }
        }
        pts.push([1.0, 0.5, 0.25]); // interior
        pts.push([1.0, 0.0, 0.0]); // middle of an edge
        let h = hull(&pts).unwrap();
        assert_eq!(h.vertices.len(), 8);
        assert_eq!(h.faces.len(), 6);
        assert!(h.faces.iter().all(|f| f.len() == 4));
        let (v, c, second) = moments(&h);
        assert!((v - 1.0).abs() < 1e-12 && norm(sub(c, [1.0, 0.5, 0.25])) < 1e-12);
        // Cxx = V a²/12 with a = 2
        assert!((second[0][0] - 4.0 / 12.0).abs() < 1e-12 && second[0][1].abs() < 1e-12);
        let (i, _) = principal(&second);
        let mut i = i.to_vec();
        i.sort_by(f64::total_cmp);
        let mut want = vec![(1.0 + 0.25) / 12.0, (4.0 + 0.25) / 12.0, (4.0 + 1.0) / 12.0];
        want.sort_by(f64::total_cmp);
        for k in 0..3 {
            assert!((i[k] - want[k]).abs() < 1e-12, "{i:?} {want:?}");
        }
        // faces are counter-clockwise seen from outside
        for (f, n) in h.faces.iter().zip(&h.normals) {
            let (a, b, c) = (h.vertices[f[0] as usize], h.vertices[f[1] as usize], h.vertices[f[2] as usize]);
            assert!(dot(cross(sub(b, a), sub(c, b)), *n) > 0.0);
        }
        assert!(hull(&[[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [1.0, 1.0, 0.0]]).is_err());
    }
}
