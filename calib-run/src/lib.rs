//! Process the recording of a calibration the tool planned: from a CSV log and the study that
//! planned it to the coefficients of every output with their uncertainties, a calibration file
//! and its application to other recordings.
//!
//! - [`recording`]: the CSV, streamed once (memory independent of its length), every bad cell
//!   named by line and column;
//! - [`segments`]: the segments, from a file or detected and matched to the schedule;
//! - [`calibrate`]: weighted least squares on the segment averages with the study's sensor
//!   model (calib-lsq's [`calib_lsq::Regression`]), the covariance from the measured noise
//!   (Allan deviation of the static segments, `allan`) and from the residuals, residuals per
//!   segment with outlier flags, a robust (Huber) option, expanded uncertainties by a GUM
//!   budget (`metrology`: the noise as measured, the table's part from a tolerance sheet),
//!   the plan's predicted uncertainty beside the run's;
//! - [`study_verdicts`] and [`verdicts`]: coefficients against the study's specifications (in
//!   their written units) and `--spec` limits, under a named decision rule;
//! - [`file`](mod@file): the calibration file (JSON or TOML, never overwritten) and [`file::apply`];
//! - [`overview`]: a recording's minima and maxima in a bounded number of buckets, for a figure;
//! - [`simulate`]: recordings with known truth, for tests and benchmarks.
#![forbid(unsafe_code)]

mod error;
mod estimate;
pub mod file;
pub mod overview;
pub mod recording;
pub mod segments;
pub mod simulate;

pub use error::{At, RunError};
pub use estimate::{
    CalibrateOptions, CoefficientResult, MeasuredNoise, OUTLIER_Z, OutputResult, ResidualRow, Run,
    Segment, Spec, Verdict, calibrate, calibrate_observed, study_verdicts, verdicts,
};
