//! Turntable errors (the values of the errors of a description); the poses they act at are
//! [`tt_core::Pose`].

use crate::error::{KinematicsError, finite};
use tt_core::units::RAD_PER_ARCMIN;

/// The values of a turntable's errors: the angular errors $\chi$ (radians, in the
/// description's error order, eq 25 for the paper) and the error translations (metres).
///
/// Invariant: every value is finite (checked by the constructors). Lengths are checked against
/// a turntable when it is used.
#[derive(Debug, Clone, PartialEq)]
pub struct TurntableErrors {
    chi_rad: Vec<f64>,
    translations_m: Vec<f64>,
}

impl TurntableErrors {
    /// From $\chi$ in radians and the translations in metres.
    ///
    /// # Errors
    /// [`tt_core::FieldError::NonFinite`] naming `chi[k]` or `translations[k]`.
    pub fn new(chi_rad: Vec<f64>, translations_m: Vec<f64>) -> Result<Self, KinematicsError> {
        for (k, &v) in chi_rad.iter().enumerate() {
            finite(format!("chi[{k}]"), v)?;
        }
        for (k, &v) in translations_m.iter().enumerate() {
            finite(format!("translations[{k}]"), v)?;
        }
        Ok(Self {
            chi_rad,
            translations_m,
        })
    }

    /// From $\chi$ in arcminutes (the unit of Table 4) and the translations in millimetres.
    ///
    /// # Errors
    /// As [`TurntableErrors::new`] (the value reported in the caller's unit).
    pub fn from_arcmin(
        chi_arcmin: &[f64],
        translations_mm: &[f64],
    ) -> Result<Self, KinematicsError> {
        Self::new(chi_arcmin.to_vec(), translations_mm.to_vec())?;
        Self::new(
            chi_arcmin.iter().map(|v| v * RAD_PER_ARCMIN).collect(),
            translations_mm.iter().map(|v| v * 1e-3).collect(),
        )
    }

    /// All errors zero for `n_chi` angular errors and `n_translations` translations.
    #[must_use]
    pub fn zero(n_chi: usize, n_translations: usize) -> Self {
        Self {
            chi_rad: vec![0.0; n_chi],
            translations_m: vec![0.0; n_translations],
        }
    }

    /// $\chi$, radians.
    #[must_use]
    pub fn chi_rad(&self) -> &[f64] {
        &self.chi_rad
    }

    /// The error translations, metres.
    #[must_use]
    pub fn translations_m(&self) -> &[f64] {
        &self.translations_m
    }

    /// The same errors with angular error `k` replaced (radians).
    ///
    /// # Errors
    /// [`tt_core::FieldError::NonFinite`] for a non-finite value; [`tt_core::FieldError::Length`] when
    /// `k` is out of range.
    pub fn with_chi(mut self, k: usize, value_rad: f64) -> Result<Self, KinematicsError> {
        let n = self.chi_rad.len();
        let slot = self.chi_rad.get_mut(k).ok_or(tt_core::FieldError::Length {
            field: "chi index".into(),
            expected: n,
            found: k,
        })?;
        *slot = finite(format!("chi[{k}]"), value_rad)?;
        Ok(self)
    }

    /// The same angular errors with other translations (metres).
    ///
    /// # Errors
    /// [`tt_core::FieldError::NonFinite`] naming `translations[k]`.
    pub fn with_translations_m(self, translations_m: Vec<f64>) -> Result<Self, KinematicsError> {
        Self::new(self.chi_rad, translations_m)
    }

    /// $\max_i |\chi_i|$, radians.
    #[must_use]
    pub fn max_abs_rad(&self) -> f64 {
        self.chi_rad.iter().fold(0.0_f64, |m, x| m.max(x.abs()))
    }

    /// $\sum_i |\chi_i|$, radians: a bound on the rotation angle of $\Delta\mathbf R$.
    #[must_use]
    pub fn l1_rad(&self) -> f64 {
        self.chi_rad.iter().map(|x| x.abs()).sum()
    }
}
