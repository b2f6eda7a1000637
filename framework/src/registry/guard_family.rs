//! The panic guard ([`super::guard`]) around the body families of run-time
//! plugins: the family kind (`load`), the loaded family (every method of
//! [`SceneFamily`], of [`Attached`] and of its one-domain stage) and each of its
//! subdomain parts ([`LocalPart`]). `as_any` answers with the family's own value,
//! so that a family still downcasts its parts and itself.

use super::guard::Guard;
use crate::dd::attach::{EntityInfo, LocalPart, SolvedOn};
use crate::dd::{Attached, Family, Rigid};
use crate::dim::Dim;
use crate::engine::{ContactStage, Diverged};
use crate::family::{EntryError, FamilyContext, FamilyKind, SceneFamily};
use crate::norms::Sums;
use crate::world::World;
use std::any::Any;
use std::path::Path;

pub(crate) struct GuardedFamilyKind<D: Dim> {
    pub inner: Box<dyn FamilyKind<D>>,
    pub guard: Guard,
}

impl<D: Dim> FamilyKind<D> for GuardedFamilyKind<D> {
    fn load(&self, entries: &[toml::Table], cx: &FamilyContext<'_, D>) -> Result<Box<dyn SceneFamily<D>>, EntryError> {
        let inner = self.guard.call(|| self.inner.load(entries, cx))?;
        Ok(Box::new(GuardedFamily {
            inner,
            guard: self.guard.clone(),
        }))
    }
    fn load_boxes(
        &self,
        entries: &[toml::Table],
        cx: &FamilyContext<'_, D>,
        saved: Option<&serde_json::Value>,
    ) -> Result<Option<Vec<[[f64; 3]; 2]>>, EntryError> {
        self.guard.call(|| self.inner.load_boxes(entries, cx, saved))
    }
}

struct GuardedFamily<D: Dim> {
    inner: Box<dyn SceneFamily<D>>,
    guard: Guard,
}

impl<D: Dim> SceneFamily<D> for GuardedFamily<D> {
    fn section(&self) -> &'static str {
        self.guard.call(|| self.inner.section())
    }
    fn describe(&self) -> String {
        self.guard.call(|| self.inner.describe())
    }
    fn one_domain(&mut self) -> Option<&mut dyn ContactStage<World<D>>> {
        let has = self.guard.call(|| self.inner.one_domain().is_some());
        // the stage's calls go through this guard too (below)
        has.then_some(self as &mut dyn ContactStage<World<D>>)
    }
    fn share_world(&mut self, w: &mut World<D>) {
        self.guard.call(|| self.inner.share_world(w))
    }
    fn update(&mut self, w: &World<D>) -> Result<(), Diverged> {
        self.guard.call(|| self.inner.update(w))
    }
    fn contacts(&self) -> usize {
        self.guard.call(|| self.inner.contacts())
    }
    fn history_columns(&self) -> Vec<String> {
        self.guard.call(|| self.inner.history_columns())
    }
    fn history_values(&self, out: &mut Vec<f64>) {
        self.guard.call(|| self.inner.history_values(out))
    }
    fn write_frame(&mut self, dir: &Path, frame: u32, t: f64) -> std::io::Result<()> {
        self.guard.call(|| self.inner.write_frame(dir, frame, t))
    }
    fn finish(&mut self, dir: &Path) -> std::io::Result<()> {
        self.guard.call(|| self.inner.finish(dir))
    }
    fn save_state(&self) -> serde_json::Value {
        self.guard.call(|| self.inner.save_state())
    }
    fn local_problem(&self, w: &World<D>) -> Option<crate::fc::FamilyShare> {
        self.guard.call(|| self.inner.local_problem(w))
    }
    fn load_state(&mut self, state: &serde_json::Value) -> Result<(), String> {
        self.guard.call(|| self.inner.load_state(state))
    }
    fn as_any(&self) -> &dyn Any {
        self.inner.as_any()
    }
    fn as_any_mut(&mut self) -> &mut dyn Any {
        self.inner.as_any_mut()
    }
}

/// The family's one-domain stage, through the guard.
impl<D: Dim> ContactStage<World<D>> for GuardedFamily<D> {
    fn after_free_velocity(&mut self, w: &World<D>) {
        let inner = &mut self.inner;
        self.guard.call(|| {
            if let Some(s) = inner.one_domain() {
                s.after_free_velocity(w)
            }
        })
    }
    fn prepare(&mut self, w: &mut World<D>) {
        let inner = &mut self.inner;
        self.guard.call(|| {
            if let Some(s) = inner.one_domain() {
                s.prepare(w)
            }
        })
    }
    fn solve(&mut self, w: &mut World<D>) -> crate::solver::SolveReport {
        let inner = &mut self.inner;
        self.guard.call(|| inner.one_domain().map(|s| s.solve(w)).unwrap_or_default())
    }
}

impl<D: Dim> Attached<Rigid<D>> for GuardedFamily<D> {
    fn after_free_velocity(&mut self, w: &World<D>) {
        self.guard.call(|| Attached::after_free_velocity(&mut *self.inner, w))
    }
    fn build(&mut self, w: &mut World<D>) {
        self.guard.call(|| self.inner.build(w))
    }
    fn points(&self, out: &mut Vec<[f64; 3]>) {
        self.guard.call(|| self.inner.points(out))
    }
    fn n_entities(&self) -> usize {
        self.guard.call(|| self.inner.n_entities())
    }
    fn entity(&self, e: u32) -> EntityInfo {
        self.guard.call(|| self.inner.entity(e))
    }
    fn split(&self, w: &World<D>, owner: &[u32], copy: &mut dyn FnMut(u32, u32) -> u32) -> Vec<(u32, Box<dyn LocalPart<Rigid<D>>>)> {
        let parts = self.guard.call(|| self.inner.split(w, owner, copy));
        parts
            .into_iter()
            .map(|(s, inner)| {
                let part: Box<dyn LocalPart<Rigid<D>>> = Box::new(GuardedPart::<Rigid<D>> {
                    inner,
                    guard: self.guard.clone(),
                });
                (s, part)
            })
            .collect()
    }
    fn write_back(&mut self, w: &mut World<D>, parts: &[(u32, &dyn LocalPart<Rigid<D>>)]) {
        self.guard.call(|| self.inner.write_back(w, parts))
    }
    fn residual_parts(&self, w: &World<D>) -> (f64, f64) {
        self.guard.call(|| self.inner.residual_parts(w))
    }
    fn residual_parts_in(&self, w: &World<D>, contacts: &[u32]) -> Option<(f64, f64)> {
        self.guard.call(|| self.inner.residual_parts_in(w, contacts))
    }
    fn held_everywhere(&self) -> Option<Vec<u32>> {
        self.guard.call(|| self.inner.held_everywhere())
    }
    fn reach(&self, w: &World<D>, out: &mut Vec<[[f64; 3]; 2]>) {
        self.guard.call(|| self.inner.reach(w, out))
    }
    fn solved_on(&mut self, w: &World<D>, on: Option<&SolvedOn<'_>>) -> bool {
        self.guard.call(|| self.inner.solved_on(w, on))
    }
    fn share_stepped(&mut self, rounds: &dyn crate::dd::Rounds, next: Option<&crate::dd::RankCells<'_>>) {
        self.guard.call(|| self.inner.share_stepped(rounds, next))
    }
    fn new_cells(&mut self, cells: &crate::dd::RankCells<'_>, rounds: &dyn crate::dd::Rounds) {
        self.guard.call(|| self.inner.new_cells(cells, rounds))
    }
    fn gather_whole(&mut self, rounds: &dyn crate::dd::Rounds) {
        self.guard.call(|| self.inner.gather_whole(rounds))
    }
    fn frames_per_rank(&self) -> bool {
        self.guard.call(|| self.inner.frames_per_rank())
    }
    fn keep_own(&mut self, own: &dyn Fn([f64; 3]) -> bool) -> bool {
        self.guard.call(|| self.inner.keep_own(own))
    }
    fn after_free_velocity_own(&mut self, w: &World<D>, own: &crate::dd::OwnCells<'_>) -> bool {
        self.guard.call(|| self.inner.after_free_velocity_own(w, own))
    }
    fn near_bodies(&self) -> Option<usize> {
        self.guard.call(|| self.inner.near_bodies())
    }
    fn stepped_bodies(&self) -> Option<(usize, usize)> {
        self.guard.call(|| self.inner.stepped_bodies())
    }
    fn built_bodies(&self) -> Option<usize> {
        self.guard.call(|| self.inner.built_bodies())
    }
}

struct GuardedPart<F: Family> {
    inner: Box<dyn LocalPart<F>>,
    guard: Guard,
}

impl<F: Family> LocalPart<F> for GuardedPart<F> {
    fn len(&self) -> usize {
        self.guard.call(|| self.inner.len())
    }
    fn is_empty(&self) -> bool {
        self.guard.call(|| self.inner.is_empty())
    }
    fn entities(&self) -> &[u32] {
        self.guard.call(|| self.inner.entities())
    }
    fn prepare(&mut self, inv: &[F::InvMass], mult: &[u32]) {
        self.guard.call(|| self.inner.prepare(inv, mult))
    }
    fn warm_start(&mut self, vel: &mut [F::V], inv: &[F::InvMass]) {
        self.guard.call(|| self.inner.warm_start(vel, inv))
    }
    fn sweep(&mut self, vel: &mut [F::V], inv: &[F::InvMass], omega: f64, sums: Option<&mut Sums>) {
        self.guard.call(|| self.inner.sweep(vel, inv, omega, sums))
    }
    fn entity_velocity(&self, e: usize, out: &mut Vec<f64>) {
        self.guard.call(|| self.inner.entity_velocity(e, out))
    }
    fn glue_entity(&mut self, e: usize, dv: &[f64]) {
        self.guard.call(|| self.inner.glue_entity(e, dv))
    }
    fn pack(&self, out: &mut Vec<f64>) {
        self.guard.call(|| self.inner.pack(out))
    }
    fn packed_len(&self) -> usize {
        self.guard.call(|| self.inner.packed_len())
    }
    fn unpack(&mut self, values: &[f64]) {
        self.guard.call(|| self.inner.unpack(values))
    }
    fn as_any(&self) -> &dyn Any {
        self.inner.as_any()
    }
}
