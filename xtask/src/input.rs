//! Errors in what the user gave us (files, flags): they exit with code 2.

use std::fmt;

/// A problem with the user's input, naming where it is (file, line, column or key) and why.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct InputError {
    /// Where: a file and line/column, a key, or a flag.
    pub location: String,
    /// Why it was rejected.
    pub reason: String,
}

impl InputError {
    /// A new input error.
    pub fn new(location: impl Into<String>, reason: impl Into<String>) -> Self {
        Self {
            location: location.into(),
            reason: reason.into(),
        }
    }
}

impl fmt::Display for InputError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}: {}", self.location, self.reason)
    }
}

impl std::error::Error for InputError {}

/// The study key of the lower bounds.
pub const LOWER_BOUNDS_KEY: &str = "allocation.lower_bounds_arcmin";

/// A lower bound above an upper bound, in the user's units (the box's values come in rad),
/// naming the study file and key and the box (`what`: `Table 4`, a tolerance file...).
#[must_use]
pub fn lower_above_upper(
    study_path: &str,
    component: &str,
    lb_rad: f64,
    ub_rad: f64,
    what: &str,
) -> InputError {
    use tt_kinematics::units::rad_to_arcmin;
    InputError::new(
        format!("{study_path}: key `{LOWER_BOUNDS_KEY}.{component}`"),
        format!(
            "the lower bound {} arcmin exceeds the upper bound {} arcmin of {what}: lower it or widen the box",
            study::fmt::num(rad_to_arcmin(lb_rad)),
            study::fmt::num(rad_to_arcmin(ub_rad))
        ),
    )
}

/// Lower bounds that alone violate a requirement, in the user's units.
#[must_use]
pub fn infeasible_lower_bounds(
    study_path: &str,
    lower_bounds_rad: &[f64],
    names: &[&str],
    components: &[String],
    angle: &str,
    worst_rad: f64,
    requirement_rad: f64,
) -> InputError {
    use tt_kinematics::units::rad_to_arcmin;
    let listed: Vec<String> = components
        .iter()
        .map(|c| {
            let lb = names
                .iter()
                .position(|n| n == c)
                .map_or(f64::NAN, |j| lower_bounds_rad[j]);
            format!("{c} = {} arcmin", study::fmt::num(rad_to_arcmin(lb)))
        })
        .collect();
    InputError::new(
        format!("{study_path}: key `{LOWER_BOUNDS_KEY}`"),
        format!(
            "the lower bounds {} alone give a worst-case {angle} error of {} deg, above the requirement {} deg: no tolerance can meet it; lower them or loosen the requirement",
            listed.join(", "),
            study::fmt::num(worst_rad.to_degrees()),
            study::fmt::num(requirement_rad.to_degrees())
        ),
    )
}
