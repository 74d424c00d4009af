//! Fast, deterministic Monte Carlo verification of a turntable tolerance allocation, for any
//! turntable described as data (after Zhao, Zhao, Huo, Yao 2017, §4.3, Figure 9).
//!
//! The paper checks its allocation (Table 4) by drawing 10,000 random turntables whose
//! angular errors satisfy $\mathrm{LB}_i \le |\chi_i| \le \mathrm{UB}_i$, evaluating the exact
//! orientation error model (eq 25) and showing that every $\Delta\psi, \Delta\theta,
//! \Delta\gamma$ stays inside the requirement (eq 16). This crate does the same for any
//! [`tt_kinematics::Turntable`] (one, two or three axes, compiled from a
//! [`tt_kinematics::TurntableDescription`]) with $10^8$-$10^9$ draws in seconds,
//! reproducible to the bit:
//!
//! - [`sampler`]: the sampling distribution (uniform magnitudes, fair signs, uniform pose in
//!   the joint ranges; the paper does not state it, NOTES item 15) and the random streams,
//!   one per (seed, chunk) ([`chunk_rng`], [`TurntableSampler`]);
//! - [`fast`]: the turntable's evaluation plan compiled once and run on lanes of samples with
//!   quaternions of the small rotations and short exact series ([`FastChain`] for one
//!   sample), equal to [`tt_kinematics::ExactChain`] to rounding;
//! - [`MonteCarlo`]: chunks on rayon threads, reduced in chunk order so the result does not
//!   depend on the thread count; memory does not grow with the number of samples;
//! - [`simd`]: the block loop compiled for SSE2 and AVX2, chosen at run time
//!   ([`SimdLevel`]), with bit-identical results on every level;
//! - [`McResult`]: extremes with their worst samples, mean and spread, histograms (the data
//!   of Figure 9) and the draws inside the requirement ([`YieldCount`], the workspace's one
//!   yield count, with [`wilson_interval_95`]);
//! - `baseline`: the earlier kernel specialised to the paper's table, kept as a reference
//!   (the general path reproduces it bit for bit) and as a benchmark baseline.
//!
//! # Example: the paper's Table 4
//! ```
//! use mc_verify::{ErrorBox, McConfig, MonteCarlo};
//! let table = tt_kinematics::paper::table3();
//! // Table 4 of the paper, arcminutes, order of chi (eq 25); lower bounds zero.
//! let table4 = vec![0.4235, 0.7800, 0.4234, 0.7800, 0.2825, 0.2824, 0.4234, 0.4233];
//! let bounds = ErrorBox::from_arcmin(&table, vec![0.0; 8], table4)?;
//! // eq 16: |angle| <= 0.027 deg on all three angles
//! let i = tt_core::Requirement::uniform_deg(0.027)?;
//! let mc = MonteCarlo::new(&table, bounds, McConfig::new(100_000, 42, i))?;
//! let result = mc.run();
//! assert_eq!(result.count().meeting(), 100_000);
//! // never beyond the rigorous bound (certified linear worst case + remainder)
//! let h = MonteCarlo::histogram_half_range_rad(&table, mc.bounds())?;
//! assert!(result.max_abs_rad().iter().zip(h).all(|(&m, h)| m <= h));
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
//!
//! # Example: your own table
//! ```
//! use mc_verify::{ErrorBox, McConfig, MonteCarlo};
//! use tt_kinematics::{FactorSpec, SignedAxis, Turntable, TurntableDescription};
//! let j = FactorSpec::joint;
//! let e = FactorSpec::error;
//! // A three-axis table: outer about z, middle about x, inner about y; the inner axis
//! // turns only through [-90, 90] deg.
//! let mut d = TurntableDescription::new(vec![
//!     j("outer", SignedAxis::Z), e("d_outer", SignedAxis::Z),
//!     e("perp_om", SignedAxis::Y),
//!     j("middle", SignedAxis::X), e("d_middle", SignedAxis::X),
//!     e("perp_mi", SignedAxis::Z),
//!     j("inner", SignedAxis::Y), e("d_inner", SignedAxis::Y),
//! ]);
//! d.joint_ranges_rad = vec![("inner".into(), [-90_f64.to_radians(), 90_f64.to_radians()])];
//! let table = Turntable::new(&d)?;
//! let bounds = ErrorBox::from_arcmin(&table, vec![0.0; 5], vec![0.5; 5])?;
//! // a requirement on theta only
//! let cfg = McConfig::new(50_000, 7, tt_core::Requirement::from_options([None, Some(2e-4), None])?);
//! let r = MonteCarlo::new(&table, bounds, cfg)?.run();
//! assert_eq!(r.count().meeting_per_output()[0], 50_000); // no requirement on psi
//! assert_eq!(r.axes()[0].worst().pose().len(), 3); // every joint, the cancelling outer one too
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
//!
//! # Reference
//! Y. Zhao, H. Zhao, X. Huo, Y. Yao, "Error Analysis and Error Allocation for Turntable Systems
//! Used in GyroWheel Calibration Tests", Int. J. Aerospace Eng. 2017, 6524782, §4.3.
// `unsafe` only in `simd` (runtime CPU-feature dispatch, with its safety argument).
#![doc = include_str!("../README.md")]
#![deny(unsafe_code)]

#[cfg(feature = "paper")]
pub mod baseline;
mod bounds;
mod count;
pub mod driver;
mod error;
pub mod fast;
#[cfg(feature = "paper")]
pub mod paper;
mod run;
pub mod sampler;
pub mod simd;
mod stats;

pub use bounds::ErrorBox;
pub use count::{YieldCount, Z_95, wilson_interval_95};
pub use error::{BoundKind, McError};
pub use fast::{FastChain, LANES, SERIES_MAX_ABS_RAD, SHORT_SERIES_MAX_ABS_RAD, Tier};
pub use run::{
    DEFAULT_CHUNK_SIZE, DEFAULT_HISTOGRAM_BINS, MAX_HISTOGRAM_BINS, McConfig, McResult, MonteCarlo,
};
pub use sampler::{BLOCK_CAPACITY, McRng, SampleBlock, TurntableSampler, chunk_rng};
pub use simd::SimdLevel;
pub use stats::{AxisSummary, Histogram, WorstSample, quantile_rank};
