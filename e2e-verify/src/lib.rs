//! End to end: does a turntable deliver the calibration accuracy of every output of a sensor?
//! Direct and yield-based allocation against those accuracies, and the check of a vendor's
//! tolerances, for any described turntable and sensor (extending Zhao, Zhao, Huo and Yao
//! 2017).
//!
//! The paper splits the problem in two: §2 assumes one constant orientation error at every
//! test position and derives a square requirement (0.027 deg, eq 16); §4 allocates the
//! turntable against that square (Table 4). A real turntable has fixed geometric errors $\chi$
//! whose orientation error differs from position to position. This crate closes the loop:
//!
//! - [`EndToEnd`]: one calibration run for a turntable $\chi$: at every position of the
//!   schedule $\Delta\mathbf R_i$ from the exact chain (eq 23), the outputs, the least-squares
//!   calibration and $\Delta\omega_k$ (eq 14) of every output under a
//!   [`calib_lsq::Reading`] of eq 13 ([`Reading::PAPER`](calib_lsq::Reading::PAPER)
//!   reproduces §2; [`Reading::USER`](calib_lsq::Reading::USER) is what a calibrating
//!   engineer gets); a fast path with everything that does not change between turntables
//!   computed once, and the reference path through calib-lsq;
//! - [`Linearization`]: $\Delta\hat{\boldsymbol\omega} \approx \mathbf M\chi$ (analytic and by
//!   finite differences) and the worst case of a box ([`WorstCase`]): a vertex, confirmed on
//!   the exact chain, with a derived second-order bound ([`EndToEnd::second_order_bound`]);
//! - [`crate::MonteCarloQuestions::rate_distribution`]: Monte Carlo over turntables drawn from a box with memory
//!   independent of the draw count; the yield with a Wilson interval; exact order statistics
//!   ([`crate::MonteCarloQuestions::ratio_quantile`]);
//! - [`EndToEnd::allocate_direct`], [`EndToEnd::allocate_direct_certified`] and
//!   [`EndToEnd::allocate_yield`]: allocations against every output's accuracy (with rate
//!   steps: [`crate::RateQuestions::allocate_direct_rate`] and its certificate
//!   [`crate::RateQuestions::allocate_direct_rate_certified`]); the same three as alloc-opt
//!   [`alloc_opt::Allocator`]s over the linearisation ([`Direct`], [`DirectCertified`],
//!   [`YieldBased`], on [`EndToEnd::allocation_problem`]), returning alloc-opt's one
//!   [`alloc_opt::ToleranceBox`];
//! - [`crate::VendorQuestions::check_tolerances`]: the buyer's check of a tolerance box, with each error's
//!   contribution and a verdict; [`crate::VendorQuestions::check_sheet`] the same of a vendor's
//!   [`ToleranceSheet`] (bounds, lower bounds, discs, rate and translation bounds, measured
//!   errors, validated once; [`sheet`]);
//! - [`answer()`]: all of it for one study, used by `cargo xtask end-to-end`;
//! - [`noise`]: one answer for both error sources, the table's worst case and the sensor's
//!   noise (calib-lsq's covariance) at a stated confidence, with the combined yield, the
//!   direct allocation that gives the table what the noise leaves and the time/table
//!   trade-off (the shortest dwell at which some table suffices);
//! - [`timedomain`]: an independent time-domain simulation of the whole calibration (samples
//!   at the sample rate, white, Gauss-Markov and quantization noise, the estimator on the
//!   position averages) that checks the analytic noise answer;
//! - [`estimable`]: which table errors a joint least squares of the sensor coefficients and
//!   the table errors estimates from the same data, and the allocation of the rest;
//! - the calibration schedule that lets the cheapest turntable meet every accuracy is the
//!   `schedule-design` crate's, built on this one.
//!
//! [`EndToEnd`] keeps construction, the calibration run, the linearisation, the worst case and
//! the allocations; every other question is a small type reached from it, a view of the
//! end-to-end holding that question's methods: [`EndToEnd::noise`] ([`NoiseQuestions`]),
//! [`EndToEnd::rates`] ([`RateQuestions`]), [`EndToEnd::angle`] ([`AngleQuestions`]),
//! [`EndToEnd::estimable`] ([`EstimableQuestions`]), [`EndToEnd::budget`]
//! ([`BudgetQuestions`]), [`EndToEnd::monte_carlo`] ([`MonteCarloQuestions`]) and
//! [`EndToEnd::vendor`] ([`VendorQuestions`]).
//!
//! # Why a separate crate
//! It needs calib-lsq (the calibration), alloc-opt (the allocation core) and mc-verify (the
//! random streams) together. A crate on top keeps the graph acyclic and the lower crates
//! light.
//!
//! # Example
//! ```
//! use e2e_verify::EndToEnd;
//! use calib_lsq::{Calibration, Reading};
//! use tt_kinematics::{paper, Pose};
//!
//! let table = paper::table3();
//! let cal = Calibration::new(&gw_model::paper::gyrowheel(), &gw_model::paper::site(), &calib_lsq::paper::schedule())?;
//! let poses: Vec<Pose> = cal.schedule().positions().iter().map(|p| Pose::from_deg(p.joint_angles_deg())).collect::<Result<_, _>>()?;
//! let e2e = EndToEnd::new(&table, &cal, &poses, Reading::PAPER)?;
//! // A perfect turntable calibrates perfectly.
//! assert!(e2e.delta_omega(&[0.0; 8])?.iter().all(|v| v.abs() < 1e-12));
//! // The worst turntable within Table 4's bounds, linearised and confirmed on the exact chain.
//! let wc = e2e.worst_case(&e2e.linearization(), &alloc_opt::paper::table4_rad())?;
//! assert!(wc.exact().iter().all(|&v| v > 0.0 && v < 0.01));
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
//!
//! # Reference
//! Y. Zhao, H. Zhao, X. Huo, Y. Yao, "Error Analysis and Error Allocation for Turntable Systems
//! Used in GyroWheel Calibration Tests", Int. J. Aerospace Eng. 2017, 6524782,
//! doi:10.1155/2017/6524782.
#![doc = include_str!("../README.md")]
#![forbid(unsafe_code)]

mod allocate;
mod allocators;
pub mod angle;
mod answer;
pub mod budget;
pub mod budget_mc;
mod check;
pub mod disc;
mod error;
pub mod estimable;
#[doc(hidden)]
pub mod internals;
mod kernel;
mod linear;
pub mod montecarlo;
pub mod noise;
#[cfg(feature = "paper")]
pub mod paper;
mod questions;
pub mod rate;
mod seam;
pub mod sensitivity;
pub mod sheet;
mod simulate;
mod specified_yield;
pub mod timedomain;
pub mod ziggurat;

pub use allocate::{
    CertifyParams, DEFAULT_YIELD_FRACTION, DirectAllocation, NO_BOUND_NEEDED, RowLoad, SpecLoad,
    YieldAllocation, YieldParams, YieldVerdict, min_yield_samples,
};
pub use allocators::{Direct, DirectCertified, YieldBased};
pub use answer::{
    AnswerAllocations, BoxAnswer, BuyersAnswer, DEFAULT_SAMPLES, EndToEndInputs, ReadingAnswer,
    answer, answer_allocations, answer_with_two_step,
};
pub use check::{CheckDetail, Contribution, OutputCheck, OutputVerdict, TurntableCheck, Verdict};
pub use error::E2eError;
pub use linear::{BoxDetail, BoxMeets, Linearization, OutputWorstCase, WorstCase};
/// The one histogram of the workspace's Monte Carlos (mc-verify's), here on $[0, H)$ in the
/// output unit.
pub use mc_verify::Histogram;
/// The workspace's one yield count (mc-verify's): every yield of this crate reports one.
pub use mc_verify::{YieldCount, wilson_interval_95};
pub use montecarlo::{
    DEFAULT_CHUNK_SIZE, MAX_BINS, MAX_SAMPLES, McSettings, QUANTILE_BINS, REPORTED_QUANTILES,
    RateDistribution, RateQuantile, WorstDraw,
};
pub use noise::{
    CombinedBox, CombinedDetail, CombinedOutput, DEFAULT_K_SIGMA, Dominant, NoRoom, NoiseAnswer,
    NoiseBudget, NoisyAllocation, NoisyDirect, Tradeoff, TradeoffInputs, TradeoffParams,
    TradeoffPoint, check_k_sigma,
};
pub use questions::{
    AngleQuestions, BudgetQuestions, EstimableQuestions, MonteCarloQuestions, NoiseQuestions,
    RateQuestions, VendorQuestions,
};
pub use rate::{ExtraError, ExtraOutputWorstCase, RateAllocation, RateCertificate, RateTolerance};
pub use sensitivity::{NoiseSensitivity, ParameterSpread};
pub use sheet::ToleranceSheet;
pub use simulate::{DrawWork, EndToEnd, EndToEndRun, resolved};
pub use specified_yield::{ACCURACY_YIELD_COUNTS, SPECIFIED_YIELD_COUNTS, SpecifiedCount};
pub use timedomain::{OutputMoments, TimeDomainRun};
