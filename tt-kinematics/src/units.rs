//! Angle unit conversions used at the crate's edges (radians inside).

/// Radians in one degree.
pub const RAD_PER_DEG: f64 = std::f64::consts::PI / 180.0;
/// Radians in one arcminute.
pub const RAD_PER_ARCMIN: f64 = RAD_PER_DEG / 60.0;
/// Radians in one arcsecond.
pub const RAD_PER_ARCSEC: f64 = RAD_PER_DEG / 3600.0;

/// Degrees to radians.
#[must_use]
pub fn deg_to_rad(deg: f64) -> f64 {
    deg * RAD_PER_DEG
}
/// Radians to degrees.
#[must_use]
pub fn rad_to_deg(rad: f64) -> f64 {
    rad / RAD_PER_DEG
}
/// Arcminutes to radians.
#[must_use]
pub fn arcmin_to_rad(arcmin: f64) -> f64 {
    arcmin * RAD_PER_ARCMIN
}
/// Radians to arcminutes.
#[must_use]
pub fn rad_to_arcmin(rad: f64) -> f64 {
    rad / RAD_PER_ARCMIN
}
/// Arcseconds to radians.
#[must_use]
pub fn arcsec_to_rad(arcsec: f64) -> f64 {
    arcsec * RAD_PER_ARCSEC
}
/// Radians to arcseconds.
#[must_use]
pub fn rad_to_arcsec(rad: f64) -> f64 {
    rad / RAD_PER_ARCSEC
}
