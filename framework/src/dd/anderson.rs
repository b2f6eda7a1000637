//! Anderson acceleration of the NSCDD iteration (`[solver] method = "anderson"` with
//! a decomposition).
//!
//! One NSCDD stage (the subdomains' sweeps, then the gluing) is a fixed-point map
//! x ↦ G(x) of the iterate x = (r, F_Γ): every subdomain's contact impulses and its
//! interface copies' net gluing impulses, subdomain after subdomain (the copies'
//! velocities follow from them: V_E = V_free + M̂_E⁻¹ (H r + F_Γ)). The mixing of
//! the one-domain method ([`crate::solver::anderson::Mixer`]: type II, memory 5, a
//! plain stage and a restarted history when ‖G(x) − x‖ grows) takes the next iterate
//!
//! ```text
//! x_{k+1} = P(G(x_k) − ΔG γ),   γ = argmin ‖f_k − ΔF γ‖
//! ```
//!
//! P projecting each contact's impulse on its Coulomb cone (F_Γ is free); the
//! subdomains' velocities are moved with it (V += M̂_E⁻¹ (H Δr + ΔF_Γ)). A stage
//! whose check converges is not mixed (the state the check judged is kept); a
//! step that runs out of stages ends on the stage output with the least ‖f‖.
//!
//! The mixing runs on the coordinator (of each rank) over its subdomains; every
//! dot product is the sum, in subdomain order, of each subdomain's own
//! ([`crate::solver::anderson::Reduce`]: over the ranks an all-gather of the
//! subdomains' values), so the result is bitwise the same for any number of
//! threads and ranks. Body families attached to the subdomains (deformable bodies)
//! are refused by the run (`solver.method`): their state is not in x.

use super::family::Family;
use super::subdomain::Subdomain;
use crate::norms::project_cone;
use crate::solver::anderson::{Mixer, Reduce};

/// The mixing state of one step's stages (buffers kept across steps).
pub struct StageMixer {
    mixer: Mixer,
    x: Vec<f64>,
    g: Vec<f64>,
    best: Vec<f64>,
    best_f: f64,
    offsets: Vec<usize>,
}

impl Default for StageMixer {
    fn default() -> Self {
        StageMixer {
            mixer: Mixer::new(0),
            x: Vec::new(),
            g: Vec::new(),
            best: Vec::new(),
            best_f: f64::INFINITY,
            offsets: Vec::new(),
        }
    }
}

/// Which subdomains this process mixes (its own; the others' state arrives with
/// the step's results).
pub type Own<'a> = &'a dyn Fn(u32) -> bool;

/// The iterate x of the own subdomains into `out`, one segment a subdomain (see the
/// module docs); with `offsets`, the segments' starts and the end.
fn gather<D: Family>(subs: &[&mut Subdomain<D>], own: Own, out: &mut Vec<f64>, mut offsets: Option<&mut Vec<usize>>) {
    out.clear();
    if let Some(o) = offsets.as_deref_mut() {
        o.clear();
    }
    for s in subs.iter().filter(|s| own(s.id)) {
        if let Some(o) = offsets.as_deref_mut() {
            o.push(out.len());
        }
        for a in 0..D::len(&s.contacts) {
            out.extend_from_slice(D::r(&s.contacts, a));
        }
        for f in &s.f_gamma {
            out.extend_from_slice(f.as_ref());
        }
    }
    if let Some(o) = offsets {
        o.push(out.len());
    }
}

/// Sets the own subdomains' state to the iterate `x` (impulses projected on their
/// cones; `x` then holds the state as set), the velocities following.
fn scatter<D: Family>(subs: &mut [&mut Subdomain<D>], own: Own, x: &mut [f64]) {
    let mut k = 0;
    for s in subs.iter_mut().filter(|s| own(s.id)) {
        let s = &mut **s;
        for a in 0..D::len(&s.contacts) {
            let d = D::r(&s.contacts, a).len();
            let p = project_cone(&x[k..k + d], D::mu(&s.contacts, a));
            x[k..k + d].copy_from_slice(&p[..d]);
            D::set_r(&mut s.contacts, a, &p[..d], &mut s.vel, &s.inv_mass);
            k += d;
        }
        for q in 0..s.f_gamma.len() {
            let l = s.iface[q] as usize;
            let mut df = D::V::default();
            for (j, v) in df.as_mut().iter_mut().enumerate() {
                *v = x[k + j] - s.f_gamma[q].as_ref()[j];
            }
            D::apply_impulse(&mut s.vel[l], &s.inv_mass[l], &df);
            for (j, v) in s.f_gamma[q].as_mut().iter_mut().enumerate() {
                *v += df.as_ref()[j];
                x[k + j] = *v;
            }
            k += df.as_ref().len();
        }
    }
}

impl StageMixer {
    /// Before the first stage of a step: forgets the last step's history.
    pub fn start<D: Family>(&mut self, subs: &[&mut Subdomain<D>], own: Own) {
        gather(subs, own, &mut self.x, Some(&mut self.offsets));
        self.mixer.reset(&self.offsets);
        self.best_f = f64::INFINITY;
    }

    /// After a stage that did not converge: records G(x) and sets the own
    /// subdomains to the mixed iterate, the next x (dot products over every
    /// process's subdomains through `red`, in subdomain order).
    pub fn after<D: Family>(&mut self, subs: &mut [&mut Subdomain<D>], own: Own, red: &mut dyn Reduce) {
        gather(subs, own, &mut self.g, None);
        let gamma = self.mixer.step(&self.x, &self.g, red);
        if self.mixer.f_norm() < self.best_f {
            self.best_f = self.mixer.f_norm();
            self.best.clone_from(&self.g);
        }
        match gamma {
            None => self.x.clone_from(&self.g),
            Some(gamma) => {
                self.x.resize(self.g.len(), 0.0);
                self.mixer.mix_into(&gamma, &self.g, &mut self.x);
                scatter(subs, own, &mut self.x);
            }
        }
    }

    /// After the last stage of a step that did not converge: the own subdomains
    /// back to the stage output with the least ‖f‖ (the same stage on every process).
    pub fn give_up<D: Family>(&mut self, subs: &mut [&mut Subdomain<D>], own: Own) {
        if self.best_f.is_finite() {
            scatter(subs, own, &mut self.best);
        }
    }
}
