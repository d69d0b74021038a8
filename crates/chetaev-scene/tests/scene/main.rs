//! The integration tests of this package in one binary, so that the library is linked once: a module per subject.

mod autodiff;
mod cli;
mod describe;
mod forces;
mod fuzz;
mod guide;
mod holonomic;
mod isokinetic_gas;
mod loads;
mod paper;
mod parameters;
mod parser;
mod pictures;
mod powers;
mod recorded_quantities;
mod rust_and_scene_agree;
mod scenes;
mod sensitivities;
mod sweep;
