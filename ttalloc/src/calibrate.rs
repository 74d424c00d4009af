//! `ttalloc calibrate --study S [LOG.csv] [--segments FILE] [--out CAL.json] [--json] ...`:
//! process the recording of the calibration the study planned (the `calib-run` crate does the
//! work, one call): the coefficients of every output with their expanded uncertainties, the
//! measured noise, the residuals per segment with outlier flags, the plan's predicted
//! uncertainty beside the run's, and verdicts on `--spec NAME=LIMIT` under a named decision
//! rule. `--out` writes the calibration file (JSON or TOML, by its extension), never over an existing file. The log is a
//! CSV file or standard input (`-` or nothing), streamed. See docs/calibrate.md.
//!
//! Bad input (a cell, a missing column, a gap, segments that do not fit the schedule) exits
//! with code 2 naming the line, the column or the segment, and nothing is written.

use crate::InputError;
use crate::csvio::Source;
use crate::input::lab;
use crate::loaded as st;
use anyhow::Result;
use calib_run::Spec;
use clap::Parser;
use std::path::PathBuf;
use tt_core::human::sig;
use tt_lab::calibrate::Options;

/// Arguments of `calibrate`.
#[derive(Debug, Parser)]
pub(crate) struct Args {
    /// Study file that planned the calibration (default: `studies/gyrowheel-2017.toml`).
    #[arg(long)]
    pub study: Option<PathBuf>,
    /// The recording: a CSV file with a header line, or `-` (or nothing) for standard input.
    pub log: Option<PathBuf>,
    /// Write the calibration file here (`.json` or `.toml`, the format chosen by the
    /// extension); it must not exist.
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// The table's tolerance sheet (its part of the uncertainty budget).
    #[arg(long)]
    pub tolerances: Option<PathBuf>,
    /// How the recording is read and processed.
    #[command(flatten)]
    pub recording: RecordingArgs,
    /// Print JSON instead of text.
    #[arg(long)]
    pub json: bool,
}

/// How a recording is read and processed (`calibrate`, and `report --recording`).
#[derive(Debug, Clone, Default, clap::Args)]
pub(crate) struct RecordingArgs {
    /// Segments file (CSV `start,end,entry[,kind]`); default: detected.
    #[arg(long)]
    pub segments: Option<PathBuf>,
    /// An output's column when not named as the output: `OUTPUT=HEADER` (repeatable).
    #[arg(long = "column", value_name = "OUTPUT=HEADER")]
    pub columns: Vec<String>,
    /// The time column (default: `t_s`, `time_s`, `sample` or `index`).
    #[arg(long)]
    pub time_column: Option<String>,
    /// Sample rate, Hz (needed with a sample-index column when the study has no timing).
    #[arg(long, value_parser = |s: &str| crate::args::positive(s, 1e12))]
    pub sample_rate_hz: Option<f64>,
    /// The outputs' range: values at or above it in magnitude are flagged saturated.
    #[arg(long, value_parser = |s: &str| crate::args::positive(s, f64::MAX))]
    pub range: Option<f64>,
    /// Also fit robustly (Huber) and report what it changed; the robust estimate is the one
    /// written.
    #[arg(long)]
    pub robust: bool,
    /// A specification `COEFFICIENT=LIMIT` (|value| <= LIMIT, the coefficient's unit;
    /// repeatable), judged with the ILAC-G8 guard band w = U.
    #[arg(long = "spec", value_name = "COEFFICIENT=LIMIT")]
    pub specs: Vec<String>,
    /// Detection: block length, s (default 0.5).
    #[arg(long, value_parser = |s: &str| crate::args::positive(s, 1e6))]
    pub block_s: Option<f64>,
    /// Detection: shortest static interval used, s (default: half the study's shortest dwell,
    /// else 1 s).
    #[arg(long, value_parser = |s: &str| crate::args::positive(s, 1e9))]
    pub min_static_s: Option<f64>,
}

impl RecordingArgs {
    /// The first of these flags given (as the user writes it), if any: `report` refuses them
    /// without `--recording`.
    #[must_use]
    pub(crate) fn first_given(&self) -> Option<&'static str> {
        [
            (self.segments.is_some(), "--segments"),
            (!self.columns.is_empty(), "--column"),
            (self.time_column.is_some(), "--time-column"),
            (self.sample_rate_hz.is_some(), "--sample-rate-hz"),
            (self.range.is_some(), "--range"),
            (self.robust, "--robust"),
            (!self.specs.is_empty(), "--spec"),
            (self.block_s.is_some(), "--block-s"),
            (self.min_static_s.is_some(), "--min-static-s"),
        ]
        .into_iter()
        .find_map(|(given, flag)| given.then_some(flag))
    }

    /// The flags as given, for a command line that reproduces the run (unquoted).
    #[must_use]
    pub(crate) fn flags(&self) -> Vec<String> {
        let mut f: Vec<String> = Vec::new();
        let mut push = |flag: &str, v: String| {
            f.push(flag.into());
            f.push(v);
        };
        if let Some(p) = &self.segments {
            push("--segments", p.display().to_string());
        }
        for c in &self.columns {
            push("--column", c.clone());
        }
        if let Some(t) = &self.time_column {
            push("--time-column", t.clone());
        }
        if let Some(v) = self.sample_rate_hz {
            push("--sample-rate-hz", v.to_string());
        }
        if let Some(v) = self.range {
            push("--range", v.to_string());
        }
        for x in &self.specs {
            push("--spec", x.clone());
        }
        if let Some(v) = self.block_s {
            push("--block-s", v.to_string());
        }
        if let Some(v) = self.min_static_s {
            push("--min-static-s", v.to_string());
        }
        if self.robust {
            f.push("--robust".into());
        }
        f
    }

    /// The processing options for study `s` (the segments file read against its schedule);
    /// `tolerances`: the table's sheet of the budget, already read.
    ///
    /// # Errors
    /// [`InputError`] naming the flag or the segments file's line.
    pub(crate) fn options(
        &self,
        s: &study::Study,
        tolerances: Option<study::Tolerances>,
    ) -> Result<Options> {
        let mut opts = Options::default();
        for c in &self.columns {
            let (o, h) = pair("--column", c)?;
            opts.recording.columns.push((o.into(), h.into()));
        }
        opts.recording.time_column.clone_from(&self.time_column);
        opts.recording.sample_rate_hz = self.sample_rate_hz;
        opts.recording.range = self.range;
        opts.robust = self.robust;
        if let Some(b) = self.block_s {
            opts.block_s = b;
        }
        opts.min_static_s = self.min_static_s;
        opts.tolerances = tolerances;
        opts.specs = self
            .specs
            .iter()
            .map(|x| {
                let (c, l) = pair("--spec", x)?;
                let limit: f64 = l
                    .parse()
                    .map_err(|_| InputError::new("--spec", format!("`{l}` is not a number")))?;
                Ok(Spec {
                    coefficient: c.into(),
                    limit,
                    unit: None,
                })
            })
            .collect::<Result<Vec<_>, InputError>>()?;
        if let Some(p) = &self.segments {
            let name = p.display().to_string();
            let f = std::fs::File::open(p)
                .map_err(|e| InputError::new(&name, format!("cannot read: {e}")))?;
            opts.segments = Some(tt_lab::calibrate::segments(s, f, &name).map_err(lab)?);
        }
        Ok(opts)
    }
}

fn pair<'a>(flag: &str, s: &'a str) -> Result<(&'a str, &'a str), InputError> {
    s.split_once('=')
        .filter(|(a, b)| !a.is_empty() && !b.is_empty())
        .ok_or_else(|| InputError::new(flag, format!("`{s}` is not NAME=VALUE")))
}

/// Run `calibrate`.
///
/// # Errors
/// [`InputError`] for bad input (exit 2); others.
pub(crate) fn run(args: &Args) -> Result<()> {
    let s = st::load(args.study.as_deref())?;
    if let Some(out) = &args.out {
        calib_run::file::Format::of_path(out, "--out")
            .map_err(|e| lab(tt_lab::calibrate::run_error(e)))?;
        crate::newfile::check(out, "--out")?;
    }
    let tolerances = match &args.tolerances {
        Some(t) => Some(study::Tolerances::load(t, &s.turntable).map_err(InputError::from)?),
        None => None,
    };
    let opts = args.recording.options(&s, tolerances)?;
    let source = Source::from_arg(args.log.as_deref());
    let reader = source.open()?;
    let answer = tt_lab::calibrate::calibrate(&s, reader, &source.name(), &opts).map_err(lab)?;
    let run = answer.run();
    if let Some(out) = &args.out {
        calib_run::file::write_new(out, &calib_run::file::CalibrationFile::of(run))
            .map_err(|e| lab(tt_lab::calibrate::run_error(e)))?;
    }
    if args.json {
        return crate::json::print(
            &answer.view(args.out.as_ref().map(|p| p.display().to_string())),
        );
    }
    crate::out::print(&text(
        run,
        answer.verdicts(),
        answer.specification_notes(),
        args.out.as_ref(),
    ))
}

fn text(
    run: &calib_run::Run,
    verdicts: &[calib_run::Verdict],
    spec_notes: &[String],
    out: Option<&PathBuf>,
) -> String {
    use std::fmt::Write;
    let mut t = String::new();
    let r = run.recording();
    let _ = writeln!(
        t,
        "recording {}: {} samples, {} s at {} Hz, sha256 {}",
        r.source,
        r.samples,
        sig(r.duration_s, 6),
        sig(1.0 / r.dt_s, 6),
        r.sha256
    );
    let _ = writeln!(t, "segments: {}", run.segments().len());
    for w in run.warnings() {
        let _ = writeln!(t, "warning: {w}");
    }
    for o in run.outputs() {
        let n = o.noise();
        let _ = writeln!(
            t,
            "\noutput {}: measured white noise {} per sqrt(Hz) (study {}), chi2 {} with {} dof",
            o.name(),
            sig(n.white_per_sqrt_hz, 4),
            n.study_white_per_sqrt_hz
                .map_or("not given".into(), |v| sig(v, 4)),
            sig(o.chi2().0, 4),
            o.chi2().1
        );
        let _ = writeln!(t, "  plan predicted: {}", o.predicted_basis());
        for c in o.coefficients() {
            let (u, k) = c.expanded();
            let _ = writeln!(
                t,
                "  {} = {} +- {} {} (k = {}); u: noise {}, residuals {}, table {}; plan predicted {}{}",
                c.name(),
                sig(c.value(), 6),
                sig(u, 3),
                c.unit(),
                sig(k, 3),
                sig(c.u_measured_noise(), 3),
                c.u_residuals().map_or("-".into(), |v| sig(v, 3)),
                sig(c.u_table(), 3),
                c.predicted_u().map_or("-".into(), |v| sig(v, 3)),
                c.robust_change().map_or(String::new(), |d| format!(
                    "; robust moved it by {}",
                    sig(d, 3)
                ))
            );
        }
        let outliers: Vec<String> = o
            .residuals()
            .iter()
            .filter(|r| r.outlier)
            .map(|r| {
                format!(
                    "entry {} (z = {})",
                    run.segments()[r.segment].entry(),
                    sig(r.standardized, 3)
                )
            })
            .collect();
        if !outliers.is_empty() {
            let _ = writeln!(t, "  outliers: {}", outliers.join(", "));
        }
    }
    for v in verdicts {
        let _ = writeln!(t, "{}", v.statement);
    }
    for n in spec_notes {
        let _ = writeln!(t, "specification not judged here: {n}");
    }
    if let Some(p) = out {
        let _ = writeln!(t, "calibration file written: {}", crate::paths::visible(p));
    }
    t
}
