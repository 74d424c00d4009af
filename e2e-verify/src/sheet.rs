//! A vendor's tolerance sheet as one validated value: the bound of every angular error, the
//! lower bounds that go with it (clamped once, here), the magnitude bounds on pairs of errors
//! (discs), the bounds of the errors only rotation exposes (translations, a joint's rate
//! accuracy and ripple) and the table's measured errors with their uncertainties.
//!
//! Every check of a sheet takes it ([`crate::VendorQuestions::check_sheet`]); the compensated check
//! takes [`ToleranceSheet::compensated`], the sheet once the measured errors are known inputs
//! of the chain (a measured error bounded by what the measurement leaves, its disc dropped).
//!
//! ```
//! use e2e_verify::sheet::{SheetEntries, ToleranceSheet};
//! let table = tt_kinematics::paper::table3();
//! let n = table.n_rotation_errors();
//! let arcmin = tt_core::units::RAD_PER_ARCMIN;
//! let entries = SheetEntries::with_bounds(&table, vec![0.4 * arcmin; n]);
//! // the study's lower bounds (here 0.5') are held within the sheet's 0.4'
//! let sheet = ToleranceSheet::new(&table, "sheet.toml", entries, &vec![0.5 * arcmin; n], vec![None; n])?;
//! assert!(sheet.lower_bounds_rad().iter().zip(sheet.upper_bounds_rad()).all(|(l, u)| l <= u));
//! // nothing measured: no compensated check
//! assert!(sheet.compensated().is_none());
//! # Ok::<(), e2e_verify::E2eError>(())
//! ```

use crate::E2eError;
use tt_kinematics::{ErrorVariation, Turntable};

/// Points per harmonic order at which a measured harmonic error is evaluated to find its
/// largest magnitude (a value it certainly reaches: a lower bound of its maximum).
const MEASURED_GRID_PER_ORDER: usize = 720;

/// A magnitude (disc) bound on two angular errors: $\sqrt{\chi_a^2 + \chi_b^2} \le w$ (a
/// vendor's wobble or perpendicularity, the magnitude of a tilt with two components).
#[derive(Debug, Clone, PartialEq)]
pub struct DiscBound {
    /// The sheet's key (`axes.phi2.wobble_arcsec`).
    pub key: String,
    /// The two errors' indices in $\chi$.
    pub errors: [usize; 2],
    /// $w$, rad.
    pub bound_rad: f64,
}

/// A sheet's entries as read from its file: the bounds of every error, before they meet the
/// study's lower bounds and measurements ([`ToleranceSheet::new`] validates them).
#[derive(Debug, Clone, PartialEq)]
pub struct SheetEntries {
    /// The data sheet's name, if given.
    pub name: Option<String>,
    /// $\mathrm{UB}_i$, rad, in the turntable's order of $\chi$.
    pub upper_bounds_rad: Vec<f64>,
    /// Translation tolerances, metres, in the turntable's order (`None` when not given).
    pub translations_m: Vec<Option<f64>>,
    /// Magnitude bounds on pairs of errors: the members' entries of `upper_bounds_rad` hold
    /// the square around the disc.
    pub discs: Vec<DiscBound>,
    /// The error model a vendor quantity implies per error (order of $\chi$); `None` for a
    /// plain per-error value.
    pub implied: Vec<Option<ErrorVariation>>,
    /// Each joint's rate accuracy bound (relative), `None` when not given.
    pub rate_accuracy: Vec<Option<f64>>,
    /// Each joint's rate ripple bound (relative, each of its two components), `None` when
    /// not given.
    pub rate_ripple: Vec<Option<f64>>,
}

impl SheetEntries {
    /// Entries that bound every angular error of `turntable` by `upper_bounds_rad` and
    /// nothing else (no name, no disc, no implied model, no translation or rate bound).
    #[must_use]
    pub fn with_bounds(turntable: &Turntable, upper_bounds_rad: Vec<f64>) -> Self {
        Self {
            name: None,
            implied: vec![None; upper_bounds_rad.len()],
            upper_bounds_rad,
            translations_m: vec![None; turntable.n_translation_errors()],
            discs: Vec::new(),
            rate_accuracy: vec![None; turntable.n_joints()],
            rate_ripple: vec![None; turntable.n_joints()],
        }
    }
}

/// A measured error of the table: the lab's measurement, a known input of the compensated
/// chain, and its uncertainty, $\lvert\chi(\phi) - m(\phi)\rvert \le u$ over the revolution.
#[derive(Debug, Clone, PartialEq)]
pub struct MeasuredError {
    /// The measurement's key as written (`compensation.measured[0].value_arcmin`), named by
    /// the errors about it.
    pub key: String,
    /// How the error varies with its shaft's angle: constant, or harmonics (the measured
    /// coefficients' layout); `any` cannot be measured.
    pub variation: ErrorVariation,
    /// The measured coefficients (rad): one constant, or $(c_0, a_{k_1}, b_{k_1}, \dots)$.
    pub coefficients_rad: Vec<f64>,
    /// The measurement uncertainty $u$ (rad), a bound over the revolution.
    pub uncertainty_rad: f64,
}

impl MeasuredError {
    /// The largest magnitude the measured error certainly reaches over the revolution (rad;
    /// on a grid of [`MEASURED_GRID_PER_ORDER`] points per order for harmonics) and an upper
    /// bound of its largest magnitude.
    fn magnitudes(&self) -> (f64, f64) {
        match &self.variation {
            ErrorVariation::Harmonics { orders, .. } => {
                let k = orders.iter().copied().max().unwrap_or(1).max(1) as usize;
                let points = MEASURED_GRID_PER_ORDER * k;
                let reached = (0..points)
                    .map(|i| {
                        let phi = std::f64::consts::TAU * i as f64 / points as f64;
                        tt_kinematics::variation::harmonic_value(
                            orders,
                            &self.coefficients_rad,
                            phi,
                        )
                        .abs()
                    })
                    .fold(0.0, f64::max);
                (
                    reached,
                    tt_kinematics::variation::sup_norm_upper(orders, &self.coefficients_rad),
                )
            }
            _ => {
                let v = self.coefficients_rad.first().map_or(0.0, |v| v.abs());
                (v, v)
            }
        }
    }
}

/// A measured error whose uncertainty exceeds the sheet's bound: compensation cannot bound it
/// better than the sheet and the measured value do.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ResidualAboveSheet {
    error: usize,
    sheet_bound_rad: f64,
    largest_measured_rad: f64,
    residual_rad: f64,
}

impl ResidualAboveSheet {
    /// The error's index in $\chi$.
    #[must_use]
    pub fn error(&self) -> usize {
        self.error
    }

    /// The sheet's bound of the error (rad).
    #[must_use]
    pub fn sheet_bound_rad(&self) -> f64 {
        self.sheet_bound_rad
    }

    /// An upper bound of the measured error's largest magnitude over the revolution (rad).
    #[must_use]
    pub fn largest_measured_rad(&self) -> f64 {
        self.largest_measured_rad
    }

    /// The bound used after compensation (rad): the sheet's plus the measured value's
    /// largest magnitude.
    #[must_use]
    pub fn residual_rad(&self) -> f64 {
        self.residual_rad
    }
}

/// A turntable's tolerance sheet, validated against the turntable and the study's lower
/// bounds and measurements ([`ToleranceSheet::new`]).
#[derive(Debug, Clone, PartialEq)]
pub struct ToleranceSheet {
    source: String,
    entries: SheetEntries,
    /// The lower bounds as given (the study's manufacturing capability).
    given_lower_bounds_rad: Vec<f64>,
    /// Each held within the sheet's bound.
    lower_bounds_rad: Vec<f64>,
    measured: Vec<Option<MeasuredError>>,
}

/// The study's lower bounds each held within the sheet's bound: a vendor's tolerance below
/// the study's manufacturing capability is the vendor's claim to check, not an error.
fn clamp_lower(lower: &[f64], upper: &[f64]) -> Vec<f64> {
    lower.iter().zip(upper).map(|(l, u)| l.min(*u)).collect()
}

impl ToleranceSheet {
    /// A sheet named `source` in messages (its path as the user gave it) for `turntable`:
    /// its `entries`, the study's lower bounds `lower_bounds_rad` (each held within the
    /// sheet's bound, here once) and the table's measured errors (order of $\chi$, `None`
    /// where not measured).
    ///
    /// # Errors
    /// An [`E2eError`] naming the entry: a length that is not the turntable's
    /// ([`E2eError::Field`], `upper_bounds`, `implied`, `translations`, `rate_accuracy`,
    /// `rate_ripple`, `lower_bounds`, `measured`), a bound that is negative or not finite
    /// (`upper_bounds.<error>`, `translations.<error>`, `rate_accuracy.<joint>`,
    /// `lower_bounds.<error>`, `<disc key>`, `<measurement key>`), a disc naming an error the
    /// turntable does not have or one error twice ([`E2eError::SheetDisc`]), a measured error
    /// whose coefficients do not fit its model or that varies as `any`
    /// ([`E2eError::MeasuredModel`]), a measured error whose magnitude somewhere on the
    /// revolution exceeds the sheet's bound: the measured table is outside its
    /// specification, which a check of the sheet assumes it meets
    /// ([`E2eError::MeasuredOutsideSheet`]).
    pub fn new(
        turntable: &Turntable,
        source: &str,
        entries: SheetEntries,
        lower_bounds_rad: &[f64],
        measured: Vec<Option<MeasuredError>>,
    ) -> Result<Self, E2eError> {
        let names = turntable.rotation_error_names();
        let n = names.len();
        let translations = turntable.translation_error_names();
        let joints = turntable.joint_names();
        tt_core::length("upper_bounds", n, entries.upper_bounds_rad.len())?;
        tt_core::length("implied", n, entries.implied.len())?;
        tt_core::length("lower_bounds", n, lower_bounds_rad.len())?;
        tt_core::length("measured", n, measured.len())?;
        tt_core::length(
            "translations",
            translations.len(),
            entries.translations_m.len(),
        )?;
        tt_core::length("rate_accuracy", joints.len(), entries.rate_accuracy.len())?;
        tt_core::length("rate_ripple", joints.len(), entries.rate_ripple.len())?;
        for (name, u) in names.iter().zip(&entries.upper_bounds_rad) {
            tt_core::non_negative(format!("upper_bounds.{name}"), *u)?;
        }
        for (name, l) in names.iter().zip(lower_bounds_rad) {
            tt_core::non_negative(format!("lower_bounds.{name}"), *l)?;
        }
        for (name, t) in translations.iter().zip(&entries.translations_m) {
            if let Some(t) = t {
                tt_core::non_negative(format!("translations.{name}"), *t)?;
            }
        }
        for (what, values) in [
            ("rate_accuracy", &entries.rate_accuracy),
            ("rate_ripple", &entries.rate_ripple),
        ] {
            for (joint, v) in joints.iter().zip(values) {
                if let Some(v) = v {
                    tt_core::non_negative(format!("{what}.{joint}"), *v)?;
                }
            }
        }
        let mut in_disc = vec![false; n];
        for d in &entries.discs {
            tt_core::non_negative(d.key.as_str(), d.bound_rad)?;
            for &e in &d.errors {
                if e >= n {
                    return Err(E2eError::SheetDisc {
                        key: d.key.clone(),
                        reason: format!(
                            "error index {e} is not an angular error of the turntable ({n} errors)"
                        ),
                    });
                }
                if in_disc[e] {
                    return Err(E2eError::SheetDisc {
                        key: d.key.clone(),
                        reason: format!("`{}` is in two discs (or twice in this one)", names[e]),
                    });
                }
                in_disc[e] = true;
            }
        }
        for (j, m) in measured.iter().enumerate() {
            let Some(m) = m else { continue };
            tt_core::non_negative(m.key.as_str(), m.uncertainty_rad)?;
            let want = match &m.variation {
                ErrorVariation::Constant => Some(1),
                ErrorVariation::Harmonics { orders, .. } => Some(1 + 2 * orders.len()),
                ErrorVariation::Any { .. } => None,
            };
            if want != Some(m.coefficients_rad.len()) {
                return Err(E2eError::MeasuredModel {
                    key: m.key.clone(),
                    error: names[j].to_string(),
                    coefficients: m.coefficients_rad.len(),
                    expected: want,
                });
            }
            for c in &m.coefficients_rad {
                tt_core::finite(m.key.as_str(), *c)?;
            }
            let (reached, _) = m.magnitudes();
            let bound = entries.upper_bounds_rad[j];
            if reached > bound {
                return Err(E2eError::MeasuredOutsideSheet {
                    key: m.key.clone(),
                    error: names[j].to_string(),
                    reached_rad: reached,
                    bound_rad: bound,
                });
            }
        }
        Ok(Self {
            source: source.to_string(),
            lower_bounds_rad: clamp_lower(lower_bounds_rad, &entries.upper_bounds_rad),
            given_lower_bounds_rad: lower_bounds_rad.to_vec(),
            entries,
            measured,
        })
    }

    /// The sheet as named in messages and outputs (its path as the user gave it).
    #[must_use]
    pub fn source(&self) -> &str {
        &self.source
    }

    /// The data sheet's name, if given.
    #[must_use]
    pub fn name(&self) -> Option<&str> {
        self.entries.name.as_deref()
    }

    /// The name shown in a heading: the data sheet's name, else its source.
    #[must_use]
    pub fn title(&self) -> &str {
        self.name().unwrap_or(&self.source)
    }

    /// $\mathrm{UB}_i$, rad, in the turntable's order of $\chi$.
    #[must_use]
    pub fn upper_bounds_rad(&self) -> &[f64] {
        &self.entries.upper_bounds_rad
    }

    /// The lower bounds (rad, order of $\chi$), each held within the sheet's bound.
    #[must_use]
    pub fn lower_bounds_rad(&self) -> &[f64] {
        &self.lower_bounds_rad
    }

    /// The magnitude bounds on pairs of errors.
    #[must_use]
    pub fn discs(&self) -> &[DiscBound] {
        &self.entries.discs
    }

    /// The magnitude bounds as (errors, $w$ in rad).
    #[must_use]
    pub fn disc_bounds(&self) -> Vec<([usize; 2], f64)> {
        self.entries
            .discs
            .iter()
            .map(|d| (d.errors, d.bound_rad))
            .collect()
    }

    /// The error model a vendor quantity implies per error (order of $\chi$), `None` for a
    /// plain per-error value.
    #[must_use]
    pub fn implied(&self) -> &[Option<ErrorVariation>] {
        &self.entries.implied
    }

    /// How each error varies with a shaft angle as far as the sheet says (order of $\chi$):
    /// the model a vendor quantity implies (a wobble or a positioning accuracy bounds an
    /// error over the revolution of its axis, `any` of the joint; an orthogonality is a
    /// constant), else `any` function of the angle of the shaft the error rides on
    /// ([`tt_kinematics::on_shafts`]): what a sheet that bounds each error over the whole
    /// revolution supports and nothing more.
    #[must_use]
    pub fn supported_model(&self, turntable: &Turntable) -> Vec<ErrorVariation> {
        let mut v = tt_kinematics::on_shafts(turntable, |j| ErrorVariation::Any {
            joint: j.to_string(),
        });
        for (x, i) in v.iter_mut().zip(&self.entries.implied) {
            if let Some(i) = i {
                x.clone_from(i);
            }
        }
        v
    }

    /// Translation bounds (m, turntable's order), `None` when not given.
    #[must_use]
    pub fn translations_m(&self) -> &[Option<f64>] {
        &self.entries.translations_m
    }

    /// Each joint's rate accuracy bound (relative), `None` when not given.
    #[must_use]
    pub fn rate_accuracy(&self) -> &[Option<f64>] {
        &self.entries.rate_accuracy
    }

    /// Each joint's rate ripple bound (relative, each component), `None` when not given.
    #[must_use]
    pub fn rate_ripple(&self) -> &[Option<f64>] {
        &self.entries.rate_ripple
    }

    /// The measured errors (order of $\chi$), `None` where not measured.
    #[must_use]
    pub fn measured(&self) -> &[Option<MeasuredError>] {
        &self.measured
    }

    /// Whether the table has a measured error.
    #[must_use]
    pub fn has_measured(&self) -> bool {
        self.measured.iter().any(Option::is_some)
    }

    /// The sheet once the measured errors are compensated (`None` when nothing is measured):
    /// a measured error is a known input of the chain, so the residual $\chi - m$ the
    /// compensated calibration sees is what matters. It is bounded by the measurement's
    /// uncertainty and, since the table is within the sheet ($\lvert\chi\rvert \le
    /// \mathrm{UB}$), by $\mathrm{UB} + \max_\phi\lvert m(\phi)\rvert$: the smaller. A
    /// measured error is then bounded by that residual, no longer by the sheet's disc (its
    /// disc is dropped); the study's lower bounds are held within the new bounds; the rest of
    /// the sheet is unchanged. Beside it, every measured error whose uncertainty exceeds the
    /// sheet's bound.
    #[must_use]
    pub fn compensated(&self) -> Option<(ToleranceSheet, Vec<ResidualAboveSheet>)> {
        if !self.has_measured() {
            return None;
        }
        let mut entries = self.entries.clone();
        let mut above = Vec::new();
        for (j, m) in self.measured.iter().enumerate() {
            let Some(m) = m else { continue };
            let ub = self.entries.upper_bounds_rad[j];
            let (_, sup_upper) = m.magnitudes();
            let residual = m.uncertainty_rad.min(ub + sup_upper);
            entries.upper_bounds_rad[j] = residual;
            if m.uncertainty_rad > ub {
                above.push(ResidualAboveSheet {
                    error: j,
                    sheet_bound_rad: ub,
                    largest_measured_rad: sup_upper,
                    residual_rad: residual,
                });
            }
        }
        entries
            .discs
            .retain(|d| d.errors.iter().all(|&j| self.measured[j].is_none()));
        let sheet = ToleranceSheet {
            source: self.source.clone(),
            lower_bounds_rad: clamp_lower(&self.given_lower_bounds_rad, &entries.upper_bounds_rad),
            given_lower_bounds_rad: self.given_lower_bounds_rad.clone(),
            entries,
            // compensated: known inputs of the chain, no longer bounded by the sheet
            measured: vec![None; self.measured.len()],
        };
        Some((sheet, above))
    }
}
