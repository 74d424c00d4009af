//! Specifications per calibrated quantity: what a test plan states a calibration must reach,
//! each in its own unit.
//!
//! A [`Specification`] names one output of a [`SensorModel`] and one quantity of it:
//!
//! - an estimated **coefficient** by its name in the model, in a unit of its kind
//!   ([`CoefficientKind`]): a bias in a unit of the output's family (`deg_per_h`, `mg`, `ug`,
//!   ...), a scale factor as a ratio (`ppm`, `%`), a misalignment as an angle (`arcsec`,
//!   `urad`, `mrad`), a gyro's g-sensitivity as a rate per g (`deg_per_h_per_g`), any other
//!   coefficient in its model unit as [`Output::coefficient_unit`] prints it;
//! - the **error over an operating range**: the calibrated output's error at the inputs
//!   $\pm R$ along its sensitive axis (bias, scale factor and every power of that input), the
//!   larger of the two, in a unit of the output's family;
//! - the paper's **accuracy** (eq 14): the rate (or specific-force) error at every test
//!   position, in a unit of the output's family.
//!
//! Every limit is converted once to the model's units (output unit per regressor unit:
//! deg/h, mg/g, ...). The kinds are told apart by the coefficient's regressor: `1` is a bias;
//! the one input of the output's own family along its sensitive axis (the input whose linear
//! terms, known and estimated, sum to the largest magnitude) a scale factor; another input of
//! the output's family a misalignment; a specific force on a rate output a g-sensitivity.
//!
//! ```
//! use gw_model::spec::{Quantity, Specification};
//! let sensor = gw_model::paper::gyrowheel();
//! let o = &sensor.outputs()[0];
//! let name = o.estimated_names()[0].to_string();
//! let s = Specification::new(&sensor, 0, Quantity::Coefficient(name), 0.05, "deg/h", 0.95)?;
//! assert!((s.limit() - 0.05).abs() < 1e-15); // already the output's unit
//! # Ok::<(), gw_model::ModelError>(())
//! ```

use crate::error::ModelError;
use crate::noise::{OutputUnit, STANDARD_GRAVITY_M_PER_S2, UnitFamily};
use crate::sensor::{Input, Output, Regressor, SensorModel};
use tt_core::units::RAD_PER_S_PER_DEG_PER_H;

/// One arcsecond in rad.
const RAD_PER_ARCSEC: f64 = std::f64::consts::PI / (180.0 * 3600.0);

/// The units of a ratio (a scale factor): label, value of one unit.
pub(crate) const RATIO_UNITS: &[(&str, f64)] = &[("ppm", 1e-6), ("%", 1e-2), ("1", 1.0)];

/// The units of a small angle (a misalignment): label, rad per unit.
pub(crate) const ANGLE_UNITS: &[(&str, f64)] = &[
    ("arcsec", RAD_PER_ARCSEC),
    ("urad", 1e-6),
    ("mrad", 1e-3),
    ("rad", 1.0),
    ("deg", std::f64::consts::PI / 180.0),
];

/// The units of a rate per g (a g-sensitivity): label, (rad/s)/g per unit.
pub(crate) const RATE_PER_G_UNITS: &[(&str, f64)] = &[
    ("deg_per_h_per_g", RAD_PER_S_PER_DEG_PER_H),
    ("deg/h/g", RAD_PER_S_PER_DEG_PER_H),
    ("deg_per_s_per_g", std::f64::consts::PI / 180.0),
    ("deg/s/g", std::f64::consts::PI / 180.0),
    ("rad_per_s_per_g", 1.0),
];

/// What a specified coefficient is, from its regressor and its output's unit.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum CoefficientKind {
    /// Regressor `1`: in a unit of the output's family.
    Bias,
    /// The output's own input along its sensitive axis: a ratio (ppm).
    ScaleFactor,
    /// Another input of the output's family: an angle (arcsec, urad).
    Misalignment,
    /// A specific force on an angular-rate output: a rate per g (deg/h/g).
    GSensitivity,
    /// Any other regressor: in the coefficient's model unit only.
    Other,
}

impl CoefficientKind {
    /// The kind's name in messages (`bias`, `scale factor`, ...).
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            CoefficientKind::Bias => "bias",
            CoefficientKind::ScaleFactor => "scale factor",
            CoefficientKind::Misalignment => "misalignment",
            CoefficientKind::GSensitivity => "g-sensitivity",
            CoefficientKind::Other => "coefficient",
        }
    }
}

/// The quantity a specification constrains, as the caller names it.
#[derive(Debug, Clone, PartialEq)]
pub enum Quantity {
    /// An estimated coefficient of the output, by its name in the model.
    Coefficient(String),
    /// The output's error at the inputs $\pm$`range` (in the input's unit as written in
    /// `range_unit`: `deg/s`, `deg/h` or `g`) along its sensitive axis.
    ErrorOverRange {
        /// The range's magnitude as written.
        range: f64,
        /// Its unit as written (`deg/s`, `deg_per_s`, `deg/h`, `deg_per_h`, `g`).
        range_unit: String,
    },
    /// Eq 14: the rate (specific-force) error at every test position.
    Accuracy,
}

/// A resolved quantity: what the budget evaluates.
#[derive(Debug, Clone, PartialEq)]
pub enum Resolved {
    /// Estimated coefficient number `index` (order of [`Output::estimated`]).
    Coefficient {
        /// Index among the output's estimated terms.
        index: usize,
        /// Its kind.
        kind: CoefficientKind,
    },
    /// The error at the inputs $\pm$`range` along `axis` (regressor units: g or deg/h).
    ErrorOverRange {
        /// The sensitive input.
        axis: Input,
        /// The magnitude in the input's regressor unit (g or deg/h).
        range: f64,
    },
    /// Eq 14 at every test position.
    Accuracy,
}

/// One specification of one output: the limit of a quantity at a stated coverage.
#[derive(Debug, Clone, PartialEq)]
pub struct Specification {
    output: usize,
    quantity: Quantity,
    resolved: Resolved,
    limit: f64,
    written_limit: f64,
    unit: String,
    coverage: f64,
}

/// The family an input belongs to.
fn input_family(u: Input) -> UnitFamily {
    match u {
        Input::Ax | Input::Ay | Input::Az => UnitFamily::SpecificForce,
        _ => UnitFamily::AngularRate,
    }
}

/// SI per regressor unit of an input (g in m/s^2, deg/h in rad/s).
fn input_si(u: Input) -> f64 {
    match input_family(u) {
        UnitFamily::SpecificForce => STANDARD_GRAVITY_M_PER_S2,
        UnitFamily::AngularRate => RAD_PER_S_PER_DEG_PER_H,
    }
}

/// The single input of a linear regressor.
fn linear_input(r: &Regressor) -> Option<Input> {
    (r.degree() == 1)
        .then(|| Input::ALL.into_iter().find(|&u| r.power(u) == 1))
        .flatten()
}

/// The output's sensitive axis: the input of its family whose linear terms (known and
/// estimated) sum to the largest magnitude; `None` when it has none or the unit is unknown.
#[must_use]
pub(crate) fn sensitive_axis(o: &Output) -> Option<Input> {
    let family = OutputUnit::parse(&o.unit)?.family();
    let mut sums = [0.0_f64; 6];
    for t in &o.terms {
        if let Some(u) = linear_input(&t.regressor).filter(|&u| input_family(u) == family) {
            sums[u as usize] += t.value;
        }
    }
    Input::ALL
        .into_iter()
        .filter(|&u| input_family(u) == family && sums[u as usize] != 0.0)
        .max_by(|a, b| sums[*a as usize].abs().total_cmp(&sums[*b as usize].abs()))
}

/// The kind of a coefficient on regressor `r` of output `o`.
#[must_use]
pub(crate) fn coefficient_kind(o: &Output, r: &Regressor) -> CoefficientKind {
    if *r == Regressor::ONE {
        return CoefficientKind::Bias;
    }
    let (Some(unit), Some(u)) = (OutputUnit::parse(&o.unit), linear_input(r)) else {
        return CoefficientKind::Other;
    };
    match (unit.family(), input_family(u)) {
        (UnitFamily::AngularRate, UnitFamily::SpecificForce) => CoefficientKind::GSensitivity,
        (f, g) if f == g && sensitive_axis(o) == Some(u) => CoefficientKind::ScaleFactor,
        (f, g) if f == g => CoefficientKind::Misalignment,
        _ => CoefficientKind::Other,
    }
}

/// The units (labels) a quantity of `kind` may be given in for output `o`.
fn units_of(o: &Output, kind: CoefficientKind, model_unit: &str) -> Vec<String> {
    let family_units = || -> Vec<String> {
        match OutputUnit::parse(&o.unit) {
            Some(u) => crate::noise::OUTPUT_UNITS
                .iter()
                .filter(|(_, f, _)| *f == u.family())
                .map(|(l, _, _)| (*l).to_string())
                .collect(),
            None => vec![o.unit.clone()],
        }
    };
    let labels = |t: &[(&str, f64)]| t.iter().map(|(l, _)| (*l).to_string()).collect();
    match kind {
        CoefficientKind::Bias => family_units(),
        CoefficientKind::ScaleFactor => labels(RATIO_UNITS),
        CoefficientKind::Misalignment => labels(ANGLE_UNITS),
        CoefficientKind::GSensitivity => labels(RATE_PER_G_UNITS),
        CoefficientKind::Other => vec![model_unit.to_string()],
    }
}

/// The value of one `unit` of a quantity of `kind` in the model's units of output `o` and
/// regressor `r` (`None` when `unit` is not one of the kind's units).
fn model_per_unit(
    o: &Output,
    kind: CoefficientKind,
    r: &Regressor,
    model_unit: &str,
    unit: &str,
) -> Option<f64> {
    let find = |t: &[(&str, f64)]| t.iter().find(|(l, _)| *l == unit).map(|&(_, v)| v);
    let out = OutputUnit::parse(&o.unit);
    // SI of one model unit of a coefficient on a linear regressor: output SI / input SI
    let per_model = || {
        let u = linear_input(r)?;
        Some(out?.si_per_unit() / input_si(u))
    };
    match kind {
        CoefficientKind::Bias => match (out, OutputUnit::parse(unit)) {
            (Some(o), Some(u)) if o.family() == u.family() => {
                Some(u.si_per_unit() / o.si_per_unit())
            }
            (None, _) if unit == o.unit => Some(1.0),
            _ => None,
        },
        CoefficientKind::ScaleFactor => Some(find(RATIO_UNITS)? / per_model()?),
        CoefficientKind::Misalignment => Some(find(ANGLE_UNITS)? / per_model()?),
        // (rad/s)/g per model unit: the regressor is already in g
        CoefficientKind::GSensitivity => Some(find(RATE_PER_G_UNITS)? / out?.si_per_unit()),
        CoefficientKind::Other => (unit == model_unit).then_some(1.0),
    }
}

impl Specification {
    /// A specification of output `output` of `sensor`: `quantity` within `limit` (> 0, in
    /// `unit`) at coverage probability `coverage` in (0, 1).
    ///
    /// # Errors
    /// [`ModelError::Specification`] naming the field (`output`, `coefficient`, `unit`,
    /// `limit`, `coverage`, `range`, `range_unit`): no such output; a coefficient the model
    /// does not estimate (a known term, or no term of that name); a unit not of the
    /// quantity's kind (the message names the unit, the coefficient and its kind, and the
    /// units it accepts); a limit that is not finite and positive; a coverage outside (0, 1).
    pub fn new(
        sensor: &SensorModel,
        output: usize,
        quantity: Quantity,
        limit: f64,
        unit: &str,
        coverage: f64,
    ) -> Result<Self, ModelError> {
        let err = |key: &str, reason: String| ModelError::Specification {
            key: key.to_string(),
            reason,
        };
        let o = sensor.outputs().get(output).ok_or_else(|| {
            err(
                "output",
                format!(
                    "output number {output}, but the sensor has {}",
                    sensor.n_outputs()
                ),
            )
        })?;
        if !(coverage > 0.0 && coverage < 1.0) {
            return Err(err(
                "coverage",
                format!("a coverage probability lies in (0, 1), found {coverage}"),
            ));
        }
        if !(limit.is_finite() && limit > 0.0) {
            return Err(err(
                "limit",
                format!("must be finite and positive, found {limit}"),
            ));
        }
        let shown_unit = unit.escape_debug().to_string();
        let family_factor = |what: &str| -> Result<f64, ModelError> {
            let r = Regressor::ONE;
            model_per_unit(o, CoefficientKind::Bias, &r, &o.unit, unit).ok_or_else(|| {
                err(
                    "unit",
                    format!(
                        "unit \"{shown_unit}\" is not a unit of {what} of output `{}` (unit \"{}\"); give one of {}",
                        o.name,
                        o.unit.escape_debug(),
                        units_of(o, CoefficientKind::Bias, &o.unit).join(", ")
                    ),
                )
            })
        };
        let (resolved, per_unit) = match &quantity {
            Quantity::Coefficient(name) => {
                let Some(index) = o.estimated().position(|t| t.coefficient == *name) else {
                    let why = if o.known_terms().any(|t| t.coefficient == *name) {
                        format!(
                            "`{name}` of output `{}` is a known term: the calibration does not estimate it",
                            o.name
                        )
                    } else {
                        format!(
                            "`{name}` is not a coefficient the model of output `{}` estimates ({})",
                            o.name,
                            o.estimated_names().join(", ")
                        )
                    };
                    return Err(err("coefficient", why));
                };
                let term = o.estimated().nth(index).expect("index found above");
                let kind = coefficient_kind(o, &term.regressor);
                let model_unit = o.coefficient_unit(term);
                let f = model_per_unit(o, kind, &term.regressor, &model_unit, unit).ok_or_else(|| {
                    err(
                        "unit",
                        format!(
                            "unit \"{shown_unit}\" does not fit `{name}`, a {} of output `{}` (model unit {}): give one of {}",
                            kind.name(),
                            o.name,
                            model_unit.escape_debug(),
                            units_of(o, kind, &model_unit).join(", ")
                        ),
                    )
                })?;
                (Resolved::Coefficient { index, kind }, f)
            }
            Quantity::ErrorOverRange { range, range_unit } => {
                let Some(axis) = sensitive_axis(o) else {
                    return Err(err(
                        "range",
                        format!(
                            "output `{}` has no sensitive axis (no linear term of its own family, or an unknown unit \"{}\"): an error over a range needs one",
                            o.name,
                            o.unit.escape_debug()
                        ),
                    ));
                };
                let per = match (input_family(axis), range_unit.as_str()) {
                    (UnitFamily::AngularRate, "deg/s" | "deg_per_s") => 3600.0,
                    (UnitFamily::AngularRate, "deg/h" | "deg_per_h") => 1.0,
                    (UnitFamily::SpecificForce, "g") => 1.0,
                    _ => {
                        return Err(err(
                            "range_unit",
                            format!(
                                "unit \"{}\" is not one of the sensitive input {}: give {}",
                                range_unit.escape_debug(),
                                axis.symbol(),
                                match input_family(axis) {
                                    UnitFamily::AngularRate => "deg/s or deg/h",
                                    UnitFamily::SpecificForce => "g",
                                }
                            ),
                        ));
                    }
                };
                if !(range.is_finite() && *range > 0.0) {
                    return Err(err(
                        "range",
                        format!("must be finite and positive, found {range}"),
                    ));
                }
                (
                    Resolved::ErrorOverRange {
                        axis,
                        range: range * per,
                    },
                    family_factor("the output's error")?,
                )
            }
            Quantity::Accuracy => (Resolved::Accuracy, family_factor("the output's error")?),
        };
        Ok(Self {
            output,
            quantity,
            resolved,
            limit: limit * per_unit,
            written_limit: limit,
            unit: unit.to_string(),
            coverage,
        })
    }

    /// The output's index.
    #[must_use]
    pub fn output(&self) -> usize {
        self.output
    }

    /// The quantity as named.
    #[must_use]
    pub fn quantity(&self) -> &Quantity {
        &self.quantity
    }

    /// The quantity resolved against the model.
    #[must_use]
    pub fn resolved(&self) -> &Resolved {
        &self.resolved
    }

    /// The limit in the model's units (output unit per regressor unit).
    #[must_use]
    pub fn limit(&self) -> f64 {
        self.limit
    }

    /// The limit as written, in [`Specification::unit`].
    #[must_use]
    pub fn written_limit(&self) -> f64 {
        self.written_limit
    }

    /// The unit as written.
    #[must_use]
    pub fn unit(&self) -> &str {
        &self.unit
    }

    /// The written unit's value per model unit: a model-unit figure times this is in
    /// [`Specification::unit`].
    #[must_use]
    pub fn to_written(&self) -> f64 {
        self.written_limit / self.limit
    }

    /// The coverage probability.
    #[must_use]
    pub fn coverage(&self) -> f64 {
        self.coverage
    }

    /// A short label: `gx bg_x (bias)`, `gx error over +-300 deg/s`, `gx accuracy (eq 14)`.
    #[must_use]
    pub fn label(&self, sensor: &SensorModel) -> String {
        let o = &sensor.outputs()[self.output].name;
        match (&self.quantity, &self.resolved) {
            (Quantity::Coefficient(name), Resolved::Coefficient { kind, .. }) => {
                format!("{o} {name} ({})", kind.name())
            }
            (
                Quantity::ErrorOverRange {
                    range, range_unit, ..
                },
                _,
            ) => format!("{o} error over +-{range} {range_unit}"),
            _ => format!("{o} accuracy (eq 14)"),
        }
    }
}
