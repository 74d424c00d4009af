//! The conformance suite of [`OrientationErrorModel`], as library code: run it on your own
//! implementation (enable the `conformance` feature, as this crate's own tests do).
//!
//! Every orientation-error model must
//! 1. give no error for a perfect turntable;
//! 2. agree with its OWN first-order coefficients
//!    ([`OrientationErrorModel::first_order`]) to second order:
//!    $|f - J\chi| \le K S^2$ with $S = \sum_i |\chi_i|$ (the exact chain's remainder is at most
//!    $e^S - 1 - S \le S^2$ for $S \le \ln 2$, hence the default $K = 1$);
//! 3. be odd in $\chi$ to first order: $|f(\chi) + f(-\chi)| \le 2KS^2$;
//! 4. have first-order coefficients equal to those derived from its orientation error
//!    ([`check_derived_first_order`]: an analytic first order is checked, not trusted);
//! 5. obey the physics of any orientation error ([`check_rotation`]): its
//!    $\Delta\mathbf R$ is a rotation and its angles are read off it, to second order (a
//!    model with wrong physics fails here even with the default, derived first order);
//! 6. name as many errors as every case carries (check `error-count`);
//!
//! ([`check_model_general`], for any model, with [`cases_in`] over its joint ranges); and a
//! model of a described [`Turntable`] ([`check_model`]) must also
//! 7. not depend on the joints that come before the first error (they cancel from
//!    $\mathbf R_d^T\mathbf R_t$);
//! 8. not depend on the error translations (the claim under eq 25).
//!
//! ```
//! use tt_kinematics::conformance::{cases, check_model, Tolerances};
//! use tt_kinematics::{paper, ExactChain};
//! let table = paper::table3();
//! check_model(&ExactChain::new(&table), &table, &cases(&table, 20, 1e-3), &Tolerances::default())
//!     .map_err(|f| f.to_string())?;
//! # Ok::<(), String>(())
//! ```

use crate::linear::LinearModel;
use crate::model::{DERIVED_FIRST_ORDER_TOLERANCE, OrientationErrorModel, derived_first_order};
use crate::pose::TurntableErrors;
use crate::rotation::SignedAxis;
use crate::turntable::{FactorSpec, Turntable, TurntableDescription};
use std::fmt;
use tt_core::Pose;

/// A reference three-axis table to run the suite (and any other check) on besides the paper's:
/// outer axis about z, middle about x, inner about y; a position error and two wobbles per
/// axis, two orthogonality errors and a non-intersection translation per pair of adjacent
/// axes, as the three-axis literature models such tables (13 angular errors, 2 translations,
/// 3 joints; the outer joint comes first, so it cancels). It is the table of
/// `studies/three-axis-example.toml`, where the sources are cited; the workspace's tests,
/// benchmarks and examples all use this one description.
#[must_use]
pub fn three_axis_description() -> TurntableDescription {
    let j = FactorSpec::joint;
    let e = FactorSpec::error;
    let t = |n: &str, a| FactorSpec::Translation {
        name: n.into(),
        along: a,
    };
    let (x, y, z) = (SignedAxis::X, SignedAxis::Y, SignedAxis::Z);
    TurntableDescription::new(vec![
        j("phi_o", z),
        e("dphi_o", z),
        e("dalpha_ox", x),
        e("dalpha_oy", y),
        t("deta_om", y),
        e("deps_om_y", y),
        e("deps_om_z", z),
        j("phi_m", x),
        e("dphi_m", x),
        e("dalpha_my", y),
        e("dalpha_mz", z),
        t("deta_mi", z),
        e("deps_mi_z", z),
        e("deps_mi_x", x),
        j("phi_i", y),
        e("dphi_i", y),
        e("dalpha_ix", x),
        e("dalpha_iz", z),
    ])
}

/// [`three_axis_description`] compiled.
///
/// # Panics
/// Never: the description is valid (tested).
#[must_use]
pub fn three_axis() -> Turntable {
    Turntable::new(&three_axis_description())
        .unwrap_or_else(|e| unreachable!("the reference three-axis description is valid: {e}"))
}

/// One test point: a pose and the turntable's errors.
#[derive(Debug, Clone, PartialEq)]
pub struct Case {
    /// The pose.
    pub pose: Pose,
    /// The errors.
    pub errors: TurntableErrors,
}

impl Case {
    /// `what` at this case (its pose and errors, rad).
    fn at(&self, what: &str) -> String {
        format!(
            "{what} at pose {:?} rad, chi {:?} rad",
            self.pose.angles_rad(),
            self.errors.chi_rad()
        )
    }
}

/// The tolerances of the suite.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Tolerances {
    /// $K$ of checks 2 and 3 (unitless, rad per rad²).
    pub second_order: f64,
    /// Rounding allowed where two results are equal in exact arithmetic, rad.
    pub rounding_rad: f64,
}

impl Default for Tolerances {
    /// $K = 1$, rounding $10^{-14}$ rad (a few ulps of unit-size entries over a chain of
    /// some ten 3x3 products).
    fn default() -> Self {
        Self {
            second_order: 1.0,
            rounding_rad: 1e-14,
        }
    }
}

/// A failed check: which one, and the case and numbers that broke it.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct Failure {
    /// The check (`zero`, `first-order`, `odd`, `derived-first-order`, `rotation`, `readout`,
    /// `error-count`, `leading-joints`, `translations`, `evaluation`).
    pub(crate) check: &'static str,
    /// What was found.
    pub(crate) detail: String,
}

/// Read access to the fields (crate-private, so the type can grow without breaking callers).
impl Failure {
    /// The check (`zero`, `first-order`, `odd`, `derived-first-order`, `rotation`, `readout`,
    /// `error-count`, `leading-joints`, `translations`, `evaluation`).
    #[must_use]
    pub fn check(&self) -> &'static str {
        self.check
    }

    /// What was found.
    #[must_use]
    pub fn detail(&self) -> &str {
        &self.detail
    }
}

impl fmt::Display for Failure {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "conformance check `{}` failed: {}",
            self.check, self.detail
        )
    }
}

impl std::error::Error for Failure {}

/// Deterministic test points: `n` poses spread over the joint ranges (a low-discrepancy
/// sequence) with errors of magnitude up to `max_error_rad` (signs and sizes varied) and
/// translations up to 1 mm.
#[must_use]
pub fn cases(turntable: &Turntable, n: usize, max_error_rad: f64) -> Vec<Case> {
    cases_in(
        &turntable.joint_ranges_rad(),
        turntable.n_rotation_errors(),
        turntable.n_translation_errors(),
        n,
        max_error_rad,
    )
}

/// [`cases`] for any model: `n` poses over `joint_ranges_rad` (one `[lo, hi]` per joint),
/// `n_errors` angular errors up to `max_error_rad` and `n_translations` translations up to
/// 1 mm.
#[must_use]
pub fn cases_in(
    joint_ranges_rad: &[[f64; 2]],
    n_errors: usize,
    n_translations: usize,
    n: usize,
    max_error_rad: f64,
) -> Vec<Case> {
    // additive recurrences with irrational steps: reproducible, well spread
    let frac = |k: usize, a: f64| (k as f64 * a).fract();
    let steps = [
        0.618_033_988_749_895,
        0.414_213_562_373_095,
        0.732_050_807_568_877,
    ];
    (0..n)
        .map(|k| {
            let pose: Vec<f64> = joint_ranges_rad
                .iter()
                .enumerate()
                .map(|(j, [lo, hi])| lo + (hi - lo) * frac(k + 1, steps[j % 3] + j as f64 * 0.1))
                .collect();
            let chi: Vec<f64> = (0..n_errors)
                .map(|i| max_error_rad * (2.0 * frac(k * 7 + i + 1, 0.754_877_666_246_693) - 1.0))
                .collect();
            let tr: Vec<f64> = (0..n_translations)
                .map(|i| 1e-3 * (2.0 * frac(k + i + 3, 0.569_840_290_998) - 1.0))
                .collect();
            Case {
                pose: Pose::new(pose).unwrap_or_else(|_| unreachable!("finite")),
                errors: TurntableErrors::new(chi, tr).unwrap_or_else(|_| unreachable!("finite")),
            }
        })
        .collect()
}

/// Run the general checks of the [module](self) (1 to 6) on any `model` at `cases`: the error
/// count, the model's first order against the derived one, the physics of its
/// $\Delta\mathbf R$, zero for a perfect table (errors shaped as `zero`), agreement with the
/// model's own [`OrientationErrorModel::first_order`] to second order, oddness.
///
/// # Errors
/// The first [`Failure`].
pub fn check_model_general<M: OrientationErrorModel + ?Sized>(
    model: &M,
    zero: &TurntableErrors,
    cases: &[Case],
    tol: &Tolerances,
) -> Result<(), Failure> {
    let eval = |pose: &Pose, e: &TurntableErrors| angles(model, pose, e);
    let n = model.n_errors();
    for (what, len) in std::iter::once(("zero", zero.chi_rad().len()))
        .chain(cases.iter().map(|c| ("a case", c.errors.chi_rad().len())))
    {
        if len != n {
            return Err(Failure {
                check: "error-count",
                detail: format!(
                    "{what} has {len} errors, the model names {n} ({:?})",
                    model.error_names()
                ),
            });
        }
    }
    for case in cases {
        let at = |what: &str| case.at(what);
        check_derived_first_order(model, &case.pose, zero, tol).map_err(|f| Failure {
            detail: at(&f.detail),
            ..f
        })?;
        check_rotation(model, case, tol).map_err(|f| Failure {
            detail: at(&f.detail),
            ..f
        })?;
        let f0 = eval(&case.pose, zero)?;
        if f0.iter().any(|v| v.abs() > tol.rounding_rad) {
            return Err(Failure {
                check: "zero",
                detail: at(&format!("a perfect turntable gives {f0:?} rad")),
            });
        }
        let f = eval(&case.pose, &case.errors)?;
        let j = model.first_order(&case.pose, zero).map_err(evaluation)?;
        let chi = case.errors.chi_rad();
        let lin: Vec<f64> = (0..3)
            .map(|k| (0..chi.len()).map(|i| j[(k, i)] * chi[i]).sum())
            .collect();
        let s = case.errors.l1_rad();
        let bound = tol.second_order * s * s + tol.rounding_rad;
        per_angle("first-order", |k| {
            ((f[k] - lin[k]).abs() > bound).then(|| {
                at(&format!(
                    "angle {k}: model {} rad, its first-order coefficients give {} rad, bound {bound} rad",
                    f[k], lin[k]
                ))
            })
        })?;
        let neg = TurntableErrors::new(
            case.errors.chi_rad().iter().map(|v| -v).collect(),
            case.errors.translations_m().to_vec(),
        )
        .unwrap_or_else(|_| unreachable!("finite"));
        let fm = eval(&case.pose, &neg)?;
        per_angle("odd", |k| {
            ((f[k] + fm[k]).abs() > 2.0 * bound).then(|| {
                at(&format!(
                    "angle {k}: f(chi) {} and f(-chi) {} rad",
                    f[k], fm[k]
                ))
            })
        })?;
    }
    Ok(())
}

/// Check `model`'s own first order ([`OrientationErrorModel::first_order`], the analytic one
/// when the model supplies it) against the one derived from its orientation error
/// ([`derived_first_order`]) at `pose`, within [`DERIVED_FIRST_ORDER_TOLERANCE`] (plus
/// `tol.rounding_rad`): check `derived-first-order`.
///
/// # Errors
/// The [`Failure`] naming the coefficient and both values.
pub fn check_derived_first_order<M: OrientationErrorModel + ?Sized>(
    model: &M,
    pose: &Pose,
    zero: &TurntableErrors,
    tol: &Tolerances,
) -> Result<(), Failure> {
    let own = model.first_order(pose, zero).map_err(evaluation)?;
    let derived =
        derived_first_order(model, pose, zero.translations_m().len()).map_err(evaluation)?;
    let names = model.error_names();
    let bound = DERIVED_FIRST_ORDER_TOLERANCE + tol.rounding_rad;
    for k in 0..3 {
        for j in 0..derived.ncols() {
            let (a, d) = (own[(k, j)], derived[(k, j)]);
            if exceeds((a - d).abs(), bound) {
                return Err(Failure {
                    check: "derived-first-order",
                    detail: format!(
                        "coefficient of {} in angle {k}: the model's first order {a}, derived from its orientation error {d}, bound {bound}",
                        names.get(j).map_or("?", String::as_str)
                    ),
                });
            }
        }
    }
    Ok(())
}

/// Physics any orientation error obeys, checked on the model's own
/// [`OrientationErrorModel::delta_r`] at `case` (skipped for a model without one,
/// [`crate::KinematicsError::NoDeltaR`]): $\Delta\mathbf R$ is a rotation to second order
/// ($\lVert\Delta\mathbf R^T\Delta\mathbf R - \mathbf I\rVert_{\max} \le 2KS^2$, check
/// `rotation`; a shear or a scale is no rotation), and the angles are read off it (eq 24's
/// elements, to second order: $|f - (\Delta R_{13}, \Delta R_{21}, \Delta R_{32})| \le KS^2$,
/// check `readout`). So a model with wrong physics is caught even when it keeps the default
/// (derived) first order.
///
/// # Errors
/// The first [`Failure`].
pub fn check_rotation<M: OrientationErrorModel + ?Sized>(
    model: &M,
    case: &Case,
    tol: &Tolerances,
) -> Result<(), Failure> {
    let dr = match model.delta_r(&case.pose, &case.errors) {
        Ok(dr) => dr,
        Err(crate::KinematicsError::NoDeltaR) => return Ok(()),
        Err(err) => return Err(evaluation(err)),
    };
    let s = case.errors.l1_rad();
    let bound = tol.second_order * s * s + tol.rounding_rad;
    let gram = dr.transpose() * dr - nalgebra::Matrix3::identity();
    let off = gram.amax();
    if exceeds(off, 2.0 * bound) {
        return Err(Failure {
            check: "rotation",
            detail: format!(
                "delta_r is no rotation: |delta_r^T delta_r - I| = {off}, bound {}",
                2.0 * bound
            ),
        });
    }
    let f = model
        .orientation_error(&case.pose, &case.errors)
        .map_err(evaluation)?
        .to_array();
    let read = tt_core::OrientationError::from_matrix_elements(&dr).to_array();
    per_angle("readout", |k| {
        exceeds((f[k] - read[k]).abs(), bound).then(|| {
            format!(
                "angle {k}: orientation_error {} rad, read off delta_r {} rad, bound {bound} rad",
                f[k], read[k]
            )
        })
    })
}

/// `model`'s three angles at `pose` with errors `e` (rad); its error as a [`Failure`] of
/// check `evaluation`.
fn angles<M: OrientationErrorModel + ?Sized>(
    model: &M,
    pose: &Pose,
    e: &TurntableErrors,
) -> Result<[f64; 3], Failure> {
    model
        .orientation_error(pose, e)
        .map(|o| o.to_array())
        .map_err(evaluation)
}

/// A model's error as a [`Failure`] of check `evaluation`.
#[allow(
    clippy::needless_pass_by_value,
    reason = "by value: it is the argument of `map_err`"
)]
fn evaluation(err: crate::KinematicsError) -> Failure {
    Failure {
        check: "evaluation",
        detail: err.to_string(),
    }
}

/// A [`Failure`] of `check` with the detail `fails` gives for the first angle (0, 1, 2) it
/// gives one for.
fn per_angle(check: &'static str, fails: impl Fn(usize) -> Option<String>) -> Result<(), Failure> {
    match (0..3).find_map(fails) {
        Some(detail) => Err(Failure { check, detail }),
        None => Ok(()),
    }
}

/// Whether `x` exceeds `bound` or is NaN.
fn exceeds(x: f64, bound: f64) -> bool {
    x.is_nan() || x > bound
}

/// Run the checks of the [module](self) on `model` of the described `turntable` at `cases`:
/// the general ones ([`check_model_general`], against the model's own first order), then,
/// because the model claims to be THIS turntable's, agreement to second order with the
/// turntable's first-order model ([`LinearModel`], check `first-order` too), and the two
/// checks that belong to a described turntable (leading joints, translations). A model that
/// is not a described turntable's uses [`check_model_general`] alone.
///
/// # Errors
/// The first [`Failure`].
pub fn check_model<M: OrientationErrorModel + ?Sized>(
    model: &M,
    turntable: &Turntable,
    cases: &[Case],
    tol: &Tolerances,
) -> Result<(), Failure> {
    check_model_general(model, &turntable.zero_errors(), cases, tol)?;
    let linear = LinearModel::new(turntable);
    let eval = |pose: &Pose, e: &TurntableErrors| angles(model, pose, e);
    for case in cases {
        let at = |what: &str| case.at(what);
        let f = eval(&case.pose, &case.errors)?;
        let lin = linear
            .evaluate(&case.pose, &case.errors)
            .map_err(evaluation)?
            .to_array();
        let s = case.errors.l1_rad();
        let bound = tol.second_order * s * s + tol.rounding_rad;
        per_angle("first-order", |k| {
            ((f[k] - lin[k]).abs() > bound).then(|| {
                at(&format!(
                    "angle {k}: model {} rad, the turntable's first-order model {} rad, bound {bound} rad",
                    f[k], lin[k]
                ))
            })
        })?;
        let free = turntable.free_joints();
        let mut moved = case.pose.angles_rad().to_vec();
        let mut any = false;
        for (j, a) in moved.iter_mut().enumerate() {
            if !free.contains(&j) {
                *a += 1.234_567;
                any = true;
            }
        }
        if any {
            let g = eval(
                &Pose::new(moved).unwrap_or_else(|_| unreachable!("finite")),
                &case.errors,
            )?;
            per_angle("leading-joints", |k| {
                ((g[k] - f[k]).abs() > tol.rounding_rad).then(|| {
                    at(&format!(
                        "angle {k} changed from {} to {} rad when a cancelling joint moved",
                        f[k], g[k]
                    ))
                })
            })?;
        }
        if turntable.n_translation_errors() > 0 {
            let shifted = case
                .errors
                .clone()
                .with_translations_m(
                    case.errors
                        .translations_m()
                        .iter()
                        .map(|t| 2.0 * t + 1e-3)
                        .collect(),
                )
                .unwrap_or_else(|_| unreachable!("finite"));
            let g = eval(&case.pose, &shifted)?;
            per_angle("translations", |k| {
                ((g[k] - f[k]).abs() > tol.rounding_rad).then(|| {
                    at(&format!(
                        "angle {k} changed from {} to {} rad with other translations",
                        f[k], g[k]
                    ))
                })
            })?;
        }
    }
    Ok(())
}
