//! The rate of a study's rate steps chosen among candidate rates, with designed static
//! positions (issue 23).
//!
//! For each candidate rate R every rate step of the study turns at R (its sign, joint, angles
//! and revolutions kept), the static positions are the designed ones or the study's (the
//! position search takes the static positions alone, so its design need not be the better one
//! once the rate steps count), and each schedule is answered by the direct allocation of the
//! angles and the rate tolerances together ([`e2e_verify::RateQuestions::allocate_direct_rate`],
//! J over both, arcmin^-2). The pair (positions, rate) with the least J is chosen; when the
//! study gives specifications that leave the table room, the pair with the least largest
//! specification load at one reference box ([`SPEC_RULE`]: J is not comparable across rates). The rate
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

/// The rule of the rate choice when the study gives specifications that leave the table room.
pub const SPEC_RULE: &str = "with specifications: the pair with the least largest specification load, (the quantity's linear bound at one reference tolerance box + its noise part at its coverage) / its limit over every specification row, each in its own unit; the box is the specified allocation of the angles and the rate tolerances of the study as written (its rates, the designed positions), the same for every candidate, so the loads compare across rates where J, whose rate tolerances' weights change with the rate, does not; a pair qualifies only if a table meets every specification and every output's accuracy (eq 14) at every entry";

/// The rule of the rate choice without specifications.
pub const J_RULE: &str = "the pair with the least J of the allocation with the rate tolerances";

/// The choice among candidate rates.
#[derive(Debug, Clone)]
#[non_exhaustive]
pub struct RateChoice {
    candidates: Vec<(f64, Option<f64>)>,
    study_positions: Vec<Option<f64>>,
    chosen_study_positions: bool,
    study_rates_objective_arcmin: Option<f64>,
    chosen: Option<(f64, f64)>,
    loads: Option<Loads>,
}

/// A candidate rate (deg/s) answered: J (arcmin^-2) and its specification load.
type Answered = (f64, Option<f64>, Option<f64>);

/// Per candidate, the loads with the designed positions and with the study's.
type LoadLists<'a> = (&'a [Option<f64>], &'a [Option<f64>]);

/// The specification loads of the rate choice ([`SPEC_RULE`]).
#[derive(Debug, Clone)]
struct Loads {
    designed: Vec<Option<f64>>,
    study_positions: Vec<Option<f64>>,
    chosen: Option<f64>,
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
    pub(crate) fn study_positions(&self) -> &[Option<f64>] {
        &self.study_positions
    }

    /// Whether the chosen pair has the study's positions (else the designed ones).
    #[must_use]
    pub(crate) fn chosen_study_positions(&self) -> bool {
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

    /// Per candidate: the largest specification load at the reference box with the designed
    /// positions, then with the study's ([`SPEC_RULE`]; `None` when the choice is by J: no
    /// specification leaves room, or the study as written has no table).
    #[must_use]
    pub fn specification_loads(&self) -> Option<LoadLists<'_>> {
        self.loads
            .as_ref()
            .map(|l| (l.designed.as_slice(), l.study_positions.as_slice()))
    }

    /// The rule the choice used: [`SPEC_RULE`] or [`J_RULE`].
    #[must_use]
    pub fn rule(&self) -> &'static str {
        if self.loads.is_some() {
            SPEC_RULE
        } else {
            J_RULE
        }
    }

    /// The choice's view (`rates` of `design-schedule --json`).
    #[must_use]
    pub(crate) fn view(&self) -> RatesJson<'_> {
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

/// The tolerance box the specification loads of every candidate are taken at (the rate
/// choice's rule with specifications, [`SPEC_RULE`]): the specified allocation of the angles
/// and the rate tolerances of the study as written (its rates, the designed positions), in
/// the order of its tolerances.
#[derive(Debug, Clone)]
struct Reference {
    upper_bounds: Vec<f64>,
    tolerances: Vec<e2e_verify::RateTolerance>,
}

/// A candidate answered: J (arcmin^-2) of its allocation with the rate tolerances, `None`
/// when no table suffices (the allocation is infeasible, its exact-chain check does not
/// converge, or the noise part of a specification fills its limit); with `reference` and a
/// table that suffices, its largest specification load at the reference box ([`SPEC_RULE`]);
/// and its own box. With `specs` (the specifications the study as written leaves the table
/// room for) the allocation holds them too, over the angles and the rate tolerances
/// ([`e2e_verify::EndToEnd::rate_specification_rows`]), with the noise of `s`'s own rate
/// steps: a scale factor in ppm is judged in ppm at every rate.
fn answered(
    s: &Study,
    specs: &[gw_model::spec::Specification],
    reference: Option<&Reference>,
) -> Result<(Option<f64>, Option<f64>, Option<Reference>)> {
    let e2e = crate::loaded::simulator(s)?;
    let (linear, extra) = (e2e.linearization(), e2e.rates().extra_linearization());
    let rows = if specs.is_empty() {
        Vec::new()
    } else {
        let ctx = crate::allocation::spec::context_of(s, &e2e, specs)?;
        e2e.rates()
            .rate_specification_rows(&ctx, &extra)
            .map_err(|e| crate::error::library(e, s))?
    };
    let Ok(a) =
        e2e.rates()
            .allocate_direct_rate_specified(&linear, &extra, &s.lower_bounds_rad, &rows)
    else {
        return Ok((None, None, None));
    };
    let own = Reference {
        upper_bounds: a.combined().upper_bounds_rad().to_vec(),
        tolerances: a.tolerances().to_vec(),
    };
    let load = reference
        .filter(|r| r.tolerances == own.tolerances && !rows.is_empty())
        .map(|r| {
            rows.iter()
                .map(|row| (row.value(&r.upper_bounds) + row.noise_part()) / row.limit())
                .fold(0.0, f64::max)
        });
    Ok((Some(a.combined().objective_arcmin()), load, Some(own)))
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
    let (study, _, own) = answered(&written, &specs, None)?;
    // with specifications, every candidate is compared at the box of the study as written
    let reference = own.filter(|_| !specs.is_empty());
    let at = |positions: &[Vec<f64>]| -> Result<Vec<Answered>> {
        rates
            .iter()
            .map(|&r| {
                let (j, load, _) =
                    answered(&with_rate(s, positions, r)?, &specs, reference.as_ref())?;
                Ok((r, j, load))
            })
            .collect()
    };
    let designed_list = at(designed_deg)?;
    let study_list = if designed_deg == s.positions_deg.as_slice() {
        designed_list.clone()
    } else {
        at(&s.positions_deg)?
    };
    // the key of a pair: its load with specifications, else its J
    let key = |(_, j, load): &Answered| {
        if reference.is_some() { *load } else { *j }
    };
    let best = |list: &[Answered]| {
        list.iter().filter_map(|c| key(c).map(|k| (k, *c))).fold(
            None,
            |b: Option<(f64, Answered)>, c| match b {
                Some(b) if b.0 <= c.0 => Some(b),
                _ => Some(c),
            },
        )
    };
    let (designed, of_study) = (best(&designed_list), best(&study_list));
    let (chosen, chosen_study_positions) = match (designed, of_study) {
        (Some(d), Some(t)) if t.0 < d.0 => (Some(t.1), true),
        (None, Some(t)) => (Some(t.1), true),
        (d, _) => (d.map(|d| d.1), false),
    };
    let loads = reference.as_ref().map(|_| Loads {
        designed: designed_list.iter().map(|c| c.2).collect(),
        study_positions: study_list.iter().map(|c| c.2).collect(),
        chosen: chosen.and_then(|c| c.2),
    });
    Ok(RateChoice {
        candidates: designed_list.iter().map(|c| (c.0, c.1)).collect(),
        study_positions: study_list.iter().map(|c| c.1).collect(),
        chosen_study_positions,
        study_rates_objective_arcmin: study,
        chosen: chosen.and_then(|(r, j, _)| j.map(|j| (r, j))),
        loads,
    })
}

/// `design-schedule --rates-deg-per-s` (`rates`): the rate chosen among the candidates.
#[derive(Debug)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
#[cfg_attr(not(feature = "serde"), allow(dead_code))]
pub(crate) struct RatesJson<'a> {
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
    /// With specifications ([`SPEC_RULE`]): the rule of the choice.
    #[cfg_attr(feature = "serde", serde(skip_serializing_if = "Option::is_none"))]
    rule: Option<&'static str>,
    /// With specifications: the largest specification load at the reference box per
    /// candidate, designed positions (`null`: no table suffices).
    #[cfg_attr(feature = "serde", serde(skip_serializing_if = "Option::is_none"))]
    specification_load: Option<&'a [Option<f64>]>,
    /// The same with the study's positions.
    #[cfg_attr(feature = "serde", serde(skip_serializing_if = "Option::is_none"))]
    study_positions_specification_load: Option<&'a [Option<f64>]>,
    /// The chosen pair's load.
    #[cfg_attr(feature = "serde", serde(skip_serializing_if = "Option::is_none"))]
    chosen_specification_load: Option<f64>,
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
        rule: c.loads.as_ref().map(|_| SPEC_RULE),
        specification_load: c.loads.as_ref().map(|l| l.designed.as_slice()),
        study_positions_specification_load: c.loads.as_ref().map(|l| l.study_positions.as_slice()),
        chosen_specification_load: c.loads.as_ref().and_then(|l| l.chosen),
    }
}
