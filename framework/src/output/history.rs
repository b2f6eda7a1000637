//! `history.csv`: one row per step, the same columns in 2D and 3D with the
//! dimension's names ([`History`]).

use crate::dd::DdStepReport;
use crate::dim::{Coords, Dim, Vector};
use crate::engine::StepReport;
use crate::world::{World, World3};
use std::io::Write;

/// Writes the history rows, each with one `write_all` (over an unbuffered file, a
/// run killed at any moment leaves whole lines); the columns are fixed when the run
/// starts:
///
/// - [`SOLVER_COLUMNS`]: the step, its solve and the energies;
/// - per named or driven body `_x, _y[, _z]`, its rotation (`_rot` in 2D, the
///   rotation vector `_rx, _ry, _rz` in 3D), the contact force resultant
///   `_fx, _fy[, _fz]` (N) and moment (`_m` in 2D, `_mx, _my, _mz` in 3D);
/// - with a box sample (`[output] box` / `box3`): `solid_fraction`, `eps1` (along
///   the last axis), `sigma_xx, sigma_yy[, sigma_zz]` (Pa, compression positive),
///   `p` (mean), `q` (axial − mean lateral), `q_over_p`, `sin_phi`
///   ((σ_axial − σ_lateral)/(σ_axial + σ_lateral)), `z` (grain–grain
///   coordination), `z_m` (loaded contacts per grain without the rattlers), and in
///   3D, away from the walls (inner box shrunk by 4 largest radii,
///   [`World3::bulk_measures`](crate::world::World3)), `nu_bulk, z_bulk,
///   rattlers_bulk`;
/// - the stage timings, then with NSCDD [`DD_COLUMNS`].
pub struct History<W: Write, D: Dim> {
    out: W,
    /// Bodies with their own columns: named or driven ones.
    tracked: Vec<(u32, String)>,
    has_box: bool,
    /// NSCDD columns (a decomposed run).
    dd: bool,
    /// Margin of the 3D bulk measures: 4 × the largest grain radius.
    margin: f64,
    _dim: std::marker::PhantomData<D>,
}

/// The NSCDD columns, after the timings.
pub const DD_COLUMNS: [&str; 10] = [
    "nscdd_iterations",
    "egluing",
    "egluing_rel",
    "interface_bodies",
    "links",
    "migrations",
    "prevailing",
    "subdomains",
    "repartitioned",
    "imbalance",
];

/// Column suffixes of a tracked body: position, rotation, force, moment.
fn body_columns(n: usize) -> Vec<&'static str> {
    if n == 2 {
        vec!["x", "y", "rot", "fx", "fy", "m"]
    } else {
        vec!["x", "y", "z", "rx", "ry", "rz", "fx", "fy", "fz", "mx", "my", "mz"]
    }
}

impl<W: Write, D: Dim> History<W, D> {
    pub fn new(out: W, w: &World<D>) -> std::io::Result<Self> {
        Self::with_columns(out, w, false, &[])
    }

    /// With `dd`, the NSCDD columns [`DD_COLUMNS`] follow the timings; `extra`
    /// columns (the body families') come last.
    pub fn with_columns(mut out: W, w: &World<D>, dd: bool, extra: &[String]) -> std::io::Result<Self> {
        let tracked: Vec<(u32, String)> = w
            .observed()
            .into_iter()
            .map(|b| {
                (
                    w.ids.global(b),
                    w.names[b as usize].clone().unwrap_or_else(|| format!("body{}", w.ids.global(b))),
                )
            })
            .collect();
        let has_box = w.box_walls.is_some();
        let mut head = String::from(SOLVER_COLUMNS);
        for (_, n) in &tracked {
            for c in body_columns(D::N) {
                head.push_str(&format!(",{n}_{c}"));
            }
        }
        if has_box {
            head.push_str(if D::N == 2 {
                ",solid_fraction,eps1,sigma_xx,sigma_yy,p,q,q_over_p,sin_phi,z,z_m"
            } else {
                ",solid_fraction,eps1,sigma_xx,sigma_yy,sigma_zz,p,q,q_over_p,sin_phi,z,z_m,nu_bulk,z_bulk,rattlers_bulk"
            });
        }
        head.push_str(",t_detect,t_delassus,t_nlgs,t_update,t_output");
        if dd {
            for c in DD_COLUMNS {
                head.push(',');
                head.push_str(c);
            }
        }
        for c in extra {
            head.push(',');
            head.push_str(c);
        }
        head.push('\n');
        out.write_all(head.as_bytes())?;
        let margin = 4.0 * w.max_grain_size();
        Ok(History {
            out,
            tracked,
            has_box,
            dd,
            margin,
            _dim: std::marker::PhantomData,
        })
    }

    pub fn row(&mut self, w: &World<D>, r: &StepReport, t_output: f64) -> std::io::Result<()> {
        self.row_dd(w, r, None, t_output, &[])
    }

    /// A row; `dd` fills the NSCDD columns (empty when the history has them and
    /// `dd` is `None`), `extra` the extra columns.
    pub fn row_dd(&mut self, w: &World<D>, r: &StepReport, dd: Option<&DdStepReport>, t_output: f64, extra: &[f64]) -> std::io::Result<()> {
        // NSCDD's counts (the same as the world's in one process; exact on ranks) and
        // sums over bodies (per cell, in cell order)
        let census = dd.and_then(|d| d.census);
        let (ek, ep) = census.and_then(|c| c.energies).unwrap_or_else(|| w.energies());
        let mut r = *r;
        if let Some(c) = census {
            r.contacts = c.contacts;
        }
        let mut s = solver_fields(w.step, w.t, w.ids.n_global(w.bodies.len()), &r, ek, ep);
        let h = w.time.h;
        for (g, _) in &self.tracked {
            // (a tracked body is held by every process: its slot may change)
            let b = w.ids.slot(*g).expect("a tracked body is held") as usize;
            let (p, f) = (w.bodies.pos[b], w.reaction[b]);
            let rot = D::rot_to_vec(&w.bodies.rot[b]);
            for x in p.as_ref().iter().chain(rot.coords()) {
                s.push_str(&format!(",{x:e}"));
            }
            for x in f.as_ref() {
                s.push_str(&format!(",{:e}", x / h));
            }
        }
        if self.has_box {
            box_fields(w, self.margin, census.filter(|c| !c.z.is_nan()), &mut s);
        }
        let tm = r.times;
        s.push_str(&format!(
            ",{:e},{:e},{:e},{:e},{:e}",
            tm.detect, tm.delassus, tm.nlgs, tm.update, t_output
        ));
        if self.dd {
            s.push_str(&dd_fields(dd));
        }
        for x in extra {
            s.push_str(&format!(",{x:e}"));
        }
        // one write per row: an unbuffered sink never holds half a line
        s.push('\n');
        self.out.write_all(s.as_bytes())
    }

    pub fn flush(&mut self) -> std::io::Result<()> {
        self.out.flush()
    }
}

/// The box sample's fields of a row (see [`History`]).
fn box_fields<D: Dim>(w: &World<D>, margin: f64, census: Option<crate::dd::Census>, s: &mut String) {
    let nu = w.solid_fraction().unwrap_or(f64::NAN);
    let height = w.box_extent().map_or(f64::NAN, |e| e.max[D::N - 1] - e.min[D::N - 1]);
    let eps1 = w.box_h0.map_or(0.0, |h0| (h0 - height) / h0);
    let sg = w.box_stresses().unwrap_or(D::Point::from_fn(|_| f64::NAN));
    let axial = sg[D::N - 1];
    let lateral = (0..D::N - 1).map(|k| sg[k]).sum::<f64>() / (D::N - 1) as f64;
    let p = (0..D::N).map(|k| sg[k]).sum::<f64>() / D::N as f64;
    let q = axial - lateral;
    let sin_phi = if axial + lateral != 0.0 { q / (axial + lateral) } else { 0.0 };
    s.push_str(&format!(",{nu:e},{eps1:e}"));
    for k in 0..D::N {
        s.push_str(&format!(",{:e}", sg[k]));
    }
    let (z, zm) = census.map_or_else(|| w.coordination(), |c| (c.z, c.z_m));
    let q_over_p = if p != 0.0 { q / p } else { 0.0 };
    s.push_str(&format!(",{p:e},{q:e},{q_over_p:e},{sin_phi:e},{z:e},{zm:e}"));
    if let Some(w3) = (w as &dyn std::any::Any).downcast_ref::<World3>() {
        let (counts, vol) = (census.and_then(|c| c.bulk), census.and_then(|c| c.bulk_volume));
        let (nb, zb, rb) = w3.bulk_measures_with(margin, counts, vol).unwrap_or((f64::NAN, f64::NAN, f64::NAN));
        s.push_str(&format!(",{nb:e},{zb:e},{rb:e}"));
    }
}

/// The NSCDD fields of a history row (empty fields without a report).
pub fn dd_fields(dd: Option<&DdStepReport>) -> String {
    match dd {
        Some(d) => format!(
            ",{},{:e},{:e},{},{},{},{},{},{},{:e}",
            d.stages,
            d.egluing,
            d.egluing_rel,
            d.interface_bodies,
            d.links,
            d.migrations,
            d.prevailing.name(),
            d.subdomains,
            d.repartitioned as u8,
            d.imbalance
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
