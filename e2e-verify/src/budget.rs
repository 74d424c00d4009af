//! The GUM uncertainty budget (JCGM 100) of every specified quantity of a calibration: one
//! row per input quantity, each with its law, standard uncertainty, sensitivity coefficient,
//! contribution and degrees of freedom; the combined standard uncertainty, the effective
//! degrees of freedom, the coverage factor and the expanded uncertainty at the
//! specification's coverage probability, against its limit.
//!
//! The input quantities are
//! - each angular error $\chi_j$ of the table, with the law the caller gives (type B:
//!   rectangular on its tolerance, or normal with a measured value's uncertainty), its
//!   sensitivity from the linearised chain ([`EndToEnd::coefficient_linearization`] for a
//!   coefficient and an error over a range, [`EndToEnd::linearization`] for eq 14's error at
//!   a test position);
//! - per output with a noise model and a timing, its white and its correlated noise
//!   (bias instability, rate random walk, ramp), each with the standard uncertainty the
//!   least squares gives the quantity, $\sqrt{\mathbf w^T\boldsymbol\Sigma\mathbf w}$ with
//!   $\boldsymbol\Sigma = \mathbf A^+\boldsymbol\Sigma_{\text{positions}}\mathbf A^{+T}$
//!   (calib-lsq's [`calib_lsq::CoefficientCovariance`]): the correlations the schedule induces
//!   between the positions' averages are carried in $\boldsymbol\Sigma$, not assumed away;
//!   sensitivity 1.
//!
//! Which quantity: a coefficient is $\mathbf w = \mathbf e_t$; the error over a range is
//! $\mathbf w = (r_t(\pm R\,\mathbf e_{\text{axis}}))_t$ over the estimated terms, the sign
//! with the larger combined uncertainty; eq 14's accuracy is the rate error at the test
//! position with the largest combined uncertainty. Every quantity is in the model's units
//! (output unit per regressor unit); [`gw_model::spec::Specification::to_written`] converts.

use crate::error::E2eError;
use crate::simulate::EndToEnd;
use calib_lsq::{NoiseCovariance, Timing};
use gw_model::InputValues;
use gw_model::noise::NoiseModel;
use gw_model::spec::{Resolved, Specification};
use metrology::plan::SpecificationCheck;
use metrology::{Budget, BudgetResult, BudgetSettings, Input, OutputUncertainty};
use nalgebra::DMatrix;
use tt_kinematics::ScheduleErrorModel;

/// Where a specified quantity was evaluated.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum EvaluatedAt {
    /// A coefficient: one quantity.
    Coefficient,
    /// An error over a range: at the input $+R$ (`true`) or $-R$ (`false`) along the axis.
    RangeEnd {
        /// Whether at $+R$.
        positive: bool,
    },
    /// Eq 14's error at test position `0`-based index.
    Position(usize),
}

/// The budget of one specification.
#[derive(Debug, Clone, PartialEq)]
pub struct SpecificationBudget {
    spec: usize,
    at: EvaluatedAt,
    result: BudgetResult,
    check: SpecificationCheck,
    noise_modelled: bool,
    table_rows: usize,
}

impl SpecificationBudget {
    /// The specification's index (the order given).
    #[must_use]
    pub fn spec(&self) -> usize {
        self.spec
    }

    /// Where the quantity was evaluated.
    #[must_use]
    pub fn at(&self) -> EvaluatedAt {
        self.at
    }

    /// The budget: its rows ([`BudgetResult::rows`]: the table's errors in the order of
    /// $\chi$, then the noise terms) and its one output.
    #[must_use]
    pub fn result(&self) -> &BudgetResult {
        &self.result
    }

    /// The quantity's uncertainty (sensitivities, contributions, $u_c$, $\nu_{\text{eff}}$,
    /// $k$, $U$; model units).
    #[must_use]
    pub fn output(&self) -> &OutputUncertainty {
        &self.result.outputs()[0]
    }

    /// $U$ against the limit (model units): the ratio and whether $U \le$ limit.
    #[must_use]
    pub fn check(&self) -> &SpecificationCheck {
        &self.check
    }

    /// Whether the output's noise is in the budget (a noise model and a timing).
    #[must_use]
    pub fn noise_modelled(&self) -> bool {
        self.noise_modelled
    }

    /// The number of rows that are the table's errors (the first rows).
    #[must_use]
    pub fn table_rows(&self) -> usize {
        self.table_rows
    }

    /// The table's part alone: $\sqrt{\sum_{\text{table}} (c_j u_j)^2}$ (model units).
    #[must_use]
    pub fn table_combined(&self) -> f64 {
        self.output().contributions()[..self.table_rows]
            .iter()
            .map(|c| c * c)
            .sum::<f64>()
            .sqrt()
    }
}

/// One candidate quantity: the table's sensitivities and the noise's two standard
/// uncertainties.
struct Candidate {
    at: EvaluatedAt,
    table: Vec<f64>,
    white: f64,
    correlated: f64,
}

impl Candidate {
    fn variance(&self, u: &[f64]) -> f64 {
        let t: f64 = self.table.iter().zip(u).map(|(c, u)| (c * u).powi(2)).sum();
        t + self.white.powi(2) + self.correlated.powi(2)
    }
}

/// The weights $\mathbf w = (r_t(\pm R\,\mathbf e_{\text{axis}}))_t$ of an output's error
/// at the end of its range (`positive`: $+R$) over its estimated terms: the error over a range
/// as a combination of the coefficients' errors (the budget's and the Monte Carlo's quantity).
pub(crate) fn range_end_weights(
    output: &calib_lsq::OutputCalibration,
    axis: usize,
    range: f64,
    positive: bool,
) -> Vec<f64> {
    let mut v = [0.0; 6];
    v[axis] = if positive { range } else { -range };
    let v = InputValues(v);
    output
        .output()
        .estimated()
        .map(|t| t.regressor.eval(&v))
        .collect()
}

/// $\mathbf w^T\mathbf M\mathbf w$.
fn quadratic(m: &DMatrix<f64>, w: &[f64]) -> f64 {
    let mut s = 0.0;
    for (i, wi) in w.iter().enumerate() {
        for (j, wj) in w.iter().enumerate() {
            s += wi * m[(i, j)] * wj;
        }
    }
    s
}

impl<S: ScheduleErrorModel> EndToEnd<S> {
    /// The GUM budget of every specification in `specs` (see the [module](self)): `table`
    /// holds one input per angular error (order of $\chi$, rad; its law and uncertainty),
    /// `noise` one noise model per output (`None` for a noiseless one) and `timing` the dwell
    /// per position (`None`: no noise is modelled).
    ///
    /// # Errors
    /// [`E2eError::Field`] (length) naming `table inputs` unless one single-component input
    /// per angular error; [`E2eError::Calib`] from the noise covariances (one noise entry per
    /// output, one dwell per position); [`E2eError::Metrology`] for a budget the metrology
    /// crate refuses.
    pub fn specification_budgets(
        &self,
        specs: &[Specification],
        table: &[Input],
        noise: &[Option<NoiseModel>],
        timing: Option<&Timing>,
    ) -> Result<Vec<SpecificationBudget>, E2eError> {
        tt_core::length("table inputs", self.n_errors(), table.len())?;
        if let Some(bad) = table.iter().find(|i| i.components() != 1) {
            return Err(tt_core::FieldError::Length {
                field: format!("table inputs.{}", bad.name()),
                expected: 1,
                found: bad.components(),
            }
            .into());
        }
        let u: Vec<f64> = table.iter().map(Input::standard_uncertainty).collect();
        let covs: Vec<Option<NoiseCovariance>> = match timing {
            Some(t) => self.calibration().noise_covariances(noise, t)?,
            None => vec![None; self.n_outputs()],
        };
        let jac = self.coefficient_linearization();
        let needs_m = specs.iter().any(|s| *s.resolved() == Resolved::Accuracy);
        let m = needs_m.then(|| self.linearization());
        let outputs = self.calibration().outputs();
        specs
            .iter()
            .enumerate()
            .map(|(index, spec)| {
                let k = spec.output();
                let cov = covs.get(k).and_then(Option::as_ref);
                let of_weights = |at: EvaluatedAt, w: &[f64]| Candidate {
                    at,
                    table: (0..self.n_errors())
                        .map(|j| {
                            w.iter()
                                .enumerate()
                                .map(|(t, wt)| wt * jac[k][(t, j)])
                                .sum()
                        })
                        .collect(),
                    white: cov.map_or(0.0, |c| {
                        quadratic(c.coefficients().white(), w).max(0.0).sqrt()
                    }),
                    correlated: cov.map_or(0.0, |c| {
                        quadratic(c.coefficients().correlated(), w).max(0.0).sqrt()
                    }),
                };
                let n_coef = jac[k].nrows();
                let candidates: Vec<Candidate> = match *spec.resolved() {
                    Resolved::Coefficient { index: t, .. } => {
                        let mut w = vec![0.0; n_coef];
                        w[t] = 1.0;
                        vec![of_weights(EvaluatedAt::Coefficient, &w)]
                    }
                    Resolved::ErrorOverRange { axis, range } => [true, false]
                        .into_iter()
                        .map(|positive| {
                            let w = range_end_weights(&outputs[k], axis as usize, range, positive);
                            of_weights(EvaluatedAt::RangeEnd { positive }, &w)
                        })
                        .collect(),
                    Resolved::Accuracy => {
                        let m = m.as_ref().expect("computed when an accuracy is specified");
                        let rate = cov.map(NoiseCovariance::rate_error);
                        let (ws, cs) = rate.map_or((None, None), |r| {
                            (Some(r.white_sigma()), Some(r.correlated_sigma()))
                        });
                        (0..self.len())
                            .map(|i| Candidate {
                                at: EvaluatedAt::Position(i),
                                table: m.row(k, i),
                                white: ws.as_ref().map_or(0.0, |s| s[i]),
                                correlated: cs.as_ref().map_or(0.0, |s| s[i]),
                            })
                            .collect()
                    }
                };
                let worst = candidates
                    .iter()
                    .reduce(|a, b| {
                        if b.variance(&u) > a.variance(&u) {
                            b
                        } else {
                            a
                        }
                    })
                    .expect("at least one candidate");
                let name = &outputs[k].output().name;
                let mut inputs = table.to_vec();
                let mut c = worst.table.clone();
                if cov.is_some() {
                    inputs.push(Input::normal(
                        &format!("noise, white ({name})"),
                        0.0,
                        worst.white,
                    )?);
                    inputs.push(Input::normal(
                        &format!("noise, correlated ({name})"),
                        0.0,
                        worst.correlated,
                    )?);
                    c.extend([1.0, 1.0]);
                }
                let settings = BudgetSettings {
                    coverage: spec.coverage(),
                    ..BudgetSettings::default()
                };
                let result = Budget::new(inputs, settings)?
                    .evaluate(&[name.as_str()], &DMatrix::from_row_slice(1, c.len(), &c))?;
                let out = &result.outputs()[0];
                let check = SpecificationCheck::of_output(out, spec.coverage(), spec.limit())?;
                Ok(SpecificationBudget {
                    spec: index,
                    at: worst.at,
                    check,
                    noise_modelled: cov.is_some(),
                    table_rows: table.len(),
                    result,
                })
            })
            .collect()
    }
}

/// The rule of a plan's verdict against specifications, in words (printed with every
/// verdict).
pub const PLAN_RULE: &str = "a specification is met when the expanded uncertainty U of its quantity at its coverage probability is within it (U / limit <= 1; GUM budget of the table's tolerances and the modelled noise, no guard band)";

/// The rule when a study gives no specification: each output's accuracy (eq 14).
pub const ACCURACY_RULE: &str = "no [[specifications]] in the study: each output's accuracy (eq 14) against the worst case over the tolerance box (the table's part; proven only where a second-order bound certifies it), with the noise at k sigma at the worst position where the study models noise";

/// A plan's verdict against every specification: each specification's budget, and the
/// errors with no tolerance (an infinite bound) that move its quantity.
#[derive(Debug, Clone, PartialEq)]
pub struct PlanVerdict {
    budgets: Vec<SpecificationBudget>,
    unbounded: Vec<Vec<String>>,
}

impl PlanVerdict {
    /// One budget per specification, in their order.
    #[must_use]
    pub fn budgets(&self) -> &[SpecificationBudget] {
        &self.budgets
    }

    /// Per specification: the table's errors without a finite tolerance whose sensitivity is
    /// not zero (its U is then not bounded).
    #[must_use]
    pub fn unbounded(&self) -> &[Vec<String>] {
        &self.unbounded
    }

    /// Whether specification `i` is met: $U \le$ limit and no unbounded error moves it.
    #[must_use]
    pub fn meets(&self, i: usize) -> bool {
        self.unbounded[i].is_empty() && self.budgets[i].check().meets()
    }

    /// Whether every specification is met.
    #[must_use]
    pub fn meets_all(&self) -> bool {
        (0..self.budgets.len()).all(|i| self.meets(i))
    }

    /// Whether every specified output's noise is in its budget.
    #[must_use]
    pub fn noise_modelled_everywhere(&self) -> bool {
        self.budgets.iter().all(SpecificationBudget::noise_modelled)
    }
}

impl<S: ScheduleErrorModel> EndToEnd<S> {
    /// The verdict of a plan (this schedule, the tolerances `tolerances_rad` of the angular
    /// errors with the law `law`, the noise and timing) against `specs` by [`PLAN_RULE`]. An
    /// infinite tolerance enters as zero and the specification whose quantity it moves is
    /// not met ([`PlanVerdict::unbounded`]).
    ///
    /// # Errors
    /// As [`EndToEnd::specification_budgets`]; `law`'s error for a tolerance.
    pub fn plan_verdict(
        &self,
        specs: &[Specification],
        tolerances_rad: &[f64],
        law: impl Fn(&str, f64) -> Result<Input, metrology::MetrologyError>,
        noise: &[Option<NoiseModel>],
        timing: Option<&Timing>,
    ) -> Result<PlanVerdict, E2eError> {
        tt_core::length("tolerances", self.n_errors(), tolerances_rad.len())?;
        let names = self.error_names();
        let table = names
            .iter()
            .zip(tolerances_rad)
            .map(|(n, &a)| law(n, if a.is_finite() { a } else { 0.0 }))
            .collect::<Result<Vec<_>, _>>()?;
        let budgets = self.specification_budgets(specs, &table, noise, timing)?;
        let unbounded = budgets
            .iter()
            .map(|b| {
                let c = &b.output().sensitivities()[..b.table_rows()];
                let scale = c.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
                names
                    .iter()
                    .zip(tolerances_rad)
                    .zip(c)
                    .filter(|((_, a), c)| !a.is_finite() && c.abs() > 1e-9 * scale)
                    .map(|((n, _), _)| n.clone())
                    .collect()
            })
            .collect();
        Ok(PlanVerdict { budgets, unbounded })
    }
}
