//! # Deformable bodies: linear elastic finite elements, coupled to rigid bodies
pub mod python;
