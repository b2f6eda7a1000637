//! `history.csv`: one row per step.

use crate::dd::DdStepReport;
use crate::engine::StepReport;
use crate::world::World2;
use std::io::Write;

/// Writes the history rows; the columns are fixed when the run starts.
pub struct History<W: Write> {
    out: W,
    /// Bodies with their own columns: named or driven ones.
    tracked: Vec<(u32, String)>,
    has_box: bool,
    /// NSCDD columns (a decomposed run).
    dd: bool,
}

/// The NSCDD columns, after the timings.
pub const DD_COLUMNS: [&str; 8] = [
    "nscdd_iterations",
    "egluing",
    "egluing_rel",
    "interface_bodies",
    "links",
    "migrations",
    "prevailing",
    "subdomains",
];

impl<W: Write> History<W> {
    pub fn new(out: W, w: &World2) -> std::io::Result<Self> {
        Self::with_columns(out, w, false)
    }

    /// With `dd`, the NSCDD columns [`DD_COLUMNS`] follow the timings.
    pub fn with_columns(mut out: W, w: &World2, dd: bool) -> std::io::Result<Self> {
        let mut tracked: Vec<(u32, String)> = vec![];
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
            for c in ["x", "y", "rot", "fx", "fy", "m"] {
                head.push_str(&format!(",{n}_{c}"));
            }
        }
        if has_box {
            head.push_str(",solid_fraction,eps1,sigma1,sigma2,sin_phi");
        }
        head.push_str(",t_detect,t_delassus,t_nlgs,t_update,t_output");
        if dd {
            for c in DD_COLUMNS {
                head.push(',');
                head.push_str(c);
            }
        }
        writeln!(out, "{head}")?;
        Ok(History { out, tracked, has_box, dd })
    }

    pub fn row(&mut self, w: &World2, r: &StepReport, t_output: f64) -> std::io::Result<()> {
        self.row_dd(w, r, None, t_output)
    }

    /// A row; `dd` fills the NSCDD columns (empty when the history has them and
    /// `dd` is `None`).
    pub fn row_dd(&mut self, w: &World2, r: &StepReport, dd: Option<&DdStepReport>, t_output: f64) -> std::io::Result<()> {
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
                w.bodies.rot[b],
                f[0] / h,
                f[1] / h,
                f[2] / h
            ));
        }
        if self.has_box {
            let (nu, eps1, s1, s2, sphi) = box_measures(w);
            s.push_str(&format!(",{nu:e},{eps1:e},{s1:e},{s2:e},{sphi:e}"));
        }
        let tm = r.times;
        s.push_str(&format!(
            ",{:e},{:e},{:e},{:e},{:e}",
            tm.detect, tm.delassus, tm.nlgs, tm.update, t_output
        ));
        if self.dd {
            s.push_str(&dd_fields(dd));
        }
        writeln!(self.out, "{s}")
    }

    pub fn flush(&mut self) -> std::io::Result<()> {
        self.out.flush()
    }
}

/// Box sample measures: solid fraction ν, axial strain ε1 = (H0 − H)/H0, mean wall
/// stresses σ1 = (|F_top| + |F_bottom|)/(2W) and σ2 = (|F_left| + |F_right|)/(2H)
/// from the contact forces on the walls, and sin φ = (σ1 − σ2)/(σ1 + σ2).
pub fn box_measures(w: &World2) -> (f64, f64, f64, f64, f64) {
    let (Some(bw), Some(e)) = (&w.box_walls, w.box_extent()) else {
        return (f64::NAN, f64::NAN, f64::NAN, f64::NAN, f64::NAN);
    };
    let h = w.time.h;
    let (width, height) = (e.max[0] - e.min[0], e.max[1] - e.min[1]);
    let [left, right, bottom, top, ..] = bw.walls;
    let f = |b: u32, k: usize| w.reaction[b as usize][k].abs() / h;
    let s1 = (f(top, 1) + f(bottom, 1)) / (2.0 * width);
    let s2 = (f(left, 0) + f(right, 0)) / (2.0 * height);
    let sphi = if s1 + s2 > 0.0 { (s1 - s2) / (s1 + s2) } else { 0.0 };
    let eps1 = w.box_h0.map(|h0| (h0 - height) / h0).unwrap_or(0.0);
    (w.solid_fraction().unwrap_or(f64::NAN), eps1, s1, s2, sphi)
}

/// The NSCDD fields of a history row (empty fields without a report).
pub fn dd_fields(dd: Option<&DdStepReport>) -> String {
    match dd {
        Some(d) => format!(
            ",{},{:e},{:e},{},{},{},{},{}",
            d.stages,
            d.egluing,
            d.egluing_rel,
            d.interface_bodies,
            d.links,
            d.migrations,
            d.prevailing.name(),
            d.subdomains
        ),
        None => ",".repeat(DD_COLUMNS.len()),
    }
}

/// The first columns of every history (2D and 3D): the step and its solve.
pub const SOLVER_COLUMNS: &str =
    "step,time,bodies,contacts,active,sweeps,converged,QuadDV,QuadDVR,MaxmDV,MaxmDVR,MeanDVoR,residual,kinetic_energy,potential_energy";

/// The fields of [`SOLVER_COLUMNS`] for one step.
pub fn solver_fields(step: u64, t: f64, bodies: usize, r: &StepReport, ek: f64, ep: f64) -> String {
    let n = &r.solve.norms;
    format!(
        "{},{},{},{},{},{},{},{:e},{:e},{:e},{:e},{:e},{:e},{:e},{:e}",
        step,
        t,
        bodies,
        r.contacts,
        n.nactif,
        r.solve.sweeps,
        r.solve.converged as u8,
        n.quad_dv,
        n.quad_dvr,
        n.maxm_dv,
        n.maxm_dvr,
        n.mean_dvor,
        r.solve.residual,
        ek,
        ep
    )
}
