//! The embedded Python: scikit-fem assembles M and K, meshio reads meshes.
//!
//! The interpreter starts the first time a scene needs it (a scene without deformable
//! bodies never gets here). It looks for scikit-fem and meshio in, first found:
//! the virtualenv named by `NSCDD_PYTHON_ENV`, the active `VIRTUAL_ENV`, the
//! virtualenv this program was built against (`PYO3_PYTHON=<venv>/bin/python` at
//! build time), `./venv`. Arrays cross the boundary as little-endian bytes.

use pyo3::prelude::*;
use pyo3::types::{PyBytes, PyModule};
use std::ffi::CString;
use std::path::{Path, PathBuf};

/// A matrix in compressed sparse row form (of a symmetric matrix: also its CSC form).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Csr {
    pub n: usize,
    pub indptr: Vec<usize>,
    pub indices: Vec<usize>,
    pub data: Vec<f64>,
}

/// Mesh data as the Python side returns it: node coordinates (node-major) and
/// cell connectivity (`dim + 1` nodes per simplex).
#[derive(Clone, Debug, PartialEq)]
pub struct RawMesh {
    pub dim: usize,
    pub points: Vec<f64>,
    pub cells: Vec<u32>,
}

/// The Python side failed: a message saying what to do.
#[derive(Clone, Debug, PartialEq)]
pub struct PyError(pub String);

impl std::fmt::Display for PyError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}

const INSTALL: &str = "create the virtualenv with `python3 -m venv venv && venv/bin/pip install scikit-fem meshio` \
(./scripts/test.sh does) and point NSCDD_PYTHON_ENV at it";

/// Candidate virtualenvs, in the order they are tried.
pub fn venv_candidates() -> Vec<PathBuf> {
    let mut v = Vec::new();
    for var in ["NSCDD_PYTHON_ENV", "VIRTUAL_ENV"] {
        if let Some(p) = std::env::var_os(var).filter(|p| !p.is_empty()) {
            v.push(PathBuf::from(p));
        }
    }
    if let Some(p) = option_env!("NSCDD_BUILD_VENV") {
        v.push(PathBuf::from(p));
    }
    v.push(PathBuf::from("venv"));
    v
}

/// `<venv>/lib/python3.X/site-packages` directories of a virtualenv.
fn site_packages(venv: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    for lib in ["lib", "lib64"] {
        if let Ok(rd) = std::fs::read_dir(venv.join(lib)) {
            for e in rd.flatten() {
                let sp = e.path().join("site-packages");
                if e.file_name().to_string_lossy().starts_with("python") && sp.is_dir() {
                    out.push(sp);
                }
            }
        }
    }
    out
}

fn err(py: Python<'_>, e: PyErr) -> PyError {
    let tb = e.traceback(py).and_then(|t| t.format().ok()).unwrap_or_default();
    PyError(format!("{}{}", tb, e.value(py)))
}

/// Imports the project's Python module (after adding the virtualenv's site-packages).
fn module(py: Python<'_>) -> Result<Bound<'_, PyModule>, PyError> {
    let sys = py.import("sys").map_err(|e| err(py, e))?;
    let modules = sys.getattr("modules").map_err(|e| err(py, e))?;
    if let Ok(m) = modules.get_item("nscdd_fem") {
        return m.cast_into::<PyModule>().map_err(|e| PyError(e.to_string()));
    }
    let site = py.import("site").map_err(|e| err(py, e))?;
    let tried = venv_candidates();
    for venv in &tried {
        for sp in site_packages(venv) {
            site.call_method1("addsitedir", (sp.display().to_string(),))
                .map_err(|e| err(py, e))?;
        }
    }
    // NumPy's and SciPy's OpenBLAS start a pool of threads per library that spin
    // after each call, taking the cores the solver's threads and ranks run on (5 %
    // of a hybrid run's samples, measured with perf): one thread each, unless the
    // user set otherwise. OpenBLAS reads this when NumPy first loads it.
    let environ = py.import("os").and_then(|os| os.getattr("environ")).map_err(|e| err(py, e))?;
    for var in ["OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS"] {
        environ.call_method1("setdefault", (var, "1")).map_err(|e| err(py, e))?;
    }
    for pkg in ["skfem", "meshio", "numpy"] {
        if py.import(pkg).is_err() {
            let exe: String = sys.getattr("executable").and_then(|x| x.extract()).unwrap_or_default();
            let name = if pkg == "skfem" { "scikit-fem" } else { pkg };
            return Err(PyError(format!(
                "deformable bodies need the Python package `{name}`, not found by Python {} ({exe}) in the virtualenvs tried ({}): {INSTALL}",
                Python::version_str().split_whitespace().next().unwrap_or("?"),
                tried.iter().map(|p| p.display().to_string()).collect::<Vec<_>>().join(", ")
            )));
        }
    }
    let code = CString::new(include_str!("fem.py")).expect("no NUL in fem.py");
    let m = PyModule::from_code(py, &code, c"nscdd_fem.py", c"nscdd_fem").map_err(|e| err(py, e))?;
    modules.set_item("nscdd_fem", &m).map_err(|e| err(py, e))?;
    Ok(m)
}

fn f64s(b: &[u8]) -> Vec<f64> {
    b.chunks_exact(8).map(|c| f64::from_le_bytes(c.try_into().unwrap())).collect()
}
fn i64s(b: &[u8]) -> Vec<i64> {
    b.chunks_exact(8).map(|c| i64::from_le_bytes(c.try_into().unwrap())).collect()
}
fn f64_bytes(v: &[f64]) -> Vec<u8> {
    v.iter().flat_map(|x| x.to_le_bytes()).collect()
}
fn i64_bytes(v: &[u32]) -> Vec<u8> {
    v.iter().flat_map(|&x| (x as i64).to_le_bytes()).collect()
}

fn mesh_out(t: (usize, Vec<u8>, usize, Vec<u8>)) -> Result<RawMesh, PyError> {
    let (dim, p, nv, c) = t;
    let cells = i64s(&c);
    if nv != dim + 1 || cells.iter().any(|&x| x < 0 || x > u32::MAX as i64) {
        return Err(PyError(format!("unexpected cells of {nv} nodes in {dim}D")));
    }
    Ok(RawMesh {
        dim,
        points: f64s(&p),
        cells: cells.into_iter().map(|x| x as u32).collect(),
    })
}

fn call_mesh(name: &str, args: impl for<'py> pyo3::call::PyCallArgs<'py>) -> Result<RawMesh, PyError> {
    Python::attach(|py| {
        let m = module(py)?;
        let r = m.getattr(name).and_then(|f| f.call1(args)).map_err(|e| err(py, e))?;
        let t: (usize, Vec<u8>, usize, Vec<u8>) = r.extract().map_err(|e| err(py, e))?;
        mesh_out(t)
    })
}

/// A structured triangle mesh of the rectangle [x0, x0+lx] × [y0, y0+ly].
pub fn rectangle(origin: [f64; 2], size: [f64; 2], n: [usize; 2]) -> Result<RawMesh, PyError> {
    call_mesh("rectangle", (origin[0], origin[1], size[0], size[1], n[0], n[1]))
}

/// A structured tetrahedral mesh of a box.
pub fn cuboid(origin: [f64; 3], size: [f64; 3], n: [usize; 3]) -> Result<RawMesh, PyError> {
    call_mesh(
        "box",
        (origin[0], origin[1], origin[2], size[0], size[1], size[2], n[0], n[1], n[2]),
    )
}

/// scikit-fem's unstructured disk mesh, `refine` times refined.
pub fn disk(centre: [f64; 2], radius: f64, refine: usize) -> Result<RawMesh, PyError> {
    call_mesh("disk", (centre[0], centre[1], radius, refine))
}

/// Reads a mesh file with meshio (triangles in 2D, tetrahedra in 3D).
pub fn read(path: &Path, dim: usize) -> Result<RawMesh, PyError> {
    call_mesh("read", (path.display().to_string(), dim))
}

/// Assembled mass and stiffness matrices of one body.
#[derive(Clone, Debug)]
pub struct Assembled {
    pub m: Csr,
    pub k: Csr,
    pub skfem_version: String,
}

/// M (consistent mass, density ρ) and K (linear elasticity, E, ν; 2D plane strain,
/// or plane stress) by scikit-fem, in node-major dof order.
pub fn assemble(mesh: &RawMesh, young: f64, poisson: f64, density: f64, plane_stress: bool) -> Result<Assembled, PyError> {
    assemble_scaled(mesh, young, poisson, density, plane_stress, None)
}

/// [`assemble`] with both forms weighted cell by cell by `scale` (one number per
/// cell: a continuum region's share of its overlap band, [`crate::continuum`]).
pub fn assemble_scaled(
    mesh: &RawMesh,
    young: f64,
    poisson: f64,
    density: f64,
    plane_stress: bool,
    scale: Option<&[f64]>,
) -> Result<Assembled, PyError> {
    Python::attach(|py| {
        let m = module(py)?;
        let p = PyBytes::new(py, &f64_bytes(&mesh.points));
        let c = PyBytes::new(py, &i64_bytes(&mesh.cells));
        let s = scale.map(|s| PyBytes::new(py, &f64_bytes(s)));
        let r = m
            .getattr("assemble")
            .and_then(|f| f.call1((mesh.dim, p, c, young, poisson, density, plane_stress, s)))
            .map_err(|e| err(py, e))?;
        type Arr = (Vec<u8>, Vec<u8>, Vec<u8>);
        let (mm, kk, ver): (Arr, Arr, String) = r.extract().map_err(|e| err(py, e))?;
        let n = mesh.points.len();
        let csr = |(d, i, p): Arr| Csr {
            n,
            indptr: i64s(&p).into_iter().map(|x| x as usize).collect(),
            indices: i64s(&i).into_iter().map(|x| x as usize).collect(),
            data: f64s(&d),
        };
        Ok(Assembled {
            m: csr(mm),
            k: csr(kk),
            skfem_version: ver,
        })
    })
}
