//! The one error type of the core. Every variant names the offending argument.

use thiserror::Error;

/// Result alias used throughout the crate.
pub type Result<T> = std::result::Result<T, Error>;

/// Everything that can go wrong in a core call. Variants carry the argument's name and
/// the value that was rejected, so that a message is useful on its own.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum Error {
    /// An array argument has the wrong length or shape.
    #[error("{arg}: expected {expected}, got {got}")]
    Shape {
        /// Name of the argument.
        arg: String,
        /// What was expected, e.g. `"length 9"`.
        expected: String,
        /// What was received.
        got: String,
    },
    /// An argument contains NaN or an infinite value.
    #[error("{arg}: non-finite value {value} at index {index}")]
    NonFinite {
        /// Name of the argument.
        arg: String,
        /// Flat index of the first offending element.
        index: usize,
        /// The offending value.
        value: f64,
    },
    /// A value lies outside its allowed closed range.
    #[error("{arg} = {value} is out of range [{min}, {max}]")]
    OutOfRange {
        /// Name of the argument.
        arg: String,
        /// The offending value.
        value: f64,
        /// Smallest allowed value.
        min: f64,
        /// Largest allowed value.
        max: f64,
    },
    /// A model parameter is invalid (non-positive length, lower >= upper, ...).
    #[error("{arg} = {value}: {reason}")]
    Parameter {
        /// Name of the argument.
        arg: String,
        /// The offending value.
        value: f64,
        /// Why it is rejected.
        reason: String,
    },
    /// A named choice (a mode, a schedule) is not one of the accepted names.
    #[error("{arg} = {value:?}: {reason}")]
    Choice {
        /// Name of the argument.
        arg: String,
        /// The rejected name.
        value: String,
        /// What is accepted.
        reason: String,
    },
    /// A pose is malformed (non-finite, rotation not orthonormal, bad last row).
    #[error("{arg}: {reason}")]
    Pose {
        /// Name of the argument.
        arg: String,
        /// Why it is rejected.
        reason: String,
    },
}

impl Error {
    /// A shape error for `arg`.
    pub fn shape(arg: &str, expected: impl Into<String>, got: impl Into<String>) -> Self {
        Error::Shape {
            arg: arg.to_owned(),
            expected: expected.into(),
            got: got.into(),
        }
    }

    /// A parameter error for `arg`.
    pub fn parameter(arg: &str, value: f64, reason: impl Into<String>) -> Self {
        Error::Parameter {
            arg: arg.to_owned(),
            value,
            reason: reason.into(),
        }
    }
}

/// Fails with [`Error::NonFinite`] on the first NaN or infinity in `values`.
pub fn check_finite(arg: &str, values: &[f64]) -> Result<()> {
    match values.iter().position(|v| !v.is_finite()) {
        None => Ok(()),
        Some(index) => Err(Error::NonFinite {
            arg: arg.to_owned(),
            index,
            value: values[index],
        }),
    }
}

/// Fails with [`Error::Shape`] unless `values` has exactly `len` elements.
pub fn check_len(arg: &str, values: &[f64], len: usize) -> Result<()> {
    if values.len() == len {
        Ok(())
    } else {
        Err(Error::shape(
            arg,
            format!("length {len}"),
            format!("length {}", values.len()),
        ))
    }
}

/// Fails with [`Error::OutOfRange`] unless `min <= value <= max` (NaN fails too).
pub fn check_range(arg: &str, value: f64, min: f64, max: f64) -> Result<()> {
    if value >= min && value <= max {
        Ok(())
    } else {
        Err(Error::OutOfRange {
            arg: arg.to_owned(),
            value,
            min,
            max,
        })
    }
}

/// Largest magnitude of a configuration coordinate (m or rad). Far beyond any arm, and
/// small enough that every product the kinematics forms (lengths times bending angles,
/// squared distances) stays finite.
pub const MAX_COORDINATE: f64 = 1e6;

/// Largest magnitude of an obstacle coordinate or a goal position (m). Squared distances
/// and the curve search's products of positions and speeds stay below 1e300.
pub const MAX_POSITION: f64 = 1e100;

/// Most samples of one curve, section or path that a call may ask for: enough for any
/// plot or baseline, small enough that the output (3 f64 per sample) always fits in memory.
pub const MAX_SAMPLES: usize = 1_000_000;

/// Most iterations of an iterative call (planner steps, stall windows): the path stores one
/// configuration per iteration.
pub const MAX_ITERATIONS: usize = 100_000;

/// Fails with [`Error::OutOfRange`] unless `min <= value <= max`, for a count.
pub fn check_count(arg: &str, value: usize, min: usize, max: usize) -> Result<()> {
    if value >= min && value <= max {
        Ok(())
    } else {
        Err(Error::OutOfRange {
            arg: arg.to_owned(),
            value: value as f64,
            min: min as f64,
            max: max as f64,
        })
    }
}

/// Fails unless every value is finite and at most `bound` in magnitude: a
/// [`Error::NonFinite`] for NaN or infinity, an [`Error::OutOfRange`] naming `arg[index]`
/// for a finite value beyond the bound.
#[inline]
pub fn check_bounded(arg: &str, values: &[f64], bound: f64) -> Result<()> {
    // One branch-free pass for the common case; NaN fails `<=` and falls through.
    if values.iter().fold(true, |ok, v| ok & (v.abs() <= bound)) {
        return Ok(());
    }
    check_finite(arg, values)?;
    match values.iter().position(|v| v.abs() > bound) {
        None => Ok(()),
        Some(i) => Err(Error::OutOfRange {
            arg: format!("{arg}[{i}]"),
            value: values[i],
            min: -bound,
            max: bound,
        }),
    }
}

/// Fails with [`Error::Parameter`] unless `value` is finite and `min <= value <= max`.
pub fn check_parameter(arg: &str, value: f64, min: f64, max: f64) -> Result<()> {
    if !value.is_finite() {
        return Err(Error::parameter(arg, value, "must be finite"));
    }
    if value >= min && value <= max {
        Ok(())
    } else {
        Err(Error::parameter(
            arg,
            value,
            format!("must lie in [{min}, {max}]"),
        ))
    }
}
