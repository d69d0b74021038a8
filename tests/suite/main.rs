//! The integration tests of this package in one binary, so that the library is linked once: a module per subject.

mod bad_input;
mod conventions;
mod derivatives;
mod forces;
mod holonomic;
mod large;
mod paper;
mod properties;
mod runtime_sizes;
mod stats;
mod stiff;
mod time_dependent;
