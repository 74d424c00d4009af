#![doc = include_str!("../README.md")]

mod compute;
mod error;
mod jcgm101;
mod paper;
mod processed;
mod render;
mod report;
mod results;

pub mod allan_figure;
pub mod doc;
pub mod figures;

pub use doc::{Block, Doc};
pub use error::{Error, Result};
pub use processed::ProcessedRun;
pub use report::{Report, ReportFile, ReportOptions};
