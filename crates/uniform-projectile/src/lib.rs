//! The uniform horizontal projectile of Swaczyna and Volný: closed forms of the classical and the
//! uniform (isotachytonic) motion, and the verification of `chetaev` against them.

pub mod closed_form;
pub mod model;
pub mod report;
