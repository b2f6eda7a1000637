//! A deformable body's M and K on one shared pattern (the union of theirs, which is
//! M̂'s), their products and the energies. A body holds them while it is stepped
//! ([`crate::body::FeBody::ensure_matrices`]); on MPI ranks a rank that does not
//! step a body holds none of them ([`crate::stepped`]), and a rank that comes to
//! step it assembles them again from the mesh and the material ([`assemble`]): the
//! same scikit-fem assembly of the same arrays, the same numbers.
//!
//! ```
//! use nscdd_fem_deformable::matrices::Matrices;
//! use nscdd_fem_deformable::python::Csr;
//! // M = I, K = 2 I on 2 dofs
//! let eye = |x: f64| Csr { n: 2, indptr: vec![0, 1, 2], indices: vec![0, 1], data: vec![x, x] };
//! let m = Matrices::from_csr(&eye(1.0), &eye(2.0)).unwrap();
//! let mut y = vec![0.0; 2];
//! m.mul_add(1.0, 1.0, &[1.0, 2.0], &mut y);
//! assert_eq!(y, [3.0, 6.0]);
//! assert_eq!(m.energies(&[1.0, 0.0], &[0.0, 1.0]), [0.5, 1.0]);
//! ```

use crate::body::Elastic;
use crate::mesh::Mesh;
use crate::python::{Csr, RawMesh};
use faer::sparse::SymbolicSparseColMat;

/// M and K of a body on their shared pattern (module docs).
pub struct Matrices {
    /// Pattern shared by M, K and M̂ (the union of M's and K's), CSC of a symmetric
    /// matrix; values of M and K on it.
    pub(crate) pattern: SymbolicSparseColMat<usize>,
    pub(crate) m_val: Vec<f64>,
    pub(crate) k_val: Vec<f64>,
}

impl Matrices {
    /// M and K from their assembled CSR forms (symmetric: CSR = CSC), on the union
    /// of their patterns, column by column.
    pub fn from_csr(m: &Csr, k: &Csr) -> Result<Matrices, String> {
        let n = m.n;
        if k.n != n || m.indptr.len() != n + 1 || k.indptr.len() != n + 1 {
            return Err(format!("assembled matrices of size {}, {}", m.n, k.n));
        }
        let mut col_ptr = vec![0usize; n + 1];
        let mut rows = Vec::with_capacity(m.indices.len().max(k.indices.len()));
        let (mut mv, mut kv) = (Vec::new(), Vec::new());
        for c in 0..n {
            let (ma, mb) = (m.indptr[c], m.indptr[c + 1]);
            let (ka, kb) = (k.indptr[c], k.indptr[c + 1]);
            let (mut i, mut j) = (ma, ka);
            while i < mb || j < kb {
                let ri = if i < mb { m.indices[i] } else { usize::MAX };
                let rj = if j < kb { k.indices[j] } else { usize::MAX };
                let r = ri.min(rj);
                rows.push(r);
                mv.push(if ri == r { m.data[i] } else { 0.0 });
                kv.push(if rj == r { k.data[j] } else { 0.0 });
                if ri == r {
                    i += 1;
                }
                if rj == r {
                    j += 1;
                }
            }
            col_ptr[c + 1] = rows.len();
        }
        let pattern = SymbolicSparseColMat::new_checked(n, n, col_ptr, None, rows);
        Ok(Matrices {
            pattern,
            m_val: mv,
            k_val: kv,
        })
    }

    /// Degrees of freedom (the matrices' size).
    pub fn n(&self) -> usize {
        self.pattern.ncols()
    }

    /// Nonzeros of the pattern (both triangles).
    pub fn nnz(&self) -> usize {
        self.m_val.len()
    }

    /// y += a M x + b K x.
    pub fn mul_add(&self, a: f64, b: f64, x: &[f64], y: &mut [f64]) {
        let cp = self.pattern.col_ptr();
        let ri = self.pattern.row_idx();
        for c in 0..self.n() {
            let xc = x[c];
            if xc == 0.0 {
                continue;
            }
            for p in cp[c]..cp[c + 1] {
                y[ri[p]] += (a * self.m_val[p] + b * self.k_val[p]) * xc;
            }
        }
    }

    /// [½ vᵀMv, ½ uᵀKu] in one pass over the pattern (stored whole: column c's
    /// sums times x_c), without allocation.
    pub fn energies(&self, u: &[f64], v: &[f64]) -> [f64; 2] {
        let cp = self.pattern.col_ptr();
        let ri = self.pattern.row_idx();
        let (mut ke, mut se) = (0.0, 0.0);
        for c in 0..self.n() {
            let (mut mv, mut ku) = (0.0, 0.0);
            for p in cp[c]..cp[c + 1] {
                let r = ri[p];
                mv += self.m_val[p] * v[r];
                ku += self.k_val[p] * u[r];
            }
            ke += v[c] * mv;
            se += u[c] * ku;
        }
        [0.5 * ke, 0.5 * se]
    }

    /// M̂'s values a M + b K on the pattern, with the rows and columns of the `fixed`
    /// dofs replaced by the identity's.
    pub fn m_hat(&self, a: f64, b: f64, fixed: &[bool]) -> Vec<f64> {
        let cp = self.pattern.col_ptr();
        let ri = self.pattern.row_idx();
        let mut val = Vec::with_capacity(self.m_val.len());
        for c in 0..self.n() {
            for p in cp[c]..cp[c + 1] {
                let r = ri[p];
                val.push(if fixed[r] || fixed[c] {
                    if r == c {
                        1.0
                    } else {
                        0.0
                    }
                } else {
                    a * self.m_val[p] + b * self.k_val[p]
                });
            }
        }
        val
    }

    /// F = M g (g: one acceleration per space direction).
    pub fn weight(&self, dim: usize, g: &[f64]) -> Vec<f64> {
        let n = self.n();
        let gv: Vec<f64> = (0..n).map(|i| g[i % dim]).collect();
        let mut f = vec![0.0; n];
        self.mul_add(1.0, 0.0, &gv, &mut f);
        f
    }
}

/// M and K of `mesh` and `elastic` by scikit-fem (unweighted), with the library's
/// version.
pub fn assemble(mesh: &Mesh, elastic: &Elastic) -> Result<(Matrices, String), String> {
    let raw = RawMesh {
        dim: mesh.dim,
        points: mesh.x0.clone(),
        cells: mesh.cells.clone(),
    };
    let a = crate::python::assemble(&raw, elastic.young, elastic.poisson, elastic.density, elastic.plane_stress).map_err(|e| e.0)?;
    if a.m.n != mesh.x0.len() {
        return Err(format!("assembled matrices of size {} for {} dofs", a.m.n, mesh.x0.len()));
    }
    Ok((Matrices::from_csr(&a.m, &a.k)?, a.skfem_version))
}
