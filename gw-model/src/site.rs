//! Test site and the inputs a sensor feels at an orientation, with or without an orientation
//! error (eq 3, 7, 8).

use crate::error::{ModelError, finite, positive};
use nalgebra::{Matrix3, Rotation3, Vector3};

/// Where the test runs: latitude and earth rotation rate.
///
/// The base frame is north-west-up (§2.1: "the initial orientation of the GyroWheel axes is
/// north-west-up"): $x$ north, $y$ west, $z$ up.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Site {
    latitude_rad: f64,
    earth_rate_rad_per_s: f64,
}

impl Site {
    /// From a latitude in radians and an earth rate in rad/s.
    ///
    /// # Errors
    /// [`ModelError::LatitudeOutOfRange`] outside $[-\pi/2, \pi/2]$; [`ModelError::NonFinite`] or
    /// [`ModelError::NonPositive`] naming `latitude` or `earth_rate`.
    pub fn new(latitude_rad: f64, earth_rate_rad_per_s: f64) -> Result<Self, ModelError> {
        finite("latitude", latitude_rad)?;
        if latitude_rad.abs() > std::f64::consts::FRAC_PI_2 {
            return Err(ModelError::LatitudeOutOfRange {
                latitude_deg: latitude_rad.to_degrees(),
            });
        }
        Ok(Self {
            latitude_rad,
            earth_rate_rad_per_s: positive("earth_rate", earth_rate_rad_per_s)?,
        })
    }

    /// From a latitude in degrees (north positive) and an earth rate in rad/s.
    ///
    /// # Errors
    /// As [`Site::new`].
    pub fn from_deg(latitude_deg: f64, earth_rate_rad_per_s: f64) -> Result<Self, ModelError> {
        finite("latitude", latitude_deg)?;
        Self::new(latitude_deg.to_radians(), earth_rate_rad_per_s)
    }

    /// Latitude, radians.
    #[must_use]
    pub fn latitude_rad(&self) -> f64 {
        self.latitude_rad
    }

    /// Latitude, degrees.
    #[must_use]
    pub fn latitude_deg(&self) -> f64 {
        self.latitude_rad.to_degrees()
    }

    /// Earth rotation rate, rad/s.
    #[must_use]
    pub fn earth_rate_rad_per_s(&self) -> f64 {
        self.earth_rate_rad_per_s
    }

    /// The specific force felt at rest (reaction to gravity) in the base frame, in g: $(0, 0, 1)$.
    #[must_use]
    pub fn specific_force_base_g(&self) -> Vector3<f64> {
        Vector3::z()
    }

    /// Earth rate in the base frame (north-west-up): $\omega_e(\cos\lambda, 0, \sin\lambda)$.
    #[must_use]
    pub fn earth_rate_base_rad_per_s(&self) -> Vector3<f64> {
        let (s, c) = self.latitude_rad.sin_cos();
        self.earth_rate_rad_per_s * Vector3::new(c, 0.0, s)
    }

    /// The inputs at the intended orientation `base_from_sensor` ($\mathbf R_d$, sensor frame to
    /// base frame, from a turntable pose).
    ///
    /// # Formula
    /// $\mathbf a = \mathbf R_d^T (0,0,1)^T$, $\boldsymbol\omega = \mathbf R_d^T \omega_e
    /// (\cos\lambda, 0, \sin\lambda)^T$. For the paper's $\mathbf R_d = R_y(\phi_1)R_z(\phi_2)$
    /// this is, component by component, eq 3:
    /// $$a_x = -\sin\phi_1\cos\phi_2,\ a_y = \sin\phi_1\sin\phi_2,\ a_z = \cos\phi_1,$$
    /// $$\omega_x = \omega_e\cos\phi_2\cos(\phi_1+\lambda),\
    ///   \omega_y = -\omega_e\sin\phi_2\cos(\phi_1+\lambda),\
    ///   \omega_z = \omega_e\sin(\phi_1+\lambda).$$
    ///
    /// # Reference
    /// Eq 3 (and eq 21 for $\mathbf R_d$).
    #[must_use]
    pub fn inputs(&self, base_from_sensor: &Matrix3<f64>) -> Inputs {
        let r_t = base_from_sensor.transpose();
        Inputs {
            specific_force_g: r_t * self.specific_force_base_g(),
            rate_rad_per_s: r_t * self.earth_rate_base_rad_per_s(),
        }
    }

    /// The inputs at an orientation that differs from the intended `base_from_sensor` by
    /// $\Delta\mathbf R = \mathbf R_d^T \mathbf R_t$ (the sensor-frame matrix of eq 7/23).
    ///
    /// # Formula
    /// $$[\omega_x'\ \omega_y'\ \omega_z'] = [\omega_x\ \omega_y\ \omega_z]\,\Delta\mathbf R,
    ///   \qquad [a_x'\ a_y'\ a_z'] = [a_x\ a_y\ a_z]\,\Delta\mathbf R,$$
    /// i.e. $\mathbf v' = \Delta\mathbf R^T \mathbf R_d^T \mathbf v_{base} = \mathbf R_t^T
    /// \mathbf v_{base}$. `delta_r` need not be orthonormal (eq 7 is not).
    ///
    /// # Reference
    /// Eq 8 (with eq 7 or eq 23 for $\Delta\mathbf R$).
    #[must_use]
    pub fn inputs_with_error(
        &self,
        base_from_sensor: &Matrix3<f64>,
        delta_r: &Matrix3<f64>,
    ) -> Inputs {
        self.inputs(base_from_sensor).rotated(delta_r)
    }
}

/// Sensor-frame inputs at one orientation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Inputs {
    /// Specific force (reaction to gravity), g: $(a_x, a_y, a_z)$.
    pub specific_force_g: Vector3<f64>,
    /// Angular rate (earth rate), rad/s: $(\omega_x, \omega_y, \omega_z)$.
    pub rate_rad_per_s: Vector3<f64>,
}

impl Inputs {
    /// The inputs seen from a frame turned by $\Delta\mathbf R$ (eq 8): $\mathbf v' =
    /// \Delta\mathbf R^T\mathbf v$ for both vectors.
    #[must_use]
    pub fn rotated(&self, delta_r: &Matrix3<f64>) -> Self {
        let t = delta_r.transpose();
        Self {
            specific_force_g: t * self.specific_force_g,
            rate_rad_per_s: t * self.rate_rad_per_s,
        }
    }
}

/// How a triple of orientation-error angles becomes a matrix $\Delta\mathbf R$.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum DeltaRKind {
    /// The printed small-angle matrix of eq 7, $I + [\boldsymbol\delta]_\times$ (not orthonormal).
    /// The default: it is what the paper uses.
    #[default]
    SmallAngle,
    /// The exact rotation $\exp([\boldsymbol\delta]_\times)$ with the rotation vector
    /// $\boldsymbol\delta = (\Delta\gamma, \Delta\psi, \Delta\theta)$ (about $x$, $y$, $z$); it
    /// equals eq 7 to first order and needs no choice of rotation order.
    Exact,
}

impl DeltaRKind {
    /// `"small-angle"` or `"exact"`.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            DeltaRKind::SmallAngle => "small-angle",
            DeltaRKind::Exact => "exact",
        }
    }
}

/// The orientation error of the sensor axes: $\Delta\psi$ about $y$, $\Delta\theta$ about $z$,
/// $\Delta\gamma$ about $x$ (§2.2, Figure 3), radians.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct OrientationAngles {
    /// $\Delta\psi$, rotation error about $y$, rad.
    pub delta_psi_rad: f64,
    /// $\Delta\theta$, rotation error about $z$, rad.
    pub delta_theta_rad: f64,
    /// $\Delta\gamma$, rotation error about $x$, rad.
    pub delta_gamma_rad: f64,
}

impl OrientationAngles {
    /// No orientation error.
    pub const ZERO: Self = Self {
        delta_psi_rad: 0.0,
        delta_theta_rad: 0.0,
        delta_gamma_rad: 0.0,
    };

    /// From radians.
    ///
    /// # Errors
    /// [`ModelError::NonFinite`] naming `delta_psi`, `delta_theta` or `delta_gamma`.
    pub fn new(
        delta_psi_rad: f64,
        delta_theta_rad: f64,
        delta_gamma_rad: f64,
    ) -> Result<Self, ModelError> {
        Ok(Self {
            delta_psi_rad: finite("delta_psi", delta_psi_rad)?,
            delta_theta_rad: finite("delta_theta", delta_theta_rad)?,
            delta_gamma_rad: finite("delta_gamma", delta_gamma_rad)?,
        })
    }

    /// From degrees.
    ///
    /// # Errors
    /// As [`OrientationAngles::new`].
    pub fn from_deg(
        delta_psi_deg: f64,
        delta_theta_deg: f64,
        delta_gamma_deg: f64,
    ) -> Result<Self, ModelError> {
        Self::new(
            finite("delta_psi", delta_psi_deg)?.to_radians(),
            finite("delta_theta", delta_theta_deg)?.to_radians(),
            finite("delta_gamma", delta_gamma_deg)?.to_radians(),
        )
    }

    /// The rotation vector $(\Delta\gamma, \Delta\psi, \Delta\theta)$ (about $x$, $y$, $z$), rad.
    #[must_use]
    pub fn rotation_vector(&self) -> Vector3<f64> {
        Vector3::new(
            self.delta_gamma_rad,
            self.delta_psi_rad,
            self.delta_theta_rad,
        )
    }

    /// The orientation-error matrix $\Delta\mathbf R$.
    ///
    /// # Formula
    /// Small angle (eq 7):
    /// $$\Delta\mathbf R = \begin{bmatrix} 1 & -\Delta\theta & \Delta\psi \\ \Delta\theta & 1 &
    ///   -\Delta\gamma \\ -\Delta\psi & \Delta\gamma & 1 \end{bmatrix};$$
    /// exact: $\exp$ of the same skew-symmetric part.
    ///
    /// # Reference
    /// Eq 7.
    #[must_use]
    pub fn delta_r(&self, kind: DeltaRKind) -> Matrix3<f64> {
        let w = self.rotation_vector();
        match kind {
            DeltaRKind::SmallAngle => Matrix3::identity() + w.cross_matrix(),
            DeltaRKind::Exact => Rotation3::new(w).into_inner(),
        }
    }
}
