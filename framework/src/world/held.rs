//! A world holding part of the scene (issue 20, compact arrays; docs/SCALING.md
//! item 5): on MPI ranks a world drops the bodies its rank no longer steps and
//! admits those entering its halo, so its arrays hold ≈ N/P bodies.
//!
//! The world's slots stay ascending in global id ([`crate::model::BodyIds`]), so
//! every order taken from body ids is the scene's. A change of the held set
//! renumbers the slots and remaps every table holding a slot: the bodies' columns,
//! the names, `fixed`, the reactions, the step's V⁻, the contacts' bodies (the
//! world's, the step's next set and the raw ones), the detection region's pairs,
//! the drives, the box walls and the active list (a drop, between steps, clears
//! the step's detection and build buffers instead). A body enters with its whole record ([`World::body_record`]):
//! its moving state and its static data (mass, inertia, M̂⁻¹ as it is, free degrees
//! of freedom, volume, shape, material); the shape stores stay whole.
//!
//! ```text
//! let mut rec = Vec::new();
//! w.body_record(1, &mut rec);   // body 1 (slot 1) leaves with its record
//! w.hold(&[0, 2]);              // slots 0, 1 hold the global ids 0, 2
//! w.admit(&[(1, &rec[..])]);    // and comes back, bit for bit
//! ```

use super::World;
use crate::dim::{Coords, Dim, Vector};
use crate::model::{Bodies, ShapeRef};

/// Whole-scene values a world holding part of the scene can no longer compute
/// from its bodies (static: computed once, before its first drop).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct WholeScene {
    /// Grains ([`World::is_grain`]), their total volume (area in 2D) and the
    /// largest grain's size.
    pub grains: usize,
    pub grain_volume: f64,
    pub max_grain_size: f64,
    /// Per body (global id): whether impulses move it and its ρ² (the gluing's
    /// weight of rotations): what the centralized gluing reads of the interface
    /// bodies of every rank (9 bytes a body, against 250 to 550 held).
    pub movable: Vec<bool>,
    pub rho2: Vec<f64>,
}

/// Where a slot of the renumbered world comes from.
#[derive(Clone, Copy)]
enum Src {
    Old(usize),
    Entering(usize),
}

/// A column of the renumbered world: old slots' values, or entering ones.
fn column<T: Clone>(old: &[T], entering: &[T], src: &[Src]) -> Vec<T> {
    src.iter()
        .map(|s| match *s {
            Src::Old(k) => old[k].clone(),
            Src::Entering(i) => entering[i].clone(),
        })
        .collect()
}

/// Coordinates of an orientation (the angle in 2D, the quaternion in 3D) and of an
/// inertia (I in 2D, the principal moments in 3D) in a record.
const fn rot_len<D: Dim>() -> usize {
    if D::N == 2 {
        1
    } else {
        4
    }
}
const fn inertia_len<D: Dim>() -> usize {
    if D::N == 2 {
        1
    } else {
        3
    }
}

impl<D: Dim> World<D> {
    /// Numbers of a body's record: its moving state (position, orientation
    /// coordinates, velocity), then its static data ([`World::body_record`]).
    pub const MOVING_RECORD: usize = D::N + rot_len::<D>() + D::DOF;
    pub const BODY_RECORD: usize = Self::MOVING_RECORD + 6 + inertia_len::<D>() + D::INV_MASS_LEN;

    /// Body `k`'s moving state: position, orientation, velocity.
    fn moving_record(&self, k: usize, out: &mut Vec<f64>) {
        let b = &self.bodies;
        out.extend_from_slice(b.pos[k].as_ref());
        out.extend_from_slice(b.rot[k].coords());
        out.extend_from_slice(b.vel[k].as_ref());
    }

    /// Body `k`'s (a slot) record: position, orientation, velocity, then mass,
    /// inertia, M̂⁻¹, free degrees of freedom, volume, shape kind and index, material.
    pub fn body_record(&self, k: usize, out: &mut Vec<f64>) {
        self.moving_record(k, out);
        let b = &self.bodies;
        out.push(b.mass[k]);
        out.extend_from_slice(b.inertia[k].coords());
        D::inv_mass_coords(&b.inv_mass[k], out);
        let s = b.shape[k];
        out.extend([
            f64::from(b.free[k]),
            b.volume[k],
            f64::from(s.kind),
            f64::from(s.index),
            f64::from(b.material[k]),
        ]);
    }

    /// What `final.json` needs of a body another process holds: its moving state,
    /// then its shape kind and index and its material.
    pub const OUTPUT_RECORD: usize = Self::MOVING_RECORD + 3;
    pub fn output_record(&self, k: usize, out: &mut Vec<f64>) {
        self.moving_record(k, out);
        let (b, s) = (&self.bodies, self.bodies.shape[k]);
        out.extend([f64::from(s.kind), f64::from(s.index), f64::from(b.material[k])]);
    }

    /// Sets body `k`'s moving state from the start of a record.
    pub fn set_moving(&mut self, k: usize, x: &[f64]) {
        let b = &mut self.bodies;
        (b.pos[k], b.rot[k], b.vel[k]) = read_moving::<D>(x);
    }

    /// The values [`WholeScene`] holds, over the bodies held now (`per_body`: its
    /// per-body tables too).
    fn whole_of_held(&self, per_body: bool) -> WholeScene {
        // (−0.0: as `Iterator::sum` starts)
        let mut w = WholeScene {
            grain_volume: -0.0,
            ..Default::default()
        };
        for k in (0..self.bodies.len()).filter(|&k| self.is_grain(k)) {
            let s = self.bodies.shape[k];
            w.grains += 1;
            w.grain_volume += self.bodies.volume[k];
            w.max_grain_size = w.max_grain_size.max(self.shapes[s.kind as usize].size(s.index));
        }
        if per_body {
            // by global id (a world already partial leaves the others unknown: still)
            let n = self.ids.n_global(self.bodies.len());
            (w.movable, w.rho2) = (vec![false; n], vec![0.0; n]);
            for k in 0..self.bodies.len() {
                let g = self.ids.global(k as u32) as usize;
                (w.movable[g], w.rho2[g]) = (self.bodies.movable(k), self.bodies.rho2(k));
            }
        }
        w
    }

    /// The whole scene's grains: their number, total volume (area in 2D) and
    /// largest size (kept from before the first drop).
    pub fn grain_sums(&self) -> (usize, f64, f64) {
        let w = match &self.whole {
            Some(w) => std::borrow::Cow::Borrowed(w),
            None => std::borrow::Cow::Owned(self.whole_of_held(false)),
        };
        (w.grains, w.grain_volume, w.max_grain_size)
    }

    /// Whether impulses move body `g` (a global id) and its ρ², held or not.
    pub fn movable_rho2(&self, g: u32) -> (bool, f64) {
        match (self.ids.slot(g), &self.whole) {
            (Some(k), _) => (self.bodies.movable(k as usize), self.bodies.rho2(k as usize)),
            (None, Some(w)) => (w.movable[g as usize], w.rho2[g as usize]),
            (None, None) => (false, 0.0),
        }
    }

    /// Keeps only the bodies `keep` (ascending global ids, held), the contacts'
    /// bodies among them.
    pub fn hold(&mut self, keep: &[u32]) {
        if keep.len() == self.bodies.len() {
            return;
        }
        let src: Vec<Src> = keep
            .iter()
            .map(|&g| Src::Old(self.ids.slot(g).expect("a held body") as usize))
            .collect();
        self.renumber(keep.to_vec(), &src, &Bodies::default());
    }

    /// Admits the bodies of `entering` (global id, [`World::body_record`]) that it
    /// does not hold; the others are left as they are.
    pub fn admit(&mut self, entering: &[(u32, &[f64])]) {
        let mut new: Vec<(u32, &[f64])> = entering.iter().filter(|(g, _)| self.ids.slot(*g).is_none()).copied().collect();
        if new.is_empty() {
            return;
        }
        new.sort_unstable_by_key(|x| x.0);
        new.dedup_by_key(|x| x.0);
        let incoming = decode::<D>(&new);
        let (n, m) = (self.bodies.len(), new.len());
        let (mut globals, mut src) = (Vec::with_capacity(n + m), Vec::with_capacity(n + m));
        let (mut k, mut i) = (0, 0);
        while k < n || i < m {
            let old = (k < n).then(|| self.ids.global(k as u32));
            if i < m && old.is_none_or(|g| new[i].0 < g) {
                (globals.push(new[i].0), src.push(Src::Entering(i)), i += 1);
            } else {
                (globals.push(old.expect("an old slot")), src.push(Src::Old(k)), k += 1);
            }
        }
        self.renumber(globals, &src, &incoming);
    }

    /// The world with slots `src` (ascending global ids `globals`), entering
    /// bodies from `incoming`.
    fn renumber(&mut self, globals: Vec<u32>, src: &[Src], incoming: &Bodies<D>) {
        if self.whole.is_none() {
            self.whole = Some(self.whole_of_held(true));
        }
        let n_global = self.ids.n_global(self.bodies.len()) as u32;
        let mut new_of_old = vec![u32::MAX; self.bodies.len()];
        for (k, s) in src.iter().enumerate() {
            if let Src::Old(o) = *s {
                new_of_old[o] = k as u32;
            }
        }
        let active: Option<Vec<u32>> = self
            .scratch
            .active
            .as_ref()
            .map(|a| a.iter().map(|&k| self.ids.global(k)).collect());
        let (b, inc) = (&mut self.bodies, incoming);
        *b = Bodies {
            pos: column(&b.pos, &inc.pos, src),
            rot: column(&b.rot, &inc.rot, src),
            vel: column(&b.vel, &inc.vel, src),
            mass: column(&b.mass, &inc.mass, src),
            inertia: column(&b.inertia, &inc.inertia, src),
            inv_mass: column(&b.inv_mass, &inc.inv_mass, src),
            free: column(&b.free, &inc.free, src),
            volume: column(&b.volume, &inc.volume, src),
            shape: column(&b.shape, &inc.shape, src),
            material: column(&b.material, &inc.material, src),
        };
        let m = inc.len();
        self.names = column(&self.names, &vec![None; m], src);
        self.fixed = column(&self.fixed, &vec![false; m], src);
        self.reaction = column(&self.reaction, &vec![D::Twist::zero(); m], src);
        let s = &mut self.scratch;
        if s.v_begin.len() == new_of_old.len() {
            s.v_begin = column(&s.v_begin, &inc.vel, src);
        }
        let map = |k: &mut u32| {
            *k = new_of_old[*k as usize];
            assert!(*k != u32::MAX, "a contact, drive or box wall of a body the world drops");
        };
        self.contacts.bodies.iter_mut().for_each(|p| p.iter_mut().for_each(map));
        if new_of_old.contains(&u32::MAX) {
            // a drop (between steps): the step's buffers are stale
            (s.next.clear(), s.raw.clear());
        } else {
            s.next.bodies.iter_mut().for_each(|p| p.iter_mut().for_each(map));
            s.raw.iter_mut().for_each(|rc| {
                map(&mut rc.i);
                map(&mut rc.j);
            });
        }
        if let Some(r) = s.region.as_mut() {
            // a pair of the detection region with a body dropped cannot be detected
            r.pairs.retain_mut(|p| {
                *p = p.map(|k| new_of_old[k as usize]);
                !p.contains(&u32::MAX)
            });
        }
        self.drives.iter_mut().for_each(|d| map(&mut d.body));
        if let Some(bw) = self.box_walls.as_mut() {
            bw.walls.iter_mut().filter(|k| (**k as usize) < new_of_old.len()).for_each(map);
        }
        self.ids = std::mem::take(&mut self.ids)
            .respread(globals, n_global)
            .expect("slots ascend in global id");
        let ids = &self.ids;
        s.active = active
            .as_ref()
            .map(|a| a.iter().map(|&g| ids.slot(g).expect("an active body is held")).collect());
        s.active_global = active;
    }
}

/// A body's record ([`World::body_record`]) read back.
pub struct Record<D: Dim> {
    pub pos: D::Point,
    pub rot: D::Rot,
    pub vel: D::Twist,
    pub mass: f64,
    pub inertia: D::Inertia,
    pub inv_mass: D::InvMass,
    pub free: u8,
    pub volume: f64,
    pub shape: ShapeRef,
    pub material: u16,
}

/// A body's moving state (position, orientation, velocity) at the start of a record.
pub fn read_moving<D: Dim>(x: &[f64]) -> (D::Point, D::Rot, D::Twist) {
    let nr = rot_len::<D>();
    let (mut pos, mut rot, mut vel) = (D::Point::zero(), D::rot_identity(), D::Twist::zero());
    pos.as_mut().copy_from_slice(&x[..D::N]);
    rot.coords_mut().copy_from_slice(&x[D::N..D::N + nr]);
    vel.as_mut().copy_from_slice(&x[D::N + nr..World::<D>::MOVING_RECORD]);
    (pos, rot, vel)
}

/// A body's [`World::output_record`] read back: its moving state, shape and material.
pub fn read_output<D: Dim>(x: &[f64]) -> ((D::Point, D::Rot, D::Twist), ShapeRef, u16) {
    let r = &x[World::<D>::MOVING_RECORD..];
    let shape = ShapeRef {
        kind: r[0] as u16,
        index: r[1] as u32,
    };
    (read_moving::<D>(x), shape, r[2] as u16)
}

impl<D: Dim> Record<D> {
    /// The record `x` ([`World::BODY_RECORD`] numbers).
    pub fn read(x: &[f64]) -> Self {
        let ni = inertia_len::<D>();
        let (pos, rot, vel) = read_moving::<D>(x);
        let mut inertia = D::Inertia::default();
        // the static data: mass, inertia, M̂⁻¹, then the rest
        let s = &x[World::<D>::MOVING_RECORD..];
        inertia.coords_mut().copy_from_slice(&s[1..1 + ni]);
        let r = &s[1 + ni + D::INV_MASS_LEN..];
        Record {
            pos,
            rot,
            vel,
            mass: s[0],
            inertia,
            inv_mass: D::inv_mass_from(&s[1 + ni..]),
            free: r[0] as u8,
            volume: r[1],
            shape: ShapeRef {
                kind: r[2] as u16,
                index: r[3] as u32,
            },
            material: r[4] as u16,
        }
    }
}

/// The entering bodies' records as columns.
fn decode<D: Dim>(entering: &[(u32, &[f64])]) -> Bodies<D> {
    let mut b = Bodies::<D>::default();
    for (_, x) in entering {
        let r = Record::<D>::read(x);
        b.pos.push(r.pos);
        b.rot.push(r.rot);
        b.vel.push(r.vel);
        b.mass.push(r.mass);
        b.inertia.push(r.inertia);
        b.inv_mass.push(r.inv_mass);
        b.free.push(r.free);
        b.volume.push(r.volume);
        b.shape.push(r.shape);
        b.material.push(r.material);
    }
    b
}
