//! Rigid bodies in 2D: degrees of freedom (x, y, rotation), the contact set and its
//! NLGS solver.
//!
//! A body's generalized velocity is `V = (v_x, v_y, ω)` and its iteration matrix
//! `M̂ = diag(m, m, I)` (rigid: `M̂ = M`). A contact α between a candidate body `i`
//! and an antagonist body `j` has the frame (n, t) with n pointing from j towards i
//! and `t = (−n_y, n_x)`. With the lever arm `d_b = p − x_b` of the contact point p,
//! the local velocity is
//!
//! ```text
//! u_α = H_iᵀ V_i − H_jᵀ V_j,   H_bᵀ V_b = ( n·v_b + (d_b × n) ω_b ,  t·v_b + (d_b × t) ω_b )
//! ```
//!
//! and an impulse r_α acts as `+H_i r` on i and `−H_j r` on j. The Delassus block is
//! `W_αα = H_iᵀ M̂_i⁻¹ H_i + H_jᵀ M̂_j⁻¹ H_j`. Degrees of freedom driven by an imposed
//! velocity have a zero entry in `M̂⁻¹`, so impulses never move them.

pub mod bodies;
pub mod contacts;
pub mod coulomb;
pub mod nlgs;

pub use bodies::Bodies2;
pub use contacts::Contacts2;
