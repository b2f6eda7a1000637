//! Block-sparse NLGS on a local problem `u = W r + q`, written once for D = 2 and 3.
//!
//! W is stored per contact as its symmetrised diagonal block `W_αα` and the
//! off-diagonal D × D blocks `W_αβ` of row α in compressed rows. A sweep visits the
//! contacts in storage order: `u0_α = q_α + Σ_{β≠α} W_αβ r_β`, then `r_α` ← the
//! one-contact solution for `(W_αα, u0_α, μ_α)` (the exact 2D enumeration of
//! [`crate::dim::coulomb2`], or [`crate::dim::coulomb3`] whose block data are
//! precomputed once).

use super::FcProblem;
use crate::dim::coulomb2 as c2;
use crate::dim::coulomb3 as c3;
use crate::norms::Sums;

/// W in block form.
pub struct Blocks<const D: usize> {
    /// W_αα (2D: symmetrised).
    pub diag: Vec<[[f64; D]; D]>,
    /// Off-diagonal blocks of row α: `ptr[α]..ptr[α + 1]`.
    pub ptr: Vec<usize>,
    pub col: Vec<u32>,
    pub blk: Vec<[[f64; D]; D]>,
    /// 3D: the precomputed data of the diagonal blocks, and the full block of those
    /// that are not symmetric.
    pre3: Vec<(c3::Sym3, c3::Pre3, Option<c3::Full3>)>,
}

impl<const D: usize> Blocks<D> {
    pub fn assemble(p: &FcProblem) -> Self {
        assert_eq!(p.dim, D);
        let nc = p.nc;
        let w = &p.w;
        let mut diag = vec![[[0.0; D]; D]; nc];
        let mut off: Vec<(u32, u32, u8, u8, f64)> = Vec::new();
        for k in 0..w.rows.len() {
            let (i, j, v) = (w.rows[k], w.cols[k], w.vals[k]);
            let (a, b) = (i / D, j / D);
            if a == b {
                diag[a][i % D][j % D] += v;
            } else {
                off.push((a as u32, b as u32, (i % D) as u8, (j % D) as u8, v));
            }
        }
        // by row block (a counting sort), then by column block within a row (a
        // stable sort of a few entries): duplicates are summed in file order
        let mut start = vec![0usize; nc + 1];
        for e in &off {
            start[e.0 as usize + 1] += 1;
        }
        for a in 0..nc {
            start[a + 1] += start[a];
        }
        let mut sorted = vec![(0, 0, 0, 0, 0.0); off.len()];
        let mut next = start.clone();
        for &e in &off {
            sorted[next[e.0 as usize]] = e;
            next[e.0 as usize] += 1;
        }
        for a in 0..nc {
            sorted[start[a]..start[a + 1]].sort_by_key(|x| x.1);
        }
        let off = sorted;
        let mut ptr = vec![0usize; nc + 1];
        let mut col = Vec::new();
        let mut blk: Vec<[[f64; D]; D]> = Vec::new();
        let mut last = None;
        for &(a, b, x, y, v) in &off {
            if last != Some((a, b)) {
                last = Some((a, b));
                col.push(b);
                blk.push([[0.0; D]; D]);
                ptr[a as usize + 1] += 1;
            }
            blk.last_mut().expect("pushed")[x as usize][y as usize] += v;
        }
        for a in 0..nc {
            ptr[a + 1] += ptr[a];
        }
        // 2D: the exact enumeration takes a symmetric block (½(W_nt + W_tn)); 3D keeps
        // the file's block and solves non-symmetric ones with the full-block solver
        let sym3 = |d: &[[f64; D]; D]| {
            let scale = d.iter().flatten().fold(0.0_f64, |m, x| m.max(x.abs()));
            (0..D).all(|x| (0..D).all(|y| (d[x][y] - d[y][x]).abs() <= 1e-15 * scale))
        };
        let pre3 = if D == 3 {
            diag.iter()
                .map(|d| {
                    let s = [d[0][0], d[0][1], d[0][2], d[1][1], d[1][2], d[2][2]];
                    let full = [
                        [d[0][0], d[0][1], d[0][2]],
                        [d[1][0], d[1][1], d[1][2]],
                        [d[2][0], d[2][1], d[2][2]],
                    ];
                    (s, c3::precompute(&s), if sym3(d) { None } else { Some(full) })
                })
                .collect()
        } else {
            Vec::new()
        };
        for d in diag.iter_mut().filter(|_| D == 2) {
            for x in 0..D {
                for y in x + 1..D {
                    let s = 0.5 * (d[x][y] + d[y][x]);
                    d[x][y] = s;
                    d[y][x] = s;
                }
            }
        }
        Blocks { diag, ptr, col, blk, pre3 }
    }

    /// `q_α + Σ_{β≠α} W_αβ r_β`.
    #[inline(always)]
    fn off_sum(&self, a: usize, q: [f64; D], r: &[[f64; D]]) -> [f64; D] {
        let mut u = q;
        for k in self.ptr[a]..self.ptr[a + 1] {
            let (m, rb) = (&self.blk[k], &r[self.col[k] as usize]);
            for x in 0..D {
                let mut dot = 0.0;
                for y in 0..D {
                    dot += m[x][y] * rb[y];
                }
                u[x] += dot;
            }
        }
        u
    }

    /// u = W r + q.
    pub fn velocity(&self, q: &[[f64; D]], r: &[[f64; D]], u: &mut [[f64; D]]) {
        for a in 0..q.len() {
            let mut v = self.off_sum(a, q[a], r);
            let w = &self.diag[a];
            for x in 0..D {
                for y in 0..D {
                    v[x] += w[x][y] * r[a][y];
                }
            }
            u[a] = v;
        }
    }

    /// The one-contact solution of contact α.
    #[inline(always)]
    fn local(&self, a: usize, u0: [f64; D], mu: f64, prev: [f64; D]) -> [f64; D] {
        let mut out = [0.0; D];
        if D == 2 {
            let w = &self.diag[a];
            let r = c2::solve([w[0][0], w[0][1], w[1][1]], [u0[0], u0[1]], 0.0, mu);
            out[..2].copy_from_slice(&r);
        } else {
            let (w, pre, full) = &self.pre3[a];
            let r = match full {
                None => c3::solve_pre_warm(w, pre, [u0[0], u0[1], u0[2]], 0.0, mu, [prev[0], prev[1], prev[2]]),
                Some(f) => c3::solve_full(f, [u0[0], u0[1], u0[2]], 0.0, mu),
            };
            out[..3].copy_from_slice(&r);
        }
        out
    }

    /// One NLGS sweep in storage order, relaxed by ω ([`crate::solver::relax`]).
    #[inline(never)]
    pub fn sweep(&self, q: &[[f64; D]], mu: &[f64], r: &mut [[f64; D]], omega: f64) {
        for a in 0..q.len() {
            let u0 = self.off_sum(a, q[a], r);
            let mut rn = self.local(a, u0, mu[a], r[a]);
            if omega != 1.0 {
                crate::solver::relax(&r[a], &mut rn, omega, |z| crate::norms::project_cone(z, mu[a]));
            }
            r[a] = rn;
        }
    }
}

impl<const D: usize> Blocks<D> {
    /// LMGC90's check pass: the sums of every contact's local solution with the
    /// others as they are; `r` is not changed.
    pub fn check(&self, q: &[[f64; D]], mu: &[f64], r: &[[f64; D]], sums: &mut Sums) {
        for a in 0..q.len() {
            let u0 = self.off_sum(a, q[a], r);
            let ro = r[a];
            let rn = self.local(a, u0, mu[a], ro);
            let w = &self.diag[a];
            let (mut wr_old, mut wr, mut du) = ([0.0; D], [0.0; D], [0.0; D]);
            for x in 0..D {
                for y in 0..D {
                    wr_old[x] += w[x][y] * ro[y];
                    wr[x] += w[x][y] * rn[y];
                }
                du[x] = wr[x] - wr_old[x];
            }
            sums.add(&ro, &rn, &du, &wr_old, &wr);
        }
    }
}
