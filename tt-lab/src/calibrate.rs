//! A calibration recording processed for the study that planned it (the `calib-run` crate
//! does the work): what the lab decides beyond it, the estimation's settings from the study
//! (its coverage), the specifications judged (the study's and the caller's) under one named
//! decision rule, the segments file read against the study's schedule; and a recording
//! corrected with a calibration file.

use crate::error::{InputError, LabError, Result};
use calib_run::file::{ApplySummary, CalibrationFile};
use calib_run::overview::{Decimator, Overview};
use calib_run::recording::RecordingOptions;
use calib_run::segments::{DetectSettings, SegmentSpec, parse_segments};
use calib_run::{CalibrateOptions, Run, RunError, Spec, Verdict};
use metrology::decision::DecisionRule;
use std::io::{Read, Write};
use study::Study;

/// The decision rule of every specification judged on a run: the ILAC-G8 guard band
/// w = U (the expanded uncertainty).
pub const DECISION_RULE: DecisionRule = DecisionRule::GuardBandExpanded;

/// What [`calibrate`] does with the recording.
#[derive(Debug, Clone)]
#[non_exhaustive]
pub struct Options {
    /// Columns, time column, sample rate, range (the coverage comes from the study).
    pub recording: RecordingOptions,
    /// Segments from a file ([`segments`]); `None`: detected.
    pub segments: Option<Vec<SegmentSpec>>,
    /// Detection: block length, s.
    pub block_s: f64,
    /// Detection: shortest static interval used, s (`None`: half the study's shortest
    /// dwell, else 1 s).
    pub min_static_s: Option<f64>,
    /// Fit robustly (Huber) too; the robust estimate is the one kept.
    pub robust: bool,
    /// The table's tolerance sheet (its part of the uncertainty budget).
    pub tolerances: Option<study::Tolerances>,
    /// The caller's specifications (|coefficient| <= limit), judged beside the study's.
    pub specs: Vec<Spec>,
    /// Also keep an overview of the recording (every output's extremes in at most this many
    /// buckets, built while it streams: [`calib_run::overview`]), for a figure; `None`: none.
    pub overview_buckets: Option<usize>,
}

impl Default for Options {
    fn default() -> Self {
        Self {
            recording: RecordingOptions::default(),
            segments: None,
            block_s: 0.5,
            min_static_s: None,
            robust: false,
            tolerances: None,
            specs: Vec::new(),
            overview_buckets: None,
        }
    }
}

/// A processed recording and its verdicts.
#[derive(Debug, Clone)]
#[non_exhaustive]
pub struct CalibrationAnswer {
    run: Run,
    verdicts: Vec<Verdict>,
    spec_notes: Vec<String>,
    overview: Option<Overview>,
}

impl CalibrationAnswer {
    /// The run: coefficients with their uncertainties, noise, residuals, segments.
    #[must_use]
    pub fn run(&self) -> &Run {
        &self.run
    }

    /// The verdicts: the study's coefficient specifications, then the caller's, under
    /// [`DECISION_RULE`].
    #[must_use]
    pub fn verdicts(&self) -> &[Verdict] {
        &self.verdicts
    }

    /// The study's specifications not judged on one run, and why.
    #[must_use]
    pub fn specification_notes(&self) -> &[String] {
        &self.spec_notes
    }

    /// The recording's overview, when [`Options::overview_buckets`] asked for one.
    #[must_use]
    pub fn overview(&self) -> Option<&Overview> {
        self.overview.as_ref()
    }

    /// The JSON view (`calibrate --json`); `calibration_file`: where the calibration file
    /// was written, if it was.
    #[must_use]
    pub fn view(&self, calibration_file: Option<String>) -> CalibrationJson<'_> {
        CalibrationJson {
            run: &self.run,
            verdicts: &self.verdicts,
            specification_notes: &self.spec_notes,
            calibration_file,
        }
    }
}

/// `calibrate --json`.
#[derive(Debug)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
#[cfg_attr(not(feature = "serde"), allow(dead_code))]
pub struct CalibrationJson<'a> {
    /// The run.
    run: &'a Run,
    /// The verdicts.
    verdicts: &'a [Verdict],
    /// The specifications not judged here.
    specification_notes: &'a [String],
    /// The calibration file written, else `null`.
    calibration_file: Option<String>,
}

/// A `calib-run` error in the lab's terms: input errors (a line, a column, a segment, an
/// option) are [`InputError`]s.
#[must_use]
pub fn run_error(e: RunError) -> LabError {
    use tt_core::ErrorClass;
    match &e {
        RunError::Input { at, reason } => InputError::new(at.to_string(), reason.clone()).into(),
        _ if e.is_input() => {
            InputError::new(e.input_field().unwrap_or_default(), e.to_string()).into()
        }
        _ => LabError::internal(e),
    }
}

/// The segments file (CSV `start,end,entry[,kind]`, named `name`) read against the study's
/// schedule.
///
/// # Errors
/// An [`InputError`] naming the line for a segment that does not fit the schedule.
pub fn segments<R: Read>(s: &Study, reader: R, name: &str) -> Result<Vec<SegmentSpec>> {
    parse_segments(reader, name, s.positions_deg.len(), s.rate_steps.len()).map_err(run_error)
}

/// Process the recording `log` (named `log_name` in messages, streamed) of the calibration
/// the study planned, and judge its specifications.
///
/// # Errors
/// An [`InputError`] naming the line, column, segment or option; a library failure.
pub fn calibrate<R: Read>(
    s: &Study,
    log: R,
    log_name: &str,
    o: &Options,
) -> Result<CalibrationAnswer> {
    let opts = CalibrateOptions {
        recording: o.recording.clone(),
        segments: o.segments.clone(),
        detect: DetectSettings {
            block_s: o.block_s,
            min_static_s: o.min_static_s,
            ..DetectSettings::default()
        },
        robust: o.robust,
        coverage: s.uncertainty.coverage,
        tolerances: o.tolerances.clone(),
    };
    let mut decimator = o.overview_buckets.map(Decimator::new);
    let run = calib_run::calibrate_observed(s, log, log_name, &opts, |row| {
        if let Some(d) = decimator.as_mut() {
            d.push(row.t_s, row.values);
        }
    })
    .map_err(run_error)?;
    let (mut verdicts, spec_notes) =
        calib_run::study_verdicts(&run, s, DECISION_RULE).map_err(run_error)?;
    verdicts.extend(calib_run::verdicts(&run, &o.specs, DECISION_RULE).map_err(run_error)?);
    Ok(CalibrationAnswer {
        run,
        verdicts,
        spec_notes,
        overview: decimator.map(Decimator::finish),
    })
}

/// A calibration file's text (`name` names it) read.
///
/// # Errors
/// An [`InputError`] naming the file.
pub fn calibration_file(name: &str, text: &str) -> Result<CalibrationFile> {
    CalibrationFile::parse(name, text).map_err(run_error)
}

/// Correct the recording `log` (named `log_name`) with the calibration `cal` (its file named
/// `cal_name`), streaming the corrected CSV to `out`.
///
/// # Errors
/// An [`InputError`] naming the line or column; a library failure.
pub fn apply<R: Read, W: Write>(
    cal: &CalibrationFile,
    cal_name: &str,
    log: R,
    log_name: &str,
    o: &RecordingOptions,
    out: W,
) -> Result<ApplySummary> {
    calib_run::file::apply(cal, cal_name, log, log_name, o, out).map_err(run_error)
}
