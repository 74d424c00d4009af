//! The crate's one error type, [`LabError`]: the caller's input (an [`InputError`] naming a file
//! and line, a study key or a flag: the command line exits 2) or a library failure that is not
//! the caller's (exit 1).
//!
//! A library error of the workspace becomes a [`LabError`] by one rule ([`library`]): an input
//! error ([`tt_core::ErrorClass::input_field`] names the field) is an [`InputError`] located by
//! its field (a flag, a study key, or the file the input came from), in the user's units where
//! the library speaks radians; anything else is [`LabError::Library`].

use alloc_opt::AllocError;
use e2e_verify::E2eError;
use mc_verify::McError;
use std::any::Any;
use std::fmt;
use study::Study;
use tt_core::ErrorClass;

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

/// The error of every study-level question.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum LabError {
    /// The caller's input is wrong: a study key, a tolerance sheet, a flag, a recording row
    /// (named in [`InputError::location`]).
    #[error(transparent)]
    Input(#[from] InputError),
    /// A library failed on an accepted input (not the caller's fault).
    #[error(transparent)]
    Library(Box<dyn std::error::Error + Send + Sync + 'static>),
    /// Writing or reading the caller's output failed (`what` was being done).
    #[error("{what}")]
    Io {
        /// What was being done (`writing <file>`), paths shown visibly.
        what: String,
        /// The system's error.
        #[source]
        source: std::io::Error,
    },
}

/// What was being done when an I/O operation failed, as a [`LabError::Io`] (or, for a missing
/// value, a [`LabError::Library`] saying it).
pub(crate) trait Context<T> {
    /// The error with `what()` as its context.
    fn with_context<F: FnOnce() -> String>(self, what: F) -> Result<T>;
}

impl<T> Context<T> for std::io::Result<T> {
    fn with_context<F: FnOnce() -> String>(self, what: F) -> Result<T> {
        self.map_err(|source| LabError::Io {
            what: what(),
            source,
        })
    }
}

impl<T> Context<T> for Option<T> {
    fn with_context<F: FnOnce() -> String>(self, what: F) -> Result<T> {
        self.ok_or_else(|| LabError::Library(what().into()))
    }
}

impl LabError {
    /// The input error, when the caller's input is at fault.
    #[must_use]
    pub fn input(&self) -> Option<&InputError> {
        match self {
            Self::Input(i) => Some(i),
            Self::Library(_) | Self::Io { .. } => None,
        }
    }

    /// A library failure that is not the caller's input.
    pub(crate) fn internal(e: impl std::error::Error + Send + Sync + 'static) -> Self {
        Self::Library(Box::new(e))
    }
}

impl From<study::StudyError> for LabError {
    fn from(e: study::StudyError) -> Self {
        InputError::from(e).into()
    }
}

impl From<study::StudyError> for InputError {
    fn from(e: study::StudyError) -> Self {
        InputError::new(e.location, e.reason)
    }
}

/// The result of a study-level question.
pub type Result<T, E = LabError> = std::result::Result<T, E>;

/// The study key of the lower bounds.
pub const LOWER_BOUNDS_KEY: &str = "allocation.lower_bounds_arcmin";

/// A lower bound above an upper bound, in the user's units (the box's values come in rad),
/// naming the study file and key and the box (`what`: `Table 4`, a tolerance file...).
#[must_use]
pub(crate) fn lower_above_upper(
    study_path: &str,
    component: &str,
    lb_rad: f64,
    ub_rad: f64,
    what: &str,
) -> InputError {
    use tt_core::units::rad_to_arcmin;
    InputError::new(
        format!("{study_path}: key `{LOWER_BOUNDS_KEY}.{component}`"),
        format!(
            "the lower bound {} arcmin exceeds the upper bound {} arcmin of {what}: lower it or widen the box",
            tt_core::human::num(rad_to_arcmin(lb_rad)),
            tt_core::human::num(rad_to_arcmin(ub_rad))
        ),
    )
}

/// Lower bounds that alone violate a requirement, in the user's units.
#[must_use]
pub(crate) fn infeasible_lower_bounds(
    study_path: &str,
    lower_bounds_rad: &[f64],
    names: &[&str],
    components: &[String],
    angle: &str,
    worst_rad: f64,
    requirement_rad: f64,
) -> InputError {
    use tt_core::units::rad_to_arcmin;
    let listed: Vec<String> = components
        .iter()
        .map(|c| {
            let lb = names
                .iter()
                .position(|n| n == c)
                .map_or(f64::NAN, |j| lower_bounds_rad[j]);
            format!("{c} = {} arcmin", tt_core::human::num(rad_to_arcmin(lb)))
        })
        .collect();
    InputError::new(
        format!("{study_path}: key `{LOWER_BOUNDS_KEY}`"),
        format!(
            "the lower bounds {} alone give a worst-case {angle} error of {} deg, above the requirement {} deg: no tolerance can meet it; lower them or loosen the requirement",
            listed.join(", "),
            tt_core::human::num(worst_rad.to_degrees()),
            tt_core::human::num(requirement_rad.to_degrees())
        ),
    )
}

/// Any library error of the workspace: it says whether it is the caller's input.
pub trait LibraryError: ErrorClass + std::error::Error + Send + Sync + 'static {}

impl<T: ErrorClass + std::error::Error + Send + Sync + 'static> LibraryError for T {}

/// The one rule from a library error to the command's error: an input error is an
/// [`InputError`] (exit 2) located by its field (`location`), anything else is internal
/// (exit 1). Fields that are not flags or lower bounds are located at the study file.
pub fn library<E: LibraryError>(e: E, s: &Study) -> LabError {
    located(e, s, &s.path, "the box")
}

/// [`library`] with `at` (a tolerance file, a CSV row) as the location of the fields that are
/// not flags or lower bounds (and as the name of a box whose lower bound exceeds its upper).
pub fn library_at<E: LibraryError>(e: E, s: &Study, at: &str) -> LabError {
    located(e, s, at, at)
}

fn located<E: LibraryError>(e: E, s: &Study, at: &str, box_name: &str) -> LabError {
    if let Some(input) = in_user_units(&e, s, box_name) {
        return input.into();
    }
    match e.input_field() {
        Some(field) => InputError::new(location(field, s, at), e.to_string()).into(),
        None => LabError::internal(e),
    }
}

/// Where an input field of a library error is, for the user: its flag, the study key of the
/// lower bounds, or `at`.
fn location(field: &str, s: &Study, at: &str) -> String {
    match field {
        "samples" | "chunk_size" | "yield_fraction" | "positions" | "max_condition"
        | "constraint_form" | "time_budget_s" => format!("--{}", field.replace('_', "-")),
        "histogram_bins" => "--bins".into(),
        "safety_margin" | "1 - safety_margin" | "requirement_factor" => "--safety-margin".into(),
        "step_deg" | "candidates" => "--step-deg".into(),
        "candidate_positions" => "candidate positions (--step-deg and the joint ranges)".into(),
        f if f == "lower_bounds" || f.starts_with("lower_bounds.") => {
            format!("{}: key `{LOWER_BOUNDS_KEY}`", s.path)
        }
        _ => at.to_string(),
    }
}

/// The errors whose message is rewritten in the user's units (arcmin, the study's key) or
/// whose location quotes the flag's value.
fn in_user_units(e: &dyn Any, s: &Study, box_name: &str) -> Option<InputError> {
    if let Some(e) = e.downcast_ref::<E2eError>() {
        return match e {
            E2eError::Alloc(a) => in_user_units(a, s, box_name),
            E2eError::Bounds(b) => in_user_units(b, s, box_name),
            E2eError::LowerAboveBox {
                name,
                component,
                lb,
                ub,
            } => {
                let what = if zhao2017_box(name) {
                    format!("{name} (the paper's allocation, evaluated beside ours)")
                } else {
                    format!("the box `{name}`")
                };
                Some(lower_above_upper(&s.path, component, *lb, *ub, &what))
            }
            E2eError::GridTooLarge { step_deg, .. } => Some(InputError::new(
                format!("--step-deg {}", tt_core::human::exact(*step_deg)),
                e.to_string(),
            )),
            _ => None,
        };
    }
    if let Some(McError::LowerAboveUpper { component, lb, ub }) = e.downcast_ref::<McError>() {
        return Some(lower_above_upper(&s.path, component, *lb, *ub, box_name));
    }
    if let Some(AllocError::InfeasibleLowerBounds {
        problem,
        components,
        worst_case_rad,
        requirement_rad,
    }) = e.downcast_ref::<AllocError>()
    {
        return Some(infeasible_lower_bounds(
            &s.path,
            &s.lower_bounds_rad,
            &s.turntable.rotation_error_names(),
            components,
            problem,
            *worst_case_rad,
            *requirement_rad,
        ));
    }
    None
}

/// Whether a named box of an end-to-end answer is the paper's Table 4.
#[cfg(feature = "paper")]
fn zhao2017_box(name: &str) -> bool {
    name == e2e_verify::paper::TABLE4_BOX
}

/// Without the paper compiled in, no box is the paper's Table 4.
#[cfg(not(feature = "paper"))]
fn zhao2017_box(_name: &str) -> bool {
    false
}
