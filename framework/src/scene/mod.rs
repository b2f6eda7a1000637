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
pub mod restart;
pub mod schema;

use crate::dim::{Dim, D2, D3};
use crate::error::{line_of, InputError};
use crate::registry::Registry;
use crate::world::{Material, TimeSettings, World};
use builder::Origin;
pub use checks::parse_scheme;
pub(crate) use checks::*;
use locate::{locate, path_string, Seg};
pub use restart::restart;
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
}

/// A loaded 3D scene.
pub type Scene3 = Scene<D3>;

/// Reads and loads a 2D scene file.
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
    D3(Scene3),
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
        Some(3) => Scene3::load_str(text, file, registry).map(AnyScene::D3),
        _ => load_str(text, file, registry).map(AnyScene::D2),
    }
}

/// Loads a 2D scene from its text ([`Scene::load_str`]); `file` names it in messages.
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
    Scene::<D2>::load_str_with(text, file, registry, deformable)
}

impl<D: SceneDim> Scene<D> {
    /// Loads a scene of dimension `D` from its text; `file` names it in messages.
    pub fn load_str(text: &str, file: &str, registry: &Registry) -> Result<Self, InputError> {
        Self::load_str_with(text, file, registry, false).map(|(s, _)| s)
    }

    /// [`Scene::load_str`] that also returns the scene's `[[deformable]]` entries,
    /// for a deformable-body plugin to build; with `deformable = false` a scene
    /// holding any is refused ([`NO_DEFORMABLE`]).
    pub fn load_str_with(text: &str, file: &str, registry: &Registry, deformable: bool) -> Result<(Self, Vec<toml::Table>), InputError> {
        let mut sf: SceneFile<BodySpec<D>> = parse(text, file)?;
        let cx = Ctx {
            text,
            file,
            deformable: !sf.deformable.is_empty(),
        };
        if !deformable && cx.deformable {
            return Err(cx.err(&[k("deformable")], NO_DEFORMABLE));
        }
        if sf.dimension as usize != D::N {
            let msg = match sf.dimension {
                2 | 3 => format!("a {} scene was expected here (`dimension = {}`)", D::NAME, D::N),
                d => format!("dimension {d} is not supported: 2 or 3"),
            };
            return Err(cx.err(&[k("dimension")], msg));
        }
        let entries = std::mem::take(&mut sf.deformable);
        let scene = load::load_parsed(&cx, sf, registry)?;
        Ok((scene, entries))
    }
}
