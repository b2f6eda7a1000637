//! The other ranks' subdomains as shell parts, from their ranks' descriptions
//! (docs/SCALING.md, "Shells from the subdomains' ranks"). In a step stepped in
//! part ([`crate::stepped`]), a rank makes full parts of its own subdomains only;
//! the framework still needs every subdomain's entity copies (the deformable
//! bodies' multiplicities and interface) and its copies of the world's rigid
//! bodies (theirs), and a part's count of contacts ([`nscdd::dd::LocalPart::len`]).
//! Each rank describes its own subdomains
//! ([`Shell`]: the entities and the rigid antagonists in the order its split makes
//! their copies, and the contacts), the ranks all-gather the descriptions
//! ([`share`], in [`nscdd::dd::Attached::solved_on`]), and a rank makes the other
//! ranks' parts from them: O(bodies per subdomain) values, not O(contacts).

use nscdd::dd::SolvedOn;

/// One subdomain of another rank, as its rank's split makes it.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Shell {
    pub sub: u32,
    /// The deformable bodies copied, in the order of their local ids.
    pub entities: Vec<u32>,
    /// The world's rigid bodies (global ids) the family copies into it, in the
    /// order its split asks for them (each once).
    pub rigid: Vec<u32>,
    /// Its contacts.
    pub contacts: u32,
}

/// This rank's subdomains described ([`Shell`]) and all-gathered, with the
/// number of contact nodes of each body this rank steps (`stepped`: (body, nodes),
/// the sets it filled: an entity's values in the gluing, [`crate::nodes`]);
/// returns the other ranks' subdomains (ascending) and every rank's node counts
/// (ascending bodies). `sides(a)`: contact `a`'s candidate body, deformable
/// antagonist body if any, and rigid antagonist (global id) if any, for the `n`
/// contacts of the family's list in its order.
pub fn share(
    on: &SolvedOn<'_>,
    n: usize,
    sides: impl Fn(usize) -> (u32, Option<u32>, Option<u32>),
    stepped: &[(u32, u32)],
) -> (Vec<Shell>, Vec<(u32, u32)>) {
    let mut own: Vec<(u32, u32)> = (0..n)
        .filter(|&a| (on.rank_of)(a) == on.rank)
        .map(|a| ((on.subdomain_of)(a), a as u32))
        .collect();
    own.sort_unstable();
    let mut mine = vec![stepped.len() as f64];
    mine.extend(stepped.iter().flat_map(|&(b, k)| [f64::from(b), f64::from(k)]));
    for run in own.chunk_by(|x, y| x.0 == y.0) {
        let mut d = Shell {
            sub: run[0].0,
            contacts: run.len() as u32,
            ..Default::default()
        };
        for &(_, a) in run {
            let (c, f, r) = sides(a as usize);
            for b in std::iter::once(c).chain(f) {
                if !d.entities.contains(&b) {
                    d.entities.push(b);
                }
            }
            if let Some(g) = r.filter(|g| !d.rigid.contains(g)) {
                d.rigid.push(g);
            }
        }
        pack(&d, &mut mine);
    }
    let (mut out, mut nodes) = (Vec::new(), Vec::new());
    for (r, m) in on.rounds.all_gather(&mine).iter().enumerate() {
        let k = m.first().map_or(0, |&k| k as usize);
        let Some(counts) = m.get(1..1 + 2 * k) else { continue };
        nodes.extend(counts.chunks_exact(2).map(|x| (x[0] as u32, x[1] as u32)));
        if r as u32 != on.rank {
            unpack(&m[1 + 2 * k..], &mut out);
        }
    }
    out.sort_by_key(|d| d.sub);
    nodes.sort_unstable();
    (out, nodes)
}

/// The shell parts of the other ranks' subdomains `shells` ([`share`]), each
/// made by `part(entities, contacts)` (its count of contacts), its copies of the
/// world's rigid bodies this rank holds (`held`: those it steps; the framework
/// gives each its id on the subdomain's rank) asked of `copy` (the framework's,
/// [`nscdd::dd::Attached::split`]).
pub fn make<P>(
    shells: &[Shell],
    held: impl Fn(u32) -> bool,
    copy: &mut dyn FnMut(u32, u32) -> u32,
    part: impl Fn(Vec<u32>, u32) -> P,
) -> Vec<(u32, P)> {
    let mut out = Vec::with_capacity(shells.len());
    for sh in shells {
        for &g in sh.rigid.iter().filter(|&&g| held(g)) {
            copy(sh.sub, g);
        }
        out.push((sh.sub, part(sh.entities.clone(), sh.contacts)));
    }
    out
}

/// (sub, entities, rigid bodies, contacts) appended to `out`.
fn pack(d: &Shell, out: &mut Vec<f64>) {
    out.extend([f64::from(d.sub), d.entities.len() as f64]);
    out.extend(d.entities.iter().map(|&e| f64::from(e)));
    out.push(d.rigid.len() as f64);
    out.extend(d.rigid.iter().map(|&g| f64::from(g)));
    out.push(f64::from(d.contacts));
}

/// The [`pack`]ed descriptions of `m`, into `out` (a truncated one is dropped).
fn unpack(m: &[f64], out: &mut Vec<Shell>) {
    let mut i = 0;
    let list = |i: usize| -> Option<(Vec<u32>, usize)> {
        let n = *m.get(i)? as usize;
        Some((m.get(i + 1..i + 1 + n)?.iter().map(|&x| x as u32).collect(), i + 1 + n))
    };
    while let Some(&sub) = m.get(i) {
        let Some((entities, j)) = list(i + 1) else { return };
        let Some((rigid, k)) = list(j) else { return };
        let Some(&contacts) = m.get(k) else { return };
        out.push(Shell {
            sub: sub as u32,
            entities,
            rigid,
            contacts: contacts as u32,
        });
        i = k + 1;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::cell::RefCell;

    /// Every rank's all-gather, filled in as the ranks call it.
    struct Gather(RefCell<Vec<Vec<f64>>>, u32);

    impl nscdd::dd::Rounds for Gather {
        fn all_gather(&self, mine: &[f64]) -> Vec<Vec<f64>> {
            self.0.borrow_mut()[self.1 as usize] = mine.to_vec();
            self.0.borrow().clone()
        }
        fn exchange(&self, _peers: &[u32], _out: &[Vec<f64>]) -> Vec<Vec<f64>> {
            unreachable!()
        }
        fn send(&self, _to: Vec<(u32, Vec<f64>)>) -> Vec<(u32, Vec<f64>)> {
            unreachable!()
        }
    }

    /// Rank 0 solves three contacts in subdomains 0 (body 2 on body 1, body 2 on
    /// the rigid body 7) and 1 (body 0 on the rigid body 7), rank 1 one in
    /// subdomain 2 (body 3 on the rigid body 5): each gets the other's subdomains as
    /// the other's split makes them (entities and rigid copies in first-seen
    /// order, each once).
    #[test]
    fn the_other_ranks_subdomains_as_their_split_makes_them() {
        let sub = [0u32, 1, 0, 2];
        let rank_of = |a: usize| u32::from(sub[a] == 2);
        let subdomain_of = |a: usize| sub[a];
        let sides = |a: usize| match a {
            0 => (2, Some(1), None),
            1 => (0, None, Some(7)),
            2 => (2, None, Some(7)),
            _ => (3, None, Some(5)),
        };
        let all = RefCell::new(vec![Vec::new(); 2]);
        let run = |rank: u32| {
            let g = Gather(RefCell::new(all.borrow().clone()), rank);
            let on = SolvedOn {
                rank,
                ranks: 2,
                rank_of: &rank_of,
                subdomain_of: &subdomain_of,
                rounds: &g,
            };
            let stepped = [(rank, 10 + rank)];
            let out = share(&on, 4, sides, &stepped);
            *all.borrow_mut() = g.0.into_inner();
            out
        };
        run(1);
        let (at0, nodes0) = run(0);
        let (at1, nodes1) = run(1);
        // (every rank's node counts of the bodies it steps)
        assert_eq!((&nodes0, &nodes1), (&vec![(0, 10), (1, 11)], &vec![(0, 10), (1, 11)]));
        let shell = |sub, entities: &[u32], rigid: &[u32], contacts| Shell {
            sub,
            entities: entities.to_vec(),
            rigid: rigid.to_vec(),
            contacts,
        };
        assert_eq!(at0, [shell(2, &[3], &[5], 1)]);
        assert_eq!(at1, [shell(0, &[2, 1], &[7], 2), shell(1, &[0], &[7], 1)]);
        // a truncated message drops the description it cuts
        let mut out = Vec::new();
        unpack(&all.borrow()[0][3..13], &mut out);
        assert_eq!(out, [shell(0, &[2, 1], &[7], 2)]);
    }
}
