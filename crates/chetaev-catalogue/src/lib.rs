//! A catalogue of classic constrained systems.
