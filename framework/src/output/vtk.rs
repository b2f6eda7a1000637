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
//! written as they are encoded ([`super::vtk_xml`]). On MPI ranks ([`crate::dd::Piece`]) every rank writes its
//! piece `NAME_NNNNNN_RANK.vtp` and rank 0 the `NAME_NNNNNN.pvtp` naming them, which
//! the series list (ParaView opens the pieces as one dataset).

use super::vtk_xml::{write_piece, Array, Cells, PieceData};
use super::Writer;
use crate::dd::DdView;
use crate::dim::{Coords, Dim, Vector};
use crate::shape::Glyph;
use crate::world::World;
use std::io::Write;
use std::path::Path;

/// Writes the VTK frames and `.pvd` series.
#[derive(Default)]
pub struct VtkWriter {
    pub(crate) frames: Vec<(f64, u32)>,
    /// Whether the frames are pieces of MPI ranks (the series names the `.pvtp`).
    pieces: bool,
}

/// `n` cells of `per` consecutive points each: (connectivity, offsets).
fn runs(n: usize, per: u64) -> (Vec<u64>, Vec<u64>) {
    ((0..per * n as u64).collect(), (1..=n as u64).map(|x| per * x).collect())
}

/// Writes a piece atomically ([`super::write_atomic`]).
fn export(path: &Path, p: &PieceData) -> std::io::Result<()> {
    super::write_atomic(path, |tmp| {
        let mut f = std::io::BufWriter::new(std::fs::File::create(tmp)?);
        write_piece(&mut f, p)
            .and_then(|()| f.flush())
            .map_err(|e| std::io::Error::other(format!("writing {}: {e}", path.display())))
    })
}

/// A point or vector of either dimension as three coordinates (z = 0 in 2D).
fn xyz(p: &[f64]) -> [f64; 3] {
    [p[0], p[1], p.get(2).copied().unwrap_or(0.0)]
}

/// A scalar array in 2D, a vector in 3D (ω, rotation vectors): `n` values a body.
fn per_dim<'a>(name: &'a str, n: usize, values: &'a [f64]) -> Array<'a> {
    Array {
        name,
        components: if n == 1 { 1 } else { 3 },
        values,
    }
}

/// A scalar array.
fn scalars<'a>(name: &'a str, values: &'a [f64]) -> Array<'a> {
    Array {
        name,
        components: 1,
        values,
    }
}

/// A vector array (3 values an element).
fn vectors<'a>(name: &'a str, values: &'a [f64]) -> Array<'a> {
    Array {
        name,
        components: 3,
        values,
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

fn described(a: &[Array]) -> Vec<(String, u32)> {
    a.iter().map(|x| (x.name.to_string(), x.components)).collect()
}

/// The `.pvtp` naming the `ranks` pieces `STEM_RANK.vtp` of a frame (the arrays as
/// the pieces have them: Float64 points and data).
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
    let id: Vec<f64> = sel.iter().map(|&k| f64::from(w.ids.global(k as u32))).collect();
    let material: Vec<f64> = sel.iter().map(|&k| b.material[k] as f64).collect();
    // (the view is by global id)
    let g = |k: usize| w.ids.global(k as u32) as usize;
    let (sub, mult): (Vec<f64>, Vec<f64>) = match dd {
        Some(d) => sel
            .iter()
            .map(|&k| {
                let s = d.body_subdomain.get(g(k)).copied().unwrap_or(-1) as f64;
                (s, d.multiplicity.get(g(k)).copied().unwrap_or(0) as f64)
            })
            .unzip(),
        None => (vec![], vec![]),
    };
    let mut point = vec![
        scalars("id", &id),
        scalars("radius", &radius),
        vectors("velocity", &vel),
        per_dim("angular_velocity", rdof, &omega),
        per_dim("rotation", rdof, &rot),
        scalars("material", &material),
    ];
    if dd.is_some() {
        point.push(scalars("subdomain", &sub));
        point.push(scalars("multiplicity", &mult));
    }
    let (conn, off) = runs(n, 1);
    let verts = Cells {
        connectivity: &conn,
        offsets: &off,
    };
    let none = Cells::default();
    export(
        bodies,
        &PieceData {
            points: &pts,
            cells: [verts, none, none],
            point_data: &point,
            cell_data: &[],
        },
    )?;
    let out = [(described(&point), vec![]), (vec![], vec![("id".to_string(), 1)])];
    let polys = Cells {
        connectivity: &wconn,
        offsets: &woff,
    };
    let cell = [scalars("id", &wid)];
    export(
        walls,
        &PieceData {
            points: &wpts,
            cells: [none, none, polys],
            point_data: &[],
            cell_data: &cell,
        },
    )?;
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
    let sub: Vec<f64> = match dd {
        Some(d) => sel
            .iter()
            .map(|&a| d.contact_subdomain.get(a).map_or(-1.0, |&s| s as f64))
            .collect(),
        None => vec![],
    };
    let mut cell = vec![scalars("r_n", &rn), scalars("r_t", &rt), scalars("f_n", &fnn), scalars("gap", &gap)];
    if dd.is_some() {
        cell.push(scalars("subdomain", &sub));
    }
    let none = Cells::default();
    let (conn, off) = runs(m, 2);
    let line_cells = Cells {
        connectivity: &conn,
        offsets: &off,
    };
    export(
        lines,
        &PieceData {
            points: &cpts,
            cells: [none, line_cells, none],
            point_data: &[],
            cell_data: &cell,
        },
    )?;
    let lines_arrays = (vec![], described(&cell));
    let bonded: Vec<f64> = sel.iter().map(|&a| c.joint[a].bonded() as u8 as f64).collect();
    let point = [
        vectors("force", &force),
        scalars("f_n", &fnn),
        scalars("gap", &gap),
        scalars("bonded", &bonded),
    ];
    let (conn, off) = runs(m, 1);
    let verts = Cells {
        connectivity: &conn,
        offsets: &off,
    };
    export(
        points,
        &PieceData {
            points: &ppts,
            cells: [verts, none, none],
            point_data: &point,
            cell_data: &[],
        },
    )?;
    Ok([lines_arrays, (described(&point), vec![])])
}

impl<D: Dim> Writer<D> for VtkWriter {
    fn write(&mut self, w: &World<D>, dir: &Path, frame: u32) -> std::io::Result<()> {
        self.frame(w, None, dir, frame)
    }
    fn write_dd(&mut self, w: &World<D>, dd: &DdView, dir: &Path, frame: u32) -> std::io::Result<()> {
        self.frame(w, Some(dd), dir, frame)
    }
}
