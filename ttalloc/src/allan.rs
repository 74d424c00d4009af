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
use crate::csvio::Source;
use crate::input::lab;
use allan::{FLICKER_FLOOR_FACTOR, Taus, Term};
use anyhow::Result;
use clap::Parser;
use std::path::{Path, PathBuf};
use tt_core::human::sig;
use tt_lab::noise_log::{NoiseLog, Options, joint_terms};

/// Arguments of `allan`.
#[derive(Debug, Parser)]
pub(crate) struct Args {
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

fn text_of(log: &NoiseLog, unit: &str) -> String {
    let a = log.analysis();
    let f = &a.fit();
    let pm = |u: Option<f64>| u.map_or(String::new(), |u| format!(" (+- {})", sig(u, 2)));
    let mut t = format!(
        "Allan deviation of {}, column `{}`: {} samples at {} Hz ({} s); bands at {} % confidence\n",
        log.name().escape_debug(),
        log.column().escape_debug(),
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

/// Run the command.
///
/// # Errors
/// [`InputError`] for bad input (exit 2, nothing on standard output); other errors for a
/// failing disk.
pub(crate) fn run(args: &Args) -> Result<()> {
    let outputs: Vec<(&str, &Path)> = [
        ("--figure", &args.figure),
        ("--write-noise", &args.write_noise),
    ]
    .into_iter()
    .filter_map(|(f, p)| p.as_deref().map(|p| (f, p)))
    .collect();
    crate::newfile::check_all(&outputs)?;
    let source = Source::from_arg(args.log.as_deref());
    let mut opts = Options::at_rate_hz(args.rate_hz);
    opts.column.clone_from(&args.column);
    opts.confidence = args.confidence;
    opts.taus = args.taus.clone().unwrap_or_default();
    let log = tt_lab::noise_log::analyse(source.open()?, &source.name(), &opts).map_err(lab)?;
    let unit = args.unit.as_deref().unwrap_or("log unit");
    let stdout = if args.json {
        let mut s =
            serde_json::to_string_pretty(&serde_json::to_value(log.view(args.unit.as_deref()))?)?;
        s.push('\n');
        s
    } else {
        text_of(&log, unit)
    };
    let mut staged = Vec::new();
    if let Some(p) = &args.figure {
        staged.push((
            "--figure",
            crate::newfile::stage(
                p,
                tt_report::allan_figure::allan_figure_svg(&log, unit)
                    .map_err(crate::report::report_error)?
                    .as_bytes(),
            )
            .map_err(lab)?,
            p,
        ));
    }
    if let Some(p) = &args.write_noise {
        let block = log.noise_block();
        if block.written().is_empty() {
            let why: Vec<String> = block
                .not_written()
                .iter()
                .map(|n| format!("{}: {}", n.term(), n.reason()))
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
        for n in block.not_written() {
            eprintln!(
                "allan: not written to {}: {} = {}: {}",
                p.display().to_string().escape_debug(),
                n.term(),
                sig(n.value(), 4),
                n.reason()
            );
        }
        staged.push((
            "--write-noise",
            crate::newfile::stage(p, log.noise_toml(unit, &block).as_bytes()).map_err(lab)?,
            p,
        ));
    }
    let mut written = String::new();
    for (flag, tmp, p) in staged {
        tmp.commit(flag).map_err(lab)?;
        if !args.json {
            written.push_str(&format!("wrote {}\n", crate::paths::visible(p)));
        }
    }
    crate::out::print(&(stdout + &written))
}
