//! The sides of a continuum region (docs/CONTINUUM.md): a side moved at a
//! prescribed velocity (`drive = { top = [vx, vy] }`: its nodes held on that
//! velocity, as a platen; a component `"free"` leaves that direction free, a
//! frictionless platen or roller), a traction on a side (`load = { left = [tx, ty] }`, in Pa:
//! force per unit area, weighted by the band's α at each facet, the continuum's
//! share of the boundary), and the reaction of a driven side for the history.

use crate::body::FeBody;
use crate::mesh::Mesh;
use crate::scene::fixed_nodes;
use nscdd::family::EntryError;

/// A driven side: its name, its nodes, their degrees of freedom, the velocity and
/// the time it starts (before it, the side is free, under its `load` if any: a
/// force-controlled consolidation, then a platen).
#[derive(Clone, Debug)]
pub struct Driven {
    pub side: String,
    pub nodes: Vec<u32>,
    pub dofs: Vec<usize>,
    pub velocity: Vec<f64>,
    pub from: f64,
    pub held: bool,
    /// The side's own traction (F_ext's share, dof and value), taken off F_ext
    /// when the side is held (a held side carries no load: its reaction is the
    /// platen's).
    pub traction: Vec<(usize, f64)>,
}

/// `drive` and `load` of entry `i` (tables of side → vector of `dim` numbers; a
/// drive's component may be `"free"`, read as NaN).
pub fn sides_of(i: usize, e: &toml::Table, key: &str, dim: usize) -> Result<Vec<(String, Vec<f64>)>, EntryError> {
    let at = |message: String| crate::scene::entry_error(i, key, message);
    let Some(v) = e.get(key) else { return Ok(vec![]) };
    let t = v
        .as_table()
        .ok_or_else(|| at(format!("`{key} = {{ side = [{dim} numbers], … }}`")))?;
    let mut out = vec![];
    for (side, x) in t {
        let free = |y: &toml::Value| key == "drive" && y.as_str() == Some("free");
        let xs: Vec<f64> = x
            .as_array()
            .map(|a| {
                let num = |y: &toml::Value| y.as_float().or(y.as_integer().map(|n| n as f64));
                a.iter()
                    .filter_map(|y| {
                        if free(y) {
                            Some(f64::NAN)
                        } else {
                            num(y).filter(|v| v.is_finite())
                        }
                    })
                    .collect()
            })
            .unwrap_or_default();
        if xs.len() != dim || x.as_array().is_none_or(|a| a.len() != dim) || xs.iter().all(|y| y.is_nan()) {
            let what = if key == "drive" { " (or \"free\", not all)" } else { "" };
            return Err(at(format!("side `{side}`: {dim} finite numbers{what}")));
        }
        out.push((side.clone(), xs));
    }
    Ok(out)
}

/// The driven sides (from time `from`, with the side's own traction of `loads` to
/// take off F_ext then); errors name the side. Those driven from the start are held
/// at once ([`start`]).
pub fn drive(
    b: &mut FeBody,
    sides: &[(String, Vec<f64>)],
    from: f64,
    loads: &[(String, Vec<(usize, f64)>)],
) -> Result<Vec<Driven>, String> {
    let d = b.dim();
    let mut out = vec![];
    for (side, v) in sides {
        let nodes = fixed_nodes(&b.mesh, std::slice::from_ref(side))?;
        // the driven components only ("free" ones: NaN)
        let dofs: Vec<usize> = nodes
            .iter()
            .flat_map(|&k| (0..d).map(move |c| d * k as usize + c))
            .filter(|&i| !v[i % d].is_nan())
            .collect();
        let traction = loads.iter().find(|l| &l.0 == side).map_or_else(Vec::new, |l| l.1.clone());
        out.push(Driven {
            side: side.clone(),
            traction: traction.into_iter().filter(|x| dofs.binary_search(&x.0).is_ok()).collect(),
            nodes,
            dofs,
            velocity: v.clone(),
            from,
            held: false,
        });
    }
    start(b, &mut out, 0.0);
    Ok(out)
}

/// At time `t` (a step's start): holds the sides whose drive has started (their
/// nodes fixed: M̂ is refactored at the next free velocity; returns whether one
/// started) and sets the held degrees of freedom's V (M̂'s held rows keep it).
pub fn start(b: &mut FeBody, driven: &mut [Driven], t: f64) -> bool {
    let d = b.dim();
    let mut started = false;
    for s in driven.iter_mut() {
        if !s.held && t >= s.from {
            b.fix_dofs(&s.dofs);
            for &(i, f) in &s.traction {
                b.f_ext[i] -= f;
            }
            s.held = true;
            started = true;
        }
        if s.held {
            for &i in &s.dofs {
                b.v[i] = s.velocity[i % d];
            }
        }
    }
    started
}

/// Adds the tractions of `sides` to F_ext: each boundary facet on a side gets
/// α(facet centroid) × t × its measure, shared equally by its nodes. Returns each
/// side's nonzero shares (side, [(dof, force)]).
pub fn load(
    b: &mut FeBody,
    sides: &[(String, Vec<f64>)],
    alpha: &dyn Fn(&[f64]) -> f64,
) -> Result<Vec<(String, Vec<(usize, f64)>)>, String> {
    let mut shares = vec![];
    let d = b.dim();
    for (side, t) in sides {
        let nodes = fixed_nodes(&b.mesh, std::slice::from_ref(side))?;
        let m: &Mesh = &b.mesh;
        let mut f = vec![0.0; b.n_dofs()];
        let mut area = 0.0;
        for s in 0..m.n_facets() {
            let fct = m.facet(s);
            if !fct.iter().all(|k| nodes.binary_search(k).is_ok()) {
                continue;
            }
            let a = facet_measure(m, fct);
            let mut c = [0.0; 3];
            for &k in fct {
                for (x, y) in c.iter_mut().zip(m.node(k as usize)) {
                    *x += y / d as f64;
                }
            }
            let w = alpha(&c[..d]) * a / d as f64;
            area += a;
            for &k in fct {
                for (cc, tc) in t.iter().enumerate() {
                    f[d * k as usize + cc] += w * tc;
                }
            }
        }
        if !(area > 0.0) {
            return Err(format!("side `{side}` has no boundary facet"));
        }
        for (x, y) in b.f_ext.iter_mut().zip(&f) {
            *x += y;
        }
        shares.push((
            side.clone(),
            f.iter().enumerate().filter(|x| *x.1 != 0.0).map(|(i, &y)| (i, y)).collect(),
        ));
    }
    Ok(shares)
}

/// Length (2D) or area (3D) of a boundary facet.
fn facet_measure(m: &Mesh, f: &[u32]) -> f64 {
    let d = m.dim;
    let p = |k: u32| m.node(k as usize).to_vec();
    if d == 2 {
        let (a, b) = (p(f[0]), p(f[1]));
        ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2)).sqrt()
    } else {
        let (a, b, c) = (p(f[0]), p(f[1]), p(f[2]));
        let u = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
        let v = [c[0] - a[0], c[1] - a[1], c[2] - a[2]];
        let w = [u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]];
        0.5 * (w[0] * w[0] + w[1] * w[1] + w[2] * w[2]).sqrt()
    }
}

/// The forces the driven sides `driven` apply to the region (N, or N/m in 2D),
/// their static part: Σ over each side's degrees of freedom of K u − f_p − F_ext
/// (the internal force the side holds against the loads; K u made once).
pub fn reactions(b: &FeBody, driven: &[Driven]) -> Vec<Vec<f64>> {
    let d = b.dim();
    let mut f: Vec<f64> = b.f_ext.iter().map(|x| -x).collect();
    b.mul_add(0.0, 1.0, &b.u, &mut f);
    for (x, y) in f.iter_mut().zip(&b.f_plastic) {
        *x -= y;
    }
    driven
        .iter()
        .map(|s| {
            let mut r = vec![0.0; d];
            for &i in &s.dofs {
                r[i % d] += f[i];
            }
            r
        })
        .collect()
}

/// [`reactions`] of one side.
pub fn reaction(b: &FeBody, s: &Driven) -> Vec<f64> {
    reactions(b, std::slice::from_ref(s)).swap_remove(0)
}
