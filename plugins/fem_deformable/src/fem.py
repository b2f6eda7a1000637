"""Finite-element assembly for nscdd's deformable bodies (called from Rust).

Meshes: linear triangles (2D) and linear tetrahedra (3D). Degrees of freedom are
node-major (dof = dim * node + component), the order nscdd uses. Arrays go back to
Rust as little-endian bytes (float64 / int64) so that no numpy binding is needed.
"""
import warnings

import numpy as np
import skfem
from skfem import Basis, BilinearForm, ElementTetP1, ElementTriP1, ElementVector, MeshTet, MeshTri, asm
from skfem.helpers import ddot, dot, sym_grad, trace
from skfem.models.elasticity import lame_parameters, linear_elasticity

# an overflow or a NaN in a mesh or its matrices is an error (naming the scene's key),
# not a warning on stderr
warnings.simplefilter("error", RuntimeWarning)


def _mesh_out(points, cells):
    points = np.ascontiguousarray(points, dtype="<f8")
    cells = np.ascontiguousarray(cells, dtype="<i8")
    return points.shape[1], points.tobytes(), cells.shape[1], cells.tobytes()


def rectangle(x0, y0, lx, ly, nx, ny):
    m = MeshTri.init_tensor(np.linspace(x0, x0 + lx, nx + 1), np.linspace(y0, y0 + ly, ny + 1))
    return _mesh_out(m.p.T, m.t.T)


def box(x0, y0, z0, lx, ly, lz, nx, ny, nz):
    m = MeshTet.init_tensor(
        np.linspace(x0, x0 + lx, nx + 1), np.linspace(y0, y0 + ly, ny + 1), np.linspace(z0, z0 + lz, nz + 1)
    )
    return _mesh_out(m.p.T, m.t.T)


def disk(cx, cy, radius, refine):
    m = MeshTri.init_circle(refine)
    p = m.p * radius
    p[0] += cx
    p[1] += cy
    return _mesh_out(p.T, m.t.T)


def read(path, dim):
    import meshio

    m = meshio.read(path)
    want = "triangle" if dim == 2 else "tetra"
    blocks = [c.data for c in m.cells if c.type == want]
    if not blocks:
        kinds = sorted({c.type for c in m.cells})
        raise ValueError(f"the mesh has no {want} cells (it has: {', '.join(kinds) or 'none'})")
    cells = np.vstack(blocks)
    used = np.unique(cells)
    remap = -np.ones(len(m.points), dtype=np.int64)
    remap[used] = np.arange(len(used))
    pts = m.points[used, :dim]
    return _mesh_out(pts, remap[cells])


def _basis(points, cells):
    dim = points.shape[1]
    # scikit-fem wants (dim, n) arrays C-contiguous (else it copies and logs it)
    p, t = np.ascontiguousarray(points.T), np.ascontiguousarray(cells.T)
    if dim == 2:
        mesh, elem = MeshTri(p, t), ElementTriP1()
    else:
        mesh, elem = MeshTet(p, t), ElementTetP1()
    return Basis(mesh, ElementVector(elem)), dim


def _csr_out(a, perm):
    a = a.tocsr()[perm][:, perm].tocsr()
    a.sort_indices()
    return (
        np.ascontiguousarray(a.data, dtype="<f8").tobytes(),
        np.ascontiguousarray(a.indices, dtype="<i8").tobytes(),
        np.ascontiguousarray(a.indptr, dtype="<i8").tobytes(),
    )


def assemble(dim, points, cells, young, poisson, density, plane_stress, scale=None):
    """Consistent mass M (density rho) and stiffness K of linear elasticity.

    2D: plane strain, or plane stress with lambda* = 2 lambda mu / (lambda + 2 mu).
    `scale` (bytes of one float64 per cell, optional): both forms weighted by it,
    cell by cell (a continuum region's share of an overlap band).
    Returns the CSR arrays of M and K in nscdd's node-major dof order.
    """
    points = np.frombuffer(points, dtype="<f8").reshape(-1, dim)
    cells = np.frombuffer(cells, dtype="<i8").reshape(-1, dim + 1)
    basis, dim = _basis(points, cells)
    lam, mu = lame_parameters(young, poisson)
    if dim == 2 and plane_stress:
        lam = 2.0 * lam * mu / (lam + 2.0 * mu)
    if scale is None:
        K = asm(linear_elasticity(lam, mu), basis)

        @BilinearForm
        def mass(u, v, w):
            return density * dot(u, v)

        M = asm(mass, basis)
    else:
        s = np.frombuffer(scale, dtype="<f8")
        s = np.ascontiguousarray(np.repeat(s[:, None], basis.X.shape[-1], axis=1))

        @BilinearForm
        def stiffness(u, v, w):
            e_u, e_v = sym_grad(u), sym_grad(v)
            return w["s"] * (lam * trace(e_u) * trace(e_v) + 2.0 * mu * ddot(e_u, e_v))

        @BilinearForm
        def mass(u, v, w):
            return w["s"] * density * dot(u, v)

        K = asm(stiffness, basis, s=s)
        M = asm(mass, basis, s=s)
    # basis.nodal_dofs[c, i]: the dof of component c at node i
    order = np.asarray(basis.nodal_dofs).T.reshape(-1)
    perm = np.empty_like(order)
    perm[np.arange(order.size)] = order
    return _csr_out(M, perm), _csr_out(K, perm), skfem.__version__
