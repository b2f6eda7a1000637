//! The contact counts of an NSCDD step that outputs read, computed subdomain by
//! subdomain so that a rank holding only its subdomains gets the same integers as
//! one process: the number of contacts and the coordination numbers `z`, `z_m`
//! (`World::coordination`: grain–grain contacts carrying a normal impulse, and the
//! loaded contacts of the grains that are not rattlers).
//!
//! A contact belongs to one subdomain; a body's loaded contacts are the sum of its
//! counts in the subdomains holding it, asked of the other copies' ranks for the
//! bodies held by several (point to point); each body is then counted by its first
//! subdomain, and the per-subdomain integers are added (an all-gather on ranks).

use super::family::Family;
use super::partition::Decomposition;
use super::rank_reduce::per_subdomain;
use super::ranks::RankState;

/// The counts of a step (see the module docs).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Census {
    pub contacts: usize,
    /// Subdomains owning at least one contact.
    pub subdomains: usize,
    /// Contacts of the largest subdomain.
    pub largest: usize,
    /// Coordination numbers (NaN when not computed: the world has no box sample).
    pub z: f64,
    pub z_m: f64,
    /// A 3D box sample's bulk counts (`World3::bulk_measures_with`): Σ loaded
    /// contacts of the inner non-rattlers, their number, the inner grains, the inner
    /// rattlers.
    pub bulk: Option<[u64; 4]>,
    /// With a grid of cells (rigid bodies, [`BodySums`]): the kinetic energy and
    /// gravity potential, and a 3D box sample's grain volume in the bulk box.
    pub energies: Option<(f64, f64)>,
    pub bulk_volume: Option<f64>,
}

/// The sums over bodies of the outputs, per grid cell (each body in the cell of its
/// centre, the bodies of a cell in id order, the cells added in cell order): the
/// same bits in one process and over ranks, where each rank adds its cells' bodies
/// (it holds them, [`super::owned`]). With one cell, the world's own sums.
pub(super) struct BodySums<'a> {
    pub grid: &'a super::partition::Grid,
}

/// Values per cell in [`BodySums`]: Σ kinetic energy, Σ m g·x, Σ bulk volume, the
/// inner grains without contacts.
const SUMS: usize = 4;

impl BodySums<'_> {
    /// The sums of the cells `own` accepts (zero for the others).
    /// (`bulk`: the 3D bulk box, [`Family::bulk_box`])
    fn per_cell<D: Family>(
        &self,
        w: &D::World,
        d: &Decomposition<D>,
        bulk: Option<([f64; 3], [f64; 3])>,
        own: &dyn Fn(usize) -> bool,
    ) -> Vec<[f64; SUMS]> {
        let mut out = vec![[0.0; SUMS]; self.grid.len()];
        crate::step::each_body(D::n_bodies(w), D::stepped(w), |g| {
            let p = D::position(w, g);
            let c = self.grid.cell_of(p) as usize;
            if !own(c) {
                return;
            }
            let x = &mut out[c];
            if let Some((ek, mgx)) = D::body_energies(w, g) {
                x[0] += ek;
                x[1] -= mgx;
            }
            if let (Some((lo, hi)), true) = (bulk, D::is_grain(w, g)) {
                x[2] += D::grain_in_box(w, g, lo, hi);
                let inner = (0..3).all(|k| p[k] > lo[k] && p[k] < hi[k]);
                x[3] += (inner && d.mult_of(g as u32) == 0) as u8 as f64;
            }
        });
        out
    }
}

/// [`BodySums`] by subdomain: the first subdomains are the grid's cells (by model,
/// the families' come next, with no bodies of their own: zeros).
struct CellValues(Option<Vec<[f64; SUMS]>>);

impl CellValues {
    /// Values a subdomain adds.
    fn k(&self) -> usize {
        if self.0.is_some() {
            SUMS
        } else {
            0
        }
    }
    fn add(&self, s: usize, v: &mut Vec<f64>) {
        if let Some(c) = &self.0 {
            v.extend_from_slice(c.get(s).unwrap_or(&[0.0; SUMS]));
        }
    }
}

/// Each subdomain's loaded contacts per local body, and its loaded grain–grain contacts.
fn loaded<D: Family>(w: &D::World, d: &Decomposition<D>, s: usize) -> (Vec<u32>, u64) {
    let sub = &d.subs[s];
    let mut count = vec![0u32; sub.body_global.len()];
    let mut ngg = 0u64;
    let grain = |l: u32| D::is_grain(w, sub.body_global[l as usize] as usize);
    for a in 0..D::len(&sub.contacts) {
        if D::r(&sub.contacts, a)[0] > 0.0 {
            let [i, j] = D::bodies(&sub.contacts, a);
            count[i as usize] += 1;
            count[j as usize] += 1;
            ngg += (grain(i) && grain(j)) as u64;
        }
    }
    (count, ngg)
}

/// The bodies held by several subdomains and by one of this rank's, ascending: (body,
/// its first subdomain, its loaded contacts summed over its copies; the other
/// ranks' counts asked of their ranks, [`super::shells::copy_counts`]). Only these
/// bodies, not one entry per scene body: a step's census allocates nothing N-sized
/// here.
fn shared_totals<D: Family>(d: &Decomposition<D>, ranks: Option<&mut RankState>, counts: &[Option<Vec<u32>>]) -> Vec<(u32, u32, u32)> {
    let mut out: Vec<(u32, u32, u32)> = Vec::new();
    // (copies sorted by body, then subdomain: a body's first entry is its first subdomain)
    for (g, s, n) in super::shells::copy_counts(d, ranks, counts) {
        match out.last_mut() {
            Some(x) if x.0 == g => x.2 += n,
            _ => out.push((g, s, n)),
        }
    }
    out
}

/// The census of the step of `d` (on ranks: collective).
pub(super) fn census<D: Family>(d: &Decomposition<D>, w: &D::World, mut ranks: Option<&mut RankState>, sums: Option<BodySums>) -> Census {
    let ns = d.subs.len();
    let own = |s: usize| ranks.as_ref().is_none_or(|r| r.is_own(s as u32));
    let mut out = Census {
        z: f64::NAN,
        z_m: f64::NAN,
        ..Default::default()
    };
    let bulk = D::bulk_box(w);
    let sums = sums.filter(|b| ns.is_multiple_of(b.grid.len()));
    let cells = CellValues(sums.map(|b| b.per_cell(w, d, bulk, &own)));
    let (k, add_cell) = (cells.k(), |s: usize, v: &mut Vec<f64>| cells.add(s, v));
    if !D::wants_coordination(w) {
        let n = |s: usize, v: &mut Vec<f64>| {
            v.push(D::len(&d.subs[s].contacts) as f64);
            add_cell(s, v);
        };
        let per = per_subdomain(ranks, ns, 1 + k, n);
        out.contacts = per.chunks_exact(1 + k).map(|x| x[0] as usize).sum();
        out.subdomains = per.chunks_exact(1 + k).filter(|x| x[0] > 0.0).count();
        out.largest = per.chunks_exact(1 + k).map(|x| x[0] as usize).max().unwrap_or(0);
        out.add_sums(&per, 1, k, bulk.is_some());
        return out;
    }
    let (counts, ngg_of): (Vec<Option<Vec<u32>>>, Vec<u64>) = (0..ns)
        .map(|s| {
            if !own(s) {
                return (None, 0);
            }
            let (c, n) = loaded(w, d, s);
            (Some(c), n)
        })
        .unzip();
    let shared = shared_totals(d, ranks.as_deref_mut(), &counts);
    // per subdomain: contacts, loaded grain–grain contacts, non-rattler grains and
    // their loaded contacts, each body counted by its first subdomain
    let inner = |g: usize| bulk.is_some_and(|(lo, hi)| (0..3).all(|k| D::position(w, g)[k] > lo[k] && D::position(w, g)[k] < hi[k]));
    let aggregate = |s: usize, v: &mut Vec<f64>| {
        let sub = &d.subs[s];
        let (c, ngg) = (counts[s].as_ref().expect("an own subdomain"), ngg_of[s]);
        let mut a = [0u64; 6]; // n_m, sum_m, then the bulk counts
        for (l, &g) in sub.body_global.iter().enumerate() {
            // (a body held by one subdomain: its own count; by several: their sum)
            let (first, n) = match sub.copy_mult[l] >= 2 {
                true => shared
                    .binary_search_by_key(&g, |x| x.0)
                    .map_or((s as u32, c[l]), |i| (shared[i].1, shared[i].2)),
                false => (s as u32, c[l]),
            };
            let (g, n) = (g as usize, u64::from(n));
            if first != s as u32 || !D::is_grain(w, g) {
                continue;
            }
            if n >= 2 {
                a[0] += 1;
                a[1] += n;
            }
            if inner(g) {
                a[4] += 1;
                if n >= 2 {
                    a[2] += n;
                    a[3] += 1;
                } else {
                    a[5] += 1;
                }
            }
        }
        v.extend([D::len(&sub.contacts) as f64, ngg as f64]);
        v.extend(a.map(|x| x as f64));
        add_cell(s, v);
    };
    let per = per_subdomain(ranks, ns, 8 + k, aggregate);
    let (mut ngg, mut n_m, mut sum_m, mut b) = (0u64, 0u64, 0u64, [0u64; 4]);
    for x in per.chunks_exact(8 + k) {
        out.contacts += x[0] as usize;
        out.subdomains += (x[0] > 0.0) as usize;
        out.largest = out.largest.max(x[0] as usize);
        (ngg, n_m, sum_m) = (ngg + x[1] as u64, n_m + x[2] as u64, sum_m + x[3] as u64);
        for k in 0..4 {
            b[k] += x[4 + k] as u64;
        }
    }
    let idle = out.add_sums(&per, 8, k, bulk.is_some());
    if bulk.is_some() {
        // the inner grains without contacts are rattlers
        let idle = idle.unwrap_or_else(|| {
            (0..D::n_bodies(w))
                .filter(|&g| d.mult_of(g as u32) == 0 && D::is_grain(w, g) && inner(g))
                .count() as u64
        });
        out.bulk = Some([b[0], b[1], b[2] + idle, b[3] + idle]);
    }
    let ng = D::n_grains(w);
    out.z = if ng > 0 { 2.0 * ngg as f64 / ng as f64 } else { 0.0 };
    out.z_m = if n_m > 0 { sum_m as f64 / n_m as f64 } else { 0.0 };
    out
}

impl Census {
    /// The load imbalance of `ns` subdomains: the largest one's contacts over the
    /// mean (1: balanced; ns: every contact in one subdomain; 1 without contacts).
    pub fn imbalance(&self, ns: usize) -> f64 {
        if self.contacts == 0 {
            1.0
        } else {
            self.largest as f64 * ns as f64 / self.contacts as f64
        }
    }

    /// The cells' [`BodySums`] (`k` values at `at` of each subdomain's `per`, none
    /// when `k` = 0) added in cell order; returns the inner grains without contacts.
    fn add_sums(&mut self, per: &[f64], at: usize, k: usize, bulk: bool) -> Option<u64> {
        if k == 0 {
            return None;
        }
        let (mut ek, mut ep, mut vol, mut idle) = (0.0, 0.0, 0.0, 0u64);
        for x in per.chunks_exact(at + k) {
            ek += x[at];
            ep += x[at + 1];
            vol += x[at + 2];
            idle += x[at + 3] as u64;
        }
        self.energies = Some((ek, ep));
        self.bulk_volume = bulk.then_some(vol);
        Some(idle)
    }
}
