//! The owner rule between repartitions: a contact whose key is in `kept` (sorted by
//! key) stays in its subdomain; a new contact goes to the cell of the grid of the
//! last repartition that holds its point.

use super::family::Family;
use super::partition::Grid;
use crate::model::ContactKey;

/// The owners between repartitions: a contact whose key is in `kept` (sorted by key)
/// stays in its subdomain; a new contact goes to the cell of `grid` (the grid of the
/// last repartition) that holds its point.
pub fn kept_owners<D: Family>(c: &D::Contacts, grid: &Grid, kept: &[(ContactKey, u32)]) -> Vec<u32> {
    let mut owner = OwnerOf::new(kept, grid);
    (0..D::len(c)).map(|a| owner.of(D::key(c, a), D::point(c, a))).collect()
}

/// The subdomain of one contact between repartitions (see [`kept_owners`]): also
/// what a rank holding its contacts decides on a raw contact before building it.
pub fn owner_of(kept: &[(ContactKey, u32)], grid: &Grid, key: ContactKey, p: [f64; 3]) -> u32 {
    OwnerOf::new(kept, grid).of(key, p)
}

/// [`owner_of`] over keys that come mostly in ascending order (a contact set, raw
/// contacts of one pair of shape kinds): the search gallops from the last key's
/// place (`kept`'s keys are distinct and sorted).
pub struct OwnerOf<'a> {
    kept: &'a [(ContactKey, u32)],
    grid: &'a Grid,
    /// Where the last key was found (or would be): the next search starts there.
    pub(super) at: usize,
}

impl<'a> OwnerOf<'a> {
    pub fn new(kept: &'a [(ContactKey, u32)], grid: &'a Grid) -> Self {
        OwnerOf { kept, grid, at: 0 }
    }
    pub fn of(&mut self, key: ContactKey, p: [f64; 3]) -> u32 {
        let k = self.kept;
        let (lo, hi) = if self.at < k.len() && k[self.at].0 <= key {
            let mut step = 1;
            while self.at + step < k.len() && k[self.at + step].0 <= key {
                step *= 2;
            }
            (self.at + step / 2, (self.at + step + 1).min(k.len()))
        } else {
            (0, k.len())
        };
        match k[lo..hi].binary_search_by_key(&key, |e| e.0) {
            Ok(i) => {
                self.at = lo + i;
                k[lo + i].1
            }
            Err(i) => {
                self.at = (lo + i).min(k.len().saturating_sub(1));
                self.grid.cell_of(p)
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The galloping search gives the plain binary search's answer for keys in any
    /// order (ascending runs, jumps back, absent keys).
    #[test]
    fn galloping_matches_binary_search() {
        let key = |i: u32, j: u32, f: u32| ContactKey { i, j, feature: f };
        let kept: Vec<(ContactKey, u32)> = (0..200u32).filter(|x| x % 3 != 0).map(|x| (key(x / 7, x, x % 2), x)).collect();
        let grid = Grid::from_bounds([0.0; 3], [1.0; 3], 2, 2, 1);
        let mut probes: Vec<ContactKey> = (0..220u32).map(|x| key(x / 7, x, x % 2)).collect();
        probes.extend((0..220u32).rev().step_by(5).map(|x| key(x / 7, x, x % 2)));
        probes.extend((0..50u32).map(|x| key(x * 13 % 31, x * 7 % 220, 0)));
        let mut owner = OwnerOf::new(&kept, &grid);
        for k in probes {
            let p = [0.7, 0.2, 0.5];
            let want = match kept.binary_search_by_key(&k, |e| e.0) {
                Ok(i) => kept[i].1,
                Err(_) => grid.cell_of(p),
            };
            assert_eq!(owner.of(k, p), want, "{k:?}");
        }
    }
}
