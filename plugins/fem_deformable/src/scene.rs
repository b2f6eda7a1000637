//! `[[deformable]]` entries of a scene file and the scenes that hold them
//! ([`FeScene2`], [`FeScene3`]; the file's `dimension` chooses).
//!
//! ```toml
//! [[deformable]]
//! name = "foundation"            # optional
//! material = "soil"              # a [[materials]] name: density ρ and the laws
//! young = 1e7                    # E (Pa)
//! poisson = 0.3                  # ν ∈ [0, 0.5)
//! plane = "strain"               # or "stress" (2D)
//! rayleigh = [0.0, 0.0]          # C = α M + β K (optional)
//! velocity = [0.0, 0.0]          # initial, uniform (optional)
//! fix = ["bottom"]               # hold the nodes of these sides of the mesh's box
//! mesh = { rectangle = { origin = [0.0, 0.0], size = [1.0, 0.5], cells = [20, 10] } }
//! # or  mesh = { disk = { centre = [0.0, 1.0], radius = 0.1, refine = 4 } }
//! # or  mesh = { file = "block.msh" }       (anything meshio reads; relative to the scene)
//! ```
//!
//! In 3D (`dimension = 3`): `velocity` has 3 numbers, there is no `plane`, the
//! sides are `bottom`/`top` (z), `left`/`right` (x), `front`/`back` (y), and the
//! generated mesh is a box of tetrahedra:
//!
//! ```toml
//! mesh = { box = { origin = [0.0, 0.0, 0.0], size = [1.0, 1.0, 0.5], cells = [8, 8, 4] } }
//! ```

use crate::body::{Elastic, FeBody};
use crate::mesh::Mesh;
use crate::python;
use crate::stage2::Deformables2;
use crate::stage3::Deformables3;
use nscdd::dd::{DdConfig, NscddOf, Rigid};
use nscdd::dim::{Dim, D2, D3};
use nscdd::engine::{Diverged, StepReport};
use nscdd::error::InputError;
use nscdd::family::{EntryError, SceneFamily};
use nscdd::registry::Registry;
use nscdd::scene::schema::SceneDim;
use nscdd::scene::{OutputSettings, Scene};
use nscdd::world::{Material, World};
use serde::Deserialize;
use std::path::Path;

#[derive(Deserialize, Debug)]
#[serde(deny_unknown_fields)]
pub struct DeformableSpec {
    pub name: Option<String>,
    pub material: String,
    pub young: f64,
    pub poisson: f64,
    /// 2D only: `strain` (default) or `stress`.
    pub plane: Option<String>,
    #[serde(default)]
    pub rayleigh: [f64; 2],
    #[serde(default)]
    pub velocity: Vec<f64>,
    #[serde(default)]
    pub fix: Vec<String>,
    pub mesh: MeshSpec,
}

#[derive(Deserialize, Debug, Clone)]
#[serde(deny_unknown_fields, rename_all = "lowercase")]
pub enum MeshSpec {
    Rectangle { origin: [f64; 2], size: [f64; 2], cells: [i64; 2] },
    Box { origin: [f64; 3], size: [f64; 3], cells: [i64; 3] },
    Disk { centre: [f64; 2], radius: f64, refine: i64 },
    File(String),
}

/// A scene with deformable bodies, typed: the rigid world, the deformable stage
/// (`S`: [`Deformables2`] or [`Deformables3`]) and, with a `[decomposition]`, the
/// NSCDD stage that glues the subdomains. Loaded by the framework's loader
/// ([`nscdd::scene`], the `[[deformable]]` section built by [`crate::family`]); for
/// programs and tests that step a scene themselves (the CLI runs
/// [`nscdd::scene::Scene`] with its families through [`nscdd::run`]).
pub struct FeScene<D: Dim, S> {
    pub world: World<D>,
    pub fe: S,
    pub output: OutputSettings,
    /// The scene's `[decomposition]` (by model and/or by geometry).
    pub decomposition: Option<DdConfig>,
    /// The NSCDD state, made at the first step from `decomposition`.
    pub dd: Option<NscddOf<Rigid<D>>>,
}

/// A 2D scene with deformable bodies.
pub type FeScene2 = FeScene<D2, Deformables2>;
/// A 3D scene with deformable bodies.
pub type FeScene3 = FeScene<D3, Deformables3>;

/// The scene of `text` with its deformable family taken out, typed.
fn typed<D: SceneDim, S: SceneFamily<D>>(text: &str, file: &str, registry: &Registry) -> Result<FeScene<D, S>, InputError> {
    let scene = Scene::<D>::load_str(text, file, registry)?;
    let Scene {
        world,
        output,
        decomposition,
        families,
        ..
    } = scene;
    let mut fe = None;
    for f in families {
        let any: Box<dyn std::any::Any> = f;
        if let Ok(s) = any.downcast::<S>() {
            fe = Some(*s);
        }
    }
    let fe = fe.ok_or_else(|| InputError {
        file: file.to_string(),
        line: None,
        key: crate::family::SECTION.into(),
        message: "the scene has no [[deformable]] bodies".into(),
    })?;
    Ok(FeScene {
        world,
        fe,
        output,
        decomposition,
        dd: None,
    })
}

/// Loads a 2D scene with `[[deformable]]` bodies from its text (the registry must
/// hold [`crate::FemPlugin`]); mesh files are found beside `file`.
pub fn load_str(text: &str, file: &str, registry: &Registry) -> Result<FeScene2, InputError> {
    typed(text, file, registry)
}

/// [`load_str`] of a 3D scene (`dimension = 3`).
pub fn load3_str(text: &str, file: &str, registry: &Registry) -> Result<FeScene3, InputError> {
    typed(text, file, registry)
}

/// The error of entry `i` of a family's section at `key` (empty: the entry).
pub fn entry_error(i: usize, key: &str, message: impl Into<String>) -> EntryError {
    EntryError {
        index: Some(i),
        key: key.into(),
        message: message.into(),
    }
}

/// Reads a file entry into a [`DeformableSpec`]; an error names the key serde
/// complained about when it says which.
pub fn spec_of(i: usize, e: &toml::Table) -> Result<DeformableSpec, EntryError> {
    DeformableSpec::deserialize(toml::Value::Table(e.clone())).map_err(|x| {
        let msg = x.message().to_string();
        let key = msg.split('`').nth(1).filter(|k| !k.contains(' ')).unwrap_or("");
        EntryError {
            index: Some(i),
            key: key.into(),
            message: msg.clone(),
        }
    })
}

/// Builds the deformable bodies of a scene's `[[deformable]]` entries, factored
/// for the scene's h and θ (mesh files are relative to the scene's folder). Loaded
/// for a run on P MPI ranks (`cx.ranks`), rank r assembles and factors only the
/// bodies i with ⌊i P / N⌋ = r (N bodies: a contiguous share, as the subdomains
/// of a rank are), to check them; it holds every body's mesh and state, and
/// assembles and factors a body (the same numbers) when it first steps it
/// ([`crate::stepped`]: a large body, [`crate::stepped::RELEASE_MIN_BYTES`], it
/// does not step is dropped, factors first; a smaller one is kept once made,
/// unless it is far from the rank's cells).
/// No rank assembles every body at load, nor holds every body's matrices; a
/// body's error is reported by the rank that checks it.
pub fn bodies_from<D: nscdd::dim::Dim>(
    entries: &[toml::Table],
    cx: &nscdd::family::FamilyContext<'_, D>,
) -> Result<Vec<FeBody>, EntryError> {
    let (dir, dim, time) = (cx.dir, D::N, &cx.world.time);
    let materials = &cx.world.materials;
    let mut bodies = Vec::new();
    // bytes of the bodies before entry i
    let mut held = 0.0;
    for (i, e) in entries.iter().enumerate() {
        let at = |key: &str, message: String| entry_error(i, key, message);
        let spec = spec_of(i, e)?;
        // (on P ranks a large body counts 1/P: a rank holds the matrices of those it
        // checks, then of those it steps, about 1/P of them)
        let mut check = |nodes: f64| {
            let share = match cx.ranks {
                Some((_, p)) if large(dim, nodes) => 1.0 / f64::from(p.max(1)),
                _ => 1.0,
            };
            let bytes = share * mesh_bytes(dim, nodes);
            let what = match i {
                0 => format!("a deformable body of about {nodes:.0} nodes"),
                _ => format!("{} deformable bodies, the last of about {nodes:.0} nodes", i + 1),
            };
            cx.check_memory(held + bytes, &what).map(|()| held += bytes)
        };
        let mut b = build_with(&spec, materials, dim, dir, &mut check, Assembly::Deferred).map_err(|(k, m)| at(k, m))?;
        b.set_gravity(&cx.world.gravity.as_ref()[..dim]);
        // (its M, K and F_ext = M g are made from its mesh, material and gravity)
        b.allow_release();
        // (on ranks: assembled by the rank checking it only)
        if cx.ranks.is_none_or(|(me, p)| checked_by(i, entries.len(), p) == me) {
            b.ensure_matrices().map_err(|m| at("mesh", m))?;
            b.factorize(time.h, time.theta).map_err(|m| at("", m))?;
        }
        bodies.push(b);
    }
    Ok(bodies)
}

/// Whether a body of `nodes` nodes is large: its M, K and factors
/// ([`matrices_bytes`]) reach [`crate::stepped::RELEASE_MIN_BYTES`] (or
/// `NSCDD_FE_RELEASE`'s size, [`crate::stepped::release_rule`]).
fn large(dim: usize, nodes: f64) -> bool {
    matrices_bytes(dim, nodes) >= crate::stepped::release_rule().0
}

/// Whether body `b` is large (its [`matrices_bytes`] reach
/// [`crate::stepped::RELEASE_MIN_BYTES`]): a rank drops its factors and matrices
/// when it does not step it ([`crate::stepped::Stepped::release`]).
pub fn is_large(b: &FeBody) -> bool {
    large(b.dim(), b.mesh.n_nodes() as f64)
}

/// The rank of `ranks` that checks body `b` of `n` at load ([`bodies_from`]) and
/// steps it while it has no contact ([`crate::stepped`]): ⌊b P / n⌋, a contiguous
/// share of the bodies (as the subdomains of a rank are).
pub fn checked_by(b: usize, n: usize, ranks: u32) -> u32 {
    ((b as u64 * u64::from(ranks)) / (n as u64).max(1)) as u32
}

/// A law with a compliance ([`nscdd::law::Law::compliance`], law `compliant`)
/// between a deformable body's material and any material is refused, naming the
/// body's `material`: the deformable contacts' sweep solves rigid contacts only.
pub fn refuse_compliant<D: nscdd::dim::Dim>(bodies: &[FeBody], w: &World<D>) -> Result<(), EntryError> {
    let step = nscdd::law::LawStep {
        h: w.time.h,
        theta: w.time.theta,
        first: true,
    };
    for (i, b) in bodies.iter().enumerate() {
        for (j, other) in w.materials.iter().enumerate() {
            if w.law(b.material, j as u16).is_some_and(|l| l.compliance(&step) > 0.0) {
                let msg = format!(
                    "the law between materials `{}` and `{}` is compliant, which deformable bodies' contacts do not take (they are rigid: use `coulomb` or `frictionless` for this pair)",
                    w.materials[b.material as usize].name, other.name
                );
                return Err(entry_error(i, "material", msg));
            }
        }
    }
    Ok(())
}

/// Bytes a deformable body of `nodes` nodes holds while it is built and run (its
/// mesh, M, K, the factor of M̂ and Python's assembly arrays): measured with
/// `nscdd check` (peak memory of a rectangle of 100² and 300² cells, 2.6 kB per
/// degree of freedom; of a box of 20³ and 30³ cells, 18 and 17 kB per degree of
/// freedom, growing as the factor's fill-in), rounded up. An order of magnitude.
pub fn mesh_bytes(dim: usize, nodes: f64) -> f64 {
    bytes_per_dof(dim, nodes, (3000.0, 500.0))
}

/// Bytes of a body's M, K and factors of M̂ alone (what a rank drops when it does
/// not step the body, [`crate::stepped::RELEASE_MIN_BYTES`]): measured with peak
/// RSS on 16 blocks of 3 321 nodes (2D: 4.4 MB a body, 650 B per degree of
/// freedom) and 8 boxes of 4 851 nodes (3D: about 106 MB a body, 7.3 kB per degree
/// of freedom, growing as the factor's fill-in, d^⅓), rounded. An order of
/// magnitude.
pub fn matrices_bytes(dim: usize, nodes: f64) -> f64 {
    bytes_per_dof(dim, nodes, (650.0, 300.0))
}

/// `c2` bytes a degree of freedom d in 2D, `c3` d^⅓ in 3D (the factor's fill-in),
/// for a body of `nodes` nodes.
fn bytes_per_dof(dim: usize, nodes: f64, (c2, c3): (f64, f64)) -> f64 {
    let dofs = dim as f64 * nodes.max(0.0);
    if dim == 2 {
        c2 * dofs
    } else {
        c3 * dofs * dofs.cbrt()
    }
}

/// The number of nodes of a generated mesh (None: a file, counted once read).
fn mesh_nodes(m: &MeshSpec) -> Option<f64> {
    let c = |x: i64| x.max(0) as f64 + 1.0;
    match m {
        MeshSpec::Box { cells, .. } => Some(c(cells[0]) * c(cells[1]) * c(cells[2])),
        MeshSpec::Rectangle { cells, .. } => Some(c(cells[0]) * c(cells[1])),
        MeshSpec::Disk { refine, .. } => Some(2.0 * 4f64.powi((*refine).clamp(0, 64) as i32) + 5.0),
        MeshSpec::File(_) => None,
    }
}

/// Builds one deformable body of a spec; errors name the key. `memory(nodes)` is
/// asked before the mesh is made (a file: once read) whether a body of that many
/// nodes fits ([`mesh_bytes`]).
pub fn build(
    s: &DeformableSpec,
    materials: &[Material],
    dim: usize,
    dir: &Path,
    memory: &mut dyn FnMut(f64) -> Result<(), String>,
) -> Result<FeBody, (&'static str, String)> {
    build_with(s, materials, dim, dir, memory, Assembly::Now)
}

/// A cell-by-cell weight of M and K (None: 1 everywhere), from the mesh; an error
/// names its key.
pub type CellScale<'a> = &'a dyn Fn(&Mesh) -> Result<Option<Vec<f64>>, (&'static str, String)>;

/// How [`build_with`] makes a body's M and K.
pub enum Assembly<'a> {
    /// Now, unweighted.
    Now,
    /// Now, weighted cell by cell by the scale (a continuum region's share of its
    /// overlap band, [`crate::continuum`]).
    Scaled(CellScale<'a>),
    /// Not now: a body an MPI rank does not step yet ([`FeBody::light`];
    /// [`FeBody::ensure_matrices`] assembles them, unweighted, when it is stepped).
    Deferred,
}

/// [`build`] with M and K made as `assembly` says.
pub fn build_with(
    s: &DeformableSpec,
    materials: &[Material],
    dim: usize,
    dir: &Path,
    memory: &mut dyn FnMut(f64) -> Result<(), String>,
    assembly: Assembly<'_>,
) -> Result<FeBody, (&'static str, String)> {
    let mat = materials
        .iter()
        .position(|m| m.name == s.material)
        .ok_or(("material", format!("unknown material `{}`", s.material)))?;
    let density = materials[mat].density;
    if !(s.young > 0.0 && s.young.is_finite()) {
        return Err(("young", format!("must be > 0, got {}", s.young)));
    }
    if !(s.poisson >= 0.0 && s.poisson < 0.5) {
        return Err(("poisson", format!("must lie in [0, 0.5), got {}", s.poisson)));
    }
    if !s.rayleigh.iter().all(|x| *x >= 0.0 && x.is_finite()) {
        return Err(("rayleigh", "α and β must be ≥ 0".into()));
    }
    let plane_stress = match (dim, s.plane.as_deref()) {
        (2, None | Some("strain")) | (3, None) => false,
        (2, Some("stress")) => true,
        (2, Some(o)) => return Err(("plane", format!("`{o}`: `strain` or `stress`"))),
        _ => return Err(("plane", "`plane` (strain or stress) is for 2D scenes only".into())),
    };
    let raw = raw_mesh(&s.mesh, dim, dir, memory)?;
    let mesh = Mesh::new(raw).map_err(|e| ("mesh", e.0))?;
    if mesh_nodes(&s.mesh).is_none() {
        memory(mesh.n_nodes() as f64).map_err(|m| ("mesh", m))?;
    }
    let el = Elastic {
        young: s.young,
        poisson: s.poisson,
        density,
        plane_stress,
        rayleigh: s.rayleigh,
    };
    // (None: not now; Some(None): unweighted)
    let weights = match assembly {
        Assembly::Deferred => None,
        Assembly::Now => Some(None),
        Assembly::Scaled(scale) => Some(scale(&mesh)?),
    };
    let mut body = match weights {
        None => FeBody::light(s.name.clone(), mesh, el, mat as u16),
        Some(weights) => {
            let raw = crate::python::RawMesh {
                dim,
                points: mesh.x0.clone(),
                cells: mesh.cells.clone(),
            };
            let a = python::assemble_scaled(&raw, el.young, el.poisson, el.density, plane_stress, weights.as_deref())
                .map_err(|e| ("mesh", e.0))?;
            FeBody::new(s.name.clone(), mesh, el, mat as u16, &a.m, &a.k, a.skfem_version).map_err(|m| ("mesh", m))?
        }
    };
    let fix: Vec<u32> = fixed_nodes(&body.mesh, &s.fix).map_err(|m| ("fix", m))?;
    body.fix_nodes(&fix);
    match s.velocity.len() {
        0 => {}
        n if n == dim => {
            for (i, v) in body.v.iter_mut().enumerate() {
                if !body.fixed[i] {
                    *v = s.velocity[i % dim];
                }
            }
        }
        _ => return Err(("velocity", format!("{dim} numbers in {dim}D"))),
    }
    Ok(body)
}

/// A box `[lo, hi]` (z = 0 in 2D) holding every node of a spec's mesh, before
/// the mesh is made (a file's is read) and with a margin of 1e-9 of its size: what
/// the families give as [`nscdd::family::FamilyKind::load_boxes`]. Errors name
/// the key.
pub fn mesh_box(mesh: &MeshSpec, dim: usize, dir: &Path) -> Result<[[f64; 3]; 2], (&'static str, String)> {
    let (mut lo, mut hi) = ([0.0; 3], [0.0; 3]);
    match mesh {
        MeshSpec::Rectangle { origin, size, .. } if dim == 2 => {
            lo[..2].copy_from_slice(origin);
            (0..2).for_each(|k| hi[k] = origin[k] + size[k]);
        }
        MeshSpec::Box { origin, size, .. } if dim == 3 => {
            lo = *origin;
            (0..3).for_each(|k| hi[k] = origin[k] + size[k]);
        }
        MeshSpec::Disk { centre, radius, .. } if dim == 2 => {
            (0..2).for_each(|k| (lo[k], hi[k]) = (centre[k] - radius, centre[k] + radius));
        }
        _ => {
            let raw = raw_mesh(mesh, dim, dir, &mut |_| Ok(()))?;
            lo[..dim].fill(f64::INFINITY);
            hi[..dim].fill(f64::NEG_INFINITY);
            for p in raw.points.chunks_exact(dim) {
                for k in 0..dim {
                    (lo[k], hi[k]) = (lo[k].min(p[k]), hi[k].max(p[k]));
                }
            }
        }
    }
    let size = (0..dim).map(|k| lo[k].abs().max(hi[k].abs())).fold(0.0, f64::max);
    for k in 0..dim {
        (lo[k], hi[k]) = (lo[k] - 1e-9 * size, hi[k] + 1e-9 * size);
    }
    Ok([lo, hi])
}

/// The mesh of a spec, made by Python (checked against the memory limit first); a
/// file's, read.
fn raw_mesh(
    mesh: &MeshSpec,
    dim: usize,
    dir: &Path,
    memory: &mut dyn FnMut(f64) -> Result<(), String>,
) -> Result<crate::python::RawMesh, (&'static str, String)> {
    let mut fits = || mesh_nodes(mesh).map_or(Ok(()), |n| memory(n).map_err(|m| ("mesh", m)));
    match mesh {
        MeshSpec::Rectangle { .. } | MeshSpec::Disk { .. } if dim == 3 => {
            return Err(("mesh", "rectangles and disks are 2D meshes; in 3D use `box` or `file`".into()))
        }
        MeshSpec::Box { .. } if dim == 2 => return Err(("mesh", "a box is a 3D mesh; in 2D use `rectangle`, `disk` or `file`".into())),
        MeshSpec::Box { origin, size, cells } => {
            if !size.iter().chain(origin).all(|x| x.is_finite()) || !size.iter().all(|&x| x > 0.0) || cells.iter().any(|&c| c < 1) {
                return Err((
                    "mesh",
                    "a box needs a finite origin, a finite positive size and at least 1 cell per side".into(),
                ));
            }
            fits()?;
            python::cuboid(*origin, *size, [cells[0] as usize, cells[1] as usize, cells[2] as usize])
        }
        MeshSpec::Rectangle { origin, size, cells } => {
            if !size.iter().chain(origin).all(|x| x.is_finite()) || !(size[0] > 0.0 && size[1] > 0.0) || cells.iter().any(|&c| c < 1) {
                return Err((
                    "mesh",
                    "a rectangle needs a finite origin, a finite positive size and at least 1 cell per side".into(),
                ));
            }
            fits()?;
            python::rectangle(*origin, *size, [cells[0] as usize, cells[1] as usize])
        }
        MeshSpec::Disk { centre, radius, refine } => {
            if !(*radius > 0.0 && radius.is_finite() && centre.iter().all(|x| x.is_finite())) || !(0..=8).contains(refine) {
                return Err((
                    "mesh",
                    "a disk needs a finite centre, a finite radius > 0 and refine in 0..=8".into(),
                ));
            }
            fits()?;
            python::disk(*centre, *radius, *refine as usize)
        }
        MeshSpec::File(f) => {
            let p = dir.join(f);
            if !p.exists() {
                return Err(("mesh", format!("mesh file {} not found", p.display())));
            }
            python::read(&p, dim)
        }
    }
    .map_err(|e| ("mesh", e.0))
}

/// Nodes on the named sides of the mesh's box: `bottom`, `top` (the last axis:
/// y in 2D, z in 3D), `left`, `right` (x) and, in 3D, `front`, `back` (y).
pub fn fixed_nodes(m: &Mesh, sides: &[String]) -> Result<Vec<u32>, String> {
    let (n, dim) = (m.n_nodes(), m.dim);
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for k in 0..n {
        for d in 0..dim {
            lo[d] = lo[d].min(m.x0[dim * k + d]);
            hi[d] = hi[d].max(m.x0[dim * k + d]);
        }
    }
    let tol = 1e-9 * (0..dim).map(|d| hi[d] - lo[d]).fold(0.0, f64::max);
    let up = dim - 1;
    let mut out = vec![];
    for s in sides {
        let (d, v) = match s.as_str() {
            "bottom" => (up, lo[up]),
            "top" => (up, hi[up]),
            "left" => (0, lo[0]),
            "right" => (0, hi[0]),
            "front" if dim == 3 => (1, lo[1]),
            "back" if dim == 3 => (1, hi[1]),
            o if dim == 3 => return Err(format!("unknown side `{o}`: bottom, top, left, right, front or back")),
            o => return Err(format!("unknown side `{o}`: bottom, top, left or right")),
        };
        out.extend((0..n as u32).filter(|&k| (m.x0[dim * k as usize + d] - v).abs() <= tol));
    }
    out.sort_unstable();
    out.dedup();
    Ok(out)
}

/// One time step of the rigid bodies and the deformable bodies
/// ([`nscdd::family::step`]): contacts solved in one domain or, with a
/// decomposition, by NSCDD (its state made at the first step).
pub fn step_scene<D: Dim, S: SceneFamily<D>>(
    world: &mut World<D>,
    fe: &mut S,
    decomposition: Option<&DdConfig>,
    dd: &mut Option<NscddOf<Rigid<D>>>,
) -> Result<StepReport, Diverged> {
    if dd.is_none() {
        *dd = decomposition.map(|d| d.solver_of());
    }
    nscdd::family::step(world, &mut [fe as &mut dyn SceneFamily<D>], dd.as_mut()).map(|(r, _)| r)
}

impl<D: Dim, S: SceneFamily<D>> FeScene<D, S> {
    /// One time step ([`step_scene`]).
    pub fn step(&mut self) -> Result<StepReport, Diverged> {
        step_scene(&mut self.world, &mut self.fe, self.decomposition.as_ref(), &mut self.dd)
    }
}
