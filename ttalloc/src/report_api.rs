//! The report as a library: compute a study's report once ([`Report::compute`]), then render
//! its files ([`Report::files`]: `report.md`, `report.html`, the SVG figures, the CSV tables and
//! `results.json`) or read its results model ([`Report::results`], the JSON the report's
//! numbers come from), without running the binary or touching the disk. `ttalloc report`
//! writes exactly [`Report::files`] into its checked output directory.
//!
//! # Example
//! ```no_run
//! let study = study::Study::load(std::path::Path::new("studies/gyrowheel-2017.toml"))?;
//! let report = ttalloc::Report::compute(study, ttalloc::ReportOptions::default())?;
//! let markdown = report.markdown()?;
//! assert!(markdown.contains("Table 4"));
//! # Ok::<(), anyhow::Error>(())
//! ```

use crate::report::compute::{self, Computed, Options};
use anyhow::Result;
use e2e_verify::ToleranceSheet;
use study::Study;

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
    /// An [`crate::InputError`] (inside the [`anyhow::Error`]) naming the key or option for
    /// bad input (too few samples for the yield target, a sheet of another turntable); a
    /// library error when a computation fails.
    pub fn compute(study: Study, options: ReportOptions) -> Result<Self> {
        let samples = options.samples.unwrap_or(study.monte_carlo.samples);
        crate::end_to_end::check_yield_samples(
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
        Ok(crate::report::files(&self.computed)?
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
            .ok_or_else(|| anyhow::anyhow!("internal error: the report has no {name}"))?;
        Ok(String::from_utf8(f.bytes)?)
    }
}
