//! The tolerance box $\mathrm{LB}_i \le |\chi_i| \le \mathrm{UB}_i$ of an allocation (paper §4.2-4.3).

use crate::error::{BoundKind, McError};
use tt_kinematics::units::RAD_PER_ARCMIN;
use tt_kinematics::{CHI_LEN, ErrorComponent};

/// Validated bounds on the magnitudes of the eight angular errors, radians, in the order of
/// $\chi$ (eq 25): $\Delta\phi_{y1}, \Delta\phi_{z2}, \Delta\alpha_{x1}, \Delta\alpha_{z1},
/// \Delta\alpha_{x2}, \Delta\alpha_{y2}, \Delta\varepsilon_x, \Delta\varepsilon_y$.
///
/// Invariant: every bound is finite, $0 \le \mathrm{LB}_i \le \mathrm{UB}_i$.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ErrorBox {
    lb_rad: [f64; CHI_LEN],
    ub_rad: [f64; CHI_LEN],
}

impl ErrorBox {
    /// Bounds in radians. Errors name the component and the bound (`LB`/`UB`) at fault.
    pub fn new(lb_rad: [f64; CHI_LEN], ub_rad: [f64; CHI_LEN]) -> Result<Self, McError> {
        for c in ErrorComponent::ALL {
            let i = c.index();
            for (kind, value) in [(BoundKind::Lower, lb_rad[i]), (BoundKind::Upper, ub_rad[i])] {
                if !value.is_finite() {
                    return Err(McError::NonFiniteBound {
                        component: c.name(),
                        kind,
                        value,
                    });
                }
                if value < 0.0 {
                    return Err(McError::NegativeBound {
                        component: c.name(),
                        kind,
                        value,
                    });
                }
            }
            if lb_rad[i] > ub_rad[i] {
                return Err(McError::LowerAboveUpper {
                    component: c.name(),
                    lb_rad: lb_rad[i],
                    ub_rad: ub_rad[i],
                });
            }
        }
        Ok(Self { lb_rad, ub_rad })
    }

    /// Upper bounds in radians with every lower bound zero (the paper does not print its
    /// lower bounds; NOTES item 11).
    pub fn from_upper_rad(ub_rad: [f64; CHI_LEN]) -> Result<Self, McError> {
        Self::new([0.0; CHI_LEN], ub_rad)
    }

    /// Bounds in arcminutes (the unit of Table 4).
    pub fn from_arcmin(
        lb_arcmin: [f64; CHI_LEN],
        ub_arcmin: [f64; CHI_LEN],
    ) -> Result<Self, McError> {
        // Validate before scaling so that the error reports the caller's value.
        Self::new(lb_arcmin, ub_arcmin)?;
        Self::new(
            lb_arcmin.map(|x| x * RAD_PER_ARCMIN),
            ub_arcmin.map(|x| x * RAD_PER_ARCMIN),
        )
    }

    /// Lower bounds, rad.
    #[must_use]
    pub fn lb_rad(&self) -> [f64; CHI_LEN] {
        self.lb_rad
    }

    /// Upper bounds, rad.
    #[must_use]
    pub fn ub_rad(&self) -> [f64; CHI_LEN] {
        self.ub_rad
    }

    /// $\max_i \mathrm{UB}_i$, rad.
    #[must_use]
    pub fn max_ub_rad(&self) -> f64 {
        self.ub_rad.iter().fold(0.0_f64, |m, &x| m.max(x))
    }

    /// $S = \sum_i \mathrm{UB}_i$, rad: a bound on the rotation angle of $\Delta\mathbf R$.
    #[must_use]
    pub fn sum_ub_rad(&self) -> f64 {
        self.ub_rad.iter().sum()
    }
}
