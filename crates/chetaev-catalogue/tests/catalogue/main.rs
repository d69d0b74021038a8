//! The integration tests of this package in one binary, so that the library is linked once: a module per subject.

mod common;

mod chaplygin_sleigh;
mod isokinetic_thermostat;
mod kepler_constant_speed;
mod knife_edge;
mod rolling_disk;
