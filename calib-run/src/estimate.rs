//! The estimate: segment averages to coefficients, covariances, budget, verdicts.

use crate::error::RunError;
use crate::recording::{RecordingOptions, RecordingSummary, Row, read_rows};
use crate::segments::{
    Acc, BlockTest, DetectSettings, Detected, Detector, POSE_Z, ROTATION_MATCH_DEG, SegmentKind,
    SegmentSpec, StaticAcc,
};
use calib_lsq::Regression;
use gw_model::{Input, InputValues, Inputs, Output};
use metrology::decision::{DecisionRule, Measured, Tolerance, decide};
use metrology::{Budget, BudgetSettings, Input as MInput};
use nalgebra::{DMatrix, DVector, Vector3};
use std::io::Read;
use study::Study;
use tt_kinematics::{ChainKind, Pose, RateEnvironment, RateErrorValues, RateStep, TurntableErrors};

/// A segment whose standardized residual exceeds this is flagged an outlier.
pub const OUTLIER_Z: f64 = 3.0;

/// Huber's tuning constant (95 % efficiency at the normal), in standardized residuals.
pub(crate) const HUBER_C: f64 = 1.345;

/// Iterations of the robust fit at most.
const HUBER_MAX_ITER: usize = 100;

/// The robust fit stops when no weight moves by more than this.
const HUBER_WEIGHT_TOL: f64 = 1e-9;

/// Step of the table-error finite difference, rad.
const TABLE_STEP_RAD: f64 = 1e-6;

/// How to process a recording.
#[derive(Debug, Clone)]
pub struct CalibrateOptions {
    /// Columns, time, sample rate, range.
    pub recording: RecordingOptions,
    /// Segments from a file (`None`: detected).
    pub segments: Option<Vec<SegmentSpec>>,
    /// Detection settings.
    pub detect: DetectSettings,
    /// Run the robust (Huber) fit too and report what it changed; its estimate is the one
    /// written.
    pub robust: bool,
    /// Coverage probability of the expanded uncertainties.
    pub coverage: f64,
    /// The table's tolerance sheet (the table's part of the budget), if given.
    pub tolerances: Option<study::Tolerances>,
}

impl Default for CalibrateOptions {
    fn default() -> Self {
        CalibrateOptions {
            recording: RecordingOptions::default(),
            segments: None,
            detect: DetectSettings::default(),
            robust: false,
            coverage: 0.95,
            tolerances: None,
        }
    }
}

/// The noise of one output measured on the static segments.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct MeasuredNoise {
    /// White noise density (the Allan fit's, pooled over the static segments by samples),
    /// output unit per sqrt(Hz).
    pub white_per_sqrt_hz: f64,
    /// The Allan deviation's floor where a segment's curve reaches one (pooled), output unit;
    /// 0 where none does.
    pub floor: f64,
    /// Static samples analysed.
    pub samples: u64,
    /// The study's white density, for comparison (`None` where the study has no noise).
    pub study_white_per_sqrt_hz: Option<f64>,
}

impl MeasuredNoise {
    /// Variance of a segment's average over `duration_s`: $N^2/T$ + floor$^2$.
    #[must_use]
    pub(crate) fn variance_of_mean(&self, duration_s: f64) -> f64 {
        self.white_per_sqrt_hz.powi(2) / duration_s + self.floor.powi(2)
    }
}

/// One segment as processed.
#[derive(Debug, Clone, serde::Serialize)]
pub struct Segment {
    pub(crate) entry: usize,
    pub(crate) kind: SegmentKind,
    pub(crate) start_sample: u64,
    pub(crate) samples: u64,
    pub(crate) first_line: u64,
    pub(crate) last_line: u64,
    pub(crate) t_start_s: f64,
    pub(crate) duration_s: f64,
    pub(crate) mean: Vec<f64>,
    pub(crate) std: Vec<f64>,
    pub(crate) angles_deg: Option<Vec<f64>>,
    pub(crate) turned_deg: Option<f64>,
    pub(crate) saturated: u64,
    #[serde(skip)]
    pub(crate) inputs: InputValues,
    #[serde(skip)]
    pub(crate) pose: Pose,
}

impl Segment {
    /// Schedule entry (static positions, then rate steps).
    #[must_use]
    pub fn entry(&self) -> usize {
        self.entry
    }
    /// Kind.
    #[must_use]
    pub fn kind(&self) -> SegmentKind {
        self.kind
    }
    /// First sample (0-based data row) and count.
    #[must_use]
    pub fn range(&self) -> (u64, u64) {
        (self.start_sample, self.samples)
    }
    /// Start time and duration, s.
    #[must_use]
    pub fn time_s(&self) -> (f64, f64) {
        (self.t_start_s, self.duration_s)
    }
    /// Each output's mean.
    #[must_use]
    pub fn mean(&self) -> &[f64] {
        &self.mean
    }
    /// The inputs the regression uses (g, deg/h).
    #[must_use]
    pub fn inputs(&self) -> &InputValues {
        &self.inputs
    }
}

/// One segment's residual for one output.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct ResidualRow {
    /// Index into [`Run::segments`].
    pub segment: usize,
    /// Observed minus fitted, output unit.
    pub residual: f64,
    /// Standardized by the measured noise and the leverage.
    pub standardized: f64,
    /// `|standardized| > OUTLIER_Z`.
    pub outlier: bool,
    /// The robust fit's weight (1 without `robust`).
    pub robust_weight: f64,
}

/// One coefficient's result.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct CoefficientResult {
    pub(crate) name: String,
    pub(crate) unit: String,
    pub(crate) value: f64,
    pub(crate) nominal: f64,
    pub(crate) u_measured_noise: f64,
    pub(crate) u_residuals: Option<f64>,
    pub(crate) u_table: f64,
    pub(crate) u_combined: f64,
    pub(crate) dof_eff: f64,
    pub(crate) k: f64,
    pub(crate) expanded: f64,
    pub(crate) predicted_u: Option<f64>,
    pub(crate) robust_change: Option<f64>,
    pub(crate) table_sensitivity: Vec<(String, f64)>,
}

impl CoefficientResult {
    /// The estimate's sensitivity to each toleranced table error (coefficient unit per rad;
    /// empty without a tolerance sheet).
    #[must_use]
    pub fn table_sensitivity(&self) -> &[(String, f64)] {
        &self.table_sensitivity
    }
    /// Name.
    #[must_use]
    pub fn name(&self) -> &str {
        &self.name
    }
    /// Unit.
    #[must_use]
    pub fn unit(&self) -> &str {
        &self.unit
    }
    /// The estimate.
    #[must_use]
    pub fn value(&self) -> f64 {
        self.value
    }
    /// Standard uncertainty from the measured noise alone.
    #[must_use]
    pub fn u_measured_noise(&self) -> f64 {
        self.u_measured_noise
    }
    /// Standard uncertainty from the residuals (`None` without redundancy).
    #[must_use]
    pub fn u_residuals(&self) -> Option<f64> {
        self.u_residuals
    }
    /// The table's part (0 without a tolerance sheet).
    #[must_use]
    pub fn u_table(&self) -> f64 {
        self.u_table
    }
    /// Combined standard uncertainty.
    #[must_use]
    pub fn u_combined(&self) -> f64 {
        self.u_combined
    }
    /// Expanded uncertainty and its coverage factor.
    #[must_use]
    pub fn expanded(&self) -> (f64, f64) {
        (self.expanded, self.k)
    }
    /// The plan's predicted standard uncertainty: the study's noise over the study's timing
    /// windows, for the entries the run's fit uses ([`OutputResult::predicted_basis`] says
    /// which, or why there is none).
    #[must_use]
    pub fn predicted_u(&self) -> Option<f64> {
        self.predicted_u
    }
    /// Robust minus ordinary estimate (with `robust`).
    #[must_use]
    pub fn robust_change(&self) -> Option<f64> {
        self.robust_change
    }
}

/// One output's result.
#[derive(Debug, Clone, serde::Serialize)]
pub struct OutputResult {
    pub(crate) name: String,
    pub(crate) unit: String,
    pub(crate) noise: MeasuredNoise,
    pub(crate) coefficients: Vec<CoefficientResult>,
    pub(crate) residuals: Vec<ResidualRow>,
    pub(crate) chi2: f64,
    pub(crate) dof: usize,
    pub(crate) birge_ratio: Option<f64>,
    pub(crate) notes: Vec<String>,
    pub(crate) predicted_basis: String,
}

impl OutputResult {
    /// What the coefficients' predicted standard uncertainty
    /// ([`CoefficientResult::predicted_u`]) is computed from, or why there is none.
    #[must_use]
    pub fn predicted_basis(&self) -> &str {
        &self.predicted_basis
    }
    /// Name.
    #[must_use]
    pub fn name(&self) -> &str {
        &self.name
    }
    /// The coefficients (estimated terms, model order).
    #[must_use]
    pub fn coefficients(&self) -> &[CoefficientResult] {
        &self.coefficients
    }
    /// Residuals per segment used.
    #[must_use]
    pub fn residuals(&self) -> &[ResidualRow] {
        &self.residuals
    }
    /// Measured noise.
    #[must_use]
    pub fn noise(&self) -> &MeasuredNoise {
        &self.noise
    }
    /// What the processing did that a reader must know (segments not used, what the robust
    /// fit down-weighted).
    #[must_use]
    pub fn notes(&self) -> &[String] {
        &self.notes
    }
    /// $\chi^2$ of the weighted residuals and its degrees of freedom.
    #[must_use]
    pub fn chi2(&self) -> (f64, usize) {
        (self.chi2, self.dof)
    }
}

/// A processed run.
#[derive(Debug, Clone, serde::Serialize)]
pub struct Run {
    pub(crate) study: String,
    pub(crate) study_sha256: String,
    pub(crate) recording: RecordingSummary,
    pub(crate) segments_source: &'static str,
    pub(crate) segments: Vec<Segment>,
    pub(crate) warnings: Vec<String>,
    pub(crate) outputs: Vec<OutputResult>,
    pub(crate) coverage: f64,
    pub(crate) robust: bool,
    pub(crate) budget_rule: String,
    #[serde(skip)]
    pub(crate) models: Vec<Output>,
}

impl Run {
    /// The recording.
    #[must_use]
    pub fn recording(&self) -> &RecordingSummary {
        &self.recording
    }
    /// Segments used.
    #[must_use]
    pub fn segments(&self) -> &[Segment] {
        &self.segments
    }
    /// Every mismatch and flag that did not stop the estimate.
    #[must_use]
    pub fn warnings(&self) -> &[String] {
        &self.warnings
    }
    /// Per output.
    #[must_use]
    pub fn outputs(&self) -> &[OutputResult] {
        &self.outputs
    }
    /// Coverage probability.
    #[must_use]
    pub fn coverage(&self) -> f64 {
        self.coverage
    }
    /// The coefficient named `name`.
    #[must_use]
    pub fn coefficient(&self, name: &str) -> Option<(&OutputResult, &CoefficientResult)> {
        self.outputs.iter().find_map(|o| {
            o.coefficients
                .iter()
                .find(|c| c.name == name)
                .map(|c| (o, c))
        })
    }
}

/// A specification of one coefficient: $|\beta| \le$ `limit` in `unit` (the coefficient's).
#[derive(Debug, Clone, PartialEq)]
pub struct Spec {
    /// The coefficient.
    pub coefficient: String,
    /// The limit (symmetric tolerance), coefficient unit.
    pub limit: f64,
    /// The unit the limit is given in (must be the coefficient's), if stated.
    pub unit: Option<String>,
}

/// A verdict on one specification.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Verdict {
    /// The coefficient.
    pub coefficient: String,
    /// Its unit.
    pub unit: String,
    /// The estimate.
    pub value: f64,
    /// Expanded uncertainty and coverage factor.
    pub expanded: f64,
    /// Coverage factor.
    pub k: f64,
    /// The limit.
    pub limit: f64,
    /// Meets under the rule.
    pub meets: bool,
    /// The rule, named.
    pub rule: String,
    /// One line: "bg_x = 0.61 +- 0.02 deg/h (k = 2.0); specification 0.5: does not meet
    /// (ILAC-G8 ...)".
    pub statement: String,
}

/// The verdict of every specification under `rule` (default of the command line: ILAC-G8
/// guard band w = U).
///
/// # Errors
/// [`RunError::Option`] (`--spec`) for an unknown coefficient, a unit that is not the
/// coefficient's, a limit that is not positive and finite.
pub fn verdicts(run: &Run, specs: &[Spec], rule: DecisionRule) -> Result<Vec<Verdict>, RunError> {
    specs
        .iter()
        .map(|s| {
            let (_, c) = run.coefficient(&s.coefficient).ok_or_else(|| {
                RunError::option(
                    "--spec",
                    format!("`{}` is not an estimated coefficient", s.coefficient),
                )
            })?;
            if let Some(u) = &s.unit {
                if *u != c.unit {
                    return Err(RunError::option(
                        "--spec",
                        format!(
                            "`{}` is in {}, the limit is given in {u}",
                            s.coefficient, c.unit
                        ),
                    ));
                }
            }
            judge("--spec", &s.coefficient, c, s.limit, 1.0, &c.unit, rule)
        })
        .collect()
}

/// The verdicts on the study's own `[[specifications]]` that this run can judge: each
/// specification of an estimated coefficient, in the unit it was written in (deg/h, ppm,
/// arcsec, ...), under `rule`. A specification of an error over a range or of eq 14's accuracy
/// is a specification of the plan (`end-to-end` answers it from the study's budget), not of one
/// run's estimates: it is named in the returned notes, never dropped in silence. A
/// specification at another coverage than the run's expanded uncertainties is noted too.
///
/// # Errors
/// [`RunError::Option`] (`specifications`) when a specified coefficient is not in the run.
pub fn study_verdicts(
    run: &Run,
    study: &Study,
    rule: DecisionRule,
) -> Result<(Vec<Verdict>, Vec<String>), RunError> {
    let outputs = study.sensor.outputs();
    let mut verdicts = Vec::new();
    let mut notes = Vec::new();
    for spec in &study.specifications {
        let label = spec.label(&study.sensor);
        let gw_model::spec::Resolved::Coefficient { index, .. } = spec.resolved() else {
            notes.push(format!(
                "{label}: a specification of the plan, answered by end-to-end, not by one run"
            ));
            continue;
        };
        let output = &outputs[spec.output()];
        let name = output.estimated_names()[*index];
        let c = run
            .outputs()
            .iter()
            .filter(|o| o.name() == output.name)
            .flat_map(|o| o.coefficients())
            .find(|c| c.name == name)
            .ok_or_else(|| {
                RunError::option(
                    "specifications",
                    format!("{label}: `{name}` is not estimated by this run"),
                )
            })?;
        if (spec.coverage() - run.coverage()).abs() > COVERAGE_MATCH {
            notes.push(format!(
                "{label}: specified at coverage {}, judged with the run's expanded uncertainty at {}",
                spec.coverage(),
                run.coverage()
            ));
        }
        verdicts.push(judge(
            "specifications",
            &label,
            c,
            spec.limit(),
            spec.to_written(),
            spec.unit(),
            rule,
        )?);
    }
    Ok((verdicts, notes))
}

/// Two coverage probabilities closer than this are the same statement (dimensionless; the
/// study and the run write them with at most a few digits).
const COVERAGE_MATCH: f64 = 1e-9;

/// One coefficient against $|\beta| \le$ `limit` (model unit) under `rule`, stated in the
/// written unit (`scale` written units per model unit).
fn judge(
    key: &str,
    label: &str,
    c: &CoefficientResult,
    limit: f64,
    scale: f64,
    unit: &str,
    rule: DecisionRule,
) -> Result<Verdict, RunError> {
    let bad = |e: metrology::MetrologyError| RunError::option(key, format!("{label}: {e}"));
    if !(limit.is_finite() && limit > 0.0) {
        return Err(RunError::option(
            key,
            format!("{label}: the limit must be positive, got {limit}"),
        ));
    }
    let tol = Tolerance::two_sided(-limit, limit).map_err(bad)?;
    let m = Measured::new(c.value, c.expanded, c.k).map_err(bad)?;
    let meets = decide(rule, &tol, &m).accepted();
    let (value, expanded, limit) = (c.value * scale, c.expanded * scale, limit * scale);
    Ok(Verdict {
        coefficient: label.to_owned(),
        unit: unit.to_owned(),
        value,
        expanded,
        k: c.k,
        limit,
        meets,
        rule: rule.to_string(),
        statement: format!(
            "{label} = {} +- {} {unit} (k = {}); specification {}: {} ({rule})",
            tt_core::human::sig(value, 4),
            tt_core::human::sig(expanded, 2),
            tt_core::human::sig(c.k, 3),
            tt_core::human::sig(limit, 4),
            if meets { "meets" } else { "does not meet" }
        ),
    })
}

/// The regression's view of one output's rate inputs: (output, rate input 0..3, coefficient
/// per deg/h) for outputs with a term linear in exactly one rate input (the gyros).
fn rate_channels(study: &Study) -> Vec<(usize, usize, f64)> {
    let mut best: [Option<(usize, f64)>; 3] = [None; 3];
    for (k, o) in study.sensor.outputs().iter().enumerate() {
        for t in &o.terms {
            for (q, input) in [Input::Wx, Input::Wy, Input::Wz].into_iter().enumerate() {
                if t.regressor.degree() == 1
                    && t.regressor.power(input) == 1
                    && t.value.abs() > 0.0
                    && best[q].is_none_or(|(_, c)| t.value.abs() > c.abs())
                {
                    best[q] = Some((k, t.value));
                }
            }
        }
    }
    best.iter()
        .enumerate()
        .filter_map(|(q, b)| b.map(|(k, c)| (k, q, c)))
        .collect()
}

/// An owned copy of a row (the first, held until the sample rate is known).
struct OwnedRow {
    line: u64,
    index: u64,
    t_s: f64,
    values: Vec<f64>,
    angles: Option<Vec<f64>>,
    saturated: bool,
}

impl OwnedRow {
    fn of(r: &Row<'_>) -> Self {
        OwnedRow {
            line: r.line,
            index: r.index,
            t_s: r.t_s,
            values: r.values.to_vec(),
            angles: r.angles_deg.map(<[f64]>::to_vec),
            saturated: r.saturated,
        }
    }
    fn row(&self) -> Row<'_> {
        Row {
            line: self.line,
            index: self.index,
            t_s: self.t_s,
            values: &self.values,
            angles_deg: self.angles.as_deref(),
            saturated: self.saturated,
        }
    }
}

/// Where the rows go while the recording streams: nowhere before the sample rate is known,
/// into the segments file's intervals, or into the detector.
enum Mode {
    Waiting,
    File {
        specs: Vec<SegmentSpec>,
        next: usize,
        current: Option<Box<StaticAcc>>,
        done: Vec<(SegmentSpec, StaticAcc)>,
    },
    Detect(Box<Detector>),
}

/// Process a recording of `study`'s calibration read from `reader` (named `source` in
/// messages).
///
/// # Errors
/// [`RunError::Input`] for a bad recording (line and column named), [`RunError::Segments`]
/// for segments that do not match the schedule, [`RunError::Option`] for a bad option.
pub fn calibrate<R: Read>(
    study: &Study,
    reader: R,
    source: &str,
    options: &CalibrateOptions,
) -> Result<Run, RunError> {
    calibrate_observed(study, reader, source, options, |_| {})
}

/// [`calibrate`], handing every row to `observe` too as the recording streams by (for an
/// overview of the recording, [`crate::overview::Decimator`], without reading it twice).
///
/// # Errors
/// As [`calibrate`].
pub fn calibrate_observed<R: Read, O: FnMut(&Row<'_>)>(
    study: &Study,
    reader: R,
    source: &str,
    options: &CalibrateOptions,
    observe: O,
) -> Result<Run, RunError> {
    let sensor = &study.sensor;
    let n_out = sensor.n_outputs();
    let Streamed {
        summary,
        mode,
        rate_hz,
    } = stream(study, reader, source, options, observe)?;
    let mut warnings: Vec<String> = summary
        .saturated
        .iter()
        .map(|s| {
            format!(
                "column `{}`: {} saturated samples (first at line {}); segments holding one are flagged",
                s.column, s.count, s.first_line
            )
        })
        .collect();
    let Collected {
        raw,
        source: segments_source,
        pooled,
        static_samples,
    } = collect_segments(study, mode, &summary, rate_hz, &mut warnings)?;
    // measured noise per output, pooled over the static segments
    let noise = measured_noise(study, &pooled, static_samples);
    let segments = raw
        .iter()
        .map(|r| {
            segment_of(
                study,
                r,
                rate_hz,
                summary.angles_logged,
                n_out,
                &mut warnings,
            )
        })
        .collect::<Result<Vec<_>, _>>()?;
    let outputs = sensor
        .outputs()
        .iter()
        .enumerate()
        .map(|(k, o)| estimate_output(study, k, o, &segments, &noise[k], options))
        .collect::<Result<Vec<_>, _>>()?;
    Ok(Run {
        study: study.path.clone(),
        study_sha256: crate::recording::sha256_hex(study.text.as_bytes()),
        recording: summary,
        segments_source,
        segments,
        warnings,
        outputs,
        coverage: options.coverage,
        robust: options.robust,
        budget_rule: budget_rule(options),
        models: sensor.outputs().to_vec(),
    })
}

/// The budget's rule as the run states it.
fn budget_rule(options: &CalibrateOptions) -> String {
    format!(
        "GUM (JCGM 100) at coverage {}: measured noise (Allan, static segments; inflated by the Birge ratio when the residuals exceed it){}",
        options.coverage,
        if options.tolerances.is_some() {
            "; the table's tolerances, rectangular, sensitivities by the exact chain"
        } else {
            "; no tolerance sheet: the table's part is not counted"
        }
    )
}

/// The recording as streamed: its summary, the segments found on the way and the sample
/// rate (Hz).
struct Streamed {
    summary: RecordingSummary,
    mode: Mode,
    rate_hz: f64,
}

/// Stream the recording once: each row to `observe` and to the segments (from the file, or
/// detected), the sample rate from the first two rows (or the options).
fn stream<R: Read, O: FnMut(&Row<'_>)>(
    study: &Study,
    reader: R,
    source: &str,
    options: &CalibrateOptions,
    mut observe: O,
) -> Result<Streamed, RunError> {
    let out_names: Vec<&str> = study
        .sensor
        .outputs()
        .iter()
        .map(|o| o.name.as_str())
        .collect();
    let joint_names = study.turntable.joint_names();
    let n_out = out_names.len();
    let mut rec_opts = options.recording.clone();
    if rec_opts.index_sample_rate_hz.is_none() {
        rec_opts.index_sample_rate_hz =
            study.timing.as_ref().map(calib_lsq::Timing::sample_rate_hz);
    }
    let given_rate = rec_opts.sample_rate_hz;
    if options.segments.is_none()
        && study.noise.iter().all(Option::is_none)
        && rate_channels(study).is_empty()
    {
        return Err(RunError::option(
            "--segments",
            "detecting the segments needs the study's noise of an output (`[sensor.outputs.noise]`) or a gyro output: give a segments file",
        ));
    }
    let min_static_s = options.detect.min_static_s.unwrap_or_else(|| {
        study.timing.as_ref().map_or(1.0, |t| {
            0.5 * t.dwell_s().iter().copied().fold(f64::INFINITY, f64::min)
        })
    });
    let mut first: Option<OwnedRow> = None;
    let mut mode = Mode::Waiting;
    let mut rate_hz = 0.0;
    let summary = read_rows(reader, source, &out_names, &joint_names, &rec_opts, |row| {
        observe(row);
        if row.index == 0 {
            first = Some(OwnedRow::of(row));
            return Ok(());
        }
        if row.index == 1 {
            let dt = row.t_s - first.as_ref().map_or(0.0, |f| f.t_s);
            rate_hz = given_rate.unwrap_or(1.0 / dt);
            if !dt.is_finite() || dt <= 0.0 {
                rate_hz = given_rate.or(rec_opts.index_sample_rate_hz).unwrap_or(1.0);
            }
            mode = Mode::new(study, options, rate_hz, min_static_s);
            let f = first.take().expect("row 0 held");
            mode.feed(&f.row(), rate_hz, n_out)?;
        }
        mode.feed(row, rate_hz, n_out)
    })?;
    Ok(Streamed {
        summary,
        mode,
        rate_hz,
    })
}

/// Each output's white variance of one sample at `rate_hz` (with its quantization), where
/// the study gives its noise and it is positive.
fn noise_white_var(study: &Study, rate_hz: f64) -> Vec<Option<f64>> {
    study
        .noise
        .iter()
        .map(|n| {
            n.as_ref()
                .map(|n| n.white_sample_variance(rate_hz) + n.quantization().powi(2) / 12.0)
        })
        .map(|v| v.filter(|v| *v > 0.0))
        .collect()
}

impl Mode {
    /// The segments' source once the sample rate `rate` (Hz) is known: the options' file,
    /// else a detector.
    fn new(study: &Study, options: &CalibrateOptions, rate: f64, min_static_s: f64) -> Mode {
        match &options.segments {
            Some(specs) => Mode::File {
                specs: specs.clone(),
                next: 0,
                current: None,
                done: Vec::new(),
            },
            None => Mode::Detect(Box::new(Detector::new(
                BlockTest {
                    white_var: noise_white_var(study, rate),
                    variance_ratio: options.detect.variance_ratio,
                    rate_channels: rate_channels(study),
                    turning_rate_deg_per_h: options.detect.turning_rate_deg_per_s * 3600.0,
                    still_deg: options.detect.still_deg,
                },
                options.detect.block_s,
                min_static_s,
                rate,
                study.sensor.n_outputs(),
            ))),
        }
    }

    /// One row into the segment it belongs to (`n_out` outputs at `rate` Hz).
    fn feed(&mut self, row: &Row<'_>, rate: f64, n_out: usize) -> Result<(), RunError> {
        match self {
            Mode::Waiting => unreachable!("a mode is set before the first row is fed"),
            Mode::Detect(d) => d.push(row),
            Mode::File {
                specs,
                next,
                current,
                done,
            } => {
                if *next < specs.len() && row.index == specs[*next].start {
                    *current = Some(Box::new(StaticAcc::new(n_out, rate)?));
                }
                if let Some(c) = current.as_mut() {
                    c.acc.push(row);
                    if specs[*next].kind == SegmentKind::Static {
                        c.push_values(row.values);
                    }
                    if row.index + 1 == specs[*next].end {
                        done.push((specs[*next].clone(), *current.take().expect("open")));
                        *next += 1;
                    }
                }
                Ok(())
            }
        }
    }
}

/// One found segment: (schedule entry, kind, accumulated samples, allan fits if static).
type RawSegment = (usize, SegmentKind, Acc, Option<StaticAcc>);

/// The segments of a streamed recording, matched to the schedule entries.
struct Collected {
    raw: Vec<RawSegment>,
    /// `"file"` or `"detected"`.
    source: &'static str,
    /// Every output's pooled white density and floor ([`pool`]).
    pooled: Vec<(f64, f64)>,
    static_samples: u64,
}

/// The segments the streaming found, matched to the schedule (detected ones by
/// [`match_schedule`], whose warnings go to `warnings`).
fn collect_segments(
    study: &Study,
    mode: Mode,
    summary: &RecordingSummary,
    rate_hz: f64,
    warnings: &mut Vec<String>,
) -> Result<Collected, RunError> {
    let n_out = study.sensor.n_outputs();
    match mode {
        Mode::Waiting => unreachable!("read_rows returns at least two rows"),
        Mode::File { specs, done, .. } => {
            if let Some(s) = specs.iter().find(|s| s.end > summary.samples) {
                return Err(RunError::Segments {
                    reason: format!(
                        "the segment of line {} (samples {}..{}) is out of range: the recording has {} samples",
                        s.line, s.start, s.end, summary.samples
                    ),
                });
            }
            let mut raw = Vec::new();
            let mut static_fits = Vec::new();
            for (spec, acc) in done {
                if spec.kind == SegmentKind::Static {
                    raw.push((spec.entry, spec.kind, acc.acc.clone(), None));
                    static_fits.push(acc);
                } else {
                    raw.push((spec.entry, spec.kind, acc.acc, None));
                }
            }
            let (pooled, static_samples) = pool(&mut static_fits, n_out);
            Ok(Collected {
                raw,
                source: "file",
                pooled,
                static_samples,
            })
        }
        Mode::Detect(d) => {
            let mut det = d.finish()?;
            let (pooled, static_samples) = pool(&mut det.statics, n_out);
            let (raw, w) = match_schedule(
                study,
                det,
                study.positions_deg.len(),
                study.rate_steps.len(),
                summary.angles_logged,
                rate_hz,
                &pooled,
            )?;
            warnings.extend(w);
            Ok(Collected {
                raw,
                source: "detected",
                pooled,
                static_samples,
            })
        }
    }
}

/// One found segment as processed: its duration, pose and the regression's inputs (a
/// rotation's rate from the angle it turned); a warning for its saturated samples.
fn segment_of(
    study: &Study,
    (entry, kind, acc, _): &RawSegment,
    rate_hz: f64,
    logged: bool,
    n_out: usize,
    warnings: &mut Vec<String>,
) -> Result<Segment, RunError> {
    let duration_s = acc.n as f64 / rate_hz;
    let position = &study.calibration.schedule().positions()[*entry];
    let pose_deg: Vec<f64> = if logged && *kind == SegmentKind::Static {
        acc.angle_mean.clone()
    } else {
        position.joint_angles_deg().to_vec()
    };
    let pose = Pose::from_deg(&pose_deg).map_err(|e| RunError::Internal(e.to_string()))?;
    let (inputs, turned_deg) = match (kind, position.motion()) {
        (SegmentKind::Static, _) => {
            let r = if logged {
                study
                    .turntable
                    .nominal_rotation(&pose)
                    .map_err(|e| RunError::Internal(e.to_string()))?
            } else {
                *position.base_from_sensor()
            };
            (study.site.inputs(&r), None)
        }
        (SegmentKind::Rate, Some(m)) => (m.nominal, None),
        (SegmentKind::Rotation, Some(m)) => {
            let sign = m.rate_rad_per_s.signum();
            let theta_rad = if logged {
                acc.turned[m.joint].to_radians()
            } else {
                sign * std::f64::consts::TAU * f64::from(m.revolutions)
            };
            let axis = sign * m.nominal.rate_rad_per_s.normalize();
            let actual = theta_rad / duration_s;
            (
                Inputs {
                    specific_force_g: m.nominal.specific_force_g,
                    rate_rad_per_s: m.nominal.rate_rad_per_s + (actual - m.rate_rad_per_s) * axis,
                },
                Some(theta_rad.to_degrees()),
            )
        }
        (_, None) => {
            return Err(RunError::Segments {
                reason: format!("entry {entry} is a static position, not a rate step"),
            });
        }
    };
    if acc.saturated > 0 {
        warnings.push(format!(
            "segment of entry {entry} (lines {}-{}): {} saturated samples; its average is biased",
            acc.first_line, acc.last_line, acc.saturated
        ));
    }
    Ok(Segment {
        entry: *entry,
        kind: *kind,
        start_sample: acc.start_index,
        samples: acc.n,
        first_line: acc.first_line,
        last_line: acc.last_line,
        t_start_s: acc.t_first,
        duration_s,
        mean: acc.mean.clone(),
        std: (0..n_out).map(|k| acc.variance(k).sqrt()).collect(),
        angles_deg: logged.then(|| acc.angle_mean.clone()),
        turned_deg,
        saturated: acc.saturated,
        inputs: InputValues::from_inputs(&inputs),
        pose,
    })
}

/// Pooled white density and floor of every output over the static intervals' Allan fits
/// (each analysed once), and the samples analysed.
fn pool(fits: &mut [StaticAcc], n_out: usize) -> (Vec<(f64, f64)>, u64) {
    let (mut n2, mut f2, mut w) = (vec![0.0; n_out], vec![0.0; n_out], vec![0.0; n_out]);
    let mut samples = 0;
    for s in fits.iter_mut() {
        let n = s.acc.n as f64;
        samples += s.acc.n;
        for k in 0..n_out {
            if let Ok(an) = s.allan[k].analyse() {
                let fit = an.fit();
                n2[k] += n * fit.white_noise().powi(2);
                if fit.floor_reached() {
                    f2[k] += n * fit.floor_adev_measured().powi(2);
                }
                w[k] += n;
            }
        }
    }
    let pooled = (0..n_out)
        .map(|k| {
            if w[k] > 0.0 {
                ((n2[k] / w[k]).sqrt(), (f2[k] / w[k]).sqrt())
            } else {
                (0.0, 0.0)
            }
        })
        .collect();
    (pooled, samples)
}

fn measured_noise(study: &Study, pooled: &[(f64, f64)], samples: u64) -> Vec<MeasuredNoise> {
    pooled
        .iter()
        .enumerate()
        .map(|(k, &(white, floor))| MeasuredNoise {
            white_per_sqrt_hz: white,
            floor,
            samples,
            study_white_per_sqrt_hz: study.noise[k]
                .as_ref()
                .map(gw_model::noise::NoiseModel::white_per_sqrt_hz),
        })
        .collect()
}

type Matched = (Vec<RawSegment>, Vec<String>);

/// Match detected intervals to the schedule (module docs of [`crate::segments`]).
fn match_schedule(
    study: &Study,
    det: Detected,
    n_static: usize,
    n_rate: usize,
    logged: bool,
    rate_hz: f64,
    pooled: &[(f64, f64)],
) -> Result<Matched, RunError> {
    let mut warnings = Vec::new();
    for (a, b, d) in &det.dropped {
        warnings.push(format!(
            "a static interval at lines {a}-{b} ({} s) is too short for a dwell: not used",
            tt_core::human::sig(*d, 3)
        ));
    }
    let found = det.statics.len();
    if found < n_static {
        let listed: Vec<String> = det
            .statics
            .iter()
            .map(|s| format!("lines {}-{}", s.acc.first_line, s.acc.last_line))
            .collect();
        return Err(RunError::Segments {
            reason: format!(
                "fewer segments than the schedule needs: {found} static intervals detected ({}), the schedule has {n_static} static positions; give a segments file (--segments) or check the detection settings",
                if listed.is_empty() {
                    "none".to_string()
                } else {
                    listed.join(", ")
                }
            ),
        });
    }
    let n_out = study.sensor.n_outputs();
    let mut out = Vec::new();
    let mut rate_left: Vec<usize> = (n_static..n_static + n_rate).collect();
    rate_left.reverse();
    // turns[j] lies before statics[j]; turn j+1 between statics j and j+1
    for j in (n_static.max(1) - 1)..found.saturating_sub(1) {
        let (a, b) = (&det.statics[j].acc, &det.statics[j + 1].acc);
        let turn = &det.turns[j + 1];
        let Some(&entry) = rate_left.last() else {
            warnings.push(format!(
                "an extra interval after the schedule: lines {}-{} (not used)",
                turn.first_line, b.last_line
            ));
            continue;
        };
        let step = &study.rate_steps[entry - n_static];
        let is_rotation = if logged {
            let want = 360.0 * f64::from(step.revolutions) * step.rate_deg_per_s.signum();
            turn.n > 0
                && (turn.turned[step.joint] - want).abs() <= ROTATION_MATCH_DEG
                && turn
                    .turned
                    .iter()
                    .enumerate()
                    .all(|(q, t)| q == step.joint || t.abs() <= ROTATION_MATCH_DEG)
        } else {
            turn.n > 0
                && (0..n_out).all(|k| {
                    let (white, floor) = pooled[k];
                    let v = |n: u64| white.powi(2) / (n as f64 / rate_hz) + floor.powi(2);
                    let sd = (v(a.n) + v(b.n)).sqrt();
                    (a.mean[k] - b.mean[k]).abs() <= POSE_Z * sd.max(f64::MIN_POSITIVE)
                })
        };
        if is_rotation {
            rate_left.pop();
            let mut whole = turn.clone();
            // the rotation's samples: the turning interval (its edges rest)
            whole.start_index = turn.start_index;
            out.push((entry, SegmentKind::Rotation, whole, None));
        }
    }
    if !rate_left.is_empty() {
        let missing: Vec<String> = rate_left.iter().rev().map(|e| e.to_string()).collect();
        return Err(RunError::Segments {
            reason: format!(
                "fewer segments than the schedule needs: no rotation found for rate step entries {} (a rotation starts and ends at rest at the same pose after the last static position); give a segments file (--segments)",
                missing.join(", ")
            ),
        });
    }
    let extra_static = found - n_static;
    if extra_static > 0 && n_rate == 0 {
        warnings.push(format!(
            "{extra_static} extra static intervals after the schedule's {n_static} positions (not used; the first at lines {}-{})",
            det.statics[n_static].acc.first_line, det.statics[n_static].acc.last_line
        ));
    }
    let mut all: Vec<RawSegment> = det
        .statics
        .iter()
        .take(n_static)
        .enumerate()
        .map(|(e, s)| (e, SegmentKind::Static, s.acc.clone(), None))
        .collect();
    all.extend(out);
    Ok((all, warnings))
}

struct Fit {
    beta: DVector<f64>,
    cov: DMatrix<f64>,
    residual_w: DVector<f64>,
    leverage: Vec<f64>,
    pinv: DMatrix<f64>,
}

fn wls(
    name: &str,
    names: &[String],
    a: &DMatrix<f64>,
    y: &DVector<f64>,
    w: &[f64],
) -> Result<Fit, RunError> {
    let mut aw = a.clone();
    let mut yw = y.clone();
    for (i, &wi) in w.iter().enumerate() {
        let s = wi.sqrt();
        aw.row_mut(i).scale_mut(s);
        yw[i] *= s;
    }
    let reg =
        Regression::new(name, names.to_vec(), aw.clone()).map_err(|e| RunError::Segments {
            reason: format!("output `{name}`: the segments do not identify its coefficients: {e}"),
        })?;
    let beta = reg
        .estimate(&yw)
        .map_err(|e| RunError::Internal(e.to_string()))?;
    let pinv = reg.pinv().clone();
    let cov = &pinv * pinv.transpose();
    let residual_w = &yw - &aw * &beta;
    let hat = &aw * &pinv;
    let leverage = (0..hat.nrows()).map(|i| hat[(i, i)]).collect();
    Ok(Fit {
        beta,
        cov,
        residual_w,
        leverage,
        pinv,
    })
}

fn estimate_output(
    study: &Study,
    k: usize,
    o: &Output,
    segments: &[Segment],
    noise: &MeasuredNoise,
    options: &CalibrateOptions,
) -> Result<OutputResult, RunError> {
    let involves_rate = o.terms.iter().any(|t| t.regressor.involves_rate());
    let mut notes = Vec::new();
    let used: Vec<usize> = segments
        .iter()
        .enumerate()
        .filter(|(_, s)| s.kind != SegmentKind::Rotation || involves_rate)
        .map(|(i, _)| i)
        .collect();
    if used.len() < segments.len() {
        notes.push("rotation segments not used: the output has no rate term".into());
    }
    let entries: Vec<usize> = used.iter().map(|&i| segments[i].entry).collect();
    let (predicted, predicted_basis) = match predicted_sigma(study, k, &entries) {
        Ok((sigma, basis)) => (Some(sigma), basis),
        Err(why) => (None, format!("not computed: {why}")),
    };
    let names: Vec<String> = o
        .estimated_names()
        .iter()
        .map(|s| (*s).to_string())
        .collect();
    let p = names.len();
    let rows = Rows::of(k, o, segments, &used, noise)?;
    let w: Vec<f64> = rows.var.iter().map(|v| 1.0 / v).collect();
    let ordinary = wls(&o.name, &names, &rows.a, &rows.y, &w)?;
    let (fit, robust_w, robust_change) = if options.robust {
        let ordinary_beta = ordinary.beta.clone();
        let (fit, robust_w) = huber(&o.name, &names, &rows, &w, ordinary)?;
        notes.extend(down_weighted(segments, &used, &robust_w));
        let change = &fit.beta - &ordinary_beta;
        (fit, robust_w, Some(change))
    } else {
        (ordinary, vec![1.0; used.len()], None)
    };
    let (residuals, chi2) = residual_rows(&fit, &robust_w, &rows.var, &used);
    let dof = used.len().saturating_sub(p);
    let birge = (dof > 0).then(|| (chi2 / dof as f64).sqrt());
    // covariance with unit weights back on the measured scale: for the robust fit the
    // reweighted (A^T W H A)^-1
    let u_meas: Vec<f64> = (0..p).map(|j| fit.cov[(j, j)].sqrt()).collect();
    // the table's sensitivities
    let table = match &options.tolerances {
        Some(t) => Some(table_sensitivities(
            study, o, segments, &used, &fit, &w, &robust_w, t,
        )?),
        None => None,
    };
    let result = budget_of(
        o,
        &names,
        &fit.cov,
        &u_meas,
        birge,
        dof,
        table.as_ref(),
        options,
    )?;
    let estimated: Vec<&gw_model::Term> = o.estimated().collect();
    let coefficients = (0..p)
        .map(|j| {
            let ou = &result.outputs()[j];
            let (u_table, table_sensitivity) = table.as_ref().map_or_else(
                || (0.0, Vec::new()),
                |(nm, ub, sens)| {
                    let u = ub
                        .iter()
                        .enumerate()
                        .map(|(e, b)| (sens[(j, e)] * b / 3f64.sqrt()).powi(2))
                        .sum::<f64>()
                        .sqrt();
                    let s = nm
                        .iter()
                        .enumerate()
                        .map(|(e, n)| (n.clone(), sens[(j, e)]))
                        .collect();
                    (u, s)
                },
            );
            CoefficientResult {
                name: names[j].clone(),
                unit: o.coefficient_unit(estimated[j]),
                value: fit.beta[j],
                nominal: estimated[j].value,
                u_measured_noise: u_meas[j],
                u_residuals: birge.map(|b| b * u_meas[j]),
                u_table,
                u_combined: ou.combined(),
                dof_eff: ou.dof_eff(),
                k: ou.coverage_factor(),
                expanded: ou.expanded(),
                predicted_u: predicted.as_ref().map(|pr| pr[j]),
                robust_change: robust_change.as_ref().map(|d| d[j]),
                table_sensitivity,
            }
        })
        .collect();
    Ok(OutputResult {
        name: o.name.clone(),
        unit: o.unit.clone(),
        noise: noise.clone(),
        coefficients,
        residuals,
        chi2,
        dof,
        birge_ratio: birge,
        notes,
        predicted_basis,
    })
}

/// One output's regression over the segments it uses: the regressor rows, the means less
/// the model's known part, and each mean's variance from the measured noise.
struct Rows {
    a: DMatrix<f64>,
    y: DVector<f64>,
    var: Vec<f64>,
}

impl Rows {
    /// Output `k` (`o`) over `segments[used]`.
    ///
    /// # Errors
    /// [`RunError::Segments`] when a variance is not positive (no measured noise).
    fn of(
        k: usize,
        o: &Output,
        segments: &[Segment],
        used: &[usize],
        noise: &MeasuredNoise,
    ) -> Result<Rows, RunError> {
        let n = used.len();
        let mut a = DMatrix::zeros(n, o.estimated_names().len());
        let mut y = DVector::zeros(n);
        let mut var = vec![0.0; n];
        for (r, &i) in used.iter().enumerate() {
            let s = &segments[i];
            for (c, v) in o.regressor_row(&s.inputs).enumerate() {
                a[(r, c)] = v;
            }
            y[r] = s.mean[k] - o.known_part(&s.inputs);
            var[r] = noise.variance_of_mean(s.duration_s);
        }
        if var.iter().any(|v| *v <= 0.0) {
            return Err(RunError::Segments {
                reason: format!(
                    "output `{}`: no measured noise (no static segment long enough for an Allan deviation)",
                    o.name
                ),
            });
        }
        Ok(Rows { a, y, var })
    }
}

/// The robust (Huber) fit from the ordinary one `fit` (weights `w`): iteratively reweighted
/// until no weight moves by more than [`HUBER_WEIGHT_TOL`], at most [`HUBER_MAX_ITER`]
/// times. Returns the fit and the Huber weights.
fn huber(
    name: &str,
    names: &[String],
    rows: &Rows,
    w: &[f64],
    mut fit: Fit,
) -> Result<(Fit, Vec<f64>), RunError> {
    let mut robust_w = vec![1.0; w.len()];
    for _ in 0..HUBER_MAX_ITER {
        let new_w: Vec<f64> = fit
            .residual_w
            .iter()
            .zip(&robust_w)
            .map(|(r, hw): (&f64, &f64)| {
                // residual of the reweighted fit back on the measured-noise scale
                let z = (r / hw.sqrt()).abs();
                if z <= HUBER_C { 1.0 } else { HUBER_C / z }
            })
            .collect();
        let moved = new_w
            .iter()
            .zip(&robust_w)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        robust_w = new_w;
        let ww: Vec<f64> = w.iter().zip(&robust_w).map(|(a, b)| a * b).collect();
        fit = wls(name, names, &rows.a, &rows.y, &ww)?;
        if moved <= HUBER_WEIGHT_TOL {
            break;
        }
    }
    Ok((fit, robust_w))
}

/// A note for each segment the robust fit down-weighted.
fn down_weighted(segments: &[Segment], used: &[usize], robust_w: &[f64]) -> Vec<String> {
    robust_w
        .iter()
        .zip(used)
        .filter(|(hw, _)| **hw < 1.0)
        .map(|(&hw, &i)| {
            let s = &segments[i];
            format!(
                "robust fit: entry {} (lines {}-{}) weighted {}",
                s.entry,
                s.first_line,
                s.last_line,
                tt_core::human::sig(hw, 3)
            )
        })
        .collect()
}

/// Each used segment's residual on the measured-noise scale (standardized by its leverage),
/// and their $\chi^2$.
fn residual_rows(
    fit: &Fit,
    robust_w: &[f64],
    var: &[f64],
    used: &[usize],
) -> (Vec<ResidualRow>, f64) {
    let mut chi2 = 0.0;
    let mut residuals = Vec::with_capacity(used.len());
    for (r, &segment) in used.iter().enumerate() {
        let hw = robust_w[r];
        let rw = fit.residual_w[r] / hw.sqrt();
        chi2 += rw * rw;
        let lev = fit.leverage[r].min(1.0 - 1e-12);
        let z = rw / (1.0 - lev).sqrt();
        residuals.push(ResidualRow {
            segment,
            residual: rw * var[r].sqrt(),
            standardized: z,
            outlier: z.abs() > OUTLIER_Z,
            robust_weight: hw,
        });
    }
    (residuals, chi2)
}

/// The GUM budget of the coefficients `names`: each coefficient's noise (standard
/// uncertainty `u_meas`, inflated by the Birge ratio when above 1, then with `dof` degrees
/// of freedom; correlated by `cov`) and, with a tolerance sheet, each toleranced table error
/// (rectangular, through its sensitivities).
#[allow(
    clippy::too_many_arguments,
    reason = "the budget's parts, each computed by the caller once"
)]
fn budget_of(
    o: &Output,
    names: &[String],
    cov: &DMatrix<f64>,
    u_meas: &[f64],
    birge: Option<f64>,
    dof: usize,
    table: Option<&TableSens>,
    options: &CalibrateOptions,
) -> Result<metrology::BudgetResult, RunError> {
    let p = names.len();
    let inflate = birge.map_or(1.0, |b| b.max(1.0));
    let mut inputs = Vec::new();
    for (j, nm) in names.iter().enumerate() {
        let mut i = MInput::normal(&format!("noise {nm}"), 0.0, u_meas[j] * inflate)
            .map_err(|e| RunError::Internal(e.to_string()))?;
        if inflate > 1.0 {
            i = i
                .with_dof(dof as f64)
                .map_err(|e| RunError::Internal(e.to_string()))?;
        }
        inputs.push(i);
    }
    let mut n_table = 0;
    if let Some((names_t, ub, _)) = table {
        for (nm, &b) in names_t.iter().zip(ub.iter()) {
            inputs.push(
                MInput::rectangular(&format!("table {nm}"), 0.0, b)
                    .map_err(|e| RunError::Internal(e.to_string()))?,
            );
            n_table += 1;
        }
    }
    let m = inputs.len();
    let mut corr = DMatrix::identity(m, m);
    for i in 0..p {
        for j in 0..p {
            if i != j && u_meas[i] > 0.0 && u_meas[j] > 0.0 {
                corr[(i, j)] = (cov[(i, j)] / (u_meas[i] * u_meas[j])).clamp(-1.0, 1.0);
            }
        }
    }
    let budget = Budget::new(
        inputs,
        BudgetSettings {
            coverage: options.coverage,
            truncate_dof: true,
        },
    )
    .and_then(|b| b.with_correlation(corr))
    .map_err(|e| RunError::Internal(format!("budget of `{}`: {e}", o.name)))?;
    let mut c = DMatrix::zeros(p, m);
    for j in 0..p {
        c[(j, j)] = 1.0;
        if let Some((_, _, sens)) = table {
            for e in 0..n_table {
                c[(j, p + e)] = sens[(j, e)];
            }
        }
    }
    budget
        .evaluate(names, &c)
        .map_err(|e| RunError::Internal(format!("budget of `{}`: {e}", o.name)))
}

/// The plan's predicted standard uncertainty of output `k`'s estimated coefficients
/// (study order) for the schedule entries `entries` the run's fit of it uses, and a
/// sentence saying what it is computed from; `Err` says why there is none.
///
/// The plan's covariance (calib-lsq, module `covariance`): ordinary least squares on the
/// entries' nominal regressor rows, $\mathbf A^+\boldsymbol\Sigma\mathbf A^{+T}$, with
/// $\boldsymbol\Sigma$ the study's noise model over the study's timing windows (a static
/// position's dwell, a rate step's whole revolutions at its commanded rate; the study's
/// sample rate). When the run uses every entry this is the end-to-end noise part's
/// covariance of the coefficients; an output without a rate term leaves out the rate steps
/// the run took as rotations (their specific force depends on the unknown rate profile), and
/// the prediction leaves out their rows too.
fn predicted_sigma(
    study: &Study,
    k: usize,
    entries: &[usize],
) -> Result<(DVector<f64>, String), String> {
    let Some(timing) = &study.timing else {
        return Err("the study gives no `[calibration.timing]` (the plan's windows)".into());
    };
    let Some(noise) = study.noise.get(k).and_then(Option::as_ref) else {
        return Err("the study gives no noise for this output (`[sensor.outputs.noise]`)".into());
    };
    let plan = study.calibration.outputs()[k].regression();
    let windows = timing.windows();
    let mut rows = entries.to_vec();
    rows.sort_unstable();
    rows.dedup();
    if rows.len() < entries.len() {
        return Err("a schedule entry has more than one segment".into());
    }
    if rows
        .iter()
        .any(|&e| e >= windows.len() || e >= plan.matrix().nrows())
    {
        return Err("a segment's entry is not in the study's timing".into());
    }
    let a = DMatrix::from_fn(rows.len(), plan.matrix().ncols(), |r, c| {
        plan.matrix()[(rows[r], c)]
    });
    let w: Vec<_> = rows.iter().map(|&e| windows[e]).collect();
    let sigma = noise
        .window_covariance(&w, timing.sample_rate_hz())
        .map_err(|e| format!("the study's noise over its timing: {e}"))
        .and_then(|positions| {
            Regression::new(plan.output(), plan.names().to_vec(), a)
                .and_then(|r| r.noise_covariance(&positions))
                .map_err(|e| format!("the plan's rows used by the run: {e}"))
        })?
        .coefficients()
        .sigma();
    let n_static = timing.positions();
    let statics = rows.iter().filter(|&&e| e < n_static).count();
    let steps = rows.len() - statics;
    let mut basis = format!(
        "the study's noise and timing (its windows, not the run's): {statics} of {n_static} static positions' dwells"
    );
    if !timing.rate_step_s().is_empty() {
        basis.push_str(&format!(
            ", {steps} of {} rate steps over their whole revolutions",
            timing.rate_step_s().len()
        ));
    }
    basis.push_str(&format!(
        " at {} Hz, ordinary least squares",
        tt_core::human::sig(timing.sample_rate_hz(), 6)
    ));
    if rows.len() < timing.len() {
        basis.push_str(
            "; the entries the run does not use for this output (rotations at an unknown rate, for an output without a rate term) left out",
        );
    }
    Ok((sigma, basis))
}

type TableSens = (Vec<String>, Vec<f64>, DMatrix<f64>);

/// The coefficients' sensitivities to each toleranced rotation error (exact chain, central
/// difference): names, bounds (rad) and the p x m matrix.
#[allow(clippy::too_many_arguments)]
fn table_sensitivities(
    study: &Study,
    o: &Output,
    segments: &[Segment],
    used: &[usize],
    fit: &Fit,
    w: &[f64],
    robust_w: &[f64],
    tol: &study::Tolerances,
) -> Result<TableSens, RunError> {
    let tt = &study.turntable;
    let names = tt.rotation_error_names();
    let n_tr = tt.n_translation_errors();
    let env = RateEnvironment {
        specific_force_base_g: study.site.specific_force_base_g(),
        earth_rate_base_rad_per_s: study.site.earth_rate_base_rad_per_s(),
        lever_arm_m: Vector3::from(study.lever_arm_m),
    };
    let schedule = study.calibration.schedule();
    let value = |v: &InputValues| -> f64 {
        o.known_part(v)
            + o.regressor_row(v)
                .zip(fit.beta.iter())
                .map(|(r, b)| r * b)
                .sum::<f64>()
    };
    let inputs_at = |s: &Segment, chi: &[f64]| -> Result<InputValues, RunError> {
        let errs = TurntableErrors::new(chi.to_vec(), vec![0.0; n_tr])
            .map_err(|e| RunError::Internal(e.to_string()))?;
        let internal = |e: tt_kinematics::KinematicsError| RunError::Internal(e.to_string());
        match (s.kind, schedule.positions()[s.entry].motion()) {
            (SegmentKind::Static, _) | (_, None) => {
                let r = tt
                    .actual_rotation(&s.pose, &errs, ChainKind::Exact)
                    .map_err(internal)?;
                Ok(InputValues::from_inputs(&study.site.inputs(&r)))
            }
            (_, Some(m)) => {
                let step = RateStep {
                    joint: m.joint,
                    rate_rad_per_s: m.rate_rad_per_s,
                    pose: s.pose.clone(),
                    revolutions: m.revolutions,
                };
                let avg = tt
                    .rate_step_average(&step, &errs, &RateErrorValues::default(), &env)
                    .map_err(internal)?;
                let d = InputValues::from_inputs(&Inputs {
                    specific_force_g: avg.specific_force_g - m.nominal.specific_force_g,
                    rate_rad_per_s: avg.rate_rad_per_s - m.nominal.rate_rad_per_s,
                });
                let mut v = s.inputs;
                for q in 0..6 {
                    v.0[q] += d.0[q];
                }
                Ok(v)
            }
        }
    };
    let mut kept = Vec::new();
    let mut ub = Vec::new();
    let mut cols = Vec::new();
    for (e, nm) in names.iter().enumerate() {
        let b = tol.ub_rad[e];
        if b.is_nan() || b <= 0.0 {
            continue;
        }
        let mut dy = DVector::zeros(used.len());
        for (r, &i) in used.iter().enumerate() {
            let s = &segments[i];
            let mut chi = vec![0.0; names.len()];
            chi[e] = TABLE_STEP_RAD;
            let plus = value(&inputs_at(s, &chi)?);
            chi[e] = -TABLE_STEP_RAD;
            let minus = value(&inputs_at(s, &chi)?);
            // the outputs move by dy when the table errs; the estimate absorbs pinv * dy
            dy[r] = (plus - minus) / (2.0 * TABLE_STEP_RAD) * (w[r] * robust_w[r]).sqrt();
        }
        cols.push(&fit.pinv * dy);
        kept.push((*nm).to_string());
        ub.push(b);
    }
    let p = fit.beta.len();
    let mut s = DMatrix::zeros(p, cols.len());
    for (e, c) in cols.iter().enumerate() {
        s.set_column(e, c);
    }
    Ok((kept, ub, s))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn measured_noise_variance_of_mean_is_white_over_duration_plus_floor() {
        let m = MeasuredNoise {
            white_per_sqrt_hz: 2.0,
            floor: 0.5,
            samples: 10,
            study_white_per_sqrt_hz: None,
        };
        approx::assert_relative_eq!(m.variance_of_mean(4.0), 1.0 + 0.25, max_relative = 1e-15);
    }
}
