//! Work-precision study and benchmarks.
