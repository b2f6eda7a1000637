//! 2D rigid bodies: [`Bodies2`], the generic [`crate::model::Bodies`] with
//! [`crate::dim::D2`]'s twist (v_x, v_y, ω), angles and diagonal M̂⁻¹.

pub use crate::model::ShapeRef;

/// 2D rigid bodies.
pub type Bodies2 = crate::model::Bodies<crate::dim::D2>;
