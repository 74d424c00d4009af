//! The one error type of the crate: every variant names the field or the sample it is about.

/// What went wrong, naming the setting or the sample.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum AllanError {
    /// A sample is NaN or infinite (`index` counts from 0 over every sample pushed).
    #[error("sample {index}: `{value}` is not a finite number")]
    NonFiniteSample {
        /// Index of the sample, from 0.
        index: u64,
        /// The value given.
        value: f64,
    },
    /// The sample rate is outside [`crate::RATE_HZ`] (or not finite).
    #[error("rate_hz: `{}` is outside the accepted sample rates, 1e-9 to 1e12 Hz", short(*value))]
    InvalidRate {
        /// The value given.
        value: f64,
    },
    /// A setting is outside its range.
    #[error("{field}: `{}` is out of range; expected {expected}", short(*value))]
    InvalidSetting {
        /// The setting's name.
        field: &'static str,
        /// The value given.
        value: f64,
        /// The accepted range, in words.
        expected: &'static str,
    },
    /// Fewer samples than the shortest cluster (one sample, three clusters) needs.
    #[error(
        "samples: {samples} given, the shortest cluster time (one sample) needs at least {needed} (three clusters)"
    )]
    TooFewSamples {
        /// Samples given.
        samples: u64,
        /// Samples needed.
        needed: u64,
    },
    /// A listed cluster time the estimator cannot evaluate.
    #[error("taus: `{}` s: {reason}", short(*tau_s))]
    InvalidTau {
        /// The cluster time given, s.
        tau_s: f64,
        /// Why, in words.
        reason: String,
    },
    /// A listed cluster time longer than a third of the log.
    #[error(
        "taus: `{}` s needs at least {needed} samples (three clusters), the log has {samples}",
        short(*tau_s)
    )]
    ClusterTooLong {
        /// The cluster time given, s.
        tau_s: f64,
        /// Samples in the log.
        samples: u64,
        /// Samples needed.
        needed: u64,
    },
    /// The samples are so large (or so small) that a variance or a noise parameter is not a
    /// finite double.
    #[error(
        "samples: the Allan variance or a noise parameter at tau = {} s leaves the range of a double (the samples are too large or too small; rescale the log)",
        short(*tau_s)
    )]
    Overflow {
        /// The cluster time, s.
        tau_s: f64,
    },
}

impl tt_core::ErrorClass for AllanError {
    /// Input: a sample (`samples`), the rate (`rate_hz`), a setting, too few samples. Internal:
    /// none (an overflow comes from samples too large for a double: `samples`).
    fn input_field(&self) -> Option<&str> {
        match self {
            AllanError::NonFiniteSample { .. }
            | AllanError::TooFewSamples { .. }
            | AllanError::Overflow { .. } => Some("samples"),
            AllanError::InvalidRate { .. } => Some("rate_hz"),
            AllanError::InvalidTau { .. } | AllanError::ClusterTooLong { .. } => Some("taus"),
            AllanError::InvalidSetting { field, .. } => Some(field),
        }
    }
}

/// A number as a reader wants it: plain between 1e-6 and 1e15, else in exponent form (never
/// three hundred digits).
fn short(v: f64) -> String {
    if v == 0.0 || !v.is_finite() || (1e-6..1e15).contains(&v.abs()) {
        format!("{v}")
    } else {
        format!("{v:e}")
    }
}
