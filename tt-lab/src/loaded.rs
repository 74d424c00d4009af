//! Loading the study a command works on, and what every command derives from it the same way
//! (the requirement handed to the two-step allocation and the line that says when a given
//! requirement disagrees with the computed one).

use crate::error::{InputError, Result};
use crate::paths;
use alloc_opt::Requirement;
use calib_lsq::{AxisDisagreement, CalibError, OrientationRequirement, RequirementProblem};
use e2e_verify::EndToEnd;
use std::path::Path;
use study::{RequirementSource, Study};
use tt_core::Pose;

/// Read the study `given` (or the paper's: from the workspace root, else the copy compiled
/// in), shown in reports as the user gave it.
///
/// # Errors
/// An [`InputError`] naming the file and key.
pub fn load(given: Option<&Path>) -> Result<Study, InputError> {
    // the path as every output shows it: one visible line (a line feed in a file name cannot
    // forge a line of output); a shell line quotes the path as given instead
    let shown = given.map_or_else(
        || paths::PAPER_STUDY.to_string(),
        |p| p.display().to_string(),
    );
    let text_path = tt_core::human::visible(&shown).into_owned();
    let mut s = match paths::study_source(given) {
        paths::StudySource::File(path) => Study::load(&path).map_err(|e| {
            // name the file as the user gave it (or the workspace-relative default)
            InputError::new(
                e.location
                    .replacen(&path.display().to_string(), &text_path, 1),
                e.reason,
            )
        })?,
        paths::StudySource::BuiltIn => Study::parse(&text_path, paths::PAPER_STUDY_TEXT)?,
    };
    s.path = text_path;
    Ok(s)
}

/// The turntable pose of every schedule entry of a study (the test positions, then where
/// each rate step starts).
///
/// # Errors
/// Never for a parsed study (positions were validated); an [`InputError`] otherwise.
pub fn poses(s: &Study) -> Result<Vec<Pose>> {
    s.schedule_angles_deg()
        .iter()
        .map(|p| Pose::from_deg(p).map_err(|e| crate::error::library(e, s)))
        .collect()
}

/// The end-to-end simulator of a study: its turntable, calibration, schedule and reading.
///
/// # Errors
/// An [`InputError`] naming the study.
pub fn simulator(s: &Study) -> Result<EndToEnd> {
    EndToEnd::new(&s.turntable, &s.calibration, &poses(s)?, s.reading)
        .map_err(|e| crate::error::library(e, s))
}

/// What every command prints beside the orientation requirement of a study with rate steps.
pub const STATIC_REQUIREMENT_NOTE: &str = "the study has rate steps: the orientation requirement (eq 15-16) is a static concept (one orientation error at every test position), so the two-step allocation against it is not made; the direct allocation against every output's accuracy is the answer";

/// The requirement problem (eq 15-16) of a study.
#[must_use]
pub fn requirement_problem(s: &Study) -> RequirementProblem {
    RequirementProblem::new(s.calibration.clone(), s.reading, s.delta_r_kind)
}

/// The requirement a study hands to the two-step allocation, the computed one (if it exists)
/// and, when a given requirement disagrees with the computed one, the line that says so.
#[derive(Debug, Clone)]
pub struct StudyRequirement {
    /// The requirement used by the two-step allocation (`None`: none exists).
    pub used: Option<Requirement>,
    /// The computed requirement (eq 15-16), or why there is none.
    pub computed: Result<OrientationRequirement, CalibError>,
    /// Whether the study gives its requirement.
    pub given: bool,
    /// One line for every command and report when given and computed disagree.
    pub disagreement: Option<String>,
}

/// Resolve the study's requirement.
///
/// # Errors
/// An [`InputError`] naming `requirement` when a given value is invalid for the allocation.
pub fn requirement(s: &Study) -> Result<StudyRequirement> {
    let mut r = requirement_of(s)?;
    if s.has_rate_steps() {
        // every command and report that prints the requirement's note says it is static
        let note = format!(
            "note: {}; here it is computed over every schedule entry, a rate step's averaged inputs as if they were a static position's",
            STATIC_REQUIREMENT_NOTE
        );
        r.disagreement = Some(match r.disagreement {
            Some(d) => format!("{note}\n{d}"),
            None => note,
        });
    }
    Ok(r)
}

fn requirement_of(s: &Study) -> Result<StudyRequirement> {
    let computed = requirement_problem(s).requirement();
    match s.requirement {
        RequirementSource::Computed => {
            let used = computed.as_ref().ok().map(|r| r.requirement());
            Ok(StudyRequirement {
                used,
                computed,
                given: false,
                disagreement: None,
            })
        }
        RequirementSource::Given { rad } => {
            let used = Requirement::new(rad[0], rad[1], rad[2]).map_err(|e| {
                crate::error::library_at(e, s, &format!("{}: key `requirement`", s.path))
            })?;
            let disagreement = match &computed {
                Ok(c) => {
                    let parts: Vec<String> = c
                        .disagreement(rad)
                        .iter()
                        .map(|d| match *d {
                            AxisDisagreement::Differs {
                                axis,
                                given_rad: g,
                                computed_rad: v,
                            } => format!(
                                "{} {} deg given vs {} deg computed ({:+.2}%)",
                                axis.name(),
                                tt_core::human::num(g.to_degrees()),
                                tt_core::human::num(v.to_degrees()),
                                100.0 * (g / v - 1.0)
                            ),
                            AxisDisagreement::NoneComputed { axis, given_rad: g } => format!(
                                "{} {} deg given, none computed (no output constrains it)",
                                axis.name(),
                                tt_core::human::num(g.to_degrees())
                            ),
                        })
                        .collect();
                    (!parts.is_empty()).then(|| {
                        format!(
                            "note: the requirement given in the study differs from the one computed from its calibration inputs: {}; the allocation uses the given one",
                            parts.join(", ")
                        )
                    })
                }
                Err(e) => Some(format!(
                    "note: the study gives a requirement, but none can be computed from its calibration inputs ({e})"
                )),
            };
            Ok(StudyRequirement {
                used: Some(used),
                computed,
                given: true,
                disagreement,
            })
        }
    }
}
