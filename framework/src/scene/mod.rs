//! Loading a scene file into a [`World2`]: parse, validate, build.
//!
//! Every problem is reported as one [`InputError`] naming the file, the line and the
//! key, before anything runs: syntax errors, unknown keys, non-physical values
//! (negative radius, density, step, μ), unknown materials, shapes, laws or
//! generators, a pair of materials that can touch without a law, a pair of shape
//! kinds without a detector, bodies overlapping beyond the tolerance, and drives of
//! degrees of freedom that do not exist.

pub mod builder;
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

/// Checks that every pair of materials that can touch (two bodies, one of them
/// movable) has a law, and makes the detector table of the kinds (`kinds[id]`: the
/// kind names) with `lookup` (the registry's 2D or 3D detectors). A pair of kinds
/// needs a detector when a law acts between their materials and one of them moves.
pub(crate) fn laws_and_detectors<T>(
    cx: &Ctx,
    bodies: &[BodyInfo],
    materials: &[Material],
    kinds: &[&'static str],
    laws: &[Option<crate::law::ContactLaw>],
    declared: &[bool],
    lookup: impl Fn(&str, &str) -> Option<T>,
) -> Result<Vec<Option<T>>, InputError> {
    let (nm, nk) = (materials.len(), kinds.len());
    let mut first_mat = vec![None; nm];
    let mut mat_count = vec![0usize; nm];
    let mut mat_movable = vec![false; nm];
    let mut first_kind = vec![None; nk];
    let mut kind_movable = vec![false; nk];
    let mut kind_mats = vec![false; nk * nm];
    for bi in bodies {
        let (m, kd) = (bi.material, bi.kind);
        first_mat[m].get_or_insert(bi.origin);
        mat_count[m] += 1;
        first_kind[kd].get_or_insert(bi.origin);
        kind_mats[kd * nm + m] = true;
        mat_movable[m] |= bi.movable;
        kind_movable[kd] |= bi.movable;
    }
    for ma in 0..nm {
        for mb in ma..nm {
            if let (Some(oa), Some(_)) = (first_mat[ma], first_mat[mb]) {
                // a material touches itself only if two bodies are made of it
                let can_touch = ma != mb || mat_count[ma] >= 2;
                if can_touch && (mat_movable[ma] || mat_movable[mb]) && !declared[ma * nm + mb] {
                    let (x, y) = (&materials[ma].name, &materials[mb].name);
                    return Err(cx.err(
                        &origin_path(oa, "material"),
                        format!("no law for the material pair (`{x}`, `{y}`): add a [[laws]] entry with materials = [\"{x}\", \"{y}\"]"),
                    ));
                }
            }
        }
    }
    let mut table: Vec<Option<T>> = (0..nk * nk).map(|_| None).collect();
    for ka in 0..nk {
        for kb in 0..nk {
            let (na, nb) = (kinds[ka], kinds[kb]);
            let interact =
                (0..nm).any(|ma| (0..nm).any(|mb| kind_mats[ka * nm + ma] && kind_mats[kb * nm + mb] && laws[ma * nm + mb].is_some()));
            match lookup(na, nb) {
                Some(d) => table[ka * nk + kb] = Some(d),
                None if interact && (kind_movable[ka] || kind_movable[kb]) => {
                    let o = first_kind[ka].or(first_kind[kb]).unwrap_or(Origin::Body(0));
                    return Err(cx.err(
                        &origin_path(o, "shape"),
                        format!("no contact detector for the shape pair (`{na}`, `{nb}`) among the installed plugins"),
                    ));
                }
                None => {}
            }
        }
    }
    Ok(table)
}

/// The alert distance: `detection.alert`, or 0.1 × the median shape size.
pub(crate) fn alert_distance(cx: &Ctx, d: &schema::DetectionSpec, sizes: &[f64]) -> Result<f64, InputError> {
    match d.alert {
        Some(a) if !(a >= 0.0 && a.is_finite()) => Err(cx.err(&[k("detection"), k("alert")], format!("must be ≥ 0, got {a}"))),
        Some(a) => Ok(a),
        None => {
            let mut s: Vec<f64> = sizes.iter().copied().filter(|x| x.is_finite() && *x > 0.0).collect();
            s.sort_by(|a, c| a.total_cmp(c));
            Ok(0.1 * s.get(s.len() / 2).copied().unwrap_or(1.0))
        }
    }
}

/// Initial interpenetrations beyond `detection.overlap_tolerance` × the smaller
/// shape size, among the detected `(i, j, gap)` of materials that interact.
#[allow(clippy::too_many_arguments)]
pub(crate) fn check_overlaps(
    cx: &Ctx,
    d: &schema::DetectionSpec,
    contacts: impl Iterator<Item = (usize, usize, f64)>,
    sizes: &[f64],
    laws: &[Option<crate::law::ContactLaw>],
    nm: usize,
    material: impl Fn(usize) -> usize,
    names: &[Option<String>],
    origins: &[Origin],
) -> Result<(), InputError> {
    let tol = d.overlap_tolerance;
    if !(tol >= 0.0) {
        return Err(cx.err(&[k("detection"), k("overlap_tolerance")], "must be ≥ 0"));
    }
    for (i, j, gap) in contacts {
        if laws[material(i) * nm + material(j)].is_none() {
            continue; // materials declared never to interact
        }
        let lim = tol * sizes[i].min(sizes[j]);
        if gap < -lim {
            let label = |x: usize| match &names[x] {
                Some(n) => format!("{x} (`{n}`)"),
                None => format!("{x}"),
            };
            return Err(cx.err(
                &origin_path(origins[i], "position"),
                format!(
                    "bodies {} and {} overlap by {:.3e} m, more than the tolerance {:.3e} m (detection.overlap_tolerance × the smaller size)",
                    label(i),
                    label(j),
                    -gap,
                    lim
                ),
            ));
        }
    }
    Ok(())
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

/// A scheme name (`decentralized` or `centralized`).
pub fn parse_scheme(name: &str) -> Result<crate::dd::Scheme, String> {
    match name {
        "decentralized" => Ok(crate::dd::Scheme::Decentralized),
        "centralized" => Ok(crate::dd::Scheme::Centralized),
        other => Err(format!("unknown scheme `{other}`; expected `decentralized` or `centralized`")),
    }
}

pub(crate) fn decomposition(cx: &Ctx, d: &schema::DecompositionSpec, movable: usize) -> Result<crate::dd::DdConfig, InputError> {
    if d.by_model == Some(true) && !cx.deformable {
        return Err(cx.err(
            &[k("decomposition"), k("by_model")],
            "subdomains by model need deformable bodies in the scene",
        ));
    }
    let p = |key: &str| vec![k("decomposition"), k(key)];
    let int = |key: &str, v: Option<i64>, min: i64, def: i64| -> Result<i64, InputError> {
        let v = v.unwrap_or(def);
        if v < min || v > u32::MAX as i64 {
            return Err(cx.err(&p(key), format!("must be an integer ≥ {min}, got {v}")));
        }
        Ok(v)
    };
    let def = crate::dd::DdSettings::default();
    let mut c = crate::dd::DdConfig::default();
    c.by_model = d.by_model == Some(true);
    c.dd.nx = int("nx", d.nx, 1, def.nx as i64)? as u32;
    c.dd.ny = int("ny", d.ny, 1, def.ny as i64)? as u32;
    c.dd.nz = int("nz", d.nz, 1, 1)? as u32;
    c.dd.sweeps_per_gluing = int("sweeps_per_gluing", d.sweeps_per_gluing, 1, 1)? as u32;
    c.dd.threads = int("threads", d.threads, 1, 1)? as usize;
    c.repartition_every = int("repartition_every", d.repartition_every, 1, 1)? as u32;
    if let Some(s) = &d.scheme {
        c.dd.scheme = parse_scheme(s).map_err(|m| cx.err(&p("scheme"), m))?;
    }
    c.check_capacity(movable).map_err(|(key, m)| {
        // name a key the section has
        let key = match (d.nx.is_some(), d.ny.is_some(), d.nz.is_some()) {
            (true, _, _) | (false, false, false) => key,
            (false, true, _) => "ny",
            (false, false, true) => "nz",
        };
        cx.err(&p(key), m)
    })?;
    Ok(c)
}

pub(crate) fn time_settings<B>(cx: &Ctx, sf: &SceneFile<B>) -> Result<TimeSettings, InputError> {
    let t = &sf.time;
    if !(t.step > 0.0 && t.step.is_finite()) {
        return Err(cx.err(
            &[k("time"), k("step")],
            format!("the step must be a positive number of seconds, got {}", t.step),
        ));
    }
    if !(0.5..=1.0).contains(&t.theta) {
        return Err(cx.err(&[k("time"), k("theta")], format!("θ must lie in [0.5, 1], got {}", t.theta)));
    }
    let steps = match (t.steps, t.duration) {
        (Some(n), None) => n,
        (None, Some(d)) if d >= 0.0 && d.is_finite() => (d / t.step).round() as u64,
        (None, Some(d)) => return Err(cx.err(&[k("time"), k("duration")], format!("must be ≥ 0, got {d}"))),
        _ => return Err(cx.err(&[k("time")], "give exactly one of `steps` or `duration`")),
    };
    Ok(TimeSettings {
        h: t.step,
        theta: t.theta,
        steps,
    })
}

pub(crate) fn validate_solver(cx: &Ctx, s: &crate::solver::SolverSettings) -> Result<(), InputError> {
    let p = |key: &str| vec![k("solver"), k(key)];
    if !(s.tolerance > 0.0 && s.tolerance.is_finite()) {
        return Err(cx.err(&p("tolerance"), format!("must be > 0, got {}", s.tolerance)));
    }
    if s.max_sweeps == 0 {
        return Err(cx.err(&p("max_sweeps"), "must be ≥ 1"));
    }
    if s.check_every == 0 {
        return Err(cx.err(&p("check_every"), "must be ≥ 1"));
    }
    if !(s.relaxation > 0.0 && s.relaxation <= 1.0) {
        return Err(cx.err(&p("relaxation"), format!("ω must lie in (0, 1], got {}", s.relaxation)));
    }
    Ok(())
}

pub(crate) fn materials<B>(cx: &Ctx, sf: &SceneFile<B>) -> Result<Vec<Material>, InputError> {
    let mut out: Vec<Material> = vec![];
    for (i, m) in sf.materials.iter().enumerate() {
        if !(m.density > 0.0 && m.density.is_finite()) {
            return Err(cx.err(
                &[k("materials"), Seg::Index(i), k("density")],
                format!("density must be > 0, got {}", m.density),
            ));
        }
        if out.iter().any(|o| o.name == m.name) {
            return Err(cx.err(
                &[k("materials"), Seg::Index(i), k("name")],
                format!("material `{}` is declared twice", m.name),
            ));
        }
        out.push(Material {
            name: m.name.clone(),
            density: m.density,
        });
    }
    Ok(out)
}

/// The law table and, beside it, the pairs declared `law = "none"` (never interact).
pub(crate) fn laws<B>(
    cx: &Ctx,
    sf: &SceneFile<B>,
    registry: &Registry,
    nm: usize,
    materials: &[Material],
    dimension: u8,
) -> Result<(Vec<Option<crate::law::ContactLaw>>, Vec<bool>), InputError> {
    let mut table = vec![None; nm * nm];
    let mut declared = vec![false; nm * nm];
    for (i, l) in sf.laws.iter().enumerate() {
        let base = [k("laws"), Seg::Index(i)];
        let def = if l.law == "none" {
            None
        } else {
            Some(registry.laws.get(l.law.as_str()).ok_or_else(|| {
                cx.err(
                    &at(&base, &[k("law")]),
                    format!("unknown law `{}`; installed: none, {}", l.law, registry.law_names().join(", ")),
                )
            })?)
        };
        let mut ids = [0u16; 2];
        for (s, name) in l.materials.iter().enumerate() {
            ids[s] = builder::material_id(materials, name)
                .ok_or_else(|| cx.err(&at(&base, &[k("materials"), Seg::Index(s)]), format!("unknown material `{name}`")))?;
        }
        let law = match def {
            Some(def) => Some((def.parse)(&l.params).map_err(|e| cx.err(&at(&base, &[k(&e.key)]), e.msg))?),
            None => {
                crate::params::only_keys(&l.params, &[]).map_err(|e| cx.err(&at(&base, &[k(&e.key)]), e.msg))?;
                None
            }
        };
        if dimension == 2 && law.is_some_and(|x| x.is_cohesive()) {
            return Err(cx.err(
                &at(&base, &[k("law")]),
                format!("`{}` bonds 3D rigid bodies (joints of faces); a 2D scene cannot use it", l.law),
            ));
        }
        let (a, c) = (ids[0] as usize, ids[1] as usize);
        if declared[a * nm + c] {
            return Err(cx.err(&at(&base, &[k("materials")]), "a law for this pair of materials is already given"));
        }
        for (x, y) in [(a, c), (c, a)] {
            table[x * nm + y] = law;
            declared[x * nm + y] = true;
        }
    }
    Ok((table, declared))
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

/// A pressure (or servo) drive pushes a wall of the box sample along the wall's
/// own axis (x for the walls normal to x, …); anything else is refused, naming the
/// drive. `dofs`: the names of the drive's degrees of freedom; `section`: the
/// `[output]` key naming the box's walls.
pub(crate) fn check_pressure_drives(
    cx: &Ctx,
    drives: &[BodyDrive],
    box_walls: Option<&BoxWalls>,
    origins: &[Origin],
    dofs: &[&str],
    section: &str,
) -> Result<(), InputError> {
    let n = (dofs.len() + 1) / 2;
    for d in drives {
        for (dof, drv) in d.dof.iter().enumerate().take(dofs.len()) {
            if !drv.as_ref().is_some_and(|x| x.has_pressure()) {
                continue;
            }
            let wall = box_walls.and_then(|bw| bw.wall_of(d.body as usize, n));
            if wall.is_none_or(|wl| wl / 2 != dof) {
                let base = origin_path(origins[d.body as usize], "drive");
                return Err(cx.err(
                    &at(&base, &[k(dofs[dof])]),
                    format!("a pressure drive needs the body to be a wall of `[output] {section}`, driven along its own axis (x for the walls normal to x, ...)"),
                ));
            }
        }
    }
    Ok(())
}
