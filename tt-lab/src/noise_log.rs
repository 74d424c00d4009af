//! The noise of a sensor from a log of its output (a rate or a specific force sampled at a
//! known rate): the `allan` crate's analysis of one column of a CSV log, read once and
//! streaming (memory does not grow with the log's length), and the noise block a study
//! accepts, written from it (`[sensor.outputs.noise]`): every term of one model, the bias
//! from the joint fit's flicker floor or the Gauss-Markov alternative, whichever fits better
//! inside the study's limits, never both.
//!
//! The log: a header line naming the columns, then one numeric row per sample (RFC 4180
//! quoting, a UTF-8 byte-order mark accepted, blank lines skipped, fields may be surrounded
//! by spaces, no line longer than [`MAX_LINE_BYTES`]), read by [`crate::records`].

use crate::error::{InputError, LabError, Result};
pub use crate::records::MAX_LINE_BYTES;
use crate::records::for_each_record;
use allan::{AllanError, Analysis, FLICKER_FLOOR_FACTOR, Settings, StreamingAllan, Taus, Term};
use std::io::Read;
use tt_core::human::sig;

/// How to analyse the log.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct Options {
    /// Sample rate of the log, Hz (set it: the default, 1 Hz, is a placeholder).
    pub rate_hz: f64,
    /// The column analysed (`None`: the only one).
    pub column: Option<String>,
    /// Confidence of the bands, a probability.
    pub confidence: f64,
    /// The cluster times.
    pub taus: Taus,
}

impl Default for Options {
    fn default() -> Self {
        Self {
            rate_hz: 1.0,
            column: None,
            confidence: allan::chi2::ONE_SIGMA,
            taus: Taus::default(),
        }
    }
}

impl Options {
    /// The default options at sample rate `rate_hz`.
    #[must_use]
    pub fn at_rate_hz(rate_hz: f64) -> Self {
        Self {
            rate_hz,
            ..Self::default()
        }
    }
}

/// The analysis of one column of a log.
#[derive(Debug)]
#[non_exhaustive]
pub struct NoiseLog {
    name: String,
    column: String,
    analysis: Analysis,
}

impl NoiseLog {
    /// The log's name (its path, or standard input).
    #[must_use]
    pub fn name(&self) -> &str {
        &self.name
    }

    /// The column analysed.
    #[must_use]
    pub fn column(&self) -> &str {
        &self.column
    }

    /// The analysis (deviations, fits).
    #[must_use]
    pub fn analysis(&self) -> &Analysis {
        &self.analysis
    }

    /// The noise block a study accepts, and what it cannot take.
    #[must_use]
    pub fn noise_block(&self) -> NoiseBlock {
        noise_block(&self.analysis)
    }

    /// The study's noise block as TOML (commented: the log, the bias model, each value's
    /// uncertainty, the terms not resolved or not written), in the log's `unit`.
    #[must_use]
    pub fn noise_toml(&self, unit: &str, block: &NoiseBlock) -> String {
        noise_toml(self, unit, block)
    }

    /// The JSON view (`allan --json`); `unit`: the log's unit if given.
    #[cfg(feature = "serde")]
    #[must_use]
    pub fn view<'a>(&'a self, unit: Option<&'a str>) -> impl serde::Serialize + 'a {
        json_of(self, unit)
    }
}

/// The library's message without its leading field name (the flag names it instead).
fn without_field(e: &AllanError) -> String {
    let m = e.to_string();
    m.strip_prefix("taus: ").map_or(m.clone(), str::to_string)
}

/// The cell of one sample, checked.
fn sample(at: &str, column: &str, cell: &str) -> Result<f64, InputError> {
    let v: f64 = cell.parse().map_err(|_| {
        InputError::new(
            at,
            format!(
                "`{}`: `{}` is not a number",
                column.escape_debug(),
                cell.escape_debug()
            ),
        )
    })?;
    if !v.is_finite() {
        return Err(InputError::new(
            at,
            format!(
                "`{}`: `{}` is not a finite number",
                column.escape_debug(),
                cell.escape_debug()
            ),
        ));
    }
    Ok(v)
}

/// The analysis of one column of the log `log` (named `name` in messages), read once.
///
/// # Errors
/// An [`InputError`] naming the flag (`--rate-hz`, `--taus`, `--column`) or the line and
/// column of the log; a library failure for a non-finite number in the analysis.
pub fn analyse<R: Read>(log: R, name: &str, o: &Options) -> Result<NoiseLog> {
    let settings = Settings::new(o.rate_hz)
        .confidence(o.confidence)
        .taus(o.taus.clone());
    let mut est = StreamingAllan::new(settings).map_err(|e| match e {
        AllanError::InvalidTau { .. } => InputError::new("--taus", without_field(&e)),
        other => InputError::new("--rate-hz", other.to_string()),
    })?;
    let mut layout: Option<(usize, usize, String)> = None;
    for_each_record(log, name, |line_no, cells| {
        let Some((index, count, column)) = &layout else {
            layout = Some(pick_column(name, line_no, cells, o.column.as_deref())?);
            return Ok(());
        };
        if cells.len() != *count {
            return Err(InputError::new(
                format!("{name}:{line_no}"),
                format!("expected {count} columns, found {}", cells.len()),
            ));
        }
        let at = format!("{name}:{line_no} column {}", index + 1);
        let v = sample(&at, column, cells[*index])?;
        est.push(v).map_err(|e| InputError::new(at, e.to_string()))
    })?;
    let Some((_, _, column)) = layout else {
        return Err(InputError::new(
            name,
            "empty input: expected a header line naming the columns, then one sample per line",
        )
        .into());
    };
    let analysis = est.analyse().map_err(|e| match e {
        AllanError::TooFewSamples { samples, needed } => InputError::new(
            name,
            format!(
                "column `{}` has {samples} samples; the shortest cluster time (one sample) needs at least {needed} (three clusters)",
                column.escape_debug()
            ),
        ),
        AllanError::ClusterTooLong { .. } => InputError::new("--taus", without_field(&e)),
        other => InputError::new(name, other.to_string()),
    })?;
    if numbers(&analysis).iter().any(|v| !v.is_finite()) {
        return Err(LabError::Library(
            format!("internal: a non-finite number in the analysis of {name}").into(),
        ));
    }
    Ok(NoiseLog {
        name: name.to_string(),
        column,
        analysis,
    })
}

/// The joint fit's terms, serialised as an object keyed by term.
#[derive(Debug)]
#[cfg_attr(not(feature = "serde"), allow(dead_code))]
pub(crate) struct Terms([(&'static str, Term); 5]);

#[cfg(feature = "serde")]
impl serde::Serialize for Terms {
    fn serialize<S: serde::Serializer>(&self, s: S) -> std::result::Result<S::Ok, S::Error> {
        use serde::ser::SerializeMap;
        let mut m = s.serialize_map(Some(self.0.len()))?;
        for (k, t) in &self.0 {
            m.serialize_entry(k, t)?;
        }
        m.end()
    }
}

/// The column to read, from the header line.
fn pick_column(
    name: &str,
    line_no: usize,
    cols: &[&str],
    wanted: Option<&str>,
) -> Result<(usize, usize, String), InputError> {
    let at = format!("{name}:{line_no}");
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

/// Every number of the analysis, for the no-NaN check.
pub fn numbers(a: &Analysis) -> Vec<f64> {
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
pub fn joint_terms(a: &Analysis) -> [(&'static str, Term); 5] {
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
#[derive(Debug)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
#[cfg_attr(not(feature = "serde"), allow(dead_code))]
pub struct Written {
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
#[derive(Debug)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
#[cfg_attr(not(feature = "serde"), allow(dead_code))]
pub struct NotWritten {
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
#[derive(Debug)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
#[cfg_attr(not(feature = "serde"), allow(dead_code))]
pub struct NoiseBlock {
    /// The bias model written: `flicker` (the joint fit's floor) or `gauss_markov`.
    bias_model: &'static str,
    /// The keys written.
    written: Vec<Written>,
    /// The terms not written, and why.
    not_written: Vec<NotWritten>,
}

impl NoiseBlock {
    /// The bias model written: `flicker` (the joint fit's floor) or `gauss_markov`.
    #[must_use]
    pub fn bias_model(&self) -> &'static str {
        self.bias_model
    }

    /// The keys written.
    #[must_use]
    pub fn written(&self) -> &[Written] {
        &self.written
    }

    /// The terms not written, and why.
    #[must_use]
    pub fn not_written(&self) -> &[NotWritten] {
        &self.not_written
    }
}

impl NotWritten {
    /// The term, in words.
    #[must_use]
    pub fn term(&self) -> &'static str {
        self.term
    }

    /// Its fitted value.
    #[must_use]
    pub fn value(&self) -> f64 {
        self.value
    }

    /// Why it is not written.
    #[must_use]
    pub fn reason(&self) -> &str {
        &self.reason
    }
}

/// Why the Gauss-Markov bias `g` (its bias instability `b`) is not written, if it is not: its
/// correlation time not resolved or outside the study's limits, `b` above the study's limit,
/// or the joint fit's flicker floor fitting as well or better.
fn gauss_markov_refusal(g: &allan::GaussMarkovFit, flicker: Term, b: f64) -> Option<String> {
    let tc = g.correlation_s();
    let noise_max = study::limits::NOISE_MAX;
    let (tc_lo, tc_hi) = study::limits::CORRELATION_S;
    if !tc.resolution().is_resolved() {
        Some(format!(
            "its correlation time is not resolved: {}",
            tc.resolution().explain()
        ))
    } else if !(tc.value() > tc_lo && tc.value() <= tc_hi) {
        Some(format!(
            "bias_correlation_s = {} s is outside the study's limit ({}, {}] s",
            sig(tc.value(), 6),
            tt_core::human::num(tc_lo),
            tt_core::human::num(tc_hi)
        ))
    } else if b > noise_max {
        Some(format!(
            "bias_instability = {} is above the study's limit {}",
            sig(b, 6),
            tt_core::human::num(noise_max)
        ))
    } else if flicker.value() > 0.0 && g.rss() >= g.power_rss() {
        Some(format!(
            "the joint fit's flicker floor fits the curve as well or better (weighted residual {} against {}); both would count the same wander twice",
            sig(g.power_rss(), 4),
            sig(g.rss(), 4)
        ))
    } else {
        None
    }
}

/// The study's noise block of the analysis: only keys and values a study accepts
/// (`study::limits`); every other term listed with its reason. The bias is the joint fit's
/// flicker floor (`flicker_bias_instability`), or the Gauss-Markov alternative
/// (`bias_instability` with its fitted `bias_correlation_s`) when its correlation time is
/// resolved inside the study's limits and it fits the curve better (a lower weighted
/// residual); never both (they model the same wander). The other terms come from the model
/// whose bias is written.
pub(crate) fn noise_block(a: &Analysis) -> NoiseBlock {
    use gw_model::noise::{FLICKER_FLOOR_PER_BIAS_INSTABILITY, GM_ADEV_PEAK_PER_SIGMA};
    let f = a.fit();
    let noise_max = study::limits::NOISE_MAX;
    let mut written = Vec::new();
    let mut not_written = Vec::new();
    let above = || format!("above the study's limit {}", tt_core::human::num(noise_max));
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
        let why = gauss_markov_refusal(&g, flicker, b);
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
#[derive(Debug)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
#[cfg_attr(not(feature = "serde"), allow(dead_code))]
pub(crate) struct AllanJson<'a> {
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
    terms: Terms,
    /// The Gauss-Markov alternative (`null` for an all-zero curve).
    gauss_markov: Option<allan::GaussMarkovFit>,
    /// What `--write-noise` writes and what it cannot.
    noise_block: NoiseBlock,
    /// The curve: the library's points as its `serde` feature writes them.
    curve: &'a [allan::AllanPoint],
}

fn json_of<'a>(log: &'a NoiseLog, unit: Option<&'a str>) -> AllanJson<'a> {
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
        terms: Terms(joint_terms(a)),
        gauss_markov: f.gauss_markov(),
        noise_block: noise_block(a),
        curve: a.points(),
    }
}

/// `# {heading}:` and one `# - {item}` line per item into `t`, nothing when there is no item.
fn push_listed(t: &mut String, heading: &str, items: impl Iterator<Item = String>) {
    let mut items = items.peekable();
    if items.peek().is_some() {
        t.push_str(&format!("# {heading}:\n"));
        for item in items {
            t.push_str(&format!("# - {item}\n"));
        }
    }
}

fn noise_toml(log: &NoiseLog, unit: &str, block: &NoiseBlock) -> String {
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
    let unresolved = block
        .written
        .iter()
        .filter_map(|w| Some(format!("{}: {}", w.key, w.not_resolved?)));
    push_listed(
        &mut t,
        "Written as fitted, but the log cannot resolve them",
        unresolved,
    );
    let not_written = block.not_written.iter().map(|n| {
        format!(
            "{} = {}{}: {}",
            n.term,
            sig(n.value, 4),
            pm(n.uncertainty),
            n.reason
        )
    });
    push_listed(
        &mut t,
        "Not written (the study cannot take them)",
        not_written,
    );
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
