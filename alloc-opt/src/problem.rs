//! The inputs of an allocation: model, limits, lower bounds, weights.

use crate::error::{AllocError, length, non_negative, positive};
use crate::model::LinearErrorModel;
use nalgebra::DMatrix;
use tt_core::Requirement;
use tt_kinematics::{LinearModel, OrientationAxis};

/// What an [`crate::Allocator`] is asked: a first-order model of the constrained quantities
/// ([`LinearErrorModel`]; eq 26 for the paper's table), one limit per quantity (the
/// requirement) and one lower bound $\mathrm{LB}_i$ per error (eq 29).
#[derive(Debug, Clone, PartialEq)]
pub struct AllocationProblem<M = LinearModel> {
    model: M,
    limits: Vec<Option<f64>>,
    lower_bounds_rad: Vec<f64>,
}

impl<M: LinearErrorModel> AllocationProblem<M> {
    /// A problem for a model whose quantities are the three angles $\psi, \theta, \gamma$
    /// (a turntable's), with the requirement of eq 15-16; lower bounds (radians, one per
    /// error in the model's order, eq 25 for the paper) must be finite and non-negative.
    ///
    /// # Errors
    /// [`AllocError::Field`] (wrong length) naming `requirement` for a model without three
    /// quantities or `lower_bounds` for a vector of the wrong length;
    /// [`AllocError::Field`] (not finite, negative) naming `lower_bounds.<error name>`.
    pub fn new(
        model: M,
        requirement: Requirement,
        lower_bounds_rad: Vec<f64>,
    ) -> Result<Self, AllocError> {
        length("requirement", model.n_quantities(), 3)?;
        Self::with_limits(model, requirement.to_array().to_vec(), lower_bounds_rad)
    }

    /// A problem with one limit per quantity (`None`: unconstrained; a limit must be finite
    /// and positive, in the quantity's unit, rad for angles).
    ///
    /// # Errors
    /// [`AllocError::Field`] (wrong length) naming `limits` or `lower_bounds`;
    /// (not finite, not positive) naming `requirement.<quantity name>`; (not finite, negative)
    /// naming `lower_bounds.<error name>`.
    pub fn with_limits(
        model: M,
        limits: Vec<Option<f64>>,
        lower_bounds_rad: Vec<f64>,
    ) -> Result<Self, AllocError> {
        length("limits", model.n_quantities(), limits.len())?;
        for (k, l) in limits.iter().enumerate() {
            if let Some(l) = l {
                positive(format!("requirement.{}", model.quantity_name(k)), *l)?;
            }
        }
        length("lower_bounds", model.n_errors(), lower_bounds_rad.len())?;
        for (j, &lb) in lower_bounds_rad.iter().enumerate() {
            non_negative(format!("lower_bounds.{}", model.error_name(j)), lb)?;
        }
        Ok(Self {
            model,
            limits,
            lower_bounds_rad,
        })
    }

    /// The same problem with every limit shrunk by a relative safety margin
    /// `margin` in $[0, 1)$: $I_k \to (1 - \text{margin}) I_k$. Use it to keep room for the
    /// second-order terms the linear model omits (see [`crate::exact_chain_check`]).
    ///
    /// # Errors
    /// [`AllocError::Field`] (not finite, negative) naming `safety_margin`, or
    /// [`AllocError::Field`] (not positive) when `margin >= 1`.
    pub fn with_safety_margin(&self, margin: f64) -> Result<Self, AllocError>
    where
        M: Clone,
    {
        let m = non_negative("safety_margin", margin)?;
        if m >= 1.0 {
            return Err(tt_core::FieldError::NotPositive {
                field: "1 - safety_margin".into(),
                value: 1.0 - m,
            }
            .into());
        }
        let factor = 1.0 - m;
        let mut limits = Vec::with_capacity(self.limits.len());
        for (k, l) in self.limits.iter().enumerate() {
            limits.push(match l {
                Some(v) => Some(positive(
                    format!("requirement.{}", self.model.quantity_name(k)),
                    v * factor,
                )?),
                None => None,
            });
        }
        Ok(Self {
            limits,
            ..self.clone()
        })
    }

    /// The model.
    #[must_use]
    pub fn model(&self) -> &M {
        &self.model
    }

    /// The limit of each quantity (rad for angles; `None`: unconstrained).
    #[must_use]
    pub fn limits(&self) -> &[Option<f64>] {
        &self.limits
    }

    /// The requirement, for a model whose quantities are the three angles.
    ///
    /// # Panics
    /// When the model does not have three quantities (checked by
    /// [`AllocationProblem::new`]; use [`AllocationProblem::limits`] otherwise).
    #[must_use]
    pub fn requirement(&self) -> Requirement {
        let [psi, theta, gamma] = self.limits[..] else {
            panic!("requirement() needs three quantities; use limits()")
        };
        Requirement::from_options([psi, theta, gamma])
            .unwrap_or_else(|e| unreachable!("limits checked when built: {e}"))
    }

    /// The lower bounds (radians, the model's error order).
    #[must_use]
    pub fn lower_bounds_rad(&self) -> &[f64] {
        &self.lower_bounds_rad
    }

    /// The names of the errors (the model's order).
    #[must_use]
    pub fn error_names(&self) -> Vec<String> {
        error_names(&self.model)
    }
}

pub(crate) fn error_names<M: LinearErrorModel + ?Sized>(model: &M) -> Vec<String> {
    (0..model.n_errors()).map(|j| model.error_name(j)).collect()
}

/// Weights $W_{ki}$ of the objective $J = \sum_k \sum_{i \in \chi_k} W_{ki}^2/\chi_{ki}^2$
/// (problems 31-33): a $q \times n$ matrix (one row per quantity: $\psi, \theta, \gamma$
/// for a turntable; one column per error), zero where an error is not involved in an angle.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
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
    pub fn inverse_average_sensitivity<M: LinearErrorModel + ?Sized>(model: &M) -> Self {
        let avg = model.average_abs_coefficients();
        let mut w = DMatrix::zeros(model.n_quantities(), model.n_errors());
        for k in 0..model.n_quantities() {
            for i in model.involved(k) {
                let a = avg[(k, i)];
                if a > 0.0 && (1.0 / a).is_finite() {
                    w[(k, i)] = 1.0 / a;
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
    pub fn new<M: LinearErrorModel + ?Sized>(
        model: &M,
        w: DMatrix<f64>,
    ) -> Result<Self, AllocError> {
        let q = model.n_quantities();
        length("weights (rows)", q, w.nrows())?;
        length("weights", model.n_errors(), w.ncols())?;
        let names = error_names(model);
        let mut out = DMatrix::zeros(q, model.n_errors());
        for k in 0..q {
            let quantity = model.quantity_name(k);
            for i in model.involved(k) {
                let ij = (k, i);
                out[ij] = positive(format!("weights.{quantity}.{}", names[i]), w[ij])?;
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

    /// $W_{ki}$ of quantity `k` (zero when not involved).
    ///
    /// # Panics
    /// When `k` or `error` is out of range.
    #[must_use]
    pub fn of(&self, k: usize, error: usize) -> f64 {
        self.w[(k, error)]
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
        self.objective_of(axis.index(), ub_rad)
    }

    /// $J_k(\mathrm{UB})$ of quantity `k` (rad$^{-2}$ for bounds in radians); infinite bounds
    /// contribute 0.
    ///
    /// # Panics
    /// When `k` is out of range or `ub_rad` is shorter than [`Weights::n_errors`].
    #[must_use]
    pub fn objective_of(&self, k: usize, ub_rad: &[f64]) -> f64 {
        (0..self.n_errors())
            .map(|i| {
                let w = self.of(k, i);
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
        (0..self.w.nrows())
            .map(|k| self.objective_of(k, ub_rad))
            .sum()
    }
}
