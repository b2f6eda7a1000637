//! The `[[continuum]]` section ([`super`] for its keys): the regions built by
//! scikit-fem with their cells weighted by the band, the grains tied to them, and
//! the family's outputs and saved state (`families.continuum`: per region u and V,
//! per tie its grain and λ).

use super::band::{band_of, Band};
use super::ties::TieSet;
use super::{Continuum, SECTION};
use crate::body::FeBody;
use crate::mesh::{gradients, Mesh};
use crate::scene::entry_error;
use nscdd::dd::{Family, Rigid};
use nscdd::dim::{Dim, D2, D3};
use nscdd::engine::Diverged;
use nscdd::family::{EntryError, FamilyContext, FamilyKind, SceneFamily};
use nscdd::world::World;
use serde::{Deserialize, Serialize};
use std::any::Any;
use std::path::Path;

/// Builds the continuum regions of a scene's `[[continuum]]` entries.
pub struct ContinuumKind;

impl FamilyKind<D2> for ContinuumKind {
    fn load(&self, entries: &[toml::Table], cx: &FamilyContext<'_, D2>) -> Result<Box<dyn SceneFamily<D2>>, EntryError> {
        Ok(Box::new(load::<D2, 2>(entries, cx)?))
    }
    fn load_boxes(
        &self,
        entries: &[toml::Table],
        cx: &FamilyContext<'_, D2>,
        _: Option<&serde_json::Value>,
    ) -> Result<Option<Vec<[[f64; 3]; 2]>>, EntryError> {
        load_boxes(entries, cx.dir, 2).map(Some)
    }
}

impl FamilyKind<D3> for ContinuumKind {
    fn load(&self, entries: &[toml::Table], cx: &FamilyContext<'_, D3>) -> Result<Box<dyn SceneFamily<D3>>, EntryError> {
        Ok(Box::new(load::<D3, 3>(entries, cx)?))
    }
    fn load_boxes(
        &self,
        entries: &[toml::Table],
        cx: &FamilyContext<'_, D3>,
        _: Option<&serde_json::Value>,
    ) -> Result<Option<Vec<[[f64; 3]; 2]>>, EntryError> {
        load_boxes(entries, cx.dir, 3).map(Some)
    }
}

/// The keys of a `[[continuum]]` entry beside a deformable body's.
const CONTINUUM_KEYS: [&str; 7] = ["band", "coupling", "plastic", "drive", "drive_from", "load", "initial_stress"];

/// The regions' mesh boxes ([`FamilyKind::load_boxes`]): the load ties the grains
/// lying in a region's mesh, and the family touches no other world body (restarted
/// too: it names the grains tied at the load, and a region has no contacts).
fn load_boxes(entries: &[toml::Table], dir: &Path, dim: usize) -> Result<Vec<[[f64; 3]; 2]>, EntryError> {
    let mut out = Vec::new();
    for (i, e) in entries.iter().enumerate() {
        let mut rest = e.clone();
        CONTINUUM_KEYS.iter().for_each(|k| drop(rest.remove(*k)));
        let spec = crate::scene::spec_of(i, &rest)?;
        out.push(crate::scene::mesh_box(&spec.mesh, dim, dir).map_err(|(k, m)| entry_error(i, k, m))?);
    }
    Ok(out)
}

/// How the band's grains are tied ([`super::ties`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Coupling {
    /// One tie per grain: v_p = N(ξ_p) V.
    Grain,
    /// One tie per node: the grains' mass-weighted mean velocity around each node.
    Node,
}

fn coupling_of(i: usize, e: &toml::Table) -> Result<Coupling, EntryError> {
    match e.get("coupling").map(|v| v.as_str()) {
        None | Some(Some("node")) => Ok(Coupling::Node),
        Some(Some("grain")) => Ok(Coupling::Grain),
        Some(_) => Err(entry_error(
            i,
            "coupling",
            "`node` (one tie per band node, the default) or `grain` (one tie per band grain)",
        )),
    }
}

/// `plastic = { friction, dilatancy, cohesion }` (degrees, degrees, Pa): a
/// Drucker–Prager continuum ([`super::plastic`]).
#[derive(Deserialize, Debug, Clone, Copy)]
#[serde(deny_unknown_fields)]
struct DpSpec {
    friction: f64,
    #[serde(default)]
    dilatancy: f64,
    #[serde(default)]
    cohesion: f64,
    /// Friction hardening: the mobilized angle grows from `initial_friction` to
    /// `friction` with the plastic shear strain (`hardening_strain`: κ_h, where
    /// half of the rise is reached in sin φ).
    #[serde(default)]
    initial_friction: Option<f64>,
    #[serde(default)]
    hardening_strain: Option<f64>,
}

fn plastic_of(i: usize, e: &toml::Table) -> Result<Option<DpSpec>, EntryError> {
    let at = |message: String| entry_error(i, "plastic", message);
    let Some(v) = e.get("plastic") else { return Ok(None) };
    let d = DpSpec::deserialize(v.clone()).map_err(|x| at(x.message().to_string()))?;
    if !(d.friction >= 0.0 && d.friction < 90.0) || !(d.dilatancy >= 0.0 && d.dilatancy <= d.friction) {
        return Err(at(format!(
            "friction in [0, 90) degrees and dilatancy in [0, friction], got {} and {}",
            d.friction, d.dilatancy
        )));
    }
    if !(d.cohesion >= 0.0 && d.cohesion.is_finite()) || (d.friction == 0.0 && d.cohesion == 0.0) {
        return Err(at("cohesion ≥ 0 (and > 0 when friction is 0)".into()));
    }
    if let Some(m) = super::plastic::Hardening::check(d.friction, d.initial_friction, d.hardening_strain) {
        return Err(at(m));
    }
    Ok(Some(d))
}

/// A region's Drucker–Prager state (None: elastic), at its initial stress if any,
/// one a cell (an elastic region with one gets a cone it never leaves, c = ∞).
fn plastic_state(
    b: &FeBody,
    dp: Option<DpSpec>,
    sigma0: Option<Vec<[[f64; 3]; 3]>>,
    alpha: &[f64],
) -> Result<Option<super::plastic::Plastic>, (&'static str, String)> {
    let el = b.elastic;
    if (dp.is_some() || sigma0.is_some()) && el.plane_stress {
        let key = if dp.is_some() { "plastic" } else { "initial_stress" };
        return Err((
            key,
            "the Drucker–Prager and prestressed continuum is in plane strain (no `plane = \"stress\"`)".into(),
        ));
    }
    let dp = dp.or(sigma0.as_ref().map(|_| DpSpec {
        friction: 0.0,
        dilatancy: 0.0,
        cohesion: f64::INFINITY,
        initial_friction: None,
        hardening_strain: None,
    }));
    let mut p = dp.map(|d| {
        let p = super::plastic::Plastic::new(&b.mesh, d.friction, d.dilatancy, d.cohesion, el.young, el.poisson, alpha);
        match (d.initial_friction, d.hardening_strain) {
            (Some(f0), Some(k)) => p.with_hardening(d.friction, f0, k),
            _ => p,
        }
    });
    if let (Some(p), Some(mut s0)) = (p.as_mut(), sigma0) {
        for s in s0.iter_mut().filter(|s| s[2][2].is_nan()) {
            s[2][2] = el.poisson * (s[0][0] + s[1][1]);
        }
        p.prestress(&s0);
    }
    Ok(p)
}

/// A band grain: world id, cell, barycentric coordinates, share w_p of its mass.
type BandGrain = (u32, usize, [f64; 4], f64);

/// Regions and ties of the entries (module docs).
fn load<D: Dim, const N: usize>(entries: &[toml::Table], cx: &FamilyContext<'_, D>) -> Result<Continuum<D, N>, EntryError> {
    let w = cx.world;
    let (mut bodies, mut ties, mut band_all) = (Vec::new(), TieSet::<N>::default(), Vec::new());
    let (mut bands, mut band_region) = (Vec::new(), Vec::new());
    let (mut plastic, mut driven) = (Vec::new(), Vec::new());
    let mut tied = vec![false; w.bodies.len()];
    let mut held = 0.0;
    for (i, e) in entries.iter().enumerate() {
        let at = |key: &str, message: String| entry_error(i, key, message);
        let band = band_of(i, e, N)?;
        let coupling = coupling_of(i, e)?;
        let dp = plastic_of(i, e)?;
        let sigma0 = super::initial::of(i, e, N, &w.gravity.as_ref()[..N])?;
        let drives = super::sides::sides_of(i, e, "drive", N)?;
        let from = match e.get("drive_from") {
            None => 0.0,
            Some(v) => v
                .as_float()
                .or(v.as_integer().map(|n| n as f64))
                .filter(|x| x.is_finite() && *x >= 0.0)
                .ok_or_else(|| at("drive_from", "a time ≥ 0 (s)".into()))?,
        };
        let loads = super::sides::sides_of(i, e, "load", N)?;
        let mut rest = e.clone();
        CONTINUUM_KEYS.iter().for_each(|k| drop(rest.remove(*k)));
        let spec = crate::scene::spec_of(i, &rest)?;
        let mut memory = |nodes: f64| {
            let bytes = crate::scene::mesh_bytes(N, nodes);
            cx.check_memory(held + bytes, &format!("a continuum region of about {nodes:.0} nodes"))
                .map(|()| held += bytes)
        };
        // each cell's gradients and centroid and its α, made once with the mesh
        let made: std::cell::RefCell<(Vec<CellFrame>, Vec<f64>)> = Default::default();
        let scale = |m: &Mesh| {
            let frames = cell_frames(m);
            let alpha = cell_weights(&frames, m.dim, &band).map_err(|msg| ("band", msg))?;
            *made.borrow_mut() = (frames, alpha.clone());
            Ok(Some(alpha))
        };
        let mut b = crate::scene::build_with(&spec, &w.materials, N, cx.dir, &mut memory, crate::scene::Assembly::Scaled(&scale))
            .map_err(|(k, m)| at(k, m))?;
        let (frames, alpha) = made.into_inner();
        b.set_gravity(&w.gravity.as_ref()[..N]);
        let shares = super::sides::load(&mut b, &loads, &|x| band.alpha(x)).map_err(|m| at("load", m))?;
        driven.push(super::sides::drive(&mut b, &drives, from, &shares).map_err(|m| at("drive", m))?);
        b.factorize(w.time.h, w.time.theta).map_err(|m| at("", m))?;
        let sigma0 = match sigma0 {
            Some(s) => Some(
                super::initial::per_cell(&s, &b.mesh, &frames, b.elastic.density, b.elastic.poisson, w.gravity.as_ref())
                    .map_err(|m| at("initial_stress", m))?,
            ),
            None => None,
        };
        plastic.push(plastic_state(&b, dp, sigma0, &alpha).map_err(|(k, m)| at(k, m))?);
        let mut grains: Vec<BandGrain> = Vec::new();
        // (by slot: on MPI ranks the world may hold a part, every body near the
        // regions among it, [`FamilyKind::load_boxes`])
        for k in 0..w.bodies.len() {
            let g = w.ids.global(k as u32) as usize;
            if tied[k] || !Rigid::<D>::is_grain(w, g) || !w.bodies.movable(k) {
                continue;
            }
            let x = &w.bodies.pos[k].as_ref()[..N];
            let alpha = band.alpha(x);
            if alpha <= 0.0 {
                continue;
            }
            let Some((cell, xi)) = locate(&frames, N, x) else { continue };
            if alpha >= 1.0 {
                return Err(at("band", format!("body {g} (a grain) lies in the continuum part of the region, beyond the band: grains belong to the discrete part and the band")));
            }
            tied[k] = true;
            grains.push((g as u32, cell, xi, 1.0 - alpha));
        }
        let body = bodies.len() as u32;
        let mass = |g: u32, wp: f64| wp * w.bodies.mass[crate::family::slot(w, g)];
        push_ties(&mut ties, body, &b.mesh, &grains, coupling, &mass);
        band_all.extend(grains.iter().map(|x| (x.0, x.3)));
        band_region.extend(grains.iter().map(|x| (x.0, bodies.len() as u32)));
        bands.push(band);
        bodies.push(b);
    }
    band_all.sort_unstable_by_key(|x| x.0);
    let mut c = Continuum::new(bodies, plastic, ties, band_all);
    c.driven = driven;
    c.bands = bands;
    c.band_region = band_region;
    Ok(c)
}

/// The ties of one region's band grains (mesh node ids; [`super::ties`] for the two
/// couplings). `mass(g, w_p)`: the grain's band mass m̃.
fn push_ties<const N: usize>(
    ties: &mut TieSet<N>,
    body: u32,
    mesh: &Mesh,
    grains: &[BandGrain],
    coupling: Coupling,
    mass: &dyn Fn(u32, f64) -> f64,
) {
    let nodes_of = |cell: usize| mesh.cell(cell);
    match coupling {
        Coupling::Grain => {
            for &(g, cell, xi, _) in grains {
                ties.push(body, [(g, 1.0)], (0..=N).map(|q| (nodes_of(cell)[q], xi[q])));
            }
        }
        Coupling::Node => {
            // each grain to the node of its cell with the largest weight N_k(ξ_p)
            // (the lower node id on a tie): the nodes' grain sets are disjoint, so
            // the ties are independent (no redundant multipliers)
            let mut per_node: std::collections::BTreeMap<u32, Vec<usize>> = Default::default();
            for (ip, &(_, cell, xi, _)) in grains.iter().enumerate() {
                let nodes = nodes_of(cell);
                let q = (0..=N)
                    .max_by(|&a, &b| xi[a].total_cmp(&xi[b]).then(nodes[b].cmp(&nodes[a])))
                    .unwrap_or(0);
                per_node.entry(nodes[q]).or_default().push(ip);
            }
            for list in per_node.values() {
                let m: Vec<f64> = list.iter().map(|&ip| mass(grains[ip].0, grains[ip].3)).collect();
                let s: f64 = m.iter().sum();
                let mut b: std::collections::BTreeMap<u32, f64> = Default::default();
                for (&ip, &mp) in list.iter().zip(&m) {
                    let (_, cell, xi, _) = grains[ip];
                    for q in 0..=N {
                        *b.entry(nodes_of(cell)[q]).or_default() += mp / s * xi[q];
                    }
                }
                let gs: Vec<(u32, f64)> = list.iter().zip(&m).map(|(&ip, &mp)| (grains[ip].0, mp / s)).collect();
                ties.push(body, gs, b);
            }
        }
    }
}

/// A cell's shape-function gradients (D + 1 rows) and centroid, reference mesh.
pub type CellFrame = ([[f64; 3]; 4], [f64; 3]);

/// The [`CellFrame`] of every cell.
pub fn cell_frames(m: &Mesh) -> Vec<CellFrame> {
    let (d, nv) = (m.dim, m.dim + 1);
    (0..m.n_cells())
        .map(|e| {
            let c = m.cell(e);
            let mut g = [[0.0; 3]; 4];
            g[..nv].copy_from_slice(&gradients(d, &m.x0, c));
            let mut centroid = [0.0; 3];
            for &k in c {
                for (y, z) in centroid.iter_mut().zip(m.node(k as usize)) {
                    *y += z / nv as f64;
                }
            }
            (g, centroid)
        })
        .collect()
}

/// α at each cell's centroid; every cell must have α > 0 (a cell wholly on the
/// discrete side would have neither mass nor stiffness).
fn cell_weights(frames: &[CellFrame], d: usize, band: &Band) -> Result<Vec<f64>, String> {
    let mut out = Vec::with_capacity(frames.len());
    for (e, (_, c)) in frames.iter().enumerate() {
        let a = band.alpha(&c[..d]);
        if !(a > 0.0) {
            return Err(format!(
                "cell {e} (centroid {:?}) lies on the discrete side of the band: the mesh must end at the band's discrete edge",
                &c[..d]
            ));
        }
        out.push(a);
    }
    Ok(out)
}

/// The cell holding point x and its barycentric coordinates (`frames` of a mesh of
/// dimension `d`).
pub fn locate(frames: &[CellFrame], d: usize, x: &[f64]) -> Option<(usize, [f64; 4])> {
    let nv = d + 1;
    for (e, (g, centroid)) in frames.iter().enumerate() {
        let mut xi = [0.0; 4];
        for q in 0..nv {
            xi[q] = 1.0 / nv as f64 + (0..d).map(|j| g[q][j] * (x[j] - centroid[j])).sum::<f64>();
        }
        if xi[..nv].iter().all(|&l| l >= -1e-12) {
            return Some((e, xi));
        }
    }
    None
}

#[derive(Serialize, Deserialize)]
struct RegionState {
    #[serde(default)]
    name: Option<String>,
    displacement: Vec<f64>,
    velocity: Vec<f64>,
    /// Drucker–Prager regions: each cell's plastic strain (xx, yy, zz, xy, yz, xz).
    #[serde(default)]
    plastic_strain: Vec<f64>,
    /// Hardening regions: each cell's accumulated plastic shear strain κ.
    #[serde(default)]
    hardening_strain: Vec<f64>,
}

#[derive(Serialize, Deserialize)]
struct State {
    regions: Vec<RegionState>,
    /// The band's grains and their share of their mass (to read).
    band: Vec<(u32, f64)>,
    /// The ties' impulses λ (the next step's warm start).
    ties: Vec<Vec<f64>>,
}

impl<D: Dim, const N: usize> Continuum<D, N> {
    fn save(&self) -> serde_json::Value {
        let s = State {
            regions: self
                .bodies
                .iter()
                .zip(&self.plastic)
                .map(|(b, p)| RegionState {
                    name: b.name.clone(),
                    displacement: b.u.clone(),
                    velocity: b.v.clone(),
                    plastic_strain: p.as_ref().map_or_else(Vec::new, |p| {
                        p.eps_p
                            .iter()
                            .flat_map(|e| [e[0][0], e[1][1], e[2][2], e[0][1], e[1][2], e[0][2]])
                            .collect()
                    }),
                    hardening_strain: p
                        .as_ref()
                        .filter(|p| p.hardening.is_some())
                        .map_or_else(Vec::new, |p| p.kappa.clone()),
                })
                .collect(),
            band: self.band.clone(),
            ties: self.ties.r.iter().map(|r| r.to_vec()).collect(),
        };
        serde_json::to_value(s).expect("plain data")
    }

    fn load_saved(&mut self, v: &serde_json::Value) -> Result<(), String> {
        let s = State::deserialize(v).map_err(|e| format!("not a state of continuum regions: {e}"))?;
        let same = s.regions.len() == self.bodies.len()
            && s.regions
                .iter()
                .zip(&self.bodies)
                .all(|(r, b)| r.displacement.len() == b.u.len() && r.velocity.len() == b.v.len())
            && s.band.len() == self.band.len()
            && s.band.iter().zip(&self.band).all(|(a, b)| a.0 == b.0)
            && s.ties.len() == self.ties.len()
            && s.ties.iter().all(|r| r.len() == N);
        if !same {
            return Err("the state's continuum regions or ties are not the scene's: a restart needs the scene that wrote it".into());
        }
        let finite = |x: &[f64]| x.iter().all(|y| y.is_finite());
        if !s
            .regions
            .iter()
            .all(|r| finite(&r.displacement) && finite(&r.velocity) && finite(&r.plastic_strain) && finite(&r.hardening_strain))
            || !s.ties.iter().all(|r| finite(r))
        {
            return Err("non-finite numbers in the continuum state".into());
        }
        for ((b, r), p) in self.bodies.iter_mut().zip(s.regions).zip(&mut self.plastic) {
            b.u = r.displacement;
            b.v = r.velocity;
            if let Some(p) = p {
                for (e, x) in p.eps_p.iter_mut().zip(r.plastic_strain.chunks_exact(6)) {
                    *e = [[x[0], x[3], x[5]], [x[3], x[1], x[4]], [x[5], x[4], x[2]]];
                }
                for (k, x) in p.kappa.iter_mut().zip(&r.hardening_strain) {
                    *k = *x;
                }
            }
        }
        for (r, t) in self.ties.r.iter_mut().zip(s.ties) {
            r.copy_from_slice(&t);
        }
        Ok(())
    }

    /// `{region}_{side}_fx`, `_fy`[, `_fz`] of each driven side (the region's name,
    /// else `continuum{i}`).
    fn driven_columns(&self) -> Vec<String> {
        let mut out = vec![];
        for (i, (b, dr)) in self.bodies.iter().zip(&self.driven).enumerate() {
            let name = b.name.clone().unwrap_or_else(|| format!("continuum{i}"));
            for s in dr {
                out.extend(["fx", "fy", "fz"][..N].iter().map(|c| format!("{name}_{}_{c}", s.side)));
            }
        }
        out
    }

    /// Σ |λ_p| over the ties (N·s): the coupling's impulse.
    pub fn tie_impulse(&self) -> f64 {
        self.ties.r.iter().map(|r| r.iter().map(|x| x * x).sum::<f64>().sqrt()).sum()
    }
}

impl<D: Dim, const N: usize> SceneFamily<D> for Continuum<D, N> {
    fn section(&self) -> &'static str {
        SECTION
    }
    fn describe(&self) -> String {
        let nodes: usize = self.bodies.iter().map(|b| b.mesh.n_nodes()).sum();
        format!(
            "{} continuum region(s) ({nodes} nodes), {} band grains, {} ties",
            self.bodies.len(),
            self.band.len(),
            self.ties.len()
        )
    }
    fn share_world(&mut self, w: &mut World<D>) {
        for &(g, wp) in &self.band {
            let k = crate::family::slot(w, g);
            w.bodies.mass[k] *= wp;
            w.bodies.refresh_inverse(k);
        }
        // the contacts of a band grain keep the share 1 − α(x) of their stiffness
        // at their point (compliant laws: docs/CONTINUUM.md, energy), by global id
        let mut region = vec![u32::MAX; w.ids.n_global(w.bodies.len())];
        for &(g, r) in &self.band_region {
            region[g as usize] = r;
        }
        let bands = self.bands.clone();
        w.contact_shares.push(std::sync::Arc::new(move |keys, points, weight| {
            for ((k, p), wt) in keys.iter().zip(points).zip(weight.iter_mut()) {
                let of = |i: u32| region.get(i as usize).copied().unwrap_or(u32::MAX);
                let r = of(k.i).min(of(k.j));
                if r != u32::MAX {
                    *wt *= 1.0 - bands[r as usize].alpha(&p.as_ref()[..N]);
                }
            }
        }));
    }
    fn update(&mut self, w: &World<D>) -> Result<(), Diverged> {
        if let Some(e) = self.error.take() {
            return Err(Diverged {
                step: w.step,
                body: 0,
                message: e,
            });
        }
        crate::stage2::update_bodies(&mut self.bodies, w.time.h, w.time.theta, w.step)?;
        for (b, p) in self.bodies.iter().zip(&mut self.plastic) {
            if let Some(p) = p {
                p.update(&b.mesh, &b.u);
            }
        }
        Ok(())
    }
    fn contacts(&self) -> usize {
        self.ties.len()
    }
    fn history_columns(&self) -> Vec<String> {
        [
            "continuum_ties",
            "tie_impulse",
            "kinetic_continuum",
            "elastic_continuum",
            "load_potential_continuum",
            "yielding_cells",
        ]
        .map(String::from)
        .into_iter()
        .chain(self.driven_columns())
        .collect()
    }
    fn history_values(&self, out: &mut Vec<f64>) {
        out.push(self.ties.len() as f64);
        out.push(self.tie_impulse());
        out.push(self.bodies.iter().map(FeBody::kinetic_energy).sum());
        let elastic = |(b, p): (&FeBody, &Option<super::plastic::Plastic>)| {
            p.as_ref().map_or_else(|| b.elastic_energy(), |p| p.elastic_energy(&b.mesh, &b.u))
        };
        out.push(self.bodies.iter().zip(&self.plastic).map(elastic).sum());
        out.push(self.bodies.iter().map(FeBody::load_potential).sum());
        out.push(self.plastic.iter().flatten().map(|p| p.yielding as f64).sum());
        for (b, dr) in self.bodies.iter().zip(&self.driven) {
            out.extend(super::sides::reactions(b, dr).into_iter().flatten());
        }
    }
    fn write_frame(&mut self, dir: &Path, frame: u32, t: f64) -> std::io::Result<()> {
        crate::family::write_frame(&self.bodies, ("continuum", |_| true), &mut self.frames, dir, (frame, t))
    }
    fn finish(&mut self, dir: &Path) -> std::io::Result<()> {
        crate::output::write_series(dir, "continuum", self.bodies.len(), &self.frames)
    }
    fn save_state(&self) -> serde_json::Value {
        self.save()
    }
    fn load_state(&mut self, state: &serde_json::Value) -> Result<(), String> {
        self.load_saved(state)
    }
    fn as_any(&self) -> &dyn Any {
        self
    }
    fn as_any_mut(&mut self) -> &mut dyn Any {
        self
    }
}
