//! One subdomain: its contacts and its copies of bodies, for any body family
//! ([`super::family::Family`]; `Subdomain2` for 2D rigid bodies, `Subdomain3` for 3D).
//!
//! Local ids are dense `u32`s. Copy l of global body g = `body_global[l]` has the
//! iteration matrix M̂_E = M̂/m_g (partition of unity), stored as its inverse
//! `inv_mass[l] = m_g M̂⁻¹` (unchanged for immovable bodies, whose copies are not
//! glued). Its loads are F̂/m_g, so its free velocity is the body's V_free:
//! (F̂/m)/(M̂/m) = M̂⁻¹F̂. The contacts' Delassus blocks W_αα are those of the copies.

use super::attach::Parts;
use super::family::{Family, Rigid2, Rigid3};
use crate::norms::Sums;

/// Marks, in a chain entry, the subdomain's own copy.
pub const OWN: u32 = u32::MAX;

/// A subdomain that shares interface bodies with this one.
#[derive(Clone, Debug, Default)]
pub struct Neighbor {
    pub sub: u32,
    /// Own interface slots of the bodies shared with `sub`, in ascending body id
    /// (the same sequence on both sides: packet positions match).
    pub slots: Vec<u32>,
    /// Values (degrees of freedom) in a packet to or from `sub`.
    pub values: u32,
}

/// Struct-of-arrays subdomain.
#[derive(Debug, Default)]
pub struct Subdomain<D: Family> {
    pub id: u32,
    /// The subdomain's contacts, `bodies` as local body ids; `block` with the
    /// copies' M̂_E⁻¹.
    pub contacts: D::Contacts,
    /// Global index of each local contact.
    pub contact_global: Vec<u32>,
    /// Visiting order (local ids; empty: storage order): `nlgs::make_order_of` of the
    /// subdomain.
    pub order: Vec<u32>,
    /// Global id of each local body copy.
    pub body_global: Vec<u32>,
    /// Per local body copy: the body's number of copies in the step (its
    /// multiplicity m; [`super::partition::Decomposition::mult`]).
    pub copy_mult: Vec<u32>,
    /// Another rank's subdomain limited to the bodies this rank needs
    /// ([`super::shells`]): each body's local id on the subdomain's rank. Empty when
    /// the ids are those of the subdomain's rank ([`Subdomain::remote_id`]).
    pub shell_local: Vec<u32>,
    /// A limited shell ([`super::shells`]): the attached families' copies made
    /// into it get their ids on the subdomain's rank ([`Self::shell_local`]) from
    /// the routing after the split (`RankState::route_family_copies`).
    pub limited_shell: bool,
    /// Copy velocities V_E.
    pub vel: Vec<D::V>,
    /// Copy M̂_E⁻¹ = m M̂⁻¹.
    pub inv_mass: Vec<D::InvMass>,
    /// Local ids of the interface copies of rigid bodies (ascending global id): the
    /// first slots.
    pub iface: Vec<u32>,
    /// The attached families' parts of the subdomain ([`super::attach`]).
    pub parts: Parts<D>,
    /// Slots past the rigid ones: (index in `parts`, local entity), ascending
    /// interface entity.
    pub iface_ent: Vec<(u32, u32)>,
    /// Per slot: index of the body in [`super::partition::Interface`].
    pub iface_ib: Vec<u32>,
    /// Per slot: position of this copy in the body's chain.
    pub iface_k: Vec<u32>,
    /// Per slot: where its values start in the slot-ordered interface values
    /// (the sum of the earlier slots' degrees of freedom); one more entry at the end,
    /// the total.
    pub iface_off: Vec<u32>,
    /// Per rigid slot: F_Γ, the net interface impulse on the copy (N·s).
    pub f_gamma: Vec<D::V>,
    pub neighbors: Vec<Neighbor>,
    /// Per slot, the body's chain: `chain[chain_start[q]..chain_start[q + 1]]` holds,
    /// for each copy in chain order, (neighbor index, offset of its values in the
    /// neighbor's packet), or ([`OWN`], slot) for the own copy.
    pub chain_start: Vec<u32>,
    pub chain: Vec<(u32, u32)>,
    /// Check-pass sums of the last check sweep.
    pub sums: Sums,
}

/// A subdomain of 2D rigid bodies.
pub type Subdomain2 = Subdomain<Rigid2>;
/// A subdomain of 3D rigid bodies.
pub type Subdomain3 = Subdomain<Rigid3>;

/// What the NSCDD coordinator needs from a subdomain (DESIGN.md §3, §4). Interface
/// values are the `f64`s of each copy's degrees of freedom (the entity's
/// [`super::partition::Interface::dofs`]), so that the gluing code does not depend
/// on the body family.
pub trait SubdomainSolver {
    /// `n` NLGS sweeps with relaxation ω; the last one is a check pass when `check`
    /// (its sums are then in [`Self::sums`], else those are zero).
    fn sweeps(&mut self, n: u32, omega: f64, check: bool);
    fn sums(&self) -> &Sums;
    /// Velocities of the interface copies given by `slots`, appended to `out`.
    fn interface_velocities(&self, slots: &[u32], out: &mut Vec<f64>);
    /// Velocity of the interface copy in `slot`, appended to `out`.
    fn interface_velocity(&self, slot: usize, out: &mut Vec<f64>);
    /// Gluing increment of one interface copy: ΔF_Γ = M̂_E ΔV, applied through
    /// M̂_E⁻¹ (so the copy moves by ΔV on its free degrees of freedom).
    fn glue(&mut self, slot: usize, dv: &[f64]);
}

/// Degrees of freedom of a copy of family D.
pub fn dofs<D: Family>() -> usize {
    D::V::default().as_ref().len()
}

impl<D: Family> SubdomainSolver for Subdomain<D> {
    fn sweeps(&mut self, n: u32, omega: f64, check: bool) {
        self.sums = Sums::default();
        for k in 0..n {
            let sums = if check && k + 1 == n { Some(&mut self.sums) } else { None };
            match sums {
                None => {
                    D::sweep(&mut self.contacts, &mut self.vel, &self.inv_mass, &self.order, omega, None);
                    for (_, p) in self.parts.0.iter_mut() {
                        p.sweep(&mut self.vel, &self.inv_mass, omega, None);
                    }
                }
                Some(sm) => {
                    D::sweep(
                        &mut self.contacts,
                        &mut self.vel,
                        &self.inv_mass,
                        &self.order,
                        omega,
                        Some(&mut *sm),
                    );
                    for (_, p) in self.parts.0.iter_mut() {
                        p.sweep(&mut self.vel, &self.inv_mass, omega, Some(&mut *sm));
                    }
                }
            }
        }
    }
    fn sums(&self) -> &Sums {
        &self.sums
    }
    fn interface_velocities(&self, slots: &[u32], out: &mut Vec<f64>) {
        for &q in slots {
            self.interface_velocity(q as usize, out);
        }
    }
    #[inline]
    fn interface_velocity(&self, slot: usize, out: &mut Vec<f64>) {
        match self.iface.get(slot) {
            Some(&l) => out.extend_from_slice(self.vel[l as usize].as_ref()),
            None => {
                let (p, e) = self.iface_ent[slot - self.iface.len()];
                self.parts.0[p as usize].1.entity_velocity(e as usize, out);
            }
        }
    }
    fn glue(&mut self, slot: usize, dv: &[f64]) {
        let Some(&l) = self.iface.get(slot) else {
            let (p, e) = self.iface_ent[slot - self.iface.len()];
            self.parts.0[p as usize].1.glue_entity(e as usize, dv);
            return;
        };
        let l = l as usize;
        let mut v = D::V::default();
        v.as_mut().copy_from_slice(dv);
        D::glue(&mut self.vel[l], &mut self.f_gamma[slot], &self.inv_mass[l], &v);
    }
}

impl<D: Family> Subdomain<D> {
    /// Interface slots: the rigid copies', then the attached families' entities'.
    #[inline]
    pub fn slots(&self) -> usize {
        self.iface_ib.len()
    }

    /// Contacts of the subdomain, the attached families' included.
    pub fn n_contacts(&self) -> usize {
        D::len(&self.contacts) + self.parts.0.iter().map(|(_, p)| p.len()).sum::<usize>()
    }

    /// Appends global contact `a` of `c`, with local body ids `li`, `lj`.
    pub(crate) fn push_contact(&mut self, c: &D::Contacts, a: usize, li: u32, lj: u32) {
        D::push_contact(&mut self.contacts, c, a, li, lj);
        self.contact_global.push(a as u32);
    }

    /// The local id, on the subdomain's rank, of this process's copy `l` (the same
    /// id unless the subdomain is a limited shell).
    pub fn remote_id(&self, l: u32) -> u32 {
        self.shell_local.get(l as usize).copied().unwrap_or(l)
    }

    /// W_αα and its precomputed inverses from the copies' M̂_E⁻¹ (`split[l]`: copy
    /// l's M̂_E⁻¹ is the body's scaled by its multiplicity m ≥ 2).
    pub(crate) fn copy_delassus(&mut self, split: &[bool]) {
        D::copy_delassus(&mut self.contacts, &self.inv_mass, split);
    }

    /// V_E = V_free + M̂_E⁻¹ (F_Γ + H_E r) with the warm-start impulses, applied in
    /// storage order (as the one-domain engine does); `v_free` by slot, `slot` the
    /// slot of a global id.
    pub(crate) fn init_velocities(&mut self, v_free: &[D::V], slot: &dyn Fn(u32) -> usize) {
        self.vel.clear();
        self.vel.extend(self.body_global.iter().map(|&g| v_free[slot(g)]));
        for (q, &l) in self.iface.iter().enumerate() {
            let l = l as usize;
            D::apply_impulse(&mut self.vel[l], &self.inv_mass[l], &self.f_gamma[q]);
        }
        D::warm_start(&self.contacts, &mut self.vel, &self.inv_mass);
        for (_, p) in self.parts.0.iter_mut() {
            p.warm_start(&mut self.vel, &self.inv_mass);
        }
    }
}
