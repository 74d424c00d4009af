//! The orientation requirement of eq 15-16 for any sensor: per output the largest centred box
//! of orientation errors inside which the output meets its accuracy (Figures 4-5), combined
//! over the outputs.
//!
//! # Formula
//! Output $k$ meets its accuracy when $\Delta\omega_k(\boldsymbol\delta) \le \omega_{m,k}$ with
//! $\Delta\omega_k$ of eq 14 for the same orientation error $\boldsymbol\delta =
//! (\Delta\psi, \Delta\theta, \Delta\gamma)$ at every position (§2.2). The angles an output is
//! sensitive to are found numerically (claim 1: $\Delta\omega_x$ ignores $\Delta\gamma$,
//! $\Delta\omega_y$ ignores $\Delta\psi$). In the space of those angles (1, 2 or 3 of them),
//! the paper's criterion "maximise the areas of the rectangles" (Figure 5) becomes: the
//! centred, axis-aligned box of largest volume whose corners meet the accuracy. Then
//! $I_j = \min_k$ of the half-sides along angle $j$ of the outputs sensitive to it
//! (for the GyroWheel: $I_\psi$ from $x$, $I_\gamma$ from $y$, $I_\theta$ the smaller of the two).
//! An angle no output is sensitive to has no requirement.
//!
//! # Search
//! Corners in direction $\hat u$ (in the positive orthant) at radius $\rho$: $\rho(\hat u)$ is the
//! largest radius at which every corner meets the accuracy (from the first-order radius,
//! doubled or halved until bracketed, then bisection to [`RequirementParams::radius_tol_rel`] of the radius: the
//! search is scale-free); the direction maximises the volume (two angles: a scan of
//! [`RequirementParams::direction_scan`] directions then golden sections to [`RequirementParams::direction_tol_rad`]; three: a start
//! from the log-barrier solution of the first-order problem (a [`RequirementParams::direction_scan_3d`]² grid of
//! directions when the first-order problem is unbounded), refined by Nelder-Mead to
//! [`RequirementParams::direction_tol_3d_rad`]).
//! For a convex region (every first-order reading: $\Delta\omega$ is a maximum of absolute
//! values of linear forms) the corners bound the whole box; the result records the largest
//! $\Delta\omega/\omega_m$ found on its boundary.

use crate::analysis::{ErrorWork, OrientationErrorAnalysis, Reading};
use crate::calibration::{Calibration, OutputCalibration};
use crate::error::{CalibError, finite};
use gw_model::InputValues;
use rayon::prelude::*;
use std::cell::Cell;
use std::f64::consts::FRAC_PI_2;
use tt_core::{DeltaRKind, OrientationAxis, OrientationError, Requirement};

/// Halvings of the starting radius at most before the search brackets the boundary from 0
/// (the start is the first-order radius, so a few suffice).
const MAX_HALVINGS: usize = 200;

/// Largest barrier parameter of the first-order box problem (duality gap ~ rows / t).
const BARRIER_T_MAX: f64 = 1e13;

/// Newton steps per barrier parameter.
const BARRIER_NEWTON_STEPS: usize = 50;

/// The numerical knobs of the requirement search (eq 15-16), with [`Default`] (faer's
/// convention): `let mut p = RequirementParams::default(); p.direction_scan = 128;` and
/// [`RequirementProblem::params`]. The defaults are the values every answer of the project is
/// computed with.
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub struct RequirementParams {
    /// Bisection stops when the bracket on the box's corner radius is narrower than this fraction
    /// of the radius (dimensionless): the search is scale-free, so the requirement scales with the
    /// accuracy at every accuracy (it is linear in $\omega_m$ to first order).
    pub radius_tol_rel: f64,
    /// Below this first-order corner radius (rad, about 2 arcsec) an output's box is computed at
    /// the accuracy whose first-order radius is this ([`OutputRegion::linear_regime_accuracy`])
    /// and scaled to the output's accuracy, so the requirement is exactly proportional to
    /// $\omega_m$ below it. Why: $\Delta\omega$ comes from outputs that cancel, so a direct
    /// evaluation at corner radius $\rho$ resolves it only to a few ulp of the outputs' size, a
    /// relative error of about $5\times10^{-14}/\rho$ on the radius for the paper's sensor
    /// (measured: $10^{-4}$ at $\rho = 5\times10^{-10}$ rad); scaling instead neglects the
    /// second-order terms, a relative error of about $0.4\rho^2$ (measured for the exact
    /// $\Delta\mathbf R$). At $10^{-5}$ rad both are below $10^{-8}$.
    pub linear_regime_rad: f64,
    /// Golden-section search on a two-angle corner direction stops at this bracket width, rad.
    /// The area is flat (quadratic) at its optimum, so the half-sides are located to about
    /// $\rho \cdot$ `direction_tol_rad` $\approx 5\times10^{-13}$ rad.
    pub direction_tol_rad: f64,
    /// Directions scanned before the golden-section refinement (guards against a local optimum of
    /// a polygonal region).
    pub direction_scan: usize,
    /// Grid of directions per angle for three sensitive angles.
    pub direction_scan_3d: usize,
    /// Golden-section bracket of the three-angle refinement, rad (the volume is flat at its
    /// optimum: within $10^{-10}$ of the best, half-sides to about $\rho\cdot10^{-5}$).
    pub direction_tol_3d_rad: f64,
    /// Step of the central differences that linearise an output's error vector, rad.
    pub linearization_step_rad: f64,
    /// A column of the linearised rows below this fraction of the largest one leaves its angle
    /// unbounded to first order (the grid search is used instead).
    pub unbounded_column_rel: f64,
    /// Initial simplex size of the Nelder-Mead refinement of a three-angle direction, rad.
    pub nelder_mead_start_rad: f64,
    /// Largest number of Nelder-Mead iterations.
    pub nelder_mead_max_iter: usize,
    /// Largest corner radius searched, rad (about 28.6 deg).
    pub search_limit_rad: f64,
    /// Points per edge at which a solved box's boundary is re-checked.
    pub boundary_check_points: usize,
    /// An output is insensitive to an angle when a probe of [`RequirementParams::sensitivity_probe_rad`] along it
    /// gives less than this fraction of the largest probe response (dimensionless). Rounding of
    /// the fit leaves ~1e-11 of the response; a dependence of second order only still gives
    /// ~1e-3 (the probe size).
    pub insensitive_rel: f64,
    /// Size of the probe of the sensitivity test, rad.
    pub sensitivity_probe_rad: f64,
    /// Relative bisection tolerance on the corner radius while searching three-angle directions
    /// (the chosen direction is then solved to [`RequirementParams::radius_tol_rel`]).
    pub search_radius_rel: f64,
}

impl Default for RequirementParams {
    fn default() -> Self {
        Self {
            radius_tol_rel: 1e-12,
            linear_regime_rad: 1e-5,
            direction_tol_rad: 1e-9,
            direction_scan: 64,
            direction_scan_3d: 8,
            direction_tol_3d_rad: 1e-5,
            linearization_step_rad: 1e-6,
            unbounded_column_rel: 1e-6,
            nelder_mead_start_rad: 0.02,
            nelder_mead_max_iter: 200,
            search_limit_rad: 0.5,
            boundary_check_points: 32,
            insensitive_rel: 1e-7,
            sensitivity_probe_rad: 1e-3,
            search_radius_rel: 1e-7,
        }
    }
}

/// Everything the requirement of eq 15-16 depends on: the calibration (sensor with its
/// accuracies, site, schedule), the reading of eq 13 and the matrix of eq 7.
#[derive(Debug, Clone)]
pub struct RequirementProblem {
    /// The calibration.
    pub calibration: Calibration,
    /// The reading of eq 13.
    pub reading: Reading,
    /// How the angles become $\Delta\mathbf R$ (eq 7 small-angle, or exact).
    pub delta_r_kind: DeltaRKind,
    /// The search's knobs ([`RequirementParams::default`] unless changed).
    pub params: RequirementParams,
}

/// The rate-sensing error of one output as a function of a constant orientation error.
#[derive(Debug, Clone)]
pub struct OutputRegion {
    cal: OutputCalibration,
    reading: Reading,
    kind: DeltaRKind,
    params: RequirementParams,
    accuracy: f64,
    sensitive: Vec<usize>,
    /// $\max_i\sum_j|\partial e_i/\partial\delta_j|$ over the sensitive angles (output unit
    /// per rad; `None` without a first-order sensitivity): independent of $\omega_m$.
    gain: Option<f64>,
    /// The box search without its shortcuts (the corner that failed last tried first, the
    /// direction scan's bisections stopped once they cannot win): the tests check that the
    /// shortcuts change no bit of the box.
    long_way: bool,
}

/// The largest box of one output (in the angles it is sensitive to).
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct OutputBox {
    /// The output.
    pub(crate) output: String,
    /// Half-sides per angle ($\psi, \theta, \gamma$), rad; `None` for an angle the output is
    /// insensitive to.
    pub(crate) half_rad: [Option<f64>; 3],
    /// Volume (length, area or volume) of the box in its angles, rad^d.
    pub(crate) volume: f64,
    /// Largest $\Delta\omega/\omega_m$ found on the box's boundary (corners and
    /// [`RequirementParams::boundary_check_points`] points per edge): at most 1 up to the bisection tolerance
    /// when the region is convex.
    pub(crate) boundary_max_ratio: f64,
}

/// Read access to the fields (crate-private, so the type can grow without breaking callers).
impl OutputBox {
    /// The output.
    #[must_use]
    pub fn output(&self) -> &str {
        &self.output
    }

    /// Half-sides per angle ($\psi, \theta, \gamma$), rad; `None` for an angle the output is
    /// insensitive to.
    #[must_use]
    pub fn half_rad(&self) -> [Option<f64>; 3] {
        self.half_rad
    }

    /// Volume (length, area or volume) of the box in its angles, rad^d.
    #[must_use]
    pub fn volume(&self) -> f64 {
        self.volume
    }

    /// Largest $\Delta\omega/\omega_m$ found on the box's boundary (corners and
    /// [`RequirementParams::boundary_check_points`] points per edge): at most 1 up to the bisection tolerance
    /// when the region is convex.
    #[must_use]
    pub fn boundary_max_ratio(&self) -> f64 {
        self.boundary_max_ratio
    }
}

/// The requirement $|\Delta\psi| \le I_\psi$, $|\Delta\theta| \le I_\theta$,
/// $|\Delta\gamma| \le I_\gamma$ (eq 15), radians.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct OrientationRequirement {
    /// $(I_\psi, I_\theta, I_\gamma)$, rad; `None` where no output depends on the angle.
    pub(crate) requirement: Requirement,
    /// Each output's box.
    pub(crate) boxes: Vec<OutputBox>,
    /// For each output, the largest $\Delta\omega/\omega_m$ at the corners of the combined
    /// box (all three angles at once): at most 1 (to the bisection tolerance) when the
    /// combination is sound.
    pub(crate) combined_corner_ratio: Vec<f64>,
    /// Outputs that impose no requirement: insensitive to a constant orientation error, or
    /// meeting their accuracy for every constant orientation error up to
    /// [`RequirementParams::search_limit_rad`] (the calibration absorbs it, e.g. an accelerometer whose
    /// misalignments are estimated). Only a pose-dependent analysis (the end-to-end direct
    /// allocation) can account for them.
    pub(crate) unconstrained_outputs: Vec<String>,
}

/// Read access to the fields (crate-private, so the type can grow without breaking callers).
impl OrientationRequirement {
    /// $(I_\psi, I_\theta, I_\gamma)$, rad; `None` where no output depends on the angle.
    #[must_use]
    pub fn requirement(&self) -> Requirement {
        self.requirement
    }

    /// Each output's box.
    #[must_use]
    pub fn boxes(&self) -> &[OutputBox] {
        &self.boxes
    }

    /// For each output, the largest $\Delta\omega/\omega_m$ at the corners of the combined
    /// box (all three angles at once): at most 1 (to the bisection tolerance) when the
    /// combination is sound.
    #[must_use]
    pub fn combined_corner_ratio(&self) -> &[f64] {
        &self.combined_corner_ratio
    }

    /// Outputs that impose no requirement: insensitive to a constant orientation error, or
    /// meeting their accuracy for every constant orientation error up to
    /// [`RequirementParams::search_limit_rad`] (the calibration absorbs it, e.g. an accelerometer whose
    /// misalignments are estimated). Only a pose-dependent analysis (the end-to-end direct
    /// allocation) can account for them.
    #[must_use]
    pub fn unconstrained_outputs(&self) -> &[String] {
        &self.unconstrained_outputs
    }

    /// Where a given requirement `given_rad` ($\psi, \theta, \gamma$, rad) disagrees with
    /// this computed one, axis by axis in the order $\psi, \theta, \gamma$: a relative
    /// difference above [`DISAGREE_REL`], or a given value where no output constrains the
    /// axis. Empty when they agree.
    #[must_use]
    pub fn disagreement(&self, given_rad: [f64; 3]) -> Vec<AxisDisagreement> {
        OrientationAxis::ALL
            .iter()
            .filter_map(|&axis| {
                let given_rad = given_rad[axis.index()];
                match self.requirement.get(axis) {
                    Some(computed_rad)
                        if ((given_rad - computed_rad) / computed_rad).abs() > DISAGREE_REL =>
                    {
                        Some(AxisDisagreement::Differs {
                            axis,
                            given_rad,
                            computed_rad,
                        })
                    }
                    None => Some(AxisDisagreement::NoneComputed { axis, given_rad }),
                    _ => None,
                }
            })
            .collect()
    }
}

/// Relative difference above which a given requirement is said to disagree with the computed
/// one ([`OrientationRequirement::disagreement`]; dimensionless: the computation is accurate
/// to 1e-9).
pub const DISAGREE_REL: f64 = 1e-6;

/// One axis where a given requirement disagrees with the computed one
/// ([`OrientationRequirement::disagreement`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum AxisDisagreement {
    /// Both exist and differ by more than [`DISAGREE_REL`] of the computed one.
    Differs {
        /// The axis.
        axis: OrientationAxis,
        /// The given value, rad.
        given_rad: f64,
        /// The computed value, rad.
        computed_rad: f64,
    },
    /// A value is given where no output constrains the axis (none computed).
    NoneComputed {
        /// The axis.
        axis: OrientationAxis,
        /// The given value, rad.
        given_rad: f64,
    },
}

/// Grid data of a surface $\Gamma$ (Figure 4): one output's $\Delta\omega$ over two angles.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct Surface {
    /// The output.
    pub(crate) output: String,
    /// The two plane angles (indices into $\psi, \theta, \gamma$).
    pub(crate) angles: [usize; 2],
    /// Grid values of the first angle, rad.
    pub(crate) u_rad: Vec<f64>,
    /// Grid values of the second angle, rad.
    pub(crate) v_rad: Vec<f64>,
    /// $\Delta\omega$ (output unit) at `(u_rad[i], v_rad[j])`, indexed `[j][i]`.
    pub(crate) delta_omega: Vec<Vec<f64>>,
}

/// Read access to the fields (crate-private, so the type can grow without breaking callers).
impl Surface {
    /// The output.
    #[must_use]
    pub fn output(&self) -> &str {
        &self.output
    }

    /// The two plane angles (indices into $\psi, \theta, \gamma$).
    #[must_use]
    pub fn angles(&self) -> [usize; 2] {
        self.angles
    }

    /// Grid values of the first angle, rad.
    #[must_use]
    pub fn u_rad(&self) -> &[f64] {
        &self.u_rad
    }

    /// Grid values of the second angle, rad.
    #[must_use]
    pub fn v_rad(&self) -> &[f64] {
        &self.v_rad
    }

    /// $\Delta\omega$ (output unit) at `(u_rad[i], v_rad[j])`, indexed `[j][i]`.
    #[must_use]
    pub fn delta_omega(&self) -> &[Vec<f64>] {
        &self.delta_omega
    }
}

impl RequirementProblem {
    /// A problem.
    #[must_use]
    pub fn new(calibration: Calibration, reading: Reading, delta_r_kind: DeltaRKind) -> Self {
        Self {
            calibration,
            reading,
            delta_r_kind,
            params: RequirementParams::default(),
        }
    }

    /// The region of output `k` (its sensitivities found by probing).
    ///
    /// # Errors
    /// [`CalibError::Field`] ([`tt_core::FieldError::Length`]) for a missing output; as
    /// [`OrientationErrorAnalysis::delta_omega`].
    pub fn region(&self, k: usize) -> Result<OutputRegion, CalibError> {
        let cal = self
            .calibration
            .outputs()
            .get(k)
            .ok_or(CalibError::Field(tt_core::FieldError::Length {
                field: "output index".into(),
                expected: self.calibration.outputs().len(),
                found: k,
            }))?
            .clone();
        let accuracy = cal.output().accuracy;
        let mut region = OutputRegion {
            cal,
            reading: self.reading,
            kind: self.delta_r_kind,
            params: self.params,
            accuracy,
            sensitive: Vec::new(),
            gain: None,
            long_way: false,
        };
        let mut probe = [0.0; 3];
        for (j, p) in probe.iter_mut().enumerate() {
            let mut d = [0.0; 3];
            d[j] = self.params.sensitivity_probe_rad;
            let plus = region.rate_error(d)?;
            d[j] = -self.params.sensitivity_probe_rad;
            *p = plus.max(region.rate_error(d)?);
        }
        let top = probe.iter().copied().fold(0.0, f64::max);
        region.sensitive = (0..3)
            .filter(|&j| top > 0.0 && probe[j] > self.params.insensitive_rel * top)
            .collect();
        // the largest first-order change of the error vector at a unit corner
        let gain = region
            .derivative_rows()?
            .iter()
            .map(|r| r.iter().sum::<f64>())
            .fold(0.0, f64::max);
        region.gain = (gain > 0.0 && gain.is_finite()).then_some(gain);
        Ok(region)
    }

    /// $\Delta\omega$ of output `k` (output unit) for one orientation error.
    ///
    /// # Errors
    /// As [`RequirementProblem::region`].
    pub fn rate_error(&self, k: usize, angles: &OrientationError) -> Result<f64, CalibError> {
        OrientationErrorAnalysis::new(&self.calibration, k, self.reading)?
            .delta_omega_for_angles(angles, self.delta_r_kind)
    }

    /// The requirement of eq 15: every output's largest box, combined.
    ///
    /// # Reference
    /// Eq 15-16, Figure 5.
    ///
    /// # Errors
    /// [`CalibError::NoSensitivity`] when no output constrains a constant orientation error
    /// (every output is insensitive to it or absorbs it; see
    /// [`OrientationRequirement::unconstrained_outputs`]).
    pub fn requirement(&self) -> Result<OrientationRequirement, CalibError> {
        // Every output's region and box on its own thread (independent searches), then
        // taken in output order: the same boxes, and the same first error, as one by one.
        let regions = (0..self.calibration.outputs().len())
            .into_par_iter()
            .map(|k| self.region(k))
            .collect::<Vec<_>>()
            .into_iter()
            .collect::<Result<Vec<_>, _>>()?;
        let found: Vec<Option<Result<OutputBox, CalibError>>> = regions
            .par_iter()
            .map(|r| (!r.sensitive.is_empty()).then(|| r.max_box()))
            .collect();
        let mut boxes = Vec::new();
        let mut unconstrained_outputs = Vec::new();
        for (r, found) in regions.iter().zip(found) {
            let Some(found) = found else {
                unconstrained_outputs.push(r.output().to_string());
                continue;
            };
            match found {
                Ok(b) => boxes.push(b),
                Err(CalibError::Unbounded { .. }) => {
                    unconstrained_outputs.push(r.output().to_string())
                }
                Err(e) => return Err(e),
            }
        }
        if boxes.is_empty() {
            return Err(CalibError::NoSensitivity);
        }
        let mut rad = [None; 3];
        for b in &boxes {
            for (j, h) in b.half_rad.iter().enumerate() {
                if let Some(h) = h {
                    rad[j] = Some(rad[j].map_or(*h, |r: f64| r.min(*h)));
                }
            }
        }
        let corner = rad.map(|r| r.unwrap_or(0.0));
        let combined_corner_ratio = regions
            .iter()
            .map(|r| {
                let mut worst: f64 = 0.0;
                for signs in 0..8u32 {
                    let d: [f64; 3] = std::array::from_fn(|j| {
                        if signs & (1 << j) == 0 {
                            corner[j]
                        } else {
                            -corner[j]
                        }
                    });
                    worst = worst.max(r.accuracy_ratio(d)?);
                }
                Ok(worst)
            })
            .collect::<Result<Vec<_>, CalibError>>()?;
        Ok(OrientationRequirement {
            requirement: Requirement::from_options(rad)?,
            boxes,
            combined_corner_ratio,
            unconstrained_outputs,
        })
    }
}

impl OutputRegion {
    /// The output's name.
    #[must_use]
    pub fn output(&self) -> &str {
        &self.cal.output().name
    }

    /// Its accuracy $\omega_m$ (output unit).
    #[must_use]
    pub fn accuracy(&self) -> f64 {
        self.accuracy
    }

    /// The angles (indices into $\psi, \theta, \gamma$) the output is sensitive to.
    #[must_use]
    pub fn sensitive_angles(&self) -> &[usize] {
        &self.sensitive
    }

    /// $\Delta\omega$ (output unit) for the orientation error `[psi, theta, gamma]` (rad).
    ///
    /// # Errors
    /// [`CalibError::Field`] (not finite) for a non-finite angle; as
    /// [`OrientationErrorAnalysis::delta_omega`].
    pub fn rate_error(&self, angles_rad: [f64; 3]) -> Result<f64, CalibError> {
        for axis in OrientationAxis::ALL {
            finite(axis.name(), angles_rad[axis.index()])?;
        }
        Ok(self
            .error_vector(angles_rad)?
            .iter()
            .fold(0.0, |m: f64, v| m.max(v.abs())))
    }

    fn point(&self, coords: &[f64]) -> [f64; 3] {
        let mut d = [0.0; 3];
        for (&j, &c) in self.sensitive.iter().zip(coords) {
            d[j] = c;
        }
        d
    }

    /// Whether every corner of the box with half-sides `half` meets the accuracy.
    ///
    /// The answer does not depend on the order the corners are tried in, so the corner that
    /// failed last (`first`, updated here) is tried first: along a bisection the same corner
    /// usually binds, and a failing box then costs one evaluation instead of up to $2^d$.
    /// (Only which error is reported could differ, should two corners both fail to
    /// evaluate or one fail to evaluate and another exceed the accuracy.)
    fn corners_ok(&self, half: &[f64], first: &Cell<u32>) -> Result<bool, CalibError> {
        let d = half.len();
        let n = 1u32 << d;
        let start = if self.long_way { 0 } else { first.get() % n };
        // `start`, then every other corner in order
        let order = std::iter::once(start).chain((0..n).filter(move |&c| c != start));
        for signs in order {
            let c: Vec<f64> = (0..d)
                .map(|i| {
                    if signs & (1 << i) == 0 {
                        half[i]
                    } else {
                        -half[i]
                    }
                })
                .collect();
            if self.rate_error(self.point(&c))? > self.accuracy {
                first.set(signs);
                return Ok(false);
            }
        }
        Ok(true)
    }

    /// The first-order radius (rad) at which the corner $(\rho, \dots, \rho)$ of a box in the
    /// sensitive angles first reaches $\omega_m$: $\omega_m/\max_i\sum_j
    /// |\partial e_i/\partial\delta_j|$ (central differences); `None` without a first-order
    /// sensitivity. It is proportional to $\omega_m$: the search starts there, so it does not
    /// depend on the scale of the accuracy.
    #[must_use]
    pub fn first_order_radius(&self) -> Option<f64> {
        self.gain.map(|g| self.accuracy / g)
    }

    /// The accuracy (output unit) whose first-order radius is [`RequirementParams::linear_regime_rad`]: below
    /// it the box is computed at this accuracy and scaled (`None` without a first-order
    /// sensitivity). It does not depend on the output's own accuracy.
    #[must_use]
    pub(crate) fn linear_regime_accuracy(&self) -> Option<f64> {
        self.gain.map(|g| self.params.linear_regime_rad * g)
    }

    /// The factor $f = \omega_{ref}/\omega_m > 1$ when the output's accuracy is in the linear
    /// regime (then the region is evaluated at $\omega_{ref}$ and scaled by $1/f$), else
    /// `None`.
    fn linear_scale(&self) -> Option<(f64, Self)> {
        let reference = self.linear_regime_accuracy()?;
        (self.accuracy < reference).then(|| {
            let mut r = self.clone();
            r.accuracy = reference;
            (reference / self.accuracy, r)
        })
    }

    /// $\Delta\omega/\omega_m$ at the orientation error `angles_rad`, evaluated where it is
    /// resolved: in the linear regime at the reference accuracy with the angles scaled by the
    /// same factor (exact to first order), else directly.
    ///
    /// # Errors
    /// As [`OutputRegion::rate_error`].
    pub(crate) fn accuracy_ratio(&self, angles_rad: [f64; 3]) -> Result<f64, CalibError> {
        match self.linear_scale() {
            Some((f, r)) => Ok(r.rate_error(angles_rad.map(|a| a * f))? / r.accuracy),
            None => Ok(self.rate_error(angles_rad)? / self.accuracy),
        }
    }

    /// Largest radius $\rho$ such that `ok(ρ)`, to the relative tolerance `rel_tol` (0:
    /// [`RequirementParams::radius_tol_rel`]): from the first-order radius ([`OutputRegion::first_order_radius`]),
    /// doubled or halved until the boundary is bracketed, then bisected. Every corner meeting
    /// the accuracy at [`RequirementParams::search_limit_rad`] makes the region unbounded.
    fn radius<F>(&self, direction: &[f64], rel_tol: f64, ok: F) -> Result<f64, CalibError>
    where
        F: Fn(f64) -> Result<bool, CalibError>,
    {
        // `give_up` never holds, so the search always finds its radius
        Ok(self
            .radius_unless(direction, rel_tol, ok, |_| false)?
            .unwrap_or(0.0))
    }

    /// [`OutputRegion::radius`], abandoned (`None`) as soon as `give_up(hi)` holds for the
    /// bisection's upper end `hi` (checked once the boundary is bracketed, before each
    /// bisection step). Every later step keeps the radius found below `hi`, so a caller that
    /// gives up when even `hi` could not matter loses nothing.
    fn radius_unless<F, G>(
        &self,
        direction: &[f64],
        rel_tol: f64,
        ok: F,
        give_up: G,
    ) -> Result<Option<f64>, CalibError>
    where
        F: Fn(f64) -> Result<bool, CalibError>,
        G: Fn(f64) -> bool,
    {
        let tol = if rel_tol > 0.0 {
            rel_tol
        } else {
            self.params.radius_tol_rel
        };
        let start = self
            .first_order_radius()
            .map_or(1e-3 * self.params.search_limit_rad, |r| {
                r.min(self.params.search_limit_rad)
            });
        let (mut lo, mut hi);
        if ok(start)? {
            (lo, hi) = (start, start);
            loop {
                if hi >= self.params.search_limit_rad {
                    return Err(CalibError::Unbounded {
                        output: self.output().to_string(),
                        direction: direction.to_vec(),
                        limit_rad: self.params.search_limit_rad,
                    });
                }
                hi = (2.0 * hi).min(self.params.search_limit_rad);
                if !ok(hi)? {
                    break;
                }
                lo = hi;
            }
        } else {
            (lo, hi) = (0.5 * start, start);
            let mut halvings = 0;
            while !ok(lo)? {
                hi = lo;
                lo *= 0.5;
                halvings += 1;
                if halvings >= MAX_HALVINGS {
                    lo = 0.0;
                    break;
                }
            }
        }
        while hi - lo > tol * hi {
            if give_up(hi) {
                return Ok(None);
            }
            let mid = 0.5 * (lo + hi);
            if mid <= lo || mid >= hi {
                break;
            }
            if ok(mid)? {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        Ok(Some(lo))
    }

    /// The half-sides of the largest box whose corner points along `dir` (unit, positive),
    /// radius to the relative tolerance `rel_tol` (0: [`RequirementParams::radius_tol_rel`]).
    fn box_along(&self, dir: &[f64], rel_tol: f64) -> Result<(Vec<f64>, f64), CalibError> {
        let first = Cell::new(0);
        let r = self.radius(dir, rel_tol, |r| {
            let half: Vec<f64> = dir.iter().map(|d| r * d).collect();
            self.corners_ok(&half, &first)
        })?;
        Ok(Self::box_at(dir, r))
    }

    /// The half-sides and volume of the box of corner radius `r` along `dir`.
    fn box_at(dir: &[f64], r: f64) -> (Vec<f64>, f64) {
        let half: Vec<f64> = dir.iter().map(|d| r * d).collect();
        let volume = half.iter().map(|h| 2.0 * h).product();
        (half, volume)
    }

    /// The volume of [`OutputRegion::box_along`]`(dir, rel_tol)`, or `None` when it is at
    /// most `beat` (then the search stops early).
    ///
    /// # Why stopping early is exact
    /// The box's volume $V(r) = \prod_k 2\,(r\,d_k)$ is computed by the same rounded
    /// operations as in [`OutputRegion::box_along`]; each is monotone (non-decreasing) in its
    /// argument for $d_k \ge 0$, so $V$ is non-decreasing in $r$. The bisection keeps a radius
    /// that meets the accuracy strictly below its upper end `hi`, and returns one, so the
    /// volume it would find is at most $V(\mathit{hi})$: once $V(\mathit{hi}) \le$ `beat`,
    /// the finished search could not exceed `beat` either. (It may skip evaluations that would
    /// have failed with an error.)
    fn volume_along_unless(
        &self,
        dir: &[f64],
        rel_tol: f64,
        beat: f64,
    ) -> Result<Option<f64>, CalibError> {
        let first = Cell::new(0);
        let r = self.radius_unless(
            dir,
            rel_tol,
            |r| {
                let half: Vec<f64> = dir.iter().map(|d| r * d).collect();
                self.corners_ok(&half, &first)
            },
            |hi| !self.long_way && Self::box_at(dir, hi).1 <= beat,
        )?;
        Ok(r.map(|r| Self::box_at(dir, r).1))
    }

    /// The largest-volume centred axis-aligned box inside $\Delta\omega \le \omega_m$ in the
    /// output's sensitive angles (Figure 5, "to maximize the areas of the two rectangles").
    /// Below [`OutputRegion::linear_regime_accuracy`] the box at that accuracy, scaled by
    /// $\omega_m/\omega_{ref}$ (see [`RequirementParams::linear_regime_rad`]): the requirement is proportional to
    /// $\omega_m$ there, at every scale down to the smallest accepted accuracy.
    ///
    /// # Errors
    /// [`CalibError::Unbounded`] if the region is not bounded within [`RequirementParams::search_limit_rad`];
    /// [`CalibError::NoSensitivity`] for an output insensitive to every angle.
    pub fn max_box(&self) -> Result<OutputBox, CalibError> {
        let Some((f, reference)) = self.linear_scale() else {
            return self.max_box_direct();
        };
        // the linear regime: the box at the reference accuracy, scaled (see linear_regime_rad)
        let b = reference.max_box_direct()?;
        Ok(OutputBox {
            half_rad: b.half_rad.map(|h| h.map(|h| h / f)),
            volume: b.volume / f.powi(self.sensitive.len() as i32),
            ..b
        })
    }

    fn max_box_direct(&self) -> Result<OutputBox, CalibError> {
        let half = match self.sensitive.len() {
            0 => return Err(CalibError::NoSensitivity),
            1 => self.box_along(&[1.0], 0.0)?.0,
            2 => {
                let at = |t: f64| self.box_along(&[t.cos(), t.sin()], 0.0);
                // the scan only compares each direction's volume with the best so far
                let scan_at =
                    |t: f64, beat: f64| self.volume_along_unless(&[t.cos(), t.sin()], 0.0, beat);
                golden_max(
                    at,
                    scan_at,
                    0.0,
                    FRAC_PI_2,
                    self.params.direction_scan,
                    self.params.direction_tol_rad,
                )?
                .0
            }
            _ => self.max_box_3d()?,
        };
        let volume = half.iter().map(|h| 2.0 * h).product();
        let mut boundary: f64 = 0.0;
        let n = self.params.boundary_check_points;
        let d = half.len();
        // every edge of the box: one coordinate runs, the others sit at +-half
        for run in 0..d {
            for signs in 0..(1u32 << d) {
                if signs & (1 << run) != 0 {
                    continue;
                }
                for i in 0..=n {
                    let s = -1.0 + 2.0 * i as f64 / n as f64;
                    let c: Vec<f64> = (0..d)
                        .map(|q| {
                            if q == run {
                                s * half[q]
                            } else if signs & (1 << q) == 0 {
                                half[q]
                            } else {
                                -half[q]
                            }
                        })
                        .collect();
                    boundary = boundary.max(self.rate_error(self.point(&c))? / self.accuracy);
                }
            }
        }
        let mut half_rad = [None; 3];
        for (&j, h) in self.sensitive.iter().zip(&half) {
            half_rad[j] = Some(*h);
        }
        Ok(OutputBox {
            output: self.output().to_string(),
            half_rad,
            volume,
            boundary_max_ratio: boundary,
        })
    }

    /// The first-order model of the output's error vector in its sensitive angles, per unit
    /// of accuracy: $|\partial e_i/\partial\delta_j| / \omega_m$ by central differences.
    fn linear_rows(&self) -> Result<Vec<Vec<f64>>, CalibError> {
        Ok(self
            .derivative_rows()?
            .into_iter()
            .map(|r| r.into_iter().map(|v| v / self.accuracy).collect())
            .collect())
    }

    /// $|\partial e_i/\partial\delta_j|$ (output unit per rad) in the sensitive angles by
    /// central differences of step [`RequirementParams::linearization_step_rad`].
    fn derivative_rows(&self) -> Result<Vec<Vec<f64>>, CalibError> {
        let h = self.params.linearization_step_rad;
        let n = self.cal.nominal_values().len();
        let mut cols = Vec::new();
        for &j in &self.sensitive {
            let mut d = [0.0; 3];
            d[j] = h;
            let plus = self.error_vector(d)?;
            d[j] = -h;
            let minus = self.error_vector(d)?;
            cols.push(
                (0..n)
                    .map(|i| ((plus[i] - minus[i]) / (2.0 * h)).abs())
                    .collect::<Vec<f64>>(),
            );
        }
        Ok((0..n)
            .map(|i| cols.iter().map(|c| c[i]).collect())
            .collect())
    }

    fn max_box_3d(&self) -> Result<Vec<f64>, CalibError> {
        let dir = |t: f64, p: f64| [t.sin() * p.cos(), t.sin() * p.sin(), t.cos()];
        let volume = |x: &[f64; 2]| -> Result<f64, CalibError> {
            let (t, p) = (x[0].clamp(0.0, FRAC_PI_2), x[1].clamp(0.0, FRAC_PI_2));
            Ok(self.box_along(&dir(t, p), self.params.search_radius_rel)?.1)
        };
        // the same volume, or `None` when it is at most `beat` (the direction's components are
        // non-negative on the clamped angles, as `volume_along_unless` needs)
        let volume_unless = |x: &[f64; 2], beat: f64| -> Result<Option<f64>, CalibError> {
            let (t, p) = (x[0].clamp(0.0, FRAC_PI_2), x[1].clamp(0.0, FRAC_PI_2));
            self.volume_along_unless(&dir(t, p), self.params.search_radius_rel, beat)
        };
        // Start: the optimum of the first-order model (a convex problem) when it bounds every
        // angle, else the best of a grid of directions.
        let start = match max_log_volume(&self.linear_rows()?, self.params.unbounded_column_rel) {
            Some(h) => {
                let norm = (h[0] * h[0] + h[1] * h[1] + h[2] * h[2]).sqrt();
                let u = [h[0] / norm, h[1] / norm, h[2] / norm];
                [u[2].clamp(-1.0, 1.0).acos(), u[1].atan2(u[0])]
            }
            None => {
                let n = self.params.direction_scan_3d;
                let step = FRAC_PI_2 / n as f64;
                let mut best = (f64::NEG_INFINITY, [0.0, 0.0]);
                for i in 0..n {
                    for j in 0..n {
                        let x = [(i as f64 + 0.5) * step, (j as f64 + 0.5) * step];
                        let v = volume(&x)?;
                        if v > best.0 {
                            best = (v, x);
                        }
                    }
                }
                best.1
            }
        };
        let x = nelder_mead_max(
            volume,
            volume_unless,
            start,
            self.params.nelder_mead_start_rad,
            self.params.direction_tol_3d_rad,
            self.params.nelder_mead_max_iter,
        )?;
        let (t, p) = (x[0].clamp(0.0, FRAC_PI_2), x[1].clamp(0.0, FRAC_PI_2));
        Ok(self.box_along(&dir(t, p), 0.0)?.0)
    }

    /// The error vector (output unit) for one orientation error.
    fn error_vector(&self, angles_rad: [f64; 3]) -> Result<Vec<f64>, CalibError> {
        let [psi, theta, gamma] = angles_rad;
        let dr = OrientationError::new(psi, theta, gamma)?.delta_r(self.kind);
        let actual: Vec<InputValues> = self
            .cal
            .nominal_values()
            .iter()
            .map(|v| v.rotated(&dr))
            .collect();
        let mut out = vec![0.0; actual.len()];
        self.cal
            .error_vector_at(self.reading, &actual, &mut ErrorWork::default(), &mut out)?;
        Ok(out)
    }

    /// The surface $\Gamma$ of this output over angles `angles` (indices into
    /// $\psi, \theta, \gamma$) on a `points` x `points` grid over $[-h, h]^2$, the third angle
    /// zero (Figure 4).
    ///
    /// # Errors
    /// [`CalibError::BadGrid`] for fewer than 2 points or a non-positive half range.
    pub fn surface(
        &self,
        angles: [usize; 2],
        half_range_rad: f64,
        points: usize,
    ) -> Result<Surface, CalibError> {
        if points < 2 || !half_range_rad.is_finite() || half_range_rad <= 0.0 {
            return Err(CalibError::BadGrid {
                points,
                half_range_rad,
            });
        }
        let grid: Vec<f64> = (0..points)
            .map(|i| -half_range_rad + 2.0 * half_range_rad * i as f64 / (points - 1) as f64)
            .collect();
        let mut values = Vec::with_capacity(points);
        for &v in &grid {
            let row = grid
                .iter()
                .map(|&u| {
                    let mut d = [0.0; 3];
                    d[angles[0]] = u;
                    d[angles[1]] = v;
                    self.rate_error(d)
                })
                .collect::<Result<Vec<_>, _>>()?;
            values.push(row);
        }
        Ok(Surface {
            output: self.output().to_string(),
            angles,
            u_rad: grid.clone(),
            v_rad: grid,
            delta_omega: values,
        })
    }

    /// $\Delta\omega$ of this output against one angle (`angle`, an index into $\psi, \theta,
    /// \gamma$), the other two zero, at `points` evenly spaced values over $[-h, h]$: the 1-D cuts
    /// of Figure 4 (c-f), as `(angle_rad, delta_omega)` pairs.
    ///
    /// # Errors
    /// [`CalibError::BadGrid`] for fewer than 2 points, a non-positive half range or an angle
    /// index above 2; as [`OutputRegion::rate_error`].
    pub fn cut(
        &self,
        angle: usize,
        half_range_rad: f64,
        points: usize,
    ) -> Result<Vec<(f64, f64)>, CalibError> {
        if points < 2 || angle > 2 || !half_range_rad.is_finite() || half_range_rad <= 0.0 {
            return Err(CalibError::BadGrid {
                points,
                half_range_rad,
            });
        }
        (0..points)
            .map(|i| {
                let a = -half_range_rad + 2.0 * half_range_rad * i as f64 / (points - 1) as f64;
                let mut d = [0.0; 3];
                d[angle] = a;
                Ok((a, self.rate_error(d)?))
            })
            .collect()
    }

    /// The line of intersection of $\Gamma$ with the plane $\Delta\omega = \omega_m$ in the
    /// plane of `angles` (Figure 5): for `directions` rays from the origin, the point where
    /// $\Delta\omega$ first reaches $\omega_m$, as `[u, v]` in radians.
    ///
    /// # Errors
    /// [`CalibError::Unbounded`] if a ray never reaches $\omega_m$ within [`RequirementParams::search_limit_rad`].
    pub fn boundary(
        &self,
        angles: [usize; 2],
        directions: usize,
    ) -> Result<Vec<[f64; 2]>, CalibError> {
        (0..directions)
            .map(|k| {
                let t = std::f64::consts::TAU * k as f64 / directions as f64;
                let (s, c) = t.sin_cos();
                let r = self.radius(&[c, s], 0.0, |r| {
                    let mut d = [0.0; 3];
                    d[angles[0]] = r * c;
                    d[angles[1]] = r * s;
                    Ok(self.rate_error(d)? <= self.accuracy)
                })?;
                Ok([r * c, r * s])
            })
            .collect()
    }
}

/// $\max \sum_j \log h_j$ subject to $\sum_j a_{ij} h_j \le 1$ for every row $i$ ($a \ge 0$):
/// the largest-volume box of a region $\{\delta : |L\delta| \le \omega_m\}$ (the first-order
/// model: the worst corner of the box makes $\sum_j |L_{ij}| h_j$). A convex problem, solved by
/// a log-barrier Newton method; `None` when the rows do not bound some angle (a column below
/// `unbounded_column_rel` of the largest).
fn max_log_volume(rows: &[Vec<f64>], unbounded_column_rel: f64) -> Option<Vec<f64>> {
    let d = rows.first()?.len();
    let colmax: Vec<f64> = (0..d)
        .map(|j| rows.iter().map(|r| r[j]).fold(0.0, f64::max))
        .collect();
    let top = colmax.iter().copied().fold(0.0, f64::max);
    if top <= 0.0 || colmax.iter().any(|&c| c <= unbounded_column_rel * top) {
        return None;
    }
    let mut h: Vec<f64> = colmax.iter().map(|c| 0.5 / (d as f64 * c)).collect();
    let slack = |h: &[f64]| -> Option<Vec<f64>> {
        let s: Vec<f64> = rows
            .iter()
            .map(|r| 1.0 - r.iter().zip(h).map(|(a, x)| a * x).sum::<f64>())
            .collect();
        (s.iter().all(|&v| v > 0.0) && h.iter().all(|&x| x > 0.0)).then_some(s)
    };
    let phi = |t: f64, h: &[f64]| -> f64 {
        match slack(h) {
            Some(s) => {
                -t * h.iter().map(|x| x.ln()).sum::<f64>() - s.iter().map(|v| v.ln()).sum::<f64>()
            }
            None => f64::INFINITY,
        }
    };
    let mut t = 1.0;
    while t < BARRIER_T_MAX {
        for _ in 0..BARRIER_NEWTON_STEPS {
            let s = slack(&h)?;
            let mut g = nalgebra::DVector::zeros(d);
            let mut hess = nalgebra::DMatrix::zeros(d, d);
            for j in 0..d {
                g[j] = -t / h[j];
                hess[(j, j)] = t / (h[j] * h[j]);
            }
            for (r, si) in rows.iter().zip(&s) {
                for j in 0..d {
                    g[j] += r[j] / si;
                    for k in 0..d {
                        hess[(j, k)] += r[j] * r[k] / (si * si);
                    }
                }
            }
            let step = hess.cholesky()?.solve(&(-&g));
            let decrement = -g.dot(&step);
            if decrement < 1e-14 {
                break;
            }
            let f0 = phi(t, &h);
            let mut alpha = 1.0;
            loop {
                let trial: Vec<f64> = h
                    .iter()
                    .zip(step.iter())
                    .map(|(x, s)| x + alpha * s)
                    .collect();
                if phi(t, &trial) <= f0 - 0.25 * alpha * decrement {
                    h = trial;
                    break;
                }
                alpha *= 0.5;
                if alpha < 1e-12 {
                    break;
                }
            }
        }
        t *= 10.0;
    }
    Some(h)
}

/// Nelder-Mead maximisation of `f` over two variables from `start` with an initial simplex of
/// size `size`, until the simplex is smaller than `tol` (or `max_iter` iterations).
///
/// The trial points (reflection, expansion, contraction) are evaluated with
/// `f_unless(x, beat)`: `f(x)`, or `None` when `f(x)` is at most `beat`. Each trial's value is
/// kept only when it beats a value already known (the reflection the second best, the
/// expansion the reflection, the contraction the worst), and otherwise only compared, so
/// asking for it with that value as `beat` takes the same steps as evaluating it in full.
fn nelder_mead_max<F, U>(
    f: F,
    f_unless: U,
    start: [f64; 2],
    size: f64,
    tol: f64,
    max_iter: usize,
) -> Result<[f64; 2], CalibError>
where
    F: Fn(&[f64; 2]) -> Result<f64, CalibError>,
    U: Fn(&[f64; 2], f64) -> Result<Option<f64>, CalibError>,
{
    let mut pts = [
        start,
        [start[0] + size, start[1]],
        [start[0], start[1] + size],
    ];
    let mut vals = [f(&pts[0])?, f(&pts[1])?, f(&pts[2])?];
    for _ in 0..max_iter {
        // order best (largest) first
        let mut idx = [0usize, 1, 2];
        idx.sort_by(|&a, &b| vals[b].total_cmp(&vals[a]));
        pts = idx.map(|i| pts[i]);
        vals = idx.map(|i| vals[i]);
        let spread = (0..2)
            .map(|k| {
                (pts[1][k] - pts[0][k])
                    .abs()
                    .max((pts[2][k] - pts[0][k]).abs())
            })
            .fold(0.0, f64::max);
        if spread < tol {
            break;
        }
        let c = [(pts[0][0] + pts[1][0]) / 2.0, (pts[0][1] + pts[1][1]) / 2.0];
        let at = |s: f64| [c[0] + s * (pts[2][0] - c[0]), c[1] + s * (pts[2][1] - c[1])];
        let r = at(-1.0);
        // `None`: the reflection is at most the second best (so at most the best: vals is
        // sorted), where its value is not kept
        match f_unless(&r, vals[1])? {
            Some(fr) if fr > vals[0] => {
                let e = at(-2.0);
                // `None`: the expansion is at most the reflection, which is kept
                (pts[2], vals[2]) = match f_unless(&e, fr)? {
                    Some(fe) if fe > fr => (e, fe),
                    _ => (r, fr),
                };
            }
            Some(fr) if fr > vals[1] => (pts[2], vals[2]) = (r, fr),
            _ => {
                let k = at(0.5);
                // `None`: the contraction is at most the worst: shrink
                match f_unless(&k, vals[2])? {
                    Some(fk) if fk > vals[2] => (pts[2], vals[2]) = (k, fk),
                    _ => {
                        for i in 1..3 {
                            pts[i] = [(pts[i][0] + pts[0][0]) / 2.0, (pts[i][1] + pts[0][1]) / 2.0];
                            vals[i] = f(&pts[i])?;
                        }
                    }
                }
            }
        }
    }
    let best = (0..3).fold(0, |b, i| if vals[i] > vals[b] { i } else { b });
    Ok(pts[best])
}

/// Maximise `f(x).1` over $[lo, hi]$: a scan of `scan` midpoints, then a golden section on the
/// best cell to bracket width `tol`. Returns the argument's result and the maximiser.
///
/// The scan calls `scan_f(x, beat)` instead: `f(x).1`, or `None` when that value is at most
/// `beat` (the best so far), which cannot replace the best (it must be larger), so the scan
/// picks the cell a scan of `f` would.
fn golden_max<T, F, S>(
    f: F,
    scan_f: S,
    lo: f64,
    hi: f64,
    scan: usize,
    tol: f64,
) -> Result<(T, f64), CalibError>
where
    F: Fn(f64) -> Result<(T, f64), CalibError>,
    S: Fn(f64, f64) -> Result<Option<f64>, CalibError>,
{
    let step = (hi - lo) / scan as f64;
    let mut best = (0usize, f64::NEG_INFINITY);
    if scan > 1 {
        for k in 0..scan {
            if let Some(v) = scan_f(lo + (k as f64 + 0.5) * step, best.1)? {
                if v > best.1 {
                    best = (k, v);
                }
            }
        }
    }
    let centre = lo + (best.0 as f64 + 0.5) * step;
    let (mut a, mut b) = if scan > 1 {
        ((centre - step).max(lo), (centre + step).min(hi))
    } else {
        (lo, hi)
    };
    let g = (5f64.sqrt() - 1.0) / 2.0;
    let mut x1 = b - g * (b - a);
    let mut x2 = a + g * (b - a);
    let mut f1 = f(x1)?.1;
    let mut f2 = f(x2)?.1;
    while b - a > tol {
        if f1 < f2 {
            a = x1;
            x1 = x2;
            f1 = f2;
            x2 = a + g * (b - a);
            f2 = f(x2)?.1;
        } else {
            b = x2;
            x2 = x1;
            f2 = f1;
            x1 = b - g * (b - a);
            f1 = f(x1)?.1;
        }
    }
    let x = 0.5 * (a + b);
    Ok((f(x)?.0, x))
}

#[cfg(all(test, feature = "paper"))]
mod tests {
    use super::*;

    /// The box search's shortcuts (the corner that failed last tried first; the direction
    /// scan's bisections stopped once their upper end cannot beat the best volume) give bit
    /// for bit the boxes of the long way: the paper's sensor under three readings, both
    /// $\Delta\mathbf R$ kinds, at its accuracies (the linear regime, a scaled reference box)
    /// and at 300 and 30,000 times them (searched directly, where the region's curvature
    /// shows).
    fn same_boxes(problem: &RequirementProblem) -> usize {
        let bits = |b: &OutputBox| {
            (
                b.half_rad.map(|h| h.map(f64::to_bits)),
                b.volume.to_bits(),
                b.boundary_max_ratio.to_bits(),
            )
        };
        let mut three = 0;
        for k in 0..problem.calibration.outputs().len() {
            let short = problem.region(k).unwrap();
            if short.sensitive_angles().is_empty() {
                continue;
            }
            three += usize::from(short.sensitive_angles().len() == 3);
            let mut long = short.clone();
            long.long_way = true;
            match (short.max_box(), long.max_box()) {
                (Ok(a), Ok(b)) => assert_eq!(bits(&a), bits(&b)),
                (Err(a), Err(b)) => assert_eq!(a.to_string(), b.to_string()),
                (a, b) => panic!("{a:?} vs {b:?}"),
            }
        }
        three
    }

    /// The shortcuts on outputs sensitive to all three angles (the Nelder-Mead search of the
    /// corner direction, whose rejected trial points stop early): an IMU's gyros and
    /// accelerometers (calib-lsq's noise-covariance benchmark sensor) at 32 positions of a
    /// three-axis table, under the readings where its boxes have three sides.
    #[test]
    fn three_angle_box_search_shortcuts_equal_the_long_way() {
        use gw_model::{Output, Regressor, SensorModel, Term};
        use nalgebra::{Rotation3, Vector3};
        let term = |c: &str, r: &str, value: f64, known: bool| Term {
            coefficient: c.into(),
            regressor: Regressor::parse(r).unwrap(),
            value,
            known,
        };
        let gyro = |axis: &str, w: &str| Output {
            name: format!("g{axis}"),
            unit: "deg_per_h".into(),
            accuracy: 0.1,
            terms: vec![
                term(&format!("omega_{axis}"), w, 1.0, true),
                term(&format!("bg_{axis}"), "1", 0.6, false),
                term(&format!("gs_{axis}x"), "a_x", 0.3, false),
                term(&format!("gs_{axis}y"), "a_y", -0.2, false),
                term(&format!("gs_{axis}z"), "a_z", 0.15, false),
            ],
        };
        let acc = |axis: &str, own: &str, others: [&str; 2]| Output {
            name: format!("a{axis}"),
            unit: "mg".into(),
            accuracy: 0.1,
            terms: vec![
                term(&format!("ba_{axis}"), "1", 0.8, false),
                term(&format!("sf_{axis}"), own, 1000.3, false),
                term(&format!("mis_{axis}1"), others[0], 0.5, false),
                term(&format!("mis_{axis}2"), others[1], -0.3, false),
                term(&format!("k2_{axis}"), &format!("{own}^2"), 0.02, false),
            ],
        };
        let sensor = SensorModel::new(vec![
            gyro("x", "w_x"),
            gyro("y", "w_y"),
            acc("x", "a_x", ["a_y", "a_z"]),
            acc("z", "a_z", ["a_x", "a_y"]),
        ])
        .unwrap();
        let mut positions = Vec::new();
        for m in 0..4 {
            for i in 0..8 {
                let (m, i) = (f64::from(m) * 90.0 + 10.0, f64::from(i) * 45.0);
                let r = Rotation3::from_axis_angle(&Vector3::x_axis(), m.to_radians())
                    * Rotation3::from_axis_angle(&Vector3::y_axis(), i.to_radians());
                positions.push(crate::Position::new(*r.matrix(), vec![0.0, m, i]).unwrap());
            }
        }
        let schedule = crate::Schedule::new(positions).unwrap();
        let cal = Calibration::new(&sensor, &gw_model::paper::site(), &schedule).unwrap();
        let mut three = 0;
        for reading in [Reading::PAPER, Reading::USER, Reading::AS_PRINTED] {
            three += same_boxes(&RequirementProblem::new(
                cal.clone(),
                reading,
                DeltaRKind::Exact,
            ));
        }
        assert!(three > 0, "no output with three sensitive angles");
    }

    #[test]
    fn box_search_shortcuts_equal_the_long_way() {
        for scale in [1.0, 300.0, 3e4] {
            let sensor = gw_model::paper::gyrowheel()
                .with_accuracy_scaled(scale)
                .unwrap();
            let cal =
                Calibration::new(&sensor, &gw_model::paper::site(), &crate::paper::schedule())
                    .unwrap();
            for reading in [Reading::PAPER, Reading::USER, Reading::AS_PRINTED] {
                for kind in [DeltaRKind::SmallAngle, DeltaRKind::Exact] {
                    same_boxes(&RequirementProblem::new(cal.clone(), reading, kind));
                }
            }
        }
    }
}
