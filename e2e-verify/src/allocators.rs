//! The allocations against every output's accuracy as alloc-opt [`Allocator`]s over the
//! end-to-end linearisation ([`Linearization`], a [`LinearErrorModel`] whose quantities are
//! the outputs): [`Direct`], [`DirectCertified`] and [`YieldBased`] return the same
//! [`ToleranceBox`] as alloc-opt's two-step methods, finished by [`alloc_opt::finish`] (its
//! certificate is the worst case of every output over the schedule's positions).
//!
//! The problem's limits are what the table may use of each accuracy: the accuracies
//! themselves ([`EndToEnd::allocation_problem`]), or less, for instance the accuracy less the
//! noise part at $k\sigma$ ([`crate::noise`]), the rest being kept free.
//!
//! # Example
//! ```
//! use alloc_opt::Allocator;
//! use calib_lsq::{Calibration, Reading};
//! use e2e_verify::{Direct, DirectCertified, EndToEnd};
//! use tt_kinematics::{Pose, paper};
//!
//! let table = paper::table3();
//! let cal = Calibration::new(&gw_model::paper::gyrowheel(), &gw_model::paper::site(), &calib_lsq::paper::schedule())?;
//! let poses: Vec<Pose> = cal.schedule().positions().iter().map(|p| Pose::from_deg(p.joint_angles_deg())).collect::<Result<_, _>>()?;
//! let e2e = EndToEnd::new(&table, &cal, &poses, Reading::USER)?;
//! let problem = e2e.allocation_problem(e2e.linearization(), vec![0.0; 8])?;
//! for method in [&Direct::new(&e2e) as &dyn Allocator<_>, &DirectCertified::new(&e2e)] {
//!     let tolerances = method.allocate(&problem)?;
//!     // every output's worst case over the schedule within its accuracy (first order)
//!     assert!(tolerances.certificate().lemma1_holds());
//! }
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

use crate::allocate::{CertifyParams, DirectAllocation, YieldParams};
use crate::budget::SpecificationRow;
use crate::error::E2eError;
use crate::linear::Linearization;
use crate::montecarlo::McSettings;
use crate::simulate::EndToEnd;
use alloc_opt::{
    AllocError, AllocationProblem, Allocator, LinearErrorModel, MethodDetails, ToleranceBox,
    Weights, finish,
};
use nalgebra::DMatrix;
use tt_core::ErrorClass;
use tt_kinematics::ScheduleErrorModel;

/// The direct allocation ([`EndToEnd::allocate_direct`]) as an [`Allocator`]: the least
/// costly box (the paper's combined weights) whose linearised worst case of every output at
/// every position is within the problem's limit.
#[derive(Debug, Clone, Copy)]
pub struct Direct<'a, S> {
    analysis: &'a EndToEnd<S>,
}

impl<'a, S> Direct<'a, S> {
    /// The direct allocation of `analysis` (its combined weights, its outputs).
    #[must_use]
    pub fn new(analysis: &'a EndToEnd<S>) -> Self {
        Self { analysis }
    }
}

/// The certified direct allocation ([`EndToEnd::allocate_direct_certified_with`]) as an
/// [`Allocator`]: every turntable of the box meets every limit on the exact chain, the
/// derived second-order bound kept free ([`MethodDetails::Joint`]'s margins).
#[derive(Debug, Clone, Copy)]
pub struct DirectCertified<'a, S> {
    analysis: &'a EndToEnd<S>,
    params: CertifyParams,
}

impl<'a, S> DirectCertified<'a, S> {
    /// The certified direct allocation of `analysis` with the default search.
    #[must_use]
    pub fn new(analysis: &'a EndToEnd<S>) -> Self {
        Self::with_params(analysis, CertifyParams::default())
    }

    /// With its search tuned by `params`.
    #[must_use]
    pub(crate) fn with_params(analysis: &'a EndToEnd<S>, params: CertifyParams) -> Self {
        Self { analysis, params }
    }
}

/// The yield-based allocation ([`EndToEnd::allocate_yield_with`]) as an [`Allocator`]: the
/// direct allocation's shape scaled until the target fraction of turntables drawn in the box
/// meets every accuracy on the exact chain. Its certificate may exceed a limit (the worst
/// turntable is allowed to, a fraction of them is not); [`MethodDetails::Scaled`] states the
/// yield and its interval. The limits must be the accuracies themselves. With
/// specifications ([`YieldBased::with_specifications`]) the shape is the specified direct
/// allocation and a draw meets when every accuracy and every specification holds
/// ([`EndToEnd::allocate_yield_specified`]).
#[derive(Debug, Clone, Copy)]
pub struct YieldBased<'a, S> {
    analysis: &'a EndToEnd<S>,
    target: f64,
    settings: McSettings,
    params: YieldParams,
    spec_rows: &'a [SpecificationRow],
}

impl<'a, S> YieldBased<'a, S> {
    /// The yield-based allocation of `analysis` for the fraction `target` with the design
    /// draws `settings` (checked when allocating).
    #[must_use]
    pub fn new(analysis: &'a EndToEnd<S>, target: f64, settings: McSettings) -> Self {
        Self::with_params(analysis, target, settings, YieldParams::default())
    }

    /// With its scale search tuned by `params`.
    #[must_use]
    pub(crate) fn with_params(
        analysis: &'a EndToEnd<S>,
        target: f64,
        settings: McSettings,
        params: YieldParams,
    ) -> Self {
        Self {
            analysis,
            target,
            settings,
            params,
            spec_rows: &[],
        }
    }

    /// Counting the specification rows `spec_rows` too
    /// ([`crate::BudgetQuestions::specification_rows`]).
    #[must_use]
    pub fn with_specifications(self, spec_rows: &'a [SpecificationRow]) -> Self {
        Self { spec_rows, ..self }
    }
}

impl<S: ScheduleErrorModel + Sync> EndToEnd<S> {
    /// The allocation problem against every output's accuracy: `linear`'s outputs as the
    /// quantities (normally [`EndToEnd::linearization`]), the accuracies as their limits, and
    /// one lower bound per error (rad). For [`Direct`], [`DirectCertified`], [`YieldBased`]
    /// and any outside [`Allocator`] over a [`Linearization`].
    ///
    /// # Errors
    /// [`E2eError::Field`] (wrong length) naming `linearization` for a linearisation of other
    /// outputs, positions or errors; as [`AllocationProblem::with_limits`] for the lower
    /// bounds.
    pub fn allocation_problem(
        &self,
        linear: Linearization,
        lower_bounds_rad: Vec<f64>,
    ) -> Result<AllocationProblem<Linearization>, E2eError> {
        self.check_linearization(&linear)?;
        let limits = self.accuracies().into_iter().map(Some).collect();
        Ok(AllocationProblem::with_limits(
            linear,
            limits,
            lower_bounds_rad,
        )?)
    }

    fn check_linearization(&self, linear: &Linearization) -> Result<(), E2eError> {
        tt_core::length(
            "linearization (outputs)",
            self.n_outputs(),
            linear.outputs(),
        )?;
        tt_core::length("linearization (positions)", self.len(), linear.positions())?;
        tt_core::length(
            "linearization (errors)",
            self.n_errors(),
            linear.matrix().ncols(),
        )?;
        Ok(())
    }

    /// Per output, the part of its accuracy the problem keeps free: accuracy less limit.
    fn margins_of(&self, problem: &AllocationProblem<Linearization>) -> Result<Vec<f64>, E2eError> {
        self.check_linearization(problem.model())?;
        let names = self.output_names();
        self.accuracies()
            .iter()
            .zip(problem.limits())
            .zip(&names)
            .map(|((acc, limit), name)| match limit {
                Some(l) if *l <= *acc => Ok(acc - l),
                other => Err(E2eError::Field(tt_core::FieldError::OutOfRange {
                    field: format!("limits.{name}"),
                    value: other.unwrap_or(f64::INFINITY),
                    range: format!("(0, {acc:e}], the output's accuracy"),
                })),
            })
            .collect()
    }

    /// alloc-opt's [`Weights`] whose combined weights are this analysis's
    /// ([`EndToEnd::combined_weights`]): $W_{kj} = w_j/\sqrt{q_j}$ for each of the $q_j$
    /// outputs error $j$ is involved in, so $\sum_k W_{kj}^2 = w_j^2$ and alloc-opt's $J$ is
    /// this crate's (up to rounding).
    fn weights_for(&self, model: &Linearization) -> Result<Weights, AllocError> {
        let w = self.combined_weights();
        let q = model.n_quantities();
        let involved: Vec<Vec<usize>> = (0..q).map(|k| model.involved(k)).collect();
        let mut m = DMatrix::zeros(q, model.n_errors());
        for (j, wj) in w.iter().enumerate() {
            let count = involved.iter().filter(|inv| inv.contains(&j)).count();
            for (k, inv) in involved.iter().enumerate() {
                if inv.contains(&j) {
                    m[(k, j)] = wj / (count as f64).sqrt();
                }
            }
        }
        Weights::new(model, m)
    }

    /// A joint (direct) allocation of `problem` by `method`: `run` gets the problem's margins
    /// (accuracy less limit, per output) and returns the allocation, which alloc-opt's
    /// [`finish`] turns into the one [`ToleranceBox`].
    fn joint(
        &self,
        problem: &AllocationProblem<Linearization>,
        method: &str,
        run: impl FnOnce(&[f64]) -> Result<DirectAllocation, E2eError>,
    ) -> Result<ToleranceBox, AllocError> {
        let d = self
            .margins_of(problem)
            .and_then(|margins| run(&margins))
            .map_err(|e| method_error(method, e))?;
        finish(
            problem,
            method,
            self.weights_for(problem.model())?,
            d.upper_bounds_rad,
            MethodDetails::Joint {
                margins: d.second_order_margins,
                multiplier: d.multiplier,
                iterations: d.iterations,
            },
        )
    }
}

/// An [`E2eError`] as alloc-opt's error: the allocation core's own errors as they are, the
/// others as [`AllocError::Method`] keeping their message and input field.
fn method_error(method: &str, e: E2eError) -> AllocError {
    match e {
        E2eError::Alloc(a) => a,
        other => AllocError::Method {
            method: method.to_string(),
            message: other.to_string(),
            input_field: other.input_field().map(str::to_string),
        },
    }
}

impl<S: ScheduleErrorModel + Sync> Allocator<Linearization> for Direct<'_, S> {
    fn name(&self) -> &str {
        "direct"
    }

    fn allocate(
        &self,
        problem: &AllocationProblem<Linearization>,
    ) -> Result<ToleranceBox, AllocError> {
        self.analysis.joint(problem, self.name(), |margins| {
            self.analysis.allocate_direct_keeping(
                problem.model(),
                problem.lower_bounds_rad(),
                margins,
            )
        })
    }
}

impl<S: ScheduleErrorModel + Sync> Allocator<Linearization> for DirectCertified<'_, S> {
    fn name(&self) -> &str {
        "direct-certified"
    }

    fn allocate(
        &self,
        problem: &AllocationProblem<Linearization>,
    ) -> Result<ToleranceBox, AllocError> {
        self.analysis.joint(problem, self.name(), |margins| {
            self.analysis.certified_keeping(
                problem.model(),
                problem.lower_bounds_rad(),
                margins,
                &self.params,
            )
        })
    }
}

impl<S: ScheduleErrorModel + Sync> Allocator<Linearization> for YieldBased<'_, S> {
    fn name(&self) -> &str {
        "yield-based"
    }

    fn allocate(
        &self,
        problem: &AllocationProblem<Linearization>,
    ) -> Result<ToleranceBox, AllocError> {
        let a = self.analysis;
        let run = || -> Result<_, E2eError> {
            let margins = a.margins_of(problem)?;
            if let Some(k) = margins.iter().position(|&m| m != 0.0) {
                return Err(E2eError::Field(tt_core::FieldError::OutOfRange {
                    field: format!("limits.{}", a.output_names()[k]),
                    value: problem.limits()[k].unwrap_or(f64::NAN),
                    range: "the output's accuracy itself (the yield counts against it)".into(),
                }));
            }
            let lb = problem.lower_bounds_rad();
            let shape = if self.spec_rows.is_empty() {
                a.allocate_direct_keeping(problem.model(), lb, &margins)?
            } else {
                a.allocate_direct_specified(problem.model(), lb, self.spec_rows)?
            };
            a.allocate_yield_specified(
                &shape.upper_bounds_rad,
                lb,
                self.target,
                &self.settings,
                &self.params,
                self.spec_rows,
            )
        };
        let y = run().map_err(|e| method_error(self.name(), e))?;
        finish(
            problem,
            self.name(),
            a.weights_for(problem.model())?,
            y.upper_bounds_rad,
            MethodDetails::Scaled {
                shape_rad: y.shape_rad,
                scale: y.scale,
                target: y.target,
                samples: y.counted.count.samples(),
                meeting: y.counted.count.meeting(),
                interval_95: y.counted.count.interval_95(),
                capped: y.capped,
            },
        )
    }
}
