//! VTK output for ParaView: every output frame writes
//!
//! - `vtk/bodies_NNNNNN.vtp`: one point per body, with point data `id`, `radius`
//!   (of disk glyphs; the shape size otherwise), `velocity` (v_x, v_y, 0),
//!   `angular_velocity`, `rotation`, `material` (and, in a decomposed run,
//!   `subdomain`: the subdomain owning most of the body's contacts, ties to the
//!   smaller id, −1 without contacts; `multiplicity`: subdomains holding a copy); use ParaView's Glyph filter
//!   (sphere, scale by `radius`, factor 2) to draw the disks;
//! - `vtk/walls_NNNNNN.vtp`: the non-disk shapes (walls, half-plane pieces) as polygons;
//! - `vtk/contacts_NNNNNN.vtp`: the contact network, a line between the two bodies'
//!   centres per contact, with cell data `r_n`, `r_t` (N·s), `f_n` = r_n/h (N),
//!   `gap` (m) (and `subdomain` in a decomposed run);
//!
//! and the series `bodies.pvd`, `walls.pvd`, `contacts.pvd` (rewritten at every frame,
//! so that a stopped run leaves valid series). Files are written with `vtkio`.

use crate::dd::DdView;
use crate::dim::{D2, D3};
use crate::registry::{Glyph2, Registry, Writer};
use crate::world::World2;
use std::io::Write;
use std::path::Path;
use vtkio::model::{Attribute, Attributes, ByteOrder, DataSet, PolyDataPiece, Version, VertexNumbers, Vtk};

pub(crate) fn register_builtin(r: &mut Registry) {
    r.add_writer::<D2>("vtk", || Box::new(VtkWriter::default()));
    r.add_writer::<D3>("vtk", || Box::new(VtkWriter::default()));
}

/// Writes the VTK frames and `.pvd` series.
#[derive(Default)]
pub struct VtkWriter {
    pub(crate) frames: Vec<(f64, u32)>,
}

pub(crate) fn piece(
    points: Vec<f64>,
    verts: Option<VertexNumbers>,
    lines: Option<VertexNumbers>,
    polys: Option<VertexNumbers>,
    point: Vec<Attribute>,
    cell: Vec<Attribute>,
) -> Vtk {
    Vtk {
        version: Version::new(),
        title: "nscdd".into(),
        byte_order: ByteOrder::LittleEndian,
        file_path: None,
        data: DataSet::inline(PolyDataPiece {
            points: points.into(),
            verts,
            lines,
            polys,
            strips: None,
            data: Attributes { point, cell },
        }),
    }
}

pub(crate) fn cells(conn: Vec<u64>, offsets: Vec<u64>) -> Option<VertexNumbers> {
    Some(VertexNumbers::XML {
        connectivity: conn,
        offsets,
    })
}

pub(crate) fn export(v: Vtk, path: &Path) -> std::io::Result<()> {
    v.export(path)
        .map_err(|e| std::io::Error::other(format!("writing {}: {e}", path.display())))
}

impl VtkWriter {
    pub(crate) fn write_pvd(&self, dir: &Path, name: &str) -> std::io::Result<()> {
        let mut f = std::io::BufWriter::new(std::fs::File::create(dir.join(format!("{name}.pvd")))?);
        writeln!(
            f,
            "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n  <Collection>"
        )?;
        for (t, k) in &self.frames {
            writeln!(
                f,
                "    <DataSet timestep=\"{t:e}\" group=\"\" part=\"0\" file=\"vtk/{name}_{k:06}.vtp\"/>"
            )?;
        }
        writeln!(f, "  </Collection>\n</VTKFile>")?;
        f.flush()
    }
}

impl Writer<D2> for VtkWriter {
    fn write(&mut self, w: &World2, dir: &Path, frame: u32) -> std::io::Result<()> {
        self.frame(w, None, dir, frame)
    }
    fn write_dd(&mut self, w: &World2, dd: &DdView, dir: &Path, frame: u32) -> std::io::Result<()> {
        self.frame(w, Some(dd), dir, frame)
    }
}

impl Writer<D3> for VtkWriter {
    fn write(&mut self, w: &crate::world::World3, dir: &Path, frame: u32) -> std::io::Result<()> {
        super::out3::write_vtk3(self, w, dir, frame)
    }
}

impl VtkWriter {
    /// One frame; a decomposed run adds `subdomain` and `multiplicity` to the bodies
    /// and `subdomain` to the contacts.
    fn frame(&mut self, w: &World2, dd: Option<&DdView>, dir: &Path, frame: u32) -> std::io::Result<()> {
        let vdir = dir.join("vtk");
        std::fs::create_dir_all(&vdir)?;
        let b = &w.bodies;
        let n = b.len();
        // bodies as particles
        let mut pts = Vec::with_capacity(3 * n);
        let (mut radius, mut vel, mut omega, mut rot, mut id, mut mat) = (vec![], vec![], vec![], vec![], vec![], vec![]);
        // walls as polygons
        let (mut wpts, mut wconn, mut woff, mut wid) = (vec![], vec![], vec![], vec![]);
        for k in 0..n {
            let s = b.shape[k];
            let store = &w.shapes[s.kind as usize];
            let glyph = store.glyph(s.index, b.pos[k], b.rot[k]);
            pts.extend_from_slice(&[b.pos[k][0], b.pos[k][1], 0.0]);
            radius.push(match glyph {
                Glyph2::Ball(r) => r,
                _ => store.size(s.index),
            });
            vel.extend_from_slice(&[b.vel[k][0], b.vel[k][1], 0.0]);
            omega.push(b.vel[k][2]);
            rot.push(b.rot[k]);
            id.push(k as f64);
            mat.push(b.material[k] as f64);
            let poly: Vec<[f64; 2]> = match glyph {
                Glyph2::Ball(_) => continue,
                Glyph2::Polygon(p) => p,
                Glyph2::Faces(f) => f.concat(),
                Glyph2::Segment(p, q, th) => {
                    let d = [q[0] - p[0], q[1] - p[1]];
                    let l = (d[0] * d[0] + d[1] * d[1]).sqrt().max(f64::MIN_POSITIVE);
                    let o = [-d[1] / l * th / 2.0, d[0] / l * th / 2.0];
                    vec![
                        [p[0] - o[0], p[1] - o[1]],
                        [q[0] - o[0], q[1] - o[1]],
                        [q[0] + o[0], q[1] + o[1]],
                        [p[0] + o[0], p[1] + o[1]],
                    ]
                }
            };
            for v in poly {
                wconn.push((wpts.len() / 3) as u64);
                wpts.extend_from_slice(&[v[0], v[1], 0.0]);
            }
            woff.push(wconn.len() as u64);
            wid.push(k as f64);
        }
        let verts = cells((0..n as u64).collect(), (1..=n as u64).collect());
        let mut point = vec![
            Attribute::scalars("id", 1).with_data(id),
            Attribute::scalars("radius", 1).with_data(radius),
            Attribute::vectors("velocity").with_data(vel),
            Attribute::scalars("angular_velocity", 1).with_data(omega),
            Attribute::scalars("rotation", 1).with_data(rot),
            Attribute::scalars("material", 1).with_data(mat),
        ];
        if let Some(d) = dd {
            let sub: Vec<f64> = (0..n).map(|k| d.body_subdomain.get(k).copied().unwrap_or(-1) as f64).collect();
            let mult: Vec<f64> = (0..n).map(|k| d.multiplicity.get(k).copied().unwrap_or(0) as f64).collect();
            point.push(Attribute::scalars("subdomain", 1).with_data(sub));
            point.push(Attribute::scalars("multiplicity", 1).with_data(mult));
        }
        export(
            piece(pts, verts, None, None, point, vec![]),
            &vdir.join(format!("bodies_{frame:06}.vtp")),
        )?;
        let wcells = vec![Attribute::scalars("id", 1).with_data(wid)];
        export(
            piece(wpts, None, None, cells(wconn, woff), vec![], wcells),
            &vdir.join(format!("walls_{frame:06}.vtp")),
        )?;
        // contact network
        let c = &w.contacts;
        let m = c.len();
        let mut cpts = Vec::with_capacity(6 * m);
        let (mut rn, mut rt, mut fnn, mut gap) = (vec![], vec![], vec![], vec![]);
        for a in 0..m {
            let [i, j] = c.bodies[a];
            let (pi, pj) = (b.pos[i as usize], b.pos[j as usize]);
            // towards a wall, draw the line to the contact point
            let pj = if b.movable(j as usize) { pj } else { c.point[a] };
            cpts.extend_from_slice(&[pi[0], pi[1], 0.0, pj[0], pj[1], 0.0]);
            rn.push(c.r[a][0]);
            rt.push(c.r[a][1]);
            fnn.push(c.r[a][0] / w.time.h);
            gap.push(c.gap[a]);
        }
        let lines = cells((0..2 * m as u64).collect(), (1..=m as u64).map(|x| 2 * x).collect());
        let mut cell = vec![
            Attribute::scalars("r_n", 1).with_data(rn),
            Attribute::scalars("r_t", 1).with_data(rt),
            Attribute::scalars("f_n", 1).with_data(fnn),
            Attribute::scalars("gap", 1).with_data(gap),
        ];
        if let Some(d) = dd {
            let sub: Vec<f64> = (0..m).map(|a| d.contact_subdomain.get(a).map_or(-1.0, |&s| s as f64)).collect();
            cell.push(Attribute::scalars("subdomain", 1).with_data(sub));
        }
        export(
            piece(cpts, None, lines, None, vec![], cell),
            &vdir.join(format!("contacts_{frame:06}.vtp")),
        )?;
        self.frames.push((w.t, frame));
        for name in ["bodies", "walls", "contacts"] {
            self.write_pvd(dir, name)?;
        }
        Ok(())
    }
}
