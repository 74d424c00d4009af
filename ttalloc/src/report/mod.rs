//! `cargo xtask report --study FILE [--out DIR] [--seed N] [--samples N] [--tolerances FILE]
//! [--designed FILE] [--jcgm101 [--mc-digits D]]`: the report of any study, and `cargo xtask reproduce-paper [--out DIR]
//! [--seed N] [--samples N]`: the same report for the paper's study with the paper's printed
//! values beside ours and its claims.
//!
//! Files (written atomically by [`crate::outdir`]: nothing of the user's is touched, a failed
//! run leaves nothing behind): `report.md`, `report.html` (self-contained, figures inline),
//! the SVG figures, CSV tables and `results.json`. Default directory:
//! `target/report/<study name>` (`target/paper` for the paper) in the workspace.
//!
//! This module parses, calls the report library ([`tt_report::Report`]: the model computed from
//! the study-level questions, rendered as files) and writes; it computes and formats nothing.

use crate::InputError;
use crate::calibrate::RecordingArgs;
use crate::input::lab;
use anyhow::Result;
use clap::Parser;
use std::path::{Path, PathBuf};
/// The figures, for the other commands that draw one (allan, design-schedule).
pub(crate) use tt_report::figures;
use tt_report::{ProcessedRun, Report, ReportOptions};

/// Arguments of `report`.
#[derive(Debug, Parser)]
pub(crate) struct Args {
    /// Study file.
    #[arg(long)]
    pub study: PathBuf,
    /// Output directory (default: `target/report/<study name>`); replaced only when it holds a
    /// previous report.
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// `--samples` and `--seed` (default: the study's `monte_carlo`).
    #[command(flatten)]
    pub sampling: crate::args::Sampling,
    /// A vendor's tolerance file to check (TOML: `[tolerances_arcmin]`).
    #[arg(long)]
    pub tolerances: Option<PathBuf>,
    /// A study with a designed schedule (same sensor and turntable) to compare side by side.
    #[arg(long)]
    pub designed: Option<PathBuf>,
    /// The recording of the study's calibration (CSV, or `-` for standard input): the report
    /// gains a "Processed run" section (as `calibrate`; `--tolerances` is its table part).
    #[arg(long)]
    pub recording: Option<PathBuf>,
    /// How the recording is read and processed (as `calibrate`).
    #[command(flatten)]
    pub run: RecordingArgs,
    /// The JCGM 101 Monte Carlo of every specification (`--jcgm101`, `--mc-digits`; as
    /// `check-turntable` and `end-to-end`), seeded by `--seed`.
    #[command(flatten)]
    pub jcgm101: crate::text::jcgm101::Flags,
}

/// Arguments of `reproduce-paper`.
#[derive(Debug, Parser)]
pub(crate) struct PaperArgs {
    /// Output directory (default: `target/paper`); replaced only when it holds a previous
    /// report.
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// `--samples` and `--seed` (default: the study's `monte_carlo`).
    #[command(flatten)]
    pub sampling: crate::args::Sampling,
}

/// The workspace's `target` directory (or `./target` outside a clone).
fn target_dir() -> PathBuf {
    crate::paths::workspace_root().map_or_else(|_| PathBuf::from("target"), |r| r.join("target"))
}

/// The directory `report` writes a study's report to without `--out`: `<target>/report/<name>`.
/// The study's `name` is a file-name-safe slug (checked when the study is read), so this is one
/// entry directly inside `<target>/report` (the fuzz harness checks it for hostile names).
pub fn default_report_dir(target: &Path, study_name: &str) -> PathBuf {
    target.join("report").join(study_name)
}

/// A report's error as the command's: its input errors stay [`InputError`]s (exit 2).
pub(crate) fn report_error(e: tt_report::Error) -> anyhow::Error {
    match e {
        tt_report::Error::Lab(l) => lab(l),
        other => anyhow::Error::new(other),
    }
}

/// Write a computed report into the checked and locked output directory; print one summary
/// line and where to open it.
fn write(r: &Report, out: &Path, prepared: crate::outdir::Prepared, what: &str) -> Result<()> {
    let files: Vec<(String, Vec<u8>)> = r
        .files()
        .map_err(report_error)?
        .into_iter()
        .map(|f| (f.name, f.bytes))
        .collect();
    let notes = prepared.notes.clone();
    let dir = prepared.dir().to_path_buf();
    prepared.write(&files).map_err(lab)?;
    // every path printed as one visible line; the hint to copy as one shell word
    let linked = if dir == out {
        String::new()
    } else {
        format!(" (a link to {})", crate::paths::visible(&dir))
    };
    let s = r.study();
    let mut t = format!(
        "{what}: study {} ({}), seed {}, {} samples: wrote {} files to {}{linked} in {:.1} s\n",
        s.name,
        tt_core::human::visible(&s.path),
        r.seed(),
        r.samples(),
        files.len() + 1,
        crate::paths::visible(out),
        r.seconds()
    );
    for n in &notes {
        t.push_str(&format!("  note: {n}\n"));
    }
    for n in r.summary_notes() {
        t.push_str(&format!("  {n}\n"));
    }
    t.push_str(&format!(
        "  open {}\n",
        crate::paths::shell_quote(&out.join("report.html").display().to_string())
    ));
    crate::out::print(&t)
}

/// Read and check a report's inputs (study, tolerances, designed study) and its options.
///
/// # Errors
/// [`InputError`] for bad inputs.
fn inputs(
    study: Option<&Path>,
    seed: Option<u64>,
    samples: Option<u64>,
    tolerances: Option<&Path>,
    designed: Option<&Path>,
    paper: bool,
) -> Result<(study::Study, ReportOptions)> {
    let s = crate::loaded::load(study)?;
    let tolerances = match tolerances {
        Some(p) => Some(s.load_sheet(p).map_err(InputError::from)?),
        None => None,
    };
    let designed = match designed {
        Some(p) => Some(
            crate::loaded::load(Some(p))
                .map_err(|e| InputError::new(format!("--designed {}", e.location), e.reason))?,
        ),
        None => None,
    };
    crate::end_to_end::check_yield_samples(
        samples.unwrap_or(s.monte_carlo.samples),
        samples.is_some(),
        e2e_verify::DEFAULT_YIELD_FRACTION,
        &s,
    )?;
    let mut options = ReportOptions::default();
    options.seed = Some(seed.unwrap_or(s.monte_carlo.seed));
    options.samples = Some(samples.unwrap_or(s.monte_carlo.samples));
    options.paper = paper;
    options.tolerances = tolerances;
    options.designed = designed;
    Ok((s, options))
}

/// Run `report`: the inputs and the output directory are checked (and the directory locked)
/// before the work.
///
/// # Errors
/// As [`inputs`], [`Report::compute`] and the output directory.
pub(crate) fn run(args: &Args) -> Result<()> {
    let (s, mut options) = inputs(
        Some(&args.study),
        args.sampling.seed,
        args.sampling.samples,
        args.tolerances.as_deref(),
        args.designed.as_deref(),
        false,
    )?;
    options.run = processed_run(&s, args)?;
    options.jcgm101 = args.jcgm101.options(None);
    // the name is a file-name-safe slug (checked when the study was read): one component
    let out = args
        .out
        .clone()
        .unwrap_or_else(|| default_report_dir(&target_dir(), &s.name));
    let prepared = crate::outdir::Prepared::new(&out).map_err(lab)?;
    let r = Report::compute(s, options).map_err(report_error)?;
    write(&r, &out, prepared, "report")
}

/// The recording of `--recording` processed (before the output directory is touched: a bad
/// recording exits 2 and nothing is written), with an overview for the figure.
///
/// # Errors
/// [`InputError`] naming the flag, the line, the column or the segment.
fn processed_run(s: &study::Study, args: &Args) -> Result<Option<ProcessedRun>> {
    let Some(log) = &args.recording else {
        if let Some(flag) = args.run.first_given() {
            return Err(InputError::new(flag, "applies to a recording: give `--recording`").into());
        }
        return Ok(None);
    };
    let tolerances = match &args.tolerances {
        Some(t) => Some(study::Tolerances::load(t, &s.turntable).map_err(InputError::from)?),
        None => None,
    };
    let mut opts = args.run.options(s, tolerances)?;
    opts.overview_buckets = Some(calib_run::overview::DEFAULT_BUCKETS);
    let source = crate::csvio::Source::from_arg(Some(log));
    let answer = tt_lab::calibrate::calibrate(s, source.open()?, &source.name(), &opts)
        .map_err(crate::input::lab)?;
    let mut flags = vec!["--recording".to_string(), log.display().to_string()];
    flags.extend(args.run.flags());
    Ok(Some(ProcessedRun::new(answer, flags)))
}

/// Run `reproduce-paper`.
///
/// # Errors
/// As [`inputs`], [`Report::compute`] and the output directory.
pub(crate) fn run_paper(args: &PaperArgs) -> Result<()> {
    let (s, options) = inputs(
        None,
        args.sampling.seed,
        args.sampling.samples,
        None,
        None,
        true,
    )?;
    let out = args
        .out
        .clone()
        .unwrap_or_else(|| target_dir().join("paper"));
    let prepared = crate::outdir::Prepared::new(&out).map_err(lab)?;
    let r = Report::compute(s, options).map_err(report_error)?;
    write(&r, &out, prepared, "reproduce-paper")
}
