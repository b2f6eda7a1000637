//! Outputs of a 3D run: `history.csv`, `final.json` (also a restart file) and the
//! VTK frames (`vtk/bodies_*.vtp`: one point per body with `id`, `radius`,
//! `velocity`, `angular_velocity` (vectors), `material`; `vtk/walls_*.vtp`: planes
//! and boxes as polygons; `vtk/contacts_*.vtp`: a line per contact with `r_n`,
//! `r_t` = |r_t|, `f_n`, `gap`; `vtk/points_*.vtp`: a vertex per contact point
//! with the contact force on the candidate body as the vector `force` (impulse / h,
//! world axes), `f_n`, `gap` and `bonded` (1 for an intact mortar joint)), with the
//! series `bodies.pvd`, `walls.pvd`, `contacts.pvd`, `points.pvd`. Polyhedra and
//! other faceted shapes are drawn as their faces in `walls_*.vtp` (cell `id`: the
//! body).

use super::history::{solver_fields, SOLVER_COLUMNS};
use super::vtk::{cells, export, piece, VtkWriter};
use crate::engine::StepReport;
use crate::rigid3d::bodies::to_rotation_vector;
use crate::shape::Glyph3;
use crate::world::World3;
use serde::Serialize;
use std::io::Write;
use std::path::Path;
use vtkio::model::Attribute;

/// `history.csv` of a 3D run: the solver columns, `kinetic_energy`,
/// `potential_energy`; per named or driven body `_x, _y, _z, _fx, _fy, _fz` (contact
/// force resultant, N); with `[output] box3`: `solid_fraction`, `eps1` (along z),
/// `sigma_xx`, `sigma_yy`, `sigma_zz` (Pa, compression positive), `p`, `q`
/// (σ_zz − ½(σ_xx + σ_yy)), `q_over_p`, `z` (grain–grain coordination number),
/// `z_m` (loaded contacts per grain without the rattlers), and away from the walls
/// (inner box shrunk by 4 largest radii, [`World3::bulk_measures`]) `nu_bulk`,
/// `z_bulk`, `rattlers_bulk`; then the stage timings.
pub struct History3<W: Write> {
    out: W,
    tracked: Vec<(u32, String)>,
    has_box: bool,
    /// The NSCDD columns of 2D histories ([`super::history::DD_COLUMNS`]).
    dd: bool,
    /// Margin of the bulk measures: 4 × the largest grain radius.
    margin: f64,
}

impl<W: Write> History3<W> {
    pub fn new(out: W, w: &World3) -> std::io::Result<Self> {
        Self::with_columns(out, w, false)
    }

    /// With `dd`, the NSCDD columns follow the timings (as in 2D).
    pub fn with_columns(mut out: W, w: &World3, dd: bool) -> std::io::Result<Self> {
        let mut tracked = vec![];
        for b in 0..w.bodies.len() {
            let driven = w.drives.iter().any(|d| d.body as usize == b);
            match &w.names[b] {
                Some(n) => tracked.push((b as u32, n.clone())),
                None if driven => tracked.push((b as u32, format!("body{b}"))),
                None => {}
            }
        }
        let has_box = w.box_walls.is_some();
        let mut head = String::from(SOLVER_COLUMNS);
        for (_, n) in &tracked {
            for c in ["x", "y", "z", "fx", "fy", "fz"] {
                head.push_str(&format!(",{n}_{c}"));
            }
        }
        if has_box {
            head.push_str(",solid_fraction,eps1,sigma_xx,sigma_yy,sigma_zz,p,q,q_over_p,z,z_m,nu_bulk,z_bulk,rattlers_bulk");
        }
        head.push_str(",t_detect,t_delassus,t_nlgs,t_update,t_output");
        if dd {
            for c in super::history::DD_COLUMNS {
                head.push(',');
                head.push_str(c);
            }
        }
        writeln!(out, "{head}")?;
        let margin = 4.0 * w.max_grain_size();
        Ok(History3 {
            out,
            tracked,
            has_box,
            dd,
            margin,
        })
    }

    pub fn row(&mut self, w: &World3, r: &StepReport, t_output: f64) -> std::io::Result<()> {
        self.row_dd(w, r, None, t_output)
    }

    /// A row; `dd` fills the NSCDD columns.
    pub fn row_dd(&mut self, w: &World3, r: &StepReport, dd: Option<&crate::dd::DdStepReport>, t_output: f64) -> std::io::Result<()> {
        let (ek, ep) = w.energies();
        let mut s = solver_fields(w.step, w.t, w.bodies.len(), r, ek, ep);
        let h = w.time.h;
        for (b, _) in &self.tracked {
            let b = *b as usize;
            let (p, f) = (w.bodies.pos[b], w.reaction[b]);
            s.push_str(&format!(
                ",{:e},{:e},{:e},{:e},{:e},{:e}",
                p[0],
                p[1],
                p[2],
                f[0] / h,
                f[1] / h,
                f[2] / h
            ));
        }
        if self.has_box {
            let nu = w.solid_fraction().unwrap_or(f64::NAN);
            let h = w.box_extent().map_or(f64::NAN, |e| e.max[2] - e.min[2]);
            let eps1 = w.box_h0.map_or(0.0, |h0| (h0 - h) / h0);
            let sg = w.box_stresses().unwrap_or([f64::NAN; 3]);
            let p = (sg[0] + sg[1] + sg[2]) / 3.0;
            let q = sg[2] - 0.5 * (sg[0] + sg[1]);
            let (z, zm) = w.coordination();
            let (nb, zb, rb) = w.bulk_measures(self.margin).unwrap_or((f64::NAN, f64::NAN, f64::NAN));
            s.push_str(&format!(
                ",{nu:e},{eps1:e},{:e},{:e},{:e},{p:e},{q:e},{:e},{z:e},{zm:e},{nb:e},{zb:e},{rb:e}",
                sg[0],
                sg[1],
                sg[2],
                if p != 0.0 { q / p } else { 0.0 }
            ));
        }
        let tm = r.times;
        s.push_str(&format!(
            ",{:e},{:e},{:e},{:e},{:e}",
            tm.detect, tm.delassus, tm.nlgs, tm.update, t_output
        ));
        if self.dd {
            s.push_str(&super::history::dd_fields(dd));
        }
        writeln!(self.out, "{s}")
    }

    pub fn flush(&mut self) -> std::io::Result<()> {
        self.out.flush()
    }
}

#[derive(Serialize)]
struct BodyOut<'a> {
    id: u32,
    #[serde(skip_serializing_if = "Option::is_none")]
    name: Option<&'a str>,
    kind: &'static str,
    material: &'a str,
    position: [f64; 3],
    /// Rotation vector (axis × angle) of the orientation.
    rotation: [f64; 3],
    quaternion: [f64; 4],
    velocity: [f64; 6],
    fixed: bool,
    shape: serde_json::Value,
}

#[derive(Serialize)]
struct ContactOut {
    bodies: [u32; 2],
    feature: u32,
    point: [f64; 3],
    normal: [f64; 3],
    /// (r_n, r_t1, r_t2) in the contact frame (N·s).
    r: [f64; 3],
    /// The impulse in world axes (N·s).
    impulse: [f64; 3],
    gap: f64,
    /// An intact bonded joint (law `mohr_coulomb`).
    #[serde(skip_serializing_if = "std::ops::Not::not")]
    bonded: bool,
}

#[derive(Serialize)]
struct FinalOut<'a> {
    dimension: u8,
    step: u64,
    time: f64,
    #[serde(skip_serializing_if = "Option::is_none")]
    box_h0: Option<f64>,
    bodies: Vec<BodyOut<'a>>,
    contacts: Vec<ContactOut>,
}

/// The state of a 3D world as `final.json`.
pub fn final_json3(w: &World3) -> String {
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
                rotation: to_rotation_vector(b.rot[k]),
                quaternion: b.rot[k],
                velocity: b.vel[k],
                fixed: w.fixed[k],
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
            normal: c.frame[a].basis[0],
            r: c.r[a],
            impulse: c.world_impulse(a),
            gap: c.gap[a],
            bonded: c.joint[a].bonded(),
        })
        .collect();
    let mut s = serde_json::to_string_pretty(&FinalOut {
        dimension: 3,
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

/// One VTK frame of a 3D world.
pub fn write_vtk3(v: &mut VtkWriter, w: &World3, dir: &Path, frame: u32) -> std::io::Result<()> {
    let vdir = dir.join("vtk");
    std::fs::create_dir_all(&vdir)?;
    let b = &w.bodies;
    let n = b.len();
    let mut pts = Vec::with_capacity(3 * n);
    let (mut radius, mut vel, mut omega, mut id, mut mat) = (vec![], vec![], vec![], vec![], vec![]);
    let (mut wpts, mut wconn, mut woff, mut wid) = (vec![], vec![], vec![], vec![]);
    for k in 0..n {
        let s = b.shape[k];
        let store = &w.shapes[s.kind as usize];
        let glyph = store.glyph(s.index, b.pos[k], b.rot[k]);
        pts.extend_from_slice(&b.pos[k]);
        vel.extend_from_slice(&b.vel[k][..3]);
        omega.extend_from_slice(&b.vel[k][3..]);
        id.push(k as f64);
        mat.push(b.material[k] as f64);
        let faces = match glyph {
            Glyph3::Ball(r) => {
                radius.push(r);
                continue;
            }
            Glyph3::Faces(faces) => faces,
            Glyph3::Polygon(p) => vec![p],
            Glyph3::Segment(p, q, _) => vec![vec![p, q]],
        };
        {
            {
                radius.push(0.0);
                for f in faces {
                    for p in f {
                        wconn.push((wpts.len() / 3) as u64);
                        wpts.extend_from_slice(&p);
                    }
                    woff.push(wconn.len() as u64);
                    wid.push(k as f64);
                }
            }
        }
    }
    let verts = cells((0..n as u64).collect(), (1..=n as u64).collect());
    let point = vec![
        Attribute::scalars("id", 1).with_data(id),
        Attribute::scalars("radius", 1).with_data(radius),
        Attribute::vectors("velocity").with_data(vel),
        Attribute::vectors("angular_velocity").with_data(omega),
        Attribute::scalars("material", 1).with_data(mat),
    ];
    export(
        piece(pts, verts, None, None, point, vec![]),
        &vdir.join(format!("bodies_{frame:06}.vtp")),
    )?;
    let wcells = vec![Attribute::scalars("id", 1).with_data(wid)];
    export(
        piece(wpts, None, None, cells(wconn, woff), vec![], wcells),
        &vdir.join(format!("walls_{frame:06}.vtp")),
    )?;
    let c = &w.contacts;
    let m = c.len();
    let mut cpts = Vec::with_capacity(6 * m);
    let (mut rn, mut rt, mut fnn, mut gap) = (vec![], vec![], vec![], vec![]);
    for a in 0..m {
        let [i, j] = c.bodies[a];
        let pi = b.pos[i as usize];
        let pj = if b.movable(j as usize) && !w.fixed[j as usize] && w.shapes[b.shape[j as usize].kind as usize].is_grain() {
            b.pos[j as usize]
        } else {
            c.point[a]
        };
        cpts.extend_from_slice(&pi);
        cpts.extend_from_slice(&pj);
        let r = c.r[a];
        rn.push(r[0]);
        rt.push((r[1] * r[1] + r[2] * r[2]).sqrt());
        fnn.push(r[0] / w.time.h);
        gap.push(c.gap[a]);
    }
    let lines = cells((0..2 * m as u64).collect(), (1..=m as u64).map(|x| 2 * x).collect());
    let cell = vec![
        Attribute::scalars("r_n", 1).with_data(rn),
        Attribute::scalars("r_t", 1).with_data(rt),
        Attribute::scalars("f_n", 1).with_data(fnn),
        Attribute::scalars("gap", 1).with_data(gap),
    ];
    export(
        piece(cpts, None, lines, None, vec![], cell),
        &vdir.join(format!("contacts_{frame:06}.vtp")),
    )?;
    // contact points with their forces
    let (mut ppts, mut force, mut pfn, mut pgap, mut bonded) = (vec![], vec![], vec![], vec![], vec![]);
    for a in 0..m {
        ppts.extend_from_slice(&c.point[a]);
        force.extend(c.world_impulse(a).map(|x| x / w.time.h));
        pfn.push(c.r[a][0] / w.time.h);
        pgap.push(c.gap[a]);
        bonded.push(c.joint[a].bonded() as u8 as f64);
    }
    let point = vec![
        Attribute::vectors("force").with_data(force),
        Attribute::scalars("f_n", 1).with_data(pfn),
        Attribute::scalars("gap", 1).with_data(pgap),
        Attribute::scalars("bonded", 1).with_data(bonded),
    ];
    export(
        piece(
            ppts,
            cells((0..m as u64).collect(), (1..=m as u64).collect()),
            None,
            None,
            point,
            vec![],
        ),
        &vdir.join(format!("points_{frame:06}.vtp")),
    )?;
    v.frames.push((w.t, frame));
    for name in ["bodies", "walls", "contacts", "points"] {
        v.write_pvd(dir, name)?;
    }
    Ok(())
}
