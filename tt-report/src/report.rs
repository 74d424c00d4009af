//! The report as a library: compute a study's report once ([`Report::compute`]), then render
//! its files ([`Report::files`]: `report.md`, `report.html`, the SVG figures, the CSV tables and
//! `results.json`) or read its results model ([`Report::results`], the JSON the report's
//! numbers come from), without running the binary or touching the disk. `ttalloc report`
//! writes exactly [`Report::files`] into its checked output directory.
//!
//! # Example
//! ```no_run
//! let study = study::Study::load(std::path::Path::new("studies/gyrowheel-2017.toml"))?;
//! let report = tt_report::Report::compute(study, tt_report::ReportOptions::default())?;
//! let markdown = report.markdown()?;
//! assert!(markdown.contains("Table 4"));
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

use crate::compute::{self, Computed, Options};
use crate::doc;
use crate::render::Sections;
use crate::{Error, Result, paper, results};
use e2e_verify::ToleranceSheet;
use serde_json::Value;
use std::cell::Cell;
use study::Study;
use tt_core::units::objective_to_arcmin;

/// What a report computes besides the study; [`Default`]: the study's own Monte Carlo seed and
/// sample count, no vendor sheet, no designed schedule, no paper extras.
#[derive(Debug, Clone, Default)]
#[non_exhaustive]
pub struct ReportOptions {
    /// Monte Carlo seed (`None`: the study's).
    pub seed: Option<u64>,
    /// Monte Carlo turntables per box (`None`: the study's); at least enough to resolve the
    /// yield target ([`e2e_verify::min_yield_samples`]).
    pub samples: Option<u64>,
    /// A vendor's tolerance sheet to check (read with [`Study::load_sheet`] for the study).
    pub tolerances: Option<ToleranceSheet>,
    /// A second study with a designed schedule, shown beside the study's.
    pub designed: Option<Study>,
    /// The paper's extras (Table 4, the claims): for the paper's study, as `reproduce-paper`.
    pub paper: bool,
    /// A processed recording of the study's calibration: the report gains its section.
    pub run: Option<crate::ProcessedRun>,
    /// The JCGM 101 Monte Carlo of every specification (`--jcgm101`, its significant digits
    /// and trial limit; its seed `None`: the report's): a subsection under the
    /// specifications' budgets, a figure and `results.json`'s `jcgm101`. `None`: not run.
    pub jcgm101: Option<tt_lab::budget_mc::Options>,
}

/// A computed report.
#[derive(Debug, Clone)]
pub struct Report {
    computed: Computed,
}

/// One file of a report: its name (`report.md`, `fig-….svg`, …) and its bytes.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ReportFile {
    /// The file's name, one path component.
    pub name: String,
    /// Its contents.
    pub bytes: Vec<u8>,
}

impl Report {
    /// Compute the report of `study`.
    ///
    /// # Errors
    /// [`Error::Lab`] with an input error ([`tt_lab::InputError`]) naming the key or option for
    /// bad input (too few samples for the yield target, a sheet of another turntable); a
    /// library error when a computation fails.
    pub fn compute(study: Study, options: ReportOptions) -> Result<Self> {
        let samples = options.samples.unwrap_or(study.monte_carlo.samples);
        tt_lab::end_to_end::check_yield_samples(
            samples,
            options.samples.is_some(),
            e2e_verify::DEFAULT_YIELD_FRACTION,
            &study,
        )?;
        let options = Options {
            seed: options.seed.unwrap_or(study.monte_carlo.seed),
            samples,
            paper: options.paper,
            tolerances: options.tolerances,
            designed: options.designed,
            run: options.run,
            jcgm101: options.jcgm101,
        };
        Ok(Self {
            computed: compute::compute(study, options)?,
        })
    }

    /// Every file of the report, checked (no NaN, every internal link resolves), in the order
    /// `ttalloc report` writes them.
    ///
    /// # Errors
    /// When a figure cannot be drawn or the check fails (an internal error: nothing should be
    /// written).
    pub fn files(&self) -> Result<Vec<ReportFile>> {
        Ok(files(&self.computed)?
            .into_iter()
            .map(|(name, bytes)| ReportFile { name, bytes })
            .collect())
    }

    /// The report's Markdown (`report.md`).
    ///
    /// # Errors
    /// As [`Report::files`].
    pub fn markdown(&self) -> Result<String> {
        self.file_text("report.md")
    }

    /// The report's results model (`results.json`): every number the report states, with
    /// units in the key names.
    ///
    /// # Errors
    /// As [`Report::files`].
    pub fn results(&self) -> Result<serde_json::Value> {
        Ok(serde_json::from_str(&self.file_text("results.json")?)?)
    }

    /// The study the report is of.
    #[must_use]
    pub fn study(&self) -> &Study {
        &self.computed.study
    }

    /// The Monte Carlo seed used.
    #[must_use]
    pub fn seed(&self) -> u64 {
        self.computed.options.seed
    }

    /// The Monte Carlo turntables per box used.
    #[must_use]
    pub fn samples(&self) -> u64 {
        self.computed.options.samples
    }

    /// The lines a summary of the report adds (plain text, unescaped): the paper's claims
    /// (for the paper's reproduction) and the requirement's disagreement note, if any.
    #[must_use]
    pub fn summary_notes(&self) -> Vec<String> {
        let c = &self.computed;
        let mut notes = Vec::new();
        if let Some(p) = &c.paper {
            notes.push(e2e_verify::paper::registry::summary(&p.claims));
        }
        if let Some(n) = &c.requirement.disagreement {
            notes.push(n.clone());
        }
        notes
    }

    /// Seconds the computation took (wall clock; shown in the report's summary line).
    #[must_use]
    pub fn seconds(&self) -> f64 {
        self.computed.seconds
    }

    fn file_text(&self, name: &str) -> Result<String> {
        let f = self
            .files()?
            .into_iter()
            .find(|f| f.name == name)
            .ok_or_else(|| Error::Internal(format!("the report has no {name}")))?;
        String::from_utf8(f.bytes).map_err(|e| Error::Internal(format!("{name} is not UTF-8: {e}")))
    }
}

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
            .map_err(|e| tt_lab::error::library(e, s))?;
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
    crate::jcgm101::section(&mut sec)?;
    sec.rate_allocation();
    sec.vendor();
    sec.designed();
    sec.angle_allocation();
    sec.estimable();
    sec.processed_run()?;
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
    let mut json = results::results_json(c, &comparisons)?;
    crate::jcgm101::add_results(c, &mut json)?;
    Ok((title, sec.doc, sec.csv, json))
}

/// The command that reproduces the report (paths as the user gave them, shell-quoted).
fn command(c: &Computed) -> String {
    use tt_lab::paths::shell_quote as q;
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
    s.push_str(&crate::jcgm101::flags(c));
    if let Some(r) = &c.options.run {
        for f in r.flags() {
            s.push(' ');
            s.push_str(&q(f));
        }
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
        return Err(Error::Internal(format!(
            "a NaN reached the report of {}; nothing was written",
            c.study.path
        )));
    }
    let anchors = doc.anchors();
    for part in html.split("href=\"#").skip(1) {
        let id = part.split('"').next().unwrap_or("");
        if !anchors.contains(&id) {
            return Err(Error::Internal(format!(
                "the report links to #{id}, which it does not contain"
            )));
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

/// A rendered report: title, document, CSV files (name, text), `results.json`.
type Rendered = (String, doc::Doc, Vec<(String, String)>, Value);

/// What the report says of the joint estimation for a study with rate steps.
pub(crate) const ESTIMABLE_STATIC_ONLY: &str = "not evaluated: the joint estimation of table errors takes static positions only, and this study has rate steps";
