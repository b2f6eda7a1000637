//! Simplex meshes of deformable bodies: linear triangles (2D) and tetrahedra (3D),
//! their boundary (facets seen by one cell, oriented outwards) and the constant
//! strain and stress of each cell.

use crate::python::RawMesh;

/// A mesh: reference coordinates X (node-major), cells of `dim + 1` nodes, and
/// the boundary facets (`dim` nodes each; 2D: segments with the body on their
/// left; 3D: triangles whose right-hand normal points outwards).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Mesh {
    pub dim: usize,
    pub x0: Vec<f64>,
    pub cells: Vec<u32>,
    pub facets: Vec<u32>,
    /// Nodes on the boundary (sorted).
    pub boundary: Vec<u32>,
    /// The longest edge of the boundary facets (reference configuration): the
    /// mesh size a rigid grain is compared with in contact detection.
    pub longest_boundary_edge: f64,
    /// 3D: the outward unit normal of the boundary at each node (area-weighted
    /// mean of its facets', reference configuration; zero inside and in 2D).
    pub node_normal: Vec<[f64; 3]>,
}

/// A mesh that cannot be used (message for the user).
#[derive(Clone, Debug, PartialEq)]
pub struct MeshError(pub String);

impl Mesh {
    pub fn n_nodes(&self) -> usize {
        self.x0.len() / self.dim
    }
    pub fn n_cells(&self) -> usize {
        self.cells.len() / (self.dim + 1)
    }
    pub fn node(&self, k: usize) -> &[f64] {
        &self.x0[k * self.dim..(k + 1) * self.dim]
    }
    pub fn cell(&self, e: usize) -> &[u32] {
        &self.cells[e * (self.dim + 1)..(e + 1) * (self.dim + 1)]
    }

    /// Builds the mesh, orients cells positively and finds the boundary.
    pub fn new(raw: RawMesh) -> Result<Mesh, MeshError> {
        let RawMesh { dim, points, mut cells } = raw;
        if !(dim == 2 || dim == 3) || points.is_empty() || cells.is_empty() {
            return Err(MeshError(format!("empty or unsupported mesh ({dim}D)")));
        }
        let n = points.len() / dim;
        if cells.iter().any(|&c| c as usize >= n) {
            return Err(MeshError("a cell refers to a node that does not exist".into()));
        }
        let nv = dim + 1;
        for e in 0..cells.len() / nv {
            let c = &mut cells[e * nv..(e + 1) * nv];
            let v = signed_measure(dim, &points, c);
            if v.abs() < 1e-300 || !v.is_finite() {
                return Err(MeshError(format!(
                    "cell {e} is degenerate (zero {})",
                    if dim == 2 { "area" } else { "volume" }
                )));
            }
            if v < 0.0 {
                c.swap(0, 1);
            }
        }
        let mut m = Mesh {
            dim,
            x0: points,
            cells,
            facets: vec![],
            boundary: vec![],
            longest_boundary_edge: 0.0,
            node_normal: vec![],
        };
        m.find_boundary();
        m.longest_boundary_edge = m.longest_edge();
        m.node_normal = m.node_normals();
        Ok(m)
    }

    fn find_boundary(&mut self) {
        let (dim, nv) = (self.dim, self.dim + 1);
        // every facet with its sorted key; a facet seen once is on the boundary
        // (sorted key, facet, the cell's vertex opposite the facet)
        let mut all: Vec<(Vec<u32>, Vec<u32>, u32)> = Vec::with_capacity(self.n_cells() * nv);
        for e in 0..self.n_cells() {
            let c = self.cell(e).to_vec();
            for skip in 0..nv {
                // facets with the orientation induced by the positive cell
                let f: Vec<u32> = if dim == 2 {
                    // triangle (a, b, c) counter-clockwise: edges (a,b), (b,c), (c,a)
                    vec![c[(skip + 1) % 3], c[(skip + 2) % 3]]
                } else {
                    // the face opposite vertex `skip`, ordered so that its normal points away from it
                    let mut f: Vec<u32> = (0..4).filter(|&k| k != skip).map(|k| c[k]).collect();
                    if skip % 2 == 0 {
                        f.swap(0, 1);
                    }
                    f
                };
                let mut key = f.clone();
                key.sort_unstable();
                all.push((key, f, c[skip]));
            }
        }
        all.sort_unstable_by(|a, b| a.0.cmp(&b.0));
        let mut i = 0;
        while i < all.len() {
            let mut j = i + 1;
            while j < all.len() && all[j].0 == all[i].0 {
                j += 1;
            }
            if j - i == 1 {
                let f = &all[i].1;
                let f = if dim == 3 { self.orient_out(f, all[i].2) } else { f.clone() };
                self.facets.extend_from_slice(&f);
            }
            i = j;
        }
        let mut b = self.facets.clone();
        b.sort_unstable();
        b.dedup();
        self.boundary = b;
    }

    /// 3D: orders a boundary face so that its normal points away from `opposite`,
    /// the fourth vertex of its cell (checked geometrically, whatever the
    /// convention above).
    fn orient_out(&self, f: &[u32], opposite: u32) -> Vec<u32> {
        let p = |k: u32| [self.x0[3 * k as usize], self.x0[3 * k as usize + 1], self.x0[3 * k as usize + 2]];
        let a = p(f[0]);
        let nrm = cross(sub(p(f[1]), a), sub(p(f[2]), a));
        if dot(nrm, sub(p(opposite), a)) > 0.0 {
            vec![f[0], f[2], f[1]]
        } else {
            f.to_vec()
        }
    }

    fn node_normals(&self) -> Vec<[f64; 3]> {
        let mut n = vec![[0.0; 3]; self.n_nodes()];
        if self.dim != 3 {
            return n;
        }
        let p = |k: u32| [self.x0[3 * k as usize], self.x0[3 * k as usize + 1], self.x0[3 * k as usize + 2]];
        for f in 0..self.n_facets() {
            let v = self.facet(f);
            let a = p(v[0]);
            let c = cross(sub(p(v[1]), a), sub(p(v[2]), a));
            for &k in v {
                for d in 0..3 {
                    n[k as usize][d] += c[d];
                }
            }
        }
        for x in &mut n {
            let l = dot(*x, *x).sqrt();
            if l > 0.0 {
                *x = x.map(|c| c / l);
            }
        }
        n
    }

    fn longest_edge(&self) -> f64 {
        let mut l2 = 0.0f64;
        for f in 0..self.n_facets() {
            let v = self.facet(f);
            for a in 0..v.len() {
                let (pa, pc) = (self.node(v[a] as usize), self.node(v[(a + 1) % v.len()] as usize));
                l2 = l2.max(pa.iter().zip(pc).map(|(x, y)| (x - y).powi(2)).sum());
            }
        }
        l2.sqrt()
    }

    /// Facets (boundary segments in 2D, triangles in 3D).
    pub fn n_facets(&self) -> usize {
        self.facets.len() / self.dim
    }
    pub fn facet(&self, s: usize) -> &[u32] {
        &self.facets[s * self.dim..(s + 1) * self.dim]
    }
}

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
}
fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// Signed area (2D) or volume (3D) of a simplex.
pub fn signed_measure(dim: usize, x: &[f64], c: &[u32]) -> f64 {
    let p = |k: u32, d: usize| x[dim * k as usize + d];
    if dim == 2 {
        0.5 * ((p(c[1], 0) - p(c[0], 0)) * (p(c[2], 1) - p(c[0], 1)) - (p(c[2], 0) - p(c[0], 0)) * (p(c[1], 1) - p(c[0], 1)))
    } else {
        let v = |k: u32| [p(k, 0), p(k, 1), p(k, 2)];
        let (a, b, cc, d) = (v(c[0]), v(c[1]), v(c[2]), v(c[3]));
        dot(sub(b, a), cross(sub(cc, a), sub(d, a))) / 6.0
    }
}

/// Gradients of the P1 shape functions of a cell (rows: nodes, columns: x, y[, z]),
/// from the reference coordinates.
pub fn gradients(dim: usize, x: &[f64], c: &[u32]) -> Vec<[f64; 3]> {
    let p = |k: u32, d: usize| x[dim * k as usize + d];
    if dim == 2 {
        let a2 = 2.0 * signed_measure(2, x, c);
        (0..3)
            .map(|i| {
                let (j, k) = (c[(i + 1) % 3], c[(i + 2) % 3]);
                [(p(j, 1) - p(k, 1)) / a2, (p(k, 0) - p(j, 0)) / a2, 0.0]
            })
            .collect()
    } else {
        // invert the 3×3 Jacobian J = [x1−x0, x2−x0, x3−x0]
        let v = |k: u32| [p(k, 0), p(k, 1), p(k, 2)];
        let x0 = v(c[0]);
        let e = [sub(v(c[1]), x0), sub(v(c[2]), x0), sub(v(c[3]), x0)];
        let det = dot(e[0], cross(e[1], e[2]));
        // rows of J⁻ᵀ: gradients of the barycentric coordinates 1..3
        let g1 = cross(e[1], e[2]).map(|t| t / det);
        let g2 = cross(e[2], e[0]).map(|t| t / det);
        let g3 = cross(e[0], e[1]).map(|t| t / det);
        let g0 = [-(g1[0] + g2[0] + g3[0]), -(g1[1] + g2[1] + g3[1]), -(g1[2] + g2[2] + g3[2])];
        vec![g0, g1, g2, g3]
    }
}

/// The constant stress of each cell of a displacement field `u` (node-major):
/// 2D [σxx, σyy, σxy, σzz] (σzz = ν(σxx + σyy) in plane strain, 0 in plane stress),
/// 3D [σxx, σyy, σzz, σxy, σyz, σxz].
pub fn cell_stress(m: &Mesh, u: &[f64], young: f64, poisson: f64, plane_stress: bool) -> Vec<[f64; 6]> {
    let (dim, nu) = (m.dim, poisson);
    let mu = young / (2.0 * (1.0 + nu));
    let mut lam = young * nu / ((1.0 + nu) * (1.0 - 2.0 * nu));
    if dim == 2 && plane_stress {
        lam = 2.0 * lam * mu / (lam + 2.0 * mu);
    }
    (0..m.n_cells())
        .map(|e| {
            let c = m.cell(e);
            let g = gradients(dim, &m.x0, c);
            // displacement gradient ∂u_a/∂x_b
            let mut du = [[0.0; 3]; 3];
            for (i, &k) in c.iter().enumerate() {
                for a in 0..dim {
                    for b in 0..dim {
                        du[a][b] += u[dim * k as usize + a] * g[i][b];
                    }
                }
            }
            let eps = |a: usize, b: usize| 0.5 * (du[a][b] + du[b][a]);
            let tr = (0..dim).map(|a| eps(a, a)).sum::<f64>();
            let s = |a: usize, b: usize| 2.0 * mu * eps(a, b) + if a == b { lam * tr } else { 0.0 };
            if dim == 2 {
                let szz = if plane_stress { 0.0 } else { nu * (s(0, 0) + s(1, 1)) };
                [s(0, 0), s(1, 1), s(0, 1), szz, 0.0, 0.0]
            } else {
                [s(0, 0), s(1, 1), s(2, 2), s(0, 1), s(1, 2), s(0, 2)]
            }
        })
        .collect()
}
