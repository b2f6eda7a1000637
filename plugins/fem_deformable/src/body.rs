//! One linear elastic body: its mesh, M and K, the iteration matrix M̂ and its
//! Cholesky factor, its state and the θ-method of DESIGN.md §2.
//!
//! With the Rayleigh damping C = α M + β K and the θ-weighted internal force
//! −K(θ u⁺ + (1−θ) u⁻) − C(θ V⁺ + (1−θ) V⁻), where u⁺ = u⁻ + h((1−θ)V⁻ + θV⁺):
//!
//! ```text
//! M̂ (V⁺ − V⁻) = h (F_ext − K (u⁻ + hθ V⁻) − C V⁻) + H r,   M̂ = M + hθ C + h²θ² K
//! V_free = V⁻ + M̂⁻¹ h (F_ext − K (u⁻ + hθ V⁻) − C V⁻)
//! u⁺ = u⁻ + h ((1 − θ) V⁻ + θ V⁺)
//! ```
//!
//! θ = ½ conserves the energy ½ VᵀMV + ½ uᵀKu − u·F_ext of a free body; θ > ½
//! dissipates it. M̂ is factored once (faer's supernodal Cholesky: the symbolic
//! analysis once per body, a numeric refactorization only when h, θ or the
//! material change). On MPI ranks a large body's M and K ([`Matrices`]) and
//! factors are held only where it is stepped: a rank drops them when it does not
//! step it ([`FeBody::release_matrices`], [`crate::stepped`]) and assembles and
//! factors them again, the same numbers, when it does ([`FeBody::ensure_matrices`]).
//! Degrees of freedom held fixed (Dirichlet, zero velocity) have their rows and
//! columns of M̂ replaced by the identity and a zero right-hand side.
//!
//! Contacts need columns of M̂⁻¹ at their nodes (the Delassus blocks and the NLGS
//! velocity updates): [`FeBody::column`] solves for the `dim` columns of a node on
//! first use and caches them while M̂ is unchanged (see docs/DEFORMABLE.md for the
//! choice and its cost).

use crate::matrices::Matrices;
use crate::mesh::Mesh;
use crate::python::Csr;
use faer::prelude::*;
use faer::sparse::linalg::solvers::{Llt, SymbolicLlt};
use faer::sparse::SparseColMat;
use faer::{Mat, Side};
use std::collections::HashMap;

/// Elastic material of a deformable body.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Elastic {
    /// Young's modulus E (Pa).
    pub young: f64,
    /// Poisson's ratio ν.
    pub poisson: f64,
    /// Density ρ (kg/m³).
    pub density: f64,
    /// 2D: plane stress instead of plane strain.
    pub plane_stress: bool,
    /// Rayleigh damping C = α M + β K: [α (1/s), β (s)].
    pub rayleigh: [f64; 2],
}

/// A deformable body (see the module docs).
pub struct FeBody {
    pub name: Option<String>,
    pub mesh: Mesh,
    pub elastic: Elastic,
    /// Index of the body's material among the scene's materials (for the laws).
    pub material: u16,
    /// M and K ([`Matrices`]; `None` on an MPI rank that does not step the body:
    /// [`Self::ensure_matrices`] assembles them again, the same numbers).
    mats: Option<Matrices>,
    /// Whether [`Self::release_matrices`] may drop M, K and F_ext (a body whose M,
    /// K and F_ext are made from its mesh, material and gravity alone).
    releasable: bool,
    /// The acceleration of gravity F_ext = M g is made of.
    gravity: Vec<f64>,
    /// The symbolic and numeric Cholesky factors of M̂ (`None` until first needed,
    /// or dropped by [`Self::release_factor`]: rebuilt from the pattern, M and K
    /// with the same bits).
    symbolic: Option<SymbolicLlt<usize>>,
    factor: Option<Llt<usize, f64>>,
    /// (h, θ) the factor was computed for.
    factored_for: (f64, f64),
    /// Fixed degrees of freedom.
    pub fixed: Vec<bool>,
    /// Displacement u, velocity V (V⁻ at the start of a step, V⁺ after it),
    /// V⁻ kept during a step, free velocity.
    pub u: Vec<f64>,
    pub v: Vec<f64>,
    pub v_begin: Vec<f64>,
    pub v_free: Vec<f64>,
    /// External load per dof (gravity: M g; empty while M is not held).
    pub f_ext: Vec<f64>,
    /// A force of the step beside F_ext (empty: none): a continuum's plastic strains'
    /// share f_p of the internal force K u − f_p ([`crate::continuum::plastic`]).
    pub f_plastic: Vec<f64>,
    /// Cached columns of M̂⁻¹, `dim` per node (node-major inside).
    columns: HashMap<u32, Vec<f64>>,
    /// Column solves done since the last refactorization (a measure).
    pub solves: u64,
    /// Counts the changes of M̂⁻¹ (refactorizations, fixed dofs): what was built
    /// from its columns at another count is stale ([`crate::nodes::fill_set`]).
    generation: u64,
    pub skfem_version: String,
}

impl FeBody {
    /// Builds a body from its assembled M and K (same dof order as the mesh).
    pub fn new(
        name: Option<String>,
        mesh: Mesh,
        elastic: Elastic,
        material: u16,
        m: &Csr,
        k: &Csr,
        skfem_version: String,
    ) -> Result<FeBody, String> {
        let n = mesh.x0.len();
        if m.n != n || k.n != n {
            return Err(format!("assembled matrices of size {}, {} for {} dofs", m.n, k.n, n));
        }
        let mut b = FeBody::light(name, mesh, elastic, material);
        b.mats = Some(Matrices::from_csr(m, k)?);
        b.f_ext = vec![0.0; n];
        b.skfem_version = skfem_version;
        Ok(b)
    }

    /// A body without M and K (a body an MPI rank does not step): its mesh, material
    /// and state; [`Self::ensure_matrices`] assembles them when it is stepped.
    pub fn light(name: Option<String>, mesh: Mesh, elastic: Elastic, material: u16) -> FeBody {
        let n = mesh.x0.len();
        FeBody {
            name,
            mesh,
            elastic,
            material,
            mats: None,
            releasable: false,
            gravity: Vec::new(),
            symbolic: None,
            factor: None,
            factored_for: (f64::NAN, f64::NAN),
            fixed: vec![false; n],
            u: vec![0.0; n],
            v: vec![0.0; n],
            v_begin: vec![0.0; n],
            v_free: vec![0.0; n],
            f_ext: Vec::new(),
            f_plastic: Vec::new(),
            columns: HashMap::new(),
            solves: 0,
            generation: 0,
            skfem_version: String::new(),
        }
    }

    /// M and K, held ([`Self::ensure_matrices`] before any use).
    fn mats(&self) -> &Matrices {
        self.mats
            .as_ref()
            .expect("M and K are assembled before use (FeBody::ensure_matrices)")
    }

    /// Whether M and K are held now.
    pub fn has_matrices(&self) -> bool {
        self.mats.is_some()
    }

    /// Assembles M and K (and F_ext = M g) if they are not held (a body an MPI rank
    /// starts to step): the same scikit-fem assembly of the same mesh and material
    /// as at load, the same numbers. Returns whether it assembled.
    pub fn ensure_matrices(&mut self) -> Result<bool, String> {
        if self.mats.is_some() {
            return Ok(false);
        }
        let (m, version) = crate::matrices::assemble(&self.mesh, &self.elastic)?;
        self.f_ext = m.weight(self.dim(), &self.gravity);
        self.mats = Some(m);
        self.skfem_version = version;
        Ok(true)
    }

    /// Lets [`Self::release_matrices`] drop M, K and F_ext (a body whose M and K
    /// are its mesh's and material's unweighted assembly and F_ext = M g).
    pub fn allow_release(&mut self) {
        self.releasable = true;
    }

    /// Whether [`Self::allow_release`] was called.
    pub fn is_releasable(&self) -> bool {
        self.releasable
    }

    /// Drops M, K, F_ext, the factors and the columns of a body
    /// [`Self::allow_release`] was called for (else the factors and columns only):
    /// a body this MPI rank does not step ([`crate::stepped`]).
    pub fn release_matrices(&mut self) {
        self.release_factor();
        if self.releasable {
            self.mats = None;
            self.f_ext = Vec::new();
        }
    }

    pub fn dim(&self) -> usize {
        self.mesh.dim
    }
    pub fn n_dofs(&self) -> usize {
        self.mesh.x0.len()
    }
    /// Nonzeros of M̂ (both triangles).
    pub fn nnz(&self) -> usize {
        self.mats().nnz()
    }

    /// y += a M x + b K x (M and K on the shared pattern).
    pub fn mul_add(&self, a: f64, b: f64, x: &[f64], y: &mut [f64]) {
        self.mats().mul_add(a, b, x, y);
    }

    /// Loads of gravity: F_ext = M g (made when M is, if it is not held now).
    pub fn set_gravity(&mut self, g: &[f64]) {
        self.gravity = g.to_vec();
        if let Some(m) = &self.mats {
            self.f_ext = m.weight(self.dim(), g);
        }
    }

    /// Holds the given nodes fixed (all their components).
    pub fn fix_nodes(&mut self, nodes: &[u32]) {
        let d = self.dim();
        let dofs: Vec<usize> = nodes.iter().flat_map(|&k| (0..d).map(move |c| d * k as usize + c)).collect();
        self.fix_dofs(&dofs);
    }

    /// Fixes degrees of freedom (node-major indices); M̂ is factored again.
    pub fn fix_dofs(&mut self, dofs: &[usize]) {
        for &i in dofs {
            self.fixed[i] = true;
        }
        self.factor = None;
        self.columns.clear();
        self.generation += 1;
    }

    /// Factors M̂ = (1 + hθα) M + (h²θ² + hθβ) K if (h, θ) changed or the factor
    /// was released (the symbolic analysis is reused while kept). Returns whether a
    /// numeric factorization was done.
    pub fn factorize(&mut self, h: f64, theta: f64) -> Result<bool, String> {
        if self.factor.is_some() && self.factored_for == (h, theta) {
            return Ok(false);
        }
        let symbolic = match &self.symbolic {
            Some(s) => s.clone(),
            None => {
                let Some(mats) = &self.mats else {
                    return Err("M and K are not assembled (FeBody::ensure_matrices)".into());
                };
                let s = SymbolicLlt::try_new(mats.pattern.as_ref(), Side::Lower).map_err(|e| format!("symbolic Cholesky failed: {e:?}"))?;
                self.symbolic = Some(s.clone());
                s
            }
        };
        let [al, be] = self.elastic.rayleigh;
        let (a, b) = (1.0 + h * theta * al, h * h * theta * theta + h * theta * be);
        let Some(mats) = &self.mats else {
            return Err("M and K are not assembled (FeBody::ensure_matrices)".into());
        };
        let val = mats.m_hat(a, b, &self.fixed);
        let mat = SparseColMat::new(mats.pattern.clone(), val);
        let llt = Llt::try_new_with_symbolic(symbolic, mat.as_ref(), Side::Lower)
            .map_err(|e| format!("M̂ = M + h²θ²K is not positive definite ({e:?}): check E, ν, ρ and the mesh"))?;
        self.factor = Some(llt);
        self.factored_for = (h, theta);
        self.columns.clear();
        self.generation += 1;
        self.solves = 0;
        Ok(true)
    }

    /// x ← M̂⁻¹ x (fixed dofs get 0).
    pub fn solve_in_place(&self, x: &mut [f64]) {
        for (xi, &f) in x.iter_mut().zip(&self.fixed) {
            if f {
                *xi = 0.0;
            }
        }
        let llt = self.factor.as_ref().expect("M̂ is factored before any solve");
        let mut m = Mat::<f64>::from_fn(x.len(), 1, |r, _| x[r]);
        llt.solve_in_place(m.as_mut());
        for (r, xi) in x.iter_mut().enumerate() {
            *xi = m[(r, 0)];
        }
    }

    /// The free velocity V_free (module docs); keeps V⁻.
    pub fn free_velocity(&mut self, h: f64, theta: f64) {
        let n = self.n_dofs();
        self.v_begin.clone_from(&self.v);
        let [al, be] = self.elastic.rayleigh;
        // rhs = h (F_ext + f_p − K (u + hθ V) − C V) = h (F_ext + f_p) − h (α M V) − h K (u + (hθ + β) V)
        let mut w: Vec<f64> = (0..n).map(|i| self.u[i] + (h * theta + be) * self.v[i]).collect();
        let mut rhs: Vec<f64> = self.f_ext.iter().map(|f| h * f).collect();
        for (r, f) in rhs.iter_mut().zip(&self.f_plastic) {
            *r += h * f;
        }
        self.mul_add(0.0, -h, &w, &mut rhs);
        if al != 0.0 {
            self.mul_add(-h * al, 0.0, &self.v, &mut rhs);
        }
        self.solve_in_place(&mut rhs);
        for i in 0..n {
            w[i] = self.v[i] + rhs[i];
        }
        self.v_free = w;
    }

    /// The `dim` columns of M̂⁻¹ at `node` (component c of the node at
    /// `[c * n_dofs ..]`), solved on first use and cached.
    pub fn column(&mut self, node: u32) -> &[f64] {
        if !self.columns.contains_key(&node) {
            let (d, n) = (self.dim(), self.n_dofs());
            let mut out = vec![0.0; d * n];
            for c in 0..d {
                let x = &mut out[c * n..(c + 1) * n];
                x[d * node as usize + c] = 1.0;
                self.solve_in_place(x);
            }
            self.solves += d as u64;
            self.columns.insert(node, out);
        }
        &self.columns[&node]
    }

    /// Solves the columns of the nodes of `nodes` not cached yet in one solve with
    /// many right-hand sides (the factor is traversed once for all of them: several
    /// times faster per column than one by one on 3D meshes).
    pub fn ensure_columns(&mut self, nodes: &[u32]) {
        let missing: Vec<u32> = nodes.iter().copied().filter(|k| !self.columns.contains_key(k)).collect();
        let (d, n) = (self.dim(), self.n_dofs());
        // in blocks, to bound the memory of the dense right-hand side
        for chunk in missing.chunks(64) {
            let mut m = Mat::<f64>::zeros(n, d * chunk.len());
            for (j, &node) in chunk.iter().enumerate() {
                for c in 0..d {
                    let r = d * node as usize + c;
                    if !self.fixed[r] {
                        m[(r, d * j + c)] = 1.0;
                    }
                }
            }
            let llt = self.factor.as_ref().expect("M̂ is factored before any solve");
            llt.solve_in_place(m.as_mut());
            for (j, &node) in chunk.iter().enumerate() {
                let mut out = vec![0.0; d * n];
                for c in 0..d {
                    let col = m.col(d * j + c);
                    for (r, x) in out[c * n..(c + 1) * n].iter_mut().enumerate() {
                        *x = if self.fixed[r] { 0.0 } else { col[r] };
                    }
                }
                self.columns.insert(node, out);
            }
            self.solves += (d * chunk.len()) as u64;
        }
    }

    /// Whether an impulse along `n` at the point Σ_q w_q x_q (nodes `nodes`) moves
    /// the body: some node with w_q ≠ 0 has a free degree of freedom c with
    /// n_c ≠ 0. Then the point's block of M̂⁻¹ along n is positive (M̂ restricted to
    /// the free degrees of freedom is positive definite; the columns are 0 on the
    /// fixed ones): a test of W_αα > 0 without the columns.
    pub fn mobile(&self, nodes: &[u32], w: &[f64], n: &[f64]) -> bool {
        let d = self.dim();
        nodes
            .iter()
            .zip(w)
            .any(|(&k, &wq)| wq != 0.0 && (0..d).any(|c| n[c] != 0.0 && !self.fixed[d * k as usize + c]))
    }

    /// Drops the state u, V, V⁻ and V_free (a body whose boundary an MPI rank
    /// holds stale, [`crate::near`]): its mesh, material and matrices stay.
    pub fn release_state(&mut self) {
        for x in [&mut self.u, &mut self.v, &mut self.v_begin, &mut self.v_free] {
            *x = Vec::new();
        }
    }

    /// The state made again where released ([`Self::release_state`]), at zero: a
    /// body whose boundary or whole state an MPI rank receives.
    pub fn ensure_state(&mut self) {
        let n = self.n_dofs();
        for x in [&mut self.u, &mut self.v, &mut self.v_begin, &mut self.v_free] {
            if x.len() != n {
                *x = vec![0.0; n];
            }
        }
    }

    /// Drops every cached column and their memory (a body this MPI rank no longer
    /// steps, [`crate::stepped`]).
    pub fn release_columns(&mut self) {
        self.columns = HashMap::new();
    }

    /// Drops the factors of M̂ and the cached columns (a body this MPI rank does not
    /// step, [`crate::stepped`]); the next [`Self::factorize`] makes them again, the
    /// same numbers (the symbolic analysis and the numeric factorization are
    /// deterministic functions of the pattern, M, K, h, θ and the fixed dofs).
    pub fn release_factor(&mut self) {
        self.release_columns();
        (self.factor, self.symbolic) = (None, None);
        self.factored_for = (f64::NAN, f64::NAN);
        self.generation += 1;
    }

    /// Whether M̂ is factored now.
    pub fn is_factored(&self) -> bool {
        self.factor.is_some()
    }

    /// Keeps the cached columns of `keep` only (memory bound between steps).
    pub fn retain_columns(&mut self, keep: &[u32]) {
        self.columns.retain(|k, _| keep.binary_search(k).is_ok());
    }
    /// The count of M̂⁻¹'s changes (refactorizations, fixed dofs).
    pub fn generation(&self) -> u64 {
        self.generation
    }
    pub fn cached_columns(&self) -> usize {
        self.columns.len()
    }

    /// Current position of node k.
    pub fn position(&self, k: usize) -> [f64; 3] {
        let d = self.dim();
        let mut p = [0.0; 3];
        for c in 0..d {
            p[c] = self.mesh.x0[d * k + c] + self.u[d * k + c];
        }
        p
    }

    /// [`Self::energies`] at the body's u and V; M and K assembled aside if they are
    /// not held (the same numbers: a body an MPI rank does not step).
    pub fn energies_now(&self) -> Result<[f64; 3], String> {
        if self.mats.is_some() {
            return Ok(self.energies(&self.u, &self.v));
        }
        let (m, _) = crate::matrices::assemble(&self.mesh, &self.elastic)?;
        let f_ext = m.weight(self.dim(), &self.gravity);
        Ok(energies_with(&m, &f_ext, &self.u, &self.v))
    }

    /// ½ VᵀMV.
    pub fn kinetic_energy(&self) -> f64 {
        self.energies(&self.u, &self.v)[0]
    }
    /// ½ uᵀKu.
    pub fn elastic_energy(&self) -> f64 {
        self.energies(&self.u, &self.v)[1]
    }
    /// −u·F_ext (the potential of the constant external loads, gravity).
    pub fn load_potential(&self) -> f64 {
        -dot(&self.u, &self.f_ext)
    }
    /// Component i of u⁺ = u⁻ + h((1 − θ)V⁻ + θV⁺) (V⁻ = `v_begin`, V⁺ = `v`).
    #[inline]
    pub fn u_next(&self, i: usize, h: f64, theta: f64) -> f64 {
        self.u[i] + h * ((1.0 - theta) * self.v_begin[i] + theta * self.v[i])
    }
    /// [½ vᵀMv, ½ uᵀKu, −u·F_ext] at displacements `u` and velocities `v`, in one
    /// pass over the pattern of M and K (stored whole: column c's sums times x_c),
    /// without allocation.
    pub fn energies(&self, u: &[f64], v: &[f64]) -> [f64; 3] {
        energies_with(self.mats(), &self.f_ext, u, v)
    }
    /// Total mass (Σ of M's entries of one component).
    pub fn mass(&self) -> f64 {
        let ones: Vec<f64> = (0..self.n_dofs()).map(|i| if i % self.dim() == 0 { 1.0 } else { 0.0 }).collect();
        let mut m1 = vec![0.0; self.n_dofs()];
        self.mul_add(1.0, 0.0, &ones, &mut m1);
        dot(&ones, &m1)
    }
}

/// [½ vᵀMv, ½ uᵀKu, −u·F_ext] of M and K `m` and the load `f_ext`.
fn energies_with(m: &Matrices, f_ext: &[f64], u: &[f64], v: &[f64]) -> [f64; 3] {
    let [ke, se] = m.energies(u, v);
    [ke, se, -dot(u, f_ext)]
}

pub fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}
