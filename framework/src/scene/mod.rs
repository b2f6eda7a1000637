//! Loading a scene file into a [`Scene<D>`] (2D or 3D): parse, validate, build.
//!
//! Every problem is reported as one [`InputError`] naming the file, the line and the
//! key, before anything runs: syntax errors, unknown keys, non-physical values
//! (negative radius, density, step, μ), unknown materials, shapes, laws or
//! generators, a pair of materials that can touch without a law, a pair of shape
//! kinds without a detector, bodies overlapping beyond the tolerance, and drives of
//! degrees of freedom that do not exist.

pub use crate::registry::builder;
mod checks;
mod load;
pub mod locate;
pub mod part;
pub mod restart;
mod restart_scan;
mod restart_stream;
pub mod schema;

use crate::dim::{Dim, D2, D3};
use crate::error::{line_of, InputError};
use crate::registry::Registry;
use crate::world::{Material, TimeSettings, World};
use builder::Origin;
pub use checks::parse_scheme;
pub(crate) use checks::*;
use locate::{locate, path_string, Seg};
pub use restart::{restart, restart_scene, restart_scene_on};
use schema::{BodySpec, SceneDim, SceneFile};

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
    /// The plugins' body families of the scene ([`crate::family`]), in the order of
    /// their section names.
    pub families: Vec<Box<dyn crate::family::SceneFamily<D>>>,
    /// A restarted scene: the NSCDD state of the saved run ([`restart_scene`]),
    /// given to the solver of the same decomposition at the first step.
    pub dd_state: Option<crate::dd::NscddState>,
    /// A rank's part of a fresh scene ([`part`]): the first step's provisional grid
    /// and its cells' ranks, given to the solver, which starts from them.
    pub part: Option<crate::dd::LoadedPart>,
    /// The first pass of a scene loaded on ranks ([`part::survey_any`]): what every
    /// rank knows of every body before it builds its part.
    pub survey: Option<part::Survey>,
}

/// A loaded 3D scene.
pub type Scene3 = Scene<D3>;

/// Reads and loads a 2D scene file.
pub fn load(path: &std::path::Path, registry: &Registry) -> Result<Scene, InputError> {
    let (text, file) = read_file(path)?;
    load_str(&text, &file, registry)
}

/// The text of the scene file at `path` and its name for messages.
pub(crate) fn read_file(path: &std::path::Path) -> Result<(String, String), InputError> {
    let file = path.display().to_string();
    let text = std::fs::read_to_string(path).map_err(|e| InputError {
        file: file.clone(),
        line: None,
        key: String::new(),
        message: format!("cannot read the file: {e}"),
    })?;
    Ok((text, file))
}

/// The `dimension` key of a scene's text (`None` when it does not parse or has
/// none: the 2D loader reports what is wrong).
pub(crate) fn dimension_of(text: &str) -> Option<i64> {
    toml::from_str::<toml::Table>(text)
        .ok()
        .and_then(|t| t.get("dimension").and_then(|d| d.as_integer()))
}

#[derive(Clone, Copy)]
pub(crate) struct Ctx<'a> {
    text: &'a str,
    file: &'a str,
    /// The scene has sections of body families ([`crate::family`]).
    families: bool,
    /// (this rank, ranks) of a run on several MPI ranks ([`crate::family::FamilyContext::ranks`]).
    ranks: Option<(u32, u32)>,
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

/// The file's `dimension` is `D`'s.
fn dimension_is<D: SceneDim>(cx: &Ctx, sf: &SceneFile<BodySpec<D>>) -> Result<(), InputError> {
    if sf.dimension as usize != D::N {
        let msg = match sf.dimension {
            2 | 3 => format!("a {} scene was expected here (`dimension = {}`)", D::NAME, D::N),
            d => format!("dimension {d} is not supported: 2 or 3"),
        };
        return Err(cx.err(&[k("dimension")], msg));
    }
    Ok(())
}

/// A loaded scene of either dimension.
pub enum AnyScene {
    D2(Scene),
    D3(Scene3),
}

/// Reads and loads a scene file of either dimension (its `dimension` key).
pub fn load_any(path: &std::path::Path, registry: &Registry) -> Result<AnyScene, InputError> {
    let (text, file) = read_file(path)?;
    load_any_str(&text, &file, registry)
}

/// [`load_any`] from the text of a scene.
pub fn load_any_str(text: &str, file: &str, registry: &Registry) -> Result<AnyScene, InputError> {
    match dimension_of(text) {
        Some(3) => Scene3::load_str(text, file, registry).map(AnyScene::D3),
        _ => load_str(text, file, registry).map(AnyScene::D2),
    }
}

/// The plugin libraries a scene names (`[[plugins]] library = "…"`, relative to the
/// scene's folder), each given to `load` in order before the scene is read (its
/// shapes, laws, generators and families may come from them:
/// [`crate::plugin::load_for_scene`]). An error names the entry's line and key.
pub fn load_plugins(text: &str, file: &str, mut load: impl FnMut(&std::path::Path) -> Result<(), String>) -> Result<(), InputError> {
    let cx = Ctx {
        text,
        file,
        families: false,
        ranks: None,
    };
    // a text that does not parse is reported by the scene's loader
    let Ok(t) = toml::from_str::<toml::Table>(text) else {
        return Ok(());
    };
    let Some(list) = t.get("plugins") else { return Ok(()) };
    let Some(list) = list.as_array() else {
        return Err(cx.err(&[k("plugins")], "expected [[plugins]] entries with `library = \"path\"`"));
    };
    let dir = std::path::Path::new(file).parent().filter(|p| !p.as_os_str().is_empty());
    for (i, e) in list.iter().enumerate() {
        let at = [k("plugins"), Seg::Index(i), k("library")];
        let Some(lib) = e.get("library").and_then(|v| v.as_str()) else {
            return Err(cx.err(&at, "the path of a plugin library (a string) is required"));
        };
        let path = dir.map_or_else(|| std::path::PathBuf::from(lib), |d| d.join(lib));
        load(&path).map_err(|m| cx.err(&at, m))?;
    }
    Ok(())
}

/// Loads a 2D scene from its text ([`Scene::load_str`]); `file` names it in messages.
pub fn load_str(text: &str, file: &str, registry: &Registry) -> Result<Scene, InputError> {
    Scene::<D2>::load_str(text, file, registry)
}

impl<D: SceneDim> Scene<D> {
    /// Loads a scene of dimension `D` from its text; `file` names it in messages
    /// (and its folder is where the files a body family's entries name are found).
    pub fn load_str(text: &str, file: &str, registry: &Registry) -> Result<Self, InputError> {
        Self::load_str_on(text, file, registry, None)
    }

    /// [`Self::load_str`] for rank `on` = (this rank, ranks) of a run on several MPI
    /// ranks ([`crate::family::FamilyContext::ranks`]).
    pub(crate) fn load_str_on(text: &str, file: &str, registry: &Registry, on: Option<(u32, u32)>) -> Result<Self, InputError> {
        let mut sf: SceneFile<BodySpec<D>> = parse(text, file)?;
        let cx = Ctx {
            text,
            file,
            families: !sf.sections.is_empty(),
            ranks: on,
        };
        dimension_is::<D>(&cx, &sf)?;
        let sections = std::mem::take(&mut sf.sections);
        check_sections::<D>(&cx, &sections, registry)?;
        let mut scene = load::load_parsed(&cx, sf, registry)?;
        scene.add_families(&cx, sections, registry)?;
        Ok(scene)
    }

    /// Builds the body families of `sections` (checked by [`check_sections`]) on
    /// the world's rigid bodies (all of them, or a rank's part: [`part`]).
    fn add_families(&mut self, cx: &Ctx, sections: Sections, registry: &Registry) -> Result<(), InputError> {
        for (name, value) in sections {
            let kind = registry.family::<D>(&name).expect("checked by check_sections");
            let entries = family_entries(cx, &name, value)?;
            let fcx = crate::family::FamilyContext {
                world: &self.world,
                dir: scene_dir(cx.file),
                max_memory: registry.max_memory(),
                ranks: cx.ranks,
            };
            let mut fam = kind.load(&entries, &fcx).map_err(|e| entry_error(cx, &name, e))?;
            fam.share_world(&mut self.world);
            self.families.push(fam);
        }
        Ok(())
    }
}

/// The body families' sections of a scene file, by name.
type Sections = std::collections::BTreeMap<String, toml::Value>;

/// The folder of the scene file `file` (where the files an entry names are found).
fn scene_dir(file: &str) -> &std::path::Path {
    std::path::Path::new(file)
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(std::path::Path::new("."))
}

/// A family's bad entry, as the loader's error (file, line, key).
fn entry_error(cx: &Ctx, name: &str, e: crate::family::EntryError) -> InputError {
    let mut path = vec![k(name)];
    path.extend(e.index.map(Seg::Index));
    if !e.key.is_empty() {
        path.push(k(&e.key));
    }
    cx.err(&path, e.message)
}

/// Every section is an installed family's.
fn check_sections<D: SceneDim>(cx: &Ctx, sections: &Sections, registry: &Registry) -> Result<(), InputError> {
    for name in sections.keys() {
        if registry.family::<D>(name).is_none() {
            let installed = registry.family_sections::<D>();
            let installed = if installed.is_empty() {
                "none".to_string()
            } else {
                installed.join(", ")
            };
            let msg = format!(
                "unknown key `{name}`: not a key of {} scene files nor the section of an installed body family (installed: {installed}; a plugin may provide it)",
                D::NAME
            );
            return Err(cx.err(&[k(name)], msg));
        }
    }
    Ok(())
}

/// The families' [`crate::family::FamilyKind::load_boxes`] of `sections` on the
/// surveyed world (no body built), with a restart's `saved` families' states (by
/// section); `None` if one family has none (the scene is then loaded whole on
/// every rank).
fn family_boxes<D: SceneDim>(
    cx: &Ctx,
    scene: &Scene<D>,
    sections: &Sections,
    registry: &Registry,
    saved: Option<&serde_json::Map<String, serde_json::Value>>,
) -> Result<Option<Vec<[[f64; 3]; 2]>>, InputError> {
    let mut all = Vec::new();
    for (name, value) in sections {
        let kind = registry.family::<D>(name).expect("checked by check_sections");
        let entries = family_entries(cx, name, value.clone())?;
        let fcx = crate::family::FamilyContext {
            world: &scene.world,
            dir: scene_dir(cx.file),
            max_memory: registry.max_memory(),
            ranks: cx.ranks,
        };
        let state = saved.and_then(|m| m.get(name));
        match kind.load_boxes(&entries, &fcx, state).map_err(|e| entry_error(cx, name, e))? {
            Some(b) => all.extend(b),
            None => return Ok(None),
        }
    }
    Ok(Some(all))
}

/// The `[[name]]` entries of a body family's section.
fn family_entries(cx: &Ctx, name: &str, value: toml::Value) -> Result<Vec<toml::Table>, InputError> {
    let not = || {
        cx.err(
            &[k(name)],
            format!("`{name}` is a list of tables: write its entries as `[[{name}]]`"),
        )
    };
    match value {
        toml::Value::Array(a) => a
            .into_iter()
            .map(|v| match v {
                toml::Value::Table(t) => Ok(t),
                _ => Err(not()),
            })
            .collect(),
        _ => Err(not()),
    }
}
