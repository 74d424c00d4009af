//! The [`Allocator`] seam, its result [`Allocation`] and the Lemma 1 [`Certificate`].

use crate::error::{AllocError, finite_result, length};
use crate::problem::{AllocationProblem, Weights, error_names};
use crate::solver::{Cut, CutOracle};
use tt_core::Requirement;
use tt_core::units::RAD_PER_ARCMIN;
use tt_kinematics::{CERTIFY_REL_GAP, LinearModel, OrientationAxis, Pose, WorstPose};

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

/// Turns an [`AllocationProblem`] into upper bounds $\mathrm{UB}_i$ with a certificate.
///
/// # Example
/// ```
/// use alloc_opt::{Allocator, EqualEffects, SensitivityWeighted, paper};
/// let problem = paper::example_problem()?;
/// for allocator in [&SensitivityWeighted::paper() as &dyn Allocator, &EqualEffects] {
///     let a = allocator.allocate(&problem)?;
///     assert!(a.certificate.lemma1_holds());
/// }
/// # Ok::<(), alloc_opt::AllocError>(())
/// ```
pub trait Allocator {
    /// A short name of the method (`"sensitivity-weighted"`, `"equal-effects"`).
    fn name(&self) -> &'static str;

    /// Allocate the upper bounds.
    ///
    /// # Errors
    /// [`AllocError`] naming the problem and errors when the lower bounds are infeasible,
    /// when the method does not apply to the turntable, or when a solver fails.
    fn allocate(&self, problem: &AllocationProblem) -> Result<Allocation, AllocError>;
}

/// The solution of one per-angle problem ((31) $\gamma$, (32) $\theta$, (33) $\psi$ for the
/// paper's table).
#[derive(Debug, Clone, PartialEq)]
pub struct Subproblem {
    /// The angle (problem) concerned.
    pub axis: OrientationAxis,
    /// Its errors (indices into $\chi$; $\chi_\gamma$, $\chi_\theta$, $\chi_\psi$ of eq 27).
    pub components: Vec<usize>,
    /// The optimal $\chi_k^*$ (rad), one per component.
    pub bounds_rad: Vec<f64>,
    /// The joint ranges (rad, one `[lo, hi]` per joint) of the constraint.
    pub pose_ranges_rad: Vec<[f64; 2]>,
    /// $J_k(\chi_k^*)$ (rad$^{-2}$); `None` for the equal-effects allocator.
    pub objective: Option<f64>,
    /// A pose (rad, every joint) where the constraint is tight.
    pub worst_pose_rad: Vec<f64>,
    /// The constraint's load at the optimum (1 = the whole requirement used).
    pub load: f64,
    /// The requirement's Lagrange multiplier (units of $J$); `None` when not computed.
    pub multiplier: Option<f64>,
    /// Conic solves done by the exchange method (0 when none was needed).
    pub iterations: usize,
    /// Whether the worst-case oracle of this problem is exact (at most one free joint).
    pub exact_oracle: bool,
}

/// The certificate of one angle: the worst case over all poses in the joint ranges and all
/// admissible errors.
#[derive(Debug, Clone, PartialEq)]
pub struct AxisCertificate {
    /// The angle.
    pub axis: OrientationAxis,
    /// $I_k$ (rad); `None` when the angle carries no requirement.
    pub requirement_rad: Option<f64>,
    /// The largest worst case found,
    /// $\max_{\phi} \max_{\mathrm{LB} \le |\chi| \le \mathrm{UB}} |f_k(\phi,\chi)|
    /// = \max_{\phi} \sum_i \mathrm{UB}_i |c_{ki}(\phi)|$ (rad), over the errors with a
    /// finite bound. Exact when [`AxisCertificate::exact`].
    pub worst_case_rad: f64,
    /// A pose (rad, every joint) where it is reached (joints that cancel sit at the lower end
    /// of their range).
    pub worst_pose_rad: Vec<f64>,
    /// A rigorous upper bound on the worst case (rad): equal to `worst_case_rad` when exact,
    /// the branch-and-bound bound of [`LinearModel::worst_pose_certified`] otherwise.
    pub upper_bound_rad: f64,
    /// Whether the worst case is exact (at most one free joint).
    pub exact: bool,
    /// `worst_case_rad / requirement_rad`: the share of the requirement used (`None` without
    /// a requirement).
    pub share: Option<f64>,
    /// The requirement is active: share $\ge 1 -$ [`TIGHT_REL`] when exact; when searched,
    /// `upper_bound_rad` $\ge (1 -$ [`SEARCHED_TIGHT_REL`]$)\,I_k$.
    pub requirement_active: bool,
    /// The requirement holds (Lemma 1 for this angle): `upper_bound_rad` $\le (1 +$
    /// [`SATISFIED_REL`]$)\,I_k$; true for an angle without a requirement.
    pub satisfied: bool,
    /// Involved errors (indices) whose upper bound equals their positive lower bound.
    pub active_lower_bounds: Vec<usize>,
    /// Involved errors (indices) with an infinite upper bound (only for an angle without a
    /// requirement): the angle's true worst case is then unbounded, and the numbers above are
    /// those of the bounded errors.
    pub unbounded: Vec<usize>,
}

/// Lemma 1's certificate for all three angles.
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
/// - Neither covers the second-order terms of the exact chain: see
///   [`crate::exact_chain_check`].
#[derive(Debug, Clone, PartialEq)]
pub struct Certificate {
    /// One per angle, in the order $\psi, \theta, \gamma$.
    pub axes: [AxisCertificate; 3],
}

impl Certificate {
    /// The worst cases of `ub_rad` on `model` over the turntable's joint ranges.
    ///
    /// # Formula
    /// $$\max_{\phi}\sum_i \mathrm{UB}_i\,|c_{ki}(\phi)|,$$ the signs of $\chi$ chosen
    /// adversarially (the lower bounds do not lower the maximum), found by
    /// [`LinearModel::worst_pose_certified`].
    ///
    /// # Errors
    /// [`AllocError::Field`] (wrong length) for vectors of the wrong length; [`AllocError::Field`] (not finite) or
    /// [`AllocError::Field`] (negative) naming `upper_bounds.<error name>` for a bound that is NaN,
    /// negative, or infinite on an angle with a requirement.
    ///
    /// # Reference
    /// Zhao et al. 2017, Lemma 1 and eq 30.
    pub fn compute(
        model: &LinearModel,
        requirement: &Requirement,
        lower_bounds_rad: &[f64],
        ub_rad: &[f64],
    ) -> Result<Self, AllocError> {
        let n = model.n_errors();
        length("lower_bounds", n, lower_bounds_rad.len())?;
        length("upper_bounds", n, ub_rad.len())?;
        let names = error_names(model);
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
        let mut axes = Vec::with_capacity(3);
        for axis in OrientationAxis::ALL {
            let involved = model.involved(axis);
            let mut w = vec![0.0; n];
            let mut unbounded = Vec::new();
            for &i in &involved {
                if ub_rad[i].is_finite() {
                    w[i] = ub_rad[i];
                } else if requirement.get(axis).is_some() {
                    return Err(tt_core::FieldError::NonFinite {
                        field: format!("upper_bounds.{}", names[i]),
                        value: ub_rad[i],
                    }
                    .into());
                } else {
                    unbounded.push(i);
                }
            }
            let worst = model.worst_pose_certified(axis, &w, true, None)?;
            let active_lower_bounds = involved
                .iter()
                .copied()
                .filter(|&i| {
                    let lb = lower_bounds_rad[i];
                    lb > 0.0 && ub_rad[i] <= lb * (1.0 + AT_LOWER_REL)
                })
                .collect();
            axes.push(AxisCertificate::new(
                axis,
                requirement.get(axis),
                worst,
                active_lower_bounds,
                unbounded,
            ));
        }
        let [psi, theta, gamma]: [AxisCertificate; 3] = axes
            .try_into()
            .unwrap_or_else(|_| unreachable!("three angles"));
        Ok(Self {
            axes: [psi, theta, gamma],
        })
    }

    /// The certificate of one angle.
    #[must_use]
    pub fn get(&self, axis: OrientationAxis) -> &AxisCertificate {
        &self.axes[axis.index()]
    }

    /// Lemma 1: every angle's rigorous worst-case bound is within its requirement.
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
    fn new(
        axis: OrientationAxis,
        requirement_rad: Option<f64>,
        worst: WorstPose,
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
            axis,
            requirement_rad,
            worst_case_rad: worst.value,
            worst_pose_rad: worst.pose_rad,
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
            let axis = self.axis.name();
            let field = field.to_string();
            move || format!("certificate.{axis}.{field}")
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

/// An allocation: upper bounds with their objective, per-problem solutions and certificate.
#[derive(Debug, Clone, PartialEq)]
pub struct Allocation {
    /// The allocator's name.
    pub method: &'static str,
    /// The names of the rotation errors (the turntable's error order).
    pub error_names: Vec<String>,
    /// $\mathrm{UB}_i$ (rad, the turntable's error order); `+inf` exactly for the errors in
    /// [`Allocation::unconstrained`], finite otherwise.
    pub upper_bounds_rad: Vec<f64>,
    /// The lower bounds used (rad).
    pub lower_bounds_rad: Vec<f64>,
    /// The requirement used.
    pub requirement: Requirement,
    /// $J(\mathrm{UB}) = J_\psi + J_\theta + J_\gamma$ (rad$^{-2}$) under
    /// [`Allocation::weights`] (unconstrained errors contribute 0).
    pub objective: f64,
    /// The weights the objective is computed with (the paper's inverse average sensitivities
    /// unless the allocator was given others).
    pub weights: Weights,
    /// The per-angle problems, in the order solved (angles with a requirement and at least
    /// one involved error).
    pub subproblems: Vec<Subproblem>,
    /// Worst cases over the joint ranges (Lemma 1).
    pub certificate: Certificate,
    /// Errors (indices) that no angle with a requirement depends on: their bound is `+inf`.
    pub unconstrained: Vec<usize>,
    /// Per angle ($\psi, \theta, \gamma$), the factor by which the free bounds of its errors
    /// were shrunk after the combination (34) so that the rigorous worst-case bound is within
    /// the requirement (an error shared by several such angles is shrunk by the smallest of
    /// their factors); 1 when the worst case is exact.
    pub safety_scale: [f64; 3],
}

impl Allocation {
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

    /// The share of each requirement used, order $\psi, \theta, \gamma$ (`None` without a
    /// requirement).
    #[must_use]
    pub fn shares(&self) -> [Option<f64>; 3] {
        [0, 1, 2].map(|k| self.certificate.axes[k].share)
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

/// The constraint family of one angle's problem as a separation oracle: rows
/// $c_{ki}(\phi)$ (or $|c_{ki}(\phi)|$) for every pose $\phi$ in the joint ranges.
#[derive(Debug, Clone)]
pub(crate) struct AxisOracle<'m> {
    pub model: &'m LinearModel,
    pub axis: OrientationAxis,
    pub components: Vec<usize>,
    pub ranges: Vec<[f64; 2]>,
    pub abs: bool,
    pub requirement_rad: f64,
}

/// Start-grid points per free joint: 17 for one free joint (the paper's), fewer for more.
fn start_points(free: usize) -> usize {
    match free {
        0 => 1,
        1 => 17,
        2 => 9,
        _ => 5,
    }
}

impl<'m> AxisOracle<'m> {
    /// The oracle; checks the lengths once so that later searches cannot fail.
    pub fn new(
        model: &'m LinearModel,
        axis: OrientationAxis,
        components: Vec<usize>,
        ranges: Vec<[f64; 2]>,
        abs: bool,
        requirement_rad: f64,
    ) -> Result<Self, AllocError> {
        let o = Self {
            model,
            axis,
            components,
            ranges,
            abs,
            requirement_rad,
        };
        o.search(&vec![0.0; o.components.len()])?;
        Ok(o)
    }

    /// Whether the search of this oracle is exact.
    pub fn exact(&self) -> bool {
        self.model.free_joints().len() <= 1
    }

    /// The weight vector over all errors for the components' values `x`.
    pub fn full(&self, x: &[f64]) -> Vec<f64> {
        let mut w = vec![0.0; self.model.n_errors()];
        for (k, &i) in self.components.iter().enumerate() {
            w[i] = x[k];
        }
        w
    }

    /// The worst pose of the components' values `x` (the search).
    pub fn search(&self, x: &[f64]) -> Result<WorstPose, AllocError> {
        let w = self.full(x);
        Ok(if self.abs {
            self.model
                .max_abs_weighted(self.axis, &w, Some(&self.ranges))?
        } else {
            self.model
                .max_signed_weighted(self.axis, &w, Some(&self.ranges))?
        })
    }

    fn search_infallible(&self, x: &[f64]) -> WorstPose {
        self.search(x)
            .unwrap_or_else(|e| unreachable!("lengths checked in AxisOracle::new: {e}"))
    }

    /// The row at `pose`; its tag is the angle of the last free joint (the paper's
    /// $\phi_2$), or 0 when no joint is free.
    pub fn row(&self, pose: &[f64]) -> Cut {
        let c = Pose::new(pose.to_vec())
            .ok()
            .and_then(|p| self.model.coefficients(&p).ok());
        let coefficients = self
            .components
            .iter()
            .map(|&i| {
                let v = c.as_ref().map_or(0.0, |c| c[(self.axis.index(), i)]);
                if self.abs { v.abs() } else { v }
            })
            .collect();
        Cut {
            coefficients,
            bound: self.requirement_rad,
            tag: self.model.free_joints().last().map_or(0.0, |&j| pose[j]),
        }
    }

    /// Start rows: a grid over the free joints' ranges (one row when nothing depends on the
    /// pose); rows equal to an earlier one are dropped.
    pub fn grid(&self) -> Vec<Cut> {
        let free = self.model.free_joints().to_vec();
        let per = start_points(free.len());
        let base: Vec<f64> = self.ranges.iter().map(|r| r[0]).collect();
        let total = per.pow(free.len() as u32);
        let mut rows: Vec<Cut> = Vec::new();
        for cell in 0..total {
            let mut pose = base.clone();
            let mut rest = cell;
            for &j in &free {
                let [lo, hi] = self.ranges[j];
                let k = rest % per;
                rest /= per;
                pose[j] = if per == 1 {
                    lo
                } else {
                    lo + (hi - lo) * k as f64 / (per - 1) as f64
                };
            }
            let row = self.row(&pose);
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
    pub fn check_lower_bounds(&self, lower: &[f64], names: &[String]) -> Result<(), AllocError> {
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
                problem: self.axis,
                components,
                worst_case_rad: load * self.requirement_rad,
                requirement_rad: self.requirement_rad,
            });
        }
        Ok(())
    }
}

impl AxisOracle<'_> {
    /// Reject errors whose coefficient is never positive on the pose ranges (possible in the
    /// signed form only): no row bounds them, so the objective has no minimiser. Caught here
    /// by name rather than left to the conic solver, which stalls on such a problem.
    pub fn check_each_bounded(&self, names: &[String]) -> Result<(), AllocError> {
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
                problem: self.axis.name().to_string(),
                components: unbounded,
            })
        }
    }
}

impl CutOracle for AxisOracle<'_> {
    fn most_violated(&self, x: &[f64]) -> Cut {
        let wp = self.search_infallible(x);
        self.row(&wp.pose_rad)
    }
}

/// The errors of `model` that no angle with a requirement depends on.
pub(crate) fn unconstrained_errors(model: &LinearModel, requirement: &Requirement) -> Vec<usize> {
    let constrained: Vec<Vec<usize>> = requirement
        .constrained_axes()
        .into_iter()
        .map(|a| model.involved(a))
        .collect();
    (0..model.n_errors())
        .filter(|i| !constrained.iter().any(|inv| inv.contains(i)))
        .collect()
}

/// The common last step of every allocator: make the combined bounds safe with respect to
/// the rigorous worst-case bound (tables with two or more free joints), compute the
/// certificate and the objective, and check that every number is finite.
///
/// # Formula
/// For an angle whose rigorous bound $U$ exceeds $I$: the free bounds $x_F$ of its errors are
/// shrunk by $s = (I - U_L)/((1 + 2g)U - U_L)$, $U_L$ the rigorous bound with only the errors
/// held at their lower bounds and $g$ = [`CERTIFY_REL_GAP`]. The worst case
/// $F(x) = \max_\phi \sum_i x_i|c_{ki}(\phi)|$ is convex and positively homogeneous, so
/// $F(s x_F + x_L) \le sF(x) + (1 - s)F(x_L) \le sU + (1 - s)U_L < I$.
pub(crate) fn finish(
    method: &'static str,
    problem: &AllocationProblem,
    weights: Weights,
    mut ub: Vec<f64>,
    subproblems: Vec<Subproblem>,
) -> Result<Allocation, AllocError> {
    let model = problem.model();
    let requirement = problem.requirement();
    let lb = problem.lower_bounds_rad().to_vec();
    let names = problem.error_names();
    let unconstrained = unconstrained_errors(model, &requirement);
    for &i in &unconstrained {
        ub[i] = f64::INFINITY;
    }
    let mut safety_scale = [1.0; 3];
    let mut certificate = Certificate::compute(model, &requirement, &lb, &ub)?;
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
                problem: format!("{} (rigorous worst-case bound)", a.axis.name()),
                iterations: rounds,
                violation: a.upper_bound_rad / a.requirement_rad.unwrap_or(f64::NAN) - 1.0,
            });
        }
        rounds += 1;
        // Each error is shrunk by the smallest factor of the unsafe angles that depend on it:
        // the worst case is monotone in the bounds (absolute coefficients), so each angle's
        // own factor already makes it safe.
        let mut factor = vec![1.0_f64; ub.len()];
        for a in unsafe_axes {
            let i_k = a.requirement_rad.unwrap_or(f64::INFINITY);
            let involved = model.involved(a.axis);
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
                model
                    .worst_pose_certified(a.axis, &held, true, None)?
                    .upper_bound
            } else {
                0.0
            };
            let s = (i_k - u_l) / ((1.0 + 2.0 * CERTIFY_REL_GAP) * a.upper_bound_rad - u_l);
            if !(s > 0.0 && s < 1.0) {
                return Err(AllocError::NonFiniteResult {
                    what: format!("safety scale of {}", a.axis.name()),
                    value: s,
                });
            }
            for &i in &free {
                factor[i] = factor[i].min(s);
            }
            safety_scale[a.axis.index()] *= s;
        }
        for (u, (f, l)) in ub.iter_mut().zip(factor.iter().zip(&lb)) {
            if *f < 1.0 {
                *u = (*u * f).max(*l);
            }
        }
        certificate = Certificate::compute(model, &requirement, &lb, &ub)?;
    }
    let objective = weights.objective(&ub);
    let allocation = Allocation {
        method,
        error_names: names,
        upper_bounds_rad: ub,
        lower_bounds_rad: lb,
        requirement,
        objective,
        weights,
        subproblems,
        certificate,
        unconstrained,
        safety_scale,
    };
    check_finite(&allocation)?;
    Ok(allocation)
}

/// No NaN or infinity may reach an allocation, except the `+inf` bound of an unconstrained
/// error.
fn check_finite(a: &Allocation) -> Result<(), AllocError> {
    for (i, (&u, name)) in a.upper_bounds_rad.iter().zip(&a.error_names).enumerate() {
        if !(a.unconstrained.contains(&i) && u == f64::INFINITY) {
            finite_result(|| format!("upper_bounds.{name}"), u)?;
        }
    }
    finite_result(|| "objective".into(), a.objective)?;
    for s in &a.subproblems {
        let axis = s.axis.name();
        for &v in s.bounds_rad.iter().chain(&s.worst_pose_rad) {
            finite_result(|| format!("subproblem.{axis}"), v)?;
        }
        finite_result(|| format!("subproblem.{axis}.load"), s.load)?;
        if let Some(j) = s.objective {
            finite_result(|| format!("subproblem.{axis}.objective"), j)?;
        }
        if let Some(m) = s.multiplier {
            finite_result(|| format!("subproblem.{axis}.multiplier"), m)?;
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
