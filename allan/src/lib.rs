#![doc = include_str!("../README.md")]

pub mod chi2;
pub mod edf;
mod error;
pub mod fit;
pub mod noise;
mod stream;

pub use error::AllanError;
pub use fit::FLICKER_FLOOR_FACTOR;
pub use noise::{NoiseModel, PowerLaw};
pub use stream::{
    AllanPoint, Analysis, DEFAULT_OVERLAP, MAX_OVERLAP, NoiseFit, Settings, StreamingAllan, analyse,
};
