//! One VTK XML PolyData piece (`.vtp`) written as it is encoded: each array goes
//! through a base64 encoder straight into the file, so writing a piece holds no
//! copy of its arrays. `vtkio` serialized a piece into strings first, ≈ 7 times the
//! arrays' bytes at once (56 MB for a frame of 55 000 spheres), the largest item of
//! an MPI rank's peak memory. The files are those `vtkio` wrote (the same elements,
//! attributes and encoding: binary, UInt64 headers, little endian) and `vtkio` reads
//! them back (`tests/tests/outputs.rs`).
//!
//! ```
//! # use nscdd::output::vtk_xml::{write_piece, Array, Cells, PieceData};
//! // two points, one line between them, a scalar per point
//! let mut out = Vec::new();
//! let piece = PieceData {
//!     points: &[0.0, 0.0, 0.0, 1.0, 0.0, 0.0],
//!     cells: [Cells::default(), Cells { connectivity: &[0, 1], offsets: &[2] }, Cells::default()],
//!     point_data: &[Array { name: "id", components: 1, values: &[0.0, 1.0] }],
//!     cell_data: &[],
//! };
//! write_piece(&mut out, &piece).unwrap();
//! let text = String::from_utf8(out).unwrap();
//! assert!(text.contains("<Piece NumberOfPoints=\"2\" NumberOfVerts=\"0\" NumberOfLines=\"1\""));
//! ```

use base64::engine::general_purpose::STANDARD;
use base64::write::EncoderWriter;
use std::io::{self, Write};

/// A data array: `components` values per point or cell.
pub struct Array<'a> {
    pub name: &'a str,
    pub components: u32,
    pub values: &'a [f64],
}

/// The cells of one kind (verts, lines or polys): point indices, and the end of
/// each cell in them.
#[derive(Clone, Copy, Default)]
pub struct Cells<'a> {
    pub connectivity: &'a [u64],
    pub offsets: &'a [u64],
}

/// A piece: its points (3 coordinates each), cells (verts, lines, polys) and data.
pub struct PieceData<'a> {
    pub points: &'a [f64],
    pub cells: [Cells<'a>; 3],
    pub point_data: &'a [Array<'a>],
    pub cell_data: &'a [Array<'a>],
}

/// Values an array is written from.
trait Le: Copy {
    const TYPE: &'static str;
    fn le(self) -> [u8; 8];
    fn f(self) -> f64;
}

impl Le for f64 {
    const TYPE: &'static str = "Float64";
    fn le(self) -> [u8; 8] {
        self.to_le_bytes()
    }
    fn f(self) -> f64 {
        self
    }
}

impl Le for u64 {
    const TYPE: &'static str = "UInt64";
    fn le(self) -> [u8; 8] {
        self.to_le_bytes()
    }
    fn f(self) -> f64 {
        self as f64
    }
}

/// One `DataArray`: its values' bytes after a UInt64 byte count, base64 encoded
/// as one stream, with the values' range when there are values.
fn data_array<T: Le>(out: &mut impl Write, name: &str, components: u32, values: &[T]) -> io::Result<()> {
    write!(out, "<DataArray type=\"{}\" Name=\"{name}\"", T::TYPE)?;
    if components > 1 {
        write!(out, " NumberOfComponents=\"{components}\"")?;
    }
    write!(out, " format=\"binary\"")?;
    if let Some(first) = values.first() {
        let (lo, hi) = values
            .iter()
            .fold((first.f(), first.f()), |(lo, hi), v| (lo.min(v.f()), hi.max(v.f())));
        write!(out, " RangeMin=\"{lo}\" RangeMax=\"{hi}\"")?;
    }
    write!(out, ">")?;
    {
        let mut enc = EncoderWriter::new(&mut *out, &STANDARD);
        enc.write_all(&(8 * values.len() as u64).to_le_bytes())?;
        let mut buf = [0u8; 4096];
        for chunk in values.chunks(buf.len() / 8) {
            for (k, v) in chunk.iter().enumerate() {
                buf[8 * k..8 * k + 8].copy_from_slice(&v.le());
            }
            enc.write_all(&buf[..8 * chunk.len()])?;
        }
        enc.finish()?;
    }
    write!(out, "</DataArray>")
}

/// `<PointData>` or `<CellData>`, naming the first scalar and the first vector.
fn data(out: &mut impl Write, tag: &str, arrays: &[Array]) -> io::Result<()> {
    if arrays.is_empty() {
        return Ok(());
    }
    write!(out, "<{tag}")?;
    if let Some(a) = arrays.iter().find(|a| a.components == 1) {
        write!(out, " Scalars=\"{}\"", a.name)?;
    }
    if let Some(a) = arrays.iter().find(|a| a.components == 3) {
        write!(out, " Vectors=\"{}\"", a.name)?;
    }
    write!(out, ">")?;
    for a in arrays {
        data_array(out, a.name, a.components, a.values)?;
    }
    write!(out, "</{tag}>")
}

/// Writes `p` as a `.vtp` file's content (every count given, zeros included: VTK's
/// readers refuse a piece without them).
pub fn write_piece(out: &mut impl Write, p: &PieceData) -> io::Result<()> {
    let [verts, lines, polys] = p.cells;
    write!(
        out,
        "<VTKFile type=\"PolyData\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\"><PolyData>\
         <Piece NumberOfPoints=\"{}\" NumberOfVerts=\"{}\" NumberOfLines=\"{}\" NumberOfStrips=\"0\" NumberOfPolys=\"{}\">",
        p.points.len() / 3,
        verts.offsets.len(),
        lines.offsets.len(),
        polys.offsets.len()
    )?;
    data(out, "PointData", p.point_data)?;
    data(out, "CellData", p.cell_data)?;
    write!(out, "<Points>")?;
    data_array(out, "Points", 3, p.points)?;
    write!(out, "</Points>")?;
    for (tag, c) in [("Verts", verts), ("Lines", lines), ("Polys", polys)] {
        if !c.offsets.is_empty() {
            write!(out, "<{tag}>")?;
            data_array(out, "connectivity", 1, c.connectivity)?;
            data_array(out, "offsets", 1, c.offsets)?;
            write!(out, "</{tag}>")?;
        }
    }
    write!(out, "</Piece></PolyData></VTKFile>")
}
