//! The inputs of an allocation: model, requirement, lower bounds, weights.

use crate::error::{AllocError, length, non_negative, positive};
use nalgebra::DMatrix;
use tt_core::Requirement;
use tt_kinematics::{LinearModel, OrientationAxis};

/// What an [`crate::Allocator`] is asked: the first-order orientation-error model of a
/// turntable (eq 26 for the paper's table), the requirement and one lower bound
/// $\mathrm{LB}_i$ per rotation error (eq 29).
#[derive(Debug, Clone, PartialEq)]
pub struct AllocationProblem {
    model: LinearModel,
    requirement: Requirement,
    lower_bounds_rad: Vec<f64>,
}

impl AllocationProblem {
    /// A problem; lower bounds (radians, one per rotation error in the turntable's error
    /// order, eq 25 for the paper) must be finite and non-negative.
    ///
    /// # Errors
    /// [`AllocError::Field`] (wrong length) naming `lower_bounds` for a vector of the wrong length;
    /// [`AllocError::Field`] (not finite, negative) naming
    /// `lower_bounds.<error name>`.
    pub fn new(
        model: LinearModel,
        requirement: Requirement,
        lower_bounds_rad: Vec<f64>,
    ) -> Result<Self, AllocError> {
        length("lower_bounds", model.n_errors(), lower_bounds_rad.len())?;
        for (name, &lb) in model
            .turntable()
            .rotation_error_names()
            .iter()
            .zip(&lower_bounds_rad)
        {
            non_negative(format!("lower_bounds.{name}"), lb)?;
        }
        Ok(Self {
            model,
            requirement,
            lower_bounds_rad,
        })
    }

    /// The same problem with every requirement shrunk by a relative safety margin
    /// `margin` in $[0, 1)$: $I_k \to (1 - \text{margin}) I_k$. Use it to keep room for the
    /// second-order terms the linear model omits (see [`crate::exact_chain_check`]).
    ///
    /// # Errors
    /// [`AllocError::Field`] (not finite, negative) naming `safety_margin`, or
    /// [`AllocError::Field`] (not positive) when `margin >= 1`.
    pub fn with_safety_margin(&self, margin: f64) -> Result<Self, AllocError> {
        let m = non_negative("safety_margin", margin)?;
        if m >= 1.0 {
            return Err(tt_core::FieldError::NotPositive {
                field: "1 - safety_margin".into(),
                value: 1.0 - m,
            }
            .into());
        }
        Ok(Self {
            requirement: self.requirement.scaled(1.0 - m)?,
            ..self.clone()
        })
    }

    /// The model.
    #[must_use]
    pub fn model(&self) -> &LinearModel {
        &self.model
    }

    /// The requirement.
    #[must_use]
    pub fn requirement(&self) -> Requirement {
        self.requirement
    }

    /// The lower bounds (radians, the turntable's error order).
    #[must_use]
    pub fn lower_bounds_rad(&self) -> &[f64] {
        &self.lower_bounds_rad
    }

    /// The names of the rotation errors (the turntable's error order).
    #[must_use]
    pub fn error_names(&self) -> Vec<String> {
        error_names(&self.model)
    }
}

pub(crate) fn error_names(model: &LinearModel) -> Vec<String> {
    model
        .turntable()
        .rotation_error_names()
        .into_iter()
        .map(str::to_string)
        .collect()
}

/// Weights $W_{ki}$ of the objective $J = \sum_k \sum_{i \in \chi_k} W_{ki}^2/\chi_{ki}^2$
/// (problems 31-33): a $3 \times n$ matrix (rows $\psi, \theta, \gamma$, one column per
/// rotation error), zero where an error is not involved in an angle.
#[derive(Debug, Clone, PartialEq)]
pub struct Weights {
    w: DMatrix<f64>,
}

impl Weights {
    /// The paper's weights: the multiplicative inverse of the average sensitivity over the
    /// joint ranges (eq 28, Figure 8), zero where an error is not involved. For eq 26 this is
    /// $\pi/2$ for every $\sin\phi_2$/$\cos\phi_2$ term and 1 for a constant term.
    ///
    /// # Formula
    /// $$W_{ki} = 1 \Big/ \overline{\Big|\frac{\partial f_k}{\partial\chi_i}\Big|},$$ the
    /// average taken uniformly over the free joints' ranges
    /// ([`LinearModel::average_abs_coefficients`]: exact in the last free joint, a midpoint
    /// rule in the others).
    ///
    /// # Reference
    /// Zhao et al. 2017, eq 28 and the text below (33).
    #[must_use]
    pub fn inverse_average_sensitivity(model: &LinearModel) -> Self {
        let avg = model.average_abs_coefficients();
        let mut w = DMatrix::zeros(3, model.n_errors());
        for axis in OrientationAxis::ALL {
            for i in model.involved(axis) {
                let a = avg[(axis.index(), i)];
                if a > 0.0 && (1.0 / a).is_finite() {
                    w[(axis.index(), i)] = 1.0 / a;
                }
            }
        }
        Self { w }
    }

    /// Explicit weights ($3 \times n$, rows $\psi, \theta, \gamma$); every entry of an error
    /// involved in an angle (per `model`) must be finite and positive, the others are ignored
    /// (set to zero).
    ///
    /// # Errors
    /// [`AllocError::Field`] (wrong length) naming `weights` for a matrix that is not $3 \times n$;
    /// [`AllocError::Field`] (not finite, not positive) naming
    /// `weights.<axis>.<error name>`.
    pub fn new(model: &LinearModel, w: DMatrix<f64>) -> Result<Self, AllocError> {
        length("weights (rows)", 3, w.nrows())?;
        length("weights", model.n_errors(), w.ncols())?;
        let names = error_names(model);
        let mut out = DMatrix::zeros(3, model.n_errors());
        for axis in OrientationAxis::ALL {
            for i in model.involved(axis) {
                let ij = (axis.index(), i);
                out[ij] = positive(format!("weights.{}.{}", axis.name(), names[i]), w[ij])?;
            }
        }
        Ok(Self { w: out })
    }

    /// Number of errors (columns).
    #[must_use]
    pub fn n_errors(&self) -> usize {
        self.w.ncols()
    }

    /// $W_{ki}$ (zero when not involved).
    ///
    /// # Panics
    /// When `error` is not below [`Weights::n_errors`].
    #[must_use]
    pub fn get(&self, axis: OrientationAxis, error: usize) -> f64 {
        self.w[(axis.index(), error)]
    }

    /// The matrix (rows $\psi, \theta, \gamma$).
    #[must_use]
    pub fn matrix(&self) -> &DMatrix<f64> {
        &self.w
    }

    /// The combined weight of each error, $w_i = \sqrt{\sum_k W_{ki}^2}$: then
    /// $\sum_i w_i^2/\mathrm{UB}_i^2 = J(\mathrm{UB})$ of [`Weights::objective`], so an error
    /// that appears in two angles counts twice, as in the per-angle problems. For eq 26:
    /// $\pi/\sqrt2$ for the four errors shared by $\psi$ and $\gamma$, 1 for the others.
    #[must_use]
    pub fn combined(&self) -> Vec<f64> {
        (0..self.n_errors())
            .map(|i| self.w.column(i).norm())
            .collect()
    }

    /// $J_k(\mathrm{UB}) = \sum_{i} W_{ki}^2 / \mathrm{UB}_i^2$ for one angle (rad$^{-2}$ for
    /// bounds in radians). Infinite bounds (unconstrained errors) contribute 0.
    ///
    /// # Panics
    /// When `ub_rad` is shorter than [`Weights::n_errors`].
    #[must_use]
    pub fn objective_axis(&self, axis: OrientationAxis, ub_rad: &[f64]) -> f64 {
        (0..self.n_errors())
            .map(|i| {
                let w = self.get(axis, i);
                if w > 0.0 {
                    (w / ub_rad[i]).powi(2)
                } else {
                    0.0
                }
            })
            .sum()
    }

    /// $J(\mathrm{UB}) = J_\psi + J_\theta + J_\gamma$: the paper's three objectives evaluated
    /// at the combined bounds (rad$^{-2}$ for bounds in radians; multiply by
    /// $(\pi/10800)^2$ for arcmin$^{-2}$). Infinite bounds contribute 0.
    ///
    /// # Panics
    /// When `ub_rad` is shorter than [`Weights::n_errors`].
    #[must_use]
    pub fn objective(&self, ub_rad: &[f64]) -> f64 {
        OrientationAxis::ALL
            .into_iter()
            .map(|a| self.objective_axis(a, ub_rad))
            .sum()
    }
}
