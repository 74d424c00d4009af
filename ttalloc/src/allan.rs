//! `cargo xtask allan [LOG.csv] --rate-hz F [--column NAME] [--unit U] [--confidence P]
//! [--taus octave|decade|all|T1,T2,...] [--json] [--figure FILE.svg] [--write-noise FILE.toml]`:
//! the noise of a sensor from a log of its output (a rate or a specific force sampled at F Hz,
//! 1e-9 to 1e12): the overlapping Allan deviation with its confidence bands, the modified,
//! Hadamard and total deviations, the joint fit of the IEEE Std 952 / 1293 terms (quantization,
//! white noise, flicker bias instability, rate random walk, rate ramp) each with its
//! uncertainty and whether the log resolves it, a Gauss-Markov alternative with a fitted
//! correlation time, a log-log figure and the noise block for a study (the `allan` crate does
//! the science).
//!
//! The log is a CSV file, or standard input (`-` or nothing; a named pipe works too): a header
//! line naming the columns, then one numeric row per sample (a UTF-8 byte-order mark is
//! accepted, blank lines are skipped, fields may be surrounded by spaces). One column is used:
//! the only one, or `--column NAME`. The log is read once, streaming: memory does not grow
//! with its length. Every problem exits with code 2 naming the flag, or the line and column.
//!
//! `--taus` chooses the cluster times: `octave` (default: 1, 2, 4, ... samples), `decade`
//! (1, 10, 100, ...), `all` (every size to 64 samples, then 32 per octave) or a list of
//! cluster times in s, each a whole number of samples and at most a third of the log.
//!
//! `--json` prints one object: `white_noise_per_sqrt_hz` (the log's unit per sqrt(Hz): the
//! 1 s Allan deviation of the white part), `bias_instability` (the log's unit: the floor of
//! the Allan deviation divided by sqrt(2 ln 2 / pi) = 0.664), their uncertainties,
//! `floor_tau_s`, `floor_reached`, `rate_random_walk`, `quantization`, `rate_ramp` (null when
//! not in the fit), `samples`, `rate_hz`, `duration_s`, `confidence`, `overlap`, `column`,
//! `unit`, `terms` (each of `quantization`, `white`, `flicker_bias_instability`,
//! `rate_random_walk`, `rate_ramp`: `{value, uncertainty, resolution}`), `gauss_markov` (the
//! alternative's `sigma`, `correlation_s`, `quantization`, `white`, `rate_random_walk`,
//! `rate_ramp`, `rss`, `power_rss`), `noise_block` (what `--write-noise` writes, `written`
//! with each key's uncertainty and `not_resolved`, `bias_model`, and what it cannot,
//! `not_written` with the reason), and `curve`, a list of `{tau_s, adev,
//! lower, upper, edf, cluster, stride, terms, noise, mdev, hdev, totdev}`; full precision,
//! never NaN.
//!
//! `--figure FILE.svg` draws the curve, its band, the other three deviations and the fitted
//! lines; `--write-noise FILE.toml` writes `[sensor.outputs.noise]` with the keys a study
//! accepts, every term of one model: `white_per_sqrt_hz`, the bias, `rate_random_walk`,
//! `rate_ramp` and `angle_quantization` (the fit's Q). The bias is the joint fit's flicker
//! floor, `flicker_bias_instability`, unless the Gauss-Markov alternative resolves its
//! correlation time (fitted, never the floor's cluster time) inside the study's limits and
//! fits the curve better (a lower weighted residual): then `bias_instability` with
//! `bias_correlation_s`, and the other terms of that model. A comment names the log, the
//! bias model, each value's uncertainty, the written terms the log cannot resolve, and every
//! term it could not write with its value and why (also on standard error); the
//! uncertainties are also written as `[sensor.outputs.noise.uncertainty]` (end-to-end gives
//! its answers at each +- 1 of them). Both refuse an existing path (exit 2)
//! and are written atomically (a temporary file renamed into place; nothing is left behind
//! on failure).

use crate::InputError;
use crate::csvio::{Source, for_each_line_in};
use crate::report::figures::{LIMIT, WIDTH, colour, finite};
use allan::{AllanError, Analysis, FLICKER_FLOOR_FACTOR, Settings, StreamingAllan, Taus, Term};
use anyhow::{Result, anyhow, bail};
use clap::Parser;
use plotters::prelude::*;
use serde::Serialize;
use std::path::{Path, PathBuf};
use study::fmt::sig;

/// Arguments of `allan`.
#[derive(Debug, Parser)]
pub struct Args {
    /// The log: a CSV file with a header line, or `-` (or nothing) for standard input.
    pub log: Option<PathBuf>,
    /// Sample rate of the log, Hz (required).
    #[arg(long, value_parser = rate)]
    pub rate_hz: f64,
    /// The column to analyse (needed when the log has more than one).
    #[arg(long)]
    pub column: Option<String>,
    /// The log's unit, for the text, figure and noise file (default: "log unit").
    #[arg(long, value_parser = unit)]
    pub unit: Option<String>,
    /// Confidence of the bands, a probability (default: 1 sigma, 0.6827).
    #[arg(long, default_value_t = allan::chi2::ONE_SIGMA, value_parser = confidence)]
    pub confidence: f64,
    /// Cluster times: `octave` (default), `decade`, `all`, or a comma-separated list in s.
    #[arg(long, value_parser = taus)]
    pub taus: Option<Taus>,
    /// Print JSON instead of text.
    #[arg(long)]
    pub json: bool,
    /// Write a log-log SVG figure of the curve, its band and the fitted lines to this new file.
    #[arg(long)]
    pub figure: Option<PathBuf>,
    /// Write the study's noise block (TOML) to this new file.
    #[arg(long)]
    pub write_noise: Option<PathBuf>,
}

fn rate(s: &str) -> Result<f64, String> {
    let (lo, hi) = allan::RATE_HZ;
    crate::args::number_in(s, lo, hi, "the sample rate (Hz)")
}

fn taus(s: &str) -> Result<Taus, String> {
    match s.trim() {
        "octave" => Ok(Taus::Octave),
        "decade" => Ok(Taus::Decade),
        "all" => Ok(Taus::All),
        list => list
            .split(',')
            .map(|t| {
                t.trim().parse::<f64>().ok().filter(|v| v.is_finite() && *v > 0.0).ok_or_else(|| {
                    format!(
                        "`{}`: expected octave, decade, all or a list of positive cluster times in s (1,10,100); `{}` is not one",
                        s.escape_debug(),
                        t.escape_debug()
                    )
                })
            })
            .collect::<Result<Vec<f64>, String>>()
            .map(Taus::List),
    }
}

fn confidence(s: &str) -> Result<f64, String> {
    let v: f64 = s
        .trim()
        .parse()
        .map_err(|_| format!("`{s}` is not a number"))?;
    if v > 0.0 && v < 1.0 && v <= 1.0 - 1e-9 {
        Ok(v)
    } else {
        Err(format!("`{s}`: a confidence is a probability in (0, 1)"))
    }
}

fn unit(s: &str) -> Result<String, String> {
    if s.is_empty() || s.chars().count() > 40 || s.chars().any(char::is_control) {
        return Err(format!(
            "`{}`: a unit is 1 to 40 printable characters",
            s.escape_debug()
        ));
    }
    Ok(s.to_string())
}

/// The library's message without its leading field name (the flag names it instead).
fn without_field(e: &AllanError) -> String {
    let m = e.to_string();
    m.strip_prefix("taus: ").map_or(m.clone(), str::to_string)
}

/// What was read: the analysis and where it came from.
struct Log {
    name: String,
    column: String,
    analysis: Analysis,
}

/// The column to read, from the header line.
fn pick_column(
    name: &str,
    line_no: usize,
    header: &str,
    wanted: Option<&str>,
) -> Result<(usize, usize, String), InputError> {
    let at = format!("{name}:{line_no}");
    let cols: Vec<&str> = header.split(',').map(str::trim).collect();
    let listed = || {
        cols.iter()
            .map(|c| format!("`{}`", c.escape_debug()))
            .collect::<Vec<_>>()
            .join(", ")
    };
    if let Some(first) = cols.first() {
        if first.parse::<f64>().is_ok() {
            return Err(InputError::new(
                at,
                format!(
                    "the first line must name the columns, found the number `{}`; add a header line",
                    first.escape_debug()
                ),
            ));
        }
    }
    for (i, c) in cols.iter().enumerate() {
        if c.is_empty() {
            return Err(InputError::new(
                format!("{at} column {}", i + 1),
                "a column without a name in the header",
            ));
        }
        if cols[..i].contains(c) {
            return Err(InputError::new(
                format!("{at} column {}", i + 1),
                format!("column `{}` appears twice", c.escape_debug()),
            ));
        }
    }
    let index = match wanted {
        Some(w) => cols.iter().position(|c| *c == w).ok_or_else(|| {
            InputError::new(
                "--column",
                format!(
                    "`{}` is not a column of {name}; its columns are {}",
                    w.escape_debug(),
                    listed()
                ),
            )
        })?,
        None if cols.len() == 1 => 0,
        None => {
            return Err(InputError::new(
                "--column",
                format!(
                    "{name} has {} columns ({}); choose one with --column NAME",
                    cols.len(),
                    listed()
                ),
            ));
        }
    };
    Ok((index, cols.len(), cols[index].to_string()))
}

/// Read the log once, line by line, into the estimator.
fn read_log(source: &Source, args: &Args) -> Result<Log, InputError> {
    let name = source.name();
    let settings = Settings::new(args.rate_hz)
        .confidence(args.confidence)
        .taus(args.taus.clone().unwrap_or_default());
    let mut est = StreamingAllan::new(settings).map_err(|e| match e {
        AllanError::InvalidTau { .. } => InputError::new("--taus", without_field(&e)),
        other => InputError::new("--rate-hz", other.to_string()),
    })?;
    let reader = source.open()?;
    let mut layout: Option<(usize, usize, String)> = None;
    for_each_line_in(reader, &name, |line_no, line| {
        let Some((index, count, column)) = &layout else {
            layout = Some(pick_column(&name, line_no, line, args.column.as_deref())?);
            return Ok(());
        };
        let mut fields = 0usize;
        let mut cell = "";
        for (i, f) in line.split(',').enumerate() {
            if i == *index {
                cell = f.trim();
            }
            fields += 1;
        }
        if fields != *count {
            return Err(InputError::new(
                format!("{name}:{line_no}"),
                format!("expected {count} columns, found {fields}"),
            ));
        }
        let at = || format!("{name}:{line_no} column {}", index + 1);
        let v: f64 = cell.parse().map_err(|_| {
            InputError::new(
                at(),
                format!(
                    "`{}`: `{}` is not a number",
                    column.escape_debug(),
                    cell.escape_debug()
                ),
            )
        })?;
        if !v.is_finite() {
            return Err(InputError::new(
                at(),
                format!(
                    "`{}`: `{}` is not a finite number",
                    column.escape_debug(),
                    cell.escape_debug()
                ),
            ));
        }
        est.push(v)
            .map_err(|e| InputError::new(at(), e.to_string()))
    })?;
    let Some((_, _, column)) = layout else {
        return Err(InputError::new(
            name,
            "empty input: expected a header line naming the columns, then one sample per line",
        ));
    };
    let analysis = est.analyse().map_err(|e| match e {
        AllanError::TooFewSamples { samples, needed } => InputError::new(
            name.clone(),
            format!(
                "column `{}` has {samples} samples; the shortest cluster time (one sample) needs at least {needed} (three clusters)",
                column.escape_debug()
            ),
        ),
        AllanError::ClusterTooLong { .. } => InputError::new("--taus", without_field(&e)),
        other => InputError::new(name.clone(), other.to_string()),
    })?;
    Ok(Log {
        name,
        column,
        analysis,
    })
}

/// Every number of the analysis, for the no-NaN check.
fn numbers(a: &Analysis) -> Vec<f64> {
    let f = &a.fit();
    let mut v = vec![
        a.rate_hz(),
        a.confidence(),
        f.white_noise(),
        f.bias_instability(),
        f.floor_tau_s(),
        f.floor_adev_measured(),
    ];
    v.extend(
        [
            f.white_noise_uncertainty(),
            f.bias_instability_uncertainty(),
            f.rate_random_walk(),
            f.rate_random_walk_uncertainty(),
            f.quantization(),
            f.rate_ramp(),
        ]
        .into_iter()
        .flatten(),
    );
    v.extend(f.coefficients());
    for t in joint_terms(a)
        .iter()
        .map(|t| t.1)
        .chain(gm_terms(a).iter().map(|t| t.1))
    {
        v.push(t.value());
        v.extend(t.uncertainty());
    }
    for p in a.points() {
        v.extend([
            p.tau_s(),
            p.adev(),
            p.lower(),
            p.upper(),
            p.edf(),
            p.mdev(),
            p.hdev(),
            p.totdev(),
        ]);
    }
    v
}

/// The joint fit's terms, by JSON name.
fn joint_terms(a: &Analysis) -> [(&'static str, Term); 5] {
    let f = a.fit();
    [
        ("quantization", f.quantization_term()),
        ("white", f.white_term()),
        ("flicker_bias_instability", f.flicker_term()),
        ("rate_random_walk", f.rate_random_walk_term()),
        ("rate_ramp", f.rate_ramp_term()),
    ]
}

/// The Gauss-Markov alternative's terms, by JSON name (empty for an all-zero curve).
fn gm_terms(a: &Analysis) -> Vec<(&'static str, Term)> {
    a.fit().gauss_markov().map_or_else(Vec::new, |g| {
        vec![
            ("sigma", g.sigma()),
            ("correlation_s", g.correlation_s()),
            ("quantization", g.quantization()),
            ("white", g.white()),
            ("rate_random_walk", g.rate_random_walk()),
            ("rate_ramp", g.rate_ramp()),
        ]
    })
}

/// A key `--write-noise` writes.
#[derive(Debug, Serialize)]
struct Written {
    /// The study's key.
    key: &'static str,
    /// Its value (the log's unit, or s).
    value: f64,
    /// Its standard uncertainty (the schema has no key for it).
    uncertainty: Option<f64>,
    /// `null` when the log resolves the term, else why not (written as fitted).
    not_resolved: Option<&'static str>,
}

impl Written {
    fn of(key: &'static str, t: Term) -> Self {
        Self {
            key,
            value: t.value(),
            uncertainty: t.uncertainty(),
            not_resolved: (!t.resolution().is_resolved()).then(|| t.resolution().explain()),
        }
    }
}

/// A term `--write-noise` cannot write.
#[derive(Debug, Serialize)]
struct NotWritten {
    /// The term, in words.
    term: &'static str,
    /// Its fitted value.
    value: f64,
    /// Its standard uncertainty.
    uncertainty: Option<f64>,
    /// Why it is not written.
    reason: String,
}

/// What `--write-noise` writes and what it cannot, whether or not it is asked for.
#[derive(Debug, Serialize)]
struct NoiseBlock {
    /// The bias model written: `flicker` (the joint fit's floor) or `gauss_markov`.
    bias_model: &'static str,
    written: Vec<Written>,
    not_written: Vec<NotWritten>,
}

/// The study's noise block of the analysis: only keys and values a study accepts
/// (`study::limits`); every other term listed with its reason. The bias is the joint fit's
/// flicker floor (`flicker_bias_instability`), or the Gauss-Markov alternative
/// (`bias_instability` with its fitted `bias_correlation_s`) when its correlation time is
/// resolved inside the study's limits and it fits the curve better (a lower weighted
/// residual); never both (they model the same wander). The other terms come from the model
/// whose bias is written.
fn noise_block(a: &Analysis) -> NoiseBlock {
    use gw_model::noise::{FLICKER_FLOOR_PER_BIAS_INSTABILITY, GM_ADEV_PEAK_PER_SIGMA};
    let f = a.fit();
    let noise_max = study::limits::NOISE_MAX;
    let (tc_lo, tc_hi) = study::limits::CORRELATION_S;
    let mut written = Vec::new();
    let mut not_written = Vec::new();
    let above = || format!("above the study's limit {}", study::fmt::num(noise_max));
    let gm = f.gauss_markov();
    let flicker = f.flicker_term();
    // the Gauss-Markov bias, when its correlation time is resolved and inside the limits and
    // it fits better than the flicker floor
    let mut bias_from_gm = false;
    if let Some(g) = gm {
        let (sigma, tc) = (g.sigma(), g.correlation_s());
        let b = sigma.value() * GM_ADEV_PEAK_PER_SIGMA / FLICKER_FLOOR_PER_BIAS_INSTABILITY;
        let b_u = sigma
            .uncertainty()
            .map(|u| u * GM_ADEV_PEAK_PER_SIGMA / FLICKER_FLOOR_PER_BIAS_INSTABILITY);
        let why = if !tc.resolution().is_resolved() {
            Some(format!(
                "its correlation time is not resolved: {}",
                tc.resolution().explain()
            ))
        } else if !(tc.value() > tc_lo && tc.value() <= tc_hi) {
            Some(format!(
                "bias_correlation_s = {} s is outside the study's limit ({}, {}] s",
                sig(tc.value(), 6),
                study::fmt::num(tc_lo),
                study::fmt::num(tc_hi)
            ))
        } else if b > noise_max {
            Some(format!(
                "bias_instability = {} is above the study's limit {}",
                sig(b, 6),
                study::fmt::num(noise_max)
            ))
        } else if flicker.value() > 0.0 && g.rss() >= g.power_rss() {
            Some(format!(
                "the joint fit's flicker floor fits the curve as well or better (weighted residual {} against {}); both would count the same wander twice",
                sig(g.power_rss(), 4),
                sig(g.rss(), 4)
            ))
        } else {
            None
        };
        match why {
            None => {
                bias_from_gm = true;
                written.push(Written {
                    key: "bias_instability",
                    value: b,
                    uncertainty: b_u,
                    not_resolved: (!sigma.resolution().is_resolved())
                        .then(|| sigma.resolution().explain()),
                });
                written.push(Written::of("bias_correlation_s", tc));
            }
            Some(reason) if sigma.value() > 0.0 => {
                not_written.push(NotWritten {
                    term: "Gauss-Markov bias sigma",
                    value: sigma.value(),
                    uncertainty: sigma.uncertainty(),
                    reason: reason.clone(),
                });
                not_written.push(NotWritten {
                    term: "Gauss-Markov correlation time (s)",
                    value: tc.value(),
                    uncertainty: tc.uncertainty(),
                    reason,
                });
            }
            Some(_) => {}
        }
    }
    if flicker.value() > 0.0 {
        if bias_from_gm {
            not_written.push(NotWritten {
                term: "flicker bias instability B",
                value: flicker.value(),
                uncertainty: flicker.uncertainty(),
                reason: gm.map_or_else(String::new, |g| {
                    format!(
                        "the Gauss-Markov alternative fits the curve better (weighted residual {} against {}) and is written instead; both would count the same wander twice",
                        sig(g.rss(), 4),
                        sig(g.power_rss(), 4)
                    )
                }),
            });
        } else if flicker.value() > noise_max {
            not_written.push(NotWritten {
                term: "flicker bias instability B",
                value: flicker.value(),
                uncertainty: flicker.uncertainty(),
                reason: above(),
            });
        } else {
            written.push(Written::of("flicker_bias_instability", flicker));
        }
    }
    // the terms of the model whose bias is written (the joint fit's otherwise)
    let (q, n, k, r) = match gm.filter(|_| bias_from_gm) {
        Some(g) => (
            g.quantization(),
            g.white(),
            g.rate_random_walk(),
            g.rate_ramp(),
        ),
        None => (
            f.quantization_term(),
            f.white_term(),
            f.rate_random_walk_term(),
            f.rate_ramp_term(),
        ),
    };
    if n.value() > noise_max {
        not_written.push(NotWritten {
            term: "white noise N",
            value: n.value(),
            uncertainty: n.uncertainty(),
            reason: above(),
        });
    } else if n.value() == 0.0 {
        not_written.push(NotWritten {
            term: "white noise N",
            value: 0.0,
            uncertainty: None,
            reason: n.resolution().explain().into(),
        });
    } else {
        written.insert(0, Written::of("white_per_sqrt_hz", n));
    }
    // the drifts: the study's `rate_random_walk` (unit/sqrt(s)) and `rate_ramp` (unit/s), and
    // the angle quantization (unit*s), the same definitions as the fit's (sigma^2 = K^2 tau /
    // 3, R^2 tau^2 / 2, 3 Q^2 / tau^2)
    for (term, key, t) in [
        ("rate random walk K", "rate_random_walk", k),
        ("rate ramp R", "rate_ramp", r),
        ("quantization Q", "angle_quantization", q),
    ] {
        if t.value() > noise_max {
            not_written.push(NotWritten {
                term,
                value: t.value(),
                uncertainty: t.uncertainty(),
                reason: above(),
            });
        } else if t.value() > 0.0 {
            written.push(Written::of(key, t));
        }
    }
    NoiseBlock {
        bias_model: if bias_from_gm {
            "gauss_markov"
        } else {
            "flicker"
        },
        written,
        not_written,
    }
}

/// `allan --json`: the noise of the log, in the log's unit (`unit`, else the log's column's).
#[derive(Debug, Serialize)]
struct AllanJson<'a> {
    /// The log's name (its path, or standard input).
    log: &'a str,
    /// The column analysed.
    column: &'a str,
    /// `--unit`, else `null`.
    unit: Option<&'a str>,
    /// Samples in the log.
    samples: u64,
    /// The sampling rate, Hz.
    rate_hz: f64,
    /// The log's duration, s.
    duration_s: f64,
    /// The confidence of the bands (a fraction).
    confidence: f64,
    /// The overlap of the cluster times.
    overlap: u64,
    /// White noise N, the log's unit per sqrt(Hz).
    white_noise_per_sqrt_hz: f64,
    /// Its uncertainty (`null` when not estimated), same unit.
    white_noise_uncertainty: Option<f64>,
    /// Bias instability B, the log's unit.
    bias_instability: f64,
    /// Its uncertainty (`null` when not estimated), the log's unit.
    bias_instability_uncertainty: Option<f64>,
    /// The flicker floor's factor (B = floor / factor).
    floor_factor: f64,
    /// The floor's cluster time, s.
    floor_tau_s: f64,
    /// The floor's measured Allan deviation, the log's unit.
    floor_adev: f64,
    /// Whether the curve reached its floor.
    floor_reached: bool,
    /// Rate random walk (`null` when not fitted).
    rate_random_walk: Option<f64>,
    /// Its uncertainty (`null` when not estimated).
    rate_random_walk_uncertainty: Option<f64>,
    /// Quantization noise (`null` when not fitted).
    quantization: Option<f64>,
    /// Rate ramp (`null` when not fitted).
    rate_ramp: Option<f64>,
    /// The joint fit's terms, each `{value, uncertainty, resolution}`.
    terms: serde_json::Map<String, serde_json::Value>,
    /// The Gauss-Markov alternative (`null` for an all-zero curve).
    gauss_markov: Option<allan::GaussMarkovFit>,
    /// What `--write-noise` writes and what it cannot.
    noise_block: NoiseBlock,
    /// The curve: the library's points as its `serde` feature writes them.
    curve: &'a [allan::AllanPoint],
}

fn json_of<'a>(log: &'a Log, unit: Option<&'a str>) -> AllanJson<'a> {
    let a = &log.analysis;
    let f = &a.fit();
    AllanJson {
        log: &log.name,
        column: &log.column,
        unit,
        samples: a.samples(),
        rate_hz: a.rate_hz(),
        duration_s: a.samples() as f64 / a.rate_hz(),
        confidence: a.confidence(),
        overlap: a.overlap(),
        white_noise_per_sqrt_hz: f.white_noise(),
        white_noise_uncertainty: f.white_noise_uncertainty(),
        bias_instability: f.bias_instability(),
        bias_instability_uncertainty: f.bias_instability_uncertainty(),
        floor_factor: FLICKER_FLOOR_FACTOR,
        floor_tau_s: f.floor_tau_s(),
        floor_adev: f.floor_adev_measured(),
        floor_reached: f.floor_reached(),
        rate_random_walk: f.rate_random_walk(),
        rate_random_walk_uncertainty: f.rate_random_walk_uncertainty(),
        quantization: f.quantization(),
        rate_ramp: f.rate_ramp(),
        terms: joint_terms(a)
            .iter()
            .map(|(k, t)| (k.to_string(), serde_json::to_value(t).unwrap_or_default()))
            .collect(),
        gauss_markov: f.gauss_markov(),
        noise_block: noise_block(a),
        curve: a.points(),
    }
}

fn text_of(log: &Log, unit: &str) -> String {
    let a = &log.analysis;
    let f = &a.fit();
    let pm = |u: Option<f64>| u.map_or(String::new(), |u| format!(" (+- {})", sig(u, 2)));
    let mut t = format!(
        "Allan deviation of {}, column `{}`: {} samples at {} Hz ({} s); bands at {} % confidence\n",
        log.name.escape_debug(),
        log.column.escape_debug(),
        a.samples(),
        sig(a.rate_hz(), 6),
        sig(a.samples() as f64 / a.rate_hz(), 4),
        sig(100.0 * a.confidence(), 3)
    );
    t.push_str(&format!(
        "white noise N        {} {unit}/sqrt(Hz){}: the -1/2 line at tau = 1 s\n",
        sig(f.white_noise(), 4),
        pm(f.white_noise_uncertainty())
    ));
    t.push_str(&format!(
        "bias instability B   {} {unit}{}: the floor {} {unit} / 0.664{}\n",
        sig(f.bias_instability(), 4),
        pm(f.bias_instability_uncertainty()),
        sig(f.bias_instability() * FLICKER_FLOOR_FACTOR, 4),
        if f.floor_reached() {
            ""
        } else {
            " (an upper bound: the curve still falls at the longest cluster time)"
        }
    ));
    t.push_str(&format!(
        "floor cluster time   {} s (not a correlation time: see the Gauss-Markov fit below)\n",
        sig(f.floor_tau_s(), 4)
    ));
    if let Some(k) = f.rate_random_walk() {
        t.push_str(&format!(
            "rate random walk K   {} {unit}*sqrt(Hz){}: the +1/2 line at tau = 3 s\n",
            sig(k, 4),
            pm(f.rate_random_walk_uncertainty())
        ));
    }
    let term_line = |name: &str, unit_of: &str, term: Term| {
        let status = if term.resolution().is_resolved() {
            String::new()
        } else {
            format!(": {}", term.resolution().explain())
        };
        format!(
            "  {name:<30} {} {unit_of}{}{status}\n",
            sig(term.value(), 4),
            pm(term.uncertainty())
        )
    };
    t.push_str("\njoint weighted fit of the IEEE 952 / 1293 terms (1-sigma uncertainties):\n");
    for ((_, term), (name, unit_of)) in joint_terms(a).into_iter().zip([
        ("quantization Q", format!("{unit}*s")),
        ("white noise N", format!("{unit}/sqrt(Hz)")),
        ("bias instability B (flicker)", unit.to_string()),
        ("rate random walk K", format!("{unit}*sqrt(Hz)")),
        ("rate ramp R", format!("{unit}/s")),
    ]) {
        t.push_str(&term_line(name, &unit_of, term));
    }
    if let Some(g) = f.gauss_markov() {
        t.push_str("Gauss-Markov alternative (correlation time fitted, other terms profiled):\n");
        t.push_str(&term_line("Gauss-Markov sigma", unit, g.sigma()));
        t.push_str(&term_line("correlation time Tc", "s", g.correlation_s()));
        t.push_str(&term_line(
            "white noise N",
            &format!("{unit}/sqrt(Hz)"),
            g.white(),
        ));
        t.push_str(&format!(
            "  weighted residual {} (power terms: {})\n",
            sig(g.rss(), 4),
            sig(g.power_rss(), 4)
        ));
    }
    t.push_str(&format!(
        "\n{:>12} {:>12} {:>12} {:>12} {:>10}  {:<13} {:>12} {:>12} {:>12}\n",
        "tau (s)", "adev", "lower", "upper", "edf", "noise (band)", "mdev", "hdev", "totdev"
    ));
    for p in a.points() {
        t.push_str(&format!(
            "{:>12} {:>12} {:>12} {:>12} {:>10}  {:<13} {:>12} {:>12} {:>12}\n",
            sig(p.tau_s(), 4),
            sig(p.adev(), 4),
            sig(p.lower(), 4),
            sig(p.upper(), 4),
            sig(p.edf(), 3),
            p.noise().to_string(),
            sig(p.mdev(), 4),
            sig(p.hdev(), 4),
            sig(p.totdev(), 4)
        ));
    }
    t
}

fn noise_toml(log: &Log, unit: &str, block: &NoiseBlock) -> String {
    let a = &log.analysis;
    let pm = |u: Option<f64>| u.map_or(String::new(), |u| format!(" +- {}", sig(u, 3)));
    let bias = if block.bias_model == "gauss_markov" {
        "the bias is the first-order\n\
         # Gauss-Markov alternative, whose correlation time is fitted and whose fit is better"
    } else {
        "the bias is the flicker floor\n\
         # of the joint fit (the Gauss-Markov alternative, if any, fits no better)"
    };
    let mut t = format!(
        "# Noise of column `{}` of {}: {} samples at {} Hz, by `cargo xtask allan` (IEEE Std 952\n\
         # Annex C: a joint weighted fit of the Allan variance; {bias}).\n\
         # The values are in the log's unit ({unit}): white_per_sqrt_hz in {unit}/sqrt(Hz),\n\
         # bias_instability in {unit}, bias_correlation_s in s, rate_random_walk in\n\
         # {unit}/sqrt(s), rate_ramp in {unit}/s, flicker_bias_instability in {unit},\n\
         # angle_quantization in {unit}*s. Convert them if the output's unit differs from the\n\
         # log's.\n",
        log.column.escape_debug(),
        log.name.escape_debug(),
        a.samples(),
        sig(a.rate_hz(), 15),
    );
    t.push_str("# Standard uncertainties (the schema has no key for them):");
    for w in &block.written {
        t.push_str(&format!(
            " {} = {}{};",
            w.key,
            sig(w.value, 4),
            pm(w.uncertainty)
        ));
    }
    t.push('\n');
    let unresolved: Vec<&Written> = block
        .written
        .iter()
        .filter(|w| w.not_resolved.is_some())
        .collect();
    if !unresolved.is_empty() {
        t.push_str("# Written as fitted, but the log cannot resolve them:\n");
        for w in unresolved {
            t.push_str(&format!(
                "# - {}: {}\n",
                w.key,
                w.not_resolved.unwrap_or_default()
            ));
        }
    }
    if !block.not_written.is_empty() {
        t.push_str("# Not written (the study cannot take them):\n");
        for n in &block.not_written {
            t.push_str(&format!(
                "# - {} = {}{}: {}\n",
                n.term,
                sig(n.value, 4),
                pm(n.uncertainty),
                n.reason
            ));
        }
    }
    t.push_str("[sensor.outputs.noise]\n");
    for w in &block.written {
        t.push_str(&format!("{} = {:?}\n", w.key, w.value));
    }
    // the standard uncertainties the study accepts, for end-to-end's sensitivity
    let (_, tc_hi) = study::limits::CORRELATION_S;
    let u: Vec<(&str, f64)> = block
        .written
        .iter()
        .filter_map(|w| {
            let hi = if w.key == "bias_correlation_s" {
                tc_hi
            } else {
                study::limits::NOISE_MAX
            };
            w.uncertainty
                .filter(|u| u.is_finite() && *u >= 0.0 && *u <= hi)
                .map(|u| (w.key, u))
        })
        .collect();
    if !u.is_empty() {
        t.push_str("[sensor.outputs.noise.uncertainty]\n");
        for (key, u) in u {
            t.push_str(&format!("{key} = {u:?}\n"));
        }
    }
    t
}

/// The log-log figure: the curve with its band, the fitted -1/2 line and the floor.
fn figure_svg(log: &Log, unit: &str) -> Result<String> {
    let a = &log.analysis;
    let f = &a.fit();
    let what = "Allan deviation figure";
    finite(what, numbers(a))?;
    if let Some(p) = a.points().iter().find(|p| p.lower() <= 0.0) {
        return Err(InputError::new(
            "--figure",
            format!(
                "the Allan deviation (or its band) is zero at tau = {} s: nothing to draw on a log scale",
                sig(p.tau_s(), 4)
            ),
        )
        .into());
    }
    let x0 = a.points()[0].tau_s();
    let x1 = a.points()[a.points().len() - 1].tau_s();
    let (x0, x1) = (x0 / 1.5, x1 * 1.5);
    let mut y0 = a
        .points()
        .iter()
        .map(|p| p.lower())
        .fold(f64::INFINITY, f64::min);
    // the other deviations, drawn where every point is positive (a log scale)
    type Dev = fn(&allan::AllanPoint) -> f64;
    let others: Vec<(&str, Dev)> = [
        ("modified Allan deviation", allan::AllanPoint::mdev as Dev),
        (
            "overlapping Hadamard deviation",
            allan::AllanPoint::hdev as Dev,
        ),
        ("total deviation", allan::AllanPoint::totdev as Dev),
    ]
    .into_iter()
    .filter(|(_, d)| a.points().iter().all(|p| d(p) > 0.0))
    .collect();
    for (_, d) in &others {
        y0 = a.points().iter().map(d).fold(y0, f64::min);
    }
    let y1 = others.iter().fold(
        a.points().iter().map(|p| p.upper()).fold(0.0, f64::max),
        |m, (_, d)| a.points().iter().map(d).fold(m, f64::max),
    );
    let floor = f.bias_instability() * FLICKER_FLOOR_FACTOR;
    if floor > 0.0 {
        y0 = y0.min(floor);
    }
    let (y0, y1) = (y0 / 2.0, y1 * 2.0);
    let white = |t: f64| f.white_noise() / t.sqrt();
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (WIDTH, 640)).into_drawing_area();
        root.fill(&WHITE).map_err(|e| anyhow!("{what}: {e:?}"))?;
        let title = format!(
            "Allan deviation of {}, column {} ({} samples at {} Hz)",
            log.name.escape_debug(),
            log.column.escape_debug(),
            a.samples(),
            sig(a.rate_hz(), 6)
        );
        let mut chart = ChartBuilder::on(&root)
            .caption(title, ("sans-serif", 19))
            .margin(16)
            .x_label_area_size(48)
            .y_label_area_size(90)
            .build_cartesian_2d(
                (x0..x1).log_scale().with_key_points(log_ticks(x0, x1)),
                (y0..y1).log_scale().with_key_points(log_ticks(y0, y1)),
            )
            .map_err(|e| anyhow!("{what}: {e:?}"))?;
        chart
            .configure_mesh()
            .x_desc("cluster time tau (s)")
            .y_desc(format!("Allan deviation ({unit})"))
            .x_label_formatter(&|v| sig(*v, 3))
            .y_label_formatter(&|v| sig(*v, 3))
            .light_line_style(TRANSPARENT)
            .bold_line_style(RGBColor(225, 225, 225))
            .draw()
            .map_err(|e| anyhow!("{what}: {e:?}"))?;
        let band: Vec<(f64, f64)> = a
            .points()
            .iter()
            .map(|p| (p.tau_s(), p.upper()))
            .chain(a.points().iter().rev().map(|p| (p.tau_s(), p.lower())))
            .collect();
        let c = colour(0);
        chart
            .draw_series(std::iter::once(Polygon::new(band, c.mix(0.18).filled())))
            .map_err(|e| anyhow!("{what}: {e:?}"))?
            .label(format!("{} % band", sig(100.0 * a.confidence(), 3)))
            .legend(move |(x, y)| {
                Rectangle::new([(x, y - 6), (x + 20, y + 6)], c.mix(0.18).filled())
            });
        chart
            .draw_series(LineSeries::new(
                a.points().iter().map(|p| (p.tau_s(), p.adev())),
                c.stroke_width(2),
            ))
            .map_err(|e| anyhow!("{what}: {e:?}"))?
            .label("overlapping Allan deviation")
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], c.stroke_width(2)));
        chart
            .draw_series(
                a.points()
                    .iter()
                    .map(|p| Circle::new((p.tau_s(), p.adev()), 3, c.filled())),
            )
            .map_err(|e| anyhow!("{what}: {e:?}"))?;
        for (k, (name, d)) in others.iter().enumerate() {
            let oc = colour(2 + k);
            chart
                .draw_series(LineSeries::new(
                    a.points().iter().map(|p| (p.tau_s(), d(p))),
                    oc.stroke_width(1),
                ))
                .map_err(|e| anyhow!("{what}: {e:?}"))?
                .label(*name)
                .legend(move |(x, y)| {
                    PathElement::new(vec![(x, y), (x + 20, y)], oc.stroke_width(1))
                });
        }
        if f.white_noise() > 0.0 {
            let w = colour(1);
            // the -1/2 line where it lies inside the plot
            let pts: Vec<(f64, f64)> = (0..=64)
                .map(|i| x0 * (x1 / x0).powf(f64::from(i) / 64.0))
                .map(|t| (t, white(t)))
                .filter(|(_, v)| *v >= y0 && *v <= y1)
                .collect();
            chart
                .draw_series(LineSeries::new(pts, w.stroke_width(2)))
                .map_err(|e| anyhow!("{what}: {e:?}"))?
                .label(format!(
                    "white noise N / sqrt(tau), N = {} {unit}/sqrt(Hz)",
                    sig(f.white_noise(), 3)
                ))
                .legend(move |(x, y)| {
                    PathElement::new(vec![(x, y), (x + 20, y)], w.stroke_width(2))
                });
        }
        if floor > 0.0 {
            chart
                .draw_series(LineSeries::new(
                    [(x0, floor), (x1, floor)],
                    LIMIT.stroke_width(2),
                ))
                .map_err(|e| anyhow!("{what}: {e:?}"))?
                .label(format!(
                    "floor 0.664 B, B = {} {unit} (at tau = {} s)",
                    sig(f.bias_instability(), 3),
                    sig(f.floor_tau_s(), 3)
                ))
                .legend(move |(x, y)| {
                    PathElement::new(vec![(x, y), (x + 20, y)], LIMIT.stroke_width(2))
                });
        }
        chart
            .configure_series_labels()
            .position(SeriesLabelPosition::LowerLeft)
            .background_style(WHITE.mix(0.9))
            .border_style(BLACK.mix(0.3))
            .label_font(("sans-serif", 14))
            .draw()
            .map_err(|e| anyhow!("{what}: {e:?}"))?;
        root.present().map_err(|e| anyhow!("{what}: {e:?}"))?;
    }
    Ok(svg)
}

/// Tick values of a log axis over `[lo, hi]`: 1, 2, 5 times the powers of ten, or the powers
/// of ten alone over more than four decades.
fn log_ticks(lo: f64, hi: f64) -> Vec<f64> {
    let first = lo.log10().floor() as i32;
    let last = hi.log10().ceil() as i32;
    let steps: &[f64] = if last - first > 4 {
        &[1.0]
    } else {
        &[1.0, 2.0, 5.0]
    };
    (first..=last)
        .flat_map(|e| steps.iter().map(move |s| s * 10f64.powi(e)))
        .filter(|v| *v >= lo && *v <= hi)
        .collect()
}

/// Run the command.
///
/// # Errors
/// [`InputError`] for bad input (exit 2, nothing on standard output); other errors for a
/// failing disk.
pub fn run(args: &Args) -> Result<()> {
    let outputs: Vec<(&str, &Path)> = [
        ("--figure", &args.figure),
        ("--write-noise", &args.write_noise),
    ]
    .into_iter()
    .filter_map(|(f, p)| p.as_deref().map(|p| (f, p)))
    .collect();
    crate::newfile::check_all(&outputs)?;
    let source = Source::from_arg(args.log.as_deref());
    let log = read_log(&source, args)?;
    let unit = args.unit.as_deref().unwrap_or("log unit");
    let nums = numbers(&log.analysis);
    if nums.iter().any(|v| !v.is_finite()) {
        bail!(
            "internal: a non-finite number in the analysis of {}",
            log.name
        );
    }
    let stdout = if args.json {
        let mut s = serde_json::to_string_pretty(&serde_json::to_value(json_of(
            &log,
            args.unit.as_deref(),
        ))?)?;
        s.push('\n');
        s
    } else {
        text_of(&log, unit)
    };
    let mut staged = Vec::new();
    if let Some(p) = &args.figure {
        staged.push((
            "--figure",
            crate::newfile::stage(p, figure_svg(&log, unit)?.as_bytes())?,
            p,
        ));
    }
    if let Some(p) = &args.write_noise {
        let block = noise_block(&log.analysis);
        if block.written.is_empty() {
            let why: Vec<String> = block
                .not_written
                .iter()
                .map(|n| format!("{}: {}", n.term, n.reason))
                .collect();
            return Err(InputError::new(
                "--write-noise",
                format!(
                    "the log gives no noise term a study accepts ({}); nothing written",
                    why.join("; ")
                ),
            )
            .into());
        }
        for n in &block.not_written {
            eprintln!(
                "allan: not written to {}: {} = {}: {}",
                p.display().to_string().escape_debug(),
                n.term,
                sig(n.value, 4),
                n.reason
            );
        }
        staged.push((
            "--write-noise",
            crate::newfile::stage(p, noise_toml(&log, unit, &block).as_bytes())?,
            p,
        ));
    }
    let mut written = String::new();
    for (flag, tmp, p) in staged {
        tmp.commit(flag)?;
        if !args.json {
            written.push_str(&format!("wrote {}\n", crate::paths::visible(p)));
        }
    }
    crate::out::print(&(stdout + &written))
}
