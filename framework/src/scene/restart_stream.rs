//! A saved state read as a stream ([`super::restart`]): one pass over the file, each
//! body written into the world as it is read and each contact into the world's
//! contact list, so that neither the file's text nor a list of its bodies is ever
//! held whole (a 55 000-sphere state is a 60 MB file, and every MPI rank reads it).
//! A check that fails names its key; its line is looked up in the text only then.

use crate::dim::joint::Joint;
use crate::dim::{Dim, Vector};
use crate::model::{ContactKey, Contacts};
use crate::world::World;
use serde::de::{DeserializeSeed, Error as _, IgnoredAny, MapAccess, SeqAccess, Visitor};
use serde::Deserialize;
use std::fmt;

#[derive(Deserialize)]
#[serde(bound = "")]
pub(super) struct SavedBody<D: Dim> {
    pub id: u32,
    pub kind: String,
    pub position: D::Point,
    /// The angle in 2D, the rotation vector in 3D.
    rotation: D::RotVec,
    /// 3D: the exact orientation (the rotation vector is for reading).
    #[serde(default)]
    quaternion: Option<D::Rot>,
    pub velocity: D::Twist,
}

impl<D: Dim> SavedBody<D> {
    /// The saved orientation: the quaternion where given (3D), else the rotation.
    pub fn rot(&self) -> D::Rot {
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

/// A check that failed while reading: its key, its message, and the k-th
/// occurrence of which key holds its line.
pub(super) struct Failed {
    pub key: String,
    pub message: String,
    pub at: Option<(&'static str, usize)>,
}

/// What a saved state holds besides the bodies (written into the world as read).
pub(super) struct Streamed<D: Dim> {
    pub step: Option<u64>,
    pub time: Option<f64>,
    pub box_h0: Option<f64>,
    /// The number of saved bodies (those past the scene's are skipped).
    pub bodies: Option<usize>,
    /// The contacts (their frames set by [`Streamed::frames`]) and their normals.
    pub contacts: Option<(Contacts<D>, Vec<D::Point>)>,
    pub nscdd: Option<crate::dd::NscddState>,
    pub families: Option<serde_json::Map<String, serde_json::Value>>,
}

impl<D: Dim> Streamed<D> {
    /// The contacts' frames at the bodies' saved positions.
    pub fn frames(c: &mut Contacts<D>, normals: &[D::Point], pos: &[D::Point]) {
        for (a, n) in normals.iter().enumerate() {
            let [i, j] = c.bodies[a];
            c.frame[a] = D::frame(&c.point[a], n, &pos[i as usize], &pos[j as usize]);
        }
    }
}

/// Reads a saved state (a JSON object) into `w` and the returned parts; `parts`:
/// whether to read `nscdd` and `families` (else skipped). A failed check is left
/// in `failed` (the error returned is then a placeholder), and the dimension read
/// in `dimension` (an error of a state without it may be a 2D state's).
pub(super) struct StateSeed<'a, D: Dim> {
    pub w: &'a mut World<D>,
    pub parts: bool,
    pub failed: &'a mut Option<Failed>,
    pub dimension: &'a mut Option<u64>,
    /// On an MPI rank: the contacts it keeps (the others are read and checked,
    /// then left out).
    pub part: Option<&'a mut crate::dd::RestartPart>,
}

impl<'de, D: Dim> DeserializeSeed<'de> for StateSeed<'_, D> {
    type Value = Streamed<D>;
    fn deserialize<De: serde::Deserializer<'de>>(self, de: De) -> Result<Streamed<D>, De::Error> {
        de.deserialize_map(self)
    }
}

impl<'de, D: Dim> Visitor<'de> for StateSeed<'_, D> {
    type Value = Streamed<D>;
    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str("a saved state (a JSON object)")
    }
    fn visit_map<A: MapAccess<'de>>(mut self, mut map: A) -> Result<Streamed<D>, A::Error> {
        let mut s = Streamed {
            step: None,
            time: None,
            box_h0: None,
            bodies: None,
            contacts: None,
            nscdd: None,
            families: None,
        };
        while let Some(key) = map.next_key::<String>()? {
            match key.as_str() {
                "dimension" => {
                    let d: u64 = map.next_value()?;
                    if d != D::N as u64 {
                        let message = format!("the state is {d}D, the scene {}", D::NAME);
                        return Err(fail(self.failed, "dimension", message, ("dimension", 0)));
                    }
                    *self.dimension = Some(d);
                }
                "step" => s.step = Some(map.next_value()?),
                "time" => s.time = Some(map.next_value()?),
                "box_h0" => s.box_h0 = map.next_value()?,
                "bodies" => {
                    let seed = BodiesSeed {
                        w: &mut *self.w,
                        failed: &mut *self.failed,
                    };
                    s.bodies = Some(map.next_value_seed(seed)?);
                }
                "contacts" => {
                    let nb = self.w.ids.n_global(self.w.bodies.len());
                    s.contacts = Some(map.next_value_seed(ContactsSeed::<D> {
                        nb,
                        ids: &self.w.ids,
                        failed: &mut *self.failed,
                        part: self.part.as_deref_mut(),
                        dim: std::marker::PhantomData,
                    })?);
                }
                "nscdd" if self.parts => s.nscdd = map.next_value()?,
                "families" if self.parts => s.families = map.next_value()?,
                _ => {
                    map.next_value::<IgnoredAny>()?;
                }
            }
        }
        Ok(s)
    }
}

/// Records a failed check and returns the error that stops the reading.
fn fail<E: serde::de::Error>(failed: &mut Option<Failed>, key: impl Into<String>, message: String, at: (&'static str, usize)) -> E {
    *failed = Some(Failed {
        key: key.into(),
        message,
        at: Some(at),
    });
    E::custom("a failed check")
}

/// The saved bodies, each checked against the scene's (id in order, kind, finite
/// state) and written into the world; returns their count.
struct BodiesSeed<'a, D: Dim> {
    w: &'a mut World<D>,
    failed: &'a mut Option<Failed>,
}

impl<'de, D: Dim> DeserializeSeed<'de> for BodiesSeed<'_, D> {
    type Value = usize;
    fn deserialize<De: serde::Deserializer<'de>>(self, de: De) -> Result<usize, De::Error> {
        de.deserialize_seq(self)
    }
}

impl<'de, D: Dim> Visitor<'de> for BodiesSeed<'_, D> {
    type Value = usize;
    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str("a list of saved bodies")
    }
    fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<usize, A::Error> {
        // (a world holding part of the scene: the scan checked the bodies it lacks)
        let nb = self.w.ids.n_global(self.w.bodies.len());
        let (mut k, mut first) = (0usize, None::<Failed>);
        while k < nb && first.is_none() {
            let Some(sb) = seq.next_element::<SavedBody<D>>()? else { break };
            if let Some(slot) = self.w.ids.slot(k as u32).map(|s| s as usize) {
                first = body_error(k, self.w.kind_name(slot), &sb);
                if first.is_none() {
                    let b = &mut self.w.bodies;
                    (b.pos[slot], b.rot[slot], b.vel[slot]) = (sb.position, sb.rot(), sb.velocity);
                    b.refresh_inverse(slot);
                }
            }
            k += 1;
        }
        // (the rest counted: a state of another body count says so first)
        while seq.next_element::<IgnoredAny>()?.is_some() {
            k += 1;
        }
        if k != nb {
            let message = format!("the saved state has {k} bodies, the scene {nb}: a restart needs the scene that wrote it");
            return Err(fail(self.failed, "bodies", message, ("bodies", 0)));
        }
        if let Some(f) = first {
            *self.failed = Some(f);
            return Err(A::Error::custom("a failed check"));
        }
        Ok(k)
    }
}

/// What is wrong with saved body `k` against the scene's body of kind `kind`: its
/// id, its kind, a non-finite state (the restart's checks of a body, and the first
/// pass's of a restart loaded in part, [`super::restart_scan`]).
pub(super) fn body_error<D: Dim>(k: usize, kind: &str, sb: &SavedBody<D>) -> Option<Failed> {
    let failed = |key: String, message: String, at: (&'static str, usize)| {
        Some(Failed {
            key,
            message,
            at: Some(at),
        })
    };
    if sb.id as usize != k {
        return failed(format!("bodies[{k}].id"), format!("expected id {k}, found {}", sb.id), ("id", k));
    }
    if sb.kind != kind {
        let message = format!("the saved body is a `{}`, the scene's body {k} a `{kind}`", sb.kind);
        return failed(format!("bodies[{k}].kind"), message, ("kind", k));
    }
    let finite = sb.position.as_ref().iter().chain(sb.velocity.as_ref()).all(|x| x.is_finite());
    if !(finite && D::rot_finite(&sb.rot())) {
        return failed(format!("bodies[{k}]"), "non-finite state".into(), ("position", k));
    }
    None
}

/// The saved contacts (keys, impulses, bonds: the next step's warm start) as a
/// contact list, their frames left to [`Streamed::frames`], and their normals.
struct ContactsSeed<'a, D: Dim> {
    nb: usize,
    /// The world's slots of the contacts' bodies (global ids in their keys).
    ids: &'a crate::model::BodyIds,
    failed: &'a mut Option<Failed>,
    part: Option<&'a mut crate::dd::RestartPart>,
    dim: std::marker::PhantomData<D>,
}

impl<'de, D: Dim> DeserializeSeed<'de> for ContactsSeed<'_, D> {
    type Value = (Contacts<D>, Vec<D::Point>);
    fn deserialize<De: serde::Deserializer<'de>>(self, de: De) -> Result<Self::Value, De::Error> {
        de.deserialize_seq(self)
    }
}

impl<'de, D: Dim> Visitor<'de> for ContactsSeed<'_, D> {
    type Value = (Contacts<D>, Vec<D::Point>);
    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str("a list of saved contacts")
    }
    fn visit_seq<A: SeqAccess<'de>>(mut self, mut seq: A) -> Result<Self::Value, A::Error> {
        let (mut c, mut normals) = (Contacts::default(), Vec::new());
        let mut a = 0usize;
        while let Some(sc) = seq.next_element::<SavedContact<D>>()? {
            let [i, j] = sc.bodies;
            if i as usize >= self.nb || j as usize >= self.nb {
                let message = format!("body ids must be below {}", self.nb);
                return Err(fail(self.failed, format!("contacts[{a}].bodies"), message, ("bodies", a + 1)));
            }
            let r = match (sc.r, sc.r_n, sc.r_t) {
                (Some(r), _, _) => r,
                (None, Some(rn), Some(rt)) if D::N == 2 => D::Local::from_fn(|k| [rn, rt][k]),
                _ => {
                    return Err(fail(
                        self.failed,
                        format!("contacts[{a}].r"),
                        "missing impulse `r`".into(),
                        ("gap", a),
                    ))
                }
            };
            let key = ContactKey {
                i,
                j,
                feature: sc.feature.unwrap_or(0),
            };
            if let Some(part) = self.part.as_deref_mut() {
                // every contact read goes into the ranks' digest, kept or not
                part.saw([
                    u64::from(i),
                    u64::from(j),
                    u64::from(key.feature),
                    u64::from(sc.bonded),
                    sc.gap.to_bits(),
                ]);
                let values = r.as_ref().iter().chain(sc.point.as_ref()).chain(sc.normal.as_ref());
                part.saw(values.map(|v| v.to_bits()));
                let mut p = [0.0; 3];
                p[..D::N].copy_from_slice(sc.point.as_ref());
                if !part.keeps(key, p) {
                    a += 1;
                    continue;
                }
            }
            let (Some(si), Some(sj)) = (self.ids.slot(i), self.ids.slot(j)) else {
                // (a rank holds the bodies of the contacts it keeps: the scan's)
                let message = "the state changed while it was read".to_string();
                return Err(fail(self.failed, format!("contacts[{a}].bodies"), message, ("bodies", a + 1)));
            };
            c.bodies.push([si, sj]);
            c.frame.push(Default::default());
            c.block.push(Default::default());
            c.target.push(Default::default());
            c.r.push(r);
            c.u_free.push(D::Local::zero());
            c.gap.push(sc.gap);
            c.point.push(sc.point);
            c.key.push(key);
            c.joint.push(if sc.bonded { Joint::RESTORED } else { Joint::default() });
            normals.push(sc.normal);
            a += 1;
        }
        Ok((c, normals))
    }
}
