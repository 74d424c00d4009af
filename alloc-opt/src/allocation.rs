//! The [`Allocator`] seam, its one result [`ToleranceBox`], the public finishing step
//! [`finish`] and the Lemma 1 [`Certificate`].

use crate::error::{AllocError, finite_result, length};
use crate::model::{LinearErrorModel, WorstRow};
use crate::problem::{AllocationProblem, Weights};
use crate::solver::{Cut, CutOracle};
use tt_core::units::RAD_PER_ARCMIN;
use tt_kinematics::{CERTIFY_REL_GAP, LinearModel, OrientationAxis};

/// A requirement counts as active (tight) when the worst case uses at least
/// $1 - 10^{-9}$ of it (relative; the exchange method ends within $10^{-13}$). Applies when
/// the worst-case search is exact (at most one free joint).
pub const TIGHT_REL: f64 = 1e-9;

/// For a table with two or more free joints, where the worst case is searched and bounded
/// rigorously, a requirement counts as active when the rigorous upper bound reaches at least
/// $1 - 10^{-8}$ of it: the bounds were made safe against that bound (which they then exceed
/// by $2\times$ [`CERTIFY_REL_GAP`] at most), so no bound can grow without it exceeding the
/// requirement. The worst case found may be lower by the bound's gap (see [`Certificate`]).
pub const SEARCHED_TIGHT_REL: f64 = 1e-8;

/// A requirement counts as satisfied when the rigorous upper bound of the worst case exceeds
/// it by at most this (relative): the rounding of the worst-case evaluation, a few ulp.
pub const SATISFIED_REL: f64 = 1e-12;

/// An upper bound counts as sitting at its positive lower bound within this relative
/// distance (the solver's own threshold).
const AT_LOWER_REL: f64 = 1e-7;

/// Rounds of the safety rescaling of [`Allocation`] bounds against the rigorous bound (one
/// suffices unless the branch and bound hits its evaluation limit).
const SAFETY_ROUNDS: usize = 8;

/// Turns an [`AllocationProblem`] over a [`LinearErrorModel`] `M` into a [`ToleranceBox`]
/// with a certificate. The methods of this crate implement it for every model; an outside
/// method implements it too and ends with [`finish`].
///
/// # Example
/// ```
/// use alloc_opt::{Allocator, EqualEffects, SensitivityWeighted, paper};
/// let problem = paper::example_problem()?;
/// for allocator in [&SensitivityWeighted::paper() as &dyn Allocator, &EqualEffects] {
///     let a = allocator.allocate(&problem)?;
///     assert!(a.certificate().lemma1_holds());
/// }
/// # Ok::<(), alloc_opt::AllocError>(())
/// ```
pub trait Allocator<M: LinearErrorModel = LinearModel> {
    /// A short name of the method (`"sensitivity-weighted"`, `"equal-effects"`).
    fn name(&self) -> &str;

    /// Allocate the upper bounds.
    ///
    /// # Errors
    /// [`AllocError`] naming the problem and errors when the lower bounds are infeasible,
    /// when the method does not apply to the model, or when a solver fails.
    fn allocate(&self, problem: &AllocationProblem<M>) -> Result<ToleranceBox, AllocError>;
}

/// The solution of one per-quantity problem ((31) $\gamma$, (32) $\theta$, (33) $\psi$ for
/// the paper's table).
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct Subproblem {
    /// The quantity (problem) concerned: its index in the model.
    pub(crate) quantity: usize,
    /// Its name (`gamma`, ...).
    pub(crate) name: String,
    /// Its errors (indices into $\chi$; $\chi_\gamma$, $\chi_\theta$, $\chi_\psi$ of eq 27).
    pub(crate) components: Vec<usize>,
    /// The optimal $\chi_k^*$ (rad), one per component.
    pub(crate) bounds_rad: Vec<f64>,
    /// $J_k(\chi_k^*)$ (rad$^{-2}$); `None` for the equal-effects allocator.
    pub(crate) objective: Option<f64>,
    /// A point of the domain (a pose, rad, every joint) where the constraint is tight.
    pub(crate) worst_pose_rad: Vec<f64>,
    /// The constraint's load at the optimum (1 = the whole requirement used).
    pub(crate) load: f64,
    /// The requirement's Lagrange multiplier (units of $J$); `None` when not computed.
    pub(crate) multiplier: Option<f64>,
    /// Conic solves done by the exchange method (0 when none was needed).
    pub(crate) iterations: usize,
    /// Whether the worst-case oracle of this problem is exact (at most one free joint).
    pub(crate) exact_oracle: bool,
}

/// Read access to the fields (crate-private, so the type can grow without breaking callers).
impl Subproblem {
    /// The quantity (problem) concerned: its index in the model.
    #[must_use]
    pub fn quantity(&self) -> usize {
        self.quantity
    }

    /// Its name (`gamma`, ...).
    #[must_use]
    pub fn name(&self) -> &str {
        &self.name
    }

    /// Its errors (indices into $\chi$; $\chi_\gamma$, $\chi_\theta$, $\chi_\psi$ of eq 27).
    #[must_use]
    pub fn components(&self) -> &[usize] {
        &self.components
    }

    /// The optimal $\chi_k^*$ (rad), one per component.
    #[must_use]
    pub fn bounds_rad(&self) -> &[f64] {
        &self.bounds_rad
    }

    /// $J_k(\chi_k^*)$ (rad$^{-2}$); `None` for the equal-effects allocator.
    #[must_use]
    pub fn objective(&self) -> Option<f64> {
        self.objective
    }

    /// A point of the domain (a pose, rad, every joint) where the constraint is tight.
    #[must_use]
    pub fn worst_pose_rad(&self) -> &[f64] {
        &self.worst_pose_rad
    }

    /// The constraint's load at the optimum (1 = the whole requirement used).
    #[must_use]
    pub fn load(&self) -> f64 {
        self.load
    }

    /// The requirement's Lagrange multiplier (units of $J$); `None` when not computed.
    #[must_use]
    pub fn multiplier(&self) -> Option<f64> {
        self.multiplier
    }

    /// Conic solves done by the exchange method (0 when none was needed).
    #[must_use]
    pub fn iterations(&self) -> usize {
        self.iterations
    }

    /// Whether the worst-case oracle of this problem is exact (at most one free joint).
    #[must_use]
    pub fn exact_oracle(&self) -> bool {
        self.exact_oracle
    }
}

impl Subproblem {
    /// The angle of the problem, for a model whose quantities are the three angles
    /// ($\psi, \theta, \gamma$ in that order); `None` for another quantity index.
    #[must_use]
    pub fn axis(&self) -> Option<OrientationAxis> {
        OrientationAxis::ALL.get(self.quantity).copied()
    }
}

/// The certificate of one quantity: the worst case over the model's domain (all poses in
/// the joint ranges) and all admissible errors.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct AxisCertificate {
    /// The quantity's index in the model (for a turntable: [`OrientationAxis::index`]).
    pub(crate) quantity: usize,
    /// Its name (`psi`, `theta`, `gamma` for a turntable).
    pub(crate) name: String,
    /// $I_k$ (rad); `None` when the quantity carries no requirement.
    pub(crate) requirement_rad: Option<f64>,
    /// The largest worst case found,
    /// $\max_{\phi} \max_{\mathrm{LB} \le |\chi| \le \mathrm{UB}} |f_k(\phi,\chi)|
    /// = \max_{\phi} \sum_i \mathrm{UB}_i |c_{ki}(\phi)|$ (rad), over the errors with a
    /// finite bound. Exact when [`AxisCertificate::exact`].
    pub(crate) worst_case_rad: f64,
    /// A point where it is reached (for a turntable a pose, rad, every joint; joints that
    /// cancel sit at the lower end of their range).
    pub(crate) worst_pose_rad: Vec<f64>,
    /// A rigorous upper bound on the worst case (rad): equal to `worst_case_rad` when exact,
    /// the branch-and-bound bound of [`LinearModel::worst_pose_certified`] otherwise.
    pub(crate) upper_bound_rad: f64,
    /// Whether the worst case is exact (at most one free joint).
    pub(crate) exact: bool,
    /// `worst_case_rad / requirement_rad`: the share of the requirement used (`None` without
    /// a requirement).
    pub(crate) share: Option<f64>,
    /// The requirement is active: share $\ge 1 -$ [`TIGHT_REL`] when exact; when searched,
    /// `upper_bound_rad` $\ge (1 -$ [`SEARCHED_TIGHT_REL`]$)\,I_k$.
    pub(crate) requirement_active: bool,
    /// The requirement holds (Lemma 1 for this quantity): `upper_bound_rad` $\le (1 +$
    /// [`SATISFIED_REL`]$)\,I_k$; true for a quantity without a requirement.
    pub(crate) satisfied: bool,
    /// Involved errors (indices) whose upper bound equals their positive lower bound.
    pub(crate) active_lower_bounds: Vec<usize>,
    /// Involved errors (indices) with an infinite upper bound (only for a quantity without a
    /// requirement): its true worst case is then unbounded, and the numbers above are
    /// those of the bounded errors.
    pub(crate) unbounded: Vec<usize>,
}

/// Read access to the fields (crate-private, so the type can grow without breaking callers).
impl AxisCertificate {
    /// The quantity's index in the model (for a turntable: [`OrientationAxis::index`]).
    #[must_use]
    pub fn quantity(&self) -> usize {
        self.quantity
    }

    /// Its name (`psi`, `theta`, `gamma` for a turntable).
    #[must_use]
    pub fn name(&self) -> &str {
        &self.name
    }

    /// $I_k$ (rad); `None` when the quantity carries no requirement.
    #[must_use]
    pub fn requirement_rad(&self) -> Option<f64> {
        self.requirement_rad
    }

    /// The largest worst case found,
    /// $\max_{\phi} \max_{\mathrm{LB} \le |\chi| \le \mathrm{UB}} |f_k(\phi,\chi)|
    /// = \max_{\phi} \sum_i \mathrm{UB}_i |c_{ki}(\phi)|$ (rad), over the errors with a
    /// finite bound. Exact when [`AxisCertificate::exact`].
    #[must_use]
    pub fn worst_case_rad(&self) -> f64 {
        self.worst_case_rad
    }

    /// A point where it is reached (for a turntable a pose, rad, every joint; joints that
    /// cancel sit at the lower end of their range).
    #[must_use]
    pub fn worst_pose_rad(&self) -> &[f64] {
        &self.worst_pose_rad
    }

    /// A rigorous upper bound on the worst case (rad): equal to `worst_case_rad` when exact,
    /// the branch-and-bound bound of [`LinearModel::worst_pose_certified`] otherwise.
    #[must_use]
    pub fn upper_bound_rad(&self) -> f64 {
        self.upper_bound_rad
    }

    /// Whether the worst case is exact (at most one free joint).
    #[must_use]
    pub fn exact(&self) -> bool {
        self.exact
    }

    /// `worst_case_rad / requirement_rad`: the share of the requirement used (`None` without
    /// a requirement).
    #[must_use]
    pub fn share(&self) -> Option<f64> {
        self.share
    }

    /// The requirement is active: share $\ge 1 -$ [`TIGHT_REL`] when exact; when searched,
    /// `upper_bound_rad` $\ge (1 -$ [`SEARCHED_TIGHT_REL`]$)\,I_k$.
    #[must_use]
    pub fn requirement_active(&self) -> bool {
        self.requirement_active
    }

    /// The requirement holds (Lemma 1 for this quantity): `upper_bound_rad` $\le (1 +$
    /// [`SATISFIED_REL`]$)\,I_k$; true for a quantity without a requirement.
    #[must_use]
    pub fn satisfied(&self) -> bool {
        self.satisfied
    }

    /// Involved errors (indices) whose upper bound equals their positive lower bound.
    #[must_use]
    pub fn active_lower_bounds(&self) -> &[usize] {
        &self.active_lower_bounds
    }

    /// Involved errors (indices) with an infinite upper bound (only for a quantity without a
    /// requirement): its true worst case is then unbounded, and the numbers above are
    /// those of the bounded errors.
    #[must_use]
    pub fn unbounded(&self) -> &[usize] {
        &self.unbounded
    }
}

/// Lemma 1's certificate for every quantity of the model (the three angles of a turntable).
///
/// # What is guaranteed
/// - At most one free joint (the paper's table, any two-axis table whose outer joint comes
///   first): the worst case over the joint ranges is found exactly
///   ([`LinearModel::max_abs_weighted`] solves the one-dimensional problem piece by piece), so
///   `satisfied` is Lemma 1 itself for the linear model.
/// - Two or more free joints: the worst case is searched (grid and refinement over the outer
///   free joints, exact in the last one) and bounded rigorously by branch and bound with a
///   second-order cell bound ([`LinearModel::worst_pose_certified`], relative gap
///   [`CERTIFY_REL_GAP`] $= 10^{-9}$, reached on the three-axis example). `satisfied` uses the rigorous bound, so it
///   is still Lemma 1 for the linear model; the allocators shrink the bounds until it holds,
///   giving away the bound's gap (plus $2\times10^{-9}$) of the requirement.
/// - Any other [`LinearErrorModel`]: what its [`LinearErrorModel::worst_case`] proves.
/// - Neither covers the second-order terms of the exact chain: see
///   [`crate::exact_chain_check`].
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct Certificate {
    /// One per quantity, in the model's order ($\psi, \theta, \gamma$ for a turntable).
    pub(crate) axes: Vec<AxisCertificate>,
}

/// Read access to the fields (crate-private, so the type can grow without breaking callers).
impl Certificate {
    /// One per quantity, in the model's order ($\psi, \theta, \gamma$ for a turntable).
    #[must_use]
    pub fn axes(&self) -> &[AxisCertificate] {
        &self.axes
    }
}

impl Certificate {
    /// The worst cases of `ub_rad` on `model` over its domain (the turntable's joint ranges)
    /// against `limits` (one per quantity, rad, `None` for no requirement).
    ///
    /// # Formula
    /// $$\max_{\phi}\sum_i \mathrm{UB}_i\,|c_{ki}(\phi)|,$$ the signs of $\chi$ chosen
    /// adversarially (the lower bounds do not lower the maximum), found by
    /// [`LinearErrorModel::worst_case`] ([`LinearModel::worst_pose_certified`] for a
    /// turntable).
    ///
    /// # Errors
    /// [`AllocError::Field`] (wrong length) for vectors of the wrong length; [`AllocError::Field`] (not finite) or
    /// [`AllocError::Field`] (negative) naming `upper_bounds.<error name>` for a bound that is NaN,
    /// negative, or infinite on a quantity with a requirement.
    ///
    /// # Reference
    /// Zhao et al. 2017, Lemma 1 and eq 30.
    pub fn compute<M: LinearErrorModel + ?Sized>(
        model: &M,
        limits: &[Option<f64>],
        lower_bounds_rad: &[f64],
        ub_rad: &[f64],
    ) -> Result<Self, AllocError> {
        let n = model.n_errors();
        length("limits", model.n_quantities(), limits.len())?;
        length("lower_bounds", n, lower_bounds_rad.len())?;
        length("upper_bounds", n, ub_rad.len())?;
        let names: Vec<String> = (0..n).map(|j| model.error_name(j)).collect();
        for (name, &u) in names.iter().zip(ub_rad) {
            if u.is_nan() {
                return Err(tt_core::FieldError::NonFinite {
                    field: format!("upper_bounds.{name}"),
                    value: u,
                }
                .into());
            }
            if u < 0.0 {
                return Err(tt_core::FieldError::Negative {
                    field: format!("upper_bounds.{name}"),
                    value: u,
                }
                .into());
            }
        }
        let mut axes = Vec::with_capacity(limits.len());
        for (k, &limit) in limits.iter().enumerate() {
            let involved = model.involved(k);
            let mut w = vec![0.0; n];
            let mut unbounded = Vec::new();
            for &i in &involved {
                if ub_rad[i].is_finite() {
                    w[i] = ub_rad[i];
                } else if limit.is_some() {
                    return Err(tt_core::FieldError::NonFinite {
                        field: format!("upper_bounds.{}", names[i]),
                        value: ub_rad[i],
                    }
                    .into());
                } else {
                    unbounded.push(i);
                }
            }
            let worst = model.worst_case(k, &w)?;
            let active_lower_bounds = involved
                .iter()
                .copied()
                .filter(|&i| {
                    let lb = lower_bounds_rad[i];
                    lb > 0.0 && ub_rad[i] <= lb * (1.0 + AT_LOWER_REL)
                })
                .collect();
            axes.push(AxisCertificate::new(
                k,
                model.quantity_name(k),
                limit,
                worst,
                active_lower_bounds,
                unbounded,
            ));
        }
        Ok(Self { axes })
    }

    /// The certificate of one angle (a model whose quantities are the three angles).
    ///
    /// # Panics
    /// When the model has fewer quantities than `axis.index() + 1`.
    #[must_use]
    pub fn get(&self, axis: OrientationAxis) -> &AxisCertificate {
        &self.axes[axis.index()]
    }

    /// The certificate of quantity `k`, if there is one.
    #[must_use]
    pub fn quantity(&self, k: usize) -> Option<&AxisCertificate> {
        self.axes.get(k)
    }

    /// Lemma 1: every quantity's rigorous worst-case bound is within its requirement.
    #[must_use]
    pub fn lemma1_holds(&self) -> bool {
        self.axes.iter().all(|a| a.satisfied)
    }

    /// Whether every worst case is exact (at most one free joint).
    #[must_use]
    pub fn exact(&self) -> bool {
        self.axes.iter().all(|a| a.exact)
    }
}

impl AxisCertificate {
    /// The angle, for a model whose quantities are the three angles ($\psi, \theta,
    /// \gamma$ in that order); `None` for another quantity index.
    #[must_use]
    pub fn axis(&self) -> Option<OrientationAxis> {
        OrientationAxis::ALL.get(self.quantity).copied()
    }

    fn new(
        quantity: usize,
        name: String,
        requirement_rad: Option<f64>,
        worst: WorstRow,
        active_lower_bounds: Vec<usize>,
        unbounded: Vec<usize>,
    ) -> Self {
        let share = requirement_rad.map(|i| worst.value / i);
        let requirement_active = requirement_rad.is_some_and(|i| {
            if worst.exact {
                worst.value >= i * (1.0 - TIGHT_REL)
            } else {
                worst.upper_bound >= i * (1.0 - SEARCHED_TIGHT_REL)
            }
        });
        Self {
            quantity,
            name,
            requirement_rad,
            worst_case_rad: worst.value,
            worst_pose_rad: worst.point,
            upper_bound_rad: worst.upper_bound,
            exact: worst.exact,
            share,
            requirement_active,
            satisfied: requirement_rad
                .is_none_or(|i| worst.upper_bound <= i * (1.0 + SATISFIED_REL)),
            active_lower_bounds,
            unbounded,
        }
    }

    /// Check every number (no NaN or infinity may reach an allocation).
    fn check_finite(&self) -> Result<(), AllocError> {
        let what = |field: &str| {
            let q = self.name.clone();
            let field = field.to_string();
            move || format!("certificate.{q}.{field}")
        };
        finite_result(what("worst_case_rad"), self.worst_case_rad)?;
        finite_result(what("upper_bound_rad"), self.upper_bound_rad)?;
        for &p in &self.worst_pose_rad {
            finite_result(what("worst_pose_rad"), p)?;
        }
        if let Some(s) = self.share {
            finite_result(what("share"), s)?;
        }
        Ok(())
    }
}

/// What a method adds to its [`ToleranceBox`].
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize),
    serde(rename_all = "snake_case")
)]
pub enum MethodDetails {
    /// Per-quantity problems combined by rule (34) (sensitivity-weighted, equal effects).
    TwoStep {
        /// The per-quantity problems, in the order solved (quantities with a requirement and
        /// at least one involved error).
        subproblems: Vec<Subproblem>,
    },
    /// One problem over every quantity at once, each quantity held to its limit less a
    /// margin (the direct allocation against every output's accuracy, e2e-verify's
    /// `Direct` and `DirectCertified`).
    Joint {
        /// Per quantity, the part of its limit kept free besides it (the quantity's unit; the
        /// certified method's second-order bound $\tau_k$, 0 for the plain method).
        margins: Vec<f64>,
        /// Sum of the Lagrange multipliers of the rows (units of $J$).
        multiplier: f64,
        /// Conic solves of the exchange method.
        iterations: usize,
    },
    /// A shape scaled until a target fraction of boxes drawn in it meets every limit on the
    /// exact model (the yield-based allocation, e2e-verify's `YieldBased`). Its certificate
    /// may exceed a limit: the worst case is allowed to, a fraction of draws is not.
    Scaled {
        /// The shape (rad, the model's error order).
        shape_rad: Vec<f64>,
        /// The scale $s^*$ applied to it.
        scale: f64,
        /// The target fraction $p$.
        target: f64,
        /// Draws of the design Monte Carlo.
        samples: u64,
        /// Draws meeting every limit at $s^*$.
        meeting: u64,
        /// The 95% Wilson interval of the yield at $s^*$.
        interval_95: (f64, f64),
        /// The target is met even at the largest scale searched: the limits do not constrain
        /// the errors, and the bounds are that cap.
        capped: bool,
    },
    /// A method defined outside this crate, with its own description.
    External {
        /// Free text (for printing).
        description: String,
    },
}

/// The one result of every [`Allocator`]: upper bounds $\mathrm{UB}_i$ with their
/// objective, certificate and the method's details. (Formerly `Allocation`, which remains
/// as an alias.) Read it through the accessors (the fields are private). With the `serde` feature it derives `Serialize` (radians,
/// as the fields; serde_json writes an unconstrained error's `+inf` bound as `null`).
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct ToleranceBox {
    /// The allocator's name.
    pub(crate) method: String,
    /// The names of the errors (the model's order).
    pub(crate) error_names: Vec<String>,
    /// $\mathrm{UB}_i$ (rad, the model's error order); `+inf` exactly for the errors in
    /// [`ToleranceBox::unconstrained`], finite otherwise.
    pub(crate) upper_bounds_rad: Vec<f64>,
    /// The lower bounds used (rad).
    pub(crate) lower_bounds_rad: Vec<f64>,
    /// The limit of each quantity used (rad; `None`: no requirement).
    pub(crate) limits: Vec<Option<f64>>,
    /// $J(\mathrm{UB}) = \sum_k J_k$ (rad$^{-2}$) under [`ToleranceBox::weights`]
    /// (unconstrained errors contribute 0).
    pub(crate) objective: f64,
    /// The weights the objective is computed with (the paper's inverse average sensitivities
    /// unless the allocator was given others).
    pub(crate) weights: Weights,
    /// Worst cases over the model's domain (Lemma 1).
    pub(crate) certificate: Certificate,
    /// Errors (indices) that no quantity with a requirement depends on: their bound is `+inf`.
    pub(crate) unconstrained: Vec<usize>,
    /// Per quantity, the factor by which the free bounds of its errors were shrunk after the
    /// combination (34) so that the rigorous worst-case bound is within the requirement (an
    /// error shared by several such quantities is shrunk by the smallest of their factors);
    /// 1 when the worst case is exact.
    pub(crate) safety_scale: Vec<f64>,
    /// What the method adds.
    pub(crate) details: MethodDetails,
}

/// The former name of [`ToleranceBox`].
pub type Allocation = ToleranceBox;

impl ToleranceBox {
    /// The allocator's name.
    #[must_use]
    pub fn method(&self) -> &str {
        &self.method
    }

    /// The names of the errors (the model's order).
    #[must_use]
    pub fn error_names(&self) -> &[String] {
        &self.error_names
    }

    /// $\mathrm{UB}_i$ (rad); `+inf` exactly for the unconstrained errors.
    #[must_use]
    pub fn upper_bounds_rad(&self) -> &[f64] {
        &self.upper_bounds_rad
    }

    /// The lower bounds used (rad).
    #[must_use]
    pub fn lower_bounds_rad(&self) -> &[f64] {
        &self.lower_bounds_rad
    }

    /// The limit of each quantity used (rad).
    #[must_use]
    pub fn limits(&self) -> &[Option<f64>] {
        &self.limits
    }

    /// $J$ (rad$^{-2}$).
    #[must_use]
    pub fn objective(&self) -> f64 {
        self.objective
    }

    /// The weights of the objective.
    #[must_use]
    pub fn weights(&self) -> &Weights {
        &self.weights
    }

    /// The certificate (Lemma 1).
    #[must_use]
    pub fn certificate(&self) -> &Certificate {
        &self.certificate
    }

    /// The errors without a bound (indices).
    #[must_use]
    pub fn unconstrained(&self) -> &[usize] {
        &self.unconstrained
    }

    /// The safety factors, one per quantity.
    #[must_use]
    pub fn safety_scale(&self) -> &[f64] {
        &self.safety_scale
    }

    /// What the method adds.
    #[must_use]
    pub fn details(&self) -> &MethodDetails {
        &self.details
    }

    /// The per-quantity problems of a two-step method (empty for other methods).
    #[must_use]
    pub fn subproblems(&self) -> &[Subproblem] {
        match &self.details {
            MethodDetails::TwoStep { subproblems } => subproblems,
            MethodDetails::Joint { .. }
            | MethodDetails::Scaled { .. }
            | MethodDetails::External { .. } => &[],
        }
    }

    /// $\mathrm{UB}_i$ in arcminutes (for printing).
    #[must_use]
    pub fn upper_bounds_arcmin(&self) -> Vec<f64> {
        self.upper_bounds_rad
            .iter()
            .map(|v| v / RAD_PER_ARCMIN)
            .collect()
    }

    /// The upper bound of the error called `name` (rad), if there is one.
    #[must_use]
    pub fn upper_bound_rad(&self, name: &str) -> Option<f64> {
        self.error_names
            .iter()
            .position(|n| n == name)
            .map(|i| self.upper_bounds_rad[i])
    }

    /// $J$ with the bounds in arcminutes (unit arcmin$^{-2}$), the scale of Table 4.
    #[must_use]
    pub fn objective_arcmin(&self) -> f64 {
        tt_core::units::objective_to_arcmin(self.objective)
    }

    /// The share of each requirement used, in the model's quantity order ($\psi, \theta,
    /// \gamma$; `None` without a requirement).
    #[must_use]
    pub fn shares(&self) -> Vec<Option<f64>> {
        self.certificate.axes.iter().map(|a| a.share).collect()
    }

    /// The names of the unconstrained errors.
    #[must_use]
    pub fn unconstrained_names(&self) -> Vec<&str> {
        self.unconstrained
            .iter()
            .map(|&i| self.error_names[i].as_str())
            .collect()
    }
}

/// The constraint family of one quantity's problem as a separation oracle: the rows of
/// [`LinearErrorModel::search`] over the model's domain.
pub(crate) struct AxisOracle<'m, S: LinearErrorModel + ?Sized> {
    pub model: &'m S,
    pub quantity: usize,
    pub name: String,
    pub components: Vec<usize>,
    pub requirement_rad: f64,
    exact: bool,
}

impl<'m, S: LinearErrorModel + ?Sized> AxisOracle<'m, S> {
    /// The oracle; checks the lengths once so that later searches cannot fail.
    pub(crate) fn new(
        model: &'m S,
        quantity: usize,
        components: Vec<usize>,
        requirement_rad: f64,
    ) -> Result<Self, AllocError> {
        let mut o = Self {
            model,
            quantity,
            name: model.quantity_name(quantity),
            components,
            requirement_rad,
            exact: false,
        };
        o.exact = o.search(&vec![0.0; o.components.len()])?.exact;
        Ok(o)
    }

    /// Whether the search of this oracle is exact.
    pub(crate) fn exact(&self) -> bool {
        self.exact
    }

    /// The weight vector over all errors for the components' values `x`.
    pub(crate) fn full(&self, x: &[f64]) -> Vec<f64> {
        let mut w = vec![0.0; self.model.n_errors()];
        for (k, &i) in self.components.iter().enumerate() {
            w[i] = x[k];
        }
        w
    }

    /// The worst point of the components' values `x` (the search).
    pub(crate) fn search(&self, x: &[f64]) -> Result<WorstRow, AllocError> {
        self.model.search(self.quantity, &self.full(x))
    }

    fn search_infallible(&self, x: &[f64]) -> WorstRow {
        self.search(x)
            .unwrap_or_else(|e| unreachable!("lengths checked in AxisOracle::new: {e}"))
    }

    /// The cut of a worst row (its components).
    pub(crate) fn row(&self, r: &WorstRow) -> Cut {
        Cut {
            coefficients: self
                .components
                .iter()
                .map(|&i| r.row.get(i).copied().unwrap_or(0.0))
                .collect(),
            bound: self.requirement_rad,
            tag: r.tag,
        }
    }

    /// Start rows: the model's [`LinearErrorModel::start_rows`] (the search at equal weights
    /// when it has none); rows equal to an earlier one are dropped.
    pub(crate) fn grid(&self) -> Vec<Cut> {
        let mut start = self.model.start_rows(self.quantity);
        if start.is_empty() {
            start.push(self.search_infallible(&vec![1.0; self.components.len()]));
        }
        let mut rows: Vec<Cut> = Vec::new();
        for r in &start {
            let row = self.row(r);
            let duplicate = rows.iter().any(|r| {
                r.coefficients
                    .iter()
                    .zip(&row.coefficients)
                    .all(|(a, b)| (a - b).abs() <= tt_kinematics::STRUCTURAL_ZERO)
            });
            if !duplicate {
                rows.push(row);
            }
        }
        rows
    }

    /// Reject lower bounds that alone exceed the requirement, naming the errors.
    pub(crate) fn check_lower_bounds(
        &self,
        lower: &[f64],
        names: &[String],
    ) -> Result<(), AllocError> {
        let worst = self.most_violated(lower);
        let load = worst.load(lower);
        if load > 1.0 {
            let components = self
                .components
                .iter()
                .zip(lower)
                .zip(&worst.coefficients)
                .filter(|((_, l), a)| **l > 0.0 && **a > 0.0)
                .map(|((&i, _), _)| names[i].clone())
                .collect();
            return Err(AllocError::InfeasibleLowerBounds {
                problem: self.name.clone(),
                components,
                worst_case_rad: load * self.requirement_rad,
                requirement_rad: self.requirement_rad,
            });
        }
        Ok(())
    }

    /// Reject errors whose coefficient is never positive on the domain (possible in the
    /// signed form only): no row bounds them, so the objective has no minimiser. Caught here
    /// by name rather than left to the conic solver, which stalls on such a problem.
    pub(crate) fn check_each_bounded(&self, names: &[String]) -> Result<(), AllocError> {
        let n = self.components.len();
        let mut unbounded = Vec::new();
        for k in 0..n {
            let mut unit = vec![0.0; n];
            unit[k] = 1.0;
            if self.search(&unit)?.value <= tt_kinematics::STRUCTURAL_ZERO {
                unbounded.push(names[self.components[k]].clone());
            }
        }
        if unbounded.is_empty() {
            Ok(())
        } else {
            Err(AllocError::Unbounded {
                problem: self.name.clone(),
                components: unbounded,
            })
        }
    }
}

impl<S: LinearErrorModel + ?Sized> CutOracle for AxisOracle<'_, S> {
    fn most_violated(&self, x: &[f64]) -> Cut {
        let wp = self.search_infallible(x);
        self.row(&wp)
    }
}

/// The errors of `model` that no quantity with a limit depends on.
pub(crate) fn unconstrained_errors<M: LinearErrorModel + ?Sized>(
    model: &M,
    limits: &[Option<f64>],
) -> Vec<usize> {
    let constrained: Vec<Vec<usize>> = limits
        .iter()
        .enumerate()
        .filter(|(_, l)| l.is_some())
        .map(|(k, _)| model.involved(k))
        .collect();
    (0..model.n_errors())
        .filter(|i| !constrained.iter().any(|inv| inv.contains(i)))
        .collect()
}

/// Combination rule (34), generalised: $\mathrm{UB}_i = \min_k \chi^*_{ki}$ over the
/// per-quantity solutions `(components, bounds)` that contain error $i$; `+inf` for an
/// error none of them contains.
///
/// # Reference
/// Zhao et al. 2017, eq 34.
#[must_use]
pub fn combine_rule_34(n_errors: usize, solutions: &[(&[usize], &[f64])]) -> Vec<f64> {
    let mut ub = vec![f64::INFINITY; n_errors];
    for (components, bounds) in solutions {
        for (&i, &b) in components.iter().zip(bounds.iter()) {
            ub[i] = ub[i].min(b);
        }
    }
    ub
}

/// The finishing step every allocator ends with, this crate's and an outside one: errors
/// no quantity with a limit depends on get `+inf`; the bounds are made safe with respect to
/// the rigorous worst-case bound ([`LinearErrorModel::worst_case`]; for a turntable with two
/// or more free joints); the certificate and the objective are computed, and every number
/// is checked finite.
///
/// # Formula
/// For a quantity whose rigorous bound $U$ exceeds $I$: the free bounds $x_F$ of its errors
/// are shrunk by $s = (I - U_L)/((1 + 2g)U - U_L)$, $U_L$ the rigorous bound with only the
/// errors held at their lower bounds and $g$ = [`CERTIFY_REL_GAP`]. The worst case
/// $F(x) = \max_\phi \sum_i x_i|c_{ki}(\phi)|$ is convex and positively homogeneous, so
/// $F(s x_F + x_L) \le sF(x) + (1 - s)F(x_L) \le sU + (1 - s)U_L < I$.
///
/// # Errors
/// [`AllocError::Field`] for bounds of the wrong length or NaN/negative;
/// [`AllocError::NoConvergence`] when the bounds cannot be made safe;
/// [`AllocError::NonFiniteResult`] for a non-finite number.
pub fn finish<M: LinearErrorModel>(
    problem: &AllocationProblem<M>,
    method: &str,
    weights: Weights,
    mut ub: Vec<f64>,
    details: MethodDetails,
) -> Result<ToleranceBox, AllocError> {
    let model = problem.model();
    let limits = problem.limits().to_vec();
    let lb = problem.lower_bounds_rad().to_vec();
    let names = problem.error_names();
    length("upper_bounds", model.n_errors(), ub.len())?;
    length("weights", model.n_errors(), weights.n_errors())?;
    let unconstrained = unconstrained_errors(model, &limits);
    for &i in &unconstrained {
        ub[i] = f64::INFINITY;
    }
    let mut safety_scale = vec![1.0; limits.len()];
    let mut certificate = Certificate::compute(model, &limits, &lb, &ub)?;
    let mut rounds = 0;
    while !certificate.lemma1_holds() {
        let unsafe_axes: Vec<&AxisCertificate> = certificate
            .axes
            .iter()
            .filter(|a| !a.satisfied && !a.exact)
            .collect();
        if unsafe_axes.is_empty() || rounds >= SAFETY_ROUNDS {
            // Exact worst cases that exceed the requirement are reported as such (the
            // paper's quarter ranges on a table without eq 26's symmetry); a search that
            // cannot be made safe is an error.
            if unsafe_axes.is_empty() {
                break;
            }
            let a = unsafe_axes[0];
            return Err(AllocError::NoConvergence {
                problem: format!("{} (rigorous worst-case bound)", a.name),
                iterations: rounds,
                violation: a.upper_bound_rad / a.requirement_rad.unwrap_or(f64::NAN) - 1.0,
            });
        }
        rounds += 1;
        // Each error is shrunk by the smallest factor of the unsafe quantities that depend
        // on it: the worst case is monotone in the bounds (absolute coefficients), so each
        // quantity's own factor already makes it safe.
        let mut factor = vec![1.0_f64; ub.len()];
        for a in unsafe_axes {
            let i_k = a.requirement_rad.unwrap_or(f64::INFINITY);
            let involved = model.involved(a.quantity);
            let free: Vec<usize> = involved
                .iter()
                .copied()
                .filter(|&i| ub[i] > lb[i] * (1.0 + AT_LOWER_REL))
                .collect();
            let mut held = vec![0.0; ub.len()];
            for &i in &involved {
                if !free.contains(&i) {
                    held[i] = ub[i];
                }
            }
            let u_l = if held.iter().any(|&v| v > 0.0) {
                model.worst_case(a.quantity, &held)?.upper_bound
            } else {
                0.0
            };
            let s = (i_k - u_l) / ((1.0 + 2.0 * CERTIFY_REL_GAP) * a.upper_bound_rad - u_l);
            if !(s > 0.0 && s < 1.0) {
                return Err(AllocError::NonFiniteResult {
                    what: format!("safety scale of {}", a.name),
                    value: s,
                });
            }
            for &i in &free {
                factor[i] = factor[i].min(s);
            }
            safety_scale[a.quantity] *= s;
        }
        for (u, (f, l)) in ub.iter_mut().zip(factor.iter().zip(&lb)) {
            if *f < 1.0 {
                *u = (*u * f).max(*l);
            }
        }
        certificate = Certificate::compute(model, &limits, &lb, &ub)?;
    }
    let objective = weights.objective(&ub);
    let allocation = ToleranceBox {
        method: method.to_string(),
        error_names: names,
        upper_bounds_rad: ub,
        lower_bounds_rad: lb,
        limits,
        objective,
        weights,
        certificate,
        unconstrained,
        safety_scale,
        details,
    };
    check_finite(&allocation)?;
    Ok(allocation)
}

/// No NaN or infinity may reach an allocation, except the `+inf` bound of an unconstrained
/// error.
fn check_finite(a: &ToleranceBox) -> Result<(), AllocError> {
    for (i, (&u, name)) in a.upper_bounds_rad.iter().zip(&a.error_names).enumerate() {
        if !(a.unconstrained.contains(&i) && u == f64::INFINITY) {
            finite_result(|| format!("upper_bounds.{name}"), u)?;
        }
    }
    finite_result(|| "objective".into(), a.objective)?;
    for s in a.subproblems() {
        let q = &s.name;
        for &v in s.bounds_rad.iter().chain(&s.worst_pose_rad) {
            finite_result(|| format!("subproblem.{q}"), v)?;
        }
        finite_result(|| format!("subproblem.{q}.load"), s.load)?;
        if let Some(j) = s.objective {
            finite_result(|| format!("subproblem.{q}.objective"), j)?;
        }
        if let Some(m) = s.multiplier {
            finite_result(|| format!("subproblem.{q}.multiplier"), m)?;
        }
    }
    for c in &a.certificate.axes {
        c.check_finite()?;
    }
    for (k, &s) in a.safety_scale.iter().enumerate() {
        finite_result(|| format!("safety_scale[{k}]"), s)?;
    }
    Ok(())
}
