//! Restart of a 3D world from its saved state (`final.json` / `checkpoint.json` of a
//! 3D run): positions, quaternions, velocities, the contacts' keys, impulses and bonds, the
//! step, the time and the box height. The same rules as in 2D
//! ([`super::restart`]): the scene that wrote the state, the same step h; a
//! continued one-domain run is bitwise the uninterrupted one.

use super::restart::StateChecks;
use crate::dim::joint::Joint;
use crate::error::InputError;
use crate::rigid2d::contacts::ContactKey;
use crate::rigid3d::contacts::Frame3;
use crate::rigid3d::Contacts3;
use crate::world::World3;
use serde::Deserialize;
use std::path::Path;

#[derive(Deserialize)]
struct SavedBody {
    id: u32,
    kind: String,
    position: [f64; 3],
    quaternion: [f64; 4],
    velocity: [f64; 6],
}

#[derive(Deserialize)]
struct SavedContact {
    bodies: [u32; 2],
    feature: u32,
    point: [f64; 3],
    normal: [f64; 3],
    r: [f64; 3],
    gap: f64,
    #[serde(default)]
    bonded: bool,
}

#[derive(Deserialize)]
struct Saved {
    dimension: u8,
    step: u64,
    time: f64,
    #[serde(default)]
    box_h0: Option<f64>,
    bodies: Vec<SavedBody>,
    contacts: Vec<SavedContact>,
}

/// Loads the saved 3D state in `path` into `w`.
pub fn restart3(w: &mut World3, path: &Path) -> Result<(), InputError> {
    let file = path.display().to_string();
    let text = std::fs::read_to_string(path).map_err(|e| InputError {
        file: file.clone(),
        line: None,
        key: String::new(),
        message: format!("cannot read the restart file: {e}"),
    })?;
    restart3_str(w, &text, &file)
}

/// [`restart3`] from the text of a saved state; `file` names it in messages.
pub fn restart3_str(w: &mut World3, text: &str, file: &str) -> Result<(), InputError> {
    let ck = StateChecks { text, file };
    let saved: Saved = serde_json::from_str(text).map_err(|e| {
        ck.err(
            Some(e.line()),
            String::new(),
            format!("not a saved 3D state (final.json of a 3D run): {e}"),
        )
    })?;
    if saved.dimension != 3 {
        return Err(ck.err(
            ck.line_of("dimension", 0),
            "dimension".into(),
            format!("the state is {}D, the scene 3D", saved.dimension),
        ));
    }
    let nb = w.bodies.len();
    let finite = |sb: &SavedBody| sb.position.iter().chain(&sb.velocity).chain(&sb.quaternion).all(|x| x.is_finite());
    ck.bodies(
        saved.bodies.iter().map(|sb| (sb.id, sb.kind.as_str(), finite(sb))),
        |k| w.kind_name(k),
        nb,
    )?;
    let expected = ck.time(saved.step, saved.time, &w.time)?;
    let mut c = Contacts3::default();
    for (a, sc) in saved.contacts.iter().enumerate() {
        let [i, j] = sc.bodies;
        if i as usize >= nb || j as usize >= nb {
            return Err(ck.err(
                ck.line_of("bodies", a + 1),
                format!("contacts[{a}].bodies"),
                format!("body ids must be below {nb}"),
            ));
        }
        let (t1, t2) = crate::rigid3d::contacts::tangents(sc.normal);
        c.bodies.push([i, j]);
        c.frame.push(Frame3 {
            basis: [sc.normal, t1, t2],
            ..Default::default()
        });
        c.block.push(Default::default());
        c.target.push(Default::default());
        c.r.push(sc.r);
        c.u_free.push([0.0; 3]);
        c.gap.push(sc.gap);
        c.point.push(sc.point);
        c.key.push(ContactKey { i, j, feature: sc.feature });
        c.joint.push(if sc.bonded { Joint::RESTORED } else { Joint::default() });
    }
    let b = &mut w.bodies;
    for (k, sb) in saved.bodies.iter().enumerate() {
        b.pos[k] = sb.position;
        b.rot[k] = sb.quaternion;
        b.vel[k] = sb.velocity;
        b.refresh_inverse(k);
    }
    w.contacts = c;
    w.step = saved.step;
    w.t = expected;
    w.box_h0 = saved.box_h0;
    Ok(())
}
