//! An attached family stepped in part on each rank (docs/SCALING.md, "Deformable
//! bodies stepped per rank"): after each step's partition the framework tells the
//! families where each of their contacts is solved ([`SolvedOn`], given to
//! [`Attached::solved_on`]), before they split their contacts into parts. A family
//! that uses it does the work of its contacts' bodies on the ranks solving them
//! only, and after its [`Attached::write_back`] the ranks exchange what each
//! computed ([`Attached::share_stepped`], the family's rounds), so that what its
//! residual and position update read on each rank is what one process reads
//! there.

use super::attach::{with_cells, Attached, SteppedOn};
use super::family::Family;
use super::ranks::RankState;

/// Where this step's contacts of one attached family are solved.
pub struct SolvedOn<'a> {
    /// This rank and the number of ranks.
    pub rank: u32,
    pub ranks: u32,
    /// The rank solving contact `a` (the family's [`Attached::points`] order).
    pub rank_of: &'a dyn Fn(usize) -> u32,
    /// The subdomain of contact `a` (the `owner` [`Attached::split`] gets).
    pub subdomain_of: &'a dyn Fn(usize) -> u32,
    /// Rounds among the ranks the family may run in [`Attached::solved_on`]
    /// (collective: every rank's family runs the same rounds in the same order).
    pub rounds: &'a dyn Rounds,
}

/// Communication rounds among the ranks for a family stepped in part
/// ([`SolvedOn::rounds`]), counted with the reductions in `ranks.json`.
pub trait Rounds {
    /// Every rank's `mine` (any length), by rank (collective).
    fn all_gather(&self, mine: &[f64]) -> Vec<Vec<f64>>;
    /// One point-to-point round: `out[i]` goes to rank `peers[i]`, whose message
    /// comes back in the same place. The relation is symmetric (a peer lists this
    /// rank in the same round; a message may be empty).
    fn exchange(&self, peers: &[u32], out: &[Vec<f64>]) -> Vec<Vec<f64>>;
    /// Values to ranks that need not expect them: `to` = (rank, values), each rank
    /// once, not this one. Returns (rank, values) of every rank that sent this one
    /// something, ascending (collective: one all-to-all of the lengths, then one
    /// point-to-point round with the ranks sent to or receiving from this one).
    fn send(&self, to: Vec<(u32, Vec<f64>)>) -> Vec<(u32, Vec<f64>)>;
}

/// Runs `f` with the [`Rounds`] of the ranks `rs` (a family's collective rounds
/// outside the step: [`Attached::gather_whole`]).
pub fn with_rounds(rs: &mut RankState, f: impl FnOnce(&dyn Rounds)) {
    f(&RankRounds(std::cell::RefCell::new(rs)))
}

/// [`Rounds`] over the ranks of a run.
struct RankRounds<'a>(std::cell::RefCell<&'a mut RankState>);

impl Rounds for RankRounds<'_> {
    fn all_gather(&self, mine: &[f64]) -> Vec<Vec<f64>> {
        let (counts, all) = self.0.borrow_mut().all_gather_any(mine);
        let mut at = 0;
        counts
            .iter()
            .map(|&n| {
                at += n;
                all[at - n..at].to_vec()
            })
            .collect()
    }
    fn exchange(&self, peers: &[u32], out: &[Vec<f64>]) -> Vec<Vec<f64>> {
        let mut inbox = vec![Vec::new(); peers.len()];
        if !peers.is_empty() {
            let rs = &mut *self.0.borrow_mut();
            rs.cluster.exchange(peers, out, &mut inbox);
            // (counted with the reductions' messages and values)
            rs.totals.reduce.messages += peers.len() as u64;
            rs.totals.reduce.values += out.iter().map(|m| m.len() as u64).sum::<u64>();
        }
        inbox
    }
    fn send(&self, to: Vec<(u32, Vec<f64>)>) -> Vec<(u32, Vec<f64>)> {
        let rs = &mut *self.0.borrow_mut();
        let mut out = vec![Vec::new(); rs.cluster.size() as usize];
        for (r, m) in to {
            out[r as usize] = m;
        }
        let (peers, inbox) = rs.send_ranks(out);
        peers.into_iter().zip(inbox).filter(|x| !x.1.is_empty()).collect()
    }
}

/// After the families' write-back: each family stepped in part (`on`) runs its
/// rounds ([`Attached::share_stepped`], with every rank's cells of its next
/// detection, `cells`; collective: `on` is the same on every rank).
pub(super) fn share_stepped<D: Family>(fams: &mut [&mut dyn Attached<D>], (on, cells): SteppedOn<'_>, mut ranks: Option<&mut RankState>) {
    for (f, (fam, _)) in fams.iter_mut().zip(on).enumerate().filter(|x| *x.1 .1) {
        let Some(rs) = ranks.as_deref_mut() else { return };
        let rank = (rs.cluster.rank(), rs.cluster.size());
        match cells.get(f).and_then(Option::as_ref) {
            Some(index) => with_cells(index, rank, |c| with_rounds(rs, |r| fam.share_stepped(r, Some(c)))),
            None => with_rounds(rs, |r| fam.share_stepped(r, None)),
        }
        if let Some((here, n)) = fam.stepped_bodies() {
            rs.totals.family_bodies_stepped += here as u64;
            rs.totals.family_bodies += n as u64;
        }
        rs.totals.family_bodies_built += fam.built_bodies().unwrap_or(0) as u64;
        rs.totals.family_bodies_near += fam.near_bodies().or(fam.stepped_bodies().map(|x| x.1)).unwrap_or(0) as u64;
    }
}

/// No contact on any rank: the families' V⁺ is their V_free (each family stepped
/// in part then shares it, [`share_stepped`]).
pub(super) fn write_back_alone<D: Family>(
    w: &mut D::World,
    fams: &mut [&mut dyn Attached<D>],
    on: SteppedOn<'_>,
    ranks: Option<&mut RankState>,
) {
    for fam in fams.iter_mut() {
        fam.write_back(w, &[]);
    }
    share_stepped(fams, on, ranks);
}

/// After the partition (`owner`: each family's contacts' subdomains; the ranks'
/// `rank_of` decided): each family told where its contacts are solved
/// ([`Attached::solved_on`]), `stepped` whether it is stepped in part.
pub(super) fn solved_on<D: Family>(
    w: &D::World,
    fams: &mut [&mut dyn Attached<D>],
    (owner, mut ranks): (&[Vec<u32>], Option<&mut RankState>),
    stepped: &mut Vec<bool>,
) {
    stepped.clear();
    for (f, fam) in fams.iter_mut().enumerate() {
        let s = match ranks.as_deref_mut() {
            Some(rs) => {
                let o = &owner[f];
                let sub_rank = rs.rank_of.clone();
                let rank_of = |a: usize| sub_rank[o[a] as usize];
                let subdomain_of = |a: usize| o[a];
                let (rank, size) = (rs.cluster.rank(), rs.cluster.size());
                let rounds = RankRounds(std::cell::RefCell::new(rs));
                let on = SolvedOn {
                    rank,
                    ranks: size,
                    rank_of: &rank_of,
                    subdomain_of: &subdomain_of,
                    rounds: &rounds,
                };
                fam.solved_on(w, Some(&on))
            }
            None => fam.solved_on(w, None),
        };
        stepped.push(s);
    }
}
