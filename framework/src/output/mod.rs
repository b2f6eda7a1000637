//! Run outputs: `history.csv` (one row per step), `final.json` (the last state) and
//! the VTK series (see [`vtk`]). Column and field names are listed in the README.

pub mod history;
pub mod out3;
pub mod vtk;

use crate::world::World2;
use serde::Serialize;

#[derive(Serialize)]
struct BodyOut<'a> {
    id: u32,
    #[serde(skip_serializing_if = "Option::is_none")]
    name: Option<&'a str>,
    kind: &'static str,
    material: &'a str,
    position: [f64; 2],
    rotation: f64,
    velocity: [f64; 3],
    fixed: bool,
    shape: serde_json::Value,
}

#[derive(Serialize)]
struct ContactOut {
    bodies: [u32; 2],
    feature: u32,
    point: [f64; 2],
    normal: [f64; 2],
    r_n: f64,
    r_t: f64,
    gap: f64,
}

#[derive(Serialize)]
struct FinalOut<'a> {
    step: u64,
    time: f64,
    #[serde(skip_serializing_if = "Option::is_none")]
    box_h0: Option<f64>,
    bodies: Vec<BodyOut<'a>>,
    contacts: Vec<ContactOut>,
}

/// The state as `final.json`: step, time, `box_h0` (the box height ε1 is measured
/// from, once set), bodies (id, name, kind, material, position, rotation, velocity,
/// fixed, shape) and contacts (bodies [candidate, antagonist], feature, point, normal
/// from antagonist to candidate, impulses r_n, r_t in N·s, gap in m). It is also a
/// restart file ([`crate::scene::restart`]).
pub fn final_json(w: &World2) -> String {
    let b = &w.bodies;
    let bodies = (0..b.len())
        .map(|k| {
            let s = b.shape[k];
            BodyOut {
                id: k as u32,
                name: w.names[k].as_deref(),
                kind: w.kind_name(k),
                material: &w.materials[b.material[k] as usize].name,
                position: b.pos[k],
                rotation: b.rot[k],
                velocity: b.vel[k],
                fixed: !b.movable(k),
                shape: w.shapes[s.kind as usize].describe(s.index),
            }
        })
        .collect();
    let c = &w.contacts;
    let contacts = (0..c.len())
        .map(|a| ContactOut {
            bodies: c.bodies[a],
            feature: c.key[a].feature,
            point: c.point[a],
            normal: c.frame[a].n,
            r_n: c.r[a][0],
            r_t: c.r[a][1],
            gap: c.gap[a],
        })
        .collect();
    let mut s = serde_json::to_string_pretty(&FinalOut {
        step: w.step,
        time: w.t,
        box_h0: w.box_h0,
        bodies,
        contacts,
    })
    .expect("plain data serializes");
    s.push('\n');
    s
}
