//! Loading a scene file into a [`World2`]: parse, validate, build.
//!
//! Every problem is reported as one [`InputError`] naming the file, the line and the
//! key, before anything runs: syntax errors, unknown keys, non-physical values
//! (negative radius, density, step, μ), unknown materials, shapes, laws or
//! generators, a pair of materials that can touch without a law, a pair of shape
//! kinds without a detector, bodies overlapping beyond the tolerance, and drives of
//! degrees of freedom that do not exist.

pub mod builder;
mod checks;
pub mod load3;
pub mod locate;
pub mod restart;
pub mod schema;

use crate::detect::{Detector, DetectorTable};
use crate::dim::{Dim, D2};
use crate::drive::BodyDrive;
use crate::error::{line_of, InputError};
use crate::registry::{ParamError, Registry};
use crate::world::{BoxWalls, Material, TimeSettings, World, World2};
use builder::{Origin, SceneBuilder2};
pub use checks::parse_scheme;
pub(crate) use checks::*;
use locate::{locate, path_string, Seg};
pub use restart::restart;
use schema::SceneFile;

/// Output settings of a scene.
#[derive(Clone, Debug, PartialEq)]
pub struct OutputSettings {
    pub every: u64,
    pub vtk: bool,
    pub writers: Vec<String>,
    /// Steps between saved states (`checkpoint.json`); 0: none.
    pub checkpoint_every: u64,
}

/// A loaded scene: the world and how to write it.
pub struct Scene<D: Dim = D2> {
    pub world: World<D>,
    pub output: OutputSettings,
    /// NSCDD settings (`[decomposition]`); `None`: the one-domain engine.
    /// [`crate::run::run`] steps with [`crate::dd::Nscdd`] when set.
    pub decomposition: Option<crate::dd::DdConfig>,
}

/// Reads and loads a scene file.
pub fn load(path: &std::path::Path, registry: &Registry) -> Result<Scene, InputError> {
    let file = path.display().to_string();
    let text = std::fs::read_to_string(path).map_err(|e| InputError {
        file: file.clone(),
        line: None,
        key: String::new(),
        message: format!("cannot read the file: {e}"),
    })?;
    load_str(&text, &file, registry)
}

#[derive(Clone, Copy)]
pub(crate) struct Ctx<'a> {
    text: &'a str,
    file: &'a str,
    /// The scene holds deformable bodies (loaded by a plugin).
    deformable: bool,
}

impl Ctx<'_> {
    pub(crate) fn err(&self, path: &[Seg], message: impl Into<String>) -> InputError {
        InputError {
            file: self.file.to_string(),
            line: locate(self.text, path).map(|o| line_of(self.text, o)),
            key: path_string(path),
            message: message.into(),
        }
    }
}

pub(crate) fn k(s: &str) -> Seg {
    Seg::Key(s.to_string())
}
pub(crate) fn at(base: &[Seg], more: &[Seg]) -> Vec<Seg> {
    base.iter().chain(more).cloned().collect()
}

/// Parses a scene file's TOML into its schema; errors name the line and the full
/// key path.
pub(crate) fn parse<T: serde::de::DeserializeOwned>(text: &str, file: &str) -> Result<T, InputError> {
    toml::from_str(text).map_err(|e| {
        let span = e.span();
        let line = span.as_ref().map(|s| line_of(text, s.start));
        // the full key path: from the parsed document (unknown keys, wrong types), or
        // from the line's header and key (syntax errors)
        let key = span
            .as_ref()
            .and_then(|s| locate::path_at(text, s.start))
            .or_else(|| line.and_then(|l| locate::path_on_line(text, l)))
            .or_else(|| {
                span.clone()
                    .map(|s| text[s].trim().trim_matches('"').to_string())
                    .filter(|s| s.len() < 40 && !s.contains('\n'))
            })
            .unwrap_or_default();
        InputError {
            file: file.to_string(),
            line,
            key,
            message: e.message().trim().to_string(),
        }
    })
}

/// What the law and detector checks need of a body.
pub(crate) struct BodyInfo {
    pub material: usize,
    pub kind: usize,
    /// Movable or driven.
    pub movable: bool,
    pub origin: Origin,
}

pub(crate) fn origin_path(o: Origin, key: &str) -> Vec<Seg> {
    match o {
        Origin::Body(i) => vec![k("bodies"), Seg::Index(i), k(key)],
        Origin::Generated(i) => vec![k("generate"), Seg::Index(i)],
    }
}

/// A loaded scene of either dimension.
pub enum AnyScene {
    D2(Scene),
    D3(load3::Scene3),
}

/// Reads and loads a scene file of either dimension (its `dimension` key).
pub fn load_any(path: &std::path::Path, registry: &Registry) -> Result<AnyScene, InputError> {
    let file = path.display().to_string();
    let text = std::fs::read_to_string(path).map_err(|e| InputError {
        file: file.clone(),
        line: None,
        key: String::new(),
        message: format!("cannot read the file: {e}"),
    })?;
    load_any_str(&text, &file, registry)
}

/// [`load_any`] from the text of a scene.
pub fn load_any_str(text: &str, file: &str, registry: &Registry) -> Result<AnyScene, InputError> {
    let dim = toml::from_str::<toml::Table>(text)
        .ok()
        .and_then(|t| t.get("dimension").and_then(|d| d.as_integer()));
    match dim {
        Some(3) => load3::load_str(text, file, registry).map(AnyScene::D3),
        _ => load_str(text, file, registry).map(AnyScene::D2),
    }
}

/// Loads a scene from its text; `file` names it in messages.
pub fn load_str(text: &str, file: &str, registry: &Registry) -> Result<Scene, InputError> {
    load_str_with(text, file, registry, false).map(|(s, _)| s)
}

/// The message for a scene with deformable bodies given to a program without them.
pub const NO_DEFORMABLE: &str =
    "deformable bodies need the fem_deformable plugin: build nscdd with `cargo build --release --features nscdd-cli/fem` (and Python's scikit-fem, see the README)";

/// [`load_str`] that also returns the scene's `[[deformable]]` entries, for a
/// deformable-body plugin to build; with `deformable = false` a scene holding any is
/// refused ([`NO_DEFORMABLE`]).
pub fn load_str_with(text: &str, file: &str, registry: &Registry, deformable: bool) -> Result<(Scene, Vec<toml::Table>), InputError> {
    let mut sf: SceneFile = parse(text, file)?;
    let cx = Ctx {
        text,
        file,
        deformable: !sf.deformable.is_empty(),
    };
    if !deformable && cx.deformable {
        return Err(cx.err(&[k("deformable")], NO_DEFORMABLE));
    }
    let entries = std::mem::take(&mut sf.deformable);
    let scene = load_parsed(&cx, sf, registry)?;
    Ok((scene, entries))
}

fn load_parsed(cx: &Ctx, sf: SceneFile, registry: &Registry) -> Result<Scene, InputError> {
    let cx = *cx;
    if sf.dimension != 2 {
        return Err(cx.err(&[k("dimension")], format!("dimension {} is not supported: 2 or 3", sf.dimension)));
    }
    let gravity = match sf.gravity.as_deref() {
        None => [0.0, -9.81],
        Some(&[x, y]) if x.is_finite() && y.is_finite() => [x, y],
        Some(_) => return Err(cx.err(&[k("gravity")], "gravity must be 2 finite numbers in 2D")),
    };
    if sf.output.box3.is_some() {
        return Err(cx.err(
            &[k("output"), k("box3")],
            "`box3` names the 6 walls of a 3D sample; in 2D use `box`",
        ));
    }
    if sf.decomposition.as_ref().is_some_and(|d| d.nz.is_some()) {
        return Err(cx.err(&[k("decomposition"), k("nz")], "`nz` splits along z: 3D scenes only"));
    }
    let time = time_settings(&cx, &sf)?;
    validate_solver(&cx, &sf.solver)?;
    let materials = materials(&cx, &sf)?;
    let mut b = SceneBuilder2::new(registry, materials);
    let mut drives = vec![];
    add_bodies(&cx, &sf, &mut b, &mut drives)?;
    for (g, spec) in sf.generate.iter().enumerate() {
        let base = [k("generate"), Seg::Index(g)];
        let gen = registry.tables::<D2>().generators.get(spec.kind.as_str()).ok_or_else(|| {
            cx.err(
                &at(&base, &[k("kind")]),
                format!(
                    "unknown generator `{}`; installed: {}",
                    spec.kind,
                    registry.generator_names::<D2>().join(", ")
                ),
            )
        })?;
        b.origin = Origin::Generated(g);
        gen.generate(&spec.params, &mut b)
            .map_err(|e: ParamError| cx.err(&at(&base, &[k(&e.key)]), e.msg))?;
    }
    if b.bodies.is_empty() {
        return Err(cx.err(&[], "the scene has no bodies"));
    }
    let nm = b.materials.len();
    let (laws, declared) = laws(&cx, &sf, registry, nm, &b.materials, 2)?;
    // every pair of materials that can touch needs a law; every pair of kinds a detector
    let info: Vec<BodyInfo> = (0..b.bodies.len())
        .map(|i| BodyInfo {
            material: b.bodies.material[i] as usize,
            kind: b.bodies.shape[i].kind as usize,
            movable: b.bodies.movable(i) || drives.iter().any(|d: &BodyDrive| d.body as usize == i),
            origin: b.origins[i],
        })
        .collect();
    let kinds: Vec<&'static str> = b.shapes.iter().map(|x| x.kind()).collect();
    let table = DetectorTable {
        nk: kinds.len(),
        table: laws_and_detectors(&cx, &info, &b.materials, &kinds, &laws, &declared, |x, y| {
            registry.detector::<D2>(x, y)
        })?,
    };
    let sizes: Vec<f64> = (0..b.bodies.len())
        .map(|i| b.shapes[b.bodies.shape[i].kind as usize].size(b.bodies.shape[i].index))
        .collect();
    let alert = alert_distance(&cx, &sf.detection, &sizes)?;
    // initial interpenetrations beyond the tolerance
    let mut raw = vec![];
    Detector::default().detect(&b.bodies, &b.shapes, &table, 0.0, &mut raw);
    let contacts = raw.iter().map(|rc| (rc.i as usize, rc.j as usize, rc.gap));
    let material = |x: usize| b.bodies.material[x] as usize;
    check_overlaps(&cx, &sf.detection, contacts, &sizes, &laws, nm, material, &b.names, &b.origins)?;
    let box_walls = match &sf.output.box_walls {
        None => None,
        Some(bs) => {
            let find = |key: &str, name: &str| {
                b.names
                    .iter()
                    .position(|n| n.as_deref() == Some(name))
                    .map(|p| p as u32)
                    .ok_or_else(|| cx.err(&[k("output"), k("box"), k(key)], format!("no body is named `{name}`")))
            };
            let (l, r) = (find("left", &bs.left)?, find("right", &bs.right)?);
            Some(BoxWalls {
                walls: [l, r, find("bottom", &bs.bottom)?, find("top", &bs.top)?, u32::MAX, u32::MAX],
                strain_from: bs.strain_from,
            })
        }
    };
    check_pressure_drives(&cx, &drives, box_walls.as_ref(), &b.origins, &["x", "y", "rot"], "box")?;
    for (i, w) in sf.output.writers.iter().enumerate() {
        if registry.writer::<D2>(w).is_none() {
            return Err(cx.err(&[k("output"), k("writers"), Seg::Index(i)], format!("unknown writer `{w}`")));
        }
    }
    let nb = b.bodies.len();
    let movable = (0..nb).filter(|&i| b.bodies.movable(i)).count();
    let decomposition = match &sf.decomposition {
        None => None,
        Some(d) => Some(decomposition(&cx, d, movable)?),
    };
    let world = World2 {
        bodies: b.bodies,
        names: b.names,
        shapes: b.shapes,
        materials: b.materials,
        laws,
        drives,
        fixed: b.fixed,
        gravity,
        time,
        solver: sf.solver,
        alert,
        box_walls,
        box_h0: None,
        detectors: table,
        t: 0.0,
        step: 0,
        contacts: Default::default(),
        reaction: vec![[0.0; 3]; nb],
        scratch: Default::default(),
    };
    Ok(Scene {
        world,
        output: OutputSettings {
            every: sf.output.every,
            vtk: sf.output.vtk,
            writers: sf.output.writers,
            checkpoint_every: sf.output.checkpoint_every,
        },
        decomposition,
    })
}

fn add_bodies(cx: &Ctx, sf: &SceneFile, b: &mut SceneBuilder2, drives: &mut Vec<BodyDrive>) -> Result<(), InputError> {
    for (i, spec) in sf.bodies.iter().enumerate() {
        let base = [k("bodies"), Seg::Index(i)];
        let p = |key: &str| at(&base, &[k(key)]);
        b.origin = Origin::Body(i);
        let kind = b.kind(&spec.shape).ok_or_else(|| {
            cx.err(
                &p("shape"),
                format!(
                    "unknown shape `{}`; installed: {}",
                    spec.shape,
                    b.registry.shape_kinds::<D2>().join(", ")
                ),
            )
        })?;
        let material = b.material(&spec.material).ok_or_else(|| {
            cx.err(
                &p("material"),
                format!("unknown material `{}`; declare it in [[materials]]", spec.material),
            )
        })?;
        let index = b.shapes[kind as usize]
            .push_params(&spec.params)
            .map_err(|e| cx.err(&p(&e.key), e.msg))?;
        if spec
            .position
            .iter()
            .chain(&spec.velocity)
            .chain([&spec.rotation])
            .any(|x| !x.is_finite())
        {
            return Err(cx.err(&p("position"), "position, rotation and velocity must be finite"));
        }
        let id = b.add_body(
            crate::rigid2d::bodies::ShapeRef { kind, index },
            material,
            spec.position,
            spec.rotation,
            spec.velocity,
        );
        let (m, i) = (b.bodies.mass[id as usize], b.bodies.inertia[id as usize]);
        if !(m > 0.0 && m.is_finite() && i > 0.0 && i.is_finite()) {
            return Err(cx.err(
                &p("shape"),
                format!("the body's mass ({m}) and inertia ({i}) must be positive and finite"),
            ));
        }
        if let Some(name) = &spec.name {
            if b.names.iter().any(|n| n.as_deref() == Some(name.as_str())) {
                return Err(cx.err(&p("name"), format!("two bodies are named `{name}`")));
            }
            b.names[id as usize] = Some(name.clone());
        }
        if spec.fixed {
            if spec.drive.is_some() {
                return Err(cx.err(&p("drive"), "a fixed body cannot also be driven"));
            }
            b.set_fixed(id);
        }
        if let Some(d) = &spec.drive {
            let mut dof: [Option<crate::drive::DofDrive>; 6] = Default::default();
            for (slot, (name, dd)) in [("x", &d.x), ("y", &d.y), ("rot", &d.rot)].into_iter().enumerate() {
                if let Some(dd) = dd {
                    dd.validate().map_err(|m| cx.err(&at(&base, &[k("drive"), k(name)]), m))?;
                    dof[slot] = Some(dd.clone());
                }
            }
            drives.push(BodyDrive { body: id, dof });
        }
    }
    Ok(())
}
