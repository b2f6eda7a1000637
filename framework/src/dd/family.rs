//! What NSCDD needs from a family of bodies: the dimension lives here, in one small
//! trait, so that the partition, the subdomains, the gluing, the schemes, the
//! threads and the transport are written once for 2D and 3D rigid bodies (and,
//! later, for deformable ones). A family gives its generalized velocity type `V`
//! (one per body, `[f64; 3]` = (v_x, v_y, ω) in 2D, `[f64; 6]` = (v, ω) in 3D), its
//! contact set, the copies' M̂_E⁻¹ and the operations of DESIGN.md §3: one NLGS sweep,
//! M̂_E⁻¹ applied to an impulse, M̂_E applied to a velocity increment (the gluing).

use crate::engine::{Diverged, StepReport};
use crate::norms::Sums;
use crate::rigid2d::contacts::ContactKey;
use crate::rigid3d::coulomb as c3;

/// A body family as NSCDD sees it (see the module docs).
pub trait Family: Sized + Send + Sync + Default + Clone + std::fmt::Debug + 'static {
    /// Generalized velocity (and impulse) of one body.
    type V: Copy + Default + Send + Sync + std::fmt::Debug + PartialEq + AsRef<[f64]> + AsMut<[f64]>;
    /// M̂⁻¹ of one body (as the solver stores it).
    type InvMass: Copy + Default + Send + Sync + std::fmt::Debug;
    type Contacts: Default + Clone + std::fmt::Debug + Send + Sync;
    type World;
    /// Space dimension (2 or 3): the first `SPACE` components of `V` are translations.
    const SPACE: usize;

    fn len(c: &Self::Contacts) -> usize;
    fn reserve(c: &mut Self::Contacts, n: usize);
    /// Appends contact `a` of `src` with local body ids `li`, `lj`.
    fn push_contact(dst: &mut Self::Contacts, src: &Self::Contacts, a: usize, li: u32, lj: u32);
    fn bodies(c: &Self::Contacts, a: usize) -> [u32; 2];
    fn key(c: &Self::Contacts, a: usize) -> ContactKey;
    /// Contact point (z = 0 in 2D).
    fn point(c: &Self::Contacts, a: usize) -> [f64; 3];
    /// dst.r[ga] = src.r[la].
    fn copy_r(dst: &mut Self::Contacts, ga: usize, src: &Self::Contacts, la: usize);
    /// The impulse of contact `a` (local frame: normal first), for the exchange
    /// between processes.
    fn r(c: &Self::Contacts, a: usize) -> &[f64];
    fn r_mut(c: &mut Self::Contacts, a: usize) -> &mut [f64];
    /// W_αα (and its precomputed data) from the copies' M̂_E⁻¹.
    fn copy_delassus(c: &mut Self::Contacts, inv: &[Self::InvMass]);
    /// V += M̂⁻¹ H r for every contact with r ≠ 0, in storage order.
    fn warm_start(c: &Self::Contacts, vel: &mut [Self::V], inv: &[Self::InvMass]);
    /// One NLGS sweep (a check pass when `sums` is given).
    fn sweep(c: &mut Self::Contacts, vel: &mut [Self::V], inv: &[Self::InvMass], order: &[u32], omega: f64, sums: Option<&mut Sums>);
    /// M̂_E⁻¹ = m M̂⁻¹ (partition of unity over m copies).
    fn scale_inv(inv: Self::InvMass, m: f64) -> Self::InvMass;
    /// v += M̂_E⁻¹ f.
    fn apply_impulse(v: &mut Self::V, inv: &Self::InvMass, f: &Self::V);
    /// The gluing increment of a copy: it moves by `dv` on its free degrees of
    /// freedom and its interface impulse grows by M̂_E dv.
    fn glue(v: &mut Self::V, f_gamma: &mut Self::V, inv: &Self::InvMass, dv: &Self::V);

    fn n_bodies(w: &Self::World) -> usize;
    fn movable(w: &Self::World, g: usize) -> bool;
    fn inv_mass(w: &Self::World, g: usize) -> Self::InvMass;
    /// ρ² = I/m of body g (0 when undefined): the weight of rotations in the gluing
    /// norm |V|² = |v|² + ρ² |ω|².
    fn rho2(w: &Self::World, g: usize) -> f64;
    fn contacts(w: &Self::World) -> &Self::Contacts;
    fn contacts_mut(w: &mut Self::World) -> &mut Self::Contacts;
    fn vel(w: &Self::World) -> &[Self::V];
    fn vel_mut(w: &mut Self::World) -> &mut [Self::V];
    /// The step's visiting order of the contacts (empty: storage order).
    fn order(w: &Self::World) -> &[u32];
    /// Natural-map residual of the world's contact problem.
    fn residual(w: &Self::World) -> f64;
    fn solver(w: &Self::World) -> &crate::solver::SolverSettings;
    /// One step of the world with NSCDD as its contact stage.
    fn step_with(w: &mut Self::World, stage: &mut super::NscddOf<Self>) -> Result<StepReport, Diverged>;
}

/// 2D rigid bodies ([`crate::rigid2d`], [`crate::world::World2`]).
#[derive(Clone, Copy, Debug, Default)]
pub struct Rigid2;

impl Family for Rigid2 {
    type V = [f64; 3];
    type InvMass = [f64; 3];
    type Contacts = crate::rigid2d::Contacts2;
    type World = crate::world::World2;
    const SPACE: usize = 2;

    fn len(c: &Self::Contacts) -> usize {
        c.len()
    }
    fn reserve(c: &mut Self::Contacts, n: usize) {
        c.reserve(n);
    }
    fn push_contact(dst: &mut Self::Contacts, src: &Self::Contacts, a: usize, li: u32, lj: u32) {
        dst.push_from(src, a, li, lj);
    }
    fn bodies(c: &Self::Contacts, a: usize) -> [u32; 2] {
        c.bodies[a]
    }
    fn key(c: &Self::Contacts, a: usize) -> ContactKey {
        c.key[a]
    }
    fn point(c: &Self::Contacts, a: usize) -> [f64; 3] {
        [c.point[a][0], c.point[a][1], 0.0]
    }
    fn copy_r(dst: &mut Self::Contacts, ga: usize, src: &Self::Contacts, la: usize) {
        dst.r[ga] = src.r[la];
    }
    fn r(c: &Self::Contacts, a: usize) -> &[f64] {
        &c.r[a]
    }
    fn r_mut(c: &mut Self::Contacts, a: usize) -> &mut [f64] {
        &mut c.r[a]
    }
    fn copy_delassus(c: &mut Self::Contacts, inv: &[Self::InvMass]) {
        for a in 0..c.len() {
            let [i, j] = c.bodies[a];
            let w = crate::rigid2d::Contacts2::delassus(&c.frame[a], inv[i as usize], inv[j as usize]);
            c.block[a] = crate::rigid2d::contacts::Block2 {
                w,
                pre: crate::rigid2d::coulomb::precompute(w, c.target[a].mu),
            };
        }
    }
    fn warm_start(c: &Self::Contacts, vel: &mut [Self::V], inv: &[Self::InvMass]) {
        for a in 0..c.len() {
            if c.r[a] != [0.0, 0.0] {
                c.apply(a, c.r[a], vel, inv);
            }
        }
    }
    fn sweep(c: &mut Self::Contacts, vel: &mut [Self::V], inv: &[Self::InvMass], order: &[u32], omega: f64, sums: Option<&mut Sums>) {
        crate::rigid2d::nlgs::sweep(c, vel, inv, order, omega, sums);
    }
    fn scale_inv(im: Self::InvMass, m: f64) -> Self::InvMass {
        [im[0] * m, im[1] * m, im[2] * m]
    }
    fn apply_impulse(v: &mut Self::V, im: &Self::InvMass, f: &Self::V) {
        for d in 0..3 {
            v[d] += im[d] * f[d];
        }
    }
    fn glue(v: &mut Self::V, f: &mut Self::V, im: &Self::InvMass, dv: &Self::V) {
        for d in 0..3 {
            if im[d] != 0.0 {
                v[d] += dv[d];
                f[d] += dv[d] / im[d];
            }
        }
    }
    fn n_bodies(w: &Self::World) -> usize {
        w.bodies.len()
    }
    fn movable(w: &Self::World, g: usize) -> bool {
        w.bodies.movable(g)
    }
    fn inv_mass(w: &Self::World, g: usize) -> Self::InvMass {
        w.bodies.inv_mass[g]
    }
    fn rho2(w: &Self::World, g: usize) -> f64 {
        let ms = w.bodies.mass[g];
        if ms[0] > 0.0 && ms[0].is_finite() && ms[2].is_finite() {
            ms[2] / ms[0]
        } else {
            0.0
        }
    }
    fn contacts(w: &Self::World) -> &Self::Contacts {
        &w.contacts
    }
    fn contacts_mut(w: &mut Self::World) -> &mut Self::Contacts {
        &mut w.contacts
    }
    fn vel(w: &Self::World) -> &[Self::V] {
        &w.bodies.vel
    }
    fn vel_mut(w: &mut Self::World) -> &mut [Self::V] {
        &mut w.bodies.vel
    }
    fn order(w: &Self::World) -> &[u32] {
        &w.scratch.order
    }
    fn residual(w: &Self::World) -> f64 {
        crate::rigid2d::nlgs::residual(&w.contacts, &w.bodies.vel)
    }
    fn solver(w: &Self::World) -> &crate::solver::SolverSettings {
        &w.solver
    }
    fn step_with(w: &mut Self::World, stage: &mut super::NscddOf<Self>) -> Result<StepReport, Diverged> {
        w.step_with(stage)
    }
}

pub use crate::rigid3d::contacts::InvMass3;

/// 3D rigid bodies ([`crate::rigid3d`], [`crate::world3::World3`]).
#[derive(Clone, Copy, Debug, Default)]
pub struct Rigid3;

impl Family for Rigid3 {
    type V = [f64; 6];
    type InvMass = InvMass3;
    type Contacts = crate::rigid3d::Contacts3;
    type World = crate::world3::World3;
    const SPACE: usize = 3;

    fn len(c: &Self::Contacts) -> usize {
        c.len()
    }
    fn reserve(c: &mut Self::Contacts, n: usize) {
        c.reserve(n);
    }
    fn push_contact(dst: &mut Self::Contacts, src: &Self::Contacts, a: usize, li: u32, lj: u32) {
        dst.push_from(src, a, li, lj);
    }
    fn bodies(c: &Self::Contacts, a: usize) -> [u32; 2] {
        c.bodies[a]
    }
    fn key(c: &Self::Contacts, a: usize) -> ContactKey {
        c.key[a]
    }
    fn point(c: &Self::Contacts, a: usize) -> [f64; 3] {
        c.point[a]
    }
    fn copy_r(dst: &mut Self::Contacts, ga: usize, src: &Self::Contacts, la: usize) {
        dst.r[ga] = src.r[la];
    }
    fn r(c: &Self::Contacts, a: usize) -> &[f64] {
        &c.r[a]
    }
    fn r_mut(c: &mut Self::Contacts, a: usize) -> &mut [f64] {
        &mut c.r[a]
    }
    fn copy_delassus(c: &mut Self::Contacts, inv: &[Self::InvMass]) {
        for a in 0..c.len() {
            let [i, j] = c.bodies[a];
            let (bi, bj) = (&inv[i as usize], &inv[j as usize]);
            let w = crate::rigid3d::Contacts3::delassus(&c.frame[a], bi.m, &bi.i, bj.m, &bj.i);
            c.block[a] = crate::rigid3d::contacts::Block3 {
                w,
                pre: c3::precompute(&w),
            };
        }
    }
    fn warm_start(c: &Self::Contacts, vel: &mut [Self::V], inv: &[Self::InvMass]) {
        for a in 0..c.len() {
            if c.r[a] != [0.0; 3] {
                let [bi, bj] = c.bodies[a];
                crate::rigid3d::contacts::apply_with(&c.frame[a], c.r[a], bi as usize, bj as usize, vel, inv);
            }
        }
    }
    fn sweep(c: &mut Self::Contacts, vel: &mut [Self::V], inv: &[Self::InvMass], order: &[u32], omega: f64, sums: Option<&mut Sums>) {
        crate::rigid3d::nlgs::sweep_split(c, vel, inv, order, omega, sums);
    }
    fn scale_inv(im: Self::InvMass, m: f64) -> Self::InvMass {
        InvMass3 {
            m: im.m.map(|x| x * m),
            i: im.i.map(|x| x * m),
        }
    }
    fn apply_impulse(v: &mut Self::V, im: &Self::InvMass, f: &Self::V) {
        for d in 0..3 {
            v[d] += im.m[d] * f[d];
        }
        let w = c3::mul(&im.i, [f[3], f[4], f[5]]);
        for d in 0..3 {
            v[3 + d] += w[d];
        }
    }
    fn glue(v: &mut Self::V, f: &mut Self::V, im: &Self::InvMass, dv: &Self::V) {
        for d in 0..3 {
            if im.m[d] != 0.0 {
                v[d] += dv[d];
                f[d] += dv[d] / im.m[d];
            }
        }
        // rotations: M̂_E = (I_E⁻¹)⁻¹ on the free axes
        match c3::inverse(&im.i) {
            Some(ie) => {
                let df = c3::mul(&ie, [dv[3], dv[4], dv[5]]);
                for d in 0..3 {
                    v[3 + d] += dv[3 + d];
                    f[3 + d] += df[d];
                }
            }
            None => {
                // some rotations driven: the free axes (diagonal of I⁻¹ restricted)
                let diag = [im.i[0], im.i[3], im.i[5]];
                for d in 0..3 {
                    if diag[d] != 0.0 {
                        v[3 + d] += dv[3 + d];
                        f[3 + d] += dv[3 + d] / diag[d];
                    }
                }
            }
        }
    }
    fn n_bodies(w: &Self::World) -> usize {
        w.bodies.len()
    }
    fn movable(w: &Self::World, g: usize) -> bool {
        w.bodies.movable(g)
    }
    fn inv_mass(w: &Self::World, g: usize) -> Self::InvMass {
        InvMass3 {
            m: w.bodies.inv_m[g],
            i: w.bodies.inv_i[g],
        }
    }
    fn rho2(w: &Self::World, g: usize) -> f64 {
        let (m, i) = (w.bodies.mass[g], w.bodies.inertia[g]);
        if m > 0.0 && m.is_finite() && i.iter().all(|x| x.is_finite()) {
            (i[0] + i[1] + i[2]) / (3.0 * m)
        } else {
            0.0
        }
    }
    fn contacts(w: &Self::World) -> &Self::Contacts {
        &w.contacts
    }
    fn contacts_mut(w: &mut Self::World) -> &mut Self::Contacts {
        &mut w.contacts
    }
    fn vel(w: &Self::World) -> &[Self::V] {
        &w.bodies.vel
    }
    fn vel_mut(w: &mut Self::World) -> &mut [Self::V] {
        &mut w.bodies.vel
    }
    fn order(w: &Self::World) -> &[u32] {
        &w.scratch.order
    }
    fn residual(w: &Self::World) -> f64 {
        crate::rigid3d::nlgs::residual(&w.contacts, &w.bodies.vel)
    }
    fn solver(w: &Self::World) -> &crate::solver::SolverSettings {
        &w.solver
    }
    fn step_with(w: &mut Self::World, stage: &mut super::NscddOf<Self>) -> Result<StepReport, Diverged> {
        w.step_with(stage)
    }
}
