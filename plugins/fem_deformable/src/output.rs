//! The deformable bodies' VTK output: one unstructured grid per body and frame
//! (current node positions; point data displacement and velocity; cell data
//! stress) and the `deformable.pvd` series that ParaView opens as one.

use crate::mesh::cell_stress;
use std::fmt::Write as _;
use std::path::Path;

/// `deformable.pvd`: the series of the frames `(t, frame)` of `bodies` bodies.
pub fn write_pvd(dir: &Path, bodies: usize, frames: &[(f64, u32)]) -> std::io::Result<()> {
    write_series(dir, "deformable", bodies, frames)
}

/// `{prefix}.pvd`: the series of the frames `(t, frame)` of `bodies` bodies, whose
/// files are `{prefix}{body}_{frame}.vtu`.
pub fn write_series(dir: &Path, prefix: &str, bodies: usize, frames: &[(f64, u32)]) -> std::io::Result<()> {
    let mut pvd = String::from("<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\">\n<Collection>\n");
    for (t, f) in frames {
        for bi in 0..bodies {
            let _ = writeln!(pvd, "<DataSet timestep=\"{t}\" part=\"{bi}\" file=\"{prefix}{bi}_{f:05}.vtu\"/>");
        }
    }
    pvd.push_str("</Collection>\n</VTKFile>\n");
    nscdd::output::write_atomic(&dir.join(format!("{prefix}.pvd")), |tmp| std::fs::write(tmp, pvd))
}

/// One deformable body as a VTK XML unstructured grid (ASCII): current node
/// positions, point data displacement and velocity, cell data stress.
pub fn vtu(b: &crate::body::FeBody) -> String {
    let d = b.dim();
    let (nn, nc) = (b.mesh.n_nodes(), b.mesh.n_cells());
    let mut s = String::with_capacity(64 * (nn + nc));
    let _ = writeln!(
        s,
        "<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"0.1\" byte_order=\"LittleEndian\">\n<UnstructuredGrid>\n<Piece NumberOfPoints=\"{nn}\" NumberOfCells=\"{nc}\">"
    );
    let vec3 = |s: &mut String, v: &[f64]| {
        for k in 0..nn {
            let z = if d == 3 { v[3 * k + 2] } else { 0.0 };
            let _ = write!(s, "{:e} {:e} {:e} ", v[d * k], v[d * k + 1], z);
        }
    };
    s.push_str("<Points><DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"ascii\">\n");
    let pos: Vec<f64> = b.mesh.x0.iter().zip(&b.u).map(|(x, u)| x + u).collect();
    vec3(&mut s, &pos);
    s.push_str("\n</DataArray></Points>\n<Cells><DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">\n");
    for c in &b.mesh.cells {
        let _ = write!(s, "{c} ");
    }
    s.push_str("\n</DataArray><DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">\n");
    for e in 1..=nc {
        let _ = write!(s, "{} ", e * (d + 1));
    }
    s.push_str("\n</DataArray><DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">\n");
    let ty = if d == 2 { 5 } else { 10 };
    for _ in 0..nc {
        let _ = write!(s, "{ty} ");
    }
    s.push_str("\n</DataArray></Cells>\n<PointData Vectors=\"displacement\">\n");
    for (name, v) in [("displacement", &b.u), ("velocity", &b.v)] {
        let _ = writeln!(
            s,
            "<DataArray type=\"Float64\" Name=\"{name}\" NumberOfComponents=\"3\" format=\"ascii\">"
        );
        vec3(&mut s, v);
        s.push_str("\n</DataArray>\n");
    }
    s.push_str("</PointData>\n<CellData>\n");
    let st = cell_stress(&b.mesh, &b.u, b.elastic.young, b.elastic.poisson, b.elastic.plane_stress);
    // symmetric tensor as VTK's 6 components xx, yy, zz, xy, yz, xz
    s.push_str("<DataArray type=\"Float64\" Name=\"stress\" NumberOfComponents=\"6\" format=\"ascii\">\n");
    for t in &st {
        let v = if d == 2 { [t[0], t[1], t[3], t[2], 0.0, 0.0] } else { *t };
        for x in v {
            let _ = write!(s, "{x:e} ");
        }
    }
    s.push_str("\n</DataArray>\n</CellData>\n</Piece>\n</UnstructuredGrid>\n</VTKFile>\n");
    s
}
