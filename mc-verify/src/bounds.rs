//! The tolerance box $\mathrm{LB}_i \le |\chi_i| \le \mathrm{UB}_i$ of an allocation (paper
//! §4.2-4.3), for the angular errors of any turntable.

use crate::error::{BoundKind, McError};
use tt_core::units::RAD_PER_ARCMIN;
use tt_kinematics::Turntable;

/// Validated bounds on the magnitudes of a turntable's angular errors, radians, one pair per
/// error in the order of $\chi$ ([`Turntable::rotation_error_names`]; eq 25 for the paper's
/// table: $\Delta\phi_{y1}, \Delta\phi_{z2}, \Delta\alpha_{x1}, \Delta\alpha_{z1},
/// \Delta\alpha_{x2}, \Delta\alpha_{y2}, \Delta\varepsilon_x, \Delta\varepsilon_y$).
///
/// Invariant: one bound pair per angular error of the turntable it was made for, every bound
/// finite, $0 \le \mathrm{LB}_i \le \mathrm{UB}_i$. The error names are kept so that
/// [`crate::MonteCarlo::new`] can check that the box belongs to its turntable.
///
/// ```
/// use mc_verify::ErrorBox;
/// let table = tt_kinematics::paper::table3();
/// let b = ErrorBox::from_arcmin(&table, vec![0.0; 8], vec![0.5; 8])?;
/// assert_eq!(b.names()[1], "dphi_z2");
/// let e = ErrorBox::from_upper_rad(&table, vec![1e-4; 7]).unwrap_err();
/// assert!(e.to_string().contains("(8), got 7"));
/// # Ok::<(), mc_verify::McError>(())
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct ErrorBox {
    names: Vec<String>,
    lb_rad: Vec<f64>,
    ub_rad: Vec<f64>,
}

impl ErrorBox {
    /// Bounds in radians, one pair per angular error of `turntable` (order of $\chi$).
    ///
    /// # Errors
    /// [`McError::BoundsLength`] for a list of the wrong length; [`McError::NonFiniteBound`],
    /// [`McError::NegativeBound`] and [`McError::LowerAboveUpper`] naming the error (by its
    /// name in the turntable) and the bound (`LB`/`UB`) at fault.
    pub fn new(turntable: &Turntable, lb_rad: Vec<f64>, ub_rad: Vec<f64>) -> Result<Self, McError> {
        let names: Vec<String> = turntable
            .rotation_error_names()
            .into_iter()
            .map(str::to_string)
            .collect();
        validate(&names, &lb_rad, &ub_rad)?;
        Ok(Self {
            names,
            lb_rad,
            ub_rad,
        })
    }

    /// Bounds in radians of errors called `names` (any model's, in its order of $\chi$; lower
    /// case, as every name of the workspace): no turntable needed.
    ///
    /// # Errors
    /// As [`ErrorBox::new`].
    pub fn with_names(
        names: Vec<String>,
        lb_rad: Vec<f64>,
        ub_rad: Vec<f64>,
    ) -> Result<Self, McError> {
        validate(&names, &lb_rad, &ub_rad)?;
        Ok(Self {
            names,
            lb_rad,
            ub_rad,
        })
    }

    /// Upper bounds in radians with every lower bound zero (the paper does not print its
    /// lower bounds; NOTES item 11).
    ///
    /// # Errors
    /// As [`ErrorBox::new`].
    pub fn from_upper_rad(turntable: &Turntable, ub_rad: Vec<f64>) -> Result<Self, McError> {
        let lb = vec![0.0; ub_rad.len()];
        Self::new(turntable, lb, ub_rad)
    }

    /// Bounds in arcminutes (the unit of Table 4).
    ///
    /// # Errors
    /// As [`ErrorBox::new`], reporting the caller's values (arcmin).
    pub fn from_arcmin(
        turntable: &Turntable,
        lb_arcmin: Vec<f64>,
        ub_arcmin: Vec<f64>,
    ) -> Result<Self, McError> {
        // Validate before scaling so that the error reports the caller's value.
        let b = Self::new(turntable, lb_arcmin, ub_arcmin)?;
        Self::new(
            turntable,
            b.lb_rad.iter().map(|x| x * RAD_PER_ARCMIN).collect(),
            b.ub_rad.iter().map(|x| x * RAD_PER_ARCMIN).collect(),
        )
    }

    /// Lower bounds, rad, order of $\chi$.
    #[must_use]
    pub fn lb_rad(&self) -> &[f64] {
        &self.lb_rad
    }

    /// Upper bounds, rad, order of $\chi$.
    #[must_use]
    pub fn ub_rad(&self) -> &[f64] {
        &self.ub_rad
    }

    /// The names of the angular errors (those of the turntable the box was made for).
    #[must_use]
    pub fn names(&self) -> &[String] {
        &self.names
    }

    /// Number of angular errors.
    #[must_use]
    pub fn len(&self) -> usize {
        self.ub_rad.len()
    }

    /// Whether the box has no error (a turntable without angular errors).
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.ub_rad.is_empty()
    }

    /// $\max_i \mathrm{UB}_i$, rad (0 for an empty box).
    #[must_use]
    pub fn max_ub_rad(&self) -> f64 {
        self.ub_rad.iter().fold(0.0_f64, |m, &x| m.max(x))
    }

    /// $S = \sum_i \mathrm{UB}_i$, rad: a bound on the rotation angle of $\Delta\mathbf R$.
    #[must_use]
    pub fn sum_ub_rad(&self) -> f64 {
        self.ub_rad.iter().sum()
    }

    /// Whether every lower bound is zero.
    #[must_use]
    pub(crate) fn lower_bounds_are_zero(&self) -> bool {
        self.lb_rad.iter().all(|&lb| lb == 0.0)
    }
}

fn validate(names: &[String], lb: &[f64], ub: &[f64]) -> Result<(), McError> {
    for (kind, v) in [(BoundKind::Lower, lb), (BoundKind::Upper, ub)] {
        if v.len() != names.len() {
            return Err(McError::BoundsLength {
                kind,
                expected: names.len(),
                found: v.len(),
            });
        }
    }
    for (i, name) in names.iter().enumerate() {
        for (kind, value) in [(BoundKind::Lower, lb[i]), (BoundKind::Upper, ub[i])] {
            if !value.is_finite() {
                return Err(McError::NonFiniteBound {
                    component: name.clone(),
                    kind,
                    value,
                });
            }
            if value < 0.0 {
                return Err(McError::NegativeBound {
                    component: name.clone(),
                    kind,
                    value,
                });
            }
        }
        if lb[i] > ub[i] {
            return Err(McError::LowerAboveUpper {
                component: name.clone(),
                lb: lb[i],
                ub: ub[i],
            });
        }
    }
    Ok(())
}
