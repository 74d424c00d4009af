//! The one error type of the crate.

use crate::figures::MAX_PLOT_ABS;

/// Why a report or a figure could not be made. Every figure variant names the figure (its
/// title, and the panel's after a colon), as the caller gave it.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// A plotted value is not finite, or beyond ±[`MAX_PLOT_ABS`].
    #[error("{figure}: cannot plot the value {value} (not finite or beyond ±{MAX_PLOT_ABS:e})")]
    NotPlottable {
        /// The figure (and panel).
        figure: String,
        /// The offending value.
        value: f64,
    },
    /// A histogram's edges do not bound its bins (`bins + 1` edges are needed).
    #[error("{figure}: {edges} edges for {bins} bins")]
    HistogramEdges {
        /// The figure and panel.
        figure: String,
        /// Number of edges given.
        edges: usize,
        /// Number of bins (counts) given.
        bins: usize,
    },
    /// A bar series has not one value per category.
    #[error("{figure}: series {series} has {values} values for {categories} categories")]
    RaggedSeries {
        /// The figure.
        figure: String,
        /// The series' label.
        series: String,
        /// Values it has.
        values: usize,
        /// Categories of the figure.
        categories: usize,
    },
    /// A heat map's values are not one per grid point, or the grid has fewer than 2 x 2 points.
    #[error("{figure}: the grid is not {nx} x {ny}")]
    Grid {
        /// The figure and panel.
        figure: String,
        /// Abscissae given.
        nx: usize,
        /// Ordinates given.
        ny: usize,
    },
    /// The plotting backend failed (its message).
    #[error("drawing a figure failed: {0}")]
    Drawing(String),
    /// A study-level question failed: its input errors ([`tt_lab::LabError::Input`]) name the
    /// key or option, so that the command line exits with code 2 for them.
    #[error(transparent)]
    Lab(#[from] tt_lab::LabError),
    /// `results.json` could not be written or read back.
    #[error("results.json: {0}")]
    Json(#[from] serde_json::Error),
    /// The report failed its own check (a NaN, a broken internal link, a missing file): an
    /// internal error, nothing should be written.
    #[error("internal error: {0}")]
    Internal(String),
}

impl From<tt_lab::InputError> for Error {
    fn from(e: tt_lab::InputError) -> Self {
        Self::Lab(tt_lab::LabError::Input(e))
    }
}

/// The crate's result type.
pub type Result<T, E = Error> = std::result::Result<T, E>;
