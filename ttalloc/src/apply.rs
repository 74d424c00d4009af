//! `ttalloc apply --calibration C.json [LOG.csv] [--out FILE.csv] [--json]`: correct a
//! recording with a calibration file: for every sample, the inputs (specific force in g, rate
//! in deg/h) the calibrated model maps to the recorded outputs, streamed (the `calib-run`
//! crate, one call). The corrected CSV goes to `--out` (never over an existing file; written
//! whole or not at all) or to standard output.

use crate::InputError;
use crate::csvio::Source;
use crate::input::lab;
use anyhow::Result;
use calib_run::recording::RecordingOptions;
use clap::Parser;
use std::io::Write;
use std::path::PathBuf;
use tt_lab::calibrate::{apply, calibration_file};

/// Arguments of `apply`.
#[derive(Debug, Parser)]
pub(crate) struct Args {
    /// The calibration file (`ttalloc calibrate --out`).
    #[arg(long)]
    pub calibration: PathBuf,
    /// The recording: a CSV file with a header line, or `-` (or nothing) for standard input.
    pub log: Option<PathBuf>,
    /// Write the corrected CSV here (it must not exist); default: standard output.
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// The time column (default: `t_s`, `time_s`, `sample` or `index`).
    #[arg(long)]
    pub time_column: Option<String>,
    /// Sample rate, Hz (for a sample-index column).
    #[arg(long, value_parser = |s: &str| crate::args::positive(s, 1e12))]
    pub sample_rate_hz: Option<f64>,
    /// With `--out`: print the summary as JSON.
    #[arg(long, requires = "out")]
    pub json: bool,
}

/// Run `apply`.
///
/// # Errors
/// [`InputError`] for bad input (exit 2); others.
pub(crate) fn run(args: &Args) -> Result<()> {
    let name = args.calibration.display().to_string();
    let text = std::fs::read_to_string(&args.calibration)
        .map_err(|e| InputError::new(&name, format!("cannot read: {e}")))?;
    let cal = calibration_file(&name, &text).map_err(lab)?;
    if let Some(out) = &args.out {
        crate::newfile::check(out, "--out")?;
    }
    let source = Source::from_arg(args.log.as_deref());
    let reader = source.open()?;
    let opts = RecordingOptions {
        time_column: args.time_column.clone(),
        sample_rate_hz: args.sample_rate_hz,
        ..RecordingOptions::default()
    };
    match &args.out {
        None => {
            let stdout = std::io::stdout();
            let w = std::io::BufWriter::new(stdout.lock());
            apply(&cal, &name, reader, &source.name(), &opts, w).map_err(lab)?;
            Ok(())
        }
        Some(out) => {
            let dir = match out.parent() {
                Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
                _ => PathBuf::from("."),
            };
            let mut tmp = tempfile::NamedTempFile::new_in(&dir)?;
            let summary = {
                let w = std::io::BufWriter::new(tmp.as_file_mut());
                apply(&cal, &name, reader, &source.name(), &opts, w).map_err(lab)?
            };
            tmp.as_file_mut().flush()?;
            tmp.as_file().sync_all()?;
            tmp.persist_noclobber(out).map_err(|e| {
                InputError::new(crate::paths::visible(out), format!("--out: {}", e.error))
            })?;
            if args.json {
                return crate::json::print(&summary);
            }
            crate::out::print(&format!(
                "{} samples corrected ({}), max model mismatch {}; written {}\n",
                summary.samples,
                summary.columns.join(", "),
                tt_core::human::sig(summary.max_mismatch, 3),
                crate::paths::visible(out)
            ))
        }
    }
}
