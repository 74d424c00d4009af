#![doc = include_str!("../README.md")]

pub mod budget;
pub mod decision;
mod error;
pub mod input;
pub mod montecarlo;
pub mod plan;
pub mod special;

pub use budget::{
    Budget, BudgetResult, BudgetRow, BudgetSettings, OutputUncertainty, coverage_factor,
};
pub use error::MetrologyError;
pub use input::{Distribution, Input};
