//! The GUM uncertainty budget (JCGM 100) of every specified quantity of a calibration: one
//! row per input quantity, each with its law, standard uncertainty, sensitivity coefficient,
//! contribution and degrees of freedom; the combined standard uncertainty, the effective
//! degrees of freedom, the coverage factor and the expanded uncertainty at the
//! specification's coverage probability, against its limit.
//!
//! The input quantities are
//! - each angular error $\chi_j$ of the table, with the law the caller gives (type B:
//!   rectangular on its tolerance, or normal with a measured value's uncertainty), its
//!   sensitivity from the linearised chain ([`crate::EndToEnd::coefficient_linearization`] for a
//!   coefficient and an error over a range, [`crate::EndToEnd::linearization`] for eq 14's error at
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

/// One specification's answer: which specification, where its quantity was evaluated, and
/// what the method that answers adds (`D`): its GUM budget ([`SpecificationBudget`]) or its
/// Monte Carlo of JCGM 101 ([`crate::budget_mc::SpecificationMonteCarlo`], at its budget's
/// place).
#[derive(Debug, Clone, PartialEq)]
pub struct SpecificationAnswer<D> {
    pub(crate) spec: usize,
    pub(crate) at: EvaluatedAt,
    pub(crate) detail: D,
}

impl<D> SpecificationAnswer<D> {
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
}

/// What the GUM budget adds to a specification's answer ([`SpecificationBudget`]).
#[derive(Debug, Clone, PartialEq)]
pub struct BudgetDetail {
    result: BudgetResult,
    check: SpecificationCheck,
    noise_modelled: bool,
    table_rows: usize,
}

/// The budget of one specification.
pub type SpecificationBudget = SpecificationAnswer<BudgetDetail>;

impl SpecificationBudget {
    /// The budget: its rows ([`BudgetResult::rows`]: the table's errors in the order of
    /// $\chi$, then the noise terms) and its one output.
    #[must_use]
    pub fn result(&self) -> &BudgetResult {
        &self.detail.result
    }

    /// The quantity's uncertainty (sensitivities, contributions, $u_c$, $\nu_{\text{eff}}$,
    /// $k$, $U$; model units).
    #[must_use]
    pub fn output(&self) -> &OutputUncertainty {
        &self.detail.result.outputs()[0]
    }

    /// $U$ against the limit (model units): the ratio and whether $U \le$ limit.
    #[must_use]
    pub fn check(&self) -> &SpecificationCheck {
        &self.detail.check
    }

    /// Whether the output's noise is in the budget (a noise model and a timing).
    #[must_use]
    pub fn noise_modelled(&self) -> bool {
        self.detail.noise_modelled
    }

    /// The number of rows that are the table's errors (the first rows).
    #[must_use]
    pub fn table_rows(&self) -> usize {
        self.detail.table_rows
    }

    /// The table's part alone: $\sqrt{\sum_{\text{table}} (c_j u_j)^2}$ (model units).
    #[must_use]
    pub fn table_combined(&self) -> f64 {
        self.output().contributions()[..self.detail.table_rows]
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
    /// The quantity's weights over the output's estimated coefficients (`None` for eq 14's
    /// error at a position).
    weights: Option<Vec<f64>>,
    table: Vec<f64>,
    white: f64,
    correlated: f64,
}

/// Per specification its candidates, and per output its noise covariance.
type SpecCandidates = (Vec<Vec<Candidate>>, Vec<Option<NoiseCovariance>>);

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

impl<S: ScheduleErrorModel> crate::BudgetQuestions<'_, S> {
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
        let (all, covs) = self.spec_candidates(specs, noise, timing)?;
        let outputs = self.calibration().outputs();
        specs
            .iter()
            .zip(all)
            .enumerate()
            .map(|(index, (spec, candidates))| {
                let k = spec.output();
                let cov = covs.get(k).and_then(Option::as_ref);
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
                    detail: BudgetDetail {
                        check,
                        noise_modelled: cov.is_some(),
                        table_rows: table.len(),
                        result,
                    },
                })
            })
            .collect()
    }
}

impl<S: ScheduleErrorModel> crate::BudgetQuestions<'_, S> {
    /// Every specification's candidate quantities (a coefficient: one; an error over a range:
    /// its two ends; eq 14's accuracy: every test position) with their table sensitivities and
    /// noise standard uncertainties, and the outputs' noise covariances.
    fn spec_candidates(
        &self,
        specs: &[Specification],
        noise: &[Option<NoiseModel>],
        timing: Option<&Timing>,
    ) -> Result<SpecCandidates, E2eError> {
        let covs: Vec<Option<NoiseCovariance>> = match timing {
            Some(t) => self.calibration().noise_covariances(noise, t)?,
            None => vec![None; self.n_outputs()],
        };
        let jac = self.coefficient_linearization();
        let needs_m = specs.iter().any(|s| *s.resolved() == Resolved::Accuracy);
        let m = needs_m.then(|| self.linearization());
        let outputs = self.calibration().outputs();
        let all = specs
            .iter()
            .map(|spec| {
                let k = spec.output();
                let cov = covs.get(k).and_then(Option::as_ref);
                let of_weights = |at: EvaluatedAt, w: &[f64]| Candidate {
                    at,
                    weights: Some(w.to_vec()),
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
                match *spec.resolved() {
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
                                weights: None,
                                table: m.row(k, i),
                                white: ws.as_ref().map_or(0.0, |s| s[i]),
                                correlated: cs.as_ref().map_or(0.0, |s| s[i]),
                            })
                            .collect()
                    }
                }
            })
            .collect();
        Ok((all, covs))
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
}

impl<S: ScheduleErrorModel> crate::BudgetQuestions<'_, S> {
    /// The verdict of a plan (this schedule, the tolerances `tolerances_rad` of the angular
    /// errors with the law `law`, the noise and timing) against `specs` by [`PLAN_RULE`]. An
    /// infinite tolerance enters as zero and the specification whose quantity it moves is
    /// not met ([`PlanVerdict::unbounded`]).
    ///
    /// # Errors
    /// As [`crate::BudgetQuestions::specification_budgets`]; `law`'s error for a tolerance.
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

/// What the direct allocation needs to hold every specification ([`crate::BudgetQuestions::specification_rows`]):
/// the specifications, the standard uncertainty of each table error's law per unit tolerance,
/// and the noise and timing the verdict's budget uses.
#[derive(Debug, Clone, PartialEq)]
pub struct SpecificationContext {
    specs: Vec<Specification>,
    u_per_tolerance: Vec<f64>,
    noise: Vec<Option<NoiseModel>>,
    timing: Option<Timing>,
}

impl SpecificationContext {
    /// The context of `specs` with the table errors `error_names` under the law `law` (the
    /// verdict's, [`crate::BudgetQuestions::plan_verdict`]), the noise per output and the timing (`None`: no
    /// noise is modelled).
    ///
    /// # Errors
    /// `law`'s error for a unit tolerance.
    pub fn new(
        specs: &[Specification],
        error_names: &[String],
        law: impl Fn(&str, f64) -> Result<Input, metrology::MetrologyError>,
        noise: &[Option<NoiseModel>],
        timing: Option<&Timing>,
    ) -> Result<Self, E2eError> {
        let u_per_tolerance = error_names
            .iter()
            .map(|n| Ok(law(n, 1.0)?.standard_uncertainty()))
            .collect::<Result<Vec<f64>, E2eError>>()?;
        Ok(Self {
            specs: specs.to_vec(),
            u_per_tolerance,
            noise: noise.to_vec(),
            timing: timing.cloned(),
        })
    }

    /// The specifications.
    #[must_use]
    pub fn specifications(&self) -> &[Specification] {
        &self.specs
    }

    /// The noise model of each output (`None`: noiseless).
    #[must_use]
    pub fn noise(&self) -> &[Option<NoiseModel>] {
        &self.noise
    }

    /// The timing the noise part is computed with (`None`: no noise is modelled).
    #[must_use]
    pub fn timing(&self) -> Option<&Timing> {
        self.timing.as_ref()
    }

    /// The same context with the timing `timing` (another schedule's dwells: the schedule
    /// designer's candidates).
    #[must_use]
    pub fn with_timing(&self, timing: Option<Timing>) -> Self {
        Self {
            timing,
            ..self.clone()
        }
    }
}

/// One linear row of the direct allocation for a specification (per end of a range, per
/// test position of eq 14's accuracy):
/// $$\sum_j f_j\,|c_j|\,\mathrm{UB}_j \le L - k\,u_{\text{noise}},\qquad
/// f_j = \max(1,\ k\,u_j/a_j),$$
/// $c_j$ the budget's sensitivity of the quantity to error $j$ (model unit per rad), $L$ the
/// limit, $k$ the coverage factor of the verdict at the specification's coverage (every input
/// of the budget has infinite degrees of freedom), $u_{\text{noise}}$ the noise's standard
/// uncertainty in the budget and $u_j/a_j$ the table law's standard uncertainty per unit
/// tolerance ($1/\sqrt3$ rectangular). With $f_j \ge 1$ the table's worst case plus the noise
/// part is within $L$; with $f_j \ge k u_j/a_j$ the verdict's expanded uncertainty
/// $k\sqrt{u_t^2 + u_{\text{noise}}^2} \le k u_t + k u_{\text{noise}}$ is within $L$ too.
#[derive(Debug, Clone, PartialEq)]
pub struct SpecificationRow {
    spec: usize,
    output: usize,
    weights: Option<Vec<f64>>,
    label: String,
    at: EvaluatedAt,
    sensitivities: Vec<f64>,
    factors: Vec<f64>,
    limit: f64,
    noise_part: f64,
    coverage_factor: f64,
    to_written: f64,
    unit: String,
}

impl SpecificationRow {
    /// The specification's index.
    #[must_use]
    pub fn spec(&self) -> usize {
        self.spec
    }
    /// Its label (`gx bg_x (bias)`).
    #[must_use]
    pub fn label(&self) -> &str {
        &self.label
    }
    /// Where the quantity is evaluated.
    #[must_use]
    pub fn at(&self) -> EvaluatedAt {
        self.at
    }
    /// The output whose coefficients the quantity is made of.
    #[must_use]
    pub fn output(&self) -> usize {
        self.output
    }
    /// The quantity's weights over its output's coefficients (a coefficient, an end of an
    /// operating range); `None` for eq 14's rate error at a position.
    #[must_use]
    pub fn weights(&self) -> Option<&[f64]> {
        self.weights.as_deref()
    }
    /// $f_j$: each table error's factor (its coverage factor times its standard uncertainty
    /// per unit tolerance, at least 1).
    #[must_use]
    pub fn factors(&self) -> &[f64] {
        &self.factors
    }
    /// $c_j$: the quantity's sensitivity to each table error (model unit per rad).
    #[must_use]
    pub fn sensitivities(&self) -> &[f64] {
        &self.sensitivities
    }
    /// $f_j\,|c_j|$: the row's coefficients (model unit per rad).
    #[must_use]
    pub fn coefficients(&self) -> Vec<f64> {
        self.sensitivities
            .iter()
            .zip(&self.factors)
            .map(|(c, f)| f * c.abs())
            .collect()
    }
    /// The limit $L$ (model unit).
    #[must_use]
    pub fn limit(&self) -> f64 {
        self.limit
    }
    /// The noise part $k\,u_{\text{noise}}$ (model unit; 0 without noise).
    #[must_use]
    pub fn noise_part(&self) -> f64 {
        self.noise_part
    }
    /// The coverage factor $k$.
    #[must_use]
    pub fn coverage_factor(&self) -> f64 {
        self.coverage_factor
    }
    /// What the table may take: $L - k\,u_{\text{noise}}$ (model unit).
    #[must_use]
    pub fn room(&self) -> f64 {
        self.limit - self.noise_part
    }
    /// The written unit's value per model unit.
    #[must_use]
    pub fn to_written(&self) -> f64 {
        self.to_written
    }
    /// The unit as written.
    #[must_use]
    pub fn unit(&self) -> &str {
        &self.unit
    }
    /// The row's value for bounds `ub_rad` (model unit; infinite bounds count 0 where the
    /// sensitivity is 0).
    #[must_use]
    pub fn value(&self, ub_rad: &[f64]) -> f64 {
        self.coefficients()
            .iter()
            .zip(ub_rad)
            .filter(|(c, _)| **c != 0.0)
            .map(|(c, u)| c * u)
            .sum()
    }
    /// The quantity on the exact chain for table errors `chi_rad` (model unit):
    /// `coefficients` are [`crate::EndToEnd::coefficient_errors`] and `errors`
    /// [`crate::EndToEnd::error_vectors`] at `chi_rad`, `offsets[k]` the index of output `k`'s first
    /// coefficient in `coefficients`.
    pub(crate) fn exact(
        &self,
        coefficients: &[f64],
        offsets: &[usize],
        errors: &[Vec<f64>],
    ) -> f64 {
        match (&self.weights, self.at) {
            (Some(w), _) => w
                .iter()
                .zip(&coefficients[offsets[self.output]..])
                .map(|(w, c)| w * c)
                .sum(),
            (None, EvaluatedAt::Position(i)) => errors[self.output][i],
            (None, _) => unreachable!("a coefficient or a range end has weights"),
        }
    }

    /// The box's vertex that maximises the row's linear value: $\chi_j =
    /// \mathrm{sign}(c_j)\,\mathrm{UB}_j$ (0 for an infinite bound).
    pub(crate) fn vertex(&self, ub_rad: &[f64]) -> Vec<f64> {
        self.sensitivities
            .iter()
            .zip(ub_rad)
            .map(|(c, u)| {
                if !u.is_finite() {
                    0.0
                } else if *c < 0.0 {
                    -u
                } else {
                    *u
                }
            })
            .collect()
    }

    /// [`E2eError::NoTableSuffices`] when the noise part alone fills the limit.
    ///
    /// # Errors
    /// That error, in the specification's unit.
    pub fn check_room(&self) -> Result<(), E2eError> {
        if self.room() > 0.0 {
            return Ok(());
        }
        Err(E2eError::NoTableSuffices {
            spec: self.label.clone(),
            noise: self.noise_part * self.to_written,
            limit: self.limit * self.to_written,
            unit: self.unit.clone(),
        })
    }
}

impl<S: ScheduleErrorModel> crate::BudgetQuestions<'_, S> {
    /// The direct allocation's rows of every specification of `ctx` (see
    /// [`SpecificationRow`]): one per candidate quantity of the budget (a coefficient, each end
    /// of a range, each test position of eq 14's accuracy), with the same sensitivities and
    /// noise as [`crate::BudgetQuestions::specification_budgets`].
    ///
    /// # Errors
    /// As [`crate::BudgetQuestions::specification_budgets`]; a length error unless one law per error.
    pub fn specification_rows(
        &self,
        ctx: &SpecificationContext,
    ) -> Result<Vec<SpecificationRow>, E2eError> {
        tt_core::length("table inputs", self.n_errors(), ctx.u_per_tolerance.len())?;
        let (all, _) = self.spec_candidates(&ctx.specs, &ctx.noise, ctx.timing.as_ref())?;
        let sensor = self.calibration().sensor();
        let mut rows = Vec::new();
        for (index, (spec, candidates)) in ctx.specs.iter().zip(all).enumerate() {
            let k = metrology::coverage_factor(f64::INFINITY, spec.coverage())?;
            let factors: Vec<f64> = ctx
                .u_per_tolerance
                .iter()
                .map(|s| (k * s).max(1.0))
                .collect();
            let label = spec.label(sensor);
            for c in candidates {
                rows.push(SpecificationRow {
                    spec: index,
                    output: spec.output(),
                    weights: c.weights,
                    label: label.clone(),
                    at: c.at,
                    noise_part: k * c.white.hypot(c.correlated),
                    sensitivities: c.table,
                    factors: factors.clone(),
                    limit: spec.limit(),
                    coverage_factor: k,
                    to_written: spec.to_written(),
                    unit: spec.unit().to_string(),
                });
            }
        }
        Ok(rows)
    }
}

/// The standard uncertainty of a rate tolerance per unit tolerance in the rows of
/// [`crate::EndToEnd::rate_specification_rows`]: a rectangular law on the tolerance
/// ($1/\sqrt3$; the verdict's budget has no rate tolerance input, so the table law's default
/// is taken).
const RATE_TOLERANCE_U_PER_TOLERANCE: f64 = 0.577_350_269_189_625_8;

impl crate::RateQuestions<'_> {
    /// The Jacobian of every output's estimated coefficients with respect to the extra
    /// errors ([`crate::EndToEnd::extra_errors`]; coefficient unit per metre or per unit of
    /// relative rate error), as [`crate::EndToEnd::coefficient_linearization`] is for the angles:
    /// zero where no rate step is in the schedule.
    #[must_use]
    pub(crate) fn extra_coefficient_linearization(&self) -> Vec<DMatrix<f64>> {
        let du = self.extra_input_derivatives();
        self.coefficient_linearization_with(self.extra_errors().len(), |i, j, _| du[i][j])
    }

    /// [`crate::BudgetQuestions::specification_rows`] over the angles and the rate tolerances together
    /// (the columns of [`crate::RateQuestions::rate_linearization`]): each row's sensitivity to a
    /// tolerance is $\sum_{e \in t} |c_e|$ over the extra errors it bounds (a coefficient's
    /// or a range end's from [`crate::RateQuestions::extra_coefficient_linearization`], eq 14's at
    /// a position from `extra_linear`), its factor $\max(1, k/\sqrt3)$ (a rectangular law on
    /// the tolerance). So a scale factor specified in ppm constrains the table's rate
    /// accuracy in ppm whatever the rate of the steps, and its noise part (the noise in the
    /// rate steps' average over the rate) shrinks as the rate grows.
    ///
    /// # Errors
    /// As [`crate::BudgetQuestions::specification_rows`].
    pub fn rate_specification_rows(
        &self,
        ctx: &SpecificationContext,
        extra_linear: &crate::Linearization,
    ) -> Result<Vec<SpecificationRow>, E2eError> {
        let rows = self.budget().specification_rows(ctx)?;
        let tols = self.rate_tolerances();
        let extra = self.extra_errors();
        let jac = self.extra_coefficient_linearization();
        Ok(rows
            .into_iter()
            .map(|mut r| {
                let per_error: Vec<f64> = match (&r.weights, r.at) {
                    (Some(w), _) => (0..extra.len())
                        .map(|e| {
                            w.iter()
                                .enumerate()
                                .map(|(t, wt)| wt * jac[r.output][(t, e)])
                                .sum()
                        })
                        .collect(),
                    (None, EvaluatedAt::Position(i)) => extra_linear.row(r.output, i),
                    (None, _) => unreachable!("a coefficient or a range end has weights"),
                };
                let mut per_tolerance = vec![0.0; tols.len()];
                for (x, c) in extra.iter().zip(&per_error) {
                    if let Some(t) = tols
                        .iter()
                        .position(|t| *t == crate::rate::RateTolerance::of(*x))
                    {
                        per_tolerance[t] += c.abs();
                    }
                }
                let f = (r.coverage_factor * RATE_TOLERANCE_U_PER_TOLERANCE).max(1.0);
                r.sensitivities.extend(per_tolerance);
                r.factors.extend(std::iter::repeat_n(f, tols.len()));
                r
            })
            .collect())
    }
}
