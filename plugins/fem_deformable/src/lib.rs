//! # Deformable bodies: linear elastic finite elements, coupled to rigid bodies
pub mod body;
pub mod contact2;
pub mod coupled;
pub mod mesh;
pub mod python;
pub mod run;
pub mod scene;
pub mod stage2;
