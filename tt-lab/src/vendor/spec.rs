//! The verdict against the study's specifications per quantity (issue 34): one library call
//! ([`e2e_verify::EndToEnd::plan_verdict`]) and its JSON view, shared by `check-turntable`
//! (the sheet's tolerances) and `end-to-end` (the direct allocation's box). Every verdict
//! names its rule; where an output's noise is not modelled the same sentence says so.

use crate::Result;
use e2e_verify::EndToEnd;
use e2e_verify::budget::{ACCURACY_RULE, EvaluatedAt, PLAN_RULE, PlanVerdict};
use study::Study;

/// The plan's verdict against the study's specifications for the tolerances `ub_rad`
/// (`None` when the study gives none).
///
/// # Errors
/// As [`EndToEnd::plan_verdict`] (reported as the study's input).
pub fn compute(s: &Study, e2e: &EndToEnd, ub_rad: &[f64]) -> Result<Option<PlanVerdict>> {
    if s.specifications.is_empty() {
        return Ok(None);
    }
    let law = s.uncertainty.tolerance_distribution;
    e2e.plan_verdict(
        &s.specifications,
        ub_rad,
        |n, a| law.input(n, a),
        &s.noise,
        s.timing.as_ref(),
    )
    .map(Some)
    .map_err(|e| crate::error::library(e, s))
}

/// One row of a budget (`specifications[].budget[]`).
#[derive(Debug)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct RowJson {
    /// The input quantity (a table error, rad; or a noise term, output unit).
    pub name: String,
    /// Its law.
    pub distribution: &'static str,
    /// Its standard uncertainty, in its unit (rad for a table error, the model's output unit
    /// for a noise term).
    pub standard_uncertainty: f64,
    /// Its sensitivity coefficient (the specification's unit per the input's unit).
    pub sensitivity: f64,
    /// Its contribution |c| u, the specification's unit.
    pub contribution: f64,
    /// Its degrees of freedom (`null`: infinite).
    pub dof: Option<f64>,
}

/// One specification's verdict (`specifications[]`), in the specification's unit.
#[derive(Debug)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct SpecJson {
    /// `output coefficient (kind)`, `output error over +-R unit`, `output accuracy (eq 14)`.
    pub quantity: String,
    /// The unit of every figure (as written in the study).
    pub unit: String,
    /// The limit.
    pub limit: f64,
    /// The coverage probability.
    pub coverage: f64,
    /// The combined standard uncertainty.
    pub combined_standard_uncertainty: f64,
    /// The effective degrees of freedom (`null`: infinite).
    pub dof_eff: Option<f64>,
    /// The coverage factor.
    pub coverage_factor: f64,
    /// The expanded uncertainty.
    pub expanded: f64,
    /// U / limit.
    pub ratio: f64,
    /// Whether met by the rule.
    pub meets: bool,
    /// Whether the output's noise is in the budget.
    pub noise_modelled: bool,
    /// Errors without a finite tolerance that move the quantity.
    pub unbounded: Vec<String>,
    /// The test position evaluated (eq 14's accuracy), else `null`.
    pub position: Option<usize>,
    /// The budget's rows.
    pub budget: Vec<RowJson>,
}

/// The verdict against the specifications (`specifications` of `--json`).
#[derive(Debug)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct SpecVerdictJson {
    /// The decision rule in words.
    pub rule: &'static str,
    /// Whether every specification is met (`null` without specifications).
    pub meets: Option<bool>,
    /// The law of a tolerance (`rectangular`, ...).
    pub tolerance_distribution: &'static str,
    /// One per specification (empty without).
    pub specifications: Vec<SpecJson>,
}

impl SpecVerdictJson {
    /// The JSON view of `v` (the accuracy rule without specifications).
    #[must_use]
    pub fn new(s: &Study, v: Option<&PlanVerdict>) -> Self {
        let Some(v) = v else {
            return Self {
                rule: ACCURACY_RULE,
                meets: None,
                tolerance_distribution: s.uncertainty.tolerance_distribution.name(),
                specifications: Vec::new(),
            };
        };
        let specifications = v
            .budgets()
            .iter()
            .zip(&s.specifications)
            .map(|(b, sp)| {
                let f = sp.to_written();
                let o = b.output();
                SpecJson {
                    quantity: sp.label(&s.sensor),
                    unit: sp.unit().to_string(),
                    limit: sp.written_limit(),
                    coverage: sp.coverage(),
                    combined_standard_uncertainty: o.combined() * f,
                    dof_eff: o.dof_eff().is_finite().then(|| o.dof_eff()),
                    coverage_factor: o.coverage_factor(),
                    expanded: o.expanded() * f,
                    ratio: b.check().ratio(),
                    meets: v.meets(b.spec()),
                    noise_modelled: b.noise_modelled(),
                    unbounded: v.unbounded()[b.spec()].clone(),
                    position: match b.at() {
                        EvaluatedAt::Position(i) => Some(i),
                        _ => None,
                    },
                    budget: b
                        .result()
                        .rows()
                        .iter()
                        .zip(o.sensitivities().iter().zip(o.contributions()))
                        .map(|(r, (c, u))| RowJson {
                            name: r.name().to_string(),
                            distribution: r.distribution(),
                            standard_uncertainty: r.standard_uncertainty(),
                            sensitivity: c * f,
                            contribution: u.abs() * f,
                            dof: r.dof().is_finite().then(|| r.dof()),
                        })
                        .collect(),
                }
            })
            .collect();
        Self {
            rule: PLAN_RULE,
            meets: Some(v.meets_all()),
            tolerance_distribution: s.uncertainty.tolerance_distribution.name(),
            specifications,
        }
    }
}
