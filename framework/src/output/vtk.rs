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
//! written with `vtkio`. On MPI ranks ([`crate::dd::Piece`]) every rank writes its
//! piece `NAME_NNNNNN_RANK.vtp` and rank 0 the `NAME_NNNNNN.pvtp` naming them, which
//! the series list (ParaView opens the pieces as one dataset).

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
    /// Whether the frames are pieces of MPI ranks (the series names the `.pvtp`).
    pieces: bool,
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
/// A piece without points gets its counts written as zeros (vtkio leaves them out,
/// and VTK's readers refuse such a piece: a frame before the first contact, a rank's
/// piece without walls).
fn export(v: Vtk, path: &Path) -> std::io::Result<()> {
    let empty = match &v.data {
        DataSet::PolyData { pieces, .. } => pieces.iter().all(|p| match p {
            vtkio::model::Piece::Inline(b) => b.points.is_empty(),
            _ => false,
        }),
        _ => false,
    };
    super::write_atomic(path, |tmp| {
        v.export(tmp)
            .map_err(|e| std::io::Error::other(format!("writing {}: {e}", path.display())))?;
        if empty {
            let text = std::fs::read_to_string(tmp)?;
            let counts = "<Piece NumberOfPoints=\"0\" NumberOfVerts=\"0\" NumberOfLines=\"0\" NumberOfStrips=\"0\" NumberOfPolys=\"0\">";
            std::fs::write(tmp, text.replacen("<Piece>", counts, 1))?;
        }
        Ok(())
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
        let ext = if self.pieces { "pvtp" } else { "vtp" };
        let mut f = std::io::BufWriter::new(std::fs::File::create(path)?);
        writeln!(
            f,
            "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n  <Collection>"
        )?;
        for (t, k) in &self.frames {
            writeln!(
                f,
                "    <DataSet timestep=\"{t:e}\" group=\"\" part=\"0\" file=\"vtk/{name}_{k:06}.{ext}\"/>"
            )?;
        }
        writeln!(f, "  </Collection>\n</VTKFile>")?;
        f.flush()
    }

    /// One frame; a decomposed run adds `subdomain` and `multiplicity` to the bodies
    /// and `subdomain` to the contacts. On MPI ranks each writes its piece and rank 0
    /// the `.pvtp` files and the series.
    fn frame<D: Dim>(&mut self, w: &World<D>, dd: Option<&DdView>, dir: &Path, frame: u32) -> std::io::Result<()> {
        let vdir = dir.join("vtk");
        std::fs::create_dir_all(&vdir)?;
        let piece = dd.and_then(|d| d.piece.as_ref());
        let file = |name: &str| match piece {
            Some(p) => vdir.join(format!("{name}_{frame:06}_{}.vtp", p.rank)),
            None => vdir.join(format!("{name}_{frame:06}.vtp")),
        };
        let (nb, nc) = (w.bodies.len(), w.contacts.len());
        let (sel_b, sel_c): (Vec<usize>, Vec<usize>) = match (dd, piece) {
            (Some(d), Some(p)) => (
                (0..nb)
                    .filter(|&k| {
                        let g = w.ids.global(k as u32) as usize;
                        p.has_body(g, d.body_subdomain.get(g).copied().unwrap_or(-1))
                    })
                    .collect(),
                (0..nc)
                    .filter(|&a| d.contact_subdomain.get(a).map_or(p.rank == 0, |&s| p.has_contact(s)))
                    .collect(),
            ),
            _ => ((0..nb).collect(), (0..nc).collect()),
        };
        let mut arrays = Vec::from(bodies(w, dd, &sel_b, &file("bodies"), &file("walls"))?);
        arrays.extend(contacts(w, dd, &sel_c, &file("contacts"), &file("points"))?);
        self.frames.push((w.t, frame));
        self.pieces = piece.is_some();
        if piece.is_some_and(|p| p.rank != 0) {
            return Ok(());
        }
        for (name, (point, cell)) in ["bodies", "walls", "contacts", "points"].into_iter().zip(&arrays) {
            if let Some(p) = piece {
                let path = vdir.join(format!("{name}_{frame:06}.pvtp"));
                super::write_atomic(&path, |tmp| pvtp(tmp, &format!("{name}_{frame:06}"), p.ranks, point, cell))?;
            }
            self.write_pvd(dir, name)?;
        }
        Ok(())
    }
}

/// The point and cell arrays of a file: (name, components) each.
type Arrays = (Vec<(String, u32)>, Vec<(String, u32)>);

fn described(a: &[Attribute]) -> Vec<(String, u32)> {
    use vtkio::model::ElementType;
    a.iter()
        .filter_map(|x| match x {
            Attribute::DataArray(d) => Some((
                d.name.clone(),
                match d.elem {
                    ElementType::Scalars { num_comp, .. } => num_comp,
                    ElementType::Vectors | ElementType::Normals => 3,
                    _ => 1,
                },
            )),
            Attribute::Field { .. } => None,
        })
        .collect()
}

/// The `.pvtp` naming the `ranks` pieces `STEM_RANK.vtp` of a frame (the arrays as
/// `vtkio` writes them: Float64 points and data).
fn pvtp(path: &Path, stem: &str, ranks: u32, point: &[(String, u32)], cell: &[(String, u32)]) -> std::io::Result<()> {
    let mut f = std::io::BufWriter::new(std::fs::File::create(path)?);
    writeln!(f, "<?xml version=\"1.0\"?>")?;
    writeln!(
        f,
        "<VTKFile type=\"PPolyData\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\">"
    )?;
    writeln!(f, "  <PPolyData GhostLevel=\"0\">")?;
    for (tag, arrays) in [("PPointData", point), ("PCellData", cell)] {
        writeln!(f, "    <{tag}>")?;
        for (name, n) in arrays {
            writeln!(f, "      <PDataArray type=\"Float64\" Name=\"{name}\" NumberOfComponents=\"{n}\"/>")?;
        }
        writeln!(f, "    </{tag}>")?;
    }
    writeln!(
        f,
        "    <PPoints>\n      <PDataArray type=\"Float64\" Name=\"Points\" NumberOfComponents=\"3\"/>\n    </PPoints>"
    )?;
    for r in 0..ranks {
        writeln!(f, "    <Piece Source=\"{stem}_{r}.vtp\"/>")?;
    }
    writeln!(f, "  </PPolyData>\n</VTKFile>")?;
    f.flush()
}

/// The bodies as particles and the shapes that are not balls as polygons.
fn bodies<D: Dim>(w: &World<D>, dd: Option<&DdView>, sel: &[usize], bodies: &Path, walls: &Path) -> std::io::Result<[Arrays; 2]> {
    let b = &w.bodies;
    let n = sel.len();
    let (mut pts, mut radius, mut vel, mut omega, mut rot) = (vec![], vec![], vec![], vec![], vec![]);
    let (mut wpts, mut wconn, mut woff, mut wid) = (vec![], vec![], vec![], vec![]);
    for &k in sel {
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
            wid.push(f64::from(w.ids.global(k as u32)));
        }
    }
    let rdof = D::DOF - D::N;
    let mut point = vec![
        Attribute::scalars("id", 1).with_data(sel.iter().map(|&k| f64::from(w.ids.global(k as u32))).collect::<Vec<_>>()),
        Attribute::scalars("radius", 1).with_data(radius),
        Attribute::vectors("velocity").with_data(vel),
        per_dim("angular_velocity", rdof, omega),
        per_dim("rotation", rdof, rot),
        Attribute::scalars("material", 1).with_data(sel.iter().map(|&k| b.material[k] as f64).collect::<Vec<_>>()),
    ];
    if let Some(d) = dd {
        // (the view is by global id)
        let g = |k: usize| w.ids.global(k as u32) as usize;
        let sub: Vec<f64> = sel
            .iter()
            .map(|&k| d.body_subdomain.get(g(k)).copied().unwrap_or(-1) as f64)
            .collect();
        let mult: Vec<f64> = sel.iter().map(|&k| d.multiplicity.get(g(k)).copied().unwrap_or(0) as f64).collect();
        point.push(Attribute::scalars("subdomain", 1).with_data(sub));
        point.push(Attribute::scalars("multiplicity", 1).with_data(mult));
    }
    let out = [(described(&point), vec![]), (vec![], vec![("id".to_string(), 1)])];
    export(piece(pts, runs(n, 1), None, None, point, vec![]), bodies)?;
    let wcells = vec![Attribute::scalars("id", 1).with_data(wid)];
    export(piece(wpts, None, None, cells(wconn, woff), vec![], wcells), walls)?;
    Ok(out)
}

/// The contact network (lines) and the contact points with their forces.
fn contacts<D: Dim>(w: &World<D>, dd: Option<&DdView>, sel: &[usize], lines: &Path, points: &Path) -> std::io::Result<[Arrays; 2]> {
    let (b, c, h) = (&w.bodies, &w.contacts, w.time.h);
    let m = sel.len();
    let (mut cpts, mut rt, mut ppts, mut force) = (vec![], vec![], vec![], vec![]);
    for &a in sel {
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
    let rn: Vec<f64> = sel.iter().map(|&a| c.r[a][0]).collect();
    let fnn: Vec<f64> = rn.iter().map(|r| r / h).collect();
    let gap: Vec<f64> = sel.iter().map(|&a| c.gap[a]).collect();
    let mut cell = vec![
        Attribute::scalars("r_n", 1).with_data(rn),
        Attribute::scalars("r_t", 1).with_data(rt),
        Attribute::scalars("f_n", 1).with_data(fnn.clone()),
        Attribute::scalars("gap", 1).with_data(gap.clone()),
    ];
    if let Some(d) = dd {
        let sub: Vec<f64> = sel
            .iter()
            .map(|&a| d.contact_subdomain.get(a).map_or(-1.0, |&s| s as f64))
            .collect();
        cell.push(Attribute::scalars("subdomain", 1).with_data(sub));
    }
    let lines_arrays = (vec![], described(&cell));
    export(piece(cpts, None, runs(m, 2), None, vec![], cell), lines)?;
    let bonded: Vec<f64> = sel.iter().map(|&a| c.joint[a].bonded() as u8 as f64).collect();
    let point = vec![
        Attribute::vectors("force").with_data(force),
        Attribute::scalars("f_n", 1).with_data(fnn),
        Attribute::scalars("gap", 1).with_data(gap),
        Attribute::scalars("bonded", 1).with_data(bonded),
    ];
    let out = [lines_arrays, (described(&point), vec![])];
    export(piece(ppts, runs(m, 1), None, None, point, vec![]), points)?;
    Ok(out)
}

impl<D: Dim> Writer<D> for VtkWriter {
    fn write(&mut self, w: &World<D>, dir: &Path, frame: u32) -> std::io::Result<()> {
        self.frame(w, None, dir, frame)
    }
    fn write_dd(&mut self, w: &World<D>, dd: &DdView, dir: &Path, frame: u32) -> std::io::Result<()> {
        self.frame(w, Some(dd), dir, frame)
    }
}
