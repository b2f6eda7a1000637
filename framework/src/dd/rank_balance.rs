//! Which rank sweeps which subdomain: contiguous runs of subdomain ids balanced by
//! contact count ([`contiguous_ranks`]), or a greedy assignment when that is much
//! better balanced ([`balanced_ranks`]). Used by [`super::ranks`] at every
//! repartition.

/// Rank of each subdomain: contiguous runs of ids, one or more per rank, balanced by
/// `loads` (each rank gets at least one subdomain; needs `loads.len() ≥ ranks`).
/// A rank's run ends once the loads so far reach its share of the total, or when
/// the remaining subdomains are just enough for the remaining ranks.
pub fn contiguous_ranks(loads: &[usize], ranks: u32) -> Vec<u32> {
    let (n, p) = (loads.len(), ranks.max(1) as usize);
    assert!(n >= p, "{n} subdomains cannot feed {p} ranks");
    let total: u128 = loads.iter().map(|&l| l as u128).sum();
    let mut out = vec![0u32; n];
    let (mut r, mut acc) = (0usize, 0u128);
    for (k, &l) in loads.iter().enumerate() {
        out[k] = r as u32;
        acc += l as u128;
        let (subs_left, ranks_left) = (n - k - 1, p - r - 1);
        if ranks_left > 0 && (subs_left == ranks_left || acc * p as u128 >= total * (r as u128 + 1)) {
            r += 1;
        }
    }
    out
}

/// Rank of each of `ns` subdomains balanced by the items each owns (`owner`: an
/// item's subdomain, below `ns`): [`balanced_ranks`] over their counts. The rule of
/// a repartition ([`super::RankState::assign`]) and of the restart's part of a
/// rank ([`super::RestartPart`]), which must agree.
pub fn ranks_by_owner(owner: impl IntoIterator<Item = u32>, ns: usize, ranks: u32) -> Vec<u32> {
    let mut loads = vec![0usize; ns];
    for o in owner {
        loads[o as usize] += 1;
    }
    balanced_ranks(&loads, ranks)
}

/// Rank of each subdomain: the contiguous runs of [`contiguous_ranks`] (few peers)
/// unless their largest load exceeds by more than 5 % that of a greedy assignment
/// (largest subdomain first to the least loaded rank, ties to the smaller rank),
/// which then wins: with few subdomains per rank, contiguous runs can be far from
/// balanced (3 subdomains on 2 ranks), and a rank waits for the slowest at every
/// gluing.
pub fn balanced_ranks(loads: &[usize], ranks: u32) -> Vec<u32> {
    let p = ranks.max(1) as usize;
    let max_load = |of: &[u32]| {
        let mut l = vec![0usize; p];
        for (s, &r) in of.iter().enumerate() {
            l[r as usize] += loads[s];
        }
        l.into_iter().max().unwrap_or(0)
    };
    let runs = contiguous_ranks(loads, ranks);
    let mut by_load: Vec<usize> = (0..loads.len()).collect();
    by_load.sort_by_key(|&s| (std::cmp::Reverse(loads[s]), s));
    let (mut greedy, mut acc) = (vec![0u32; loads.len()], vec![0usize; p]);
    for (k, &s) in by_load.iter().enumerate() {
        // the first p subdomains go one to each rank, so that none is left empty
        let r = if k < p {
            k
        } else {
            (0..p).min_by_key(|&r| (acc[r], r)).unwrap_or(0)
        };
        acc[r] += loads[s];
        greedy[s] = r as u32;
    }
    if max_load(&runs) as f64 > 1.05 * max_load(&greedy) as f64 {
        greedy
    } else {
        runs
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn contiguous_runs_feed_every_rank_and_balance() {
        assert_eq!(contiguous_ranks(&[5, 5, 5, 5], 2), [0, 0, 1, 1]);
        assert_eq!(contiguous_ranks(&[5, 5, 5, 5], 4), [0, 1, 2, 3]);
        assert_eq!(contiguous_ranks(&[0, 0, 0, 0], 3), [0, 1, 2, 2]);
        assert_eq!(contiguous_ranks(&[100, 1, 1, 1], 2), [0, 1, 1, 1]);
        // the last ranks still get one subdomain each
        assert_eq!(contiguous_ranks(&[1, 1, 1, 100], 3), [0, 0, 1, 2]);
    }

    #[test]
    fn a_much_better_balanced_greedy_assignment_wins() {
        // runs: {0,1} 10, {2} 6 is within 5 % of the best: contiguous kept
        assert_eq!(balanced_ranks(&[5, 5, 6, 4], 2), [0, 0, 1, 1]);
        // runs give 12 + 4 = 16 against 10; greedy: {8, 2} and {6, 4} = 10 / 10
        assert_eq!(contiguous_ranks(&[8, 6, 4, 2], 2), [0, 0, 1, 1]);
        assert_eq!(balanced_ranks(&[8, 6, 4, 2], 2), [0, 1, 1, 0]);
        // every rank gets a subdomain
        let r = balanced_ranks(&[50, 1, 1, 1, 1], 4);
        for k in 0..4 {
            assert!(r.contains(&k), "{r:?}");
        }
    }
}
