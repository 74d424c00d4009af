#![doc = include_str!("../README.md")]

pub mod allocation;
pub mod end_to_end;
pub mod error;
pub mod estimable;
pub mod json;
pub mod loaded;
pub mod paths;
pub mod vendor;

pub use error::{InputError, LabError, Result};
