//! Unit conversions used at the edges of the crate (degrees, deg/h).
//!
//! Inside the crate angles are radians, rates rad/s and accelerations g (standard gravity);
//! degrees and deg/h appear only in constructor and accessor names that say so.

/// One degree per hour in rad/s: $\pi / (180 \cdot 3600)$.
pub const RAD_PER_S_PER_DEG_PER_H: f64 = std::f64::consts::PI / 180.0 / 3600.0;

/// Earth rotation rate of WGS-84, rad/s (NIMA TR8350.2, $\omega_e = 7.292\,115\,9 \times 10^{-5}$).
pub const WGS84_EARTH_RATE_RAD_PER_S: f64 = 7.292_115_9e-5;

/// Degrees to radians.
#[must_use]
pub fn deg_to_rad(deg: f64) -> f64 {
    deg.to_radians()
}

/// Radians to degrees.
#[must_use]
pub fn rad_to_deg(rad: f64) -> f64 {
    rad.to_degrees()
}

/// deg/h (also deg/h/g, deg/h/g^2) to rad/s (rad/s/g, rad/s/g^2).
#[must_use]
pub fn deg_per_h_to_rad_per_s(deg_per_h: f64) -> f64 {
    deg_per_h * RAD_PER_S_PER_DEG_PER_H
}

/// rad/s (rad/s/g, rad/s/g^2) to deg/h (deg/h/g, deg/h/g^2).
#[must_use]
pub fn rad_per_s_to_deg_per_h(rad_per_s: f64) -> f64 {
    rad_per_s / RAD_PER_S_PER_DEG_PER_H
}
