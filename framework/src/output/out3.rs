//! The VTK frames of a 3D run (the history and `final.json` are
//! [`super::history`]'s and [`super::final_json`], as in 2D): `vtk/bodies_*.vtp`,
//! one point per body with `id`, `radius`,
//! `velocity`, `angular_velocity` (vectors), `material`; `vtk/walls_*.vtp`: planes
//! and boxes as polygons; `vtk/contacts_*.vtp`: a line per contact with `r_n`,
//! `r_t` = |r_t|, `f_n`, `gap`; `vtk/points_*.vtp`: a vertex per contact point
//! with the contact force on the candidate body as the vector `force` (impulse / h,
//! world axes), `f_n`, `gap` and `bonded` (1 for an intact mortar joint), with the
//! series `bodies.pvd`, `walls.pvd`, `contacts.pvd`, `points.pvd`. Polyhedra and
//! other faceted shapes are drawn as their faces in `walls_*.vtp` (cell `id`: the
//! body).

use super::vtk::{cells, export, piece, VtkWriter};
use crate::shape::Glyph3;
use crate::world::World3;
use std::path::Path;
use vtkio::model::Attribute;

/// One VTK frame of a 3D world.
pub(crate) fn write_vtk3(v: &mut VtkWriter, w: &World3, dir: &Path, frame: u32) -> std::io::Result<()> {
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
