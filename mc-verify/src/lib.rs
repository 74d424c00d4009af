//! Fast, deterministic Monte Carlo verification of a turntable tolerance allocation
//! (Zhao, Zhao, Huo, Yao 2017, §4.3, Figure 9).
//!
//! The paper checks its allocation (Table 4) by drawing 10,000 random turntables whose eight
//! angular errors satisfy $\mathrm{LB}_i \le |\chi_i| \le \mathrm{UB}_i$, evaluating the exact
//! orientation error model (eq 25) and showing that every $\Delta\psi, \Delta\theta,
//! \Delta\gamma$ stays inside the requirement (eq 16). This crate does the same with
//! $10^8$-$10^9$ draws in seconds, reproducible to the bit:
//!
//! - [`sampler`]: the sampling distribution (uniform magnitudes, fair signs, uniform pose; the
//!   paper does not state it, NOTES item 15) and the random streams, one per
//!   (seed, chunk) ([`chunk_rng`], [`TurntableSampler`]);
//! - [`fast`]: the exact chain evaluated with quaternions of the small rotations and short
//!   exact series ([`FastChain`]), equal to [`tt_kinematics::ExactChain`] to rounding;
//! - [`MonteCarlo`]: chunks on rayon threads, reduced in chunk order so the result does not
//!   depend on the thread count; memory does not grow with the number of samples;
//! - [`simd`]: the block loop compiled for SSE2 and AVX2, chosen at run time
//!   ([`SimdLevel`]), with bit-identical results on every level;
//! - [`McResult`]: extremes with their worst samples, mean and spread, histograms (the data
//!   of Figure 9) and the fraction inside the requirement.
//!
//! # Example
//! ```
//! use mc_verify::{ErrorBox, McConfig, MonteCarlo};
//! // Table 4 of the paper, arcminutes, order of chi (eq 25); lower bounds zero.
//! let table4 = [0.4235, 0.7800, 0.4234, 0.7800, 0.2825, 0.2824, 0.4234, 0.4233];
//! let bounds = ErrorBox::from_arcmin([0.0; 8], table4)?;
//! let mc = MonteCarlo::new(bounds, McConfig::new(100_000, 42))?;
//! let result = mc.run();
//! // Figure 9: every sample inside |angle| <= 0.027 deg (eq 16).
//! assert_eq!(result.within_requirement_all, 100_000);
//! assert!(result.max_abs_rad().iter().all(|&m| m <= 0.027_f64.to_radians()));
//! # Ok::<(), mc_verify::McError>(())
//! ```
//!
//! # Reference
//! Y. Zhao, H. Zhao, X. Huo, Y. Yao, "Error Analysis and Error Allocation for Turntable Systems
//! Used in GyroWheel Calibration Tests", Int. J. Aerospace Eng. 2017, 6524782, §4.3.
// `unsafe` only in `simd` (runtime CPU-feature dispatch, with its safety argument).
#![deny(unsafe_code)]

mod bounds;
mod error;
pub mod fast;
mod run;
pub mod sampler;
pub mod simd;
mod stats;

pub use bounds::ErrorBox;
pub use error::{BoundKind, McError};
pub use fast::{FastChain, fast_delta_rad};
pub use run::{
    DEFAULT_CHUNK_SIZE, DEFAULT_HISTOGRAM_BINS, MAX_HISTOGRAM_BINS, McConfig, McResult, MonteCarlo,
    PAPER_REQUIREMENT_DEG,
};
pub use sampler::{
    BLOCK_CAPACITY, McRng, SampleBlock, TurntableSampler, WORDS_PER_SAMPLE, chunk_rng,
};
pub use simd::SimdLevel;
pub use stats::{AxisSummary, Histogram, WorstSample};
