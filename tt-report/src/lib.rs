#![doc = include_str!("../README.md")]

mod error;

pub mod doc;
pub mod figures;

pub use doc::{Block, Doc};
pub use error::{Error, Result};
