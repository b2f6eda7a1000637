//! The first of a restart's two passes over the saved state when an MPI rank loads
//! the scene in part ([`super::part::restart_on`], issue 20): which bodies the
//! first step after the restart keeps on this rank, decided before any body is
//! built. A body is kept when its box at the saved position and orientation, grown
//! by the alert distance, meets one of the rank's cells of the saved grid (the
//! halo's own test, [`crate::dd::first_part::Halo`]) or the halo of the body
//! families' boxes (the bodies their first step may read), when it is one every
//! rank steps, or when it is a body of a contact the rank keeps
//! ([`crate::dd::RestartPart`]). The second pass is the restart itself, into the
//! part world ([`super::restart`]).
//!
//! The scan checks what the second pass would check of a body it does not hold
//! (its id, its kind, a finite state, the bodies' count): a state that fails any
//! check is restarted whole instead, so that its error is reported as in one
//! process. It never holds the file's text or a list of its bodies: 1 byte a body.
//! (The two passes read the file twice: a state replaced between them is not told
//! apart; the run's outputs never replace the state it restarts from.)
//!
//! ```text
//! let halo = part.halo(D::N, alert * 1.01);
//! let input = ScanInput { shapes: &survey_shapes, stores: &world.shapes, everywhere, halo: &halo, near: &near };
//! let kept = scan::<D>(path, &input, &mut part);
//! // kept.keep[g]: build body g; kept.digest: every saved body's bits
//! ```

use super::restart_stream::{body_error, SavedBody};
use crate::dd::first_part::Halo;
use crate::dd::RestartPart;
use crate::dim::{Coords, Dim};
use crate::model::{ContactKey, ShapeRef};
use crate::shape::ShapeStore;
use serde::de::{DeserializeSeed, Error as _, IgnoredAny, MapAccess, SeqAccess, Visitor};
use std::fmt;
use std::hash::Hasher;
use std::path::Path;

/// What the scan reads of a saved contact (the rest skipped, not converted: the
/// restart reads it).
#[derive(serde::Deserialize)]
#[serde(bound = "")]
struct ContactAt<D: Dim> {
    bodies: [u32; 2],
    #[serde(default)]
    feature: Option<u32>,
    point: D::Point,
}

/// What a rank builds of a scene restarted in part.
pub(super) struct Scanned {
    /// Whether to build each body (by global id).
    pub keep: Vec<bool>,
    /// A digest of every saved body's id and state (the same on every rank).
    pub digest: u64,
}

/// What the scan reads of the scene: every body's shape (by global id), the shape
/// stores, the bodies every rank steps (ascending) and the rank's halo.
pub(super) struct ScanInput<'a, D: Dim> {
    pub shapes: &'a [ShapeRef],
    pub stores: &'a [Box<dyn ShapeStore<D>>],
    pub everywhere: &'a [u32],
    pub halo: &'a Halo,
    /// Around the body families' boxes ([`crate::family::FamilyKind::load_boxes`]
    /// given the saved state): the bodies their first step may read.
    pub near: &'a Halo,
}

/// The scan of the state at `path` (module docs); `None` when the state cannot be
/// read in part: a check fails or the file is not a saved state of this scene (the
/// whole restart then reports why).
/// `part` decides the contacts as the restart's pass will (no copy of its kept
/// contacts; [`RestartPart::rewind`] after).
pub(super) fn scan<D: Dim>(path: &Path, scene: &ScanInput<'_, D>, part: &mut RestartPart) -> Option<Scanned> {
    let f = std::fs::File::open(path).ok()?;
    let mut de = serde_json::Deserializer::from_reader(std::io::BufReader::with_capacity(1 << 16, f));
    let mut s = Scan {
        scene,
        part,
        keep: Vec::new(),
        hash: Default::default(),
        dimension: false,
        bodies: false,
        contacts: false,
    };
    let read = DeserializeSeed::deserialize(&mut s, &mut de).and_then(|()| de.end());
    s.part.rewind();
    read.ok()?;
    // (a state without `dimension` is 2D's)
    if !(s.bodies && s.contacts && (s.dimension || D::N == 2)) {
        return None;
    }
    Some(Scanned {
        keep: s.keep,
        digest: s.hash.finish(),
    })
}

/// The scan's state: the bodies marked so far (by global id) and the digest.
struct Scan<'s, 'a, D: Dim> {
    scene: &'s ScanInput<'a, D>,
    part: &'s mut RestartPart,
    keep: Vec<bool>,
    hash: std::collections::hash_map::DefaultHasher,
    dimension: bool,
    bodies: bool,
    contacts: bool,
}

impl<'de, D: Dim> DeserializeSeed<'de> for &mut Scan<'_, '_, D> {
    type Value = ();
    fn deserialize<De: serde::Deserializer<'de>>(self, de: De) -> Result<(), De::Error> {
        de.deserialize_map(self)
    }
}

impl<'de, D: Dim> Visitor<'de> for &mut Scan<'_, '_, D> {
    type Value = ();
    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str("a saved state (a JSON object)")
    }
    fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<(), A::Error> {
        while let Some(key) = map.next_key::<String>()? {
            match key.as_str() {
                "dimension" => {
                    let d: u64 = map.next_value()?;
                    if d != D::N as u64 {
                        return Err(A::Error::custom("another dimension"));
                    }
                    self.dimension = true;
                }
                "bodies" if !self.bodies => {
                    map.next_value_seed(Bodies(&mut *self))?;
                    self.bodies = true;
                }
                "contacts" if self.bodies && !self.contacts => {
                    map.next_value_seed(Contacts(&mut *self))?;
                    self.contacts = true;
                }
                // (bodies or contacts given twice, contacts before bodies: read whole)
                "bodies" | "contacts" => return Err(A::Error::custom("not in part")),
                _ => {
                    map.next_value::<IgnoredAny>()?;
                }
            }
        }
        Ok(())
    }
}

/// The saved bodies: each checked as the restart checks it, hashed, and marked
/// when its box meets the halo or every rank steps it.
struct Bodies<'a, 's, 'b, D: Dim>(&'a mut Scan<'s, 'b, D>);

impl<'de, D: Dim> DeserializeSeed<'de> for Bodies<'_, '_, '_, D> {
    type Value = ();
    fn deserialize<De: serde::Deserializer<'de>>(self, de: De) -> Result<(), De::Error> {
        de.deserialize_seq(self)
    }
}

impl<'de, D: Dim> Visitor<'de> for Bodies<'_, '_, '_, D> {
    type Value = ();
    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str("a list of saved bodies")
    }
    fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<(), A::Error> {
        let s = self.0;
        let sc = s.scene;
        let n = sc.shapes.len();
        s.keep = vec![false; n];
        sc.everywhere.iter().for_each(|&g| s.keep[g as usize] = true);
        let mut k = 0usize;
        while let Some(sb) = seq.next_element::<SavedBody<D>>()? {
            let Some(shape) = sc.shapes.get(k) else {
                return Err(A::Error::custom("more bodies than the scene"));
            };
            let store = &sc.stores[shape.kind as usize];
            if body_error(k, store.kind(), &sb).is_some() {
                return Err(A::Error::custom("a body the restart refuses"));
            }
            let rot = sb.rot();
            let values = sb.position.as_ref().iter().chain(rot.coords()).chain(sb.velocity.as_ref());
            s.hash.write_u32(sb.id);
            values.for_each(|x| s.hash.write_u64(x.to_bits()));
            // the box the first step computes (the world's orientation as read)
            let bx = store.aabb(shape.index, sb.position, rot).corners3();
            s.keep[k] |= sc.halo.meets(&bx) || sc.near.meets(&bx);
            k += 1;
        }
        if k != n {
            return Err(A::Error::custom("fewer bodies than the scene"));
        }
        Ok(())
    }
}

/// The saved contacts: the bodies of those this rank keeps are marked.
struct Contacts<'a, 's, 'b, D: Dim>(&'a mut Scan<'s, 'b, D>);

impl<'de, D: Dim> DeserializeSeed<'de> for Contacts<'_, '_, '_, D> {
    type Value = ();
    fn deserialize<De: serde::Deserializer<'de>>(self, de: De) -> Result<(), De::Error> {
        de.deserialize_seq(self)
    }
}

impl<'de, D: Dim> Visitor<'de> for Contacts<'_, '_, '_, D> {
    type Value = ();
    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str("a list of saved contacts")
    }
    fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<(), A::Error> {
        let s = self.0;
        let n = s.keep.len();
        while let Some(sc) = seq.next_element::<ContactAt<D>>()? {
            let [i, j] = sc.bodies;
            if i as usize >= n || j as usize >= n {
                return Err(A::Error::custom("a body past the scene's"));
            }
            let key = ContactKey {
                i,
                j,
                feature: sc.feature.unwrap_or(0),
            };
            let mut p = [0.0; 3];
            p[..D::N].copy_from_slice(sc.point.as_ref());
            if s.part.keeps(key, p) {
                (s.keep[i as usize], s.keep[j as usize]) = (true, true);
            }
        }
        Ok(())
    }
}
