#![doc = include_str!("../README.md")]

pub mod error;
pub mod loaded;
pub mod paths;

pub use error::{InputError, LabError, Result};
