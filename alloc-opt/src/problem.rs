//! The inputs of an allocation: model, requirement, lower bounds, weights.

use crate::error::{AllocError, finite, non_negative, positive};
use nalgebra::SMatrix;
use tt_kinematics::units::deg_to_rad;
use tt_kinematics::{CHI_LEN, ErrorComponent, LinearModel, OrientationAxis};

/// The orientation-accuracy requirement $(I_\psi, I_\theta, I_\gamma)$ of eq 15-16, radians.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Requirement {
    rad: [f64; 3],
}

impl Requirement {
    /// A requirement in radians; each must be finite and positive.
    ///
    /// # Errors
    /// [`AllocError::NonFinite`] or [`AllocError::NotPositive`] naming `requirement.<axis>`.
    pub fn new(psi_rad: f64, theta_rad: f64, gamma_rad: f64) -> Result<Self, AllocError> {
        Ok(Self {
            rad: [
                positive("requirement.psi", psi_rad)?,
                positive("requirement.theta", theta_rad)?,
                positive("requirement.gamma", gamma_rad)?,
            ],
        })
    }

    /// The same requirement for all three angles, in degrees (eq 16 prints 0.027 deg).
    ///
    /// # Errors
    /// As [`Requirement::new`].
    pub fn uniform_deg(deg: f64) -> Result<Self, AllocError> {
        let r = deg_to_rad(finite("requirement_deg", deg)?);
        Self::new(r, r, r)
    }

    /// $I_k$ in radians.
    #[must_use]
    pub fn get(&self, axis: OrientationAxis) -> f64 {
        self.rad[axis.index()]
    }

    /// All three, in the order $\psi, \theta, \gamma$.
    #[must_use]
    pub fn to_array(&self) -> [f64; 3] {
        self.rad
    }

    /// The requirement multiplied by `factor` (in $(0, 1]$ for a safety margin).
    ///
    /// # Errors
    /// [`AllocError::NotPositive`] when `factor` is not positive and finite.
    pub fn scaled(&self, factor: f64) -> Result<Self, AllocError> {
        let f = positive("requirement_factor", factor)?;
        Self::new(self.rad[0] * f, self.rad[1] * f, self.rad[2] * f)
    }
}

/// What an [`crate::Allocator`] is asked: a linear first-harmonic orientation-error model
/// (eq 26 is one), the requirement and the lower bounds $\mathrm{LB}_i$ of eq 29.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AllocationProblem {
    model: LinearModel,
    requirement: Requirement,
    lower_bounds_rad: [f64; CHI_LEN],
}

impl AllocationProblem {
    /// A problem; lower bounds (radians, order of $\chi$ in eq 25) must be finite and
    /// non-negative.
    ///
    /// # Errors
    /// [`AllocError::NonFinite`] or [`AllocError::Negative`] naming `lower_bounds.<component>`.
    pub fn new(
        model: LinearModel,
        requirement: Requirement,
        lower_bounds_rad: [f64; CHI_LEN],
    ) -> Result<Self, AllocError> {
        for c in ErrorComponent::ALL {
            non_negative(
                format!("lower_bounds.{}", c.name()),
                lower_bounds_rad[c.index()],
            )?;
        }
        Ok(Self {
            model,
            requirement,
            lower_bounds_rad,
        })
    }

    /// The paper's example (§4.3): model (26), $I = 0.027^\circ$ for all three angles (eq 16
    /// as printed), and $\mathrm{LB} = 0$ because the paper gives no lower bounds (NOTES item
    /// 11; the NumPy Monte Carlo anchor also draws from zero).
    ///
    /// # Errors
    /// Never in practice (the inputs are constants); kept fallible for uniformity.
    pub fn paper_example() -> Result<Self, AllocError> {
        Self::new(
            LinearModel::paper_eq26(),
            Requirement::uniform_deg(crate::PAPER_REQUIREMENT_DEG)?,
            [0.0; CHI_LEN],
        )
    }

    /// The same problem with every requirement shrunk by a relative safety margin
    /// `margin` in $[0, 1)$: $I_k \to (1 - \text{margin}) I_k$. Use it to keep room for the
    /// second-order terms the linear model omits (see [`crate::exact_chain_check`]).
    ///
    /// # Errors
    /// [`AllocError::NonFinite`]/[`AllocError::Negative`] naming `safety_margin`, or
    /// [`AllocError::NotPositive`] when `margin >= 1`.
    pub fn with_safety_margin(&self, margin: f64) -> Result<Self, AllocError> {
        let m = non_negative("safety_margin", margin)?;
        if m >= 1.0 {
            return Err(AllocError::NotPositive {
                field: "1 - safety_margin".into(),
                value: 1.0 - m,
            });
        }
        Ok(Self {
            requirement: self.requirement.scaled(1.0 - m)?,
            ..*self
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

    /// The lower bounds (radians, order of eq 25).
    #[must_use]
    pub fn lower_bounds_rad(&self) -> [f64; CHI_LEN] {
        self.lower_bounds_rad
    }
}

/// Weights $W_{ki}$ of the objective $J = \sum_k \sum_{i \in \chi_k} W_{ki}^2/\chi_{ki}^2$
/// (problems 31-33): a 3x8 matrix (rows $\psi, \theta, \gamma$), zero where a component is
/// not involved in an angle.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Weights {
    w: SMatrix<f64, 3, CHI_LEN>,
}

impl Weights {
    /// The paper's weights: the multiplicative inverse of the average sensitivity (eq 28,
    /// Figure 8). For eq 26 this is $\pi/2$ for every $\sin\phi_2$/$\cos\phi_2$ term and 1 for
    /// a constant term.
    ///
    /// # Formula
    /// $$W_{ki} = 1 \Big/ \tfrac{1}{2\pi}\int_0^{2\pi} \Big|\frac{\partial f_k}{\partial\chi_i}\Big|\,d\phi_2.$$
    ///
    /// # Reference
    /// Zhao et al. 2017, eq 28 and the text below (33).
    #[must_use]
    pub fn inverse_average_sensitivity(model: &LinearModel) -> Self {
        let avg = model.average_abs_coefficients();
        Self {
            w: avg.map(|a| if a > 0.0 { 1.0 / a } else { 0.0 }),
        }
    }

    /// Explicit weights; every entry of a component involved in an angle (per `model`) must be
    /// finite and positive, the others are ignored (set to zero).
    ///
    /// # Errors
    /// [`AllocError::NonFinite`] or [`AllocError::NotPositive`] naming
    /// `weights.<axis>.<component>`.
    pub fn new(model: &LinearModel, w: SMatrix<f64, 3, CHI_LEN>) -> Result<Self, AllocError> {
        let mut out = SMatrix::zeros();
        for axis in OrientationAxis::ALL {
            for c in model.involved(axis) {
                let ij = (axis.index(), c.index());
                out[ij] = positive(format!("weights.{}.{}", axis.name(), c.name()), w[ij])?;
            }
        }
        Ok(Self { w: out })
    }

    /// $W_{ki}$ (zero when not involved).
    #[must_use]
    pub fn get(&self, axis: OrientationAxis, c: ErrorComponent) -> f64 {
        self.w[(axis.index(), c.index())]
    }

    /// The matrix (rows $\psi, \theta, \gamma$).
    #[must_use]
    pub fn matrix(&self) -> SMatrix<f64, 3, CHI_LEN> {
        self.w
    }

    /// $J_k(\mathrm{UB}) = \sum_{i} W_{ki}^2 / \mathrm{UB}_i^2$ for one angle (rad$^{-2}$ for
    /// bounds in radians). Infinite bounds contribute 0.
    #[must_use]
    pub fn objective_axis(&self, axis: OrientationAxis, ub_rad: &[f64; CHI_LEN]) -> f64 {
        ErrorComponent::ALL
            .into_iter()
            .map(|c| {
                let w = self.get(axis, c);
                if w > 0.0 {
                    (w / ub_rad[c.index()]).powi(2)
                } else {
                    0.0
                }
            })
            .sum()
    }

    /// $J(\mathrm{UB}) = J_\psi + J_\theta + J_\gamma$: the paper's three objectives evaluated
    /// at the combined bounds (rad$^{-2}$ for bounds in radians; multiply by
    /// $(\pi/10800)^2$ for arcmin$^{-2}$).
    #[must_use]
    pub fn objective(&self, ub_rad: &[f64; CHI_LEN]) -> f64 {
        OrientationAxis::ALL
            .into_iter()
            .map(|a| self.objective_axis(a, ub_rad))
            .sum()
    }
}
