#![doc = include_str!("../README.md")]

pub mod chi2;
pub mod edf;
mod error;
pub mod fit;
mod levels;
pub mod noise;
mod stream;

pub use error::AllanError;
pub use fit::{FLICKER_FLOOR_FACTOR, GaussMarkovFit, Resolution, Term};
pub use levels::{ALL_DENSE, ALL_PER_OCTAVE, MAX_LIST_EVALUATIONS, Taus};
pub use noise::{NoiseModel, PowerLaw};
pub use stream::{
    AllanPoint, Analysis, DEFAULT_OVERLAP, NoiseFit, RATE_HZ, Settings, StreamingAllan, analyse,
};
