//! The deformable bodies as a body family of the framework ([`nscdd::family`]): the
//! `[[deformable]]` section of 2D and 3D scenes ([`DeformableKind`]), stepped,
//! written (history columns, one VTK unstructured grid per body and frame,
//! `deformable.pvd`), saved and restarted by the framework's run loop.
//!
//! The saved state (`final.json` and checkpoints, under `families.deformable`): per
//! body its displacement u and velocity V (and, to read, its name, sizes and
//! energies), and the contacts' keys and impulses (the next step's warm start); M̂'s
//! factors and the cached columns of M̂⁻¹ are rebuilt from the scene, so a restart
//! continues bitwise.

use crate::body::FeBody;
use crate::nodes::{FeContacts, FeKey};
use crate::stage2::Deformables2;
use crate::stage3::Deformables3;
use nscdd::dim::{Dim, D2, D3};
use nscdd::engine::{ContactStage, Diverged};
use nscdd::family::{EntryError, FamilyContext, FamilyKind, SceneFamily};
use nscdd::world::World;
use serde::{Deserialize, Serialize};
use std::any::Any;
use std::path::Path;

/// The scene section of deformable bodies.
pub const SECTION: &str = "deformable";

/// Builds the deformable bodies of a scene's `[[deformable]]` entries
/// ([`crate::scene`] for the keys).
pub struct DeformableKind;

impl FamilyKind<D2> for DeformableKind {
    fn load(&self, entries: &[toml::Table], cx: &FamilyContext<'_, D2>) -> Result<Box<dyn SceneFamily<D2>>, EntryError> {
        let bodies = crate::scene::bodies_from(entries, cx)?;
        crate::scene::refuse_compliant(&bodies, cx.world)?;
        let mut fe = Deformables2::new(bodies, cx.world.alert);
        fe.ranks = cx.ranks;
        Ok(Box::new(fe))
    }
    fn load_boxes(
        &self,
        entries: &[toml::Table],
        cx: &FamilyContext<'_, D2>,
        saved: Option<&serde_json::Value>,
    ) -> Result<Option<Vec<[[f64; 3]; 2]>>, EntryError> {
        load_boxes(entries, cx, 2, saved)
    }
}

impl FamilyKind<D3> for DeformableKind {
    fn load(&self, entries: &[toml::Table], cx: &FamilyContext<'_, D3>) -> Result<Box<dyn SceneFamily<D3>>, EntryError> {
        let bodies = crate::scene::bodies_from(entries, cx)?;
        crate::scene::refuse_compliant(&bodies, cx.world)?;
        let mut fe = Deformables3::new(bodies, cx.world.alert);
        fe.ranks = cx.ranks;
        Ok(Box::new(fe))
    }
    fn load_boxes(
        &self,
        entries: &[toml::Table],
        cx: &FamilyContext<'_, D3>,
        saved: Option<&serde_json::Value>,
    ) -> Result<Option<Vec<[[f64; 3]; 2]>>, EntryError> {
        load_boxes(entries, cx, 3, saved)
    }
}

/// The bodies' boxes before they are built ([`FamilyKind::load_boxes`]): each
/// mesh's box grown by what its first step may move it (h |V|, V the initial or
/// the `saved` velocity) and by 2 % of the alert distance, which hold the first
/// [`reach`] (the family reads no world body at load and names none by id);
/// restarted, grown by the saved displacement too. `None`: a saved state that is
/// not this scene's (the restart reports it).
fn load_boxes<D: Dim>(
    entries: &[toml::Table],
    cx: &FamilyContext<'_, D>,
    dim: usize,
    saved: Option<&serde_json::Value>,
) -> Result<Option<Vec<[[f64; 3]; 2]>>, EntryError> {
    let saved = match saved.map(State::deserialize) {
        None => None,
        Some(Ok(s)) if s.bodies.len() == entries.len() => Some(s.bodies),
        Some(_) => return Ok(None),
    };
    let most = |x: &[f64]| x.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    let mut out = Vec::new();
    for (i, e) in entries.iter().enumerate() {
        let spec = crate::scene::spec_of(i, e)?;
        let [mut lo, mut hi] = crate::scene::mesh_box(&spec.mesh, dim, cx.dir).map_err(|(k, m)| crate::scene::entry_error(i, k, m))?;
        let (u, v) = saved
            .as_ref()
            .map_or((0.0, 0.0), |b| (most(&b[i].displacement), most(&b[i].velocity)));
        let grow = u + cx.world.time.h * most(&spec.velocity).max(v) + 0.02 * cx.world.alert;
        if !grow.is_finite() {
            return Ok(None);
        }
        for k in 0..dim {
            (lo[k], hi[k]) = (lo[k] - grow, hi[k] + grow);
        }
        out.push([lo, hi]);
    }
    Ok(Some(out))
}

#[derive(Serialize, Deserialize)]
struct BodyState {
    #[serde(default)]
    name: Option<String>,
    #[serde(default)]
    nodes: usize,
    #[serde(default)]
    cells: usize,
    #[serde(default)]
    max_displacement: f64,
    #[serde(default)]
    kinetic_energy: f64,
    #[serde(default)]
    elastic_energy: f64,
    displacement: Vec<f64>,
    velocity: Vec<f64>,
}

#[derive(Serialize, Deserialize)]
struct ContactState {
    key: FeKey,
    r: Vec<f64>,
}

#[derive(Serialize, Deserialize)]
struct State {
    bodies: Vec<BodyState>,
    contacts: Vec<ContactState>,
}

/// The saved state; `known`: each body's energies after the step, as the rank
/// stepping it computed them ([`crate::stepped::Stepped::energies`]; the same
/// numbers as [`FeBody::energies_now`], which a body whose M and K are not held
/// here assembles them aside for: NaN if that fails). The contacts in key order:
/// `gathered`'s on MPI ranks (every rank's, [`crate::whole::gather_contacts`]),
/// else the family's list's.
fn save<C, A, F, B, const N: usize>(
    bodies: &[FeBody],
    c: &FeContacts<C, A, F, B, N>,
    known: Option<&[[f64; 3]]>,
    gathered: Option<&[(FeKey, [f64; N])]>,
) -> serde_json::Value {
    let mut contacts: Vec<(FeKey, [f64; N])> = match gathered {
        Some(g) => g.to_vec(),
        None => c.key.iter().copied().zip(c.r.iter().copied()).collect(),
    };
    contacts.sort_unstable_by_key(|x| x.0);
    let state = State {
        bodies: bodies
            .iter()
            .enumerate()
            .map(|(i, b)| {
                let [kinetic_energy, elastic_energy, _] = energies_of(b, i, known);
                BodyState {
                    name: b.name.clone(),
                    nodes: b.mesh.n_nodes(),
                    cells: b.mesh.n_cells(),
                    max_displacement: b.u.iter().fold(0.0f64, |m, x| m.max(x.abs())),
                    kinetic_energy,
                    elastic_energy,
                    displacement: b.u.clone(),
                    velocity: b.v.clone(),
                }
            })
            .collect(),
        contacts: contacts.into_iter().map(|(key, r)| ContactState { key, r: r.to_vec() }).collect(),
    };
    serde_json::to_value(state).expect("plain data")
}

/// Puts a saved state into the bodies and the contacts' warm start (only keys and
/// impulses: the next step's build reads nothing else).
fn load<C: Copy, A: Copy, F: Copy, B: Copy, const N: usize>(
    bodies: &mut [FeBody],
    c: &mut FeContacts<C, A, F, B, N>,
    v: &serde_json::Value,
) -> Result<(), String> {
    let s: State = State::deserialize(v).map_err(|e| format!("not a state of deformable bodies: {e}"))?;
    if s.bodies.len() != bodies.len() {
        return Err(format!(
            "the state has {} deformable bodies, the scene {}: a restart needs the scene that wrote it",
            s.bodies.len(),
            bodies.len()
        ));
    }
    for (i, (b, sb)) in bodies.iter().zip(&s.bodies).enumerate() {
        let n = b.n_dofs();
        if sb.displacement.len() != n || sb.velocity.len() != n {
            return Err(format!(
                "deformable body {i} has {n} degrees of freedom in the scene, {} in the state: a restart needs the scene that wrote it",
                sb.displacement.len()
            ));
        }
        if !sb.displacement.iter().chain(&sb.velocity).all(|x| x.is_finite()) {
            return Err(format!("deformable body {i}: non-finite displacement or velocity"));
        }
    }
    if let Some(k) = s.contacts.iter().position(|k| k.r.len() != N || !k.r.iter().all(|x| x.is_finite())) {
        return Err(format!("contact {k}: the impulse must be {N} finite numbers"));
    }
    for (b, sb) in bodies.iter_mut().zip(s.bodies) {
        b.ensure_state();
        b.u = sb.displacement;
        b.v = sb.velocity;
    }
    c.clear();
    for k in s.contacts {
        c.key.push(k.key);
        c.r.push(std::array::from_fn(|i| k.r[i]));
    }
    Ok(())
}

/// Body `i`'s energies after the step: `known`'s (the rank stepping it computed
/// them, [`crate::stepped::Stepped::energies`]), else [`FeBody::energies_now`]
/// (NaN if its assembly aside fails).
fn energies_of(b: &FeBody, i: usize, known: Option<&[[f64; 3]]>) -> [f64; 3] {
    known.map_or_else(|| b.energies_now().unwrap_or([f64::NAN; 3]), |k| k[i])
}

/// The contacts and the sums over the bodies of [`FeBody::energies_now`], added in
/// body order; `known`: each body's, already computed by the rank stepping it
/// ([`crate::stepped::Stepped::energies`]).
fn history_values(bodies: &[FeBody], contacts: usize, known: Option<&[[f64; 3]]>, out: &mut Vec<f64>) {
    let mut sum = [0.0; 3];
    for (b, body) in bodies.iter().enumerate() {
        for (s, x) in sum.iter_mut().zip(energies_of(body, b, known)) {
            *s += x;
        }
    }
    out.push(contacts as f64);
    out.extend(sum);
}

fn describe(bodies: &[FeBody]) -> String {
    let nodes: usize = bodies.iter().map(|b| b.mesh.n_nodes()).sum();
    let n = bodies.len();
    format!("{n} deformable bod{} ({nodes} nodes)", if n == 1 { "y" } else { "ies" })
}

/// One VTK unstructured grid per body (`{prefix}{i}_{frame}.vtu`) of the bodies
/// `mine` says, the frame recorded for the `.pvd` series.
pub(crate) fn write_frame(
    bodies: &[FeBody],
    (prefix, mine): (&str, impl Fn(usize) -> bool),
    frames: &mut Vec<(f64, u32)>,
    dir: &Path,
    (frame, t): (u32, f64),
) -> std::io::Result<()> {
    for (bi, b) in bodies.iter().enumerate().filter(|x| mine(x.0)) {
        let path = dir.join(format!("{prefix}{bi}_{frame:05}.vtu"));
        nscdd::output::write_atomic(&path, |tmp| std::fs::write(tmp, crate::output::vtu(b)))?;
    }
    frames.push((t, frame));
    Ok(())
}

/// The [`nscdd::dd::Attached`] hooks of the deformable family on MPI ranks that
/// read nothing of the dimension but the world's type (`$world`), the same in
/// [`crate::family2`] and [`crate::family3`].
macro_rules! rank_hooks {
    ($world:ty) => {
        /// None by id: the world bodies near the deformable bodies ([`Self::reach`],
        /// asked before the first step and after a step that detected whole: with the
        /// decentralized scheme the family detects in each rank's cells,
        /// [`Self::after_free_velocity_own`], and its antagonists are in their halos).
        fn held_everywhere(&self) -> Option<Vec<u32>> {
            Some(Vec::new())
        }
        fn reach(&self, w: &$world, out: &mut Vec<[[f64; 3]; 2]>) {
            crate::family::reach(&self.bodies, w.time.h, self.alert, out);
        }
        /// A repartition step's new cells: the boundary of the bodies stepped here
        /// last to the ranks now near them that lack it ([`crate::near::new_cells`]).
        fn new_cells(&mut self, cells: &nscdd::dd::RankCells<'_>, rounds: &dyn nscdd::dd::Rounds) {
            crate::near::new_cells(&mut self.stepped, &mut self.bodies, self.alert, cells, rounds);
        }
        /// Each rank writes the frames of the bodies it holds whole (loaded knowing
        /// its rank: [`crate::stepped::Stepped::writes_frame`]).
        fn frames_per_rank(&self) -> bool {
            self.ranks.is_some()
        }
        /// The bodies stepped elsewhere whole, every rank's contacts (the saved state).
        fn gather_whole(&mut self, rounds: &dyn nscdd::dd::Rounds) {
            crate::whole::gather_whole(&self.stepped, &mut self.bodies, rounds);
            let c = &self.solved.list;
            let own = c.key.iter().copied().zip(c.r.iter().copied());
            self.gathered = crate::whole::gather_contacts(&self.stepped, own, rounds);
        }
        fn stepped_bodies(&self) -> Option<(usize, usize)> {
            self.stepped.counts()
        }
        fn built_bodies(&self) -> Option<usize> {
            self.stepped.built(&self.bodies)
        }
        fn near_bodies(&self) -> Option<usize> {
            self.stepped.near.held().map(|h| h.iter().filter(|&&x| x).count())
        }
    };
}
pub(crate) use rank_hooks;

macro_rules! scene_family {
    ($stage:ty, $dim:ty, $share:path) => {
        impl SceneFamily<$dim> for $stage {
            fn section(&self) -> &'static str {
                SECTION
            }
            fn describe(&self) -> String {
                describe(&self.bodies)
            }
            fn one_domain(&mut self) -> Option<&mut dyn ContactStage<World<$dim>>> {
                Some(self)
            }
            fn update(&mut self, w: &World<$dim>) -> Result<(), Diverged> {
                if let Some(e) = self.error.take() {
                    return Err(Diverged {
                        step: w.step,
                        body: 0,
                        message: e,
                    });
                }
                // (a body diverged on the rank stepping it: every rank stops here)
                if let Some(b) = self.stepped.diverged.take() {
                    let name = self.bodies[b as usize]
                        .name
                        .as_deref()
                        .map(|n| format!(" (`{n}`)"))
                        .unwrap_or_default();
                    return Err(Diverged {
                        step: w.step,
                        body: b,
                        message: format!("deformable body {b}{name} has a non-finite state (on the MPI rank stepping it)"),
                    });
                }
                <$stage>::update(self, w.time.h, w.time.theta, w.step)
            }
            fn contacts(&self) -> usize {
                self.stepped.contacts_total().unwrap_or(self.contacts.len())
            }
            fn history_columns(&self) -> Vec<String> {
                [
                    "deformable_contacts",
                    "kinetic_deformable",
                    "elastic_deformable",
                    "load_potential_deformable",
                ]
                .map(String::from)
                .to_vec()
            }
            fn history_values(&self, out: &mut Vec<f64>) {
                history_values(&self.bodies, self.contacts(), self.stepped.energies(), out)
            }
            fn write_frame(&mut self, dir: &Path, frame: u32, t: f64) -> std::io::Result<()> {
                // (on MPI ranks each body by the rank holding it whole)
                let (st, n, on) = (&self.stepped, self.bodies.len(), self.ranks);
                let mine = |b: usize| st.writes_frame(b, n, on);
                write_frame(&self.bodies, ("deformable", mine), &mut self.frames, dir, (frame, t))
            }
            fn finish(&mut self, dir: &Path) -> std::io::Result<()> {
                crate::output::write_pvd(dir, self.bodies.len(), &self.frames)
            }
            fn save_state(&self) -> serde_json::Value {
                save(
                    &self.bodies,
                    &self.contacts,
                    self.stepped.energies(),
                    self.gathered.as_deref(),
                )
            }
            fn load_state(&mut self, state: &serde_json::Value) -> Result<(), String> {
                self.stepped = Default::default();
                self.warm.loaded();
                load(&mut self.bodies, &mut self.contacts, state)
            }
            fn local_problem(&self, w: &World<$dim>) -> Option<nscdd::fc::FamilyShare> {
                Some($share(self, w))
            }
            fn as_any(&self) -> &dyn Any {
                self
            }
            fn as_any_mut(&mut self) -> &mut dyn Any {
                self
            }
        }
    };
}

scene_family!(Deformables2, D2, crate::problem::share2);
scene_family!(Deformables3, D3, crate::problem::share3);

/// The deformable family of a loaded scene, if it has one.
pub fn of<D: Dim, S: 'static>(families: &[Box<dyn SceneFamily<D>>]) -> Option<&S> {
    families.iter().find_map(|f| f.as_any().downcast_ref::<S>())
}

/// The raw contacts' rigid antagonists (`slots`: the world's slots) renamed by
/// global id, and their V_free by global id (sorted, once each) into `free`: on MPI
/// ranks a repartition moves bodies between the world's slots before the contacts
/// are built again ([`crate::stepped`]).
pub(crate) fn rigid_by_global<'a, D: Dim>(w: &World<D>, slots: impl Iterator<Item = &'a mut u32>, free: &mut Vec<(u32, D::Twist)>) {
    free.clear();
    for j in slots {
        let g = w.ids.global(*j);
        free.push((g, w.bodies.vel[*j as usize]));
        *j = g;
    }
    free.sort_unstable_by_key(|x| x.0);
    free.dedup_by_key(|x| x.0);
}

/// The world's slot of rigid body `g` (a global id; on MPI ranks the world holds a
/// part, every body a family touches among it: [`nscdd::dd::Attached::held_everywhere`]
/// and [`nscdd::dd::Attached::reach`]).
#[inline]
pub(crate) fn slot<D: Dim>(w: &World<D>, g: u32) -> usize {
    <nscdd::dd::Rigid<D> as nscdd::dd::Family>::held_slot(w, g as usize)
}

/// The boxes in which the deformable bodies' next detection may touch a world body
/// ([`nscdd::dd::Attached::reach`], after a step's write-back): each body's box of
/// its boundary nodes now (the detections' test, [`crate::contact2::detect`],
/// [`crate::contact3::detect`]), grown by what the position update may move a node
/// (h max(|v⁻|, |v⁺|) in each direction) and by 1 % of the alert distance and
/// 1e-12 of its coordinates (two tests of the same boxes may round differently).
pub(crate) fn reach(bodies: &[FeBody], h: f64, alert: f64, out: &mut Vec<[[f64; 3]; 2]>) {
    for b in bodies {
        let d = b.dim();
        let (mut lo, mut hi) = ([0.0; 3], [0.0; 3]);
        lo[..d].fill(f64::INFINITY);
        hi[..d].fill(f64::NEG_INFINITY);
        let mut moves = 0.0f64;
        for &k in &b.mesh.boundary {
            let p = b.position(k as usize);
            for c in 0..d {
                lo[c] = lo[c].min(p[c]);
                hi[c] = hi[c].max(p[c]);
                let i = d * k as usize + c;
                moves = moves.max(b.v_begin[i].abs()).max(b.v[i].abs());
            }
        }
        let size = (0..d).map(|c| lo[c].abs().max(hi[c].abs())).fold(0.0, f64::max);
        let grow = h * moves + 0.01 * alert + 1e-12 * size;
        for c in 0..d {
            lo[c] -= grow;
            hi[c] += grow;
        }
        out.push([lo, hi]);
    }
}
