//! The rate of a study's rate steps chosen among candidate rates, with designed static
//! positions (issue 23).
//!
//! For each candidate rate R every rate step of the study turns at R (its sign, joint, angles
//! and revolutions kept), the static positions are the designed ones or the study's (the
//! position search takes the static positions alone, so its design need not be the better one
//! once the rate steps count), and each schedule is answered by the direct allocation of the
//! angles and the rate tolerances together ([`e2e_verify::EndToEnd::allocate_direct_rate`],
//! J over both, arcmin^-2). The pair (positions, rate) with the least J is chosen. The rate
//! changes how the rate accuracy, the ripple and the centripetal terms reach the outputs (the
//! centripetal acceleration grows as the rate squared), so the best rate depends on the
//! sensor, the table and the schedule.

use crate::error::{InputError, Result};
use study::Study;
use tt_core::human::exact;

/// The flag of the candidate rates.
pub const FLAG: &str = "--rates-deg-per-s";

/// The largest candidate rate accepted before the study's limits (deg/s).
pub const MAX_RATE_DEG_PER_S: f64 = 1e5;

/// The choice among candidate rates.
#[derive(Debug, Clone)]
#[non_exhaustive]
pub struct RateChoice {
    candidates: Vec<(f64, Option<f64>)>,
    study_positions: Vec<Option<f64>>,
    chosen_study_positions: bool,
    study_rates_objective_arcmin: Option<f64>,
    chosen: Option<(f64, f64)>,
}

impl RateChoice {
    /// Per candidate (deg/s): J (arcmin^-2) with the designed positions, `None` when no table
    /// suffices at that rate.
    #[must_use]
    pub fn candidates(&self) -> &[(f64, Option<f64>)] {
        &self.candidates
    }

    /// Per candidate: J (arcmin^-2) with the study's positions, as above.
    #[must_use]
    pub fn study_positions(&self) -> &[Option<f64>] {
        &self.study_positions
    }

    /// Whether the chosen pair has the study's positions (else the designed ones).
    #[must_use]
    pub fn chosen_study_positions(&self) -> bool {
        self.chosen_study_positions
    }

    /// The study's own rates with the designed positions: J (arcmin^-2), `None` as above.
    #[must_use]
    pub fn study_rates_objective_arcmin(&self) -> Option<f64> {
        self.study_rates_objective_arcmin
    }

    /// The chosen rate (deg/s) and its J; `None` when no candidate has a table that suffices.
    #[must_use]
    pub fn chosen(&self) -> Option<(f64, f64)> {
        self.chosen
    }

    /// The choice's view (`rates` of `design-schedule --json`).
    #[must_use]
    pub fn view(&self) -> RatesJson<'_> {
        json(self)
    }
}

/// Check the candidates against the study, before any work: it must have rate steps, every
/// candidate must be within the rate limit of every joint the study's steps turn, and the
/// study with its steps at each candidate must be one the study file accepts (a rate so
/// small that it is zero in rad/s is refused here, not after the search).
///
/// # Errors
/// An [`InputError`] naming the flag.
pub fn check(s: &Study, rates: &[f64]) -> Result<(), InputError> {
    if !s.has_rate_steps() {
        return Err(InputError::new(
            FLAG,
            "the study has no rate steps (`calibration.rate_steps`): there is no rate to choose",
        ));
    }
    if rates.is_empty() {
        return Err(InputError::new(FLAG, "give at least one candidate rate"));
    }
    let joints = s.turntable.joint_names();
    for step in &s.rate_steps {
        if let Some(limit) = s.max_rate_deg_per_s.get(step.joint).copied().flatten() {
            if let Some(r) = rates.iter().find(|r| **r > limit) {
                return Err(InputError::new(
                    FLAG,
                    format!(
                        "{} deg/s is above the rate limit of joint {} ({} deg/s, `turntable.max_rate_deg_per_s`)",
                        exact(*r),
                        joints[step.joint],
                        exact(limit)
                    ),
                ));
            }
        }
    }
    for &r in rates {
        with_rate(s, &s.positions_deg, r).map_err(|e| {
            InputError::new(
                FLAG,
                format!(
                    "{} deg/s: the study's rate steps at this rate are refused: {}: {}",
                    exact(r),
                    e.location,
                    e.reason
                ),
            )
        })?;
    }
    Ok(())
}

/// The study with the static positions `positions_deg` and every rate step at `rate` (deg/s,
/// each step's sign kept).
fn with_rate(s: &Study, positions_deg: &[Vec<f64>], rate: f64) -> Result<Study, InputError> {
    let mut s2 = s.clone();
    for step in &mut s2.rate_steps {
        step.rate_deg_per_s = rate.copysign(step.rate_deg_per_s);
    }
    s2.with_positions_deg(positions_deg.to_vec())
        .map_err(InputError::from)
}

/// J (arcmin^-2) of the allocation with the rate tolerances for `s`; `None` when no table
/// suffices (the allocation is infeasible, its exact-chain check does not converge, or the
/// noise part of a specification fills its limit). With `specs` (the specifications the
/// study as written leaves the table room for) the allocation holds them too, over the
/// angles and the rate tolerances ([`e2e_verify::EndToEnd::rate_specification_rows`]), with
/// the noise of `s`'s own rate steps: a scale factor in ppm is judged in ppm at every rate.
fn objective(s: &Study, specs: &[gw_model::spec::Specification]) -> Result<Option<f64>> {
    let e2e = crate::loaded::simulator(s)?;
    let (linear, extra) = (e2e.linearization(), e2e.extra_linearization());
    let rows = if specs.is_empty() {
        Vec::new()
    } else {
        let ctx = crate::allocation::spec::context_of(s, &e2e, specs)?;
        e2e.rate_specification_rows(&ctx, &extra)
            .map_err(|e| crate::error::library(e, s))?
    };
    Ok(e2e
        .allocate_direct_rate_specified(&linear, &extra, &s.lower_bounds_rad, &rows)
        .ok()
        .map(|a| a.combined().objective_arcmin()))
}

/// The specifications of `s` (its rates as written) that leave the table room
/// ([`crate::allocation::spec::context`]): the ones every candidate rate is judged by; a
/// candidate rate at which one of them has no room has no table that suffices.
fn kept_specifications(s: &Study) -> Result<Vec<gw_model::spec::Specification>> {
    if s.specifications.is_empty() {
        return Ok(Vec::new());
    }
    let e2e = crate::loaded::simulator(s)?;
    Ok(crate::allocation::spec::context(s, &e2e)?
        .context
        .map(|c| c.specifications().to_vec())
        .unwrap_or_default())
}

/// Choose the rate among `rates` (deg/s) and the static positions between `designed_deg`
/// and the study's (ties go to the designed positions, then to the earlier rate).
///
/// # Errors
/// As [`check`]; a library error located in the study.
pub fn choose(s: &Study, designed_deg: &[Vec<f64>], rates: &[f64]) -> Result<RateChoice> {
    check(s, rates)?;
    let written = s
        .with_positions_deg(designed_deg.to_vec())
        .map_err(InputError::from)?;
    let specs = kept_specifications(&written)?;
    let study = objective(&written, &specs)?;
    let at = |positions: &[Vec<f64>]| -> Result<Vec<(f64, Option<f64>)>> {
        rates
            .iter()
            .map(|&r| Ok((r, objective(&with_rate(s, positions, r)?, &specs)?)))
            .collect()
    };
    let candidates = at(designed_deg)?;
    let study_positions: Vec<Option<f64>> = if designed_deg == s.positions_deg.as_slice() {
        candidates.iter().map(|(_, j)| *j).collect()
    } else {
        at(&s.positions_deg)?.into_iter().map(|(_, j)| j).collect()
    };
    let best = |list: Vec<(f64, Option<f64>)>| {
        list.into_iter()
            .filter_map(|(r, j)| j.map(|j| (r, j)))
            .fold(None, |b: Option<(f64, f64)>, c| match b {
                Some(b) if b.1 <= c.1 => Some(b),
                _ => Some(c),
            })
    };
    let designed = best(candidates.clone());
    let of_study = best(
        rates
            .iter()
            .copied()
            .zip(study_positions.iter().copied())
            .collect(),
    );
    let (chosen, chosen_study_positions) = match (designed, of_study) {
        (Some(d), Some(t)) if t.1 < d.1 => (Some(t), true),
        (None, Some(t)) => (Some(t), true),
        (d, _) => (d, false),
    };
    Ok(RateChoice {
        candidates,
        study_positions,
        chosen_study_positions,
        study_rates_objective_arcmin: study,
        chosen,
    })
}

/// `design-schedule --rates-deg-per-s` (`rates`): the rate chosen among the candidates.
#[derive(Debug)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
#[cfg_attr(not(feature = "serde"), allow(dead_code))]
pub struct RatesJson<'a> {
    /// The candidate rates, deg/s.
    candidates_deg_per_s: Vec<f64>,
    /// J with the designed positions at each candidate, arcmin^-2 (`null`: no allocation).
    objective_arcmin: Vec<Option<f64>>,
    /// J with the study's positions at each candidate, arcmin^-2 (`null`: no allocation).
    study_positions_objective_arcmin: &'a [Option<f64>],
    /// J of the study as written (its rates and positions), arcmin^-2.
    study_rates_objective_arcmin: Option<f64>,
    /// `designed` or `study`: the static positions chosen (`null`: none chosen).
    chosen_positions: Option<&'static str>,
    /// The rate chosen, deg/s (`null`: none).
    chosen_deg_per_s: Option<f64>,
    /// Its J, arcmin^-2.
    chosen_objective_arcmin: Option<f64>,
}

/// The choice's view (`rates`).
fn json(c: &RateChoice) -> RatesJson<'_> {
    RatesJson {
        candidates_deg_per_s: c.candidates.iter().map(|(r, _)| *r).collect(),
        objective_arcmin: c.candidates.iter().map(|(_, j)| *j).collect(),
        study_positions_objective_arcmin: &c.study_positions,
        study_rates_objective_arcmin: c.study_rates_objective_arcmin,
        chosen_positions: c.chosen.map(|_| {
            if c.chosen_study_positions {
                "study"
            } else {
                "designed"
            }
        }),
        chosen_deg_per_s: c.chosen.map(|(r, _)| r),
        chosen_objective_arcmin: c.chosen.map(|(_, j)| j),
    }
}
