//! `design-schedule --rates-deg-per-s R1,R2,...` (issue 23): the rate of the study's rate steps
//! chosen among candidate rates, with the designed positions.
//!
//! For each candidate rate R every rate step of the study turns at R (its sign, joint, angles
//! and revolutions kept), the static positions are the designed ones or the study's (the
//! position search takes the static positions alone, so its design need not be the better one
//! once the rate steps count), and each schedule is answered by the direct allocation
//! of the angles and the rate tolerances together ([`e2e_verify::RateQuestions::allocate_direct_rate`],
//! J over both, arcmin^-2, as `end-to-end --json` reports `rate_allocation.objective_arcmin`).
//! The pair (positions, rate) with the least J is chosen and written by `--write-study`. The rate changes
//! how the rate accuracy, the ripple and the centripetal terms reach the outputs (the
//! centripetal acceleration grows as the rate squared), so the best rate depends on the
//! sensor, the table and the schedule.

use anyhow::Result;
use study::Study;
pub(crate) use tt_lab::design::rates::{FLAG, MAX_RATE_DEG_PER_S};

/// One candidate rate, finite and in (0, [`MAX_RATE_DEG_PER_S`]] (deg/s).
///
/// # Errors
/// A message for clap (exit 2 naming the flag).
pub(crate) fn rate(s: &str) -> Result<f64, String> {
    crate::args::positive(s, MAX_RATE_DEG_PER_S)
}

/// [`tt_lab::design::rates::check`] as the command's result.
///
/// # Errors
/// As the library's.
pub(crate) fn check(s: &Study, rates: &[f64]) -> Result<()> {
    Ok(tt_lab::design::rates::check(s, rates)?)
}
