//! VTK output for ParaView, one writer for 2D and 3D (2D points are written with
//! z = 0). Every output frame writes
//!
//! - `vtk/bodies_NNNNNN.vtp`: one point per body, with point data `id`, `radius`
//!   (of disk and sphere glyphs; the shape's size otherwise), `velocity` (a 3-vector),
//!   `angular_velocity` (ω: a scalar in 2D, a vector in 3D), `rotation` (the angle
//!   in 2D, the rotation vector in 3D), `material` (and, in a decomposed run,
//!   `subdomain`: the subdomain owning most of the body's contacts, ties to the
//!   smaller id, −1 without contacts; `multiplicity`: subdomains holding a copy);
//!   use ParaView's Glyph filter (sphere, scale by `radius`, factor 2) to draw the
//!   disks and spheres;
//! - `vtk/walls_NNNNNN.vtp`: the shapes that are not balls (walls, polygons,
//!   polyhedra as their faces) as polygons, cell data `id` (the body);
//! - `vtk/contacts_NNNNNN.vtp`: the contact network, a line per contact from the
//!   candidate's centre to the antagonist's (to the contact point when the
//!   antagonist is not a free grain), with cell data `r_n`, `r_t` (N·s; 2D: signed,
//!   3D: |r_t|), `f_n` = r_n/h (N), `gap` (m) (and `subdomain` in a decomposed run);
//! - `vtk/points_NNNNNN.vtp`: a vertex per contact point with the contact force on
//!   the candidate body as the vector `force` (impulse / h, world axes), `f_n`,
//!   `gap` and `bonded` (1 for an intact mortar joint);
//!
//! and the series `bodies.pvd`, `walls.pvd`, `contacts.pvd`, `points.pvd`
//! (rewritten at every frame, so that a stopped run leaves valid series). Files are
//! written with `vtkio`.

use super::Writer;
use crate::dd::DdView;
use crate::dim::{Coords, Dim, Vector};
use crate::shape::Glyph;
use crate::world::World;
use std::io::Write;
use std::path::Path;
use vtkio::model::{Attribute, Attributes, ByteOrder, DataSet, PolyDataPiece, Version, VertexNumbers, Vtk};

/// Writes the VTK frames and `.pvd` series.
#[derive(Default)]
pub struct VtkWriter {
    pub(crate) frames: Vec<(f64, u32)>,
}

fn piece(
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

fn cells(conn: Vec<u64>, offsets: Vec<u64>) -> Option<VertexNumbers> {
    Some(VertexNumbers::XML {
        connectivity: conn,
        offsets,
    })
}

/// `n` cells of `per` consecutive points each.
fn runs(n: usize, per: u64) -> Option<VertexNumbers> {
    cells((0..per * n as u64).collect(), (1..=n as u64).map(|x| per * x).collect())
}

/// Writes a VTK file atomically ([`super::write_atomic`]).
fn export(v: Vtk, path: &Path) -> std::io::Result<()> {
    super::write_atomic(path, |tmp| {
        v.export(tmp)
            .map_err(|e| std::io::Error::other(format!("writing {}: {e}", path.display())))
    })
}

/// A point or vector of either dimension as three coordinates (z = 0 in 2D).
fn xyz(p: &[f64]) -> [f64; 3] {
    [p[0], p[1], p.get(2).copied().unwrap_or(0.0)]
}

/// A scalar attribute in 2D, a vector in 3D (ω, rotation vectors).
fn per_dim(name: &str, n: usize, data: Vec<f64>) -> Attribute {
    if n == 1 {
        Attribute::scalars(name, 1).with_data(data)
    } else {
        Attribute::vectors(name).with_data(data)
    }
}

/// The outline of a glyph that is not a ball, as polygons (2D: one outline; a
/// segment drawn as a rectangle of its thickness; 3D: one polygon per face).
fn polygons<D: Dim>(g: Glyph<D>) -> Vec<Vec<D::Point>> {
    match g {
        Glyph::Ball(_) => vec![],
        Glyph::Polygon(p) => vec![p],
        Glyph::Faces(f) if D::N == 2 => vec![f.concat()],
        Glyph::Faces(f) => f,
        Glyph::Segment(p, q, th) if D::N == 2 => {
            let d = q.sub(&p);
            let l = d.dot(&d).sqrt().max(f64::MIN_POSITIVE);
            let o = D::Point::from_fn(|k| [-d[1], d[0]].get(k).copied().unwrap_or(0.0) / l * th / 2.0);
            let at = |a: &D::Point, s: f64| D::Point::from_fn(|k| a[k] + s * o[k]);
            vec![vec![at(&p, -1.0), at(&q, -1.0), at(&q, 1.0), at(&p, 1.0)]]
        }
        Glyph::Segment(p, q, _) => vec![vec![p, q]],
    }
}

impl VtkWriter {
    fn write_pvd(&self, dir: &Path, name: &str) -> std::io::Result<()> {
        super::write_atomic(&dir.join(format!("{name}.pvd")), |tmp| self.write_pvd_to(tmp, name))
    }

    fn write_pvd_to(&self, path: &Path, name: &str) -> std::io::Result<()> {
        let mut f = std::io::BufWriter::new(std::fs::File::create(path)?);
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

    /// One frame; a decomposed run adds `subdomain` and `multiplicity` to the bodies
    /// and `subdomain` to the contacts.
    fn frame<D: Dim>(&mut self, w: &World<D>, dd: Option<&DdView>, dir: &Path, frame: u32) -> std::io::Result<()> {
        let vdir = dir.join("vtk");
        std::fs::create_dir_all(&vdir)?;
        let file = |name: &str| vdir.join(format!("{name}_{frame:06}.vtp"));
        bodies(w, dd, &file("bodies"), &file("walls"))?;
        contacts(w, dd, &file("contacts"), &file("points"))?;
        self.frames.push((w.t, frame));
        for name in ["bodies", "walls", "contacts", "points"] {
            self.write_pvd(dir, name)?;
        }
        Ok(())
    }
}

/// The bodies as particles and the shapes that are not balls as polygons.
fn bodies<D: Dim>(w: &World<D>, dd: Option<&DdView>, bodies: &Path, walls: &Path) -> std::io::Result<()> {
    let b = &w.bodies;
    let n = b.len();
    let (mut pts, mut radius, mut vel, mut omega, mut rot) = (vec![], vec![], vec![], vec![], vec![]);
    let (mut wpts, mut wconn, mut woff, mut wid) = (vec![], vec![], vec![], vec![]);
    for k in 0..n {
        let s = b.shape[k];
        let store = &w.shapes[s.kind as usize];
        let glyph = store.glyph(s.index, b.pos[k], b.rot[k]);
        pts.extend(xyz(b.pos[k].as_ref()));
        radius.push(match glyph {
            Glyph::Ball(r) => r,
            _ => store.size(s.index),
        });
        vel.extend(xyz(&b.vel[k].as_ref()[..D::N]));
        omega.extend_from_slice(&b.vel[k].as_ref()[D::N..]);
        rot.extend_from_slice(D::rot_to_vec(&b.rot[k]).coords());
        for poly in polygons(glyph) {
            for v in poly {
                wconn.push((wpts.len() / 3) as u64);
                wpts.extend(xyz(v.as_ref()));
            }
            woff.push(wconn.len() as u64);
            wid.push(k as f64);
        }
    }
    let rdof = D::DOF - D::N;
    let mut point = vec![
        Attribute::scalars("id", 1).with_data((0..n).map(|k| k as f64).collect::<Vec<_>>()),
        Attribute::scalars("radius", 1).with_data(radius),
        Attribute::vectors("velocity").with_data(vel),
        per_dim("angular_velocity", rdof, omega),
        per_dim("rotation", rdof, rot),
        Attribute::scalars("material", 1).with_data(b.material.iter().map(|&m| m as f64).collect::<Vec<_>>()),
    ];
    if let Some(d) = dd {
        let sub: Vec<f64> = (0..n).map(|k| d.body_subdomain.get(k).copied().unwrap_or(-1) as f64).collect();
        let mult: Vec<f64> = (0..n).map(|k| d.multiplicity.get(k).copied().unwrap_or(0) as f64).collect();
        point.push(Attribute::scalars("subdomain", 1).with_data(sub));
        point.push(Attribute::scalars("multiplicity", 1).with_data(mult));
    }
    export(piece(pts, runs(n, 1), None, None, point, vec![]), bodies)?;
    let wcells = vec![Attribute::scalars("id", 1).with_data(wid)];
    export(piece(wpts, None, None, cells(wconn, woff), vec![], wcells), walls)
}

/// The contact network (lines) and the contact points with their forces.
fn contacts<D: Dim>(w: &World<D>, dd: Option<&DdView>, lines: &Path, points: &Path) -> std::io::Result<()> {
    let (b, c, h) = (&w.bodies, &w.contacts, w.time.h);
    let m = c.len();
    let (mut cpts, mut rt, mut ppts, mut force) = (vec![], vec![], vec![], vec![]);
    for a in 0..m {
        let [i, j] = c.bodies[a].map(|x| x as usize);
        // towards a wall or a driven body, draw the line to the contact point
        let free_grain = b.movable(j) && !w.fixed[j] && w.shapes[b.shape[j].kind as usize].is_grain();
        let pj = if free_grain { b.pos[j] } else { c.point[a] };
        cpts.extend(xyz(b.pos[i].as_ref()));
        cpts.extend(xyz(pj.as_ref()));
        let r = c.r[a].as_ref();
        rt.push(if D::N == 2 { r[1] } else { (r[1] * r[1] + r[2] * r[2]).sqrt() });
        ppts.extend(xyz(c.point[a].as_ref()));
        force.extend(xyz(c.world_impulse(a).as_ref()).map(|x| x / h));
    }
    let rn: Vec<f64> = (0..m).map(|a| c.r[a][0]).collect();
    let fnn: Vec<f64> = rn.iter().map(|r| r / h).collect();
    let gap = c.gap.clone();
    let mut cell = vec![
        Attribute::scalars("r_n", 1).with_data(rn),
        Attribute::scalars("r_t", 1).with_data(rt),
        Attribute::scalars("f_n", 1).with_data(fnn.clone()),
        Attribute::scalars("gap", 1).with_data(gap.clone()),
    ];
    if let Some(d) = dd {
        let sub: Vec<f64> = (0..m).map(|a| d.contact_subdomain.get(a).map_or(-1.0, |&s| s as f64)).collect();
        cell.push(Attribute::scalars("subdomain", 1).with_data(sub));
    }
    export(piece(cpts, None, runs(m, 2), None, vec![], cell), lines)?;
    let bonded: Vec<f64> = c.joint.iter().map(|j| j.bonded() as u8 as f64).collect();
    let point = vec![
        Attribute::vectors("force").with_data(force),
        Attribute::scalars("f_n", 1).with_data(fnn),
        Attribute::scalars("gap", 1).with_data(gap),
        Attribute::scalars("bonded", 1).with_data(bonded),
    ];
    export(piece(ppts, runs(m, 1), None, None, point, vec![]), points)
}

impl<D: Dim> Writer<D> for VtkWriter {
    fn write(&mut self, w: &World<D>, dir: &Path, frame: u32) -> std::io::Result<()> {
        self.frame(w, None, dir, frame)
    }
    fn write_dd(&mut self, w: &World<D>, dd: &DdView, dir: &Path, frame: u32) -> std::io::Result<()> {
        self.frame(w, Some(dd), dir, frame)
    }
}
