//! The verdict against the study's specifications per quantity (issue 34): one library call
//! ([`e2e_verify::BudgetQuestions::plan_verdict`]) and its JSON view, shared by `check-turntable`
//! (the sheet's tolerances) and `end-to-end` (the direct allocation's box). Every verdict
//! names its rule; where an output's noise is not modelled the same sentence says so.

use crate::Result;
use e2e_verify::EndToEnd;
use e2e_verify::budget::{ACCURACY_RULE, EvaluatedAt, PLAN_RULE, PlanVerdict};
use study::Study;
use tt_core::human::num;

/// The plan's verdict against the study's specifications for the tolerances `ub_rad`
/// (`None` when the study gives none).
///
/// # Errors
/// As [`e2e_verify::BudgetQuestions::plan_verdict`] (reported as the study's input).
pub fn compute(s: &Study, e2e: &EndToEnd, ub_rad: &[f64]) -> Result<Option<PlanVerdict>> {
    if s.specifications.is_empty() {
        return Ok(None);
    }
    let law = s.uncertainty.tolerance_distribution;
    e2e.budget()
        .plan_verdict(
            &s.specifications,
            ub_rad,
            |n, a| law.input(n, a),
            &s.noise,
            s.timing.as_ref(),
        )
        .map(Some)
        .map_err(|e| crate::error::library(e, s))
}

/// A budget row's sensitivity coefficient is shown as 0 (in the report's budget table and
/// any text; `--json` and `results.json` keep the raw value) when $|c|$ is below this
/// fraction of the largest $|c|$ among the budget's rows of the same input unit (the table
/// errors, rad; the noise terms, the output's unit). The coefficients come out of the
/// linearised chain and the least squares in double precision, so a coefficient that is
/// zero exactly (an error that does not move the quantity to first order) comes out as a
/// residue of a few times $2^{-52} \approx 2.2 \times 10^{-16}$ of the coefficients it was
/// computed from (gx's bias against `dphi_o` on the IMU example: $-1.11 \times 10^{-16}$
/// deg/h/rad); $10^{-9}$ leaves seven orders of magnitude for the schedule's condition
/// number, and a true coefficient that small adds less than $10^{-18}$ of the largest term
/// to $u_c^2$ at equal $u(x)$: no printed digit changes.
pub const NUMERICAL_ZERO_REL: f64 = 1e-9;

/// Whether the sensitivity `c` is numerically zero: $|c|$ below [`NUMERICAL_ZERO_REL`] of
/// `scale` (the largest $|c|$ of the rows of its input's unit).
#[must_use]
pub(crate) fn numerically_zero(c: f64, scale: f64) -> bool {
    c.abs() < NUMERICAL_ZERO_REL * scale
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
    /// The sensitivity as shown (0 when [`numerically_zero`]); not in the JSON, which keeps
    /// the raw value.
    #[cfg_attr(feature = "serde", serde(skip))]
    pub shown_sensitivity: f64,
    /// The contribution as shown: 0 with a sensitivity shown as 0, else `contribution`.
    #[cfg_attr(feature = "serde", serde(skip))]
    pub shown_contribution: f64,
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
                // the largest |c| of the table errors' rows and of the noise terms' rows
                let c = o.sensitivities();
                let (table, noise) = c.split_at(b.table_rows().min(c.len()));
                let largest = |c: &[f64]| c.iter().fold(0.0_f64, |m, c| m.max(c.abs()));
                let scale = [largest(table), largest(noise)];
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
                        .enumerate()
                        .map(|(k, (r, (c, u)))| {
                            let zero =
                                numerically_zero(*c, scale[usize::from(k >= b.table_rows())]);
                            let shown = |v: f64| if zero { 0.0 } else { v };
                            RowJson {
                                name: r.name().to_string(),
                                distribution: r.distribution(),
                                standard_uncertainty: r.standard_uncertainty(),
                                sensitivity: c * f,
                                shown_sensitivity: shown(c * f),
                                shown_contribution: shown(u.abs() * f),
                                contribution: u.abs() * f,
                                dof: r.dof().is_finite().then(|| r.dof()),
                            }
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

/// Where a quantity was evaluated, in words.
fn at_text(at: EvaluatedAt) -> String {
    match at {
        EvaluatedAt::Coefficient => String::new(),
        EvaluatedAt::RangeEnd { positive } => {
            format!(" (at the {} end)", if positive { "+" } else { "-" })
        }
        EvaluatedAt::Position(i) => format!(" (at test position {i})"),
    }
}

/// The outputs whose noise is not in the budgets, by name.
fn unmodelled(s: &Study, v: &PlanVerdict) -> Vec<String> {
    let mut names: Vec<String> = v
        .budgets()
        .iter()
        .filter(|b| !b.noise_modelled())
        .map(|b| {
            s.sensor.outputs()[s.specifications[b.spec()].output()]
                .name
                .clone()
        })
        .collect();
    names.dedup();
    names
}

/// The verdict line of specification `i` of `v` (plain text, the study's names unescaped):
/// the quantity, U, u_c, k, p, the limit, the ratio, the verdict, the dominant input and
/// whether the output's noise is modelled.
pub fn spec_line(s: &Study, v: &PlanVerdict, i: usize) -> String {
    let b = &v.budgets()[i];
    let sp = &s.specifications[b.spec()];
    let f = sp.to_written();
    let o = b.output();
    let dominant = o.dominant().map_or(String::new(), |d| {
        let share = o.contributions()[d].powi(2) / o.combined().powi(2);
        format!(
            "; dominant: {} ({:.0}% of the variance)",
            b.result().rows()[d].name(),
            100.0 * share
        )
    });
    let unbounded = &v.unbounded()[b.spec()];
    let verdict = if !unbounded.is_empty() {
        format!(
            "does NOT meet: not bounded ({} has no tolerance and moves it)",
            unbounded.join(", ")
        )
    } else if b.check().meets() {
        "meets".to_string()
    } else {
        "does NOT meet".to_string()
    };
    let noise = if b.noise_modelled() {
        String::new()
    } else {
        "; noise not modelled for this output: the table's errors only".to_string()
    };
    format!(
        "{}{}: U = {} {u} (u_c {}, k = {}, p = {}%) against {} {u}, ratio {}: {verdict}{dominant}{noise}",
        sp.label(&s.sensor),
        at_text(b.at()),
        num(o.expanded() * f),
        num(o.combined() * f),
        num(o.coverage_factor()),
        num(100.0 * sp.coverage()),
        num(sp.written_limit()),
        num(b.check().ratio()),
        u = sp.unit(),
    )
}

/// The headline of `v` (plain text): met or not, how many, the noise and the rule.
pub fn headline(s: &Study, v: &PlanVerdict) -> String {
    let missing = unmodelled(s, v);
    let noise = if missing.is_empty() {
        "the noise modelled for every specified output".to_string()
    } else {
        format!(
            "noise not modelled for {} (no noise model or no [calibration.timing]): the table's errors only there",
            missing.join(", ")
        )
    };
    format!(
        "verdict: {} every specification ({} of {} met); {noise}; rule: {PLAN_RULE}",
        if v.meets_all() {
            "MEETS"
        } else {
            "does NOT meet"
        },
        (0..v.budgets().len()).filter(|&i| v.meets(i)).count(),
        v.budgets().len(),
    )
}
