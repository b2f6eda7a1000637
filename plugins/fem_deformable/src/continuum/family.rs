//! The continuum regions as a body family of the NSCDD stage ([`nscdd::dd::attach`]):
//! their ties are the family's "contacts", given a subdomain like any contact (by
//! geometry, or by model in subdomains of their own), and solved in that
//! subdomain's sweep beside its rigid contacts.
//!
//! A tied grain is a world body: when its contacts and its tie lie in different
//! subdomains, it is an interface body whose copies the one gluing stage glues
//! (F_Γ, A_ΓE the copy's twist). A continuum region is an entity as a deformable
//! body is ([`crate::family2`]): its copy in subdomain E holds the region's tie
//! nodes with M̂_E = M̂/m (block m G), A_ΓE picks their velocities, and the gluing
//! takes the copies to their mean. V⁺ = V_free − M̂⁻¹ Σ_p N(ξ_p)ᵀ λ_p.

use super::ties::{self, TieSet};
use crate::body::FeBody;
use crate::family::slot;
use crate::nodes::{fill_set, NodeSet};
use nscdd::dd::{Attached, EntityInfo, LocalPart, Rigid};
use nscdd::dim::Dim;
use nscdd::norms::Sums;
use nscdd::world::World;
use std::any::Any;
use std::marker::PhantomData;

/// The continuum regions of a scene and their ties (module docs). `N` is the
/// dimension's (2 or 3).
pub struct Continuum<D: Dim, const N: usize> {
    pub bodies: Vec<FeBody>,
    /// Each region's Drucker–Prager state (None: linear elastic).
    pub plastic: Vec<Option<super::plastic::Plastic>>,
    /// Each region's driven sides ([`super::sides`]).
    pub driven: Vec<Vec<super::sides::Driven>>,
    /// The ties ([`ties`]): grains by world id, nodes by index in `sets[body]`.
    pub ties: TieSet<N>,
    /// The band's grains and their share w_p of their mass (the partition of
    /// unity), ascending grain.
    pub band: Vec<(u32, f64)>,
    /// Each region's band, and the region of each band grain (grain, region).
    pub bands: Vec<super::band::Band>,
    pub band_region: Vec<(u32, u32)>,
    /// Each region's tie nodes (fixed), G among them and their velocities.
    pub sets: Vec<NodeSet<N>>,
    /// Per entry of `ties.grain`: the grain's V⁻ and V_free of the step (the world's
    /// warm start moves the grains before the ties are built).
    grain_begin: Vec<[f64; N]>,
    grain_free: Vec<[f64; N]>,
    /// Each tie's point at the step's start, Σ c_ai x_i (its subdomain by geometry).
    point: Vec<[f64; N]>,
    /// A failure inside the step (a refactorization), reported after it.
    pub error: Option<String>,
    /// The VTK frames written, (t, frame).
    pub frames: Vec<(f64, u32)>,
    _d: PhantomData<D>,
}

impl<D: Dim, const N: usize> Continuum<D, N> {
    /// Regions with their ties (`ties.node` holding mesh node ids, turned here into
    /// indices of each region's tie node set) and band grains.
    pub fn new(bodies: Vec<FeBody>, plastic: Vec<Option<super::plastic::Plastic>>, mut ties: TieSet<N>, band: Vec<(u32, f64)>) -> Self {
        assert_eq!(D::N, N, "the continuum family's N is the dimension's");
        let mut nodes: Vec<Vec<u32>> = vec![vec![]; bodies.len()];
        for a in 0..ties.len() {
            nodes[ties.body[a] as usize].extend(&ties.node[ties.nodes(a)]);
        }
        let mut sets = vec![NodeSet::default(); bodies.len()];
        for (ns, set) in nodes.iter_mut().zip(&mut sets) {
            ns.sort_unstable();
            ns.dedup();
            set.nodes = ns.clone();
        }
        for a in 0..ties.len() {
            let set = &sets[ties.body[a] as usize];
            for j in ties.nodes(a) {
                ties.node[j] = set.nodes.binary_search(&ties.node[j]).expect("a tie node is in its region's set") as u32;
            }
        }
        let driven = vec![vec![]; bodies.len()];
        Continuum {
            bodies,
            plastic,
            driven,
            ties,
            band,
            bands: vec![],
            band_region: vec![],
            sets,
            grain_begin: vec![],
            grain_free: vec![],
            point: vec![],
            error: None,
            frames: vec![],
            _d: PhantomData,
        }
    }

    /// Free velocities of the regions (factoring M̂ if h or θ changed; with the
    /// plastic strains' force f_p) and the tied grains' V⁻ and V_free.
    pub fn begin_step(&mut self, w: &World<D>) -> Result<(), String> {
        for (((b, p), dr), set) in self.bodies.iter_mut().zip(&self.plastic).zip(&mut self.driven).zip(&mut self.sets) {
            if let Some(p) = p {
                p.plastic_force(&b.mesh, &mut b.f_plastic);
            }
            if super::sides::start(b, dr, w.t) {
                // M̂ changes: the tie nodes' G is filled again from the new factor
                set.g.clear();
            }
        }
        crate::stage2::free_velocities(&mut self.bodies, w.time.h, w.time.theta, (None, None))?;
        let begin = w.velocity_begin();
        self.grain_begin.clear();
        self.grain_free.clear();
        for &g in &self.ties.grain {
            let k = slot(w, g);
            self.grain_begin.push(ties::grain_velocity::<D, N>(&begin[k]));
            self.grain_free.push(ties::grain_velocity::<D, N>(&w.bodies.vel[k]));
        }
        Ok(())
    }

    /// The node sets at V_free (G filled once: the tie nodes and M̂ do not change)
    /// and each tie's point, target and u_free.
    pub fn build(&mut self, w: &World<D>) {
        for (set, body) in self.sets.iter_mut().zip(&mut self.bodies) {
            if set.g.is_empty() && !set.nodes.is_empty() {
                let nodes = set.nodes.clone();
                fill_set(set, body, &nodes, 1.0);
            }
            for (v, &nd) in set.v.iter_mut().zip(&set.nodes) {
                *v = std::array::from_fn(|c| body.v_free[N * nd as usize + c]);
            }
        }
        let (h, theta) = (w.time.h, w.time.theta);
        let t = &mut self.ties;
        self.point.clear();
        for a in 0..t.len() {
            let b = t.body[a] as usize;
            let (body, set) = (&self.bodies[b], &self.sets[b]);
            // Σ c x, Σ c v⁻, Σ c v_free over the grains; minus Σ b (x, V⁻, V_free) over the nodes
            let (mut x, mut gap, mut ub, mut uf) = ([0.0; N], [0.0; N], [0.0; N], [0.0; N]);
            for i in t.grains(a) {
                let p = w.bodies.pos[slot(w, t.grain[i])];
                for d in 0..N {
                    x[d] += t.c[i] * p.as_ref()[d];
                    ub[d] += t.c[i] * self.grain_begin[i][d];
                    uf[d] += t.c[i] * self.grain_free[i][d];
                }
            }
            gap.copy_from_slice(&x);
            for j in t.nodes(a) {
                let l = t.node[j] as usize;
                let nd = set.nodes[l] as usize;
                let p = body.position(nd);
                for d in 0..N {
                    gap[d] -= t.b[j] * p[d];
                    ub[d] -= t.b[j] * body.v_begin[N * nd + d];
                    uf[d] -= t.b[j] * set.v[l][d];
                }
            }
            self.point.push(x);
            for d in 0..N {
                t.target[a][d] = -(gap[d] + h * (1.0 - theta) * ub[d]) / (h * theta);
            }
            t.u_free[a] = uf;
        }
        // W_a is made by each subdomain's part from its copies' M̂_E⁻¹ (`prepare`)
    }

    /// V⁺ = V_free − M̂⁻¹ Σ_a Σ_l b_al λ_a of every region, and the sets' velocities.
    pub fn finish_velocities(&mut self) {
        let mut f: Vec<Vec<f64>> = self.bodies.iter().map(|b| vec![0.0; b.n_dofs()]).collect();
        let t = &self.ties;
        for a in 0..t.len() {
            let b = t.body[a] as usize;
            for j in t.nodes(a) {
                let nd = self.sets[b].nodes[t.node[j] as usize] as usize;
                for c in 0..N {
                    f[b][N * nd + c] -= t.b[j] * t.r[a][c];
                }
            }
        }
        for ((body, mut dv), set) in self.bodies.iter_mut().zip(f).zip(&mut self.sets) {
            body.solve_in_place(&mut dv);
            body.v = body.v_free.iter().zip(&dv).map(|(a, b)| a + b).collect();
            for (v, &nd) in set.v.iter_mut().zip(&set.nodes) {
                *v = std::array::from_fn(|c| body.v[N * nd as usize + c]);
            }
        }
    }
}

/// The continuum's share of one subdomain: its ties there, a copy of each region
/// they touch (its tie nodes), and the grains' local copies.
#[derive(Default)]
pub struct ContinuumPart<D: Dim, const N: usize> {
    fe: Vec<u32>,
    sets: Vec<NodeSet<N>>,
    ties: TieSet<N>,
    global: Vec<u32>,
    _d: PhantomData<D>,
}

impl<D: Dim, const N: usize> LocalPart<Rigid<D>> for ContinuumPart<D, N> {
    fn len(&self) -> usize {
        self.ties.len()
    }
    fn entities(&self) -> &[u32] {
        &self.fe
    }
    fn prepare(&mut self, inv: &[D::InvMass], mult: &[u32]) {
        for (set, &m) in self.sets.iter_mut().zip(mult) {
            if m > 1 {
                let m = m as f64;
                set.g.iter_mut().for_each(|g| *g *= m);
            }
        }
        ties::refresh_delassus::<D, N>(&mut self.ties, &self.sets, inv);
    }
    fn warm_start(&mut self, vel: &mut [D::Twist], inv: &[D::InvMass]) {
        ties::warm_start::<D, N>(&self.ties, &mut self.sets, vel, inv);
    }
    fn sweep(&mut self, vel: &mut [D::Twist], inv: &[D::InvMass], omega: f64, sums: Option<&mut Sums>) {
        ties::sweep::<D, N>(&mut self.ties, &mut self.sets, vel, inv, omega, sums);
    }
    fn entity_velocity(&self, e: usize, out: &mut Vec<f64>) {
        out.extend(self.sets[e].v.iter().flatten());
    }
    fn glue_entity(&mut self, e: usize, dv: &[f64]) {
        for (v, d) in self.sets[e].v.iter_mut().zip(dv.chunks_exact(N)) {
            for c in 0..N {
                v[c] += d[c];
            }
        }
    }
    fn pack(&self, out: &mut Vec<f64>) {
        out.extend(self.ties.r.iter().flatten());
    }
    fn packed_len(&self) -> usize {
        N * self.ties.len()
    }
    fn unpack(&mut self, values: &[f64]) {
        for (r, x) in self.ties.r.iter_mut().zip(values.chunks_exact(N)) {
            r.copy_from_slice(x);
        }
    }
    fn as_any(&self) -> &dyn Any {
        self
    }
}

impl<D: Dim, const N: usize> Attached<Rigid<D>> for Continuum<D, N> {
    fn after_free_velocity(&mut self, w: &World<D>) {
        if let Err(e) = self.begin_step(w) {
            self.error = Some(e);
        }
    }
    fn build(&mut self, w: &mut World<D>) {
        Continuum::build(self, w);
    }
    fn points(&self, out: &mut Vec<[f64; 3]>) {
        // the tie's point is the grain's centre (its subdomain by geometry)
        out.extend(self.point.iter().map(|x| {
            let mut p = [0.0; 3];
            p[..N].copy_from_slice(x);
            p
        }));
    }
    fn n_entities(&self) -> usize {
        self.bodies.len()
    }
    fn entity(&self, e: u32) -> EntityInfo {
        let n = self.sets[e as usize].len();
        EntityInfo {
            dofs: (N * n) as u32,
            space: (N * n) as u32,
            rho2: 0.0,
            weight: 1.0 / n.max(1) as f64,
        }
    }
    fn split(&self, _w: &World<D>, owner: &[u32], copy: &mut dyn FnMut(u32, u32) -> u32) -> Vec<(u32, Box<dyn LocalPart<Rigid<D>>>)> {
        let t = &self.ties;
        let make = |p: &mut ContinuumPart<D, N>, b: u32| {
            p.fe.push(b);
            p.sets.push(self.sets[b as usize].clone());
        };
        let parts = crate::family2::split_by(owner, self.bodies.len(), make, |s, part: &mut ContinuumPart<D, N>, list, entity| {
            for &a in list {
                let b = entity(part, t.body[a as usize]);
                part.ties.push_from(t, a as usize, &mut |g| copy(s, g), b);
                part.global.push(a);
            }
        });
        parts
            .into_iter()
            .map(|(s, p)| (s, Box::new(p) as Box<dyn LocalPart<Rigid<D>>>))
            .collect()
    }
    fn write_back(&mut self, _w: &mut World<D>, parts: &[(u32, &dyn LocalPart<Rigid<D>>)]) {
        for (_, p) in parts {
            let Some(p) = p.as_any().downcast_ref::<ContinuumPart<D, N>>() else {
                continue;
            };
            for (l, &g) in p.global.iter().enumerate() {
                self.ties.r[g as usize] = p.ties.r[l];
            }
        }
        self.finish_velocities();
    }
    fn residual_parts(&self, w: &World<D>) -> (f64, f64) {
        ties::residual_parts::<D, N>(&self.ties, &self.sets, (&w.bodies.vel, |g| slot(w, g)), 0..self.ties.len())
    }
    fn residual_parts_in(&self, w: &World<D>, contacts: &[u32]) -> Option<(f64, f64)> {
        let ties = contacts.iter().map(|&a| a as usize);
        Some(ties::residual_parts::<D, N>(
            &self.ties,
            &self.sets,
            (&w.bodies.vel, |g| slot(w, g)),
            ties,
        ))
    }
    /// The tied grains, which it reads, and the band's grains, whose mass it shares
    /// (every rank holds and steps them; the family reads no other world body).
    fn held_everywhere(&self) -> Option<Vec<u32>> {
        let mut g = self.ties.grain.clone();
        g.extend(self.band.iter().map(|b| b.0));
        g.sort_unstable();
        g.dedup();
        Some(g)
    }
}
