#![doc = include_str!("../README.md")]

pub mod allocation;
pub mod budget_mc;
pub mod calibrate;
pub mod design;
pub mod end_to_end;
pub mod error;
pub mod estimable;
pub mod groups;
pub mod json;
pub mod loaded;
pub mod monte_carlo;
pub mod newfile;
pub mod noise_log;
pub mod outdir;
pub mod paths;
pub mod records;
pub mod requirement;
pub mod rows;
pub mod vendor;

pub use error::{InputError, LabError, Result};
