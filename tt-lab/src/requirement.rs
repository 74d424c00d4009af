//! The orientation requirement of a study (eq 15-16, paper §2.2-2.3): under the study's
//! reading of eq 13 or another, or under every reading side by side.

use crate::Result;
use crate::json::{PerAngle, deg3};
use crate::loaded::{self, StudyRequirement};
use calib_lsq::{CalibError, OrientationRequirement, Reading, RequirementProblem};
use study::{RequirementSource, Study};
use tt_core::OrientationAxis;

/// What to compute.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
#[non_exhaustive]
pub struct Options {
    /// The reading of eq 13 (`None`: the study's).
    pub reading: Option<Reading>,
}

impl Options {
    /// The options with reading `r`.
    #[must_use]
    pub fn reading(mut self, r: Option<Reading>) -> Self {
        self.reading = r;
        self
    }
}

/// The requirement under one reading: its problem and the computed requirement (or why
/// there is none).
#[derive(Debug, Clone)]
pub struct ReadingRequirement {
    problem: RequirementProblem,
    result: std::result::Result<OrientationRequirement, CalibError>,
}

impl ReadingRequirement {
    fn of(problem: RequirementProblem) -> Self {
        let result = problem.requirement();
        Self { problem, result }
    }

    /// The problem solved (calibration, reading, Delta-R kind).
    #[must_use]
    pub fn problem(&self) -> &RequirementProblem {
        &self.problem
    }

    /// The reading of eq 13.
    #[must_use]
    pub fn reading(&self) -> Reading {
        self.problem.reading
    }

    /// The requirement, or why none can be computed.
    pub fn result(&self) -> &std::result::Result<OrientationRequirement, CalibError> {
        &self.result
    }

    /// The JSON view.
    #[must_use]
    pub fn view(&self) -> RequirementJson<'_> {
        requirement_json(&self.problem, &self.result)
    }
}

/// The study's requirement under one reading, with the requirement the study gives and the
/// line that says how it disagrees with the computed one.
#[derive(Debug, Clone)]
#[non_exhaustive]
pub struct RequirementAnswer {
    computed: ReadingRequirement,
    resolved: StudyRequirement,
    given_rad: Option<[f64; 3]>,
    study_path: String,
}

impl RequirementAnswer {
    /// The requirement under the chosen reading.
    #[must_use]
    pub fn computed(&self) -> &ReadingRequirement {
        &self.computed
    }

    /// The study's requirement as every command resolves it ([`loaded::requirement`]).
    #[must_use]
    pub fn resolved(&self) -> &StudyRequirement {
        &self.resolved
    }

    /// The requirement the study gives, rad (`None`: computed).
    #[must_use]
    pub fn given_rad(&self) -> Option<[f64; 3]> {
        self.given_rad
    }

    /// How a given requirement disagrees with the computed one (and the rate steps' note).
    #[must_use]
    pub fn disagreement(&self) -> Option<&str> {
        self.resolved.disagreement.as_deref()
    }

    /// The JSON view (`requirement --json`).
    #[cfg(feature = "serde")]
    #[must_use]
    pub fn view(&self) -> impl serde::Serialize + '_ {
        StudyRequirementJson {
            requirement: self.computed.view(),
            study: &self.study_path,
            given_requirement_deg: self.given_rad.map(|g| deg3(&g.map(Some))),
            disagreement: self.resolved.disagreement.clone(),
        }
    }
}

/// The problem of the study under the options' reading.
fn problem(s: &Study, o: &Options) -> RequirementProblem {
    let mut p = loaded::requirement_problem(s);
    if let Some(r) = o.reading {
        p.reading = r;
    }
    p
}

/// The study's orientation requirement under the options' reading.
///
/// # Errors
/// An [`crate::InputError`] naming `requirement` when a given value is invalid.
pub fn requirement(s: &Study, o: &Options) -> Result<RequirementAnswer> {
    let resolved = loaded::requirement(s)?;
    let given_rad = match s.requirement {
        RequirementSource::Given { rad } => Some(rad),
        RequirementSource::Computed => None,
    };
    Ok(RequirementAnswer {
        computed: ReadingRequirement::of(problem(s, o)),
        resolved,
        given_rad,
        study_path: s.path.clone(),
    })
}

/// The requirement under every reading of eq 13 ([`Reading::all`]), in order; the options'
/// reading is ignored.
///
/// # Errors
/// As [`requirement`].
pub fn all_readings(s: &Study, o: &Options) -> Result<Vec<ReadingRequirement>> {
    loaded::requirement(s)?;
    let base = problem(s, o);
    Ok(Reading::all()
        .into_iter()
        .map(|reading| {
            ReadingRequirement::of(RequirementProblem {
                reading,
                ..base.clone()
            })
        })
        .collect())
}

/// One output's requirement box.
#[derive(Debug)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
#[cfg_attr(not(feature = "serde"), allow(dead_code))]
pub(crate) struct RequirementOutputJson<'a> {
    /// The output's name.
    name: &'a str,
    /// Its unit (the study's).
    unit: &'a str,
    /// Its accuracy, output's unit.
    accuracy: f64,
    /// The angles it is sensitive to (`null` when the requirement failed).
    sensitive_angles: Option<Vec<&'static str>>,
    /// The half sides of its largest box, degrees (`null` where unconstrained, or when the
    /// requirement failed).
    half_sides_deg: Option<PerAngle<Option<f64>>>,
}

/// The requirement under one reading (`requirement --all-readings --json` prints a list).
#[derive(Debug)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
#[cfg_attr(not(feature = "serde"), allow(dead_code))]
pub struct RequirementJson<'a> {
    /// The reading of eq 13.
    reading: String,
    /// Its formula.
    reading_formula: String,
    /// The Delta-R kind.
    delta_r: String,
    /// Test positions.
    schedule_positions: usize,
    /// I_psi, I_theta, I_gamma, degrees (`null` where no output constrains the angle; the
    /// whole `null` when the requirement failed, `note`).
    orientation_requirement_deg: Option<PerAngle<Option<f64>>>,
    /// Every output's box.
    outputs: Vec<RequirementOutputJson<'a>>,
    /// The outputs that constrain no angle.
    unconstrained_outputs: Vec<String>,
    /// Why there is no requirement, else `null`.
    note: Option<String>,
}

impl RequirementJson<'_> {
    /// I_psi, I_theta, I_gamma, degrees (`None` when the requirement failed).
    #[must_use]
    pub fn orientation_requirement_deg(&self) -> Option<&PerAngle<Option<f64>>> {
        self.orientation_requirement_deg.as_ref()
    }
}

/// The view of one requirement.
#[must_use]
pub(crate) fn requirement_json<'a>(
    p: &'a RequirementProblem,
    r: &std::result::Result<OrientationRequirement, CalibError>,
) -> RequirementJson<'a> {
    RequirementJson {
        reading: p.reading.to_string(),
        reading_formula: p.reading.formula().to_string(),
        delta_r: p.delta_r_kind.name().to_string(),
        schedule_positions: p.calibration.schedule().len(),
        orientation_requirement_deg: r.as_ref().ok().map(|r| deg3(&r.requirement().to_array())),
        outputs: p
            .calibration
            .outputs()
            .iter()
            .map(|o| {
                let b = r
                    .as_ref()
                    .ok()
                    .and_then(|r| r.boxes().iter().find(|b| b.output() == o.output().name));
                RequirementOutputJson {
                    name: &o.output().name,
                    unit: &o.output().unit,
                    accuracy: o.output().accuracy,
                    sensitive_angles: b.map(|b| {
                        (0..3)
                            .filter(|&j| b.half_rad()[j].is_some())
                            .map(|j| OrientationAxis::ALL[j].name())
                            .collect()
                    }),
                    half_sides_deg: b.map(|b| deg3(&b.half_rad())),
                }
            })
            .collect(),
        unconstrained_outputs: r
            .as_ref()
            .map(|r| r.unconstrained_outputs().to_vec())
            .unwrap_or_default(),
        note: r.as_ref().err().map(ToString::to_string),
    }
}

/// `requirement --json`: the study's requirement under its reading (or the options').
#[derive(Debug)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
#[cfg_attr(not(feature = "serde"), allow(dead_code))]
pub(crate) struct StudyRequirementJson<'a> {
    /// The requirement (its keys at the top level).
    #[cfg_attr(feature = "serde", serde(flatten))]
    requirement: RequirementJson<'a>,
    /// The study's path.
    study: &'a str,
    /// The requirement the study gives, degrees (`null`: computed).
    given_requirement_deg: Option<PerAngle<Option<f64>>>,
    /// How the given requirement disagrees with the computed one, else `null`.
    disagreement: Option<String>,
}
