//! Partition of one step's contact set into subdomains, and the interface bodies.
//!
//! Each contact belongs to exactly one subdomain: the cell of an nx × ny (× nz in
//! 3D) grid over the bounding box of the contact points that holds its point (points
//! on the upper edges go to the last cell). A body belongs to every subdomain that owns one of
//! its contacts; its multiplicity m is that count. Movable bodies with m ≥ 2 are the
//! interface bodies, one copy per subdomain, glued; immovable bodies (M̂⁻¹ = 0) are
//! copied into every subdomain that needs them without gluing. Between repartitions
//! ([`kept_owners`]) persisting contacts keep their subdomain.

use super::attach::{Attached, EntityInfo};
use super::family::Family;
pub use super::grid::Grid;
pub use super::owner::{kept_owners, owner_of, OwnerOf};
use super::subdomain::{Neighbor, Subdomain, OWN};

/// The interface bodies and their copies, in ascending body id; copy lists in
/// subdomain order (the chain order).
#[derive(Clone, Debug, Default)]
pub struct Interface {
    /// Global body id.
    pub body: Vec<u32>,
    /// ρ² = I/m of the body (0 when undefined), for the gluing norm.
    pub rho2: Vec<f64>,
    /// The entity's translational values and its norm's weight
    /// ([`super::attach::EntityInfo`]; D::N and 1 for a rigid body).
    pub space: Vec<u32>,
    pub weight: Vec<f64>,
    /// The first `n_rigid` entities are rigid bodies (`body` their world id); the
    /// others the attached families' entities (`body`: the family's entity id).
    pub n_rigid: usize,
    /// Whether some copy had no F_Γ from the previous step (glued once before the
    /// first sweep).
    pub fresh: Vec<bool>,
    /// Degrees of freedom of the interface entity `ib` (of each of its copies).
    pub dofs: Vec<u32>,
    /// Copies of body `ib`: `start[ib]..start[ib + 1]`.
    pub start: Vec<u32>,
    pub sub: Vec<u32>,
    pub slot: Vec<u32>,
    /// Per copy: where its values start in its subdomain's slot-ordered interface
    /// values ([`super::subdomain::Subdomain::iface_off`]).
    pub off: Vec<u32>,
}

impl Interface {
    pub fn len(&self) -> usize {
        self.body.len()
    }
    pub fn is_empty(&self) -> bool {
        self.body.is_empty()
    }
    pub fn copies(&self, ib: usize) -> std::ops::Range<usize> {
        self.start[ib] as usize..self.start[ib + 1] as usize
    }
    pub fn links(&self) -> usize {
        self.sub.len() - self.body.len()
    }
}

/// F_Γ of the interface copies, kept between steps: (body, subdomain) → impulse.
#[derive(Clone, Debug)]
pub struct FGammaStore<V> {
    entries: Vec<(u32, u32, V)>,
}

impl<V> Default for FGammaStore<V> {
    fn default() -> Self {
        FGammaStore { entries: Vec::new() }
    }
}

impl<V: Copy> FGammaStore<V> {
    pub fn get(&self, body: u32, sub: u32) -> Option<V> {
        self.entries
            .binary_search_by_key(&(body, sub), |e| (e.0, e.1))
            .ok()
            .map(|p| self.entries[p].2)
    }
    /// Number of copies stored for `body`.
    pub fn count(&self, body: u32) -> usize {
        let lo = self.entries.partition_point(|e| e.0 < body);
        let hi = self.entries.partition_point(|e| e.0 <= body);
        hi - lo
    }
    pub fn len(&self) -> usize {
        self.entries.len()
    }
    /// (body, subdomain, F_Γ), by body then subdomain.
    pub fn iter(&self) -> impl Iterator<Item = (u32, u32, V)> + '_ {
        self.entries.iter().copied()
    }
    pub fn is_empty(&self) -> bool {
        self.entries.is_empty()
    }
    /// A store of the entries (body, subdomain, F_Γ) in any order (a saved state).
    pub fn from_entries(mut entries: Vec<(u32, u32, V)>) -> Self {
        entries.sort_unstable_by_key(|e| (e.0, e.1));
        FGammaStore { entries }
    }
    /// Replaces the store by the subdomains' current F_Γ (rigid copies; the attached
    /// families' entities are glued at the start of every step instead, the same warm
    /// start: [`super::attach`]).
    pub fn keep<D: Family<V = V>>(&mut self, subs: &[Subdomain<D>]) {
        self.entries.clear();
        for s in subs {
            for (q, &l) in s.iface.iter().enumerate() {
                self.entries.push((s.body_global[l as usize], s.id, s.f_gamma[q]));
            }
        }
        self.entries.sort_unstable_by_key(|e| (e.0, e.1));
    }
}

/// One step's decomposition.
#[derive(Debug)]
pub struct Decomposition<D: Family> {
    pub grid: Option<Grid>,
    /// Subdomain of each global contact.
    pub owner: Vec<u32>,
    /// (body, m) of every body copied in the step, ascending body id: m the number
    /// of subdomains holding a copy (a body not listed has none). As many entries as
    /// the step's bodies on this process (≈ N/P on a rank), not one per scene body;
    /// each copy's m is also its subdomain's [`Subdomain::copy_mult`].
    pub mult: Vec<(u32, u32)>,
    pub subs: Vec<Subdomain<D>>,
    pub iface: Interface,
}

impl<D: Family> Decomposition<D> {
    /// Body g's number of copies (0: none).
    pub fn mult_of(&self, g: u32) -> u32 {
        self.mult.binary_search_by_key(&g, |x| x.0).map_or(0, |i| self.mult[i].1)
    }
}

impl<D: Family> Default for Decomposition<D> {
    fn default() -> Self {
        Decomposition {
            grid: None,
            owner: Vec::new(),
            mult: Vec::new(),
            subs: Vec::new(),
            iface: Interface::default(),
        }
    }
}

/// Fills the other ranks' subdomains with their bodies, or those near this rank
/// (contacts held per rank, [`super::shells`]): called with `None` before the
/// attached families' split, then with `Some(first)` after it (`first[s]`:
/// subdomain s's copies before the split), when the families' copies of this
/// rank's subdomains go to the limited shells; returns the copies that adds
/// (body, subdomain, local id).
pub type Shells<'a, D> = &'a mut dyn FnMut(&mut [Subdomain<D>], Option<&[u32]>) -> Vec<(u32, u32, u32)>;

/// Every body copy of a decomposition as (body, subdomain), sorted: each body's
/// subdomains, ascending.
pub fn copies<D: Family>(d: &Decomposition<D>) -> Vec<(u32, u32)> {
    let mut out: Vec<(u32, u32)> = d.subs.iter().flat_map(|s| s.body_global.iter().map(move |&g| (g, s.id))).collect();
    out.sort_unstable();
    out
}

/// The attached families of a step and the subdomain of each of their contacts.
pub struct FamilyOwners<'a, 'f, D: Family> {
    pub fams: &'a [&'f mut dyn Attached<D>],
    pub owner: &'a [Vec<u32>],
}

/// Splits the contact set of `w` over the `ns` subdomains given by `owner` (one per
/// contact, each below `ns`), and the attached families' contacts by theirs;
/// copies start at V_free + M̂_E⁻¹(F_Γ + H_E r).
/// Each subdomain visits its contacts in the scene's `ordering` of its own
/// (`nlgs::make_order_of`: storage order, reversed, a permutation seeded by the
/// step and the subdomain id, or sorted along a direction), which needs no other
/// subdomain's contacts.
/// With `build`, only the subdomains it marks get their copies' M̂_E⁻¹, W_αα and
/// starting velocities (the others are swept by another process: their structure
/// alone is kept, for the exchange of results; a family's parts too, which receive
/// its results). With `shells` (contacts held per rank) the caller makes the
/// starting velocities, once the fresh bodies' F_Γ are known
/// ([`super::RankState::fresh_f_gamma`]).
#[allow(clippy::too_many_arguments)]
pub fn decompose_owned<D: Family>(
    w: &D::World,
    // (by slot)
    v_free: &[D::V],
    grid: Grid,
    owner: Vec<u32>,
    ns: usize,
    store: &FGammaStore<D::V>,
    build: Option<&[bool]>,
    fam: &FamilyOwners<'_, '_, D>,
    shells: Option<Shells<'_, D>>,
) -> Decomposition<D> {
    let built = |s: u32| build.is_none_or(|b| b[s as usize]);
    let (mut subs, mut copy_of) = split_contacts::<D>(w, &owner, ns);
    let shelled = shells.is_some();
    let mut shells = shells;
    if let Some(fill) = shells.as_mut() {
        // contacts held per rank: the other ranks' subdomains get their bodies only
        fill(&mut subs, None);
        for sub in subs.iter().filter(|s| !built(s.id)) {
            for (l, &g) in sub.body_global.iter().enumerate() {
                copy_of.push((g, sub.id, l as u32));
            }
        }
    }
    let first: Vec<u32> = subs.iter().map(|s| s.body_global.len() as u32).collect();
    let ent_copies = split_families(w, &mut subs, &mut copy_of, fam);
    if let Some(fill) = shells.as_mut() {
        copy_of.extend(fill(&mut subs, Some(&first)));
    }
    // copies grouped by body, in subdomain order; each copy's multiplicity
    copy_of.sort_unstable_by_key(|e| (e.0, e.1));
    let mult = multiplicities(&mut subs, &copy_of);
    // copies' M̂_E⁻¹ and W_αα; each subdomain's visiting order
    let (sv, step) = (D::solver(w), D::step(w));
    for sub in subs.iter_mut() {
        if built(sub.id) {
            let c = &sub.contacts;
            crate::solver::nlgs::make_order_of(&mut sub.order, sub.contact_global.len(), sv, step, sub.id as u64, D::SPACE, |a| {
                D::point(c, a)
            });
            sub.inv_mass = sub
                .body_global
                .iter()
                .zip(&sub.copy_mult)
                .map(|(&g, &m)| D::scale_inv(D::inv_mass(w, g as usize), m as f64))
                .collect();
            let split: Vec<bool> = sub.copy_mult.iter().map(|&m| m >= 2).collect();
            sub.copy_delassus(&split);
            let Subdomain { parts, inv_mass, .. } = sub;
            for (f, p) in parts.0.iter_mut() {
                let m: Vec<u32> = p.entities().iter().map(|&e| ent_copies[*f as usize].mult[e as usize]).collect();
                p.prepare(inv_mass, &m);
            }
        }
    }
    // interface bodies: copies grouped by body, in subdomain order
    let mut iface = interface::<D>(w, &mut subs, &copy_of, store);
    for (f, ec) in ent_copies.iter().enumerate() {
        entity_interface(&mut iface, &mut subs, &*fam.fams[f], ec);
    }
    link_chains(&mut subs, &iface);
    // (with shells, the caller's, once the fresh bodies' F_Γ are known)
    let slot = |g: u32| D::held_slot(w, g as usize);
    for sub in subs.iter_mut().filter(|s| built(s.id) && !shelled) {
        sub.init_velocities(v_free, &slot);
    }
    Decomposition {
        grid: Some(grid),
        owner,
        mult,
        subs,
        iface,
    }
}

/// Each copy's multiplicity ([`Subdomain::copy_mult`]) and (body, m) of every
/// body, from the copies sorted by body.
fn multiplicities<D: Family>(subs: &mut [Subdomain<D>], copy_of: &[(u32, u32, u32)]) -> Vec<(u32, u32)> {
    for sub in subs.iter_mut() {
        sub.copy_mult.clear();
        sub.copy_mult.resize(sub.body_global.len(), 0);
    }
    let mut out = Vec::new();
    for run in copy_of.chunk_by(|a, b| a.0 == b.0) {
        let m = run.len() as u32;
        out.push((run[0].0, m));
        for &(_, s, l) in run {
            subs[s as usize].copy_mult[l as usize] = m;
        }
    }
    out
}

/// The copies of one family's entities: multiplicity per entity and the copies as
/// (entity, subdomain, index of the part in the subdomain, local entity).
#[derive(Default)]
struct EntityCopies {
    mult: Vec<u32>,
    copies: Vec<(u32, u32, u32, u32)>,
}

/// The attached families' parts, with copies of the world bodies their contacts
/// touch (made where the subdomain has none yet).
fn split_families<D: Family>(
    w: &D::World,
    subs: &mut [Subdomain<D>],
    copy_of: &mut Vec<(u32, u32, u32)>,
    fam: &FamilyOwners<'_, '_, D>,
) -> Vec<EntityCopies> {
    let mut out = Vec::with_capacity(fam.fams.len());
    if fam.fams.is_empty() {
        return out;
    }
    // the local id of each body's copy in the subdomain `cur` (a family's parts come
    // in ascending subdomain order: one refill per subdomain)
    // (by the world's slot: a family's contact's bodies are held)
    let nh = held_len::<D>(w);
    let (mut stamp, mut local) = (vec![u32::MAX; nh], vec![0u32; nh]);
    let mut cur = u32::MAX;
    for (f, a) in fam.fams.iter().enumerate() {
        let mut copy = |s: u32, g: u32| -> u32 {
            let sub = &mut subs[s as usize];
            if s != cur {
                cur = s;
                for (l, &b) in sub.body_global.iter().enumerate() {
                    if let Some(k) = D::slot(w, b as usize) {
                        stamp[k] = s;
                        local[k] = l as u32;
                    }
                }
            }
            let k = D::held_slot(w, g as usize);
            if stamp[k] != s {
                stamp[k] = s;
                local[k] = sub.body_global.len() as u32;
                sub.body_global.push(g);
                // (a limited shell: the copy's local id on the subdomain's rank comes
                // with the family copies routed after the split)
                if sub.limited_shell {
                    sub.shell_local.push(u32::MAX);
                }
                copy_of.push((g, s, local[k]));
            }
            local[k]
        };
        let parts = a.split(w, &fam.owner[f], &mut copy);
        let mut ec = EntityCopies {
            mult: vec![0; a.n_entities()],
            copies: Vec::new(),
        };
        for (s, p) in parts {
            let sub = &mut subs[s as usize];
            let pi = sub.parts.0.len() as u32;
            for (le, &e) in p.entities().iter().enumerate() {
                ec.mult[e as usize] += 1;
                ec.copies.push((e, s, pi, le as u32));
            }
            sub.parts.0.push((f as u32, p));
        }
        ec.copies.sort_unstable_by_key(|x| (x.0, x.1));
        out.push(ec);
    }
    out
}

/// Appends one family's interface entities (held by ≥ 2 subdomains) to the interface
/// and their slots to the subdomains; they are fresh: glued once before the first
/// sweep, their warm start ([`super::attach`]).
fn entity_interface<D: Family>(iface: &mut Interface, subs: &mut [Subdomain<D>], fam: &dyn Attached<D>, ec: &EntityCopies) {
    let mut p = 0;
    while p < ec.copies.len() {
        let e = ec.copies[p].0;
        let m = ec.mult[e as usize] as usize;
        let copies = &ec.copies[p..p + m];
        p += m;
        if m < 2 {
            continue;
        }
        let EntityInfo { dofs, space, rho2, weight } = fam.entity(e);
        let ib = iface.body.len() as u32;
        iface.body.push(e);
        iface.rho2.push(rho2);
        iface.space.push(space);
        iface.weight.push(weight);
        iface.dofs.push(dofs);
        iface.fresh.push(true);
        for (k, &(_, s, pi, le)) in copies.iter().enumerate() {
            let sub = &mut subs[s as usize];
            iface.sub.push(s);
            iface.slot.push(sub.slots() as u32);
            let off = sub.iface_off.last().copied().unwrap_or(0);
            iface.off.push(off);
            sub.iface_off.push(off + dofs);
            sub.iface_ent.push((pi, le));
            sub.iface_ib.push(ib);
            sub.iface_k.push(k as u32);
        }
        iface.start.push(iface.sub.len() as u32);
    }
}

/// The bodies the world holds (its slots).
fn held_len<D: Family>(w: &D::World) -> usize {
    D::held(w).map_or_else(|| D::n_bodies(w), <[u32]>::len)
}

/// The contacts of each subdomain in storage order, with a copy of each of their
/// bodies made on first sight; returns the subdomains and the copies as (body,
/// subdomain, local id). The scratch is by the world's slot (a contact's bodies are
/// held): ≈ N/P on a rank, not one entry per scene body.
#[allow(clippy::type_complexity)]
fn split_contacts<D: Family>(w: &D::World, owner: &[u32], ns: usize) -> (Vec<Subdomain<D>>, Vec<(u32, u32, u32)>) {
    let mut subs: Vec<Subdomain<D>> = (0..ns)
        .map(|s| Subdomain {
            id: s as u32,
            ..Default::default()
        })
        .collect();
    let c = D::contacts(w);
    // contacts in storage order, copies on first sight
    let nh = held_len::<D>(w);
    let (mut stamp, mut local) = (vec![u32::MAX; nh], vec![0u32; nh]);
    let mut by_sub: Vec<Vec<u32>> = vec![Vec::new(); ns];
    for (a, &s) in owner.iter().enumerate() {
        by_sub[s as usize].push(a as u32);
    }
    let mut copy_of: Vec<(u32, u32, u32)> = Vec::new(); // (body, sub, local)
    for (s, sub) in subs.iter_mut().enumerate() {
        // one allocation per field (growing them by push cost 0.4 ms of 4000 contacts)
        D::reserve(&mut sub.contacts, by_sub[s].len());
        sub.contact_global.reserve(by_sub[s].len());
        for &a in &by_sub[s] {
            let a = a as usize;
            let mut id = |g: u32| {
                let k = D::held_slot(w, g as usize);
                if stamp[k] != s as u32 {
                    stamp[k] = s as u32;
                    local[k] = sub.body_global.len() as u32;
                    sub.body_global.push(g);
                    copy_of.push((g, s as u32, local[k]));
                }
                local[k]
            };
            let [bi, bj] = D::contact_bodies(w, a);
            let (li, lj) = (id(bi), id(bj));
            sub.push_contact(c, a, li, lj);
        }
    }
    (subs, copy_of)
}

/// The interface: the movable bodies copied in several subdomains (copies sorted
/// by body, in subdomain order), with the copies' F_Γ from the previous step
/// where the same subdomains held them.
fn interface<D: Family>(w: &D::World, subs: &mut [Subdomain<D>], copy_of: &[(u32, u32, u32)], store: &FGammaStore<D::V>) -> Interface {
    for sub in subs.iter_mut() {
        sub.iface_off.push(0);
    }
    let mut iface = Interface {
        start: vec![0],
        ..Default::default()
    };
    for copies in copy_of.chunk_by(|a, b| a.0 == b.0) {
        let (g, m) = (copies[0].0, copies.len());
        if m < 2 || !D::movable(w, g as usize) {
            continue;
        }
        let ib = iface.body.len() as u32;
        iface.body.push(g);
        iface.rho2.push(D::rho2(w, g as usize));
        iface.space.push(D::SPACE as u32);
        iface.weight.push(1.0);
        let dofs = super::subdomain::dofs::<D>() as u32;
        iface.dofs.push(dofs);
        // F_Γ from the previous step where the same subdomain held a copy, made to sum to zero
        let mut fresh = store.count(g) != m;
        let mut f: Vec<D::V> = copies
            .iter()
            .map(|&(_, s, _)| {
                store.get(g, s).unwrap_or_else(|| {
                    fresh = true;
                    D::V::default()
                })
            })
            .collect();
        if fresh {
            zero_mean(&mut f);
        }
        iface.fresh.push(fresh);
        for (k, &(_, s, l)) in copies.iter().enumerate() {
            let sub = &mut subs[s as usize];
            iface.sub.push(s);
            iface.slot.push(sub.iface.len() as u32);
            let off = sub.iface_off.last().copied().unwrap_or(0);
            iface.off.push(off);
            sub.iface_off.push(off + dofs);
            sub.iface.push(l);
            sub.iface_ib.push(ib);
            sub.iface_k.push(k as u32);
            sub.f_gamma.push(f[k]);
        }
        iface.start.push(iface.sub.len() as u32);
    }
    iface.n_rigid = iface.body.len();
    iface
}

/// The kept F_Γ of a fresh body's copies (zero for its new ones), made to sum to
/// zero: the mean removed.
pub(super) fn zero_mean<V: AsRef<[f64]> + AsMut<[f64]>>(f: &mut [V]) {
    let (m, Some(ndof)) = (f.len(), f.first().map(|x| x.as_ref().len())) else {
        return;
    };
    let mean: Vec<f64> = (0..ndof).map(|d| f.iter().map(|x| x.as_ref()[d]).sum::<f64>() / m as f64).collect();
    for x in f.iter_mut() {
        for (v, mu) in x.as_mut().iter_mut().zip(&mean) {
            *v -= mu;
        }
    }
}

/// Each subdomain's neighbours and the chains of its interface copies.
fn link_chains<D: Family>(subs: &mut [Subdomain<D>], iface: &Interface) {
    for sub in subs.iter_mut() {
        sub.chain_start.push(0);
        for q in 0..sub.slots() {
            let ib = sub.iface_ib[q] as usize;
            for k in iface.copies(ib) {
                let t = iface.sub[k];
                if t == sub.id {
                    sub.chain.push((OWN, q as u32));
                    continue;
                }
                let ni = match sub.neighbors.iter().position(|n| n.sub == t) {
                    Some(ni) => ni,
                    None => {
                        sub.neighbors.push(Neighbor {
                            sub: t,
                            slots: Vec::new(),
                            values: 0,
                        });
                        sub.neighbors.len() - 1
                    }
                };
                let nbr = &mut sub.neighbors[ni];
                sub.chain.push((ni as u32, nbr.values));
                nbr.slots.push(q as u32);
                nbr.values += iface.dofs[ib];
            }
            sub.chain_start.push(sub.chain.len() as u32);
        }
    }
}
