//! The one error type of the catalogue.

/// What can go wrong when building a catalogue entry or comparing a motion with its reference.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// A parameter is outside the range for which the system and its reference are defined.
    #[error("invalid parameter {name} = {value}: {hint}")]
    InvalidParameter {
        /// The parameter.
        name: &'static str,
        /// Its value.
        value: f64,
        /// The allowed range, and why.
        hint: &'static str,
    },

    /// A list (of parameters, or a recorded state or multiplier) does not have the length the model
    /// needs (`N` coordinates, `K` constraints).
    #[error("{what} has {got} entries, but the model needs {expected}")]
    WrongLength {
        /// Which list.
        what: &'static str,
        /// Its length.
        got: usize,
        /// The length the model needs.
        expected: usize,
    },

    /// `chetaev` refused the problem (see its message).
    #[error(transparent)]
    Chetaev(#[from] chetaev::Error),
}

/// `Ok(value)` if `value` is finite and `ok(value)` holds, otherwise
/// [`Error::InvalidParameter`] with `hint`.
pub(crate) fn check(
    name: &'static str,
    value: f64,
    ok: impl Fn(f64) -> bool,
    hint: &'static str,
) -> Result<f64, Error> {
    if value.is_finite() && ok(value) {
        Ok(value)
    } else {
        Err(Error::InvalidParameter { name, value, hint })
    }
}

/// [`check`] for a finite, strictly positive parameter.
pub(crate) fn positive(name: &'static str, value: f64) -> Result<f64, Error> {
    check(name, value, |v| v > 0.0, "must be finite and > 0")
}

/// [`check`] for a finite parameter.
pub(crate) fn finite(name: &'static str, value: f64) -> Result<f64, Error> {
    check(name, value, |_| true, "must be finite")
}
