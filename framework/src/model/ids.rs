//! The world's body slots and the scene's global body ids (docs/SCALING.md,
//! "Compact arrays"). The world's arrays are indexed by dense slots; a body's
//! global id is its index in the scene. One process holds every body and the map is
//! the identity (nothing stored). A world holding part of the scene (an MPI rank's
//! bodies) keeps its slots ascending in global id, so every order taken from body
//! ids — contact keys, the pairs' i < j, sums in id order — is the global one.
//!
//! What leaves the world speaks global ids: contact keys, NSCDD's subdomains and
//! stores, the messages between processes, the outputs.
//!
//! ```
//! use nscdd::model::BodyIds;
//! let ids = BodyIds::spread(vec![1, 4, 5, 9], 12).unwrap();
//! assert_eq!((ids.global(2), ids.slot(5), ids.slot(6)), (5, Some(2), None));
//! assert_eq!(ids.n_global(4), 12);
//! let one = BodyIds::default(); // every body, slot = global id
//! assert_eq!((one.global(7), one.slot(7), one.n_global(10)), (7, Some(7), 10));
//! ```

/// Slot ↔ global id of a world's bodies (see the module docs).
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct BodyIds {
    /// Global id of each slot, ascending; empty: the identity.
    global: Vec<u32>,
    /// Bodies in the scene (0 with the identity: the world's own count).
    n_global: u32,
    /// Slot of each global id (`u32::MAX`: not held; empty with the identity):
    /// 4 bytes a body of the scene, so that a lookup is one load; kept up to date
    /// by [`BodyIds::respread`] in the time of the slots changed.
    slot_of: Vec<u32>,
}

impl BodyIds {
    /// Slots holding the bodies `global` (strictly ascending, each below
    /// `n_global`); `None` otherwise.
    pub fn spread(global: Vec<u32>, n_global: u32) -> Option<BodyIds> {
        BodyIds::default().respread(global, n_global)
    }

    /// [`BodyIds::spread`] reusing this map's table: its time is that of the slots
    /// before and after, not of the scene's bodies (once the table exists).
    pub fn respread(mut self, global: Vec<u32>, n_global: u32) -> Option<BodyIds> {
        let ascending = global.windows(2).all(|p| p[0] < p[1]);
        let below = global.last().is_none_or(|&g| g < n_global);
        if !(ascending && below) {
            return None;
        }
        if self.slot_of.len() != n_global as usize {
            self.slot_of = vec![u32::MAX; n_global as usize];
        } else {
            self.global.iter().for_each(|&g| self.slot_of[g as usize] = u32::MAX);
        }
        for (k, &g) in global.iter().enumerate() {
            self.slot_of[g as usize] = k as u32;
        }
        Some(BodyIds {
            global,
            n_global,
            slot_of: self.slot_of,
        })
    }

    /// Whether slot = global id (every body held, none other).
    #[inline]
    pub fn is_identity(&self) -> bool {
        self.global.is_empty() && self.n_global == 0
    }

    /// Global id of `slot`.
    #[inline]
    pub fn global(&self, slot: u32) -> u32 {
        if self.is_identity() {
            slot
        } else {
            self.global[slot as usize]
        }
    }

    /// Slot of global id `g`, if the world holds it.
    #[inline]
    pub fn slot(&self, g: u32) -> Option<u32> {
        if self.is_identity() {
            Some(g)
        } else {
            self.slot_of.get(g as usize).copied().filter(|&k| k != u32::MAX)
        }
    }

    /// The global ids of the slots (ascending); `None` with the identity.
    pub fn held(&self) -> Option<&[u32]> {
        (!self.is_identity()).then_some(&self.global[..])
    }

    /// Bodies in the scene, of a world of `n_slots` slots.
    #[inline]
    pub fn n_global(&self, n_slots: usize) -> usize {
        if self.is_identity() {
            n_slots
        } else {
            self.n_global as usize
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn spread_ids_must_ascend_below_the_count() {
        assert!(BodyIds::spread(vec![2, 1], 5).is_none());
        assert!(BodyIds::spread(vec![1, 1], 5).is_none());
        assert!(BodyIds::spread(vec![1, 5], 5).is_none());
        let ids = BodyIds::spread(vec![0, 3], 5).unwrap();
        assert_eq!(ids.held(), Some(&[0, 3][..]));
        assert_eq!(BodyIds::default().held(), None);
        // respread: the old slots forgotten, the new ones found
        let ids = ids.respread(vec![1, 3, 4], 5).unwrap();
        let slots: Vec<Option<u32>> = (0..6).map(|g| ids.slot(g)).collect();
        assert_eq!(slots, [None, Some(0), None, Some(1), Some(2), None]);
        assert_eq!(ids, BodyIds::spread(vec![1, 3, 4], 5).unwrap());
    }
}
