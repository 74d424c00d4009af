//! The rate-sensing model of eq 1 and the coefficient set of Table 1.

use crate::error::{ModelError, finite, positive};
use crate::site::Inputs;
use crate::units::{deg_per_h_to_rad_per_s, rad_per_s_to_deg_per_h};
use nalgebra::Vector3;

/// Number of drift coefficients of one sensing axis (eq 1).
pub const N_COEFFICIENTS: usize = 7;

/// A rate-sensing axis of the GyroWheel.
///
/// The $x$ axis senses $\omega_x$ through the torque-coil current $i_y$; the $y$ axis senses
/// $\omega_y$ through $i_x$ (eq 1).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum SensingAxis {
    /// Senses $\omega_x$; output $k_y i_y$.
    X,
    /// Senses $\omega_y$; output $k_x i_x$.
    Y,
}

impl SensingAxis {
    /// Both axes, $x$ first.
    pub const ALL: [SensingAxis; 2] = [SensingAxis::X, SensingAxis::Y];

    /// `"x"` or `"y"`.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            SensingAxis::X => "x",
            SensingAxis::Y => "y",
        }
    }

    /// The coefficient names of this axis as printed in eq 1, in the order of the unknown vector
    /// $\boldsymbol\beta$ (eq 2, corrected per NOTES item 2).
    ///
    /// The last $y$ coefficient is $D(y)_{yx}$ (eq 1). Table 1 prints it as "$D(y)_{xy}$ = 47.8";
    /// both names denote the coefficient of $a_x a_y$ in the $y$-axis model: the same
    /// coefficient.
    #[must_use]
    pub fn coefficient_names(self) -> [&'static str; N_COEFFICIENTS] {
        match self {
            SensingAxis::X => [
                "D(x)_F", "D(x)_x", "D(x)_y", "D(x)_z", "D(x)_xx", "D(x)_zz", "D(x)_xy",
            ],
            SensingAxis::Y => [
                "D(y)_F", "D(y)_x", "D(y)_y", "D(y)_z", "D(y)_yy", "D(y)_zz", "D(y)_yx",
            ],
        }
    }

    /// The unit of each coefficient as printed in Table 1, in the order of
    /// [`coefficient_names`](Self::coefficient_names).
    #[must_use]
    pub fn coefficient_units(self) -> [&'static str; N_COEFFICIENTS] {
        [
            "deg/h",
            "deg/h/g",
            "deg/h/g",
            "deg/h/g",
            "deg/h/g^2",
            "deg/h/g^2",
            "deg/h/g^2",
        ]
    }

    /// The component of a body-frame rate this axis senses ($\omega_x$ or $\omega_y$).
    #[must_use]
    pub fn rate_component(self, rate: &Vector3<f64>) -> f64 {
        match self {
            SensingAxis::X => rate.x,
            SensingAxis::Y => rate.y,
        }
    }
}

/// The regressor row of one axis at a specific force $\mathbf a$ (in g): the row of $\mathbf A$ in
/// eq 2/5.
///
/// # Formula
/// $$x:\ [1,\ a_x,\ a_y,\ a_z,\ a_x^2,\ a_z^2,\ a_x a_y], \qquad
///   y:\ [1,\ a_x,\ a_y,\ a_z,\ a_y^2,\ a_z^2,\ a_x a_y].$$
///
/// # Reference
/// Eq 1-2 (the printed eq 2 lists $D(x)_y$ twice and drops $D(x)_F$; NOTES item 2).
#[must_use]
pub fn regressors(axis: SensingAxis, a: &Vector3<f64>) -> [f64; N_COEFFICIENTS] {
    let quad = match axis {
        SensingAxis::X => a.x * a.x,
        SensingAxis::Y => a.y * a.y,
    };
    [1.0, a.x, a.y, a.z, quad, a.z * a.z, a.x * a.y]
}

/// The seven drift coefficients of one axis, stored in rad/s, rad/s/g and rad/s/g^2.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AxisCoefficients {
    axis: SensingAxis,
    values: [f64; N_COEFFICIENTS],
}

impl AxisCoefficients {
    /// From values in rad/s, rad/s/g, rad/s/g^2, in the order of
    /// [`SensingAxis::coefficient_names`].
    ///
    /// # Errors
    /// [`ModelError::NonFinite`] naming the first non-finite coefficient.
    pub fn from_rad_per_s(
        axis: SensingAxis,
        values: [f64; N_COEFFICIENTS],
    ) -> Result<Self, ModelError> {
        for (name, v) in axis.coefficient_names().iter().zip(values) {
            finite(name, v)?;
        }
        Ok(Self { axis, values })
    }

    /// From values in deg/h, deg/h/g, deg/h/g^2 (the units of Table 1).
    ///
    /// # Errors
    /// [`ModelError::NonFinite`] naming the first non-finite coefficient.
    pub fn from_deg_per_h(
        axis: SensingAxis,
        values_deg_per_h: [f64; N_COEFFICIENTS],
    ) -> Result<Self, ModelError> {
        Self::from_rad_per_s(axis, values_deg_per_h.map(deg_per_h_to_rad_per_s))
    }

    /// The axis these coefficients belong to.
    #[must_use]
    pub fn axis(&self) -> SensingAxis {
        self.axis
    }

    /// Values in rad/s, rad/s/g, rad/s/g^2.
    #[must_use]
    pub fn rad_per_s(&self) -> [f64; N_COEFFICIENTS] {
        self.values
    }

    /// Values in deg/h, deg/h/g, deg/h/g^2.
    #[must_use]
    pub fn deg_per_h(&self) -> [f64; N_COEFFICIENTS] {
        self.values.map(rad_per_s_to_deg_per_h)
    }

    /// The drift $\sum_j D_j r_j(\mathbf a)$ at a specific force (rad/s): the terms of eq 1
    /// after the rate.
    #[must_use]
    pub fn drift_rad_per_s(&self, a: &Vector3<f64>) -> f64 {
        regressors(self.axis, a)
            .iter()
            .zip(self.values)
            .map(|(r, d)| r * d)
            .sum()
    }

    /// The output $k\,i$ (rad/s) of this axis for the given body-frame inputs.
    ///
    /// # Formula
    /// Eq 1 solved for the output, e.g. for $x$:
    /// $$k_y i_y = \omega_x + D(x)_F + D(x)_x a_x + D(x)_y a_y + D(x)_z a_z + D(x)_{xx} a_x^2 +
    ///   D(x)_{zz} a_z^2 + D(x)_{xy} a_x a_y.$$
    ///
    /// # Reference
    /// Eq 1.
    #[must_use]
    pub fn output_rad_per_s(&self, inputs: &Inputs) -> f64 {
        self.axis.rate_component(&inputs.rate_rad_per_s)
            + self.drift_rad_per_s(&inputs.specific_force_g)
    }
}

/// The drift coefficients of both axes (eq 1).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DriftCoefficients {
    /// The $x$ axis ($D(x)_\cdot$).
    pub x: AxisCoefficients,
    /// The $y$ axis ($D(y)_\cdot$).
    pub y: AxisCoefficients,
}

impl DriftCoefficients {
    /// Table 1 of the paper, "Nominal values of calibration coefficients", values and units
    /// exactly as printed (deg/h, deg/h/g, deg/h/g^2).
    ///
    /// | $x$ | value | $y$ | value |
    /// |---|---|---|---|
    /// | $D(x)_F$ (deg/h) | -93.3 | $D(y)_F$ (deg/h) | 105.3 |
    /// | $D(x)_x$ (deg/h/g) | -43.2 | $D(y)_x$ (deg/h/g) | 2.2 |
    /// | $D(x)_y$ (deg/h/g) | 3.5 | $D(y)_y$ (deg/h/g) | -33.2 |
    /// | $D(x)_z$ (deg/h/g) | -1.2 | $D(y)_z$ (deg/h/g) | -0.1 |
    /// | $D(x)_{xx}$ (deg/h/g²) | 2.1 | $D(y)_{yy}$ (deg/h/g²) | -10.6 |
    /// | $D(x)_{zz}$ (deg/h/g²) | -0.089 | $D(y)_{zz}$ (deg/h/g²) | -10.38 |
    /// | $D(x)_{xy}$ (deg/h/g²) | 17.4 | $D(y)_{yx}$ (deg/h/g²) | 47.8 |
    ///
    /// Table 1 labels the last $y$ entry "$D(y)_{xy}$"; eq 1 calls it $D(y)_{yx}$. It is the
    /// coefficient of $a_x a_y$ in the $y$-axis model either way: one coefficient, two names.
    ///
    /// # Reference
    /// Table 1 (§2.3).
    #[must_use]
    pub fn table_1() -> Self {
        Self {
            x: AxisCoefficients {
                axis: SensingAxis::X,
                values: TABLE_1_X_DEG_PER_H.map(deg_per_h_to_rad_per_s),
            },
            y: AxisCoefficients {
                axis: SensingAxis::Y,
                values: TABLE_1_Y_DEG_PER_H.map(deg_per_h_to_rad_per_s),
            },
        }
    }

    /// From both axes' values in deg/h, deg/h/g, deg/h/g^2.
    ///
    /// # Errors
    /// [`ModelError::NonFinite`] naming the first non-finite coefficient.
    pub fn from_deg_per_h(
        x: [f64; N_COEFFICIENTS],
        y: [f64; N_COEFFICIENTS],
    ) -> Result<Self, ModelError> {
        Ok(Self {
            x: AxisCoefficients::from_deg_per_h(SensingAxis::X, x)?,
            y: AxisCoefficients::from_deg_per_h(SensingAxis::Y, y)?,
        })
    }

    /// The coefficients of one axis.
    #[must_use]
    pub fn axis(&self, axis: SensingAxis) -> &AxisCoefficients {
        match axis {
            SensingAxis::X => &self.x,
            SensingAxis::Y => &self.y,
        }
    }
}

/// Table 1, $x$ axis, deg/h, deg/h/g, deg/h/g^2, in the order of eq 1.
pub const TABLE_1_X_DEG_PER_H: [f64; N_COEFFICIENTS] = [-93.3, -43.2, 3.5, -1.2, 2.1, -0.089, 17.4];

/// Table 1, $y$ axis, deg/h, deg/h/g, deg/h/g^2, in the order of eq 1 (last entry printed as
/// $D(y)_{xy}$, which is eq 1's $D(y)_{yx}$).
pub const TABLE_1_Y_DEG_PER_H: [f64; N_COEFFICIENTS] =
    [105.3, 2.2, -33.2, -0.1, -10.6, -10.38, 47.8];

/// Torque scale factors $k_x$, $k_y$ (eq 1): output rate per torque-coil current.
///
/// The paper gives no values; the analysis works with the products $k\,i$ (the vector
/// $\mathbf b_1$ of eq 4-5), so these only convert between currents and those products.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TorqueScaleFactors {
    k_x: f64,
    k_y: f64,
}

impl TorqueScaleFactors {
    /// From $k_x$, $k_y$ in rad/s per ampere.
    ///
    /// # Errors
    /// [`ModelError::NonPositive`] or [`ModelError::NonFinite`] naming `k_x` or `k_y`.
    pub fn from_rad_per_s_per_amp(k_x: f64, k_y: f64) -> Result<Self, ModelError> {
        Ok(Self {
            k_x: positive("k_x", k_x)?,
            k_y: positive("k_y", k_y)?,
        })
    }

    /// From $k_x$, $k_y$ in deg/h per ampere.
    ///
    /// # Errors
    /// As [`from_rad_per_s_per_amp`](Self::from_rad_per_s_per_amp).
    pub fn from_deg_per_h_per_amp(k_x: f64, k_y: f64) -> Result<Self, ModelError> {
        positive("k_x", k_x)?;
        positive("k_y", k_y)?;
        Self::from_rad_per_s_per_amp(deg_per_h_to_rad_per_s(k_x), deg_per_h_to_rad_per_s(k_y))
    }

    /// The scale factor of an axis's output: $k_y$ for the $x$ axis, $k_x$ for the $y$ axis.
    #[must_use]
    pub fn of_axis(&self, axis: SensingAxis) -> f64 {
        match axis {
            SensingAxis::X => self.k_y,
            SensingAxis::Y => self.k_x,
        }
    }

    /// The current (A) that produces an output $k\,i$ (rad/s) on an axis.
    #[must_use]
    pub fn current_amp(&self, axis: SensingAxis, output_rad_per_s: f64) -> f64 {
        output_rad_per_s / self.of_axis(axis)
    }

    /// The output $k\,i$ (rad/s) of a current (A) on an axis.
    #[must_use]
    pub fn output_rad_per_s(&self, axis: SensingAxis, current_amp: f64) -> f64 {
        current_amp * self.of_axis(axis)
    }
}
