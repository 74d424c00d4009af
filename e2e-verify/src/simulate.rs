//! One calibration run of a turntable with geometric errors $\chi$: the exact orientation at
//! every test position, the outputs and the least-squares calibration of the chosen
//! [`Reading`] of eq 13, and the rate-sensing errors $\Delta\omega_x$, $\Delta\omega_y$ (eq 14).

use crate::error::E2eError;
use calib_lsq::{
    ErrorAnalysis, ErrorForm, Estimate, OrientationErrorAnalysis, OutputsAt, Reading, Regression,
    Schedule, rate_vector, regression_matrix,
};
use gw_model::units::rad_per_s_to_deg_per_h;
use gw_model::{
    AxisCoefficients, DriftCoefficients, Inputs, N_COEFFICIENTS, SensingAxis, Site, regressors,
};
use nalgebra::{DMatrix, DVector, Matrix3, Vector3};
use tt_kinematics::rotation::{Axis, rot};
use tt_kinematics::{CHI_LEN, ChainKind, ErrorComponent, Pose, TurntableErrors, delta_r};

/// The two sensing axes in the order used by every `[_; 2]` of this crate: $x$, then $y$.
pub const AXES: [SensingAxis; 2] = [SensingAxis::X, SensingAxis::Y];

/// Precomputed data of one sensing axis: nominal regression and its pseudo-inverse.
#[derive(Debug, Clone)]
pub(crate) struct AxisData {
    pub coefficients: AxisCoefficients,
    /// $\mathbf A$ (n x 7).
    pub a: DMatrix<f64>,
    /// $\mathbf A^+ = \mathbf R^{-1}\mathbf Q^T$ (7 x n), from calib-lsq's QR.
    pub pinv: DMatrix<f64>,
    /// $\mathbf b_2$ (rad/s).
    pub b2: DVector<f64>,
    /// $\mathbf A\boldsymbol\beta$ (rad/s).
    pub a_beta: DVector<f64>,
    /// $\lVert\mathbf P\rVert_\infty$ with $\mathbf P = \mathbf A\mathbf A^+$.
    pub p_norm_inf: f64,
    /// $\lVert\mathbf I - \mathbf P\rVert_\infty$.
    pub i_minus_p_norm_inf: f64,
}

/// An end-to-end calibration simulator: drift coefficients (the truth), site, schedule and
/// reading fixed; the nominal regressions are factored once (never inside a Monte Carlo loop).
///
/// # Formula
/// For turntable errors $\chi$ and position $i$ with pose $(\phi_{1i}, \phi_{2i})$:
/// $$\Delta\mathbf R_i = \mathbf R_d^T\mathbf R_t = R_z(\phi_{2i})^T\,\mathbf U\,R_z(\phi_{2i})\,\mathbf V,$$
/// $$\mathbf U = R_y(\Delta\phi_{y1})R_z(\Delta\alpha_{z1})R_x(\Delta\alpha_{x1})R_y(\Delta\varepsilon_y)R_x(\Delta\varepsilon_x),
/// \quad \mathbf V = R_y(\Delta\alpha_{y2})R_z(\Delta\phi_{z2})R_x(\Delta\alpha_{x2})$$
/// (the exact chain of Table 3; $\phi_1$ cancels), then eq 8-14 of calib-lsq with the chosen
/// [`Reading`]: actual inputs $\mathbf v_i' = \Delta\mathbf R_i^T\mathbf v_i$, outputs
/// $\mathbf b_1$, estimate, error vector $\Delta\hat{\boldsymbol\omega}$ and
/// $\Delta\omega = \lVert\Delta\hat{\boldsymbol\omega}\rVert_\infty$.
///
/// # Reference
/// Eq 7-14 (calibration) and eq 17-23 (turntable chain).
#[derive(Debug, Clone)]
pub struct EndToEnd {
    coefficients: DriftCoefficients,
    site: Site,
    schedule: Schedule,
    reading: Reading,
    poses: Vec<Pose>,
    rz: Vec<Matrix3<f64>>,
    nominal: Vec<Inputs>,
    pub(crate) axes: [AxisData; 2],
    analyses: [OrientationErrorAnalysis; 2],
}

/// The result of one simulated calibration run (reference path through calib-lsq).
#[derive(Debug, Clone, PartialEq)]
pub struct EndToEndRun {
    /// $\Delta\mathbf R_i$ of every position (exact chain, [`tt_kinematics::delta_r`]).
    pub delta_r: Vec<Matrix3<f64>>,
    /// The full eq 7-14 analysis of the $x$ and $y$ axes.
    pub analyses: [ErrorAnalysis; 2],
}

impl EndToEndRun {
    /// $(\Delta\omega_x, \Delta\omega_y)$, rad/s.
    #[must_use]
    pub fn delta_omega_rad_per_s(&self) -> [f64; 2] {
        [
            self.analyses[0].delta_omega_rad_per_s,
            self.analyses[1].delta_omega_rad_per_s,
        ]
    }

    /// $(\Delta\omega_x, \Delta\omega_y)$, deg/h.
    #[must_use]
    pub fn delta_omega_deg_per_h(&self) -> [f64; 2] {
        self.delta_omega_rad_per_s().map(rad_per_s_to_deg_per_h)
    }
}

impl EndToEnd {
    /// Prepare the simulation.
    ///
    /// # Errors
    /// [`E2eError::Calib`] if the schedule cannot identify an axis.
    pub fn new(
        coefficients: &DriftCoefficients,
        site: &Site,
        schedule: &Schedule,
        reading: Reading,
    ) -> Result<Self, E2eError> {
        let nominal = schedule.inputs(site);
        let n = nominal.len();
        let mut axes = Vec::with_capacity(2);
        let mut analyses = Vec::with_capacity(2);
        for axis in AXES {
            let coeffs = *coefficients.axis(axis);
            let a = regression_matrix(axis, &nominal);
            let regression = Regression::new(axis, a.clone())?;
            let mut pinv = DMatrix::zeros(N_COEFFICIENTS, n);
            for k in 0..n {
                let mut e = DVector::zeros(n);
                e[k] = 1.0;
                pinv.set_column(k, &regression.estimate(&e)?);
            }
            let p = &a * &pinv;
            let i_minus_p = DMatrix::identity(n, n) - &p;
            let beta = DVector::from_column_slice(&coeffs.rad_per_s());
            axes.push(AxisData {
                coefficients: coeffs,
                a_beta: &a * &beta,
                b2: rate_vector(axis, &nominal),
                p_norm_inf: row_sum_norm(&p),
                i_minus_p_norm_inf: row_sum_norm(&i_minus_p),
                a,
                pinv,
            });
            analyses.push(OrientationErrorAnalysis::new(
                &coeffs, schedule, site, reading,
            )?);
        }
        let poses: Vec<Pose> = schedule
            .positions()
            .iter()
            .map(|p| Pose {
                phi1_rad: p.phi_1_rad(),
                phi2_rad: p.phi_2_rad(),
            })
            .collect();
        let rz = poses.iter().map(|p| rot(Axis::Z, p.phi2_rad)).collect();
        let [ax, ay]: [AxisData; 2] = axes
            .try_into()
            .unwrap_or_else(|_| unreachable!("two axes pushed"));
        let [nx, ny]: [OrientationErrorAnalysis; 2] = analyses
            .try_into()
            .unwrap_or_else(|_| unreachable!("two axes pushed"));
        Ok(Self {
            coefficients: *coefficients,
            site: *site,
            schedule: schedule.clone(),
            reading,
            poses,
            rz,
            nominal,
            axes: [ax, ay],
            analyses: [nx, ny],
        })
    }

    /// The paper's calibration (Table 1, Harbin, [`Schedule::paper_default`]) with a reading.
    #[must_use]
    pub fn paper(reading: Reading) -> Self {
        Self::new(
            &DriftCoefficients::table_1(),
            &Site::paper_default(),
            &Schedule::paper_default(),
            reading,
        )
        .unwrap_or_else(|_| unreachable!("the default schedule identifies both axes"))
    }

    /// The reading used.
    #[must_use]
    pub fn reading(&self) -> Reading {
        self.reading
    }

    /// The schedule.
    #[must_use]
    pub fn schedule(&self) -> &Schedule {
        &self.schedule
    }

    /// The site.
    #[must_use]
    pub fn site(&self) -> &Site {
        &self.site
    }

    /// The true drift coefficients.
    #[must_use]
    pub fn coefficients(&self) -> &DriftCoefficients {
        &self.coefficients
    }

    /// The turntable pose of every position (same angles as the schedule).
    #[must_use]
    pub fn poses(&self) -> &[Pose] {
        &self.poses
    }

    /// Number of positions $n$.
    #[must_use]
    pub fn len(&self) -> usize {
        self.poses.len()
    }

    /// Whether the schedule is empty (never for a constructed schedule).
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.poses.is_empty()
    }

    /// The nominal inputs of every position (eq 3).
    #[must_use]
    pub fn nominal_inputs(&self) -> &[Inputs] {
        &self.nominal
    }

    /// Whether [`delta_omega`](Self::delta_omega) uses the fast path (readings with the user's
    /// estimate $\hat{\boldsymbol\beta}_1$ and a residual form): one precomputed
    /// $\mathbf A^+$ per axis, no factorisation per draw. Other readings need a QR of
    /// $\mathbf A'$ per draw and go through calib-lsq.
    #[must_use]
    pub fn has_fast_path(&self) -> bool {
        self.reading.estimate == Estimate::Beta1 && self.reading.form != ErrorForm::DeltaBeta
    }

    /// $\Delta\mathbf R_i$ of every position through the reference chain
    /// [`tt_kinematics::delta_r`] (`ChainKind::Exact`).
    ///
    /// # Errors
    /// [`E2eError::NonFinite`] naming the component of a non-finite $\chi$.
    pub fn delta_r_reference(
        &self,
        chi_rad: &[f64; CHI_LEN],
    ) -> Result<Vec<Matrix3<f64>>, E2eError> {
        check_chi(chi_rad)?;
        let errors = TurntableErrors::from_rad(*chi_rad, 0.0).map_err(|e| E2eError::NonFinite {
            field: format!("chi ({e})"),
            value: f64::NAN,
        })?;
        Ok(self
            .poses
            .iter()
            .map(|p| delta_r(p, &errors, ChainKind::Exact))
            .collect())
    }

    /// $\Delta\mathbf R_i$ of every position by the factored exact chain of the
    /// [type documentation](Self) (two products per position; equal to
    /// [`delta_r_reference`](Self::delta_r_reference) to rounding).
    #[must_use]
    pub fn delta_r_fast(&self, chi_rad: &[f64; CHI_LEN]) -> Vec<Matrix3<f64>> {
        let (u, v) = chain_factors(chi_rad);
        self.rz
            .iter()
            .map(|rz| rz.transpose() * u * rz * v)
            .collect()
    }

    /// One calibration run through calib-lsq's analysis (eq 7-14) with the exact chain: the
    /// reference path, with every intermediate result.
    ///
    /// # Errors
    /// [`E2eError::NonFinite`] for a non-finite $\chi$; [`E2eError::Calib`] if $\mathbf A'$ is
    /// rank deficient (only for readings that need $\hat{\boldsymbol\beta}_2$).
    pub fn run(&self, chi_rad: &[f64; CHI_LEN]) -> Result<EndToEndRun, E2eError> {
        let dr = self.delta_r_reference(chi_rad)?;
        Ok(EndToEndRun {
            analyses: [
                self.analyses[0].analyze(&dr)?,
                self.analyses[1].analyze(&dr)?,
            ],
            delta_r: dr,
        })
    }

    /// One calibration run with one given $\Delta\mathbf R$ per position (reference path).
    ///
    /// # Errors
    /// As [`OrientationErrorAnalysis::analyze`].
    pub fn run_with_delta_r(&self, delta_r: &[Matrix3<f64>]) -> Result<EndToEndRun, E2eError> {
        Ok(EndToEndRun {
            analyses: [
                self.analyses[0].analyze(delta_r)?,
                self.analyses[1].analyze(delta_r)?,
            ],
            delta_r: delta_r.to_vec(),
        })
    }

    /// The error vectors $\Delta\hat{\boldsymbol\omega}$ of the $x$ and $y$ axes (rad/s, one
    /// entry per position) for turntable errors $\chi$ (exact chain).
    ///
    /// # Errors
    /// [`E2eError::NonFinite`] for a non-finite $\chi$; [`E2eError::Calib`] as
    /// [`run`](Self::run) for readings without the fast path.
    pub fn error_vectors(&self, chi_rad: &[f64; CHI_LEN]) -> Result<[DVector<f64>; 2], E2eError> {
        check_chi(chi_rad)?;
        let dr = self.delta_r_fast(chi_rad);
        if self.has_fast_path() {
            Ok(self.fast_errors(&dr))
        } else {
            let run = self.run_with_delta_r(&dr)?;
            let [x, y] = run.analyses;
            Ok([x.error_vector, y.error_vector])
        }
    }

    /// $(\Delta\omega_x, \Delta\omega_y)$ (eq 14, rad/s) for turntable errors $\chi$ (exact
    /// chain): the end-to-end answer for one turntable.
    ///
    /// # Errors
    /// As [`error_vectors`](Self::error_vectors).
    pub fn delta_omega(&self, chi_rad: &[f64; CHI_LEN]) -> Result<[f64; 2], E2eError> {
        let [x, y] = self.error_vectors(chi_rad)?;
        Ok([x.amax(), y.amax()])
    }

    /// $(\Delta\omega_x, \Delta\omega_y)$ (rad/s) for one given $\Delta\mathbf R$ per position,
    /// through the fast path when the reading has one (otherwise calib-lsq's analysis).
    ///
    /// # Errors
    /// [`E2eError::Calib`] unless there is one matrix per position, or as
    /// [`run`](Self::run).
    pub fn delta_omega_for_delta_r(&self, delta_r: &[Matrix3<f64>]) -> Result<[f64; 2], E2eError> {
        if delta_r.len() != self.len() {
            return Err(calib_lsq::CalibError::LengthMismatch {
                what: "delta_r",
                expected: self.len(),
                found: delta_r.len(),
            }
            .into());
        }
        if self.has_fast_path() {
            let [x, y] = self.fast_errors(delta_r);
            Ok([x.amax(), y.amax()])
        } else {
            Ok(self.run_with_delta_r(delta_r)?.delta_omega_rad_per_s())
        }
    }

    /// The fast path for readings with $\hat{\boldsymbol\beta}_1$: the outputs and rates of
    /// every position, then $\hat{\boldsymbol\beta}_1 = \mathbf A^+(\mathbf b_1 - \mathbf b_2)$
    /// with the precomputed pseudo-inverse, then the reading's error vector.
    pub(crate) fn fast_errors(&self, dr: &[Matrix3<f64>]) -> [DVector<f64>; 2] {
        let n = self.len();
        let actual: Vec<(Vector3<f64>, Vector3<f64>)> = self
            .nominal
            .iter()
            .zip(dr)
            .map(|(inp, d)| {
                let t = d.transpose();
                (t * inp.specific_force_g, t * inp.rate_rad_per_s)
            })
            .collect();
        let mut out = [DVector::zeros(n), DVector::zeros(n)];
        for (k, axis) in AXES.into_iter().enumerate() {
            let ad = &self.axes[k];
            let b2p = DVector::from_iterator(n, actual.iter().map(|(_, w)| axis.rate_component(w)));
            let b1 = match self.reading.outputs {
                OutputsAt::Actual => DVector::from_iterator(
                    n,
                    actual
                        .iter()
                        .zip(b2p.iter())
                        .map(|((a, _), w)| w + ad.coefficients.drift_rad_per_s(a)),
                ),
                OutputsAt::Intended => &ad.a_beta + &ad.b2,
            };
            let beta_1 = &ad.pinv * (&b1 - &ad.b2);
            let a_prime_beta = || {
                DVector::from_iterator(
                    n,
                    actual.iter().map(|(a, _)| {
                        regressors(axis, a)
                            .iter()
                            .zip(beta_1.iter())
                            .map(|(r, b)| r * b)
                            .sum::<f64>()
                    }),
                )
            };
            out[k] = match self.reading.form {
                ErrorForm::Printed => &b1 - &ad.a * &beta_1 - &b2p,
                ErrorForm::NominalRate => &b1 - &ad.a * &beta_1 - &ad.b2,
                ErrorForm::ActualRegressors => &b1 - a_prime_beta() - &b2p,
                ErrorForm::ActualRegressorsNominalRate => &b1 - a_prime_beta() - &ad.b2,
                ErrorForm::DeltaBeta => unreachable!("no fast path for DeltaBeta"),
            };
        }
        out
    }
}

/// The outer and inner factors $(\mathbf U, \mathbf V)$ of the exact chain (see
/// [`EndToEnd`]), built with the same elementary rotations as [`tt_kinematics::exact_factors`].
#[must_use]
pub fn chain_factors(chi_rad: &[f64; CHI_LEN]) -> (Matrix3<f64>, Matrix3<f64>) {
    use ErrorComponent as C;
    let c = |k: C| chi_rad[k.index()];
    let u = rot(Axis::Y, c(C::DphiY1))
        * rot(Axis::Z, c(C::DalphaZ1))
        * rot(Axis::X, c(C::DalphaX1))
        * rot(Axis::Y, c(C::DepsY))
        * rot(Axis::X, c(C::DepsX));
    let v =
        rot(Axis::Y, c(C::DalphaY2)) * rot(Axis::Z, c(C::DphiZ2)) * rot(Axis::X, c(C::DalphaX2));
    (u, v)
}

pub(crate) fn check_chi(chi_rad: &[f64; CHI_LEN]) -> Result<(), E2eError> {
    for c in ErrorComponent::ALL {
        crate::error::finite(&format!("chi.{}", c.name()), chi_rad[c.index()])?;
    }
    Ok(())
}

fn row_sum_norm(m: &DMatrix<f64>) -> f64 {
    m.row_iter()
        .map(|r| r.iter().map(|v| v.abs()).sum::<f64>())
        .fold(0.0, f64::max)
}
