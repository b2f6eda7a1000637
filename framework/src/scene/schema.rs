//! The scene file format (TOML, SI units). Unknown keys are rejected everywhere:
//! shape- and generator-specific keys are checked by the plugin that owns them.
//! See the README's "Scene files" section for a complete description.

use crate::dim::{Dim, D2, D3};
use crate::drive::DofDrive;
use crate::solver::SolverSettings;
use serde::de::DeserializeOwned;
use serde::Deserialize;
use std::fmt::Debug;

fn two() -> u8 {
    2
}
fn half() -> f64 {
    0.5
}
fn yes() -> bool {
    true
}
fn coulomb() -> String {
    "coulomb".into()
}
fn overlap() -> f64 {
    0.05
}

/// A scene file; `B` is the body entry of its dimension ([`BodySpec<D>`]).
#[derive(Deserialize, Debug)]
#[serde(bound(deserialize = "B: Deserialize<'de>"))]
pub struct SceneFile<B = BodySpec> {
    /// 2 or 3.
    #[serde(default = "two")]
    pub dimension: u8,
    /// Gravity vector (m/s²), default (0, −9.81) in 2D, (0, 0, −9.81) in 3D.
    /// Absent: the dimension's default (the loaders fill it in).
    pub gravity: Option<Vec<f64>>,
    pub time: TimeSpec,
    #[serde(default)]
    pub solver: SolverSettings,
    #[serde(default)]
    pub detection: DetectionSpec,
    #[serde(default)]
    pub materials: Vec<MaterialSpec>,
    #[serde(default)]
    pub laws: Vec<LawSpec>,
    #[serde(default = "Vec::new")]
    pub bodies: Vec<B>,
    #[serde(default)]
    pub generate: Vec<GenerateSpec>,
    #[serde(default)]
    pub output: OutputSpec,
    /// NSCDD: split the contact set over nx × ny subdomains.
    pub decomposition: Option<DecompositionSpec>,
    /// `[[plugins]] library = "…"`: plugin libraries the scene needs, relative to the
    /// scene (loaded before the scene is read: [`super::load_plugins`]).
    #[serde(default)]
    pub plugins: Vec<PluginSpec>,
    /// Every other top-level key: the sections of the plugins' body families
    /// (`[[name]]` entries, [`crate::family`]), by name. The loader refuses a key
    /// that no registered family owns, as an unknown key (the file's other tables
    /// reject unknown keys themselves).
    #[serde(flatten)]
    pub sections: std::collections::BTreeMap<String, toml::Value>,
}

/// `[decomposition]`: signed integers so that a negative value gets its own message.
#[derive(Deserialize, Debug, Default)]
#[serde(deny_unknown_fields)]
pub struct DecompositionSpec {
    pub nx: Option<i64>,
    pub ny: Option<i64>,
    /// 3D only.
    pub nz: Option<i64>,
    /// Scenes with body families ([`crate::family`]): each family's contacts form
    /// subdomains of their own (split by the same grid), glued to the rigid ones
    /// through the bodies they share.
    pub by_model: Option<bool>,
    /// `decentralized` (default) or `centralized`.
    pub scheme: Option<String>,
    pub sweeps_per_gluing: Option<i64>,
    pub threads: Option<i64>,
    pub repartition_every: Option<i64>,
    /// Re-partition between the periodic repartitions when the load imbalance (the
    /// largest subdomain's contacts over the mean) has grown by this factor (> 1)
    /// since the last one.
    pub rebalance: Option<f64>,
    /// `"uniform"` (default): equal cells over the contact points' bounding box;
    /// `"balanced"`: multi-jagged cuts that split the contact points evenly.
    pub grid: Option<String>,
}

#[derive(Deserialize, Debug)]
#[serde(deny_unknown_fields)]
pub struct TimeSpec {
    /// Step h (s).
    pub step: f64,
    /// θ ∈ [½, 1].
    #[serde(default = "half")]
    pub theta: f64,
    /// Number of steps (or give `duration`).
    pub steps: Option<u64>,
    /// Duration (s); steps = round(duration / h).
    pub duration: Option<f64>,
}

#[derive(Deserialize, Debug)]
#[serde(deny_unknown_fields)]
pub struct DetectionSpec {
    /// Alert distance (m). Default: 0.1 × the median shape size.
    pub alert: Option<f64>,
    /// Initial interpenetration allowed, relative to the smaller shape size.
    #[serde(default = "overlap")]
    pub overlap_tolerance: f64,
}

impl Default for DetectionSpec {
    fn default() -> Self {
        DetectionSpec {
            alert: None,
            overlap_tolerance: overlap(),
        }
    }
}

#[derive(Deserialize, Debug)]
#[serde(deny_unknown_fields)]
pub struct MaterialSpec {
    pub name: String,
    /// kg/m³ (per unit depth in 2D: mass = density × area).
    pub density: f64,
}

#[derive(Deserialize, Debug)]
pub struct LawSpec {
    /// The two materials (order irrelevant).
    pub materials: [String; 2],
    /// Law kind: `coulomb` (default), `frictionless`, `none` (the two materials never
    /// interact), or one a plugin registered.
    #[serde(default = "coulomb")]
    pub law: String,
    /// Law parameters (`friction`, `restitution`).
    #[serde(flatten)]
    pub params: toml::Table,
}

/// A body of a scene file of dimension `D`.
#[derive(Deserialize, Debug)]
#[serde(bound = "")]
pub struct BodySpec<D: SceneDim = D2> {
    /// Shape kind (`disk`, `wall`, `halfplane`, `sphere`, `plane`, `box`, ...).
    pub shape: String,
    pub material: String,
    /// Optional unique name, used by outputs and `[output.box]`/`box3`.
    pub name: Option<String>,
    /// (x, y) in 2D, (x, y, z) in 3D.
    pub position: D::Point,
    /// The angle (rad) in 2D; in 3D a rotation vector (axis × angle, rad).
    #[serde(default)]
    pub rotation: D::RotVec,
    /// (v_x, v_y, ω) in 2D; (v_x, v_y, v_z, ω_x, ω_y, ω_z) in 3D, ω in the world frame.
    #[serde(default)]
    pub velocity: D::Twist,
    #[serde(default)]
    pub fixed: bool,
    pub drive: Option<D::DriveSpec>,
    /// Shape-specific keys, checked by the shape's plugin.
    #[serde(flatten)]
    pub params: toml::Table,
}

/// A body of a 3D scene.
pub type BodySpec3 = BodySpec<D3>;

/// Driven degrees of freedom of a 2D body.
#[derive(Deserialize, Debug, Default)]
#[serde(deny_unknown_fields)]
pub struct DriveSpec2 {
    pub x: Option<DofDrive>,
    pub y: Option<DofDrive>,
    pub rot: Option<DofDrive>,
}

/// Driven degrees of freedom of a 3D body (rotations about the world axes).
#[derive(Deserialize, Debug, Default)]
#[serde(deny_unknown_fields)]
pub struct DriveSpec3 {
    pub x: Option<DofDrive>,
    pub y: Option<DofDrive>,
    pub z: Option<DofDrive>,
    pub rx: Option<DofDrive>,
    pub ry: Option<DofDrive>,
    pub rz: Option<DofDrive>,
}

/// What a scene file spells differently in each dimension: the drive keys of a
/// body and the `[output]` key naming a box sample's walls.
pub trait SceneDim: Dim {
    /// A body's `drive = { … }` table.
    type DriveSpec: DeserializeOwned + Debug;
    /// The drive keys, in the order of the degrees of freedom.
    const DOF_NAMES: &'static [&'static str];
    /// The `[output]` key of a box sample (`box`, `box3`) and the other dimension's.
    const BOX_KEY: &'static str;
    const OTHER_BOX_KEY: &'static str;
    /// The drives of a table, per degree of freedom.
    fn drives(d: &Self::DriveSpec) -> Vec<Option<&DofDrive>>;
    /// The box sample's wall keys and body names (walls normal to x, min then max,
    /// then y, then z) and `strain_from`.
    fn box_walls(o: &OutputSpec) -> Option<(Vec<(&'static str, &str)>, f64)>;
}

impl SceneDim for D2 {
    type DriveSpec = DriveSpec2;
    const DOF_NAMES: &'static [&'static str] = &["x", "y", "rot"];
    const BOX_KEY: &'static str = "box";
    const OTHER_BOX_KEY: &'static str = "box3";
    fn drives(d: &DriveSpec2) -> Vec<Option<&DofDrive>> {
        vec![d.x.as_ref(), d.y.as_ref(), d.rot.as_ref()]
    }
    fn box_walls(o: &OutputSpec) -> Option<(Vec<(&'static str, &str)>, f64)> {
        let b = o.box_walls.as_ref()?;
        let names = vec![
            ("left", b.left.as_str()),
            ("right", &b.right),
            ("bottom", &b.bottom),
            ("top", &b.top),
        ];
        Some((names, b.strain_from))
    }
}

impl SceneDim for D3 {
    type DriveSpec = DriveSpec3;
    const DOF_NAMES: &'static [&'static str] = &["x", "y", "z", "rx", "ry", "rz"];
    const BOX_KEY: &'static str = "box3";
    const OTHER_BOX_KEY: &'static str = "box";
    fn drives(d: &DriveSpec3) -> Vec<Option<&DofDrive>> {
        [&d.x, &d.y, &d.z, &d.rx, &d.ry, &d.rz].map(|x| x.as_ref()).to_vec()
    }
    fn box_walls(o: &OutputSpec) -> Option<(Vec<(&'static str, &str)>, f64)> {
        let b = o.box3.as_ref()?;
        let names = vec![
            ("xmin", b.xmin.as_str()),
            ("xmax", &b.xmax),
            ("ymin", &b.ymin),
            ("ymax", &b.ymax),
            ("zmin", &b.zmin),
            ("zmax", &b.zmax),
        ];
        Some((names, b.strain_from))
    }
}

#[derive(Deserialize, Debug)]
pub struct GenerateSpec {
    /// Generator name (`disk_deposit`, `square_lattice`, ...).
    pub kind: String,
    #[serde(flatten)]
    pub params: toml::Table,
}

#[derive(Deserialize, Debug)]
#[serde(deny_unknown_fields)]
pub struct OutputSpec {
    /// Write VTK (and extra writers) every `every` steps; 0: only the last step.
    #[serde(default)]
    pub every: u64,
    #[serde(default = "yes")]
    pub vtk: bool,
    /// Extra writers registered by plugins.
    #[serde(default)]
    pub writers: Vec<String>,
    /// Save the state to `checkpoint.json` every this many steps (0: never; the
    /// final state is always in `final.json`). Both are restart files.
    #[serde(default)]
    pub checkpoint_every: u64,
    /// The walls of a box sample, by body name (2D).
    #[serde(rename = "box")]
    pub box_walls: Option<BoxSpec>,
    /// The six walls of a box sample, by body name (3D).
    pub box3: Option<BoxSpec3>,
}

impl Default for OutputSpec {
    fn default() -> Self {
        OutputSpec {
            every: 0,
            vtk: true,
            writers: vec![],
            checkpoint_every: 0,
            box_walls: None,
            box3: None,
        }
    }
}

#[derive(Deserialize, Debug)]
#[serde(deny_unknown_fields)]
pub struct BoxSpec {
    pub left: String,
    pub right: String,
    pub bottom: String,
    pub top: String,
    /// ε1 is measured from the height at this time (s).
    #[serde(default)]
    pub strain_from: f64,
}

/// `[output] box3 = { xmin = .., xmax = .., ymin = .., ymax = .., zmin = .., zmax = .. }`.
#[derive(Deserialize, Debug)]
#[serde(deny_unknown_fields)]
pub struct BoxSpec3 {
    pub xmin: String,
    pub xmax: String,
    pub ymin: String,
    pub ymax: String,
    pub zmin: String,
    pub zmax: String,
    /// ε1 (along z) is measured from the height at this time (s).
    #[serde(default)]
    pub strain_from: f64,
}

/// One `[[plugins]]` entry of a scene.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PluginSpec {
    pub library: String,
}
