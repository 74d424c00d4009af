//! The crate's error type.

/// Errors from describing a turntable and from evaluating it.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum KinematicsError {
    /// An input was rejected by a check (non-finite value, wrong length), naming the field
    /// (`pose[1]`, `chi`, `weights`).
    #[error(transparent)]
    Field(#[from] tt_core::FieldError),
    /// A turntable description is invalid. `key` is the path inside the description
    /// (`factors[3].about`, `joint_ranges_deg.phi1`, ...), so that a file reader can name the
    /// offending key.
    #[error("{key}: {reason}")]
    Description {
        /// Where, relative to the description (`factors[2].error`, `error_order[0]`).
        key: String,
        /// Why it was rejected.
        reason: String,
    },
    /// A model was asked about a turntable it does not describe (for example the paper's
    /// closed form of eq 26 on a three-axis table).
    #[error("{model} applies only to {applies_to}")]
    WrongTurntable {
        /// The model.
        model: &'static str,
        /// What it applies to.
        applies_to: &'static str,
    },
    /// A caller-supplied [`crate::OrientationErrorModel`] gives no $\Delta\mathbf R$ of its own
    /// (it keeps the default [`crate::OrientationErrorModel::delta_r`]) where the exact rotation
    /// is needed (a schedule's $\Delta\mathbf R_i$, the conformance suite's rotation checks).
    #[error(
        "the orientation-error model gives no delta_r of its own: implement OrientationErrorModel::delta_r (the exact rotation R_d^T R_t), or return tt_kinematics::delta_r_of_angles(self, pose, errors) there to accept the rotation of its angles (equal to first order only)"
    )]
    NoDeltaR,
}

pub(crate) use tt_core::{finite, length};

pub(crate) fn description(key: impl Into<String>, reason: impl Into<String>) -> KinematicsError {
    KinematicsError::Description {
        key: key.into(),
        reason: reason.into(),
    }
}

impl tt_core::ErrorClass for KinematicsError {
    /// Every variant is the caller's input: a field, a key of the description, or `model`
    /// for a model asked about a turntable it does not describe.
    fn input_field(&self) -> Option<&str> {
        match self {
            KinematicsError::Field(e) => Some(e.field()),
            KinematicsError::Description { key, .. } => Some(key),
            KinematicsError::WrongTurntable { .. } | KinematicsError::NoDeltaR => Some("model"),
        }
    }
}
