//! A pressure-dependent elastoplastic continuum: Drucker–Prager matched to
//! Mohr–Coulomb in plane strain (docs/CONTINUUM.md), per cell of linear
//! elements (constant strain), integrated implicitly.
//!
//! With p = tr σ / 3 (tension positive) and J₂ = ½ s:s (s the deviator):
//!
//! ```text
//! f(σ) = √J₂ + η p − ξ c ≤ 0,      g(σ) = √J₂ + η̄ p (flow potential)
//! η = 3 tan φ / √(9 + 12 tan² φ),  ξ = 3 / √(9 + 12 tan² φ),  η̄: the same with ψ
//! ```
//!
//! φ the friction angle, ψ the dilatancy angle (ψ = φ: associative), c the
//! cohesion. At the end of each step the trial stress σ_tr = D(ε(u⁺) − ε_p) is
//! projected by the backward-Euler return mapping (closed form on the cone,
//! Δγ = f(σ_tr)/(G + K η η̄); to the apex p = ξc/η where the cone's return would
//! cross it), and ε_p = ε − D⁻¹σ. The momentum balance uses the elastic stiffness
//! (M̂ is factored once) and the plastic strains of the step's start: the internal
//! force is K u − f_p, f_p = Σ_e α_e A_e Bᵀ D ε_p (α_e the cell's band weight).

use crate::mesh::{gradients, signed_measure, Mesh};

/// Drucker–Prager parameters and the per-cell state (module docs).
#[derive(Clone, Debug)]
pub struct Plastic {
    pub eta: f64,
    pub eta_bar: f64,
    pub xi: f64,
    pub cohesion: f64,
    lam: f64,
    mu: f64,
    /// Per cell: shape-function gradients (D + 1 rows), α_e A_e, plastic strain and
    /// stress (3 × 3 tensors, tension positive).
    grad: Vec<[[f64; 3]; 4]>,
    weight: Vec<f64>,
    pub eps_p: Vec<[[f64; 3]; 3]>,
    pub sigma: Vec<[[f64; 3]; 3]>,
    /// Cells that yielded in the last update.
    pub yielding: usize,
    /// Friction hardening (None: perfectly plastic), and each cell's accumulated
    /// plastic shear strain κ = Σ Δγ.
    pub hardening: Option<Hardening>,
    pub kappa: Vec<f64>,
}

/// Friction hardening: the mobilized friction angle grows with the accumulated
/// plastic shear strain κ from φ0 to φ,
/// sin φ_m(κ) = sin φ0 + (sin φ − sin φ0) κ / (κ + κ_h).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hardening {
    pub sin0: f64,
    pub sin_peak: f64,
    pub kappa_h: f64,
}

impl Hardening {
    /// Why a scene's `initial_friction` and `hardening_strain` cannot make a
    /// hardening of `friction`; None: they can (both given, 0 ≤ φ0 ≤ φ, κ_h > 0), or
    /// neither is given.
    pub fn check(friction: f64, initial: Option<f64>, kappa_h: Option<f64>) -> Option<String> {
        let show = |x: Option<f64>| x.map_or("missing".to_string(), |v| v.to_string());
        match (initial, kappa_h) {
            (None, None) => None,
            (Some(f0), Some(k)) if (0.0..=friction).contains(&f0) && k > 0.0 && k.is_finite() => None,
            (f0, k) => Some(format!(
                "hardening takes both initial_friction in [0, friction] (degrees) and hardening_strain > 0, got {} and {}",
                show(f0),
                show(k)
            )),
        }
    }
    /// (η, ξ) at κ.
    fn cone(&self, kappa: f64) -> (f64, f64) {
        let s = self.sin0 + (self.sin_peak - self.sin0) * kappa / (kappa + self.kappa_h);
        dp_of_sin(s.clamp(0.0, 1.0 - 1e-12))
    }
}

/// η or ξ of Drucker–Prager's plane-strain match of Mohr–Coulomb for angle `deg`.
fn dp(deg: f64) -> (f64, f64) {
    let t = deg.to_radians().tan();
    let den = (9.0 + 12.0 * t * t).sqrt();
    (3.0 * t / den, 3.0 / den)
}

/// [`dp`] from s = sin φ, without trigonometry (the return at every yielding cell
/// and step calls it): with tan² φ = s²/(1 − s²), η = 3s/√(9 + 3s²) and
/// ξ = 3√(1 − s²)/√(9 + 3s²).
fn dp_of_sin(s: f64) -> (f64, f64) {
    let den = (9.0 + 3.0 * s * s).sqrt();
    (3.0 * s / den, 3.0 * (1.0 - s * s).sqrt() / den)
}

impl Plastic {
    /// Angles φ, ψ in degrees, cohesion c (Pa), elastic E, ν; `alpha`: each cell's
    /// band weight.
    pub fn new(mesh: &Mesh, friction: f64, dilatancy: f64, cohesion: f64, young: f64, poisson: f64, alpha: &[f64]) -> Plastic {
        let (eta, xi) = dp(friction);
        let (eta_bar, _) = dp(dilatancy);
        let mu = young / (2.0 * (1.0 + poisson));
        let lam = young * poisson / ((1.0 + poisson) * (1.0 - 2.0 * poisson));
        let d = mesh.dim;
        let mut grad = Vec::with_capacity(mesh.n_cells());
        let mut weight = Vec::with_capacity(mesh.n_cells());
        for e in 0..mesh.n_cells() {
            let c = mesh.cell(e);
            let g = gradients(d, &mesh.x0, c);
            let mut gg = [[0.0; 3]; 4];
            gg[..=d].copy_from_slice(&g);
            grad.push(gg);
            weight.push(alpha[e] * signed_measure(d, &mesh.x0, c).abs());
        }
        let n = mesh.n_cells();
        Plastic {
            eta,
            eta_bar,
            xi,
            cohesion,
            lam,
            mu,
            grad,
            weight,
            eps_p: vec![[[0.0; 3]; 3]; n],
            sigma: vec![[[0.0; 3]; 3]; n],
            yielding: 0,
            hardening: None,
            kappa: vec![0.0; n],
        }
    }

    /// The same material hardening from φ0 (degrees) to its friction angle with
    /// the plastic shear strain κ_h ([`Hardening`]).
    pub fn with_hardening(mut self, friction: f64, initial: f64, kappa_h: f64) -> Plastic {
        let sin = |deg: f64| deg.to_radians().sin();
        self.hardening = Some(Hardening {
            sin0: sin(initial),
            sin_peak: sin(friction),
            kappa_h,
        });
        self
    }

    /// An initial stress σ0, one a cell: the eigenstrain ε_p = −D⁻¹σ0, so that
    /// σ = σ0 + D(ε − ε_p⁺) with ε_p⁺ the strains that yielding adds, and
    /// f_p = −Σ_e α_e A_e Bᵀ σ0 balances the tractions σ0 n on the sides (a uniform
    /// σ0) or the region's weight (a geostatic one) at u = 0.
    pub fn prestress(&mut self, sigma0: &[[[f64; 3]; 3]]) {
        debug_assert_eq!(sigma0.len(), self.sigma.len(), "one σ0 a cell");
        for (e, s0) in sigma0.iter().enumerate().take(self.sigma.len()) {
            let e0 = self.compliance(s0);
            self.eps_p[e] = std::array::from_fn(|a| std::array::from_fn(|b| -e0[a][b]));
            self.sigma[e] = *s0;
        }
    }

    /// The strain of cell e (3 × 3, the plane's zz = 0 in 2D).
    fn strain(&self, mesh: &Mesh, e: usize, u: &[f64]) -> [[f64; 3]; 3] {
        let d = mesh.dim;
        let mut du = [[0.0; 3]; 3];
        for (i, &k) in mesh.cell(e).iter().enumerate() {
            for a in 0..d {
                for b in 0..d {
                    du[a][b] += u[d * k as usize + a] * self.grad[e][i][b];
                }
            }
        }
        std::array::from_fn(|a| std::array::from_fn(|b| 0.5 * (du[a][b] + du[b][a])))
    }

    fn stress_of(&self, eps_e: &[[f64; 3]; 3]) -> [[f64; 3]; 3] {
        let tr = eps_e[0][0] + eps_e[1][1] + eps_e[2][2];
        std::array::from_fn(|a| std::array::from_fn(|b| 2.0 * self.mu * eps_e[a][b] + if a == b { self.lam * tr } else { 0.0 }))
    }

    /// f_p = Σ_e α_e A_e Bᵀ D ε_p (node-major, the mesh's dofs): the force that the
    /// plastic strains take off the elastic K u.
    pub fn plastic_force(&self, mesh: &Mesh, out: &mut Vec<f64>) {
        let d = mesh.dim;
        out.clear();
        out.resize(d * mesh.n_nodes(), 0.0);
        for e in 0..mesh.n_cells() {
            let s = self.stress_of(&self.eps_p[e]);
            for (i, &k) in mesh.cell(e).iter().enumerate() {
                for a in 0..d {
                    let f: f64 = (0..d).map(|b| s[a][b] * self.grad[e][i][b]).sum();
                    out[d * k as usize + a] += self.weight[e] * f;
                }
            }
        }
    }

    /// The return mapping of every cell at displacement u (module docs).
    pub fn update(&mut self, mesh: &Mesh, u: &[f64]) {
        self.yielding = 0;
        for e in 0..mesh.n_cells() {
            let eps = self.strain(mesh, e, u);
            let ee: [[f64; 3]; 3] = std::array::from_fn(|a| std::array::from_fn(|b| eps[a][b] - self.eps_p[e][a][b]));
            let trial = self.stress_of(&ee);
            let (sigma, yielded) = match self.hardening {
                None => self.project(&trial),
                Some(h) => {
                    let (sigma, yielded, dgamma) = self.project_hardening(&trial, &h, self.kappa[e]);
                    self.kappa[e] += dgamma;
                    (sigma, yielded)
                }
            };
            if yielded {
                self.yielding += 1;
                // ε_p = ε − D⁻¹ σ
                let ee_new = self.compliance(&sigma);
                self.eps_p[e] = std::array::from_fn(|a| std::array::from_fn(|b| eps[a][b] - ee_new[a][b]));
            }
            self.sigma[e] = sigma;
        }
    }

    /// D⁻¹ σ.
    fn compliance(&self, s: &[[f64; 3]; 3]) -> [[f64; 3]; 3] {
        let k = self.lam + 2.0 * self.mu / 3.0;
        let p = (s[0][0] + s[1][1] + s[2][2]) / 3.0;
        std::array::from_fn(|a| {
            std::array::from_fn(|b| {
                let dev = s[a][b] - if a == b { p } else { 0.0 };
                dev / (2.0 * self.mu) + if a == b { p / (3.0 * k) } else { 0.0 }
            })
        })
    }

    /// The closest-point return of a trial stress; whether it yielded.
    pub fn project(&self, tr: &[[f64; 3]; 3]) -> ([[f64; 3]; 3], bool) {
        let (p, s, q) = invariants(tr);
        let f = q + self.eta * p - self.xi * self.cohesion;
        if f <= 0.0 {
            return (*tr, false);
        }
        let (g, k) = (self.mu, self.lam + 2.0 * self.mu / 3.0);
        let dgamma = f / (g + k * self.eta * self.eta_bar);
        let out = if q - g * dgamma >= 0.0 {
            let scale = if q > 0.0 { 1.0 - g * dgamma / q } else { 0.0 };
            let pn = p - k * self.eta_bar * dgamma;
            stress(scale, &s, pn)
        } else {
            // the apex: p = ξ c / η (no shear left)
            let pa = if self.eta > 0.0 { self.xi * self.cohesion / self.eta } else { p };
            isotropic(pa)
        };
        (out, true)
    }

    /// The return of a trial stress on the cone of κ_n + Δγ (the implicit hardening:
    /// r(Δγ) = √J₂_tr − GΔγ + η(κ)(p_tr − Kη̄Δγ) − ξ(κ)c = 0, solved in its bracket
    /// [0, √J₂_tr/G] by [`illinois`]; past the bracket's end, the apex);
    /// (σ, yielded, Δγ).
    pub fn project_hardening(&self, tr: &[[f64; 3]; 3], h: &Hardening, kappa: f64) -> ([[f64; 3]; 3], bool, f64) {
        let (p, s, q) = invariants(tr);
        let (g, k) = (self.mu, self.lam + 2.0 * self.mu / 3.0);
        let r = |dg: f64| {
            let (eta, xi) = h.cone(kappa + dg);
            (q - g * dg) + eta * (p - k * self.eta_bar * dg) - xi * self.cohesion
        };
        if r(0.0) <= 0.0 {
            return (*tr, false, 0.0);
        }
        let hi = q / g;
        if r(hi) > 0.0 {
            let (eta, xi) = h.cone(kappa + hi);
            let pa = if eta > 0.0 { xi * self.cohesion / eta } else { p };
            return (isotropic(pa), true, hi);
        }
        let dg = illinois(r, hi, 1e-14 * (q + p.abs() + self.cohesion));
        let scale = if q > 0.0 { (1.0 - g * dg / q).max(0.0) } else { 0.0 };
        let pn = p - k * self.eta_bar * dg;
        (stress(scale, &s, pn), true, dg)
    }

    /// Σ_e ½ α_e A_e σ:(ε − ε_p), the elastic energy stored.
    pub fn elastic_energy(&self, mesh: &Mesh, u: &[f64]) -> f64 {
        (0..mesh.n_cells())
            .map(|e| {
                let eps = self.strain(mesh, e, u);
                let s = self.stress_of(&std::array::from_fn(|a| std::array::from_fn(|b| eps[a][b] - self.eps_p[e][a][b])));
                let mut w = 0.0;
                for a in 0..3 {
                    for b in 0..3 {
                        w += s[a][b] * (eps[a][b] - self.eps_p[e][a][b]);
                    }
                }
                0.5 * self.weight[e] * w
            })
            .sum()
    }
}

/// p = tr σ / 3, the deviator s and √J₂ of a stress.
fn invariants(t: &[[f64; 3]; 3]) -> (f64, [[f64; 3]; 3], f64) {
    let p = (t[0][0] + t[1][1] + t[2][2]) / 3.0;
    let s: [[f64; 3]; 3] = std::array::from_fn(|a| std::array::from_fn(|b| t[a][b] - if a == b { p } else { 0.0 }));
    let j2 = 0.5 * s.iter().flatten().map(|x| x * x).sum::<f64>();
    (p, s, j2.sqrt())
}

/// The stress `scale` s + p I (a return: the deviator scaled, the pressure moved).
fn stress(scale: f64, s: &[[f64; 3]; 3], p: f64) -> [[f64; 3]; 3] {
    std::array::from_fn(|a| std::array::from_fn(|b| scale * s[a][b] + if a == b { p } else { 0.0 }))
}

/// The isotropic stress p I (the cone's apex).
fn isotropic(p: f64) -> [[f64; 3]; 3] {
    std::array::from_fn(|a| std::array::from_fn(|b| if a == b { p } else { 0.0 }))
}

/// The root of r in [0, hi] where r(0) > 0 ≥ r(hi): regula falsi with the
/// Illinois modification (superlinear, the bracket kept), until |r| ≤ `tol` or the
/// bracket is 1e-15 of hi (at most 200 steps).
fn illinois(r: impl Fn(f64) -> f64, hi: f64, tol: f64) -> f64 {
    let (mut a, mut fa, mut b, mut fb) = (0.0, r(0.0), hi, r(hi));
    let mut side = 0;
    let mut c = b;
    for _ in 0..200 {
        c = (a * fb - b * fa) / (fb - fa);
        let fc = r(c);
        if fc.abs() <= tol || b - a <= 1e-15 * hi {
            break;
        }
        if fc > 0.0 {
            (a, fa) = (c, fc);
            if side == 1 {
                fb *= 0.5;
            }
            side = 1;
        } else {
            (b, fb) = (c, fc);
            if side == -1 {
                fa *= 0.5;
            }
            side = -1;
        }
    }
    c
}

#[cfg(test)]
mod tests {
    use super::*;

    fn material(phi: f64, psi: f64, c: f64) -> Plastic {
        let (eta, xi) = dp(phi);
        let (eta_bar, _) = dp(psi);
        Plastic {
            eta,
            eta_bar,
            xi,
            cohesion: c,
            lam: 1e6,
            mu: 1e6,
            grad: vec![],
            weight: vec![],
            eps_p: vec![],
            sigma: vec![],
            yielding: 0,
            hardening: None,
            kappa: vec![],
        }
    }

    #[test]
    fn the_cone_from_sin_phi_is_the_cone_from_phi() {
        for k in 0..=90 {
            let deg = k as f64 * 0.99;
            let (a, b) = (dp(deg), dp_of_sin(deg.to_radians().sin()));
            assert!((a.0 - b.0).abs() < 1e-14 && (a.1 - b.1).abs() < 1e-14, "{deg}°: {a:?} {b:?}");
        }
    }

    fn f(m: &Plastic, s: &[[f64; 3]; 3]) -> f64 {
        let p = (s[0][0] + s[1][1] + s[2][2]) / 3.0;
        let j2 = 0.5
            * (0..3)
                .flat_map(|a| (0..3).map(move |b| (a, b)))
                .map(|(a, b)| (s[a][b] - if a == b { p } else { 0.0 }).powi(2))
                .sum::<f64>();
        j2.sqrt() + m.eta * p - m.xi * m.cohesion
    }

    #[test]
    fn the_return_lands_on_the_cone() {
        let m = material(30.0, 30.0, 1e3);
        // compression with shear: yields onto the cone
        let tr = [[-1e5, 8e4, 0.0], [8e4, -2e5, 0.0], [0.0, 0.0, -1.5e5]];
        let (s, y) = m.project(&tr);
        assert!(y && f(&m, &tr) > 0.0);
        assert!(f(&m, &s).abs() < 1e-9 * 1e5, "f = {}", f(&m, &s));
        // associative: the return is along D ∂f, the pressure drops by K η Δγ
        // elastic states are left alone
        let el = [[-1e5, 1e3, 0.0], [1e3, -1e5, 0.0], [0.0, 0.0, -1e5]];
        assert_eq!(m.project(&el), (el, false));
        // tension beyond the apex goes to it: p = ξ c / η, no shear
        let ten = [[1e6, 1e3, 0.0], [1e3, 1e6, 0.0], [0.0, 0.0, 1e6]];
        let (s, y) = m.project(&ten);
        let pa = m.xi * m.cohesion / m.eta;
        assert!(y && (s[0][0] - pa).abs() < 1e-9 && s[0][1] == 0.0);
    }

    #[test]
    fn the_hardening_return_lands_on_the_cone_of_its_strain() {
        let m = material(30.0, 10.0, 0.0);
        let h = Hardening {
            sin0: 0.2,
            sin_peak: 0.5,
            kappa_h: 1e-2,
        };
        let tr = [[-1e5, 8e4, 0.0], [8e4, -2e5, 0.0], [0.0, 0.0, -1.5e5]];
        for kappa in [0.0, 1e-3, 1e-1, 1e3] {
            let (s, y, dg) = m.project_hardening(&tr, &h, kappa);
            assert!(y && dg > 0.0);
            // on the cone of κ + Δγ
            let (eta, xi) = h.cone(kappa + dg);
            let at = Plastic { eta, xi, ..m.clone() };
            assert!(f(&at, &s).abs() < 1e-8 * 1e5, "κ {kappa}: f = {}", f(&at, &s));
        }
        // hardened to its peak, the return is the perfectly plastic one of φ = 30°
        let (s, _, _) = m.project_hardening(
            &tr,
            &Hardening {
                sin0: 0.5,
                sin_peak: 0.5,
                kappa_h: 1e-2,
            },
            0.0,
        );
        let (sp, _) = m.project(&tr);
        for a in 0..3 {
            for b in 0..3 {
                assert!((s[a][b] - sp[a][b]).abs() < 1e-6, "{:?} against {:?}", s, sp);
            }
        }
        // the mobilized angle grows with κ: more hardening, less plastic strain
        let (_, _, dg0) = m.project_hardening(&tr, &h, 0.0);
        let (_, _, dg1) = m.project_hardening(&tr, &h, 1.0);
        assert!(dg1 < dg0);
        // elastic states are left alone
        let el = [[-1e5, 1e3, 0.0], [1e3, -1e5, 0.0], [0.0, 0.0, -1e5]];
        assert_eq!(m.project_hardening(&el, &h, 0.0), (el, false, 0.0));
    }
}
