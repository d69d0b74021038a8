//! The tests of `chetaev`'s public API, in one binary so that the library is linked once: a module
//! per subject. They live in the workspace's root package rather than in `crates/chetaev`, since
//! its test builds are unoptimised (see the workspace's `Cargo.toml`): the same binary took about
//! nine minutes of CPU to build optimised, against about one and a half unoptimised, and its tests
//! run in about 50 s instead of 3 s (2 cores, AMD EPYC; `/usr/bin/time cargo test --test api
//! --no-run` after touching this file, then the binary it names). `cargo test --test api` runs them.

mod common;

mod compiled;
mod describe;
mod loads;
mod manifold;
mod reliability;
mod rows;
mod sensitivity;
