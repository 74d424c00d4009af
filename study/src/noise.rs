//! The noise keys of a study: `[sensor.outputs.noise]` per output and
//! `[calibration.timing]`, parsed strictly into `gw_model::noise::NoiseModel` and
//! `calib_lsq::Timing`.
//!
//! ```toml
//! [[sensor.outputs]]
//! name = "gx"
//! unit = "deg_per_h"
//! # ...
//! [sensor.outputs.noise]
//! white_deg_per_sqrt_h = 0.15   # at most one of the four white keys
//! bias_instability = 0.5        # output unit, with bias_correlation_s (both or neither)
//! bias_correlation_s = 3600
//! quantization = 0.0            # output unit (optional)
//! rate_random_walk = 0.005      # output unit per sqrt(s) (optional): sigma(tau) = K sqrt(tau/3)
//! rate_ramp = 0.0               # output unit per s (optional): sigma(tau) = R tau / sqrt(2)
//! flicker_bias_instability = 0.5 # output unit (optional): flicker floor sigma = 0.6643 B
//! angle_quantization = 0.0      # output unit times s (optional): sigma(tau) = sqrt(3) Q / tau
//!
//! [sensor.outputs.noise.uncertainty] # optional: standard uncertainties, each under its
//! white_deg_per_sqrt_h = 0.01        # term's key and in its unit (what `allan` prints);
//! bias_instability = 0.1             # the answers are given at each value +- 1 of them
//!
//! [calibration.timing]
//! dwell_s = 60                  # or one value per position
//! sample_rate_hz = 1000
//! move_s = 10                   # optional, 0 by default
//! ```

use crate::error::StudyError;
use crate::limits;
use crate::schema::in_range;
use calib_lsq::Timing;
use gw_model::ModelError;
use gw_model::noise::{NoiseModel, WhiteDensity};
use serde::Deserialize;
use tt_core::human::{exact, num};

/// `[sensor.outputs.noise]` as written.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawNoise {
    white_deg_per_sqrt_h: Option<f64>,
    white_ug_per_sqrt_hz: Option<f64>,
    white_m_per_s_per_sqrt_h: Option<f64>,
    white_per_sqrt_hz: Option<f64>,
    bias_instability: Option<f64>,
    bias_correlation_s: Option<f64>,
    quantization: Option<f64>,
    rate_random_walk: Option<f64>,
    rate_ramp: Option<f64>,
    flicker_bias_instability: Option<f64>,
    angle_quantization: Option<f64>,
    uncertainty: Option<RawNoiseUncertainty>,
}

/// `[sensor.outputs.noise.uncertainty]` as written: the standard uncertainty of each term,
/// under the term's key and in its unit.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawNoiseUncertainty {
    white_deg_per_sqrt_h: Option<f64>,
    white_ug_per_sqrt_hz: Option<f64>,
    white_m_per_s_per_sqrt_h: Option<f64>,
    white_per_sqrt_hz: Option<f64>,
    bias_instability: Option<f64>,
    bias_correlation_s: Option<f64>,
    flicker_bias_instability: Option<f64>,
    quantization: Option<f64>,
    angle_quantization: Option<f64>,
    rate_random_walk: Option<f64>,
    rate_ramp: Option<f64>,
}

/// `[calibration.timing]` as written.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawTiming {
    dwell_s: toml::Value,
    sample_rate_hz: f64,
    move_s: Option<f64>,
}

/// The unit each white key is in, for messages.
fn white_unit(key: &str) -> &'static str {
    match key {
        "white_deg_per_sqrt_h" => "deg/sqrt(h)",
        "white_ug_per_sqrt_hz" => "ug/sqrt(Hz)",
        "white_m_per_s_per_sqrt_h" => "(m/s)/sqrt(h)",
        _ => "(output unit)/sqrt(Hz)",
    }
}

/// Parse output `k`'s noise table (`unit` is the output's unit label).
pub(crate) fn parse_output_noise(
    at: &dyn Fn(&str) -> String,
    k: usize,
    unit: &str,
    raw: &RawNoise,
) -> Result<NoiseModel, StudyError> {
    let key = |s: &str| {
        if s.is_empty() {
            format!("sensor.outputs[{k}].noise")
        } else {
            format!("sensor.outputs[{k}].noise.{s}")
        }
    };
    let shown_unit = format!("({})", unit.escape_debug());
    let whites: Vec<WhiteDensity> = [
        raw.white_deg_per_sqrt_h.map(WhiteDensity::DegPerSqrtH),
        raw.white_ug_per_sqrt_hz.map(WhiteDensity::UgPerSqrtHz),
        raw.white_m_per_s_per_sqrt_h
            .map(WhiteDensity::MPerSPerSqrtH),
        raw.white_per_sqrt_hz.map(WhiteDensity::PerSqrtHz),
    ]
    .into_iter()
    .flatten()
    .collect();
    if whites.len() > 1 {
        let names: Vec<&str> = whites.iter().map(WhiteDensity::key).collect();
        return Err(StudyError::new(
            at(&key("")),
            format!(
                "give the white noise once, in one unit; found {}",
                names.join(", ")
            ),
        ));
    }
    if whites.is_empty()
        && raw.bias_instability.is_none()
        && raw.bias_correlation_s.is_none()
        && raw.quantization.is_none()
        && raw.rate_random_walk.is_none()
        && raw.rate_ramp.is_none()
        && raw.flicker_bias_instability.is_none()
        && raw.angle_quantization.is_none()
    {
        return Err(StudyError::new(
            at(&key("")),
            format!(
                "an empty noise table: give one of {}, or bias_instability with bias_correlation_s, flicker_bias_instability, quantization, angle_quantization, rate_random_walk or rate_ramp (or remove the table)",
                WhiteDensity::KEYS.join(", ")
            ),
        ));
    }
    let white = whites.first().copied();
    if let Some(w) = white {
        in_range(
            at,
            &key(w.key()),
            w.value(),
            0.0,
            limits::NOISE_MAX,
            false,
            white_unit(w.key()),
        )?;
    }
    let bias = match (raw.bias_instability, raw.bias_correlation_s) {
        (None, None) => None,
        (Some(_), None) => {
            return Err(StudyError::new(
                at(&key("bias_correlation_s")),
                "missing: bias_instability needs its correlation time bias_correlation_s (s)",
            ));
        }
        (None, Some(_)) => {
            return Err(StudyError::new(
                at(&key("bias_instability")),
                "missing: bias_correlation_s needs the bias_instability it belongs to",
            ));
        }
        (Some(b), Some(tc)) => {
            let b = in_range(
                at,
                &key("bias_instability"),
                b,
                0.0,
                limits::NOISE_MAX,
                false,
                &shown_unit,
            )?;
            let (lo, hi) = limits::CORRELATION_S;
            let tc = in_range(at, &key("bias_correlation_s"), tc, lo, hi, true, "s")?;
            Some((b, tc))
        }
    };
    let quantization = raw
        .quantization
        .map(|q| {
            in_range(
                at,
                &key("quantization"),
                q,
                0.0,
                limits::NOISE_MAX,
                false,
                &shown_unit,
            )
        })
        .transpose()?;
    let per_sqrt_s = format!("({})/sqrt(s)", unit.escape_debug());
    let per_s = format!("({})/s", unit.escape_debug());
    let drift = |name: &str, v: Option<f64>, shown: &str| {
        v.map_or(Ok(0.0), |v| {
            in_range(at, &key(name), v, 0.0, limits::NOISE_MAX, false, shown)
        })
    };
    let rate_random_walk = drift("rate_random_walk", raw.rate_random_walk, &per_sqrt_s)?;
    let rate_ramp = drift("rate_ramp", raw.rate_ramp, &per_s)?;
    let flicker = drift(
        "flicker_bias_instability",
        raw.flicker_bias_instability,
        &shown_unit,
    )?;
    let times_s = format!("({}) s", unit.escape_debug());
    let angle_quantization = drift("angle_quantization", raw.angle_quantization, &times_s)?;
    let mut model = NoiseModel::from_datasheet(unit, white, bias, quantization)
        .and_then(|m| m.with_rate_random_walk(rate_random_walk))
        .and_then(|m| m.with_rate_ramp(rate_ramp))
        .and_then(|m| m.with_flicker(flicker))
        .and_then(|m| m.with_angle_quantization(angle_quantization))
        .map_err(|e| {
            let field = match &e {
                ModelError::UnitFamilyMismatch { key, .. }
                | ModelError::UnknownUnit { key, .. } => key.clone(),
                ModelError::Field(f) => f.field().to_string(),
                _ => String::new(),
            };
            StudyError::new(at(&key(&field)), e.to_string())
        })?;
    if let Some(u) = &raw.uncertainty {
        model = with_uncertainties(at, &key, unit, raw, u, model)?;
    }
    Ok(model)
}

/// The noise model with the uncertainties of `[sensor.outputs.noise.uncertainty]`, each
/// converted as its term (a white density to the output's unit, a bias instability to the
/// Gauss-Markov sigma); an uncertainty of a term the table does not give is an error naming
/// it.
fn with_uncertainties(
    at: &dyn Fn(&str) -> String,
    key: &dyn Fn(&str) -> String,
    unit: &str,
    raw: &RawNoise,
    u: &RawNoiseUncertainty,
    mut model: NoiseModel,
) -> Result<NoiseModel, StudyError> {
    use gw_model::noise::{
        FLICKER_FLOOR_PER_BIAS_INSTABILITY, GM_ADEV_PEAK_PER_SIGMA, NoiseParameter as P,
    };
    let shown_unit = format!("({})", unit.escape_debug());
    let entries: [(&str, Option<f64>, bool, P, &str); 11] = [
        (
            "white_deg_per_sqrt_h",
            u.white_deg_per_sqrt_h,
            raw.white_deg_per_sqrt_h.is_some(),
            P::White,
            "deg/sqrt(h)",
        ),
        (
            "white_ug_per_sqrt_hz",
            u.white_ug_per_sqrt_hz,
            raw.white_ug_per_sqrt_hz.is_some(),
            P::White,
            "ug/sqrt(Hz)",
        ),
        (
            "white_m_per_s_per_sqrt_h",
            u.white_m_per_s_per_sqrt_h,
            raw.white_m_per_s_per_sqrt_h.is_some(),
            P::White,
            "(m/s)/sqrt(h)",
        ),
        (
            "white_per_sqrt_hz",
            u.white_per_sqrt_hz,
            raw.white_per_sqrt_hz.is_some(),
            P::White,
            "(output unit)/sqrt(Hz)",
        ),
        (
            "bias_instability",
            u.bias_instability,
            raw.bias_instability.is_some(),
            P::BiasSigma,
            &shown_unit,
        ),
        (
            "bias_correlation_s",
            u.bias_correlation_s,
            raw.bias_correlation_s.is_some(),
            P::BiasCorrelation,
            "s",
        ),
        (
            "flicker_bias_instability",
            u.flicker_bias_instability,
            raw.flicker_bias_instability.is_some(),
            P::Flicker,
            &shown_unit,
        ),
        (
            "quantization",
            u.quantization,
            raw.quantization.is_some(),
            P::Quantization,
            &shown_unit,
        ),
        (
            "angle_quantization",
            u.angle_quantization,
            raw.angle_quantization.is_some(),
            P::AngleQuantization,
            "(output unit) s",
        ),
        (
            "rate_random_walk",
            u.rate_random_walk,
            raw.rate_random_walk.is_some(),
            P::RateRandomWalk,
            "(output unit)/sqrt(s)",
        ),
        (
            "rate_ramp",
            u.rate_ramp,
            raw.rate_ramp.is_some(),
            P::RateRamp,
            "(output unit)/s",
        ),
    ];
    for (name, value, given, p, shown) in entries {
        let Some(v) = value else { continue };
        let k = key(&format!("uncertainty.{name}"));
        if !given {
            return Err(StudyError::new(
                at(&k),
                format!("an uncertainty of {name}, which the noise table does not give"),
            ));
        }
        let hi = if p == P::BiasCorrelation {
            limits::CORRELATION_S.1
        } else {
            limits::NOISE_MAX
        };
        let v = in_range(at, &k, v, 0.0, hi, false, shown)?;
        // converted as the term's value is
        let converted = match name {
            "white_deg_per_sqrt_h" => WhiteDensity::DegPerSqrtH(v).in_output_unit(unit),
            "white_ug_per_sqrt_hz" => WhiteDensity::UgPerSqrtHz(v).in_output_unit(unit),
            "white_m_per_s_per_sqrt_h" => WhiteDensity::MPerSPerSqrtH(v).in_output_unit(unit),
            "bias_instability" => {
                Ok(v * FLICKER_FLOOR_PER_BIAS_INSTABILITY / GM_ADEV_PEAK_PER_SIGMA)
            }
            _ => Ok(v),
        }
        .and_then(|c| model.clone().with_uncertainty(p, c));
        model = converted.map_err(|e| StudyError::new(at(&k), e.to_string()))?;
    }
    Ok(model)
}

/// Parse `[calibration.timing]` for a schedule of `n` positions.
pub(crate) fn parse_timing(
    at: &dyn Fn(&str) -> String,
    raw: &RawTiming,
    n: usize,
) -> Result<Timing, StudyError> {
    const KEY: &str = "calibration.timing.dwell_s";
    let (lo, hi) = limits::DWELL_S;
    let number = |key: &str, v: &toml::Value| -> Result<f64, StudyError> {
        let x = match v {
            toml::Value::Float(f) => *f,
            toml::Value::Integer(i) => *i as f64,
            other => {
                return Err(StudyError::new(
                    at(key),
                    format!("must be a number of seconds, found a {}", other.type_str()),
                ));
            }
        };
        in_range(at, key, x, lo, hi, true, "s")
    };
    let dwell_s = match &raw.dwell_s {
        toml::Value::Array(list) => {
            if list.len() != n {
                return Err(StudyError::new(
                    at(KEY),
                    format!(
                        "one dwell per position: {n} positions, found {} values (or give one number for all)",
                        list.len()
                    ),
                ));
            }
            list.iter()
                .enumerate()
                .map(|(i, v)| number(&format!("{KEY}[{i}]"), v))
                .collect::<Result<Vec<f64>, StudyError>>()?
        }
        v => vec![number(KEY, v)?; n],
    };
    let (flo, fhi) = limits::SAMPLE_RATE_HZ;
    let fs = in_range(
        at,
        "calibration.timing.sample_rate_hz",
        raw.sample_rate_hz,
        flo,
        fhi,
        true,
        "Hz",
    )?;
    let (mlo, mhi) = limits::MOVE_S;
    let move_s = in_range(
        at,
        "calibration.timing.move_s",
        raw.move_s.unwrap_or(0.0),
        mlo,
        mhi,
        false,
        "s",
    )?;
    let uniform = !matches!(raw.dwell_s, toml::Value::Array(_));
    // a rate at which even the longest accepted dwell holds no sample is the rate's fault
    if fs * hi < 1.0 {
        return Err(StudyError::new(
            at("calibration.timing.sample_rate_hz"),
            format!(
                "{} Hz gives less than one sample in any dwell up to the longest accepted ({} s): sample at least at {} Hz",
                exact(fs),
                num(hi),
                num(1.0 / hi)
            ),
        ));
    }
    for (i, &t) in dwell_s.iter().enumerate() {
        if t * fs < 1.0 {
            let key = if uniform {
                KEY.to_string()
            } else {
                format!("{KEY}[{i}]")
            };
            return Err(StudyError::new(
                at(&key),
                format!(
                    "{} s at sample_rate_hz = {} Hz holds less than one sample: dwell at least {} s",
                    exact(t),
                    exact(fs),
                    num(1.0 / fs)
                ),
            ));
        }
    }
    Timing::new(dwell_s, move_s, fs).map_err(|e| {
        let key = match &e {
            calib_lsq::CalibError::Timing { field, .. } => format!("calibration.timing.{field}"),
            calib_lsq::CalibError::Field(
                f @ (tt_core::FieldError::NonFinite { .. }
                | tt_core::FieldError::NotPositive { .. }),
            ) => format!("calibration.timing.{}", f.field()),
            _ => "calibration.timing".to_string(),
        };
        StudyError::new(at(&key), e.to_string())
    })
}

/// The static timing `timing` with each rate step's averaging window (its turning time) after
/// the positions.
pub(crate) fn with_rate_steps(
    at: &dyn Fn(&str) -> String,
    timing: Timing,
    steps: &[crate::schema::StudyRateStep],
) -> Result<Timing, StudyError> {
    timing
        .with_rate_steps(
            steps
                .iter()
                .map(crate::schema::StudyRateStep::duration_s)
                .collect(),
        )
        .map_err(|e| match &e {
            calib_lsq::CalibError::Timing { field, reason } => {
                match field
                    .strip_prefix("rate_step_s[")
                    .and_then(|r| r.strip_suffix(']'))
                {
                    Some(j) => StudyError::new(
                        at(&format!("calibration.rate_steps[{j}].revolutions")),
                        format!(
                            "the step's turning time (revolutions x 360 / |rate_deg_per_s|): {reason}"
                        ),
                    ),
                    None => StudyError::new(at("calibration.timing"), e.to_string()),
                }
            }
            _ => StudyError::new(at("calibration.timing"), e.to_string()),
        })
}
