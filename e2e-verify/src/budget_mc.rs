//! The Monte Carlo of JCGM 101 over the whole calibration, beside the GUM budget of every
//! specified quantity ([`crate::budget`]): the table's errors drawn from their laws, put
//! through the **exact** chain (outputs simulated at the actual orientation, calibrated at the
//! intended one: [`EndToEnd::coefficient_errors`], [`EndToEnd::error_vectors`]), the noise
//! drawn, the estimator run; run adaptively to the numerical tolerance of $n_{\mathrm{dig}}$
//! significant digits of $u(y)$ (JCGM 101 7.9, [`metrology::montecarlo::run`]), with the
//! probabilistically symmetric and the shortest coverage interval, and the validation of the
//! GUM interval $0 \pm U$ against it (JCGM 101 8.2).
//!
//! Each specification's quantity $y$ is evaluated where its budget found the largest
//! combined uncertainty ([`crate::budget::EvaluatedAt`]): a coefficient's error, the error
//! over a range at its worse end, or eq 14's rate error at the budget's test position. The
//! model is
//! $$y = q(\boldsymbol\chi) + \varepsilon_{\text{white}} + \varepsilon_{\text{corr}},$$
//! $q$ the quantity's exact-chain error for the drawn table errors $\boldsymbol\chi$ (each from
//! its budget row's law: rectangular on a tolerance, normal with a measured value's
//! uncertainty), the two noise terms normal with the standard uncertainties the least squares
//! gives the quantity (the budget's noise rows). The least squares is linear in the outputs,
//! so a Gaussian noise enters its estimate exactly so; what the Monte Carlo tests is the
//! table's part, the only place where the linearised budget can be wrong (the second order of
//! the chain, a non-normal sum of few rectangular terms).
//!
//! Every quantity is one output of one run (its marginal distribution: the joint probability
//! that every specification is met is the yield of [`crate::noise`]); the estimate of the GUM
//! is $y = 0$ (no error at the input estimates). Specifications with different coverage
//! probabilities run as separate runs (one per probability, the same seed).
//!
//! Seeded: trial $t$ of block $b$ is fixed by (seed, block, trial) whatever thread computes it
//! (metrology's streams), so the answer is the same for any number of threads; memory is one
//! block per output whatever the number of trials.

use crate::budget::{EvaluatedAt, PlanVerdict, SpecificationAnswer, SpecificationBudget};
use crate::error::E2eError;
use crate::simulate::{DrawWork, EndToEnd};
use gw_model::spec::{Resolved, Specification};
use metrology::Input;
use metrology::montecarlo::IntervalKind;
use metrology::montecarlo::{self, McOutput, McSettings, Model, Validation};
use std::sync::Mutex;
use tt_kinematics::ScheduleErrorModel;

/// The rule of the Monte Carlo's verdict on a specification, in words.
pub const MC_RULE: &str = "by Monte Carlo (JCGM 101): a specification is met when the probabilistically symmetric coverage interval of its quantity at its coverage probability lies within +-limit (table errors drawn from their laws on the exact chain, noise drawn, the estimator run)";

/// What the Monte Carlo adds to a specification's answer ([`SpecificationMonteCarlo`]).
#[derive(Debug, Clone, PartialEq)]
pub struct MonteCarloDetail {
    output: McOutput,
    validation: Validation,
    limit: f64,
    trials: u64,
    stabilized: bool,
}

/// One specification's Monte Carlo answer, evaluated at its budget's place
/// ([`SpecificationAnswer::at`]).
pub type SpecificationMonteCarlo = SpecificationAnswer<MonteCarloDetail>;

impl SpecificationMonteCarlo {
    /// The quantity's distribution: estimate, $u(y)$, both coverage intervals, the numerical
    /// tolerance (model units).
    #[must_use]
    pub fn output(&self) -> &McOutput {
        &self.detail.output
    }

    /// The GUM interval $0 \pm U$ against the Monte Carlo's symmetric interval (JCGM 101 8.2).
    #[must_use]
    pub fn validation(&self) -> &Validation {
        &self.detail.validation
    }

    /// The specification's limit (model units).
    #[must_use]
    pub fn limit(&self) -> f64 {
        self.detail.limit
    }

    /// The trials of the run that answered this specification.
    #[must_use]
    pub fn trials(&self) -> u64 {
        self.detail.trials
    }

    /// Whether that run stabilized at its numerical tolerance before its trial limit.
    #[must_use]
    pub fn stabilized(&self) -> bool {
        self.detail.stabilized
    }

    /// Whether the symmetric coverage interval lies within $\pm$limit ([`MC_RULE`]).
    #[must_use]
    pub fn meets(&self) -> bool {
        let (lo, hi) = self.detail.output.symmetric();
        lo.abs().max(hi.abs()) <= self.detail.limit
    }
}

/// The quantity of one specification as a function of the table's errors.
#[derive(Debug, Clone)]
enum Quantity {
    /// A linear combination of output `output`'s estimated coefficients' errors.
    Coefficients { offset: usize, weights: Vec<f64> },
    /// Eq 14's error of output `output` at position `position`.
    Accuracy { output: usize, position: usize },
}

/// The measurement model of one run: the table's errors (first `n_errors` components), then
/// two noise components per quantity.
struct CalibrationModel<'a, S: ScheduleErrorModel> {
    e2e: &'a EndToEnd<S>,
    quantities: Vec<Quantity>,
    needs_vectors: bool,
    needs_coefficients: bool,
    /// Scratch spaces, one per thread at a time (taken for a trial, given back after it):
    /// nothing is allocated per trial, and their number is at most the number of threads.
    scratch: Mutex<Vec<Scratch>>,
}

/// One trial's scratch space: the chain's and the least squares', and their results (also
/// one chunk's of the yield counted against the specifications).
pub(crate) struct Scratch {
    work: DrawWork,
    /// Every estimated coefficient's error ([`EndToEnd::coefficient_errors`]).
    pub(crate) coefficients: Vec<f64>,
    /// Every output's error vector ([`EndToEnd::error_vectors`]).
    pub(crate) vectors: Vec<Vec<f64>>,
}

impl Scratch {
    /// Sized for `e2e`.
    pub(crate) fn new<S: ScheduleErrorModel>(e2e: &EndToEnd<S>) -> Self {
        Self {
            work: e2e.work(),
            coefficients: vec![0.0; e2e.n_coefficients()],
            vectors: vec![vec![0.0; e2e.len()]; e2e.n_outputs()],
        }
    }

    /// The coefficients' errors at `chi` into [`Scratch::coefficients`].
    pub(crate) fn coefficients_at<S: ScheduleErrorModel>(
        &mut self,
        e2e: &EndToEnd<S>,
        chi: &[f64],
    ) -> Result<(), E2eError> {
        e2e.coefficient_errors_into(chi, &mut self.work, &mut self.coefficients)
    }

    /// The error vectors at `chi` into [`Scratch::vectors`].
    pub(crate) fn vectors_at<S: ScheduleErrorModel>(
        &mut self,
        e2e: &EndToEnd<S>,
        chi: &[f64],
    ) -> Result<(), E2eError> {
        e2e.error_vectors_into(chi, &mut self.work, &mut self.vectors)
    }
}

impl<S: ScheduleErrorModel> CalibrationModel<'_, S> {
    fn take_scratch(&self) -> Scratch {
        let pooled = self
            .scratch
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner)
            .pop();
        pooled.unwrap_or_else(|| Scratch::new(self.e2e))
    }

    fn give_back(&self, s: Scratch) {
        self.scratch
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner)
            .push(s);
    }
}

impl<S: ScheduleErrorModel + Sync> Model for CalibrationModel<'_, S> {
    fn outputs(&self) -> usize {
        self.quantities.len()
    }

    fn evaluate(&self, x: &[f64], y: &mut [f64]) {
        let n = self.e2e.n_errors();
        let chi = &x[..n];
        let mut s = self.take_scratch();
        // an evaluation failure is a non-finite value: the run stops with a typed error
        let coefficients_ok = self.needs_coefficients && s.coefficients_at(self.e2e, chi).is_ok();
        let vectors_ok = self.needs_vectors && s.vectors_at(self.e2e, chi).is_ok();
        for (q, (yq, noise)) in self
            .quantities
            .iter()
            .zip(y.iter_mut().zip(x[n..].chunks_exact(2)))
        {
            let table = match q {
                Quantity::Coefficients { offset, weights } if coefficients_ok => weights
                    .iter()
                    .zip(&s.coefficients[*offset..])
                    .map(|(w, e)| w * e)
                    .sum(),
                Quantity::Accuracy { output, position } if vectors_ok => {
                    s.vectors[*output][*position]
                }
                _ => f64::NAN,
            };
            *yq = table + noise[0] + noise[1];
        }
        self.give_back(s);
    }
}

impl<S: ScheduleErrorModel + Sync> crate::BudgetQuestions<'_, S> {
    /// The JCGM 101 Monte Carlo of every specification of `verdict` (see the
    /// [module](self)): `specs` and `table` as given to [`crate::BudgetQuestions::plan_verdict`] or
    /// [`crate::BudgetQuestions::specification_budgets`] (one input per angular error, its law), `settings`
    /// the adaptive run's (its coverage is replaced by each specification's).
    ///
    /// # Errors
    /// [`E2eError::Field`] (length) unless one budget per specification and one input per
    /// angular error; [`E2eError::Metrology`] for settings the metrology crate refuses or an
    /// evaluation of the chain that fails (a non-finite value).
    pub fn specification_monte_carlo(
        &self,
        specs: &[Specification],
        verdict: &PlanVerdict,
        table: &[Input],
        settings: &McSettings,
    ) -> Result<Vec<SpecificationMonteCarlo>, E2eError> {
        let budgets = verdict.budgets();
        tt_core::length("budgets", specs.len(), budgets.len())?;
        tt_core::length("table inputs", self.n_errors(), table.len())?;
        let mut coverages: Vec<f64> = specs.iter().map(Specification::coverage).collect();
        coverages.sort_by(f64::total_cmp);
        coverages.dedup();
        let mut answers: Vec<Option<SpecificationMonteCarlo>> = vec![None; specs.len()];
        for p in coverages {
            let members: Vec<usize> = (0..specs.len())
                .filter(|&i| specs[i].coverage().to_bits() == p.to_bits())
                .collect();
            let mut inputs = table.to_vec();
            let mut quantities = Vec::with_capacity(members.len());
            for &i in &members {
                quantities.push(self.quantity(&specs[i], &budgets[i]));
                inputs.extend(noise_inputs(&budgets[i])?);
            }
            let model = CalibrationModel {
                e2e: self,
                needs_vectors: quantities
                    .iter()
                    .any(|q| matches!(q, Quantity::Accuracy { .. })),
                needs_coefficients: quantities
                    .iter()
                    .any(|q| matches!(q, Quantity::Coefficients { .. })),
                quantities,
                scratch: Mutex::new(Vec::new()),
            };
            let run_settings = McSettings {
                coverage: p,
                ..*settings
            };
            let result = montecarlo::run(&inputs, &model, &run_settings)?;
            for (j, &i) in members.iter().enumerate() {
                let output = result.outputs()[j].clone();
                let u = budgets[i].output().expanded();
                let validation = montecarlo::validate(0.0, u, &output, IntervalKind::Symmetric)?;
                answers[i] = Some(SpecificationMonteCarlo {
                    spec: i,
                    at: budgets[i].at(),
                    detail: MonteCarloDetail {
                        output,
                        validation,
                        limit: specs[i].limit(),
                        trials: result.trials(),
                        stabilized: result.stabilized(),
                    },
                });
            }
        }
        Ok(answers.into_iter().flatten().collect())
    }

    /// The quantity of `spec` at its budget's place.
    fn quantity(&self, spec: &Specification, budget: &SpecificationBudget) -> Quantity {
        let k = spec.output();
        let outputs = self.calibration().outputs();
        let offset: usize = outputs[..k].iter().map(|o| o.beta().len()).sum();
        let n_coef = outputs[k].beta().len();
        match (spec.resolved(), budget.at()) {
            (Resolved::Coefficient { index, .. }, _) => {
                let mut weights = vec![0.0; n_coef];
                weights[*index] = 1.0;
                Quantity::Coefficients { offset, weights }
            }
            (Resolved::ErrorOverRange { axis, range }, at) => {
                let positive = !matches!(at, EvaluatedAt::RangeEnd { positive: false });
                let weights =
                    crate::budget::range_end_weights(&outputs[k], *axis as usize, *range, positive);
                Quantity::Coefficients { offset, weights }
            }
            (Resolved::Accuracy, at) => Quantity::Accuracy {
                output: k,
                position: match at {
                    EvaluatedAt::Position(i) => i,
                    _ => 0,
                },
            },
        }
    }
}

/// The two noise inputs of a budget (zero when its output's noise is not modelled): the rows
/// after the table's, each normal with the row's standard uncertainty.
fn noise_inputs(b: &SpecificationBudget) -> Result<[Input; 2], E2eError> {
    let rows = &b.result().rows()[b.table_rows()..];
    let u = |i: usize| rows.get(i).map_or(0.0, |r| r.standard_uncertainty());
    Ok([
        Input::normal("noise, white", 0.0, u(0))?,
        Input::normal("noise, correlated", 0.0, u(1))?,
    ])
}
