//! Test site and the inputs a sensor feels at an orientation, with or without an orientation
//! error (eq 3, 7, 8).

use crate::error::{ModelError, finite, positive};
use nalgebra::{Matrix3, Vector3};

/// Earth rotation rate of WGS-84, rad/s (NIMA TR8350.2, $\omega_e = 7.292\,115\,9 \times 10^{-5}$).
pub const WGS84_EARTH_RATE_RAD_PER_S: f64 = 7.292_115_9e-5;

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
    /// [`ModelError::LatitudeOutOfRange`] outside $[-\pi/2, \pi/2]$; [`ModelError::Field`] (not finite,
    /// not positive) naming `latitude` or `earth_rate`.
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
