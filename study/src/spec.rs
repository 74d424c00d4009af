//! The specification keys of a study: `[uncertainty]` and `[[specifications]]`, parsed
//! strictly into [`Uncertainty`] and [`gw_model::spec::Specification`].
//!
//! ```toml
//! [uncertainty]                         # optional
//! coverage = 0.95                       # default coverage probability, in (0, 1)
//! tolerance_distribution = "rectangular" # law of a tolerance: rectangular, triangular, arcsine
//!
//! [[specifications]]
//! output = "gx"
//! coefficient = "bg_x"                  # an estimated coefficient of the output ...
//! limit = 0.05
//! unit = "deg_per_h"                    # a bias: a unit of the output's family
//!
//! [[specifications]]
//! output = "gx"
//! quantity = "error_over_range"         # ... or the error at +-range along the sensitive axis
//! range = 300
//! range_unit = "deg/s"
//! limit = 0.5
//! unit = "deg_per_h"
//! coverage = 0.99                       # optional, else [uncertainty].coverage
//!
//! [[specifications]]
//! output = "gx"
//! quantity = "accuracy"                 # ... or eq 14's error at every test position
//! limit = 0.1
//! unit = "deg_per_h"
//! ```
//!
//! Units per kind of coefficient: see [`gw_model::spec`] (bias: deg_per_h, mg, ug, ...;
//! scale factor: ppm, %; misalignment: arcsec, urad, mrad; g-sensitivity: deg_per_h_per_g).

use crate::error::StudyError;
use gw_model::SensorModel;
use gw_model::spec::{Quantity, Specification};
use serde::Deserialize;
use tt_core::human::{exact, visible};

/// `[uncertainty]` as written.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawUncertainty {
    coverage: Option<f64>,
    tolerance_distribution: Option<String>,
}

/// `[[specifications]]` as written.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawSpecification {
    output: String,
    coefficient: Option<String>,
    quantity: Option<String>,
    limit: f64,
    unit: String,
    coverage: Option<f64>,
    range: Option<f64>,
    range_unit: Option<String>,
}

/// The law of a turntable error known by its tolerance $\pm a$ only (type B).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum ToleranceDistribution {
    /// Uniform on $[-a, a]$: $u = a/\sqrt3$ (JCGM 100 4.3.7), the default.
    #[default]
    Rectangular,
    /// Triangular on $[-a, a]$: $u = a/\sqrt6$ (JCGM 100 4.3.9).
    Triangular,
    /// Arcsine (U-shaped) on $[-a, a]$: $u = a/\sqrt2$ (a sinusoid of unknown phase).
    Arcsine,
}

impl ToleranceDistribution {
    /// The names accepted in `tolerance_distribution`.
    pub const NAMES: [&'static str; 3] = ["rectangular", "triangular", "arcsine"];

    /// The input quantity `name` of tolerance $\pm$`a` (>= 0) with this law, estimate 0.
    ///
    /// # Errors
    /// `NAME.half_width` or `NAME.amplitude` when `a` is negative or not finite.
    pub fn input(self, name: &str, a: f64) -> Result<metrology::Input, metrology::MetrologyError> {
        match self {
            ToleranceDistribution::Rectangular => metrology::Input::rectangular(name, 0.0, a),
            ToleranceDistribution::Triangular => metrology::Input::triangular(name, 0.0, a),
            ToleranceDistribution::Arcsine => metrology::Input::arcsine(name, 0.0, a),
        }
    }

    /// Its name as written in a study.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            ToleranceDistribution::Rectangular => "rectangular",
            ToleranceDistribution::Triangular => "triangular",
            ToleranceDistribution::Arcsine => "arcsine",
        }
    }
}

/// The study's uncertainty settings (`[uncertainty]`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Uncertainty {
    /// The coverage probability of an expanded uncertainty, in (0, 1); 0.95 by default.
    pub coverage: f64,
    /// Whether the study gave `[uncertainty].coverage` (else the default).
    pub coverage_given: bool,
    /// The law of a tolerance; rectangular by default.
    pub tolerance_distribution: ToleranceDistribution,
}

/// The coverage probability when a study gives none.
pub const DEFAULT_COVERAGE: f64 = 0.95;

impl Default for Uncertainty {
    fn default() -> Self {
        Self {
            coverage: DEFAULT_COVERAGE,
            coverage_given: false,
            tolerance_distribution: ToleranceDistribution::Rectangular,
        }
    }
}

/// A coverage probability in (0, 1) at `key`.
fn coverage(at: &dyn Fn(&str) -> String, key: &str, v: f64) -> Result<f64, StudyError> {
    if v > 0.0 && v < 1.0 {
        Ok(v)
    } else {
        Err(StudyError::new(
            at(key),
            format!(
                "a coverage probability lies strictly between 0 and 1 (0.95 for 95 %), found {}",
                exact(v)
            ),
        ))
    }
}

/// `[uncertainty]`.
pub(crate) fn parse_uncertainty(
    at: &dyn Fn(&str) -> String,
    raw: Option<&RawUncertainty>,
) -> Result<Uncertainty, StudyError> {
    let mut u = Uncertainty::default();
    let Some(raw) = raw else {
        return Ok(u);
    };
    if let Some(c) = raw.coverage {
        u.coverage = coverage(at, "uncertainty.coverage", c)?;
        u.coverage_given = true;
    }
    if let Some(d) = &raw.tolerance_distribution {
        u.tolerance_distribution = match d.as_str() {
            "rectangular" => ToleranceDistribution::Rectangular,
            "triangular" => ToleranceDistribution::Triangular,
            "arcsine" => ToleranceDistribution::Arcsine,
            other => {
                return Err(StudyError::new(
                    at("uncertainty.tolerance_distribution"),
                    format!(
                        "unknown distribution \"{}\"; expected one of {}",
                        visible(other),
                        ToleranceDistribution::NAMES.join(", ")
                    ),
                ));
            }
        };
    }
    Ok(u)
}

/// `[[specifications]]` against the sensor.
pub(crate) fn parse_specifications(
    at: &dyn Fn(&str) -> String,
    raw: &[RawSpecification],
    sensor: &SensorModel,
    uncertainty: &Uncertainty,
) -> Result<Vec<Specification>, StudyError> {
    raw.iter()
        .enumerate()
        .map(|(i, r)| {
            let key = |k: &str| format!("specifications[{i}].{k}");
            crate::schema::one_line(at, &key("unit"), &r.unit)?;
            let output = sensor
                .outputs()
                .iter()
                .position(|o| o.name == r.output)
                .ok_or_else(|| {
                    let names: Vec<&str> = sensor.outputs().iter().map(|o| o.name.as_str()).collect();
                    StudyError::new(
                        at(&key("output")),
                        format!(
                            "\"{}\" is not an output of the sensor ({})",
                            visible(&r.output),
                            names.join(", ")
                        ),
                    )
                })?;
            let only_range = |what: &str| -> Result<(), StudyError> {
                if let Some(k) = [("range", r.range.is_some()), ("range_unit", r.range_unit.is_some())]
                    .iter()
                    .find(|(_, given)| *given)
                    .map(|(k, _)| *k)
                {
                    return Err(StudyError::new(
                        at(&key(k)),
                        format!("only an \"error_over_range\" specification takes `{k}` (this one is {what})"),
                    ));
                }
                Ok(())
            };
            let quantity = match (r.quantity.as_deref(), &r.coefficient) {
                (None | Some("coefficient"), Some(c)) => {
                    only_range("a coefficient's")?;
                    Quantity::Coefficient(c.clone())
                }
                (None | Some("coefficient"), None) => {
                    return Err(StudyError::new(
                        at(&key("coefficient")),
                        "missing: name the estimated coefficient, or give `quantity = \"accuracy\"` or `\"error_over_range\"`",
                    ));
                }
                (Some(q @ ("accuracy" | "error_over_range")), Some(_)) => {
                    return Err(StudyError::new(
                        at(&key("coefficient")),
                        format!("a `quantity = \"{q}\"` specification names no coefficient"),
                    ));
                }
                (Some("accuracy"), None) => {
                    only_range("an accuracy")?;
                    Quantity::Accuracy
                }
                (Some("error_over_range"), None) => {
                    let range = r.range.ok_or_else(|| {
                        StudyError::new(at(&key("range")), "missing: the operating range's magnitude (with `range_unit`)")
                    })?;
                    let range_unit = r.range_unit.clone().ok_or_else(|| {
                        StudyError::new(at(&key("range_unit")), "missing: the range's unit (deg/s, deg/h or g)")
                    })?;
                    Quantity::ErrorOverRange { range, range_unit }
                }
                (Some(other), _) => {
                    return Err(StudyError::new(
                        at(&key("quantity")),
                        format!(
                            "unknown quantity \"{}\"; expected \"coefficient\", \"accuracy\" or \"error_over_range\"",
                            visible(other)
                        ),
                    ));
                }
            };
            let p = match r.coverage {
                Some(c) => coverage(at, &key("coverage"), c)?,
                None => uncertainty.coverage,
            };
            Specification::new(sensor, output, quantity, r.limit, &r.unit, p).map_err(|e| match e {
                gw_model::ModelError::Specification { key: k, reason } => {
                    StudyError::new(at(&key(&k)), reason)
                }
                other => StudyError::new(at(&format!("specifications[{i}]")), other.to_string()),
            })
        })
        .collect()
}
