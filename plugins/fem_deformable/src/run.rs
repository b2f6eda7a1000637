//! Running a scene with deformable bodies: `history.csv` (with the elastic
//! energy), VTK frames (the rigid bodies through the framework's writer, each
//! deformable body as an unstructured mesh with displacement, velocity and cell
//! stress, `deformable.pvd`), `final.json`.

use crate::body::FeBody;
use crate::mesh::cell_stress;
use crate::scene::{FeScene2, FeScene3};
use nscdd::dim::D2;
use nscdd::engine::{Diverged, StepReport};
use nscdd::output::vtk::VtkWriter;
use nscdd::registry::Writer;
use nscdd::scene::OutputSettings;
use std::fmt::Write as _;
use std::io::Write;
use std::path::Path;

/// What a run did.
#[derive(Clone, Debug, Default)]
pub struct FeSummary {
    pub steps: u64,
    pub unconverged_steps: u64,
    pub total_sweeps: u64,
    pub wall_seconds: f64,
}

fn io(dir: &Path, what: &str) -> impl Fn(std::io::Error) -> String {
    let d = dir.display().to_string();
    let w = what.to_string();
    move |e| format!("cannot write {w} in {d}: {e}")
}

/// What the run loop needs of a scene with deformable bodies (2D or 3D).
pub trait FeRunnable {
    fn step(&mut self) -> Result<StepReport, Diverged>;
    fn fe_bodies(&self) -> &[FeBody];
    fn fe_bodies_mut(&mut self) -> &mut [FeBody];
    fn fe_contacts(&self) -> usize;
    /// Time spent in the deformable stages during the last step.
    fn fe_times(&self) -> crate::stage2::FeTimes;
    fn output(&self) -> &OutputSettings;
    /// (step, t, steps to run).
    fn clock(&self) -> (u64, f64, u64);
    fn rigid_kinetic(&self) -> f64;
    fn write_rigid(&self, vtk: &mut VtkWriter, dir: &Path, frame: u32) -> std::io::Result<()>;
    fn final_json(&self) -> String;
}

impl FeRunnable for FeScene2 {
    fn step(&mut self) -> Result<StepReport, Diverged> {
        FeScene2::step(self)
    }
    fn fe_bodies(&self) -> &[FeBody] {
        &self.fe.bodies
    }
    fn fe_bodies_mut(&mut self) -> &mut [FeBody] {
        &mut self.fe.bodies
    }
    fn fe_times(&self) -> crate::stage2::FeTimes {
        self.fe.times
    }
    fn fe_contacts(&self) -> usize {
        self.fe.contacts.len()
    }
    fn output(&self) -> &OutputSettings {
        &self.output
    }
    fn clock(&self) -> (u64, f64, u64) {
        (self.world.step, self.world.t, self.world.time.steps)
    }
    fn rigid_kinetic(&self) -> f64 {
        self.world.energies().0
    }
    fn write_rigid(&self, vtk: &mut VtkWriter, dir: &Path, frame: u32) -> std::io::Result<()> {
        Writer::<D2>::write(vtk, &self.world, dir, frame)
    }
    fn final_json(&self) -> String {
        nscdd::output::final_json(&self.world)
    }
}

impl FeRunnable for FeScene3 {
    fn step(&mut self) -> Result<StepReport, Diverged> {
        FeScene3::step(self)
    }
    fn fe_bodies(&self) -> &[FeBody] {
        &self.fe.bodies
    }
    fn fe_bodies_mut(&mut self) -> &mut [FeBody] {
        &mut self.fe.bodies
    }
    fn fe_times(&self) -> crate::stage2::FeTimes {
        self.fe.times
    }
    fn fe_contacts(&self) -> usize {
        self.fe.contacts.len()
    }
    fn output(&self) -> &OutputSettings {
        &self.output
    }
    fn clock(&self) -> (u64, f64, u64) {
        (self.world.step, self.world.t, self.world.time.steps)
    }
    fn rigid_kinetic(&self) -> f64 {
        self.world.energies().0
    }
    fn write_rigid(&self, vtk: &mut VtkWriter, dir: &Path, frame: u32) -> std::io::Result<()> {
        Writer::<nscdd::dim::D3>::write(vtk, &self.world, dir, frame)
    }
    fn final_json(&self) -> String {
        nscdd::output::final_json(&self.world)
    }
}

/// Runs the scene to its end, writing in `dir`. Errors: an unwritable output, or a
/// diverging step (the step and body named; what was written is kept).
pub fn run<S: FeRunnable>(s: &mut S, dir: &Path, mut progress: impl FnMut(u64, u64)) -> Result<FeSummary, String> {
    std::fs::create_dir_all(dir).map_err(io(dir, "the output directory"))?;
    let mut hist = std::io::BufWriter::new(std::fs::File::create(dir.join("history.csv")).map_err(io(dir, "history.csv"))?);
    writeln!(
        hist,
        "step,t,sweeps,converged,residual,contacts,deformable_contacts,kinetic_rigid,kinetic_deformable,elastic,load_potential_deformable"
    )
    .map_err(io(dir, "history.csv"))?;
    let mut vtk = VtkWriter::default();
    let mut frames: Vec<(f64, u32)> = vec![];
    let every = s.output().every.max(1);
    let t0 = std::time::Instant::now();
    let mut sum = FeSummary::default();
    let write_frame = |s: &S, vtk: &mut VtkWriter, frames: &mut Vec<(f64, u32)>| -> Result<(), String> {
        if !s.output().vtk {
            return Ok(());
        }
        let f = frames.len() as u32;
        s.write_rigid(vtk, dir, f).map_err(io(dir, "VTK frames"))?;
        for (bi, b) in s.fe_bodies().iter().enumerate() {
            let name = format!("deformable{bi}_{f:05}.vtu");
            std::fs::write(dir.join(&name), vtu(b)).map_err(io(dir, &name))?;
        }
        frames.push((s.clock().1, f));
        Ok(())
    };
    write_frame(s, &mut vtk, &mut frames)?;
    let n = s.clock().2;
    for _ in 0..n {
        let rep = match s.step() {
            Ok(r) => r,
            Err(d) => {
                hist.flush().ok();
                return Err(d.to_string());
            }
        };
        sum.steps += 1;
        sum.total_sweeps += rep.solve.sweeps as u64;
        if !rep.solve.converged {
            sum.unconverged_steps += 1;
        }
        let ek = s.rigid_kinetic();
        let ekf: f64 = s.fe_bodies().iter().map(|b| b.kinetic_energy()).sum();
        let el: f64 = s.fe_bodies().iter().map(|b| b.elastic_energy()).sum();
        let lp: f64 = s.fe_bodies().iter().map(|b| b.load_potential()).sum();
        let (step, t, _) = s.clock();
        writeln!(
            hist,
            "{},{:.9e},{},{},{:.3e},{},{},{:.9e},{:.9e},{:.9e},{:.9e}",
            step,
            t,
            rep.solve.sweeps,
            rep.solve.converged as u8,
            rep.solve.residual,
            rep.contacts,
            s.fe_contacts(),
            ek,
            ekf,
            el,
            lp
        )
        .map_err(io(dir, "history.csv"))?;
        if step % every == 0 {
            write_frame(s, &mut vtk, &mut frames)?;
        }
        progress(step, n);
    }
    hist.flush().map_err(io(dir, "history.csv"))?;
    Writer::<D2>::finish(&mut vtk, dir).map_err(io(dir, "VTK series"))?;
    if s.output().vtk {
        let mut pvd = String::from("<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\">\n<Collection>\n");
        for (t, f) in &frames {
            for bi in 0..s.fe_bodies().len() {
                let _ = writeln!(pvd, "<DataSet timestep=\"{t}\" part=\"{bi}\" file=\"deformable{bi}_{f:05}.vtu\"/>");
            }
        }
        pvd.push_str("</Collection>\n</VTKFile>\n");
        std::fs::write(dir.join("deformable.pvd"), pvd).map_err(io(dir, "deformable.pvd"))?;
    }
    let fe: Vec<serde_json::Value> = s
        .fe_bodies()
        .iter()
        .map(|b| {
            serde_json::json!({
                "name": b.name, "nodes": b.mesh.n_nodes(), "cells": b.mesh.n_cells(),
                "elastic": b.elastic, "scikit_fem": b.skfem_version,
                "max_displacement": b.u.iter().fold(0.0f64, |m, x| m.max(x.abs())),
                "kinetic_energy": b.kinetic_energy(), "elastic_energy": b.elastic_energy(),
                "displacement": b.u,
            })
        })
        .collect();
    let mut fin: serde_json::Value = serde_json::from_str(&s.final_json()).unwrap_or_default();
    if let Some(o) = fin.as_object_mut() {
        o.insert("deformable".into(), serde_json::Value::Array(fe));
    }
    std::fs::write(dir.join("final.json"), serde_json::to_string_pretty(&fin).unwrap()).map_err(io(dir, "final.json"))?;
    sum.wall_seconds = t0.elapsed().as_secs_f64();
    Ok(sum)
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
