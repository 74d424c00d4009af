//! The study schema and its strict parser.

use crate::error::StudyError;
use crate::limits;
use calib_lsq::{Calibration, Position, Reading, Schedule};
use gw_model::{Output, Regressor, SensorModel, Site, Term};
use serde::Deserialize;
use std::collections::BTreeMap;
use std::io::Read;
use std::path::Path;
use tt_core::DeltaRKind;
use tt_core::human::{exact, num};
use tt_core::units::{RAD_PER_ARCMIN, RAD_PER_DEG};
use tt_kinematics::{
    ErrorVariation, FactorSpec, KinematicsError, Pose, SignedAxis, Turntable, TurntableDescription,
};

/// The reading of eq 13 when a study does not name one: outputs at the actual orientation,
/// the user's estimate, eq 13's printed form: what a calibrating engineer gets.
pub(crate) const DEFAULT_READING: &str = "actual/beta1/printed";

/// The orientation-error matrix when a study does not name one: the exact rotation.
pub(crate) const DEFAULT_DELTA_R: &str = "exact";

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawStudy {
    name: String,
    description: Option<String>,
    turntable: RawTurntable,
    site: RawSite,
    sensor: RawSensor,
    calibration: RawCalibration,
    requirement: Option<RawRequirement>,
    allocation: Option<RawAllocation>,
    monte_carlo: RawMonteCarlo,
    compensation: Option<RawCompensation>,
    uncertainty: Option<crate::spec::RawUncertainty>,
    specifications: Option<Vec<crate::spec::RawSpecification>>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawCompensation {
    measured: Vec<RawMeasured>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawMeasured {
    error: String,
    value_arcmin: Option<f64>,
    coefficients_arcmin: Option<Vec<f64>>,
    uncertainty_arcmin: f64,
}

/// A measured error of the table (`[[compensation.measured]]`): the lab's measurement, which
/// the compensated calibration uses as a known input of the chain, and its uncertainty, the
/// bound that then matters: $\lvert\chi(\phi) - m(\phi)\rvert \le u$ over the revolution.
#[derive(Debug, Clone, PartialEq)]
pub struct Measured {
    /// The measured coefficients (rad) in the order of the error's expansion group: one
    /// constant, or $(c_0, a_{k_1}, b_{k_1}, \dots)$ for harmonics.
    pub coefficients_rad: Vec<f64>,
    /// The measurement uncertainty $u$ (rad), a bound over the revolution.
    pub uncertainty_rad: f64,
    /// The key of the measured values as written (`compensation.measured[0].value_arcmin`
    /// or `...coefficients_arcmin`), for messages.
    pub key: String,
    /// The measured values as written (arcmin), for messages.
    pub written_arcmin: Vec<f64>,
    /// The uncertainty as written (arcmin), for messages.
    pub uncertainty_arcmin: f64,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawTurntable {
    factors: Vec<RawFactor>,
    error_order: Option<Vec<String>>,
    joint_ranges_deg: Option<BTreeMap<String, Vec<f64>>>,
    max_rate_deg_per_s: Option<BTreeMap<String, f64>>,
    descriptions: Option<BTreeMap<String, String>>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawFactor {
    joint: Option<String>,
    error: Option<String>,
    fixed_deg: Option<f64>,
    about: Option<String>,
    along: Option<String>,
    varies: Option<String>,
    of: Option<String>,
    harmonics: Option<Vec<f64>>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawSite {
    latitude_deg: f64,
    earth_rate_rad_per_s: f64,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawSensor {
    outputs: Vec<RawOutput>,
    lever_arm_m: Option<Vec<f64>>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawOutput {
    name: String,
    unit: String,
    accuracy: f64,
    terms: Vec<RawTerm>,
    noise: Option<crate::noise::RawNoise>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawTerm {
    coefficient: String,
    regressor: String,
    value: f64,
    known: Option<bool>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawCalibration {
    reading: Option<String>,
    delta_r: Option<String>,
    positions_deg: Vec<Vec<f64>>,
    timing: Option<crate::noise::RawTiming>,
    rate_steps: Option<Vec<RawRateStep>>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawRateStep {
    joint: String,
    rate_deg_per_s: f64,
    angles_deg: Vec<f64>,
    revolutions: Option<f64>,
}

/// A rate step of a study (`[[calibration.rate_steps]]`): joint `joint` turns at
/// `rate_deg_per_s` for `revolutions` whole revolutions from `angles_deg`; the schedule holds
/// it after the static positions. Its output is averaged over those revolutions
/// ([`StudyRateStep::duration_s`]); without `revolutions` in the file (allowed with a
/// `[calibration.timing]`) they are [`default_revolutions`].
#[derive(Debug, Clone, PartialEq)]
pub struct StudyRateStep {
    /// Index of the turning joint (pose order).
    pub joint: usize,
    /// Commanded rate, deg/s (signed, non-zero, within the joint's limit).
    pub rate_deg_per_s: f64,
    /// Every joint's angle (deg, joint order); the turning joint's is where it starts.
    pub angles_deg: Vec<f64>,
    /// Whole revolutions.
    pub revolutions: u32,
}

impl StudyRateStep {
    /// The turning time, the rate step's averaging window: $360 N / |\Omega_c|$ s.
    #[must_use]
    pub fn duration_s(&self) -> f64 {
        360.0 * f64::from(self.revolutions) / self.rate_deg_per_s.abs()
    }
}

/// The revolutions of a rate step that does not give them: the fewest whole revolutions at
/// `rate_deg_per_s` that last at least `dwell_s` (the study's longest static dwell), at least
/// one, so that the step averages its noise at least as long as a position does and the
/// table's angle-dependent errors over whole turns.
#[must_use]
pub fn default_revolutions(rate_deg_per_s: f64, dwell_s: f64) -> u64 {
    // (a relative 1e-12 below: a dwell that is a whole number of turns is that number; the
    // cast saturates, and the count is checked against the limit as a given one is)
    (dwell_s * rate_deg_per_s.abs() / 360.0 * (1.0 - 1e-12))
        .ceil()
        .max(1.0) as u64
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawRequirement {
    source: Option<String>,
    psi_deg: Option<f64>,
    theta_deg: Option<f64>,
    gamma_deg: Option<f64>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawAllocation {
    lower_bounds_arcmin: Option<BTreeMap<String, f64>>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawMonteCarlo {
    samples: Count,
    seed: u64,
}

/// A count written as an integer or as a float with an integral value (`1e6`).
#[derive(Debug, Deserialize)]
#[serde(untagged)]
enum Count {
    Int(i64),
    Float(f64),
}

/// Where the orientation requirement handed to the two-step allocation comes from.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum RequirementSource {
    /// Computed from the calibration inputs (eq 15-16), the default.
    Computed,
    /// Given in the study, rad, order $(\psi, \theta, \gamma)$.
    Given {
        /// $(I_\psi, I_\theta, I_\gamma)$, rad.
        rad: [f64; 3],
    },
}

/// Monte Carlo settings of a study.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct MonteCarloSettings {
    /// Number of random turntables.
    pub samples: u64,
    /// Seed of the random streams.
    pub seed: u64,
}

/// A validated study: the library values built from the file.
#[derive(Debug, Clone)]
pub struct Study {
    /// The path as the user gave it (printed in reports; never made absolute).
    pub path: String,
    /// The file's text (to write a modified study that keeps the comments).
    pub text: String,
    /// Short name, a file-name-safe slug ([`is_name_slug`]): it names the report directory.
    pub name: String,
    /// Description (free text, shown escaped in reports), if given.
    pub description: Option<String>,
    /// The turntable.
    pub turntable: Turntable,
    /// The sensor.
    pub sensor: SensorModel,
    /// The site.
    pub site: Site,
    /// The reading of eq 13.
    pub reading: Reading,
    /// The orientation-error matrix kind of eq 7.
    pub delta_r_kind: DeltaRKind,
    /// The test positions as written (joint angles, deg, joint order).
    pub positions_deg: Vec<Vec<f64>>,
    /// Sensor, site and schedule, checked to identify every output's coefficients.
    pub calibration: Calibration,
    /// The requirement handed to the two-step allocation.
    pub requirement: RequirementSource,
    /// Lower bounds LB_i of the angular errors (eq 29), rad, order of chi.
    pub lower_bounds_rad: Vec<f64>,
    /// Monte Carlo settings.
    pub monte_carlo: MonteCarloSettings,
    /// The noise model of each output (study order; `None` where the study gives none,
    /// `[sensor.outputs.noise]`), in the output's unit.
    pub noise: Vec<Option<gw_model::noise::NoiseModel>>,
    /// Dwell per position, move time and sample rate (`[calibration.timing]`), if given; with
    /// rate steps also each step's window, its turning time ([`StudyRateStep::duration_s`]),
    /// after the positions.
    pub timing: Option<calib_lsq::Timing>,
    /// The measured errors (order of $\chi$; `[[compensation.measured]]`), `None` where not
    /// measured.
    pub measured: Vec<Option<Measured>>,
    /// How each angular error varies with a shaft angle (order of $\chi$;
    /// `turntable.factors[i].varies`, `of`, `harmonics`); constant unless the study says so.
    pub variations: Vec<tt_kinematics::ErrorVariation>,
    /// The rate steps (`[[calibration.rate_steps]]`), after the static positions in the
    /// schedule; empty for a static schedule.
    pub rate_steps: Vec<StudyRateStep>,
    /// The sensor's mounting lever arm in the platform frame (`sensor.lever_arm_m`), m.
    pub lever_arm_m: [f64; 3],
    /// Each joint's rate limit (`turntable.max_rate_deg_per_s`), deg/s; `None` where not
    /// given.
    pub max_rate_deg_per_s: Vec<Option<f64>>,
    /// The coverage probability and the laws of the table's tolerances in an uncertainty
    /// budget (`[uncertainty]`; 95 % and rectangular when not given).
    pub uncertainty: crate::spec::Uncertainty,
    /// The specifications per calibrated quantity (`[[specifications]]`), study order; empty
    /// when the study gives none (then each output's `accuracy` is the one specification,
    /// eq 14).
    pub specifications: Vec<gw_model::spec::Specification>,
}

/// Whether `name` is a valid study `name`: a file-name-safe slug of 1 to
/// [`limits::MAX_NAME_CHARS`] characters from `A-Z a-z 0-9 . _ -`, the first a letter or a
/// digit. It names the report directory (`target/report/<name>`), so it is one path component
/// that can never be `.`, `..`, hidden, a flag, or escape its parent.
///
/// ```
/// assert!(study::is_name_slug("gyrowheel-2017"));
/// for bad in ["", ".", "..", "../../../escaped", "a/b", "-x", ".hidden", "a\0b", "my study"] {
///     assert!(!study::is_name_slug(bad), "{bad}");
/// }
/// assert!(!study::is_name_slug(&"x".repeat(65)));
/// ```
#[must_use]
pub fn is_name_slug(name: &str) -> bool {
    let b = name.as_bytes();
    !b.is_empty()
        && b.len() <= limits::MAX_NAME_CHARS
        && b[0].is_ascii_alphanumeric()
        && b.iter()
            .all(|c| c.is_ascii_alphanumeric() || matches!(c, b'.' | b'_' | b'-'))
}

/// A one-line label of a file (a unit, a turntable part's description, a tolerance sheet's
/// name): printed in every output as it is, so no control character (ESC, BEL, CR, a line
/// break, ...) or bidirectional override ([`tt_core::human::is_unsafe_char`]) is accepted.
pub(crate) fn one_line(
    at: &dyn Fn(&str) -> String,
    key: &str,
    text: &str,
) -> Result<(), StudyError> {
    if text.chars().any(tt_core::human::is_unsafe_char) {
        return Err(StudyError::new(
            at(key),
            format!(
                "must be one line of printable text (no control character such as ESC, a tab or a line break); found \"{}\"",
                tt_core::human::visible(text)
            ),
        ));
    }
    Ok(())
}

/// Why `name` is not a valid study name, showing it escaped and shortened.
fn name_error(name: &str) -> String {
    let shown: String = tt_core::human::visible(name).chars().take(40).collect();
    let more = if tt_core::human::visible(name).chars().count() > 40 {
        format!("... ({} characters)", name.chars().count())
    } else {
        String::new()
    };
    format!(
        "must be a file-name-safe name (it names the report directory): 1 to {} of the characters A-Z a-z 0-9 . _ -, the first a letter or digit; found \"{shown}\"{more}",
        limits::MAX_NAME_CHARS
    )
}

/// Read a user file (study, tolerances): a regular file of at most
/// [`limits::MAX_FILE_BYTES`], UTF-8, a leading byte-order mark removed.
pub(crate) fn read_text_file(path: &Path, what: &str) -> Result<String, StudyError> {
    let shown = tt_core::human::visible(&path.display().to_string()).into_owned();
    let meta = std::fs::metadata(path)
        .map_err(|e| StudyError::new(&shown, format!("cannot read {what}: {e}")))?;
    if !meta.is_file() {
        return Err(StudyError::new(
            &shown,
            format!("cannot read {what}: not a regular file"),
        ));
    }
    if meta.len() > limits::MAX_FILE_BYTES {
        return Err(StudyError::new(
            &shown,
            format!(
                "cannot read {what}: {} bytes, more than the {} a {what} may have",
                meta.len(),
                limits::MAX_FILE_BYTES
            ),
        ));
    }
    let mut bytes = Vec::new();
    std::fs::File::open(path)
        .and_then(|f| f.take(limits::MAX_FILE_BYTES + 1).read_to_end(&mut bytes))
        .map_err(|e| StudyError::new(&shown, format!("cannot read {what}: {e}")))?;
    if bytes.len() as u64 > limits::MAX_FILE_BYTES {
        return Err(StudyError::new(
            &shown,
            format!("cannot read {what}: file too large"),
        ));
    }
    let text = String::from_utf8(bytes).map_err(|e| {
        StudyError::new(
            &shown,
            format!(
                "{what} is not valid UTF-8 (first bad byte at offset {})",
                e.utf8_error().valid_up_to()
            ),
        )
    })?;
    Ok(text
        .strip_prefix('\u{feff}')
        .map(str::to_string)
        .unwrap_or(text))
}

/// A TOML error as `file:line:column` and a one-line reason.
pub(crate) fn toml_error(source: &str, text: &str, e: &toml::de::Error) -> StudyError {
    let location = match e.span() {
        Some(span) => {
            let before = &text[..span.start.min(text.len())];
            let line = before.matches('\n').count() + 1;
            let column = before.rsplit('\n').next().map_or(0, |l| l.chars().count()) + 1;
            format!("{source}:{line}:{column}")
        }
        None => source.to_string(),
    };
    StudyError::new(
        location,
        format!("invalid {}: {}", "TOML", e.message().trim()),
    )
}

/// Check a number is finite and in `[lo, hi]` (`open_lo`: `(lo, hi]`).
pub(crate) fn in_range(
    at: &dyn Fn(&str) -> String,
    key: &str,
    v: f64,
    lo: f64,
    hi: f64,
    open_lo: bool,
    unit: &str,
) -> Result<f64, StudyError> {
    let ok = v.is_finite() && v <= hi && if open_lo { v > lo } else { v >= lo };
    if ok {
        Ok(v)
    } else {
        let (l, h) = (num(lo), num(hi));
        let range = if open_lo {
            format!("({l}, {h}]")
        } else {
            format!("[{l}, {h}]")
        };
        Err(StudyError::new(
            at(key),
            format!("must lie in {range} {unit}, found {}", exact(v)),
        ))
    }
}

fn axis(at: &dyn Fn(&str) -> String, key: &str, s: &str) -> Result<SignedAxis, StudyError> {
    SignedAxis::parse(s).ok_or_else(|| {
        StudyError::new(
            at(key),
            format!("unknown axis `{s}`; expected x, y, z, -x, -y or -z"),
        )
    })
}

fn count(at: &dyn Fn(&str) -> String, key: &str, c: &Count, max: u64) -> Result<u64, StudyError> {
    let v = match *c {
        Count::Int(i) if i >= 1 => i as u64,
        Count::Float(f) if f.is_finite() && f >= 1.0 && f.fract() == 0.0 && f <= max as f64 => {
            f as u64
        }
        Count::Int(i) => {
            return Err(StudyError::new(
                at(key),
                format!("must be at least 1, found {i}"),
            ));
        }
        Count::Float(f) => {
            return Err(StudyError::new(
                at(key),
                format!("must be a whole number from 1 to {max}, found {}", exact(f)),
            ));
        }
    };
    if v > max {
        return Err(StudyError::new(
            at(key),
            format!("must be at most {max}, found {v}"),
        ));
    }
    Ok(v)
}

impl Study {
    /// Read and validate a study file (a regular UTF-8 file of at most [`limits::MAX_FILE_BYTES`](crate::limits::MAX_FILE_BYTES) bytes).
    ///
    /// # Errors
    /// A [`StudyError`] naming the file (and key) for any problem.
    pub fn load(path: &Path) -> Result<Self, StudyError> {
        let text = read_text_file(path, "study file")?;
        Self::parse(&tt_core::human::visible(&path.display().to_string()), &text)
    }

    /// Parse and validate study text; `source` names it in errors and reports.
    ///
    /// # Errors
    /// A [`StudyError`] naming `source`, the key and the reason.
    pub fn parse(source: &str, text: &str) -> Result<Self, StudyError> {
        let text = text.strip_prefix('\u{feff}').unwrap_or(text);
        let raw: RawStudy = toml::from_str(text).map_err(|e| toml_error(source, text, &e))?;
        let at = |key: &str| format!("{source}: key `{key}`");
        let at: &dyn Fn(&str) -> String = &at;

        if !is_name_slug(&raw.name) {
            return Err(StudyError::new(at("name"), name_error(&raw.name)));
        }
        let turntable = parse_turntable(at, &raw.turntable)?;
        let variations = parse_variations(at, &raw.turntable, &turntable)?;
        let measured = parse_measured(at, raw.compensation.as_ref(), &turntable, &variations)?;
        let site = parse_site(at, &raw.site)?;
        let sensor = parse_sensor(at, &raw.sensor)?;
        let noise = parse_noise(at, &raw.sensor)?;
        let (reading, delta_r_kind) = parse_reading(at, &raw.calibration)?;
        let positions_deg = raw.calibration.positions_deg.clone();
        let max_rate_deg_per_s = parse_max_rates(at, &raw.turntable, &turntable)?;
        let lever_arm_m = parse_lever_arm(at, raw.sensor.lever_arm_m.as_deref())?;
        let static_timing = raw
            .calibration
            .timing
            .as_ref()
            .map(|t| crate::noise::parse_timing(at, t, positions_deg.len()))
            .transpose()?;
        let rate_steps = parse_rate_steps(
            at,
            raw.calibration.rate_steps.as_deref().unwrap_or_default(),
            &turntable,
            &max_rate_deg_per_s,
            static_timing
                .as_ref()
                .map(|t| t.dwell_s().iter().copied().fold(0.0, f64::max)),
        )?;
        if !rate_steps.is_empty() && variations.iter().any(tt_kinematics::ErrorVariation::varies) {
            return Err(StudyError::new(
                at("calibration.rate_steps"),
                "errors that vary with a shaft angle (`turntable.factors[i].varies`) are modelled at static positions only: a rate step takes constant errors",
            ));
        }
        let timing = static_timing
            .map(|t| crate::noise::with_rate_steps(at, t, &rate_steps))
            .transpose()?;
        let calibration = calibration_for(
            at,
            &turntable,
            &sensor,
            &site,
            &positions_deg,
            &RateSchedule {
                steps: &rate_steps,
                lever_arm_m,
            },
        )?;
        let requirement = match &raw.requirement {
            None => RequirementSource::Computed,
            Some(r) => parse_requirement(at, r)?,
        };
        let lower_bounds_rad = parse_lower_bounds(at, raw.allocation.as_ref(), &turntable)?;
        let uncertainty = crate::spec::parse_uncertainty(at, raw.uncertainty.as_ref())?;
        let specifications = crate::spec::parse_specifications(
            at,
            raw.specifications.as_deref().unwrap_or_default(),
            &sensor,
            &uncertainty,
        )?;
        let monte_carlo = MonteCarloSettings {
            samples: count(
                at,
                "monte_carlo.samples",
                &raw.monte_carlo.samples,
                limits::MAX_SAMPLES,
            )?,
            seed: raw.monte_carlo.seed,
        };
        Ok(Self {
            path: source.to_string(),
            text: text.to_string(),
            name: raw.name,
            description: raw.description,
            turntable,
            sensor,
            site,
            reading,
            delta_r_kind,
            positions_deg,
            calibration,
            requirement,
            lower_bounds_rad,
            monte_carlo,
            noise,
            timing,
            measured,
            variations,
            rate_steps,
            lever_arm_m,
            max_rate_deg_per_s,
            uncertainty,
            specifications,
        })
    }

    /// Whether the schedule has a rate step.
    #[must_use]
    pub fn has_rate_steps(&self) -> bool {
        !self.rate_steps.is_empty()
    }

    /// The budgets' context of `specs` (the study's specifications or some of them) for the
    /// table errors `error_names` ([`e2e_verify::EndToEnd::error_names`]): the verdict's law
    /// (`uncertainty.tolerance_distribution`), the study's noise and timing.
    ///
    /// # Errors
    /// The law's error for a unit tolerance.
    pub fn specification_context(
        &self,
        specs: &[gw_model::spec::Specification],
        error_names: &[String],
    ) -> Result<e2e_verify::budget::SpecificationContext, e2e_verify::E2eError> {
        let law = self.uncertainty.tolerance_distribution;
        e2e_verify::budget::SpecificationContext::new(
            specs,
            error_names,
            |n, a| law.input(n, a),
            &self.noise,
            self.timing.as_ref(),
        )
    }

    /// The joint angles (deg) of every schedule entry: the static positions, then where each
    /// rate step starts.
    #[must_use]
    pub fn schedule_angles_deg(&self) -> Vec<Vec<f64>> {
        self.positions_deg
            .iter()
            .cloned()
            .chain(self.rate_steps.iter().map(|r| r.angles_deg.clone()))
            .collect()
    }

    /// The expansion of the turntable's errors into coefficients over the study's schedule
    /// (`turntable.factors[i].varies`; every error constant unless the study says otherwise).
    ///
    /// # Errors
    /// Never for a study that was read (the variations and positions were checked).
    pub fn expansion(&self) -> Result<tt_kinematics::Expansion, StudyError> {
        let poses = self
            .positions_deg
            .iter()
            .map(|p| Pose::from_deg(p))
            .collect::<Result<Vec<_>, _>>()
            .map_err(|e| {
                StudyError::new(
                    format!("{}: key `calibration.positions_deg`", self.path),
                    e.to_string(),
                )
            })?;
        tt_kinematics::Expansion::new(&self.turntable, &self.variations, &poses)
            .map_err(|e| StudyError::new(format!("{}: key `turntable`", self.path), e.to_string()))
    }

    /// Whether any error of the study's turntable varies with a shaft angle.
    #[must_use]
    pub fn has_angle_dependent_errors(&self) -> bool {
        self.variations
            .iter()
            .any(tt_kinematics::ErrorVariation::varies)
    }

    /// The calibration schedule.
    #[must_use]
    pub fn schedule(&self) -> &Schedule {
        self.calibration.schedule()
    }

    /// The same study with other test positions (joint angles, deg), validated as the file's
    /// would be (count per position, ranges, identifiability), named `calibration.positions_deg`.
    /// A timing with one dwell for every position carries over to any number of positions; a
    /// per-position dwell list only to as many positions as it has values. The rate steps'
    /// windows are their turning times at the steps' current rates and revolutions.
    ///
    /// # Errors
    /// A [`StudyError`] naming the position and the reason, or
    /// `calibration.timing.dwell_s` when its list does not fit the new count.
    pub fn with_positions_deg(&self, positions_deg: Vec<Vec<f64>>) -> Result<Self, StudyError> {
        let at = |key: &str| format!("{}: key `{key}`", self.path);
        let calibration = calibration_for(
            &at,
            &self.turntable,
            &self.sensor,
            &self.site,
            &positions_deg,
            &RateSchedule {
                steps: &self.rate_steps,
                lever_arm_m: self.lever_arm_m,
            },
        )?;
        let n = positions_deg.len();
        let timing = match &self.timing {
            Some(t) if t.positions() != n => Some(t.with_len(n).ok_or_else(|| {
                StudyError::new(
                    at("calibration.timing.dwell_s"),
                    format!(
                        "one dwell per position: {} values, but the new schedule has {n} positions (give one number for all)",
                        t.positions()
                    ),
                )
            })?),
            other => other.clone(),
        };
        // the rate steps' windows from the steps as they are now (a caller may change a rate)
        let timing = timing
            .map(|t| crate::noise::with_rate_steps(&at, t, &self.rate_steps))
            .transpose()?;
        Ok(Self {
            positions_deg,
            calibration,
            timing,
            ..self.clone()
        })
    }

    /// The study's text with `calibration.positions_deg` replaced by `positions_deg` (every
    /// comment and every other value kept, the comment lines above the key included) and
    /// `comment` (lines without `#`) placed right above it.
    ///
    /// # Errors
    /// A [`StudyError`] if the text no longer parses (it was parsed when loaded), or naming
    /// `calibration.timing.dwell_s` when it is a per-position list of another length.
    pub fn text_with_positions(
        &self,
        positions_deg: &[Vec<f64>],
        comment: &str,
    ) -> Result<String, StudyError> {
        self.text_with(positions_deg, None, comment)
    }

    /// The study's text with `calibration.positions_deg` replaced by `positions_deg` and
    /// `calibration.timing.dwell_s` by the one number `dwell_s` (s, the same dwell at every
    /// position), every comment and every other value kept (the comments above and beside
    /// `dwell_s` included), `comment` placed above the positions as in
    /// [`Study::text_with_positions`]. A per-position dwell list of any length is replaced.
    ///
    /// # Errors
    /// A [`StudyError`] naming `calibration.timing` when the study has no timing, or
    /// `calibration.timing.dwell_s` when `dwell_s` is outside [`crate::limits::DWELL_S`]; one
    /// naming the file if the text no longer parses.
    pub fn text_with_dwell(
        &self,
        positions_deg: &[Vec<f64>],
        dwell_s: f64,
        comment: &str,
    ) -> Result<String, StudyError> {
        let (lo, hi) = crate::limits::DWELL_S;
        if !(dwell_s.is_finite() && dwell_s > lo && dwell_s <= hi) {
            return Err(StudyError::new(
                format!("{}: key `calibration.timing.dwell_s`", self.path),
                format!("{dwell_s} s is outside ({lo}, {hi}] s"),
            ));
        }
        if self.timing.is_none() {
            return Err(StudyError::new(
                format!("{}: key `calibration.timing`", self.path),
                "the study has no [calibration.timing] to write a dwell into",
            ));
        }
        self.text_with(positions_deg, Some(dwell_s), comment)
    }

    fn text_with(
        &self,
        positions_deg: &[Vec<f64>],
        dwell_s: Option<f64>,
        comment: &str,
    ) -> Result<String, StudyError> {
        let mut doc: toml_edit::DocumentMut = self
            .text
            .parse()
            .map_err(|e: toml_edit::TomlError| StudyError::new(&self.path, e.to_string()))?;
        let mut array = toml_edit::Array::new();
        for p in positions_deg {
            let mut row = toml_edit::Array::new();
            for &a in p {
                row.push(a);
            }
            row.decor_mut().set_prefix("\n  ");
            array.push_formatted(toml_edit::Value::Array(row));
        }
        array.set_trailing("\n");
        array.set_trailing_comma(true);
        let calibration = doc
            .get_mut("calibration")
            .and_then(|c| c.as_table_like_mut())
            .ok_or_else(|| StudyError::new(&self.path, "no [calibration] table"))?;
        if let Some(t) = dwell_s {
            let timing = calibration
                .get_mut("timing")
                .and_then(|t| t.as_table_like_mut())
                .ok_or_else(|| {
                    StudyError::new(
                        format!("{}: key `calibration.timing`", self.path),
                        "no [calibration.timing] table",
                    )
                })?;
            // the new value keeps the old one's comments (before and after it)
            let decor = timing
                .get("dwell_s")
                .and_then(|d| d.as_value())
                .map(|v| v.decor().clone());
            let mut value = toml_edit::Value::from(t);
            if let Some(d) = decor {
                *value.decor_mut() = d;
            }
            timing.insert("dwell_s", toml_edit::Item::Value(value));
        } else if let Some(list) = calibration
            .get("timing")
            .and_then(|t| t.get("dwell_s"))
            .and_then(|d| d.as_array())
            .filter(|a| a.len() != positions_deg.len())
        {
            return Err(StudyError::new(
                format!("{}: key `calibration.timing.dwell_s`", self.path),
                format!(
                    "one dwell per position: {} values, but the new schedule has {} positions (give one number for all)",
                    list.len(),
                    positions_deg.len()
                ),
            ));
        }
        let before = calibration
            .key("positions_deg")
            .and_then(|k| k.leaf_decor().prefix())
            .and_then(|p| p.as_str())
            .unwrap_or_default()
            .to_string();
        calibration.insert("positions_deg", toml_edit::value(array));
        if let Some(mut key) = calibration.key_mut("positions_deg") {
            let lines: String = comment.lines().map(|l| format!("# {l}\n")).collect();
            key.leaf_decor_mut().set_prefix(format!("{before}{lines}"));
        }
        Ok(doc.to_string())
    }
}

fn parse_turntable(
    at: &dyn Fn(&str) -> String,
    raw: &RawTurntable,
) -> Result<Turntable, StudyError> {
    let mut factors = Vec::with_capacity(raw.factors.len());
    for (i, f) in raw.factors.iter().enumerate() {
        let key = |k: &str| format!("turntable.factors[{i}]{k}");
        let present: Vec<&str> = [
            ("joint", f.joint.is_some()),
            ("error", f.error.is_some()),
            ("fixed_deg", f.fixed_deg.is_some()),
        ]
        .into_iter()
        .filter_map(|(n, p)| p.then_some(n))
        .collect();
        let kind = match present.as_slice() {
            [one] => *one,
            [] => {
                return Err(StudyError::new(
                    at(&key("")),
                    "a factor needs one of `joint`, `error` or `fixed_deg`",
                ));
            }
            many => {
                return Err(StudyError::new(
                    at(&key("")),
                    format!(
                        "a factor has exactly one of `joint`, `error`, `fixed_deg`; found {}",
                        many.join(", ")
                    ),
                ));
            }
        };
        let spec = match (kind, &f.about, &f.along) {
            (_, Some(_), Some(_)) => {
                return Err(StudyError::new(
                    at(&key("")),
                    "a factor has `about` (rotation) or `along` (translation), not both",
                ));
            }
            ("joint", Some(a), None) => FactorSpec::Joint {
                name: f.joint.clone().unwrap_or_default(),
                about: axis(at, &key(".about"), a)?,
            },
            ("error", Some(a), None) => FactorSpec::Error {
                name: f.error.clone().unwrap_or_default(),
                about: axis(at, &key(".about"), a)?,
            },
            ("error", None, Some(a)) => FactorSpec::Translation {
                name: f.error.clone().unwrap_or_default(),
                along: axis(at, &key(".along"), a)?,
            },
            ("fixed_deg", Some(a), None) => {
                let deg = in_range(
                    at,
                    &key(".fixed_deg"),
                    f.fixed_deg.unwrap_or(f64::NAN),
                    -limits::ANGLE_ABS_MAX_DEG,
                    limits::ANGLE_ABS_MAX_DEG,
                    false,
                    "deg",
                )?;
                FactorSpec::Fixed {
                    angle_rad: deg * RAD_PER_DEG,
                    about: axis(at, &key(".about"), a)?,
                }
            }
            ("joint" | "fixed_deg", None, Some(_)) => {
                return Err(StudyError::new(
                    at(&key(".along")),
                    format!("a `{kind}` rotates: give `about`, not `along`"),
                ));
            }
            (_, None, None) => {
                return Err(StudyError::new(
                    at(&key("")),
                    format!(
                        "a `{kind}` factor needs `about` (or `along` for an error translation)"
                    ),
                ));
            }
            _ => unreachable!("every combination is matched"),
        };
        factors.push(spec);
    }
    let mut joint_ranges_rad = Vec::new();
    for (name, r) in raw.joint_ranges_deg.iter().flatten() {
        let key = format!("turntable.joint_ranges_deg.{name}");
        let [lo, hi] = r.as_slice() else {
            return Err(StudyError::new(
                at(&key),
                format!("a range is [min, max], found {} numbers", r.len()),
            ));
        };
        let m = limits::ANGLE_ABS_MAX_DEG;
        in_range(at, &key, *lo, -m, m, false, "deg")?;
        in_range(at, &key, *hi, -m, m, false, "deg")?;
        joint_ranges_rad.push((name.clone(), [lo * RAD_PER_DEG, hi * RAD_PER_DEG]));
    }
    for (name, text) in raw.descriptions.iter().flatten() {
        one_line(at, &format!("turntable.descriptions.{name}"), text)?;
    }
    let description = TurntableDescription {
        factors,
        error_order: raw.error_order.clone(),
        joint_ranges_rad,
        descriptions: raw
            .descriptions
            .iter()
            .flatten()
            .map(|(k, v)| (k.clone(), v.clone()))
            .collect(),
    };
    Turntable::new(&description).map_err(|e| match e {
        KinematicsError::Description { key, reason } => {
            StudyError::new(at(&format!("turntable.{key}")), reason)
        }
        other => StudyError::new(at("turntable"), other.to_string()),
    })
}

/// The measured errors of `[[compensation.measured]]` (order of $\chi$).
fn parse_measured(
    at: &dyn Fn(&str) -> String,
    raw: Option<&RawCompensation>,
    turntable: &Turntable,
    variations: &[ErrorVariation],
) -> Result<Vec<Option<Measured>>, StudyError> {
    let mut out = vec![None; turntable.n_rotation_errors()];
    let Some(raw) = raw else {
        return Ok(out);
    };
    let (lo, hi) = limits::ANGLE_TOLERANCE_ARCMIN;
    for (k, m) in raw.measured.iter().enumerate() {
        let key = |s: &str| format!("compensation.measured[{k}].{s}");
        let Some(i) = turntable.rotation_error_index(&m.error) else {
            return Err(StudyError::new(
                at(&key("error")),
                format!(
                    "`{}` is not an angular error of the turntable ({})",
                    tt_core::human::visible(&m.error),
                    turntable.rotation_error_names().join(", ")
                ),
            ));
        };
        if out[i].is_some() {
            return Err(StudyError::new(
                at(&key("error")),
                format!("`{}` is measured twice", m.error),
            ));
        }
        let n = match &variations[i] {
            ErrorVariation::Constant => 1,
            ErrorVariation::Harmonics { orders, .. } => 1 + 2 * orders.len(),
            ErrorVariation::Any { .. } => {
                return Err(StudyError::new(
                    at(&key("error")),
                    format!(
                        "`{}` varies as any function of the angle: a measurement gives it as a constant or as harmonics",
                        m.error
                    ),
                ));
            }
        };
        let values: Vec<(String, f64)> = match (&m.value_arcmin, &m.coefficients_arcmin) {
            (Some(v), None) if n == 1 => vec![(key("value_arcmin"), *v)],
            (None, Some(c)) if c.len() == n => c
                .iter()
                .enumerate()
                .map(|(j, v)| (key(&format!("coefficients_arcmin[{j}]")), *v))
                .collect(),
            (None, Some(c)) => {
                return Err(StudyError::new(
                    at(&key("coefficients_arcmin")),
                    format!(
                        "`{}` has {n} coefficients in the study's model (c0, a_k, b_k per order), found {}",
                        m.error,
                        c.len()
                    ),
                ));
            }
            (Some(_), None) => {
                return Err(StudyError::new(
                    at(&key("value_arcmin")),
                    format!(
                        "`{}` varies with the shaft angle: give its {n} `coefficients_arcmin` (c0, a_k, b_k per order)",
                        m.error
                    ),
                ));
            }
            _ => {
                return Err(StudyError::new(
                    at(&key("value_arcmin")),
                    "give one of `value_arcmin` (a constant error) or `coefficients_arcmin` (harmonics)",
                ));
            }
        };
        let value_key = if m.value_arcmin.is_some() {
            key("value_arcmin")
        } else {
            key("coefficients_arcmin")
        };
        let written_arcmin: Vec<f64> = values.iter().map(|(_, v)| *v).collect();
        let mut coefficients_rad = Vec::with_capacity(n);
        for (vkey, v) in values {
            coefficients_rad
                .push(in_range(at, &vkey, v, -hi, hi, false, "arcmin")? * RAD_PER_ARCMIN);
        }
        let uncertainty_rad = in_range(
            at,
            &key("uncertainty_arcmin"),
            m.uncertainty_arcmin,
            lo,
            hi,
            false,
            "arcmin",
        )? * RAD_PER_ARCMIN;
        out[i] = Some(Measured {
            coefficients_rad,
            uncertainty_rad,
            key: value_key,
            written_arcmin,
            uncertainty_arcmin: m.uncertainty_arcmin,
        });
    }
    Ok(out)
}

/// The error model of each angular error (order of $\chi$): `varies = "constant"` (the
/// default), `"harmonics"` (the default when `harmonics` is given) with `harmonics = [1, 2]`
/// and `of = "<joint>"`, or `"any"` with `of`.
fn parse_variations(
    at: &dyn Fn(&str) -> String,
    raw: &RawTurntable,
    turntable: &Turntable,
) -> Result<Vec<ErrorVariation>, StudyError> {
    let mut by_factor = vec![ErrorVariation::Constant; raw.factors.len()];
    for (i, f) in raw.factors.iter().enumerate() {
        let key = |k: &str| format!("turntable.factors[{i}].{k}");
        if f.varies.is_none() && f.of.is_none() && f.harmonics.is_none() {
            continue;
        }
        let first = [
            ("varies", f.varies.is_some()),
            ("of", f.of.is_some()),
            ("harmonics", f.harmonics.is_some()),
        ]
        .into_iter()
        .find_map(|(k, p)| p.then_some(k))
        .unwrap_or("varies");
        if f.error.is_none() || f.about.is_none() {
            return Err(StudyError::new(
                at(&key(first)),
                "only an angular error (`error` with `about`) can vary with a shaft angle",
            ));
        }
        let varies = f.varies.as_deref().unwrap_or(if f.harmonics.is_some() {
            "harmonics"
        } else {
            "constant"
        });
        let joint = || {
            f.of.clone().ok_or_else(|| {
                StudyError::new(
                    at(&key("of")),
                    format!("`varies = \"{varies}\"` needs `of`, the joint whose angle the error follows"),
                )
            })
        };
        let v = match varies {
            "constant" => {
                if let Some(k) = [("of", f.of.is_some()), ("harmonics", f.harmonics.is_some())]
                    .into_iter()
                    .find_map(|(k, p)| p.then_some(k))
                {
                    return Err(StudyError::new(
                        at(&key(k)),
                        "a constant error follows no joint: remove it or set `varies`",
                    ));
                }
                ErrorVariation::Constant
            }
            "harmonics" => {
                let Some(list) = &f.harmonics else {
                    return Err(StudyError::new(
                        at(&key("harmonics")),
                        "`varies = \"harmonics\"` needs `harmonics = [1, 2, ...]` (the orders; [] for the constant term only)",
                    ));
                };
                let mut orders = Vec::with_capacity(list.len());
                for (k, &o) in list.iter().enumerate() {
                    let hk = key(&format!("harmonics[{k}]"));
                    let max = f64::from(tt_kinematics::variation::MAX_HARMONIC_ORDER);
                    if !(o.is_finite() && o.fract() == 0.0 && (1.0..=max).contains(&o)) {
                        return Err(StudyError::new(
                            at(&hk),
                            format!(
                                "a harmonic order is a positive integer up to {max}, found {o:?}"
                            ),
                        ));
                    }
                    orders.push(o as u32);
                }
                ErrorVariation::Harmonics {
                    joint: joint()?,
                    orders,
                }
            }
            "any" => {
                if f.harmonics.is_some() {
                    return Err(StudyError::new(
                        at(&key("harmonics")),
                        "`varies = \"any\"` takes no harmonic orders (one free value per angle)",
                    ));
                }
                ErrorVariation::Any { joint: joint()? }
            }
            other => {
                return Err(StudyError::new(
                    at(&key("varies")),
                    format!(
                        "must be \"constant\", \"harmonics\" or \"any\", found \"{}\"",
                        tt_core::human::visible(other)
                    ),
                ));
            }
        };
        by_factor[i] = v;
    }
    let variations: Vec<ErrorVariation> = turntable
        .rotation_errors()
        .iter()
        .map(|e| by_factor[e.factor].clone())
        .collect();
    tt_kinematics::validate_variations(turntable, &variations).map_err(|e| match e {
        KinematicsError::Description { key, reason } => {
            StudyError::new(at(&format!("turntable.{key}")), reason)
        }
        other => StudyError::new(at("turntable"), other.to_string()),
    })?;
    Ok(variations)
}

fn parse_sensor(at: &dyn Fn(&str) -> String, raw: &RawSensor) -> Result<SensorModel, StudyError> {
    let mut outputs = Vec::with_capacity(raw.outputs.len());
    for (k, o) in raw.outputs.iter().enumerate() {
        let key = |s: &str| format!("sensor.outputs[{k}].{s}");
        one_line(at, &key("unit"), &o.unit)?;
        let (lo, hi) = limits::ACCURACY;
        in_range(
            at,
            &key("accuracy"),
            o.accuracy,
            lo,
            hi,
            false,
            &format!("({})", o.unit),
        )?;
        let mut terms = Vec::with_capacity(o.terms.len());
        for (t, term) in o.terms.iter().enumerate() {
            let tkey = |s: &str| format!("sensor.outputs[{k}].terms[{t}].{s}");
            let regressor = Regressor::parse(&term.regressor)
                .map_err(|e| StudyError::new(at(&tkey("regressor")), e))?;
            let m = limits::COEFFICIENT_ABS_MAX;
            in_range(
                at,
                &tkey("value"),
                term.value,
                -m,
                m,
                false,
                "(output unit per regressor unit)",
            )?;
            terms.push(Term {
                coefficient: term.coefficient.clone(),
                regressor,
                value: term.value,
                known: term.known.unwrap_or(false),
            });
        }
        outputs.push(Output {
            name: o.name.clone(),
            unit: o.unit.clone(),
            accuracy: o.accuracy,
            terms,
        });
    }
    let sensor = SensorModel::new(outputs).map_err(|e| match e {
        gw_model::ModelError::Sensor { key, reason } => {
            StudyError::new(at(&format!("sensor.{key}")), reason)
        }
        other => StudyError::new(at("sensor"), other.to_string()),
    })?;
    // derived column names must be unique (calibration-error prints one column each)
    let columns = crate::csv::calibration_error_columns(&sensor);
    for (i, (col, key)) in columns.iter().enumerate() {
        if let Some((_, first)) = columns[..i].iter().find(|(c, _)| c == col) {
            return Err(StudyError::new(
                at(key),
                format!(
                    "gives the column `{col}` of calibration-error, as does `{first}`: rename one of them"
                ),
            ));
        }
    }
    Ok(sensor)
}

fn parse_requirement(
    at: &dyn Fn(&str) -> String,
    r: &RawRequirement,
) -> Result<RequirementSource, StudyError> {
    let values = [
        ("psi_deg", r.psi_deg),
        ("theta_deg", r.theta_deg),
        ("gamma_deg", r.gamma_deg),
    ];
    let given: Vec<&str> = values
        .iter()
        .filter(|(_, v)| v.is_some())
        .map(|(n, _)| *n)
        .collect();
    match r.source.as_deref() {
        Some("computed") | None if given.is_empty() => Ok(RequirementSource::Computed),
        Some("computed") => Err(StudyError::new(
            at("requirement.source"),
            format!(
                "\"computed\" takes no values, but {} given: remove them or write source = \"given\"",
                given.join(", ")
            ),
        )),
        Some("given") | None => {
            let mut rad = [0.0; 3];
            for (slot, (name, v)) in rad.iter_mut().zip(values) {
                let key = format!("requirement.{name}");
                let v = v.ok_or_else(|| {
                    StudyError::new(
                        at(&key),
                        "missing: a given requirement needs psi_deg, theta_deg and gamma_deg",
                    )
                })?;
                let (lo, hi) = limits::REQUIREMENT_DEG;
                *slot = in_range(at, &key, v, lo, hi, false, "deg")? * RAD_PER_DEG;
            }
            Ok(RequirementSource::Given { rad })
        }
        Some(other) => Err(StudyError::new(
            at("requirement.source"),
            format!("must be \"computed\" or \"given\", found \"{other}\""),
        )),
    }
}

/// The rate steps a schedule appends to its static positions.
struct RateSchedule<'a> {
    steps: &'a [StudyRateStep],
    lever_arm_m: [f64; 3],
}

/// Each joint's rate limit, `turntable.max_rate_deg_per_s.<joint>`.
fn parse_max_rates(
    at: &dyn Fn(&str) -> String,
    raw: &RawTurntable,
    turntable: &Turntable,
) -> Result<Vec<Option<f64>>, StudyError> {
    let mut out = vec![None; turntable.n_joints()];
    for (name, &v) in raw.max_rate_deg_per_s.iter().flatten() {
        let key = format!("turntable.max_rate_deg_per_s.{name}");
        let Some(j) = turntable.joint_index(name) else {
            return Err(StudyError::new(
                at(&key),
                format!("`{name}` is not a joint of the turntable"),
            ));
        };
        let (lo, hi) = limits::MAX_RATE_DEG_PER_S;
        out[j] = Some(in_range(at, &key, v, lo, hi, true, "deg/s")?);
    }
    Ok(out)
}

/// `[site]`: the latitude and the earth rate, checked.
fn parse_site(at: &dyn Fn(&str) -> String, raw: &RawSite) -> Result<Site, StudyError> {
    Site::from_deg(
        in_range(
            at,
            "site.latitude_deg",
            raw.latitude_deg,
            limits::LATITUDE_DEG.0,
            limits::LATITUDE_DEG.1,
            false,
            "deg",
        )?,
        in_range(
            at,
            "site.earth_rate_rad_per_s",
            raw.earth_rate_rad_per_s,
            limits::EARTH_RATE_RAD_PER_S.0,
            limits::EARTH_RATE_RAD_PER_S.1,
            false,
            "rad/s",
        )?,
    )
    .map_err(|e| StudyError::new(at("site"), e.to_string()))
}

/// Each output's `[sensor.outputs.noise]`, if given.
fn parse_noise(
    at: &dyn Fn(&str) -> String,
    raw: &RawSensor,
) -> Result<Vec<Option<gw_model::noise::NoiseModel>>, StudyError> {
    raw.outputs
        .iter()
        .enumerate()
        .map(|(k, o)| {
            o.noise
                .as_ref()
                .map(|n| crate::noise::parse_output_noise(at, k, &o.unit, n))
                .transpose()
        })
        .collect()
}

/// `calibration.reading` and `calibration.delta_r` (their defaults when not given).
fn parse_reading(
    at: &dyn Fn(&str) -> String,
    raw: &RawCalibration,
) -> Result<(Reading, DeltaRKind), StudyError> {
    let reading_text = raw.reading.as_deref().unwrap_or(DEFAULT_READING);
    let reading: Reading = reading_text.parse().map_err(|e: calib_lsq::CalibError| {
        StudyError::new(at("calibration.reading"), e.to_string())
    })?;
    let delta_r_kind = match raw.delta_r.as_deref().unwrap_or(DEFAULT_DELTA_R) {
        "small-angle" => DeltaRKind::SmallAngle,
        "exact" => DeltaRKind::Exact,
        other => {
            return Err(StudyError::new(
                at("calibration.delta_r"),
                format!("must be \"small-angle\" or \"exact\", found \"{other}\""),
            ));
        }
    };
    Ok((reading, delta_r_kind))
}

/// `allocation.lower_bounds_arcmin`, rad, in the turntable's order (zero when not given).
fn parse_lower_bounds(
    at: &dyn Fn(&str) -> String,
    raw: Option<&RawAllocation>,
    turntable: &Turntable,
) -> Result<Vec<f64>, StudyError> {
    let mut lower_bounds_rad = vec![0.0; turntable.n_rotation_errors()];
    for (name, &v) in raw
        .and_then(|a| a.lower_bounds_arcmin.as_ref())
        .into_iter()
        .flatten()
    {
        let key = format!("allocation.lower_bounds_arcmin.{name}");
        let Some(i) = turntable.rotation_error_index(name) else {
            let why = if turntable.translation_error_names().contains(&name.as_str()) {
                format!(
                    "`{name}` is a translation: it has no effect on the orientation and gets no bound"
                )
            } else {
                format!("`{name}` is not an angular error of the turntable")
            };
            return Err(StudyError::new(at(&key), why));
        };
        let (lo, hi) = limits::ANGLE_TOLERANCE_ARCMIN;
        lower_bounds_rad[i] = in_range(at, &key, v, lo, hi, false, "arcmin")? * RAD_PER_ARCMIN;
    }
    Ok(lower_bounds_rad)
}

/// `sensor.lever_arm_m`: three components, m (zero when not given).
fn parse_lever_arm(
    at: &dyn Fn(&str) -> String,
    raw: Option<&[f64]>,
) -> Result<[f64; 3], StudyError> {
    let Some(v) = raw else {
        return Ok([0.0; 3]);
    };
    let [x, y, z] = v else {
        return Err(StudyError::new(
            at("sensor.lever_arm_m"),
            format!(
                "a lever arm is [x, y, z] in the platform frame, found {} numbers",
                v.len()
            ),
        ));
    };
    let m = limits::LEVER_ARM_ABS_MAX_M;
    let mut out = [0.0; 3];
    for (k, (o, c)) in out.iter_mut().zip([x, y, z]).enumerate() {
        *o = in_range(
            at,
            &format!("sensor.lever_arm_m[{k}]"),
            *c,
            -m,
            m,
            false,
            "m",
        )?;
    }
    Ok(out)
}

/// `[[calibration.rate_steps]]`: a joint of the turntable with a rate limit, a non-zero rate
/// within it, one angle per joint, a whole number of revolutions.
fn parse_rate_steps(
    at: &dyn Fn(&str) -> String,
    raw: &[RawRateStep],
    turntable: &Turntable,
    max_rates: &[Option<f64>],
    dwell_s: Option<f64>,
) -> Result<Vec<StudyRateStep>, StudyError> {
    let names = turntable.joint_names();
    raw.iter()
        .enumerate()
        .map(|(i, r)| {
            let key = |k: &str| format!("calibration.rate_steps[{i}].{k}");
            let Some(joint) = turntable.joint_index(&r.joint) else {
                return Err(StudyError::new(
                    at(&key("joint")),
                    format!(
                        "`{}` is not a joint of the turntable (joints: {})",
                        r.joint,
                        names.join(", ")
                    ),
                ));
            };
            let Some(limit) = max_rates[joint] else {
                return Err(StudyError::new(
                    at(&key("joint")),
                    format!(
                        "joint `{}` has no rate limit: give `turntable.max_rate_deg_per_s.{}`",
                        r.joint, r.joint
                    ),
                ));
            };
            let rate = r.rate_deg_per_s;
            let min = limits::MIN_RATE_STEP_DEG_PER_S;
            if !rate.is_finite() || rate.abs() < min || rate.abs() > limit {
                return Err(StudyError::new(
                    at(&key("rate_deg_per_s")),
                    format!(
                        "must have {} <= |rate| <= {} deg/s (the least rate that turns a revolution in a test's time; the rate limit of `{}`), found {}",
                        num(min),
                        exact(limit),
                        r.joint,
                        exact(rate)
                    ),
                ));
            }
            let revs = match (r.revolutions, dwell_s) {
                (Some(n), _) => n,
                (None, Some(t)) => default_revolutions(rate, t) as f64,
                (None, None) => {
                    return Err(StudyError::new(
                        at(&key("revolutions")),
                        "missing: give the whole revolutions the step turns (they may be left out only with a [calibration.timing], whose longest dwell sets them)",
                    ));
                }
            };
            if !(revs.is_finite()
                && revs >= 1.0
                && revs.fract() == 0.0
                && revs <= limits::MAX_REVOLUTIONS as f64)
            {
                return Err(StudyError::new(
                    at(&key("revolutions")),
                    format!(
                        "must be a whole number of revolutions from 1 to {} (the averages are over whole revolutions), found {}",
                        limits::MAX_REVOLUTIONS,
                        exact(revs)
                    ),
                ));
            }
            if r.angles_deg.len() != turntable.n_joints() {
                return Err(StudyError::new(
                    at(&key("angles_deg")),
                    format!(
                        "one angle per joint ({}: {}; the turning joint's is where it starts), found {} numbers",
                        turntable.n_joints(),
                        names.join(", "),
                        r.angles_deg.len()
                    ),
                ));
            }
            Ok(StudyRateStep {
                joint,
                rate_deg_per_s: rate,
                angles_deg: r.angles_deg.clone(),
                revolutions: revs as u32,
            })
        })
        .collect()
}

/// Validate positions against the turntable and build the calibration (the static positions,
/// then the rate steps).
fn calibration_for(
    at: &dyn Fn(&str) -> String,
    turntable: &Turntable,
    sensor: &SensorModel,
    site: &Site,
    positions_deg: &[Vec<f64>],
    rates: &RateSchedule<'_>,
) -> Result<Calibration, StudyError> {
    if positions_deg.is_empty() {
        return Err(StudyError::new(
            at("calibration.positions_deg"),
            "no test position",
        ));
    }
    if positions_deg.len() + rates.steps.len() > limits::MAX_POSITIONS {
        return Err(StudyError::new(
            at("calibration.positions_deg"),
            format!(
                "{} test positions and rate steps; at most {} are accepted (a calibration schedule has tens to hundreds)",
                positions_deg.len() + rates.steps.len(),
                limits::MAX_POSITIONS
            ),
        ));
    }
    let ranges = turntable.joint_ranges_rad();
    let names = turntable.joint_names();
    let mut positions = Vec::with_capacity(positions_deg.len() + rates.steps.len());
    let entries = positions_deg
        .iter()
        .map(|p| (p, None))
        .chain(rates.steps.iter().map(|r| (&r.angles_deg, Some(r))));
    for (i, (p, rate)) in entries.enumerate() {
        let key = match rate {
            None => format!("calibration.positions_deg[{i}]"),
            Some(_) => format!(
                "calibration.rate_steps[{}].angles_deg",
                i - positions_deg.len()
            ),
        };
        if p.len() != turntable.n_joints() {
            return Err(StudyError::new(
                at(&key),
                format!(
                    "a position has one angle per joint ({}: {}), found {} numbers",
                    turntable.n_joints(),
                    names.join(", "),
                    p.len()
                ),
            ));
        }
        for (j, &a) in p.iter().enumerate() {
            let key = format!("{key}[{j}]");
            let m = limits::ANGLE_ABS_MAX_DEG;
            in_range(at, &key, a, -m, m, false, "deg")?;
            let [lo, hi] = ranges[j];
            let r = a * RAD_PER_DEG;
            if r < lo - 1e-12 || r > hi + 1e-12 {
                return Err(StudyError::new(
                    at(&key),
                    format!(
                        "{} = {a} deg is outside the joint's range [{}, {}] deg",
                        names[j],
                        lo / RAD_PER_DEG,
                        hi / RAD_PER_DEG
                    ),
                ));
            }
        }
        let pose = Pose::from_deg(p).map_err(|e| StudyError::new(at(&key), e.to_string()))?;
        let rd = turntable
            .nominal_rotation(&pose)
            .map_err(|e| StudyError::new(at(&key), e.to_string()))?;
        let position = match rate {
            None => Position::new(rd, p.clone()),
            Some(r) => {
                let step = tt_kinematics::RateStep {
                    joint: r.joint,
                    rate_rad_per_s: r.rate_deg_per_s * RAD_PER_DEG,
                    pose,
                    revolutions: r.revolutions,
                };
                let env = tt_kinematics::RateEnvironment {
                    specific_force_base_g: site.specific_force_base_g(),
                    earth_rate_base_rad_per_s: site.earth_rate_base_rad_per_s(),
                    lever_arm_m: rates.lever_arm_m.into(),
                };
                let avg = turntable
                    .rate_step_average(
                        &step,
                        &turntable.zero_errors(),
                        &tt_kinematics::RateErrorValues::default(),
                        &env,
                    )
                    .map_err(|e| StudyError::new(at(&key), e.to_string()))?;
                Position::rate_step(
                    rd,
                    p.clone(),
                    calib_lsq::RateMotion {
                        joint: r.joint,
                        rate_rad_per_s: step.rate_rad_per_s,
                        revolutions: r.revolutions,
                        lever_arm_m: rates.lever_arm_m,
                        nominal: gw_model::Inputs {
                            specific_force_g: avg.specific_force_g,
                            rate_rad_per_s: avg.rate_rad_per_s,
                        },
                    },
                )
            }
        };
        positions.push(position.map_err(|e| StudyError::new(at(&key), e.to_string()))?);
    }
    let schedule = Schedule::new(positions)
        .map_err(|e| StudyError::new(at("calibration.positions_deg"), e.to_string()))?;
    Calibration::new(sensor, site, &schedule)
        .map_err(|e| StudyError::new(at("calibration.positions_deg"), e.to_string()))
}
