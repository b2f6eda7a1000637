//! Restart from a saved state: a run's `final.json` (or a `checkpoint_NNNNNN.json`
//! written every `output.checkpoint_every` steps) holds the step, the time, every
//! body's position, rotation and velocity, the contacts' keys and impulses (the warm
//! start of the next step) and the box height ε1 is measured from. [`restart`] puts
//! that state into a world loaded from the same scene, so that the run continues to
//! the scene's end time. Continuing is bitwise the uninterrupted one-domain run (the
//! saved numbers round-trip exactly through JSON); a decomposed run starts its gluing
//! multipliers F_Γ from zero and repartitions at the first step, unless the scene
//! is restarted with [`restart_scene`] and the state holds the NSCDD state of the
//! same decomposition (`nscdd`, written by a one-process run): then it continues
//! bitwise as well; body families' states (`families`) are read back the same way.
//!
//! The scene may change anything that is not state: solver settings, the
//! decomposition, outputs, the end time, drives. It may not change the bodies (their
//! number and kinds are checked) nor the step h (the saved time must be step × h).

use crate::dim::joint::Joint;
use crate::dim::{Dim, Vector};
use crate::error::InputError;
use crate::model::{ContactKey, Contacts};
use crate::world::World;
use serde::Deserialize;
use std::path::Path;

#[derive(Deserialize)]
#[serde(bound = "")]
struct SavedBody<D: Dim> {
    id: u32,
    kind: String,
    position: D::Point,
    /// The angle in 2D, the rotation vector in 3D.
    rotation: D::RotVec,
    /// 3D: the exact orientation (the rotation vector is for reading).
    #[serde(default)]
    quaternion: Option<D::Rot>,
    velocity: D::Twist,
}

impl<D: Dim> SavedBody<D> {
    /// The saved orientation: the quaternion where given (3D), else the rotation.
    fn rot(&self) -> D::Rot {
        self.quaternion.unwrap_or_else(|| D::rot_from_vec(&self.rotation))
    }
}

#[derive(Deserialize)]
#[serde(bound = "")]
struct SavedContact<D: Dim> {
    bodies: [u32; 2],
    #[serde(default)]
    feature: Option<u32>,
    point: D::Point,
    normal: D::Point,
    /// The impulse in the contact frame (normal first).
    #[serde(default)]
    r: Option<D::Local>,
    /// 2D states written before `r`: its two components.
    #[serde(default)]
    r_n: Option<f64>,
    #[serde(default)]
    r_t: Option<f64>,
    gap: f64,
    #[serde(default)]
    bonded: bool,
}

#[derive(Deserialize)]
#[serde(bound = "")]
struct Saved<D: Dim> {
    step: u64,
    time: f64,
    #[serde(default)]
    box_h0: Option<f64>,
    bodies: Vec<SavedBody<D>>,
    contacts: Vec<SavedContact<D>>,
}

/// Loads the saved state in `path` into `w` (a world loaded from the scene that
/// wrote it). Errors name the file, the line and the key.
pub fn restart<D: Dim>(w: &mut World<D>, path: &Path) -> Result<(), InputError> {
    let (text, file) = read_state(path)?;
    restart_str(w, &text, &file)
}

/// The text of a saved state and its name for messages.
fn read_state(path: &Path) -> Result<(String, String), InputError> {
    let file = path.display().to_string();
    let text = std::fs::read_to_string(path).map_err(|e| InputError {
        file: file.clone(),
        line: None,
        key: String::new(),
        message: format!("cannot read the restart file: {e}"),
    })?;
    Ok((text, file))
}

/// Why a run restarted from `state` may not write its outputs in `out`: `out` is
/// the folder holding the state (the continued run's history.csv would overwrite
/// the one it continues). The message names both; the caller names the option.
pub fn check_out_dir(out: &Path, state: &Path) -> Result<(), String> {
    let dir_of = |p: &Path| std::fs::canonicalize(p).ok();
    let parent = state.parent().map(|p| if p.as_os_str().is_empty() { Path::new(".") } else { p });
    if dir_of(out).is_some() && dir_of(out) == parent.and_then(dir_of) {
        return Err(format!(
            "{} holds the restart file {}; write the continued run elsewhere (its history.csv would be overwritten)",
            out.display(),
            state.display()
        ));
    }
    Ok(())
}

/// [`restart`] of a scene: the world's state, then each body family's from the
/// state's `families` (by section) and the NSCDD state (`nscdd`, used when the run
/// has the same decomposition: then a decomposed run continues bitwise too). A
/// state without a family of the scene, or with one the scene does not have, is
/// another scene's: an error.
pub fn restart_scene<D: Dim>(scene: &mut super::Scene<D>, path: &Path) -> Result<(), InputError> {
    let (text, file) = read_state(path)?;
    restart_str(&mut scene.world, &text, &file)?;
    let ck = StateChecks { text: &text, file: &file };
    // the state's other parts, each read into its type (the rest of the file is
    // skipped, never held as a JSON tree)
    let part = |key: &str, e: serde_json::Error| ck.err(Some(e.line()), key.into(), format!("not a saved `{key}` state: {e}"));
    scene.dd_state = serde_json::from_str::<SavedNscdd>(&text).map_err(|e| part("nscdd", e))?.nscdd;
    let states = serde_json::from_str::<SavedFamilies>(&text)
        .map_err(|e| part("families", e))?
        .families
        .unwrap_or_default();
    for (name, _) in &states {
        if !scene.families.iter().any(|f| f.section() == name) {
            let msg = format!("the state holds `{name}` bodies, the scene none: a restart needs the scene that wrote it");
            return Err(ck.err(ck.line_of(name, 0), format!("families.{name}"), msg));
        }
    }
    for f in scene.families.iter_mut() {
        let key = format!("families.{}", f.section());
        let Some(state) = states.get(f.section()) else {
            let msg = format!(
                "the scene has `{}` bodies, the state none: a restart needs the scene that wrote it",
                f.section()
            );
            return Err(ck.err(None, key, msg));
        };
        f.load_state(state)
            .map_err(|m| ck.err(ck.line_of(f.section(), 0), key.clone(), m))?;
    }
    Ok(())
}

/// The NSCDD solver's part of a saved state.
#[derive(Deserialize)]
struct SavedNscdd {
    #[serde(default)]
    nscdd: Option<crate::dd::NscddState>,
}

/// The body families' part of a saved state (their states by section).
#[derive(Deserialize)]
struct SavedFamilies {
    #[serde(default)]
    families: Option<serde_json::Map<String, serde_json::Value>>,
}

/// The dimension a saved state declares (2 when it declares none).
#[derive(Deserialize)]
struct SavedHead {
    #[serde(default)]
    dimension: Option<u64>,
}

/// [`restart`] from the text of a saved state; `file` names it in messages.
pub fn restart_str<D: Dim>(w: &mut World<D>, text: &str, file: &str) -> Result<(), InputError> {
    let ck = StateChecks { text, file };
    let dimension = serde_json::from_str::<SavedHead>(text).ok().and_then(|h| h.dimension).unwrap_or(2);
    if dimension != D::N as u64 {
        return Err(ck.err(
            ck.line_of("dimension", 0),
            "dimension".into(),
            format!("the state is {dimension}D, the scene {}", D::NAME),
        ));
    }
    let saved: Saved<D> = serde_json::from_str(text).map_err(|e| {
        ck.err(
            Some(e.line()),
            String::new(),
            format!("not a saved state (final.json of a {} run): {e}", D::NAME),
        )
    })?;
    let nb = w.bodies.len();
    let finite =
        |sb: &SavedBody<D>| sb.position.as_ref().iter().chain(sb.velocity.as_ref()).all(|x| x.is_finite()) && D::rot_finite(&sb.rot());
    ck.bodies(
        saved.bodies.iter().map(|sb| (sb.id, sb.kind.as_str(), finite(sb))),
        |k| w.kind_name(k),
        nb,
    )?;
    let expected = ck.time(saved.step, saved.time, &w.time)?;
    let b = &mut w.bodies;
    for (k, sb) in saved.bodies.iter().enumerate() {
        b.pos[k] = sb.position;
        b.rot[k] = sb.rot();
        b.vel[k] = sb.velocity;
        b.refresh_inverse(k);
    }
    w.contacts = saved_contacts(&ck, &saved.contacts, &w.bodies.pos)?;
    w.step = saved.step;
    w.t = expected;
    w.box_h0 = saved.box_h0;
    Ok(())
}

/// The saved contacts (keys, impulses, bonds: the next step's warm start).
fn saved_contacts<D: Dim>(ck: &StateChecks, saved: &[SavedContact<D>], pos: &[D::Point]) -> Result<Contacts<D>, InputError> {
    let nb = pos.len();
    let mut c = Contacts::default();
    for (a, sc) in saved.iter().enumerate() {
        let [i, j] = sc.bodies;
        if i as usize >= nb || j as usize >= nb {
            return Err(ck.err(
                ck.line_of("bodies", a + 1),
                format!("contacts[{a}].bodies"),
                format!("body ids must be below {nb}"),
            ));
        }
        let r = match (sc.r, sc.r_n, sc.r_t) {
            (Some(r), _, _) => r,
            (None, Some(rn), Some(rt)) if D::N == 2 => D::Local::from_fn(|k| [rn, rt][k]),
            _ => return Err(ck.err(ck.line_of("gap", a), format!("contacts[{a}].r"), "missing impulse `r`".into())),
        };
        c.bodies.push([i, j]);
        c.frame.push(D::frame(&sc.point, &sc.normal, &pos[i as usize], &pos[j as usize]));
        c.block.push(Default::default());
        c.target.push(Default::default());
        c.r.push(r);
        c.u_free.push(D::Local::zero());
        c.gap.push(sc.gap);
        c.point.push(sc.point);
        c.key.push(ContactKey {
            i,
            j,
            feature: sc.feature.unwrap_or(0),
        });
        c.joint.push(if sc.bonded { Joint::RESTORED } else { Joint::default() });
    }
    Ok(c)
}

/// The checks every restart file gets, whatever the dimension: errors name the
/// file, the line (the k-th occurrence of a key: the file is written one field per
/// line) and the key.
pub(crate) struct StateChecks<'a> {
    pub text: &'a str,
    pub file: &'a str,
}

impl StateChecks<'_> {
    pub fn err(&self, line: Option<usize>, key: String, message: String) -> InputError {
        InputError {
            file: self.file.to_string(),
            line,
            key,
            message,
        }
    }
    pub fn line_of(&self, key: &str, k: usize) -> Option<usize> {
        let pat = format!("\"{key}\":");
        self.text
            .match_indices(&pat)
            .nth(k)
            .map(|(o, _)| crate::error::line_of(self.text, o))
    }
    /// The saved bodies are the scene's: same count, ids in order, same kinds,
    /// finite states. `bodies[k]` = (id, kind, finite).
    pub fn bodies<'k>(
        &self,
        saved: impl ExactSizeIterator<Item = (u32, &'k str, bool)>,
        kinds: impl Fn(usize) -> &'static str,
        nb: usize,
    ) -> Result<(), InputError> {
        if saved.len() != nb {
            return Err(self.err(
                self.line_of("bodies", 0),
                "bodies".into(),
                format!(
                    "the saved state has {} bodies, the scene {nb}: a restart needs the scene that wrote it",
                    saved.len()
                ),
            ));
        }
        for (k, (id, kind, finite)) in saved.enumerate() {
            if id as usize != k {
                return Err(self.err(
                    self.line_of("id", k),
                    format!("bodies[{k}].id"),
                    format!("expected id {k}, found {id}"),
                ));
            }
            if kind != kinds(k) {
                return Err(self.err(
                    self.line_of("kind", k),
                    format!("bodies[{k}].kind"),
                    format!("the saved body is a `{kind}`, the scene's body {k} a `{}`", kinds(k)),
                ));
            }
            if !finite {
                return Err(self.err(self.line_of("position", k), format!("bodies[{k}]"), "non-finite state".into()));
            }
        }
        Ok(())
    }
    /// The saved time is step × h and the scene has steps left; returns the time.
    pub fn time(&self, step: u64, time: f64, t: &crate::world::TimeSettings) -> Result<f64, InputError> {
        let expected = step as f64 * t.h;
        if !(time.is_finite() && (time - expected).abs() <= 1e-9 * expected.abs().max(t.h)) {
            return Err(self.err(
                self.line_of("time", 0),
                "time".into(),
                format!("the saved time {time} s is not step {step} × h = {expected} s: a restart keeps the scene's step h"),
            ));
        }
        if step >= t.steps {
            return Err(self.err(
                self.line_of("step", 0),
                "step".into(),
                format!(
                    "the saved state is at step {step}, the scene ends at step {}: nothing left to run (raise time.steps or time.duration)",
                    t.steps
                ),
            ));
        }
        Ok(expected)
    }
}
