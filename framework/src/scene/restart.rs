//! Restart from a saved state: a run's `final.json` (or a `checkpoint_NNNNNN.json`
//! written every `output.checkpoint_every` steps) holds the step, the time, every
//! body's position, rotation and velocity, the contacts' keys and impulses (the warm
//! start of the next step) and the box height ε1 is measured from. [`restart`] puts
//! that state into a world loaded from the same scene, so that the run continues to
//! the scene's end time. Continuing is bitwise the uninterrupted one-domain run (the
//! saved numbers round-trip exactly through JSON); a decomposed run starts its gluing
//! multipliers F_Γ from zero and repartitions at the first step, unless the scene
//! is restarted with [`restart_scene`] and the state holds the NSCDD state of the
//! same decomposition (`nscdd`, gathered from every rank on MPI ranks): then it
//! continues bitwise as well; body families' states (`families`) are read back the
//! same way.
//!
//! The scene may change anything that is not state: solver settings, the
//! decomposition, outputs, the end time, drives. It may not change the bodies (their
//! number and kinds are checked) nor the step h (the saved time must be step × h).
//!
//! The file is read as a stream ([`super::restart_stream`]): each body is written
//! into the world as it is read, so a state that turns out bad leaves the world
//! partly restarted — after an error, load the scene again before using it (the
//! command line exits).

use super::restart_stream::{StateSeed, Streamed};
use crate::dim::Dim;
use crate::error::InputError;
use crate::world::World;
use serde::de::DeserializeSeed;
use std::path::Path;

/// Loads the saved state in `path` into `w` (a world loaded from the scene that
/// wrote it), read as a stream ([`super::restart_stream`]). Errors name the file,
/// the line and the key; after one the world is partly restarted (module docs).
pub fn restart<D: Dim>(w: &mut World<D>, path: &Path) -> Result<(), InputError> {
    restart_from(w, Source::File(path), false, None).map(|_| ())
}

/// Where a saved state is read from: its file (streamed, never held whole) or a
/// text.
enum Source<'a> {
    File(&'a Path),
    Text(&'a str, &'a str),
}

impl Source<'_> {
    /// The state's name in messages.
    fn name(&self) -> String {
        match self {
            Source::File(p) => p.display().to_string(),
            Source::Text(_, name) => name.to_string(),
        }
    }
    /// The text, for the line of an error (a file is read only then).
    fn text(&self) -> String {
        match self {
            Source::File(p) => std::fs::read_to_string(p).unwrap_or_default(),
            Source::Text(t, _) => t.to_string(),
        }
    }
}

/// The parts of a state besides the world's: the NSCDD state and the families'.
type Parts = (Option<crate::dd::NscddState>, serde_json::Map<String, serde_json::Value>);

/// [`restart`] from `src`; with `parts`, the `nscdd` and `families` parts too; with
/// `part`, only the contacts an MPI rank keeps.
fn restart_from<D: Dim>(
    w: &mut World<D>,
    src: Source,
    parts: bool,
    part: Option<&mut crate::dd::RestartPart>,
) -> Result<Parts, InputError> {
    let (mut failed, mut dimension) = (None, None);
    let seed = StateSeed {
        w: &mut *w,
        parts,
        failed: &mut failed,
        dimension: &mut dimension,
        part,
    };
    let read = match &src {
        Source::File(p) => {
            let f = std::fs::File::open(p).map_err(|e| InputError {
                file: src.name(),
                line: None,
                key: String::new(),
                message: format!("cannot read the restart file: {e}"),
            })?;
            let mut de = serde_json::Deserializer::from_reader(std::io::BufReader::with_capacity(1 << 16, f));
            seed.deserialize(&mut de).and_then(|s| de.end().map(|_| s))
        }
        Source::Text(t, _) => {
            let mut de = serde_json::Deserializer::from_str(t);
            seed.deserialize(&mut de).and_then(|s| de.end().map(|_| s))
        }
    };
    let ck = StateChecks::new(src);
    // a state without `dimension` is 2D (states written before it were)
    let other_dimension = failed.as_ref().is_some_and(|f| f.key == "dimension");
    if dimension.is_none() && D::N != 2 && !other_dimension {
        return Err(ck.err(
            ck.line_of("dimension", 0),
            "dimension".into(),
            format!("the state is 2D, the scene {}", D::NAME),
        ));
    }
    let s = match (read, failed) {
        (_, Some(f)) => return Err(ck.err(f.at.and_then(|(k, n)| ck.line_of(k, n)), f.key, f.message)),
        (Err(e), None) => {
            let message = format!("not a saved state (final.json of a {} run): {e}", D::NAME);
            return Err(ck.err(Some(e.line()).filter(|&l| l > 0), String::new(), message));
        }
        (Ok(s), None) => s,
    };
    let missing = |key: &str| {
        ck.err(
            None,
            String::new(),
            format!("not a saved state (final.json of a {} run): missing field `{key}`", D::NAME),
        )
    };
    let (step, time) = (s.step.ok_or_else(|| missing("step"))?, s.time.ok_or_else(|| missing("time"))?);
    s.bodies.ok_or_else(|| missing("bodies"))?;
    let (mut contacts, normals) = s.contacts.ok_or_else(|| missing("contacts"))?;
    let expected = ck.time(step, time, &w.time)?;
    Streamed::frames(&mut contacts, &normals, &w.bodies.pos);
    w.contacts = contacts;
    w.step = step;
    w.t = expected;
    w.box_h0 = s.box_h0;
    Ok((s.nscdd, s.families.unwrap_or_default()))
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
/// another scene's: an error. The file is read once, as a stream.
pub fn restart_scene<D: Dim>(scene: &mut super::Scene<D>, path: &Path) -> Result<(), InputError> {
    restart_scene_on(scene, path, None).map(|_| ())
}

/// [`restart_scene`] as rank `me` of `ranks` MPI ranks (`on`; `None`: one process).
/// When the run will hold its contacts per rank (a decomposition by geometry or
/// by model on no more ranks than cells, the families not yet loaded: a surveyed
/// scene, [`super::part::restart_on`]; the state of the same decomposition), the
/// state's `nscdd` part is
/// read first (the rest of the file skipped) and then, as the file streams, each
/// rank keeps only the contacts its subdomains get in the first step
/// ([`crate::dd::RestartPart`]): the sample's contacts are never all on one rank.
/// Returns, when the contacts were read in part (the world then differs between
/// ranks by its contacts), a digest of every contact read, kept or not: the same on
/// every rank reading the same file.
pub fn restart_scene_on<D: Dim>(scene: &mut super::Scene<D>, path: &Path, on: Option<(u32, u32)>) -> Result<Option<u64>, InputError> {
    let part = rank_part_of(path, scene, on);
    restart_scene_with(scene, path, part)
}

/// The contacts rank `me` of `ranks` (`on`) keeps of the state at `path`, when the
/// run will hold its contacts per rank ([`restart_scene_on`]); `None`: every
/// contact read.
pub(super) fn rank_part_of<D: Dim>(path: &Path, scene: &super::Scene<D>, on: Option<(u32, u32)>) -> Option<crate::dd::RestartPart> {
    match (on, &scene.decomposition) {
        (Some((ranks, me)), Some(c)) if ranks > 1 && scene.families.is_empty() => {
            let grid_of = [c.dd.nx, c.dd.ny, c.dd.nz];
            nscdd_of(path).and_then(|s| s.rank_part(grid_of, c.by_model, ranks, me))
        }
        _ => None,
    }
}

/// [`restart_scene_on`] with the rank's `part` of the contacts given (its world may
/// hold part of the scene's bodies: those of its first step, [`super::part::restart_on`]).
pub(super) fn restart_scene_with<D: Dim>(
    scene: &mut super::Scene<D>,
    path: &Path,
    mut part: Option<crate::dd::RestartPart>,
) -> Result<Option<u64>, InputError> {
    debug_assert!(
        part.is_some() || scene.world.ids.held().is_none(),
        "a part world reads its contacts in part"
    );
    let (nscdd, states) = restart_from(&mut scene.world, Source::File(path), true, part.as_mut())?;
    scene.dd_state = nscdd;
    let ck = StateChecks::new(Source::File(path));
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
    Ok(part.map(|p| p.digest()))
}

/// The `nscdd` part of the saved state at `path` alone (`None` when absent or
/// unreadable: the whole reading then reports what is wrong), read by [`top_key`].
fn nscdd_of(path: &Path) -> Option<crate::dd::NscddState> {
    #[derive(serde::Deserialize)]
    struct Only {
        #[serde(default)]
        nscdd: Option<crate::dd::NscddState>,
    }
    top_key(path, b"\n  \"nscdd\": ", |o: Only| o.nscdd)
}

/// The `families` part of the saved state at `path` alone (the body families'
/// states by section; `None` when absent or unreadable), read by [`top_key`].
pub(super) fn families_of(path: &Path) -> Option<serde_json::Map<String, serde_json::Value>> {
    #[derive(serde::Deserialize)]
    struct Only {
        #[serde(default)]
        families: Option<serde_json::Map<String, serde_json::Value>>,
    }
    top_key(path, b"\n  \"families\": ", |o: Only| o.families)
}

/// One top-level value of the saved state at `path`, `key` its line's start
/// (`\n  "name": `). A `final.json` or checkpoint is pretty-printed, so its
/// top-level keys are the lines starting with two spaces and a quote: the file is
/// scanned for the key (the last one, whose value the streaming reader keeps) and
/// only its value parsed (18 MB of a 137 MB state for `nscdd`: the bodies and
/// contacts are not parsed twice); another layout is parsed whole as `O`, the rest
/// skipped, and `pick` takes the value (a key given twice: none).
fn top_key<T: serde::de::DeserializeOwned, O: serde::de::DeserializeOwned>(
    path: &Path,
    key: &[u8],
    pick: impl Fn(O) -> Option<T>,
) -> Option<T> {
    use serde::Deserialize;
    use std::io::{Read, Seek};
    let mut f = std::fs::File::open(path).ok()?;
    let mut buf = vec![0u8; 1 << 20];
    let (mut kept, mut start, mut pretty, mut last) = (0usize, 0u64, None, None);
    loop {
        let n = f.read(&mut buf[kept..]).ok()?;
        let len = kept + n;
        let pretty = *pretty.get_or_insert_with(|| buf[..len].starts_with(b"{\n  \""));
        // the last occurrence, as the streaming reader keeps the last value
        if let Some(i) = memchr::memmem::rfind(&buf[..len], key) {
            last = Some(start + (i + key.len()) as u64);
        }
        if n == 0 || !pretty {
            break;
        }
        // the last bytes may begin the key
        let carry = (key.len() - 1).min(len);
        buf.copy_within(len - carry..len, 0);
        start += (len - carry) as u64;
        kept = carry;
    }
    if let Some(at) = last {
        f.seek(std::io::SeekFrom::Start(at)).ok()?;
        let mut de = serde_json::Deserializer::from_reader(std::io::BufReader::with_capacity(1 << 16, f));
        return Option::<T>::deserialize(&mut de).ok().flatten();
    }
    if pretty.unwrap_or(false) {
        return None;
    }
    f.seek(std::io::SeekFrom::Start(0)).ok()?;
    pick(serde_json::from_reader(std::io::BufReader::with_capacity(1 << 16, f)).ok()?)
}

/// [`restart`] from the text of a saved state; `file` names it in messages.
pub fn restart_str<D: Dim>(w: &mut World<D>, text: &str, file: &str) -> Result<(), InputError> {
    restart_from(w, Source::Text(text, file), false, None).map(|_| ())
}

/// The checks every restart file gets, whatever the dimension: errors name the
/// file, the line (the k-th occurrence of a key: the file is written one field per
/// line; the text is read only for an error's line) and the key.
struct StateChecks<'a> {
    src: Source<'a>,
    file: String,
    text: std::cell::OnceCell<String>,
}

impl<'a> StateChecks<'a> {
    fn new(src: Source<'a>) -> Self {
        StateChecks {
            file: src.name(),
            src,
            text: std::cell::OnceCell::new(),
        }
    }
    fn err(&self, line: Option<usize>, key: String, message: String) -> InputError {
        InputError {
            file: self.file.clone(),
            line,
            key,
            message,
        }
    }
    fn line_of(&self, key: &str, k: usize) -> Option<usize> {
        let text = self.text.get_or_init(|| self.src.text());
        let pat = format!("\"{key}\":");
        text.match_indices(&pat).nth(k).map(|(o, _)| crate::error::line_of(text, o))
    }
    /// The saved time is step × h and the scene has steps left; returns the time.
    fn time(&self, step: u64, time: f64, t: &crate::world::TimeSettings) -> Result<f64, InputError> {
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

#[cfg(test)]
mod tests {
    use super::nscdd_of;
    use crate::model::ContactKey;

    /// A 2 × 1 grid's state keeping contact (0, 1) in cell 1.
    const STATE: &str = r#"{"grid_of": [2, 1, 1], "by_model": false, "steps": 4,
        "grid": {"nx": 2, "ny": 1, "nz": 1, "origin": [0.0, 0.0, 0.0], "cell": [1.0, 1.0, 1.0]},
        "grid_empty": false, "kept": [[{"i": 0, "j": 1, "feature": 0}, 1]], "f_gamma": []}"#;

    fn read(name: &str, text: &str) -> Option<crate::dd::NscddState> {
        let dir = std::env::temp_dir().join(format!("nscdd_nscdd_of_{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join(name);
        std::fs::write(&path, text).unwrap();
        let s = nscdd_of(&path);
        let _ = std::fs::remove_file(&path);
        s
    }

    /// The `nscdd` part is found in a pretty state (also across the scan's 1 MiB
    /// chunks), in a compact one (parsed whole), the last of two keys as the
    /// streaming reader keeps it; none when absent. Its rank part gives every
    /// contact to one rank of two: the kept one by its subdomain, another by its cell,
    /// by geometry and by model alike.
    #[test]
    fn the_nscdd_part_alone_and_its_rank_parts() {
        let pretty = |before: &str, value: &str| format!("{{\n  \"step\": 3,{before}\n  \"nscdd\": {value}\n}}\n");
        assert!(read("a.json", &pretty("", STATE)).is_some());
        assert!(read("b.json", &pretty(&format!("\n  \"nscdd\": {STATE},"), "null")).is_none());
        assert!(read("c.json", &pretty("\n  \"nscdd\": null,", STATE)).is_some());
        assert!(read("d.json", "{\n  \"step\": 3\n}\n").is_none());
        assert!(read("e.json", &format!("{{\"step\":3,\"nscdd\":{STATE}}}")).is_some());
        // the key across the first chunk's end (its newline 5 bytes before 1 MiB)
        let pad = "x".repeat((1 << 20) - 19);
        let text = format!("{{\n  \"pad\": \"{pad}\",\n  \"nscdd\": {STATE}\n}}\n");
        assert_eq!(text.find("\n  \"nscdd\"").unwrap(), (1 << 20) - 5);
        let state = read("f.json", &text).expect("the key across two chunks");
        let key = |i, j| ContactKey { i, j, feature: 0 };
        let mut parts: Vec<_> = (0..2).map(|me| state.rank_part([2, 1, 1], false, 2, me).expect("a part")).collect();
        let mut keeps = |k: ContactKey, p: [f64; 3]| parts.iter_mut().map(|r| r.keeps(k, p)).collect::<Vec<bool>>();
        let (kept, cell0, cell1) = (
            keeps(key(0, 1), [0.5, 0.5, 0.0]),
            keeps(key(2, 3), [0.5, 0.5, 0.0]),
            keeps(key(2, 3), [1.5, 0.5, 0.0]),
        );
        for (what, k) in [("kept", &kept), ("cell 0", &cell0), ("cell 1", &cell1)] {
            assert_eq!(k.iter().filter(|&&x| x).count(), 1, "{what}: {k:?}");
        }
        // kept in cell 1 although its point lies in cell 0: with the contacts of cell 1
        assert_eq!(kept, cell1);
        assert_ne!(cell0, cell1);
        // by model: the same parts (a family's subdomain of a cell goes with the
        // cell to its rank); a state by geometry read by model, or the reverse, is
        // of another decomposition
        let bm = read("g.json", &pretty("", &STATE.replace("\"by_model\": false", "\"by_model\": true"))).expect("by model");
        let mut by_model: Vec<_> = (0..2).map(|me| bm.rank_part([2, 1, 1], true, 2, me).expect("a part")).collect();
        let probes = [
            (key(0, 1), [0.5, 0.5, 0.0]),
            (key(2, 3), [0.5, 0.5, 0.0]),
            (key(2, 3), [1.5, 0.5, 0.0]),
        ];
        for (k, p) in probes {
            let by_cells: Vec<bool> = parts.iter_mut().map(|r| r.keeps(k, p)).collect();
            let by_models: Vec<bool> = by_model.iter_mut().map(|r| r.keeps(k, p)).collect();
            assert_eq!(by_cells, by_models, "{k:?} at {p:?}");
        }
        assert!(state.rank_part([2, 1, 1], true, 2, 0).is_none());
        assert!(bm.rank_part([2, 1, 1], false, 2, 0).is_none());
        // one rank, another decomposition, more ranks than cells: every contact read
        assert!(state.rank_part([2, 1, 1], false, 1, 0).is_none());
        assert!(state.rank_part([1, 2, 1], false, 2, 0).is_none());
        assert!(state.rank_part([2, 1, 1], false, 4, 0).is_none());
    }
}
