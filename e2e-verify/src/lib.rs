//! End-to-end verification of a turntable tolerance allocation: does the allocated turntable
//! deliver the GyroWheel calibration accuracy? Direct and yield-based allocation (issue 7,
//! extending Zhao, Zhao, Huo and Yao 2017).
//!
//! The paper splits the problem in two: §2 assumes one constant orientation error at every
//! test position and derives a square requirement (0.027 deg, eq 16); §4 allocates the
//! turntable against that square (Table 4). A real turntable has fixed geometric errors $\chi$
//! whose orientation error differs from position to position. This crate closes the loop:
//!
//! - [`EndToEnd`]: one calibration run for a turntable $\chi$: at every position of the
//!   schedule $\Delta\mathbf R_i$ from the exact chain (eq 23), the outputs, the least-squares
//!   calibration and $\Delta\omega_x$, $\Delta\omega_y$ (eq 14) under a
//!   [`calib_lsq::Reading`] of eq 13 ([`Reading::PAPER`](calib_lsq::Reading::PAPER)
//!   reproduces §2; [`Reading::USER`](calib_lsq::Reading::USER) is what a calibrating
//!   engineer gets);
//! - [`Linearization`]: $\Delta\hat{\boldsymbol\omega} \approx \mathbf M\chi$ (analytic and by
//!   finite differences) and the worst case of a box ([`WorstCase`]): a vertex, confirmed on
//!   the exact chain, with a derived second-order bound
//!   ([`EndToEnd::second_order_bound`]);
//! - [`EndToEnd::rate_distribution`]: Monte Carlo over turntables drawn from the box, the
//!   yield with a Wilson interval;
//! - [`EndToEnd::allocate_direct`] and [`EndToEnd::allocate_yield`]: allocations against
//!   $\omega_m$ itself;
//! - [`answer`]: everything for the paper's inputs ([`EndToEndInputs::paper`]), used by
//!   `cargo xtask end-to-end`.
//!
//! # Why a separate crate
//! It needs calib-lsq (the calibration), alloc-opt (the allocation core) and mc-verify (the
//! random streams) together. Putting it in mc-verify would make that light crate depend on
//! calib-lsq and alloc-opt; putting it in alloc-opt would make alloc-opt depend on calib-lsq
//! and mc-verify, and mc-verify's users on the solver. A crate on top keeps the graph acyclic
//! and the lower crates light.
//!
//! # Example
//! ```
//! use e2e_verify::EndToEnd;
//! use calib_lsq::Reading;
//! use alloc_opt::paper_table4_rad;
//!
//! let e2e = EndToEnd::paper(Reading::PAPER);
//! // A perfect turntable calibrates perfectly (up to rounding of 1e-4 rad/s terms).
//! assert!(e2e.delta_omega(&[0.0; 8])?.iter().all(|v| v.abs() < 1e-17));
//! // The worst turntable within Table 4's bounds, linearised and confirmed on the exact chain.
//! let wc = e2e.worst_case(&e2e.linearization(), &paper_table4_rad())?;
//! let [x, y] = wc.exact_deg_per_h();
//! assert!(x > 0.0 && y > 0.0);
//! # Ok::<(), e2e_verify::E2eError>(())
//! ```
//!
//! # Reference
//! Y. Zhao, H. Zhao, X. Huo, Y. Yao, "Error Analysis and Error Allocation for Turntable Systems
//! Used in GyroWheel Calibration Tests", Int. J. Aerospace Eng. 2017, 6524782,
//! doi:10.1155/2017/6524782.
#![forbid(unsafe_code)]

mod allocate;
mod answer;
mod error;
mod linear;
mod montecarlo;
mod simulate;

pub use allocate::{
    CERTIFY_STEPS, DEFAULT_YIELD_FRACTION, DirectAllocation, RowLoad, YIELD_BISECTION_STEPS,
    YIELD_FIXED_POINT_STEPS, YIELD_SCALE_MARGIN, YieldAllocation, paper_combined_weights,
    paper_objective, paper_objective_arcmin,
};
pub use answer::{
    BoxAnswer, BuyersAnswer, DEFAULT_SAMPLES, DEFAULT_SEED, EndToEndInputs, ReadingAnswer, answer,
    objective_to_arcmin,
};
pub use error::E2eError;
pub use linear::{AxisWorstCase, Linearization, WorstCase};
pub use montecarlo::{
    DEFAULT_BINS, DEFAULT_CHUNK_SIZE, McSettings, REPORTED_QUANTILES, RateDistribution,
    RateQuantile, TurntableDraw, Z_95, wilson_interval_95,
};
pub use simulate::{AXES, EndToEnd, EndToEndRun, chain_factors};
