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
use nscdd::dd::{Attached, DdConfig, NscddOf, Rigid};
use nscdd::dim::{Dim, D2, D3};
use nscdd::engine::{ContactStage, Diverged, StepReport};
use nscdd::error::InputError;
use nscdd::registry::Registry;
use nscdd::scene::locate::{locate, path_string, Seg};
use nscdd::scene::{OutputSettings, Scene};
use nscdd::world::Material;
use nscdd::world::World;
use nscdd::world::World2;
use nscdd::world::World3;
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

/// A 2D scene with deformable bodies: the rigid world, the deformable stage and,
/// with a `[decomposition]`, the NSCDD stage that glues the subdomains (the
/// deformable bodies attached to it as a family, [`crate::family2`]).
pub struct FeScene2 {
    pub world: World2,
    pub fe: Deformables2,
    pub output: OutputSettings,
    /// The scene's `[decomposition]` (by model and/or by geometry).
    pub decomposition: Option<nscdd::dd::DdConfig>,
    /// The NSCDD state, made at the first step from `decomposition`.
    pub dd: Option<nscdd::dd::Nscdd>,
}

/// Loads a 2D scene file that may hold `[[deformable]]` entries.
pub fn load(path: &Path, registry: &Registry) -> Result<FeScene2, InputError> {
    let file = path.display().to_string();
    let text = std::fs::read_to_string(path).map_err(|e| InputError {
        file: file.clone(),
        line: None,
        key: String::new(),
        message: format!("cannot read the file: {e}"),
    })?;
    load_str(&text, &file, path.parent().unwrap_or(Path::new(".")), registry)
}

fn err(text: &str, file: &str, path: &[Seg], message: impl Into<String>) -> InputError {
    InputError {
        file: file.to_string(),
        line: locate(text, path).map(|o| nscdd::error::line_of(text, o)),
        key: path_string(path),
        message: message.into(),
    }
}

/// [`load`] from the text; mesh files are looked up relative to `dir`.
pub fn load_str(text: &str, file: &str, dir: &Path, registry: &Registry) -> Result<FeScene2, InputError> {
    let (scene, entries) = nscdd::scene::load_str_with(text, file, registry, true)?;
    let Scene {
        world,
        output,
        decomposition,
    } = scene;
    let bodies = bodies_from(
        entries,
        text,
        file,
        dir,
        &world.materials,
        2,
        &world.gravity,
        world.time.h,
        world.time.theta,
    )?;
    refuse_unsupported(text, file, &output)?;
    let fe = Deformables2::new(bodies, world.alert);
    Ok(FeScene2 {
        world,
        fe,
        output,
        decomposition,
        dd: None,
    })
}

/// The settings a scene with deformable bodies cannot use yet, refused (exit 2)
/// instead of being ignored: `checkpoint_every`.
fn refuse_unsupported(text: &str, file: &str, output: &OutputSettings) -> Result<(), InputError> {
    let at = |keys: &[&str], msg: &str| err(text, file, &keys.iter().map(|k| Seg::Key(k.to_string())).collect::<Vec<_>>(), msg);
    if output.checkpoint_every > 0 {
        return Err(at(
            &["output", "checkpoint_every"],
            "checkpoints of scenes with deformable bodies are not supported yet (their state is not saved); remove it",
        ));
    }
    Ok(())
}

/// Builds the deformable bodies of a scene's `[[deformable]]` entries, factored
/// for the scene's h and θ.
#[allow(clippy::too_many_arguments)]
fn bodies_from(
    entries: Vec<toml::Table>,
    text: &str,
    file: &str,
    dir: &Path,
    materials: &[Material],
    dim: usize,
    gravity: &[f64],
    h: f64,
    theta: f64,
) -> Result<Vec<FeBody>, InputError> {
    let mut bodies = Vec::new();
    for (i, e) in entries.into_iter().enumerate() {
        let base = vec![Seg::Key("deformable".into()), Seg::Index(i)];
        let at = |k: &str| {
            let mut p = base.clone();
            if !k.is_empty() {
                p.push(Seg::Key(k.into()));
            }
            p
        };
        let spec: DeformableSpec = DeformableSpec::deserialize(toml::Value::Table(e)).map_err(|x| {
            let msg = x.message().to_string();
            // name the key serde complained about when it says which
            let key = msg.split('`').nth(1).filter(|k| !k.contains(' ')).unwrap_or("");
            err(text, file, &at(key), msg.clone())
        })?;
        let mut b = build(&spec, materials, dim, dir).map_err(|(k, m)| err(text, file, &at(k), m))?;
        b.set_gravity(gravity);
        b.factorize(h, theta).map_err(|m| err(text, file, &at(""), m))?;
        bodies.push(b);
    }
    Ok(bodies)
}

/// A 3D scene with deformable bodies: the rigid world, the deformable stage and,
/// with a `[decomposition]`, the NSCDD stage ([`crate::family3`]).
pub struct FeScene3 {
    pub world: World3,
    pub fe: Deformables3,
    pub output: OutputSettings,
    /// The scene's `[decomposition]` (by model and/or by geometry).
    pub decomposition: Option<nscdd::dd::DdConfig>,
    /// The NSCDD state, made at the first step from `decomposition`.
    pub dd: Option<nscdd::dd::Nscdd3>,
}

/// Loads a 3D scene (`dimension = 3`) that may hold `[[deformable]]` entries.
pub fn load3_str(text: &str, file: &str, dir: &Path, registry: &Registry) -> Result<FeScene3, InputError> {
    let (scene, entries) = nscdd::scene::Scene3::load_str_with(text, file, registry, true)?;
    refuse_unsupported(text, file, &scene.output)?;
    let world = scene.world;
    let bodies = bodies_from(
        entries,
        text,
        file,
        dir,
        &world.materials,
        3,
        &world.gravity,
        world.time.h,
        world.time.theta,
    )?;
    let fe = Deformables3::new(bodies, world.alert);
    Ok(FeScene3 {
        world,
        fe,
        output: scene.output,
        decomposition: scene.decomposition,
        dd: None,
    })
}

/// A scene with deformable bodies of either dimension.
pub enum FeScene {
    D2(FeScene2),
    D3(FeScene3),
}

/// Loads a scene file with deformable bodies of either dimension (its
/// `dimension` key).
pub fn load_any(path: &Path, registry: &Registry) -> Result<FeScene, InputError> {
    let file = path.display().to_string();
    let text = std::fs::read_to_string(path).map_err(|e| InputError {
        file: file.clone(),
        line: None,
        key: String::new(),
        message: format!("cannot read the file: {e}"),
    })?;
    let dir = path.parent().unwrap_or(Path::new("."));
    let dim = toml::from_str::<toml::Table>(&text)
        .ok()
        .and_then(|t| t.get("dimension").and_then(|d| d.as_integer()));
    match dim {
        Some(3) => load3_str(&text, &file, dir, registry).map(FeScene::D3),
        _ => load_str(&text, &file, dir, registry).map(FeScene::D2),
    }
}

/// Builds one deformable body of a spec; errors name the key.
pub fn build(s: &DeformableSpec, materials: &[Material], dim: usize, dir: &Path) -> Result<FeBody, (&'static str, String)> {
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
    let raw = match &s.mesh {
        MeshSpec::Rectangle { .. } | MeshSpec::Disk { .. } if dim == 3 => {
            return Err(("mesh", "rectangles and disks are 2D meshes; in 3D use `box` or `file`".into()))
        }
        MeshSpec::Box { .. } if dim == 2 => return Err(("mesh", "a box is a 3D mesh; in 2D use `rectangle`, `disk` or `file`".into())),
        MeshSpec::Box { origin, size, cells } => {
            if !size.iter().all(|&x| x > 0.0) || cells.iter().any(|&c| c < 1) {
                return Err(("mesh", "a box needs a positive size and at least 1 cell per side".into()));
            }
            python::cuboid(*origin, *size, [cells[0] as usize, cells[1] as usize, cells[2] as usize])
        }
        MeshSpec::Rectangle { origin, size, cells } => {
            if !(size[0] > 0.0 && size[1] > 0.0) || cells.iter().any(|&c| c < 1) {
                return Err(("mesh", "a rectangle needs a positive size and at least 1 cell per side".into()));
            }
            python::rectangle(*origin, *size, [cells[0] as usize, cells[1] as usize])
        }
        MeshSpec::Disk { centre, radius, refine } => {
            if !(*radius > 0.0) || !(0..=8).contains(refine) {
                return Err(("mesh", "a disk needs radius > 0 and refine in 0..=8".into()));
            }
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
    .map_err(|e| ("mesh", e.0))?;
    let mesh = Mesh::new(raw).map_err(|e| ("mesh", e.0))?;
    let el = Elastic {
        young: s.young,
        poisson: s.poisson,
        density,
        plane_stress,
        rayleigh: s.rayleigh,
    };
    let a = python::assemble(
        &crate::python::RawMesh {
            dim,
            points: mesh.x0.clone(),
            cells: mesh.cells.clone(),
        },
        el.young,
        el.poisson,
        el.density,
        plane_stress,
    )
    .map_err(|e| ("mesh", e.0))?;
    let mut body = FeBody::new(s.name.clone(), mesh, el, mat as u16, &a.m, &a.k, a.skfem_version).map_err(|m| ("mesh", m))?;
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

/// What a time step needs of the deformable stage of either dimension
/// ([`Deformables2`], [`Deformables3`]).
pub trait FeStage<D: Dim>: ContactStage<World<D>> + Attached<Rigid<D>> + Sized {
    /// A failure inside the step (a refactorization).
    fn take_error(&mut self) -> Option<String>;
    /// u⁺ = u⁻ + h((1 − θ)V⁻ + θV⁺).
    fn update(&mut self, h: f64, theta: f64, step: u64) -> Result<(), Diverged>;
}

impl FeStage<D2> for Deformables2 {
    fn take_error(&mut self) -> Option<String> {
        self.error.take()
    }
    fn update(&mut self, h: f64, theta: f64, step: u64) -> Result<(), Diverged> {
        Deformables2::update(self, h, theta, step)
    }
}

impl FeStage<D3> for Deformables3 {
    fn take_error(&mut self) -> Option<String> {
        self.error.take()
    }
    fn update(&mut self, h: f64, theta: f64, step: u64) -> Result<(), Diverged> {
        Deformables3::update(self, h, theta, step)
    }
}

/// One time step of the rigid bodies and the deformable bodies, contacts solved in
/// one domain or, with a decomposition, by NSCDD (its state made at the first step).
pub fn step_scene<D: Dim, S: FeStage<D>>(
    world: &mut World<D>,
    fe: &mut S,
    decomposition: Option<&DdConfig>,
    dd: &mut Option<NscddOf<Rigid<D>>>,
) -> Result<StepReport, Diverged> {
    if dd.is_none() {
        *dd = decomposition.map(|d| d.solver_of());
    }
    let rep = match dd.as_mut() {
        None => world.step_with(fe)?,
        Some(dd) => {
            let r = dd.step_families(world, &mut [fe as &mut dyn Attached<Rigid<D>>])?;
            StepReport {
                solve: r.solve,
                contacts: r.contacts,
                times: r.times,
            }
        }
    };
    if let Some(e) = fe.take_error() {
        return Err(Diverged {
            step: world.step,
            body: 0,
            message: e,
        });
    }
    fe.update(world.time.h, world.time.theta, world.step)?;
    Ok(rep)
}

impl FeScene2 {
    /// One time step ([`step_scene`]).
    pub fn step(&mut self) -> Result<StepReport, Diverged> {
        step_scene(&mut self.world, &mut self.fe, self.decomposition.as_ref(), &mut self.dd)
    }
}

impl FeScene3 {
    /// One time step ([`step_scene`]).
    pub fn step(&mut self) -> Result<StepReport, Diverged> {
        step_scene(&mut self.world, &mut self.fe, self.decomposition.as_ref(), &mut self.dd)
    }
}
