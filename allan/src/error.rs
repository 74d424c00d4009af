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
    /// The sample rate is zero, negative or not finite.
    #[error("rate_hz: the sample rate must be a positive finite number of Hz, got `{value}`")]
    InvalidRate {
        /// The value given.
        value: f64,
    },
    /// A setting is outside its range.
    #[error("{field}: `{value}` is out of range; expected {expected}")]
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
    /// The samples are so large that their squared differences overflow a double.
    #[error(
        "samples: the Allan variance at tau = {tau_s} s overflows (the samples are too large; rescale the log)"
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
            AllanError::InvalidSetting { field, .. } => Some(field),
        }
    }
}
