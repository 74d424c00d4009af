#![doc = include_str!("../README.md")]

pub mod calibrate;
pub mod design;
pub mod error;
pub mod loaded;
pub mod monte_carlo;
pub mod noise_log;
pub mod paths;
pub mod requirement;
pub mod rows;
pub mod view;

pub use error::{InputError, LabError, Result};
