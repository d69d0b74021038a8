//! The integration tests of this package in one binary, so that the library is linked once: a module per subject.

mod common;

mod compiled;
mod describe;
mod loads;
mod manifold;
mod reliability;
mod rows;
mod sensitivity;
