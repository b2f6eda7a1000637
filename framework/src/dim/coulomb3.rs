//! The one-contact 3D Signorini–Coulomb solver.
//!
//! For one contact α with the symmetric positive (semi-)definite Delassus block
//! `W = W_αα` (local frame (n, t1, t2), normal first) and the part of its local
//! velocity that does not depend on its own impulse, `u0 = u − W r`, find
//! `r = (r_n, r_t)` with `u = W r + u0` such that
//!
//! ```text
//!   s = u_n − ū ≥ 0,   r_n ≥ 0,   s · r_n = 0             (Signorini, shifted by ū)
//!   |r_t| ≤ μ r_n,   |r_t| < μ r_n ⇒ u_t = 0,
//!   u_t ≠ 0 ⇒ r_t = −μ r_n u_t / |u_t|                      (Coulomb, round cone)
//! ```
//!
//! The 3D cone is round, so the 2D enumeration of four faces does not carry over.
//! The method here stays *exact* (no tolerance to tune, no iteration count), which
//! is what makes NLGS results reproducible and its convergence measurable:
//!
//! 1. **No contact**: `s0 = u0_n − ū ≥ 0` gives `r = 0`.
//! 2. **Stick**: `r = −W⁻¹ (s0, u0_t)` if it lies in the cone.
//! 3. **Slide**, when the normal is decoupled from the tangent (`W_nt = 0`, always
//!    the case for spheres, whose lever arms are along n): `r_n = −s0 / W_nn`, and
//!    r_t minimises `½ r_tᵀ W_tt r_t + u0_t · r_t` on the disk `|r_t| ≤ μ r_n`
//!    (maximal dissipation): `r_t = −(W_tt + λ I)⁻¹ u0_t` with `λ ≥ 0` the root of
//!    the monotone secular equation `|r_t(λ)| = μ r_n` (Newton on `1/|r_t|`, which is
//!    almost linear in λ; closed form `λ = |u0_t|/(μ r_n) − W_tt` when W_tt is
//!    isotropic).
//! 4. **Slide**, general coupled block: the slip direction is parametrised by an
//!    angle φ, `r_t = μ r_n (cos φ, sin φ)`; `u_n = ū` fixes
//!    `r_n(φ) = −s0 / (W_nn + μ W_nt·d(φ))`, and the remaining condition is that
//!    `u_t` be opposite to d(φ): `g(φ) = u_t · d⊥(φ) = 0` with `u_t · d ≤ 0`. The
//!    roots of g are bracketed on 64 angles and refined by bisection to machine
//!    precision.
//! 5. A degenerate block (singular W, or no consistent case, e.g. μ so large with a
//!    strongly coupled block that the local problem has no unique solution) falls
//!    back to a projected fixed point `r ← P_K(r − ρ (W r + u0 + Φ(u)))` with De
//!    Saxcé's `Φ(u) = (μ|u_t|, 0, 0)` and ρ = 1/λ_max(W).
//!
//! Blocks are stored as the upper triangle `[W_nn, W_nt1, W_nt2, W_t1t1, W_t1t2, W_t2t2]`.

use crate::norms::project_cone;

/// Relative tolerance used to accept a case.
const ACCEPT: f64 = 1e-12;

/// A symmetric 3 × 3 block, upper triangle `[nn, nt1, nt2, t1t1, t1t2, t2t2]`.
pub type Sym3 = [f64; 6];

/// W v for a symmetric block.
#[inline(always)]
pub fn mul(w: &Sym3, v: [f64; 3]) -> [f64; 3] {
    [
        w[0] * v[0] + w[1] * v[1] + w[2] * v[2],
        w[1] * v[0] + w[3] * v[1] + w[4] * v[2],
        w[2] * v[0] + w[4] * v[1] + w[5] * v[2],
    ]
}

/// A 3 × 3 block as the slip and fallback cases use it: symmetric ([`Sym3`]) or
/// full ([`Full3`], for problems whose diagonal blocks are not symmetric, as some
/// FCLIB files).
pub trait Block3 {
    fn mul(&self, v: [f64; 3]) -> [f64; 3];
    /// The normal row (W_nn, W_nt1, W_nt2).
    fn row0(&self) -> [f64; 3];
    /// |W_nn| + |W_t1t1| + |W_t2t2|, a scale for acceptance tests.
    fn trace_abs(&self) -> f64;
    /// A bound of the largest eigenvalue (Gershgorin).
    fn lmax(&self) -> f64;
}

impl Block3 for Sym3 {
    #[inline(always)]
    fn mul(&self, v: [f64; 3]) -> [f64; 3] {
        mul(self, v)
    }
    #[inline(always)]
    fn row0(&self) -> [f64; 3] {
        [self[0], self[1], self[2]]
    }
    fn trace_abs(&self) -> f64 {
        self[0].abs() + self[3].abs() + self[5].abs()
    }
    fn lmax(&self) -> f64 {
        let w = self;
        (w[0].abs() + w[1].abs() + w[2].abs())
            .max(w[1].abs() + w[3].abs() + w[4].abs())
            .max(w[2].abs() + w[4].abs() + w[5].abs())
    }
}

/// A full 3 × 3 block, row-major.
pub type Full3 = [[f64; 3]; 3];

impl Block3 for Full3 {
    #[inline(always)]
    fn mul(&self, v: [f64; 3]) -> [f64; 3] {
        let m = self;
        [
            m[0][0] * v[0] + m[0][1] * v[1] + m[0][2] * v[2],
            m[1][0] * v[0] + m[1][1] * v[1] + m[1][2] * v[2],
            m[2][0] * v[0] + m[2][1] * v[1] + m[2][2] * v[2],
        ]
    }
    fn row0(&self) -> [f64; 3] {
        self[0]
    }
    fn trace_abs(&self) -> f64 {
        self[0][0].abs() + self[1][1].abs() + self[2][2].abs()
    }
    fn lmax(&self) -> f64 {
        self.iter().map(|r| r.iter().map(|x| x.abs()).sum::<f64>()).fold(0.0, f64::max)
    }
}

/// Solves the one-contact problem for a full, possibly non-symmetric block: the
/// cases of the module docs without the symmetric shortcuts (no contact, stick by
/// the inverse, slip angle, projected fallback).
pub fn solve_full(w: &Full3, u0: [f64; 3], u_target: f64, mu: f64) -> [f64; 3] {
    let s0 = u0[0] - u_target;
    if s0 >= 0.0 {
        return [0.0; 3];
    }
    if mu == 0.0 && w[0][0] > 0.0 {
        // the normal impulse alone, r_t = 0
        return [-s0 / w[0][0], 0.0, 0.0];
    }
    let m = w;
    let c = [
        [
            m[1][1] * m[2][2] - m[1][2] * m[2][1],
            m[0][2] * m[2][1] - m[0][1] * m[2][2],
            m[0][1] * m[1][2] - m[0][2] * m[1][1],
        ],
        [
            m[1][2] * m[2][0] - m[1][0] * m[2][2],
            m[0][0] * m[2][2] - m[0][2] * m[2][0],
            m[0][2] * m[1][0] - m[0][0] * m[1][2],
        ],
        [
            m[1][0] * m[2][1] - m[1][1] * m[2][0],
            m[0][1] * m[2][0] - m[0][0] * m[2][1],
            m[0][0] * m[1][1] - m[0][1] * m[1][0],
        ],
    ];
    let det = m[0][0] * c[0][0] + m[0][1] * c[1][0] + m[0][2] * c[2][0];
    let scale = w.lmax();
    let b = [-s0, -u0[1], -u0[2]];
    let mut guess = (-u0[2]).atan2(-u0[1]);
    if det.abs() > ACCEPT * scale * scale * scale {
        let r = c.mul(b).map(|x| x / det);
        if r[0] >= 0.0 && (r[1] * r[1] + r[2] * r[2]).sqrt() <= mu * r[0] * (1.0 + ACCEPT) {
            return r;
        }
        guess = r[2].atan2(r[1]);
    }
    let u0t = [u0[1], u0[2]];
    if let Some(r) = slide_secant(w, s0, u0t, mu, guess) {
        return r;
    }
    if let Some(r) = slide_general(w, s0, u0t, mu) {
        return r;
    }
    fallback(w, u0, u_target, mu)
}

/// Inverse of a symmetric block, or `None` when it is singular (relative to its
/// largest entry).
pub fn inverse(w: &Sym3) -> Option<Sym3> {
    let [a, b, c, d, e, f] = *w;
    let c00 = d * f - e * e;
    let c01 = c * e - b * f;
    let c02 = b * e - c * d;
    let det = a * c00 + b * c01 + c * c02;
    let scale = w.iter().fold(0.0_f64, |m, x| m.max(x.abs()));
    if !(det > ACCEPT * scale * scale * scale) {
        return None;
    }
    let inv = 1.0 / det;
    Some([
        c00 * inv,
        c01 * inv,
        c02 * inv,
        (a * f - c * c) * inv,
        (b * c - a * e) * inv,
        (a * d - b * b) * inv,
    ])
}

/// What [`solve_pre`] reuses at every sweep for one block.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
#[repr(C)]
pub struct Pre3 {
    /// W⁻¹ (zeros when W is singular).
    pub inv: Sym3,
    /// 1 / W_nn (0 when W_nn ≤ 0).
    pub inv_nn: f64,
    /// 0: general block; 1: normal decoupled (W_nt = 0); 2: decoupled and W_tt
    /// isotropic (W_t1t1 = W_t2t2, W_t1t2 = 0), the sphere case.
    pub kind: u32,
    pub singular: u32,
}

/// Precomputes the block's inverse and its structure.
pub fn precompute(w: &Sym3) -> Pre3 {
    let scale = w.iter().fold(0.0_f64, |m, x| m.max(x.abs()));
    let small = |x: f64| x.abs() <= 1e-14 * scale;
    let decoupled = small(w[1]) && small(w[2]);
    let iso = decoupled && small(w[4]) && (w[3] - w[5]).abs() <= 1e-14 * scale;
    let inv = inverse(w);
    Pre3 {
        inv: inv.unwrap_or([0.0; 6]),
        inv_nn: if w[0] > 0.0 { 1.0 / w[0] } else { 0.0 },
        kind: if iso {
            2
        } else if decoupled {
            1
        } else {
            0
        },
        singular: inv.is_none() as u32,
    }
}

/// Solves the one-contact problem (see the module docs).
pub fn solve(w: &Sym3, u0: [f64; 3], u_target: f64, mu: f64) -> [f64; 3] {
    solve_pre(w, &precompute(w), u0, u_target, mu)
}

/// [`solve`] with the block's precomputed data.
#[inline]
pub fn solve_pre(w: &Sym3, pre: &Pre3, u0: [f64; 3], u_target: f64, mu: f64) -> [f64; 3] {
    solve_pre_warm(w, pre, u0, u_target, mu, [0.0; 3])
}

/// [`solve_pre`] with the contact's previous impulse `prev`: a sliding solution of a
/// coupled block is searched first from `prev`'s slip direction (in NLGS the
/// iterates change little from sweep to sweep, so the secant steps start next to
/// the root). The result is the same solution up to round-off.
///
/// Its closed forms (no contact, a sphere's isotropic block) always inlined: called,
/// it returns its 24 bytes through memory, and the sweep's reading them back failed
/// store forwarding in some builds (+9 %, PERFORMANCE.md); the rest is called.
#[inline(always)]
pub fn solve_pre_warm(w: &Sym3, pre: &Pre3, u0: [f64; 3], u_target: f64, mu: f64, prev: [f64; 3]) -> [f64; 3] {
    let s0 = u0[0] - u_target;
    // 1. no contact
    if s0 >= 0.0 {
        return [0.0; 3];
    }
    // the sphere case, frictionless or isotropic: closed form
    if pre.kind == 2 && pre.inv_nn > 0.0 {
        let rn = -s0 * pre.inv_nn;
        if mu == 0.0 {
            return [rn, 0.0, 0.0];
        }
        let wtt = w[3];
        let ut = (u0[1] * u0[1] + u0[2] * u0[2]).sqrt();
        if wtt > 0.0 && ut <= mu * rn * wtt {
            return [rn, -u0[1] / wtt, -u0[2] / wtt];
        }
        // slide: r_t = −μ r_n u0_t/|u0_t| (here |u0_t| > 0)
        let k = mu * rn / ut;
        return [rn, -k * u0[1], -k * u0[2]];
    }
    solve_general(w, pre, u0, (s0, u_target), mu, prev)
}

/// [`solve_pre_warm`] past its closed forms (called: the sweep's hot path stays small).
#[inline(never)]
fn solve_general(w: &Sym3, pre: &Pre3, u0: [f64; 3], (s0, u_target): (f64, f64), mu: f64, prev: [f64; 3]) -> [f64; 3] {
    if mu == 0.0 && pre.inv_nn > 0.0 {
        return [-s0 * pre.inv_nn, 0.0, 0.0];
    }
    // 2. stick
    if pre.singular == 0 {
        let r = mul(&pre.inv, [-s0, -u0[1], -u0[2]]);
        if r[0] >= 0.0 && (r[1] * r[1] + r[2] * r[2]).sqrt() <= mu * r[0] * (1.0 + ACCEPT) {
            return r;
        }
    }
    // 3. slide, decoupled normal
    if pre.kind >= 1 && pre.inv_nn > 0.0 {
        let rn = -s0 * pre.inv_nn;
        if let Some(rt) = disk_min(w[3], w[4], w[5], [u0[1], u0[2]], mu * rn) {
            return [rn, rt[0], rt[1]];
        }
    }
    // 4. slide, general block: a few secant steps on the slip angle from the
    // direction of the sticking impulse, then the bracketing scan
    let guess = if prev[1] != 0.0 || prev[2] != 0.0 {
        prev[2].atan2(prev[1])
    } else if pre.singular == 0 {
        let r = mul(&pre.inv, [-s0, -u0[1], -u0[2]]);
        r[2].atan2(r[1])
    } else {
        (-u0[2]).atan2(-u0[1])
    };
    if let Some(r) = slide_secant(w, s0, [u0[1], u0[2]], mu, guess) {
        return r;
    }
    if let Some(r) = slide_general(w, s0, [u0[1], u0[2]], mu) {
        return r;
    }
    fallback(w, u0, u_target, mu)
}

/// Minimiser of `½ xᵀ A x + b·x` on the disk `|x| ≤ rad`, A = [[a, c], [c, d]] SPD,
/// when the unconstrained minimiser lies outside the disk: `x = −(A + λI)⁻¹ b` with
/// `|x(λ)| = rad`. `None` if A is not positive definite.
pub(crate) fn disk_min(a: f64, c: f64, d: f64, b: [f64; 2], rad: f64) -> Option<[f64; 2]> {
    let bn = (b[0] * b[0] + b[1] * b[1]).sqrt();
    if rad <= 0.0 || bn == 0.0 {
        return Some([0.0, 0.0]);
    }
    let x_of = |l: f64| {
        let (p, q, s) = (a + l, c, d + l);
        let det = p * s - q * q;
        [-(s * b[0] - q * b[1]) / det, -(-q * b[0] + p * b[1]) / det]
    };
    let lmin = 0.5 * (a + d) - (0.25 * (a - d) * (a - d) + c * c).sqrt();
    if !(lmin > 0.0) {
        return None;
    }
    let x0 = x_of(0.0);
    if x0[0] * x0[0] + x0[1] * x0[1] <= rad * rad {
        return Some(x0);
    }
    // φ(λ) = 1/|x(λ)| − 1/rad is increasing and concave: Newton from below converges
    // monotonically; start at λ = max(0, |b|/rad − λ_max) where |x| ≥ rad.
    let lmax = 0.5 * (a + d) + (0.25 * (a - d) * (a - d) + c * c).sqrt();
    let mut l = (bn / rad - lmax).max(0.0);
    for _ in 0..60 {
        let x = x_of(l);
        let n = (x[0] * x[0] + x[1] * x[1]).sqrt();
        let phi = 1.0 / n - 1.0 / rad;
        if phi.abs() <= 1e-15 / rad {
            break;
        }
        // d|x|/dλ = −xᵀ (A + λI)⁻¹ x / |x|
        let (p, q, s) = (a + l, c, d + l);
        let det = p * s - q * q;
        let y = [(s * x[0] - q * x[1]) / det, (-q * x[0] + p * x[1]) / det];
        let dn = -(x[0] * y[0] + x[1] * y[1]) / n;
        let dphi = -dn / (n * n);
        let step = phi / dphi;
        l = (l - step).max(0.0);
        if step.abs() <= 1e-16 * l.max(lmin) {
            break;
        }
    }
    let x = x_of(l);
    let n = (x[0] * x[0] + x[1] * x[1]).sqrt();
    // put it exactly on the circle
    Some([x[0] * rad / n, x[1] * rad / n])
}

/// r(φ), g(φ) = u_t · d⊥ and h(φ) = u_t · d of case 4 (`None` where the pivot
/// W_nn + μ W_nt·d(φ) is not positive).
#[inline(always)]
fn slip_eval<B: Block3>(w: &B, s0: f64, u0t: [f64; 2], mu: f64, phi: f64) -> Option<([f64; 3], f64, f64)> {
    let (s, c) = phi.sin_cos();
    let w0 = w.row0();
    let d = w0[0] + mu * (w0[1] * c + w0[2] * s);
    if !(d > 0.0) {
        return None;
    }
    let rn = -s0 / d;
    let r = [rn, mu * rn * c, mu * rn * s];
    let u = w.mul(r);
    let (ut1, ut2) = (u[1] + u0t[0], u[2] + u0t[1]);
    Some((r, -ut1 * s + ut2 * c, ut1 * c + ut2 * s))
}

/// Case 4 by secant steps on g(φ) from `phi0`; `None` unless it lands on a valid
/// root (g = 0 to round-off, h ≤ 0).
fn slide_secant<B: Block3>(w: &B, s0: f64, u0t: [f64; 2], mu: f64, phi0: f64) -> Option<[f64; 3]> {
    let (mut a, mut b) = (phi0, phi0 + 1e-3);
    let mut ga = slip_eval(w, s0, u0t, mu, a)?.1;
    for _ in 0..30 {
        let (r, gb, h) = slip_eval(w, s0, u0t, mu, b)?;
        let scale = w.trace_abs() * r[0] + u0t[0].abs() + u0t[1].abs();
        if gb.abs() <= 1e-14 * scale || (b - a).abs() <= 1e-15 {
            return if h <= ACCEPT * scale && gb.abs() <= 1e-10 * scale {
                Some(r)
            } else {
                None
            };
        }
        if gb == ga {
            return None;
        }
        let next = b - gb * (b - a) / (gb - ga);
        if !next.is_finite() || (next - b).abs() > 1.0 {
            return None;
        }
        (a, ga, b) = (b, gb, next);
    }
    None
}

/// Case 4 of the module docs: a sliding solution of a coupled block.
fn slide_general<B: Block3>(w: &B, s0: f64, u0t: [f64; 2], mu: f64) -> Option<[f64; 3]> {
    let w0 = w.row0();
    let den = |phi: f64| {
        let (s, c) = phi.sin_cos();
        w0[0] + mu * (w0[1] * c + w0[2] * s)
    };
    let eval = |phi: f64| slip_eval(w, s0, u0t, mu, phi);
    // sample angles; where the pivot W_nn + μ W_nt·d changes sign, add the point just
    // inside the admissible arc (r_n grows without bound there, and g may change sign
    // between that point and the first sample)
    const N: usize = 64;
    let step = std::f64::consts::TAU / N as f64;
    let mut pts: Vec<(f64, Option<f64>)> = Vec::with_capacity(N + 8);
    let mut prev_ok = den(0.0) > 0.0;
    for k in 0..=N {
        let b = k as f64 * step;
        let ok = den(b) > 0.0;
        if k > 0 && ok != prev_ok {
            // boundary by bisection, then the admissible side
            let (mut lo, mut hi) = (b - step, b);
            for _ in 0..80 {
                let mid = 0.5 * (lo + hi);
                if mid <= lo || mid >= hi {
                    break;
                }
                if (den(mid) > 0.0) == prev_ok {
                    lo = mid;
                } else {
                    hi = mid;
                }
            }
            let inside = if prev_ok { lo } else { hi };
            pts.push((inside, eval(inside).map(|e| e.1)));
        }
        pts.push((b, eval(b).map(|e| e.1)));
        prev_ok = ok;
    }
    let mut best: Option<([f64; 3], f64)> = None;
    for p in pts.windows(2) {
        let ((a, ga), (b, gb)) = (p[0], p[1]);
        let (Some(ga), Some(gb)) = (ga, gb) else { continue };
        if !(ga == 0.0 || ga * gb < 0.0) {
            continue;
        }
        // bisection to machine precision in φ
        let (mut lo, mut hi, mut glo) = (a, b, ga);
        if ga != 0.0 {
            for _ in 0..80 {
                let mid = 0.5 * (lo + hi);
                if mid <= lo || mid >= hi {
                    break;
                }
                match eval(mid) {
                    Some((_, gm, _)) if gm * glo > 0.0 => {
                        lo = mid;
                        glo = gm;
                    }
                    Some(_) => hi = mid,
                    None => break,
                }
            }
        }
        if let Some((r, _, h)) = eval(lo) {
            // u_t opposite to the slip direction of r_t
            let scale = w.trace_abs() * r[0] + u0t[0].abs() + u0t[1].abs();
            if h <= ACCEPT * scale && best.is_none_or(|(_, hb)| h < hb) {
                best = Some((r, h));
            }
        }
    }
    best.map(|(r, _)| r)
}

/// Projected fixed point on the local problem, for degenerate blocks.
fn fallback<B: Block3>(w: &B, u0: [f64; 3], u_target: f64, mu: f64) -> [f64; 3] {
    projected_fixed_point(w, u0, u_target, mu, 2000, 0.0, |z| project_cone(&z, mu))
}

/// `r ← project(r − ρ (W r + u0 − ū e_n + μ|u_t| e_n))` from r = 0 with
/// ρ = 1 / (Gershgorin bound of λ_max), at most `iters` times, until the change is
/// below 1e-15 (|r|₁ + `floor`). `project` is the projection on the admissible
/// set (the Coulomb cone, or a joint's cut cone in [`super::joint`]).
pub(crate) fn projected_fixed_point<B: Block3>(
    w: &B,
    u0: [f64; 3],
    u_target: f64,
    mu: f64,
    iters: usize,
    floor: f64,
    project: impl Fn([f64; 3]) -> [f64; 3],
) -> [f64; 3] {
    let lmax = w.lmax();
    if !(lmax > 0.0) {
        return [0.0; 3];
    }
    let rho = 1.0 / lmax;
    let mut r = [0.0; 3];
    for _ in 0..iters {
        let wr = w.mul(r);
        let u = [wr[0] + u0[0] - u_target, wr[1] + u0[1], wr[2] + u0[2]];
        let ut = (u[1] * u[1] + u[2] * u[2]).sqrt();
        let p = project([r[0] - rho * (u[0] + mu * ut), r[1] - rho * u[1], r[2] - rho * u[2]]);
        let d = (p[0] - r[0]).abs() + (p[1] - r[1]).abs() + (p[2] - r[2]).abs();
        r = p;
        if d <= 1e-15 * (r[0].abs() + r[1].abs() + r[2].abs() + floor) {
            break;
        }
    }
    r
}
