//! Work-precision study, benchmarks and ensembles for `chetaev`.
//!
//! | module | what |
//! |---|---|
//! | [`handwritten`] | the paper's model written out by hand, the limit for `chetaev` |
//! | [`scenes`] | the five scenes of the study with their references and error measures |
//! | [`study`] | every method on a scene over the tolerances: error, median time, work counters |
//! | [`measure`] | timing, and comparison of curves at equal error |
//! | [`overhead`] | paying only for what is used: constraints and diagnostics, on whole solves |
//! | [`report`] | CSV and Markdown |
//! | [`criterion_results`] | criterion's results read back for the report |
//! | [`ensemble`] | a parameter sweep of the paper's range ratio, in parallel |
//! | [`parts`] | sweeps split into shards (`--shard k/n`), and the parts joined again |
//! | [`cli`] | what the binaries share: default output folder, a closed standard output |
//!
//! The models are the paper's (`uniform_projectile::model`) and those of
//! `chetaev_catalogue::benchmarks` (a 3D particle at constant speed, two particles under three
//! constraints, a constraint that does nothing, chains of any size); ode_solvers is run through
//! `chetaev_ode_solvers`.
//!
//! The binaries `work-precision`, `ensemble` and `bench-report` print; the library returns values.

pub mod cli;
pub mod criterion_results;
pub mod ensemble;
pub mod handwritten;
pub mod measure;
pub mod overhead;
pub mod parts;
pub mod report;
pub mod scenes;
pub mod study;
