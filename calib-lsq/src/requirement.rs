//! Surfaces $\Gamma_1$, $\Gamma_2$ (Figure 4) and the requirement extraction of eq 15-16
//! (Figure 5).

use crate::analysis::{OrientationErrorAnalysis, Reading};
use crate::error::{CalibError, finite};
use crate::schedule::Schedule;
use gw_model::units::deg_per_h_to_rad_per_s;
use gw_model::{DeltaRKind, DriftCoefficients, OrientationAngles, SensingAxis, Site};
use std::f64::consts::FRAC_PI_2;

/// The required calibration accuracy of §2.3, deg/h.
pub const PAPER_OMEGA_M_DEG_PER_H: f64 = 0.01;

/// Bisection stops when the bracket on the rectangle's corner radius is narrower than this, rad
/// ($10^{-12}$ rad $\approx 6\times10^{-11}$ deg, far below the $10^{-6}$ deg asked for).
pub const RADIUS_TOL_RAD: f64 = 1e-12;

/// Golden-section search on the corner direction stops at this bracket width, rad. The area is
/// flat (quadratic) at its optimum, so the half-sides are located to about
/// $\rho \cdot$ `DIRECTION_TOL_RAD` $\approx 5\times10^{-13}$ rad.
pub const DIRECTION_TOL_RAD: f64 = 1e-9;

/// Directions scanned before the golden-section refinement (guards against a local optimum of
/// a polygonal region).
pub const DIRECTION_SCAN: usize = 64;

/// Largest corner radius searched, rad (about 28.6 deg).
pub const SEARCH_LIMIT_RAD: f64 = 0.5;

/// Points per edge at which a solved rectangle's boundary is re-checked.
pub const BOUNDARY_CHECK_POINTS: usize = 32;

/// Everything the requirement of eq 15-16 depends on.
#[derive(Debug, Clone, PartialEq)]
pub struct RequirementProblem {
    /// The true (nominal) drift coefficients, e.g. Table 1.
    pub coefficients: DriftCoefficients,
    /// Latitude and earth rate.
    pub site: Site,
    /// The calibration positions.
    pub schedule: Schedule,
    /// Required calibration accuracy $\omega_m$, rad/s.
    pub omega_m_rad_per_s: f64,
    /// The reading of eq 13.
    pub reading: Reading,
    /// How the angles become $\Delta\mathbf R$ (eq 7 small-angle by default).
    pub delta_r_kind: DeltaRKind,
}

impl RequirementProblem {
    /// The paper's inputs (§2.3): Table 1, $\omega_m = 0.01$ deg/h, with this project's
    /// defaults for what the paper leaves open: Harbin and WGS-84 ([`Site::paper_default`]),
    /// [`Schedule::paper_default`], [`Reading::PAPER`], the small-angle $\Delta\mathbf R$ of eq 7.
    #[must_use]
    pub fn paper() -> Self {
        Self {
            coefficients: DriftCoefficients::table_1(),
            site: Site::paper_default(),
            schedule: Schedule::paper_default(),
            omega_m_rad_per_s: deg_per_h_to_rad_per_s(PAPER_OMEGA_M_DEG_PER_H),
            reading: Reading::PAPER,
            delta_r_kind: DeltaRKind::SmallAngle,
        }
    }

    /// Set $\omega_m$ in deg/h.
    ///
    /// # Errors
    /// [`CalibError::NonPositive`] / [`CalibError::NonFinite`] naming `omega_m`.
    pub fn with_omega_m_deg_per_h(mut self, omega_m_deg_per_h: f64) -> Result<Self, CalibError> {
        finite("omega_m", omega_m_deg_per_h)?;
        if omega_m_deg_per_h <= 0.0 {
            return Err(CalibError::NonPositive {
                field: "omega_m",
                value: omega_m_deg_per_h,
            });
        }
        self.omega_m_rad_per_s = deg_per_h_to_rad_per_s(omega_m_deg_per_h);
        Ok(self)
    }

    /// The plane problem of one axis.
    ///
    /// # Errors
    /// As [`OrientationErrorAnalysis::new`].
    pub fn plane(&self, axis: SensingAxis) -> Result<PlaneProblem, CalibError> {
        Ok(PlaneProblem {
            analysis: OrientationErrorAnalysis::new(
                self.coefficients.axis(axis),
                &self.schedule,
                &self.site,
                self.reading,
            )?,
            kind: self.delta_r_kind,
            omega_m_rad_per_s: self.omega_m_rad_per_s,
        })
    }

    /// $\Delta\omega$ (eq 14, rad/s) of one axis for one orientation error.
    ///
    /// # Errors
    /// As [`OrientationErrorAnalysis::delta_omega`].
    pub fn rate_error(
        &self,
        axis: SensingAxis,
        angles: &OrientationAngles,
    ) -> Result<f64, CalibError> {
        self.plane(axis)?
            .analysis
            .delta_omega_for_angles(angles, self.delta_r_kind)
    }

    /// The requirement of eq 15: the largest-area rectangles of both planes and the combined
    /// bounds $I_\psi$, $I_\theta$, $I_\gamma$.
    ///
    /// # Formula
    /// $I_\psi$ = half-side of the $x$-plane rectangle along $\Delta\psi$;
    /// $I_\gamma$ = half-side of the $y$-plane rectangle along $\Delta\gamma$;
    /// $I_\theta = \min$ of the two planes' half-sides along $\Delta\theta$ (both rectangles stay
    /// inside their regions when $\Delta\theta$ is cut to the smaller one).
    ///
    /// # Reference
    /// Eq 15-16, Figure 5.
    ///
    /// # Errors
    /// As [`PlaneProblem::max_rectangle`].
    pub fn requirement(&self) -> Result<OrientationRequirement, CalibError> {
        let x_plane = self.plane(SensingAxis::X)?.max_rectangle()?;
        let y_plane = self.plane(SensingAxis::Y)?.max_rectangle()?;
        Ok(OrientationRequirement {
            psi_rad: x_plane.half_u_rad,
            theta_rad: x_plane.half_v_rad.min(y_plane.half_u_rad),
            gamma_rad: y_plane.half_v_rad,
            x_plane,
            y_plane,
        })
    }
}

/// The requirement $|\Delta\psi| \le I_\psi$, $|\Delta\theta| \le I_\theta$,
/// $|\Delta\gamma| \le I_\gamma$ (eq 15), radians.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OrientationRequirement {
    /// $I_\psi$, rad.
    pub psi_rad: f64,
    /// $I_\theta$, rad (the smaller of the two planes').
    pub theta_rad: f64,
    /// $I_\gamma$, rad.
    pub gamma_rad: f64,
    /// The $x$-axis rectangle in the $(\Delta\psi, \Delta\theta)$ plane.
    pub x_plane: Rectangle,
    /// The $y$-axis rectangle in the $(\Delta\theta, \Delta\gamma)$ plane.
    pub y_plane: Rectangle,
}

impl OrientationRequirement {
    /// $(I_\psi, I_\theta, I_\gamma)$ in degrees.
    #[must_use]
    pub fn deg(&self) -> [f64; 3] {
        [
            self.psi_rad.to_degrees(),
            self.theta_rad.to_degrees(),
            self.gamma_rad.to_degrees(),
        ]
    }
}

/// A centred, axis-aligned rectangle $|u| \le$ `half_u_rad`, $|v| \le$ `half_v_rad`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Rectangle {
    /// Half-side along the plane's first angle ($\Delta\psi$ for $x$, $\Delta\theta$ for $y$), rad.
    pub half_u_rad: f64,
    /// Half-side along the plane's second angle ($\Delta\theta$ for $x$, $\Delta\gamma$ for $y$),
    /// rad.
    pub half_v_rad: f64,
    /// Area $4\,$`half_u`$\,$`half_v`, rad².
    pub area_rad2: f64,
    /// Largest $\Delta\omega$ found on the rectangle's boundary (corners and
    /// [`BOUNDARY_CHECK_POINTS`] points per edge), rad/s; at most $\omega_m$ up to the
    /// bisection tolerance when the region is convex.
    pub boundary_max_rad_per_s: f64,
}

/// Grid data of a surface $\Gamma_1$ ($x$ axis over $(\Delta\psi, \Delta\theta)$) or $\Gamma_2$
/// ($y$ axis over $(\Delta\theta, \Delta\gamma)$), Figure 4.
#[derive(Debug, Clone, PartialEq)]
pub struct Surface {
    /// The axis.
    pub axis: SensingAxis,
    /// Names of the two plane angles, e.g. `["delta_psi", "delta_theta"]`.
    pub angle_names: [&'static str; 2],
    /// Grid values of the first angle, rad.
    pub u_rad: Vec<f64>,
    /// Grid values of the second angle, rad.
    pub v_rad: Vec<f64>,
    /// $\Delta\omega$ (rad/s) at `(u_rad[i], v_rad[j])`, indexed `[j][i]`.
    pub delta_omega_rad_per_s: Vec<Vec<f64>>,
}

/// The rate-sensing error of one axis over its plane of orientation errors.
///
/// The $x$ axis is studied in the $(\Delta\psi, \Delta\theta)$ plane with $\Delta\gamma = 0$, the
/// $y$ axis in the $(\Delta\theta, \Delta\gamma)$ plane with $\Delta\psi = 0$ (Figures 4a-b, 5);
/// in the default reading the left-out angle has no effect (claim 1).
#[derive(Debug, Clone)]
pub struct PlaneProblem {
    analysis: OrientationErrorAnalysis,
    kind: DeltaRKind,
    omega_m_rad_per_s: f64,
}

impl PlaneProblem {
    /// The axis.
    #[must_use]
    pub fn axis(&self) -> SensingAxis {
        self.analysis.axis()
    }

    /// The prepared analysis.
    #[must_use]
    pub fn analysis(&self) -> &OrientationErrorAnalysis {
        &self.analysis
    }

    /// Names of the two plane angles.
    #[must_use]
    pub fn angle_names(&self) -> [&'static str; 2] {
        match self.axis() {
            SensingAxis::X => ["delta_psi", "delta_theta"],
            SensingAxis::Y => ["delta_theta", "delta_gamma"],
        }
    }

    /// The orientation error at plane point $(u, v)$, radians.
    #[must_use]
    pub fn angles(&self, u_rad: f64, v_rad: f64) -> OrientationAngles {
        match self.axis() {
            SensingAxis::X => OrientationAngles {
                delta_psi_rad: u_rad,
                delta_theta_rad: v_rad,
                delta_gamma_rad: 0.0,
            },
            SensingAxis::Y => OrientationAngles {
                delta_psi_rad: 0.0,
                delta_theta_rad: u_rad,
                delta_gamma_rad: v_rad,
            },
        }
    }

    /// $\Delta\omega$ (rad/s) at plane point $(u, v)$.
    ///
    /// # Errors
    /// [`CalibError::NonFinite`] for a non-finite angle; as
    /// [`OrientationErrorAnalysis::delta_omega`].
    pub fn rate_error(&self, u_rad: f64, v_rad: f64) -> Result<f64, CalibError> {
        finite("u", u_rad)?;
        finite("v", v_rad)?;
        self.analysis
            .delta_omega_for_angles(&self.angles(u_rad, v_rad), self.kind)
    }

    /// The surface on a `points` x `points` grid over $[-h, h]^2$ (Figure 4).
    ///
    /// # Errors
    /// [`CalibError::BadGrid`] for fewer than 2 points or a non-positive half range.
    pub fn surface(&self, half_range_rad: f64, points: usize) -> Result<Surface, CalibError> {
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
                .map(|&u| self.rate_error(u, v))
                .collect::<Result<Vec<_>, _>>()?;
            values.push(row);
        }
        Ok(Surface {
            axis: self.axis(),
            angle_names: self.angle_names(),
            u_rad: grid.clone(),
            v_rad: grid,
            delta_omega_rad_per_s: values,
        })
    }

    /// Largest radius $\rho$ along `direction_rad` such that `ok(ρ)`, by doubling then
    /// bisection to [`RADIUS_TOL_RAD`].
    fn radius<F>(&self, direction_rad: f64, ok: F) -> Result<f64, CalibError>
    where
        F: Fn(f64) -> Result<bool, CalibError>,
    {
        let mut lo = 0.0;
        let mut hi = 1e-4;
        while ok(hi)? {
            lo = hi;
            hi *= 2.0;
            if hi > SEARCH_LIMIT_RAD {
                return Err(CalibError::Unbounded {
                    axis: self.axis(),
                    direction_rad,
                    limit_rad: SEARCH_LIMIT_RAD,
                });
            }
        }
        while hi - lo > RADIUS_TOL_RAD {
            let mid = 0.5 * (lo + hi);
            if ok(mid)? {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        Ok(lo)
    }

    /// The line of intersection of $\Gamma$ with the plane $\Delta\omega = \omega_m$ (Figure 5):
    /// for `directions` rays from the origin, the point where $\Delta\omega$ first reaches
    /// $\omega_m$, as `[u, v]` in radians.
    ///
    /// # Errors
    /// [`CalibError::Unbounded`] if a ray never reaches $\omega_m$ within [`SEARCH_LIMIT_RAD`].
    pub fn boundary(&self, directions: usize) -> Result<Vec<[f64; 2]>, CalibError> {
        (0..directions)
            .map(|k| {
                let t = std::f64::consts::TAU * k as f64 / directions as f64;
                let (s, c) = t.sin_cos();
                let r = self.radius(t, |r| {
                    Ok(self.rate_error(r * c, r * s)? <= self.omega_m_rad_per_s)
                })?;
                Ok([r * c, r * s])
            })
            .collect()
    }

    fn corners_ok(&self, a: f64, b: f64) -> Result<bool, CalibError> {
        for (su, sv) in [(1.0, 1.0), (-1.0, 1.0), (1.0, -1.0), (-1.0, -1.0)] {
            if self.rate_error(su * a, sv * b)? > self.omega_m_rad_per_s {
                return Ok(false);
            }
        }
        Ok(true)
    }

    /// Half-sides of the largest rectangle whose corners point in `direction_rad`.
    fn rectangle_at(&self, t: f64) -> Result<(f64, f64, f64), CalibError> {
        let (s, c) = t.sin_cos();
        let r = self.radius(t, |r| self.corners_ok(r * c, r * s))?;
        let (a, b) = (r * c, r * s);
        Ok((a, b, 4.0 * a * b))
    }

    /// The largest-area centred axis-aligned rectangle inside $\Delta\omega \le \omega_m$
    /// (Figure 5, "to maximize the areas of the two rectangles").
    ///
    /// # Formula
    /// With corners $(\pm\rho\cos t, \pm\rho\sin t)$, $\rho(t)$ is the largest radius at which all
    /// four corners satisfy $\Delta\omega \le \omega_m$ (bisection to [`RADIUS_TOL_RAD`]), and
    /// $t$ maximises the area $2\rho(t)^2\sin 2t$ ([`DIRECTION_SCAN`]-point scan, then golden
    /// section to [`DIRECTION_TOL_RAD`]). For a convex region (every first-order reading:
    /// $\Delta\omega$ is a maximum of absolute values of linear forms) the corners bound the
    /// whole rectangle; the result records the largest $\Delta\omega$ found on its boundary.
    ///
    /// # Reference
    /// Eq 15-16, Figure 5.
    ///
    /// # Errors
    /// [`CalibError::Unbounded`] if the region is not bounded within [`SEARCH_LIMIT_RAD`].
    pub fn max_rectangle(&self) -> Result<Rectangle, CalibError> {
        let step = FRAC_PI_2 / DIRECTION_SCAN as f64;
        let mut best = (0usize, f64::NEG_INFINITY);
        for k in 0..DIRECTION_SCAN {
            let t = (k as f64 + 0.5) * step;
            let area = self.rectangle_at(t)?.2;
            if area > best.1 {
                best = (k, area);
            }
        }
        let centre = (best.0 as f64 + 0.5) * step;
        let (mut lo, mut hi) = ((centre - step).max(0.0), (centre + step).min(FRAC_PI_2));
        let inv_phi = (5f64.sqrt() - 1.0) / 2.0;
        let mut x1 = hi - inv_phi * (hi - lo);
        let mut x2 = lo + inv_phi * (hi - lo);
        let mut f1 = self.rectangle_at(x1)?.2;
        let mut f2 = self.rectangle_at(x2)?.2;
        while hi - lo > DIRECTION_TOL_RAD {
            if f1 < f2 {
                lo = x1;
                x1 = x2;
                f1 = f2;
                x2 = lo + inv_phi * (hi - lo);
                f2 = self.rectangle_at(x2)?.2;
            } else {
                hi = x2;
                x2 = x1;
                f2 = f1;
                x1 = hi - inv_phi * (hi - lo);
                f1 = self.rectangle_at(x1)?.2;
            }
        }
        let (a, b, area) = self.rectangle_at(0.5 * (lo + hi))?;
        let mut boundary_max: f64 = 0.0;
        let n = BOUNDARY_CHECK_POINTS;
        for i in 0..=n {
            let s = -1.0 + 2.0 * i as f64 / n as f64;
            for (u, v) in [(s * a, b), (s * a, -b), (a, s * b), (-a, s * b)] {
                boundary_max = boundary_max.max(self.rate_error(u, v)?);
            }
        }
        Ok(Rectangle {
            half_u_rad: a,
            half_v_rad: b,
            area_rad2: area,
            boundary_max_rad_per_s: boundary_max,
        })
    }
}
