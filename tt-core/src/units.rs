//! Unit conversions used at the edges (radians, rad/s and g inside every crate).
//!
//! Degrees, arcminutes, arcseconds and deg/h appear only in study files, flags, reports and
//! constructor or accessor names that say so; these are the only conversions.

/// Radians in one degree.
pub const RAD_PER_DEG: f64 = std::f64::consts::PI / 180.0;
/// Radians in one arcminute.
pub const RAD_PER_ARCMIN: f64 = RAD_PER_DEG / 60.0;
/// Radians in one arcsecond.
pub const RAD_PER_ARCSEC: f64 = RAD_PER_DEG / 3600.0;
/// One degree per hour in rad/s: $\pi / (180 \cdot 3600)$.
pub const RAD_PER_S_PER_DEG_PER_H: f64 = std::f64::consts::PI / 180.0 / 3600.0;

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

/// An allocation objective $J = \sum_i w_i/\mathrm{UB}_i^2$ (eq 34) from rad⁻² to
/// arcmin⁻², the unit every report and command prints it in.
///
/// # Formula
/// $J_{\mathrm{arcmin}} = J_{\mathrm{rad}} \cdot r^2$ with $r$ the radians in one arcminute
/// ([`RAD_PER_ARCMIN`]): a bound of $u$ rad is $u/r$ arcmin, so $1/u^2$ becomes $r^2/u^2$.
#[must_use]
pub fn objective_to_arcmin(objective_per_rad2: f64) -> f64 {
    objective_per_rad2 * RAD_PER_ARCMIN * RAD_PER_ARCMIN
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    /// Relative tolerance of a round trip through one multiplication and one division
    /// (dimensionless, a few ulp).
    const ROUND_TRIP_REL: f64 = 4.0 * f64::EPSILON;

    #[test]
    fn conversions_round_trip_and_agree_with_std() {
        for x in [1e-9, 0.03, 1.0, 52.5, 360.0] {
            assert_relative_eq!(rad_to_deg(deg_to_rad(x)), x, max_relative = ROUND_TRIP_REL);
            assert_relative_eq!(
                rad_to_arcmin(arcmin_to_rad(x)),
                x,
                max_relative = ROUND_TRIP_REL
            );
            assert_relative_eq!(
                rad_to_arcsec(arcsec_to_rad(x)),
                x,
                max_relative = ROUND_TRIP_REL
            );
            assert_relative_eq!(
                rad_per_s_to_deg_per_h(deg_per_h_to_rad_per_s(x)),
                x,
                max_relative = ROUND_TRIP_REL
            );
            assert_relative_eq!(deg_to_rad(x), x.to_radians(), max_relative = ROUND_TRIP_REL);
        }
        assert_relative_eq!(
            arcmin_to_rad(60.0),
            deg_to_rad(1.0),
            max_relative = ROUND_TRIP_REL
        );
    }

    /// J of one bound of 1 arcmin with unit weight is 1 arcmin^-2.
    #[test]
    fn objective_of_one_arcminute_bound_is_one_per_square_arcminute() {
        let ub = arcmin_to_rad(1.0);
        assert_relative_eq!(
            objective_to_arcmin(1.0 / (ub * ub)),
            1.0,
            max_relative = ROUND_TRIP_REL
        );
    }
}
