//! `cargo xtask report --study FILE [--out DIR] [--seed N] [--samples N] [--tolerances FILE]
//! [--designed FILE]`: the report of any study, and `cargo xtask reproduce-paper [--out DIR]
//! [--seed N] [--samples N]`: the same report for the paper's study with the paper's printed
//! values beside ours and its claims.
//!
//! Files (written atomically by [`crate::outdir`]: nothing of the user's is touched, a failed
//! run leaves nothing behind): `report.md`, `report.html` (self-contained, figures inline),
//! the SVG figures, CSV tables and `results.json`. Default directory:
//! `target/report/<study name>` (`target/paper` for the paper) in the workspace.
//!
//! This module parses, calls [`compute`] (the libraries), formats (`render`, `paper`) and
//! writes; it computes no science.

pub(crate) mod compute;
mod paper;
mod render;
mod results;

use crate::InputError;
use anyhow::{Result, bail};
use clap::Parser;
use compute::{Computed, Options};
use render::Sections;
use serde_json::Value;
use std::cell::Cell;
use std::path::{Path, PathBuf};
use tt_core::units::objective_to_arcmin;
use tt_report::doc;
/// The figures, for the other commands that draw one (allan, design-schedule).
pub(crate) use tt_report::figures;

/// Arguments of `report`.
#[derive(Debug, Parser)]
pub struct Args {
    /// Study file.
    #[arg(long)]
    pub study: PathBuf,
    /// Output directory (default: `target/report/<study name>`); replaced only when it holds a
    /// previous report.
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Seed of the Monte Carlo streams (default: the study's `monte_carlo.seed`).
    #[arg(long, allow_negative_numbers = true, value_parser = crate::args::seed)]
    pub seed: Option<u64>,
    /// Monte Carlo turntables per box (default: the study's `monte_carlo.samples`; accepts
    /// `1e4`, `10000`, `10_000`).
    #[arg(long, allow_negative_numbers = true, value_parser = crate::args::samples)]
    pub samples: Option<u64>,
    /// A vendor's tolerance file to check (TOML: `[tolerances_arcmin]`).
    #[arg(long)]
    pub tolerances: Option<PathBuf>,
    /// A study with a designed schedule (same sensor and turntable) to compare side by side.
    #[arg(long)]
    pub designed: Option<PathBuf>,
}

/// Arguments of `reproduce-paper`.
#[derive(Debug, Parser)]
pub struct PaperArgs {
    /// Output directory (default: `target/paper`); replaced only when it holds a previous
    /// report.
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Seed of the Monte Carlo streams (default: the study's, 2017).
    #[arg(long, allow_negative_numbers = true, value_parser = crate::args::seed)]
    pub seed: Option<u64>,
    /// Monte Carlo turntables per box (default: the study's, the paper's 10,000).
    #[arg(long, allow_negative_numbers = true, value_parser = crate::args::samples)]
    pub samples: Option<u64>,
}

/// A rendered report: title, document, CSV files (name, text), `results.json`.
type Rendered = (String, doc::Doc, Vec<(String, String)>, Value);

/// Render the computed report.
fn render(c: &Computed) -> Result<Rendered> {
    let mut sec = Sections::new(c);
    let s = &c.study;
    let title = if c.paper.is_some() {
        "Reproduction of Zhao, Zhao, Huo and Yao (2017)".to_string()
    } else {
        format!("Turntable error allocation: {}", doc::text(&s.name))
    };
    sec.doc.h(1, &title);
    if c.paper.is_some() {
        sec.doc.p("\"Error Analysis and Error Allocation for Turntable Systems Used in GyroWheel Calibration Tests\", Int. J. Aerospace Eng. 2017, 6524782. Every number below is computed by this project's crates from the study file; the paper's printed values stand beside ours.");
    } else if let Some(desc) = &s.description {
        sec.doc.p(doc::text(desc));
    }
    sec.doc.p(format!(
        "Study {}, {} Monte Carlo turntables per box, seed {}; computed in {:.1} s by the workspace's crates. Reproduce: {}.",
        doc::code(&s.path),
        c.options.samples,
        c.options.seed,
        c.seconds,
        doc::code(&command(c))
    ));
    sec.answer_callout();
    sec.doc.contents();
    let splice_at = sec.doc.blocks.len();
    sec.inputs();
    sec.calibration();
    sec.requirement()?;
    sec.sensitivities()?;
    let table4 = match (&c.paper, &c.two_step) {
        (Some(_), Some(t)) => {
            let w = alloc_opt::Weights::inverse_average_sensitivity(t.problem.model());
            let t4 = alloc_opt::paper::table4_rad();
            let cert = alloc_opt::Certificate::compute(
                t.problem.model(),
                t.problem.limits(),
                t.problem.lower_bounds_rad(),
                &t4,
            )
            .map_err(|e| crate::input::library(e, s))?;
            Some((
                alloc_opt::paper::TABLE4_ARCMIN.to_vec(),
                objective_to_arcmin(w.objective(&t4)),
                [0, 1, 2].map(|k| cert.axes()[k].share()),
            ))
        }
        _ => None,
    };
    sec.allocation(table4.as_ref());
    sec.monte_carlo(
        c.paper
            .as_ref()
            .map(|p| (&p.table4_monte_carlo, &p.table4_result)),
    )?;
    sec.end_to_end()?;
    sec.noise()?;
    sec.specifications()?;
    sec.rate_allocation();
    sec.vendor();
    sec.designed();
    sec.angle_allocation();
    sec.estimable();
    let comparisons = match &c.paper {
        Some(p) => {
            let rows = paper::comparisons(c, p);
            let extra = paper::sections(&sec, p, &rows);
            sec.doc.blocks.splice(splice_at..splice_at, extra.blocks);
            paper::open_points(&mut sec.doc, c);
            rows
        }
        None => Vec::new(),
    };
    sec.doc.h(2, "Reproduce");
    sec.doc.code(format!("{}\ncargo xtask test", command(c)));
    let json = results::results_json(c, &comparisons)?;
    Ok((title, sec.doc, sec.csv, json))
}

/// The command that reproduces the report (paths as the user gave them, shell-quoted).
fn command(c: &Computed) -> String {
    use crate::paths::shell_quote as q;
    if c.paper.is_some() {
        return format!(
            "cargo xtask reproduce-paper --seed {} --samples {}",
            c.options.seed, c.options.samples
        );
    }
    let mut s = format!(
        "cargo xtask report --study {} --seed {} --samples {}",
        q(&c.study.path),
        c.options.seed,
        c.options.samples
    );
    if let Some((t, _)) = &c.vendor {
        s.push_str(&format!(" --tolerances {}", q(t.source())));
    }
    if let Some([_, dsg]) = &c.designed {
        s.push_str(&format!(" --designed {}", q(&dsg.path)));
    }
    s
}

/// The files of a report (name, bytes), checked: no NaN anywhere, every internal link
/// resolves.
pub(crate) fn files(c: &Computed) -> Result<Vec<(String, Vec<u8>)>> {
    results::NAN_SEEN.with(|x| x.set(false));
    let (title, doc, csv, json) = render(c)?;
    let md = doc.to_markdown();
    let html = doc.to_html(&title);
    if results::NAN_SEEN.with(Cell::get)
        || md.contains("NaN")
        || csv.iter().any(|(_, t)| t.contains("NaN"))
    {
        bail!(
            "internal error: a NaN reached the report of {}; nothing was written",
            c.study.path
        );
    }
    let anchors = doc.anchors();
    for part in html.split("href=\"#").skip(1) {
        let id = part.split('"').next().unwrap_or("");
        if !anchors.contains(&id) {
            bail!("internal error: the report links to #{id}, which it does not contain");
        }
    }
    let mut out: Vec<(String, Vec<u8>)> = vec![
        ("report.md".into(), md.into_bytes()),
        ("report.html".into(), html.into_bytes()),
    ];
    for (name, svg) in doc.figures() {
        out.push((name.to_string(), svg.as_bytes().to_vec()));
    }
    for (name, text) in csv {
        out.push((name, text.into_bytes()));
    }
    out.push((
        "results.json".into(),
        (serde_json::to_string_pretty(&json)? + "\n").into_bytes(),
    ));
    Ok(out)
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

/// Write a computed report into the checked and locked output directory; print one summary
/// line and where to open it.
fn write(c: &Computed, out: &Path, prepared: crate::outdir::Prepared, what: &str) -> Result<()> {
    let files = files(c)?;
    let notes = prepared.notes.clone();
    let dir = prepared.dir().to_path_buf();
    prepared.write(&files)?;
    // every path printed as one visible line; the hint to copy as one shell word
    let linked = if dir == out {
        String::new()
    } else {
        format!(" (a link to {})", crate::paths::visible(&dir))
    };
    let mut t = format!(
        "{what}: study {} ({}), seed {}, {} samples: wrote {} files to {}{linked} in {:.1} s\n",
        c.study.name,
        study::fmt::visible(&c.study.path),
        c.options.seed,
        c.options.samples,
        files.len() + 1,
        crate::paths::visible(out),
        c.seconds
    );
    for n in &notes {
        t.push_str(&format!("  note: {n}\n"));
    }
    if let Some(p) = &c.paper {
        t.push_str(&format!(
            "  {}\n",
            e2e_verify::paper::registry::summary(&p.claims)
        ));
    }
    if let Some(n) = &c.requirement.disagreement {
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
) -> Result<(study::Study, Options)> {
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
    let options = Options {
        seed: seed.unwrap_or(s.monte_carlo.seed),
        samples: samples.unwrap_or(s.monte_carlo.samples),
        paper,
        tolerances,
        designed,
    };
    Ok((s, options))
}

/// Run `report`: the inputs and the output directory are checked (and the directory locked)
/// before the work.
///
/// # Errors
/// As [`inputs`], [`compute::compute`] and the output directory.
pub fn run(args: &Args) -> Result<()> {
    let (s, options) = inputs(
        Some(&args.study),
        args.seed,
        args.samples,
        args.tolerances.as_deref(),
        args.designed.as_deref(),
        false,
    )?;
    // the name is a file-name-safe slug (checked when the study was read): one component
    let out = args
        .out
        .clone()
        .unwrap_or_else(|| default_report_dir(&target_dir(), &s.name));
    let prepared = crate::outdir::Prepared::new(&out)?;
    let c = compute::compute(s, options)?;
    write(&c, &out, prepared, "report")
}

/// Run `reproduce-paper`.
///
/// # Errors
/// As [`inputs`], [`compute::compute`] and the output directory.
pub fn run_paper(args: &PaperArgs) -> Result<()> {
    let (s, options) = inputs(None, args.seed, args.samples, None, None, true)?;
    let out = args
        .out
        .clone()
        .unwrap_or_else(|| target_dir().join("paper"));
    let prepared = crate::outdir::Prepared::new(&out)?;
    let c = compute::compute(s, options)?;
    write(&c, &out, prepared, "reproduce-paper")
}

/// What the report says of the joint estimation for a study with rate steps.
pub(crate) const ESTIMABLE_STATIC_ONLY: &str = "not evaluated: the joint estimation of table errors takes static positions only, and this study has rate steps";
