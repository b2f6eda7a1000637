//! Run outputs: `history.csv` (one row per step), `final.json` (the last state) and
//! the VTK series (see [`vtk`]). Column and field names are listed in the README.

pub mod history;
pub mod vtk;
pub mod vtk_xml;

/// Writes a file atomically: `write` fills a temporary file beside `path` (its name
/// keeps the extension: `.name.part.ext`), renamed onto `path` once complete, so
/// that a run killed at any moment leaves either the previous file or the new one,
/// never a part of it.
pub fn write_atomic(path: &std::path::Path, write: impl FnOnce(&std::path::Path) -> std::io::Result<()>) -> std::io::Result<()> {
    let name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    let tmp_name = match name.rsplit_once('.') {
        Some((stem, ext)) => format!(".{stem}.part.{ext}"),
        None => format!(".{name}.part"),
    };
    let tmp = path.with_file_name(tmp_name);
    write(&tmp)?;
    std::fs::rename(&tmp, path)
}

use crate::dim::{Dim, Vector};
use crate::model::ShapeRef;
use crate::world::World;
use serde::Serialize;
use std::cell::RefCell;

/// Writes extra outputs every `output.every` steps (`[output] writers = [...]`).
pub trait Writer<D: Dim>: Send {
    fn write(&mut self, world: &World<D>, dir: &std::path::Path, frame: u32) -> std::io::Result<()>;
    /// A frame of a decomposed (NSCDD) run, with the subdomains of the bodies and
    /// contacts; by default the plain frame.
    fn write_dd(&mut self, world: &World<D>, _dd: &crate::dd::DdView, dir: &std::path::Path, frame: u32) -> std::io::Result<()> {
        self.write(world, dir, frame)
    }
    /// Called once at the end of the run.
    fn finish(&mut self, _dir: &std::path::Path) -> std::io::Result<()> {
        Ok(())
    }
}

#[derive(Serialize)]
#[serde(bound = "")]
struct BodyOut<'a, D: Dim> {
    id: u32,
    #[serde(skip_serializing_if = "Option::is_none")]
    name: Option<&'a str>,
    kind: &'static str,
    material: &'a str,
    position: D::Point,
    /// The angle in 2D, the rotation vector (axis × angle) in 3D.
    rotation: D::RotVec,
    /// 3D: the unit quaternion (w, x, y, z), exact for a restart.
    #[serde(skip_serializing_if = "Option::is_none")]
    quaternion: Option<D::Rot>,
    velocity: D::Twist,
    fixed: bool,
    shape: serde_json::Value,
}

impl<'a, D: Dim> BodyOut<'a, D> {
    /// Body `g` of `w`'s scene from its moving state, shape, material and whether
    /// it is fixed (its name given where the world holds it).
    fn new(w: &'a World<D>, g: u32, (pos, rot, vel): (D::Point, D::Rot, D::Twist), sh: ShapeRef, (material, fixed): (u16, bool)) -> Self {
        BodyOut {
            id: g,
            name: None,
            kind: w.shapes[sh.kind as usize].kind(),
            material: &w.materials[material as usize].name,
            position: pos,
            rotation: D::rot_to_vec(&rot),
            quaternion: (D::N == 3).then_some(rot),
            velocity: vel,
            fixed,
            shape: w.shapes[sh.kind as usize].describe(sh.index),
        }
    }
}

#[derive(Serialize)]
#[serde(bound = "")]
struct ContactOut<D: Dim> {
    bodies: [u32; 2],
    feature: u32,
    point: D::Point,
    normal: D::Point,
    /// The impulse in the contact frame, normal first (N·s).
    r: D::Local,
    /// The impulse on the candidate body in world axes (N·s).
    impulse: D::Point,
    gap: f64,
    /// An intact bonded joint (law `mohr_coulomb`).
    #[serde(skip_serializing_if = "std::ops::Not::not")]
    bonded: bool,
}

#[derive(Serialize)]
#[serde(bound = "")]
struct FinalOut<'a, 'p, D: Dim, N: Serialize> {
    dimension: u8,
    step: u64,
    time: f64,
    #[serde(skip_serializing_if = "Option::is_none")]
    box_h0: Option<f64>,
    bodies: BodiesOut<'a, 'p, D>,
    contacts: ContactsOut<'a, 'p, D>,
    /// The body families' states, by section ([`crate::family::SceneFamily::save_state`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    families: Option<&'a serde_json::Map<String, serde_json::Value>>,
    /// The NSCDD solver's state ([`crate::dd::NscddOf::save_state`], or on ranks
    /// [`crate::dd::NscddOf::state_on_ranks`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    nscdd: Option<&'a N>,
}

/// Records pulled one at a time, ascending by key (rank 0's merge of every rank's
/// records, [`crate::dd::rank_merge`]).
pub use crate::dd::rank_merge::Pull;

/// The bodies of `final.json`, each made as it is written (no list of them held):
/// the world's, and the pulled ones it does not hold (other processes' bodies,
/// `[g, output record…]`, [`World::output_record`]).
struct BodiesOut<'a, 'p, D: Dim>(&'a World<D>, RefCell<Option<Pull<'p>>>);

impl<D: Dim> Serialize for BodiesOut<'_, '_, D> {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        use serde::ser::SerializeSeq as _;
        let (w, b) = (self.0, &self.0.bodies);
        let held = (0..b.len()).map(|k| {
            let g = w.ids.global(k as u32);
            let moving = (b.pos[k], b.rot[k], b.vel[k]);
            let body = BodyOut::new(w, g, moving, b.shape[k], (b.material[k], w.fixed[k]));
            (
                g,
                BodyOut {
                    name: w.names[k].as_deref(),
                    ..body
                },
            )
        });
        let Some(pull) = self.1.borrow_mut().take() else {
            return s.collect_seq(held.map(|(_, t)| t));
        };
        // the others, by id (a body not held is neither named nor fixed: those every
        // process holds), each once
        let (mut rec, mut last, received) = (Vec::new(), None, std::cell::Cell::new(0usize));
        let others = std::iter::from_fn(|| loop {
            if !pull(&mut rec) {
                return None;
            }
            let g = rec[0] as u32;
            if w.ids.slot(g).is_some() || last == Some(g) {
                continue;
            }
            last = Some(g);
            received.set(received.get() + 1);
            let (moving, sh, material) = crate::world::held::read_output::<D>(&rec[1..]);
            return Some((g, BodyOut::new(w, g, moving, sh, (material, false))));
        });
        let mut seq = s.serialize_seq(None)?;
        for body in merge_by_id(held, others) {
            seq.serialize_element(&body)?;
        }
        // every body once: a body neither held nor sent would be lost from the file
        let n = w.ids.n_global(b.len());
        if b.len() + received.get() != n {
            use serde::ser::Error as _;
            let msg = format!("internal error: {} bodies held and {} received of {n}", b.len(), received.get());
            return Err(S::Error::custom(msg));
        }
        seq.end()
    }
}

/// The contacts of `final.json` in key order (candidate, antagonist, feature), the
/// same list whichever process held which contact: the world's, or the pulled
/// records ([`contact_records`] of every process, merged by key).
enum ContactsOut<'a, 'p, D: Dim> {
    World(&'a World<D>, Vec<u32>),
    Pulled(RefCell<Option<Pull<'p>>>),
}

impl<D: Dim> Serialize for ContactsOut<'_, '_, D> {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        let mut rec = Vec::new();
        match self {
            ContactsOut::World(w, order) => s.collect_seq(order.iter().map(|&a| {
                rec.clear();
                contact_records(w, std::iter::once(a as usize), &mut rec);
                contact_out::<D>(&rec)
            })),
            ContactsOut::Pulled(pull) => {
                let mut pull = pull.borrow_mut().take();
                s.collect_seq(std::iter::from_fn(|| {
                    let pull = pull.as_mut()?;
                    pull(&mut rec).then(|| contact_out::<D>(&rec))
                }))
            }
        }
    }
}

/// A contact of `final.json` from its record ([`contact_records`]).
fn contact_out<D: Dim>(x: &[f64]) -> ContactOut<D> {
    let n = D::N;
    let v = |k: usize| &x[3 + k * n..3 + (k + 1) * n];
    ContactOut::<D> {
        bodies: [x[0] as u32, x[1] as u32],
        feature: x[2] as u32,
        point: D::Point::from_fn(|d| v(0)[d]),
        normal: D::Point::from_fn(|d| v(1)[d]),
        r: D::Local::from_fn(|d| v(2)[d]),
        impulse: D::Point::from_fn(|d| v(3)[d]),
        gap: x[3 + 4 * n],
        bonded: x[4 + 4 * n] != 0.0,
    }
}

/// Two sequences ascending in id merged into one.
fn merge_by_id<T>(a: impl Iterator<Item = (u32, T)>, b: impl Iterator<Item = (u32, T)>) -> impl Iterator<Item = T> {
    let (mut a, mut b) = (a.peekable(), b.peekable());
    std::iter::from_fn(move || match (a.peek(), b.peek()) {
        (Some(x), Some(y)) if y.0 < x.0 => b.next(),
        (Some(_), _) => a.next(),
        (None, _) => b.next(),
    })
    .map(|(_, t)| t)
}

/// The state as `final.json`: the dimension, step, time, `box_h0` (the box height
/// ε1 is measured from, once set), bodies (id, name, kind, material, position,
/// rotation (3D: a rotation vector, and the quaternion), velocity (v, ω), fixed,
/// shape) and contacts (bodies [candidate, antagonist], feature, point, normal
/// from antagonist to candidate, the impulse `r` in the contact frame and
/// `impulse` in world axes (N·s), gap (m), `bonded` for an intact joint). It is
/// also a restart file ([`crate::scene::restart`]).
pub fn final_json<D: Dim>(w: &World<D>) -> String {
    final_json_of(w, None, None::<&()>)
}

/// Values per contact of [`contact_records`].
pub const fn contact_record_len(n: usize) -> usize {
    5 + 4 * n
}

/// The `final.json` fields of the contacts `which` of `w`, as numbers (bodies,
/// feature, point, normal, r, impulse, gap, bond): what a process sends the one
/// that writes the file.
pub fn contact_records<D: Dim>(w: &World<D>, which: impl Iterator<Item = usize>, out: &mut Vec<f64>) {
    let c = &w.contacts;
    for a in which {
        // (global ids: the key's)
        let k = c.key[a];
        out.extend([f64::from(k.i), f64::from(k.j), f64::from(k.feature)]);
        out.extend_from_slice(c.point[a].as_ref());
        out.extend_from_slice(D::normal(&c.frame[a]).as_ref());
        out.extend_from_slice(c.r[a].as_ref());
        out.extend_from_slice(c.world_impulse(a).as_ref());
        out.extend([c.gap[a], c.joint[a].bonded() as u8 as f64]);
    }
}

/// The world's contacts in key order (candidate, antagonist, feature): the order of
/// `final.json`'s contacts, whichever process held which.
pub fn contacts_in_key_order<D: Dim>(w: &World<D>) -> Vec<u32> {
    let mut order: Vec<u32> = (0..w.contacts.len() as u32).collect();
    order.sort_unstable_by_key(|&a| w.contacts.key[a as usize]);
    order
}

/// [`final_json`] with the body families' states under `families` (by section) and
/// the NSCDD solver's under `nscdd`: [`write_final_json`] as text.
pub fn final_json_of<D: Dim, N: Serialize>(
    w: &World<D>,
    families: Option<&serde_json::Map<String, serde_json::Value>>,
    nscdd: Option<&N>,
) -> String {
    let mut out = Vec::new();
    write_final_json(&mut out, w, families, nscdd, (None, None)).expect("writing to memory");
    String::from_utf8(out).expect("serde_json writes UTF-8")
}

/// Writes [`final_json_of`] to `out` as it is made: no copy of the state (a 55 000-
/// sphere state is ≈ 140 MB of text) is held in memory. `contacts`: every process's
/// contact records ([`contact_records`]) pulled in key order, instead of the world's
/// contacts; `bodies`: other processes' bodies' records (`[g, output record…]`,
/// [`World::output_record`]) pulled in id order, written beside the world's.
pub fn write_final_json<'p, D: Dim, N: Serialize>(
    out: impl std::io::Write,
    w: &World<D>,
    families: Option<&serde_json::Map<String, serde_json::Value>>,
    nscdd: Option<&N>,
    (contacts, bodies): (Option<Pull<'p>>, Option<Pull<'p>>),
) -> std::io::Result<()> {
    let contacts = match contacts {
        Some(pull) => ContactsOut::Pulled(RefCell::new(Some(pull))),
        None => ContactsOut::World(w, contacts_in_key_order(w)),
    };
    use std::io::Write as _;
    let mut out = std::io::BufWriter::with_capacity(1 << 16, out);
    let state = FinalOut {
        dimension: D::N as u8,
        step: w.step,
        time: w.t,
        box_h0: w.box_h0,
        bodies: BodiesOut(w, RefCell::new(bodies)),
        contacts,
        families,
        nscdd,
    };
    serde_json::to_writer_pretty(&mut out, &state).map_err(std::io::Error::from)?;
    out.write_all(b"\n")?;
    out.flush()
}
