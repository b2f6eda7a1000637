//! # Deformable bodies: linear elastic finite elements, coupled to rigid bodies
pub mod bench;
pub mod body;
pub mod contact2;
pub mod contact3;
pub mod family2;
pub mod family3;
pub mod mesh;
pub mod nodes;
pub mod python;
pub mod run;
pub mod scene;
pub mod stage2;
pub mod stage3;
