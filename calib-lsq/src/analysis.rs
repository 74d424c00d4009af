//! The orientation-error analysis of eq 7-14 and the readings of eq 13.
//!
//! # The readings of eq 13
//! Eq 13 prints $\Delta\hat{\boldsymbol\omega}_x = (\mathbf b_1 - \mathbf A\hat{\boldsymbol\beta}_2) -
//! \mathbf b_2'$, while the text around it speaks of the calibration result
//! $\hat{\boldsymbol\beta}_1$ and of $\Delta\boldsymbol\beta$, and the paper never says how the
//! outputs $\mathbf b_1$ are simulated (NOTES item 3). A [`Reading`] makes the three choices
//! explicit:
//!
//! - [`OutputsAt`]: $\mathbf b_1$ simulated at the actual orientation,
//!   $\mathbf b_1 = \mathbf A'\boldsymbol\beta + \mathbf b_2'$ (physically right), or at the
//!   intended one, $\mathbf b_1 = \mathbf A\boldsymbol\beta + \mathbf b_2$;
//! - [`Estimate`]: $\hat{\boldsymbol\beta}_1 = \mathbf A^+(\mathbf b_1 - \mathbf b_2)$ (eq 6, what
//!   the user gets) or $\hat{\boldsymbol\beta}_2 = \mathbf A'^+(\mathbf b_1 - \mathbf b_2')$ (eq 11);
//! - [`ErrorForm`]: which regressors and rates form the error vector.
//!
//! With $\mathbf e = \mathbf b_2' - \mathbf b_2$ (earth-rate perturbation),
//! $\mathbf g = (\mathbf A' - \mathbf A)\boldsymbol\beta$ (gravity perturbation) and
//! $\mathbf P = \mathbf A\mathbf A^+$, the readings give, to first order in the angles:
//!
//! | outputs | estimate | form | error vector |
//! |---|---|---|---|
//! | intended | $\hat\beta_1$ | printed $(\mathbf b_1-\mathbf A\hat\beta)-\mathbf b_2'$ | $-\mathbf e$ (exact) |
//! | actual | $\hat\beta_2$ | $(\mathbf b_1-\mathbf A'\hat\beta)-\mathbf b_2$ | $+\mathbf e$ (exact) |
//! | actual | $\hat\beta_2$ | printed | $\mathbf g$ (exact) |
//! | actual | $\hat\beta_1$ | printed | $(\mathbf I-\mathbf P)\mathbf g - \mathbf P\mathbf e$ |
//! | actual | $\hat\beta_1$ | $(\mathbf b_1-\mathbf A\hat\beta)-\mathbf b_2$ (residual) | $(\mathbf I-\mathbf P)(\mathbf g+\mathbf e)$ |
//! | intended | $\hat\beta_2$ | printed | $\mathbf P\mathbf g - (\mathbf I-\mathbf P)\mathbf e$ |
//! | either | - | $\mathbf A\Delta\boldsymbol\beta$ | $\mathbf P(\mathbf g+\mathbf e)$ |
//! | actual | $\hat\beta_2$ | $(\mathbf b_1-\mathbf A\hat\beta)-\mathbf b_2$ | $\mathbf g+\mathbf e$ (exact) |
//! | intended | $\hat\beta_1$ | $(\mathbf b_1-\mathbf A\hat\beta)-\mathbf b_2$ | $\mathbf 0$ (exact) |
//!
//! The remaining combinations repeat these up to sign (see the crate README for the full
//! table with the requirement each gives).
//!
//! Only the earth-rate-only readings ($\pm\mathbf e$) reproduce all four statements of §2.2-2.3;
//! the default, [`Reading::PAPER`], is the first row: eq 13 as printed with
//! $\hat{\boldsymbol\beta}_1$ in place of $\hat{\boldsymbol\beta}_2$ (the estimate the text
//! speaks of) and outputs simulated at the intended orientation.

use crate::error::CalibError;
use crate::lsq::{Regression, qr_estimate};
use crate::schedule::{Schedule, actual_inputs, rate_vector, regression_matrix};
use gw_model::{AxisCoefficients, DeltaRKind, Inputs, OrientationAngles, SensingAxis, Site};
use nalgebra::{DMatrix, DVector, Matrix3};
use std::fmt;
use std::str::FromStr;

/// Where the outputs $\mathbf b_1$ are simulated.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum OutputsAt {
    /// At the actual orientation: $\mathbf b_1 = \mathbf A'\boldsymbol\beta + \mathbf b_2'$ (eq 9).
    Actual,
    /// At the intended orientation: $\mathbf b_1 = \mathbf A\boldsymbol\beta + \mathbf b_2$ (eq 5).
    Intended,
}

/// Which estimate enters the error vector.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Estimate {
    /// $\hat{\boldsymbol\beta}_1 = \mathbf A^+(\mathbf b_1 - \mathbf b_2)$, eq 6: the calibration
    /// result the user obtains.
    Beta1,
    /// $\hat{\boldsymbol\beta}_2 = \mathbf A'^+(\mathbf b_1 - \mathbf b_2')$, eq 11: the "true
    /// value" with the actual inputs.
    Beta2,
}

/// Which regressors and rates form the error vector $\Delta\hat{\boldsymbol\omega}$.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum ErrorForm {
    /// $(\mathbf b_1 - \mathbf A\hat{\boldsymbol\beta}) - \mathbf b_2'$: eq 13 as printed.
    Printed,
    /// $(\mathbf b_1 - \mathbf A\hat{\boldsymbol\beta}) - \mathbf b_2$: nominal rates.
    NominalRate,
    /// $(\mathbf b_1 - \mathbf A'\hat{\boldsymbol\beta}) - \mathbf b_2'$: actual regressors.
    ActualRegressors,
    /// $(\mathbf b_1 - \mathbf A'\hat{\boldsymbol\beta}) - \mathbf b_2$: actual regressors,
    /// nominal rates.
    ActualRegressorsNominalRate,
    /// $\mathbf A\,\Delta\boldsymbol\beta = \mathbf A(\hat{\boldsymbol\beta}_1 -
    /// \hat{\boldsymbol\beta}_2)$: eq 12 mapped to the test positions (the estimate is not used).
    DeltaBeta,
}

/// One reading of eq 13: how $\mathbf b_1$ is simulated, which estimate is used and which
/// error vector is formed. See the [module documentation](self) for what each gives.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Reading {
    /// How the outputs are simulated.
    pub outputs: OutputsAt,
    /// Which estimate enters the error vector (ignored by [`ErrorForm::DeltaBeta`]).
    pub estimate: Estimate,
    /// Which error vector is formed.
    pub form: ErrorForm,
}

impl Default for Reading {
    fn default() -> Self {
        Self::PAPER
    }
}

impl Reading {
    /// The reading that reproduces §2.2-2.3 (claims 1-4): outputs at the intended orientation,
    /// $\hat{\boldsymbol\beta}_1$, eq 13's printed form. Its error vector is exactly
    /// $-(\mathbf b_2' - \mathbf b_2)$, the earth-rate perturbation.
    pub const PAPER: Reading = Reading {
        outputs: OutputsAt::Intended,
        estimate: Estimate::Beta1,
        form: ErrorForm::Printed,
    };

    /// Eq 13 exactly as printed with physically simulated outputs: outputs at the actual
    /// orientation, $\hat{\boldsymbol\beta}_2$ (which then equals $\boldsymbol\beta$). Its error
    /// vector is exactly the gravity perturbation $(\mathbf A' - \mathbf A)\boldsymbol\beta$.
    pub const AS_PRINTED: Reading = Reading {
        outputs: OutputsAt::Actual,
        estimate: Estimate::Beta2,
        form: ErrorForm::Printed,
    };

    /// The error of what the user gets: outputs at the actual orientation, the user's estimate
    /// $\hat{\boldsymbol\beta}_1$, eq 13's printed form.
    pub const USER: Reading = Reading {
        outputs: OutputsAt::Actual,
        estimate: Estimate::Beta1,
        form: ErrorForm::Printed,
    };

    /// Every distinct reading: 2 x 2 x 4 residual forms, plus [`ErrorForm::DeltaBeta`] once per
    /// output simulation (18 in all), [`Reading::PAPER`] first.
    #[must_use]
    pub fn all() -> Vec<Reading> {
        let mut v = vec![Self::PAPER];
        for outputs in [OutputsAt::Intended, OutputsAt::Actual] {
            for form in [
                ErrorForm::Printed,
                ErrorForm::NominalRate,
                ErrorForm::ActualRegressors,
                ErrorForm::ActualRegressorsNominalRate,
                ErrorForm::DeltaBeta,
            ] {
                let estimates: &[Estimate] = if form == ErrorForm::DeltaBeta {
                    &[Estimate::Beta1]
                } else {
                    &[Estimate::Beta1, Estimate::Beta2]
                };
                for &estimate in estimates {
                    let r = Reading {
                        outputs,
                        estimate,
                        form,
                    };
                    if r != Self::PAPER {
                        v.push(r);
                    }
                }
            }
        }
        v
    }

    /// The error vector in ASCII, e.g. `(b1 - A*beta1) - b2'`.
    #[must_use]
    pub fn formula(&self) -> String {
        let beta = match self.estimate {
            Estimate::Beta1 => "beta1",
            Estimate::Beta2 => "beta2",
        };
        match self.form {
            ErrorForm::Printed => format!("(b1 - A*{beta}) - b2'"),
            ErrorForm::NominalRate => format!("(b1 - A*{beta}) - b2"),
            ErrorForm::ActualRegressors => format!("(b1 - A'*{beta}) - b2'"),
            ErrorForm::ActualRegressorsNominalRate => format!("(b1 - A'*{beta}) - b2"),
            ErrorForm::DeltaBeta => "A*(beta1 - beta2)".to_string(),
        }
    }

    fn needs_beta_2(&self) -> bool {
        self.estimate == Estimate::Beta2 || self.form == ErrorForm::DeltaBeta
    }

    fn needs_beta_1(&self) -> bool {
        self.estimate == Estimate::Beta1 || self.form == ErrorForm::DeltaBeta
    }
}

impl fmt::Display for Reading {
    /// `outputs/estimate/form`, e.g. `intended/beta1/printed`; parsed back by [`FromStr`].
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let o = match self.outputs {
            OutputsAt::Actual => "actual",
            OutputsAt::Intended => "intended",
        };
        let e = match self.estimate {
            Estimate::Beta1 => "beta1",
            Estimate::Beta2 => "beta2",
        };
        let form = match self.form {
            ErrorForm::Printed => "printed",
            ErrorForm::NominalRate => "nominal-rate",
            ErrorForm::ActualRegressors => "actual-regressors",
            ErrorForm::ActualRegressorsNominalRate => "actual-regressors-nominal-rate",
            ErrorForm::DeltaBeta => "delta-beta",
        };
        write!(f, "{o}/{e}/{form}")
    }
}

impl FromStr for Reading {
    type Err = CalibError;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let bad = || CalibError::UnknownReading {
            name: s.to_string(),
        };
        let parts: Vec<&str> = s.trim().split('/').collect();
        let [o, e, form] = parts.as_slice() else {
            return Err(bad());
        };
        let outputs = match *o {
            "actual" => OutputsAt::Actual,
            "intended" => OutputsAt::Intended,
            _ => return Err(bad()),
        };
        let estimate = match *e {
            "beta1" => Estimate::Beta1,
            "beta2" => Estimate::Beta2,
            _ => return Err(bad()),
        };
        let form = match *form {
            "printed" => ErrorForm::Printed,
            "nominal-rate" => ErrorForm::NominalRate,
            "actual-regressors" => ErrorForm::ActualRegressors,
            "actual-regressors-nominal-rate" => ErrorForm::ActualRegressorsNominalRate,
            "delta-beta" => ErrorForm::DeltaBeta,
            _ => return Err(bad()),
        };
        Ok(Reading {
            outputs,
            estimate,
            form,
        })
    }
}

/// The full result of eq 7-14 for one axis.
#[derive(Debug, Clone, PartialEq)]
pub struct ErrorAnalysis {
    /// The axis.
    pub axis: SensingAxis,
    /// The reading used.
    pub reading: Reading,
    /// Simulated outputs $\mathbf b_1$, rad/s.
    pub b1: DVector<f64>,
    /// $\hat{\boldsymbol\beta}_1$ (eq 6).
    pub beta_hat_1: DVector<f64>,
    /// $\hat{\boldsymbol\beta}_2$ (eq 11).
    pub beta_hat_2: DVector<f64>,
    /// $\Delta\boldsymbol\beta = \hat{\boldsymbol\beta}_1 - \hat{\boldsymbol\beta}_2$ (eq 12).
    pub delta_beta: DVector<f64>,
    /// $\Delta\hat{\boldsymbol\omega}$ (eq 13 in the chosen reading), rad/s, one per position.
    pub error_vector: DVector<f64>,
    /// $\Delta\omega = \lVert\Delta\hat{\boldsymbol\omega}\rVert_\infty$ (eq 14), rad/s.
    pub delta_omega_rad_per_s: f64,
}

/// A prepared orientation-error analysis of one axis: true coefficients, schedule, site and
/// reading fixed; the nominal regression is factored once.
#[derive(Debug, Clone)]
pub struct OrientationErrorAnalysis {
    coefficients: AxisCoefficients,
    schedule: Schedule,
    site: Site,
    reading: Reading,
    nominal: Vec<Inputs>,
    regression: Regression,
    b2: DVector<f64>,
    a_beta: DVector<f64>,
}

struct Parts {
    b1: DVector<f64>,
    beta_1: Option<DVector<f64>>,
    beta_2: Option<DVector<f64>>,
    error: DVector<f64>,
}

impl OrientationErrorAnalysis {
    /// Prepare the analysis of the axis of `coefficients` (the true $\boldsymbol\beta$).
    ///
    /// # Errors
    /// [`CalibError::Unidentifiable`] if the schedule cannot identify the axis (cannot happen
    /// for a constructed [`Schedule`]).
    pub fn new(
        coefficients: &AxisCoefficients,
        schedule: &Schedule,
        site: &Site,
        reading: Reading,
    ) -> Result<Self, CalibError> {
        let axis = coefficients.axis();
        let nominal = schedule.inputs(site);
        let regression = Regression::new(axis, regression_matrix(axis, &nominal))?;
        let b2 = rate_vector(axis, &nominal);
        let beta = DVector::from_column_slice(&coefficients.rad_per_s());
        let a_beta = regression.matrix() * &beta;
        Ok(Self {
            coefficients: *coefficients,
            schedule: schedule.clone(),
            site: *site,
            reading,
            nominal,
            regression,
            b2,
            a_beta,
        })
    }

    /// The axis analysed.
    #[must_use]
    pub fn axis(&self) -> SensingAxis {
        self.coefficients.axis()
    }

    /// The reading used.
    #[must_use]
    pub fn reading(&self) -> Reading {
        self.reading
    }

    /// The nominal regression matrix $\mathbf A$.
    #[must_use]
    pub fn nominal_matrix(&self) -> &DMatrix<f64> {
        self.regression.matrix()
    }

    fn parts(&self, delta_r: &[Matrix3<f64>], need_both: bool) -> Result<Parts, CalibError> {
        let axis = self.axis();
        let actual = actual_inputs(&self.schedule, &self.site, delta_r)?;
        let a_prime = regression_matrix(axis, &actual);
        let b2_prime = rate_vector(axis, &actual);
        let b1 = match self.reading.outputs {
            OutputsAt::Actual => DVector::from_iterator(
                actual.len(),
                actual.iter().map(|i| self.coefficients.output_rad_per_s(i)),
            ),
            OutputsAt::Intended => &self.a_beta + &self.b2,
        };
        let beta_1 = if need_both || self.reading.needs_beta_1() {
            Some(self.regression.estimate(&(&b1 - &self.b2))?)
        } else {
            None
        };
        let beta_2 = if need_both || self.reading.needs_beta_2() {
            // A' is within the orientation error of A (full rank): plain QR, no rank analysis.
            let y = &b1 - &b2_prime;
            match qr_estimate(a_prime.clone(), &y) {
                Some(b) => Some(b),
                None => Some(Regression::new(axis, a_prime.clone())?.estimate(&y)?),
            }
        } else {
            None
        };
        let chosen = match self.reading.estimate {
            Estimate::Beta1 => beta_1.as_ref(),
            Estimate::Beta2 => beta_2.as_ref(),
        };
        let a = self.regression.matrix();
        let error = match (self.reading.form, chosen, &beta_1, &beta_2) {
            (ErrorForm::DeltaBeta, _, Some(b1h), Some(b2h)) => a * (b1h - b2h),
            (ErrorForm::Printed, Some(b), _, _) => &b1 - a * b - &b2_prime,
            (ErrorForm::NominalRate, Some(b), _, _) => &b1 - a * b - &self.b2,
            (ErrorForm::ActualRegressors, Some(b), _, _) => &b1 - &a_prime * b - &b2_prime,
            (ErrorForm::ActualRegressorsNominalRate, Some(b), _, _) => {
                &b1 - &a_prime * b - &self.b2
            }
            _ => unreachable!("the estimates a reading needs are always computed"),
        };
        Ok(Parts {
            b1,
            beta_1,
            beta_2,
            error,
        })
    }

    /// Eq 7-14 with one $\Delta\mathbf R$ per position (for example the exact turntable
    /// $\mathbf R_d^T\mathbf R_t$ of eq 23 at each position).
    ///
    /// # Formula
    /// Actual inputs $\mathbf v_i' = \Delta\mathbf R_i^T\mathbf v_i$ (eq 8), $\mathbf A'$ and
    /// $\mathbf b_2'$ (eq 10), $\hat{\boldsymbol\beta}_1$ (eq 6), $\hat{\boldsymbol\beta}_2$
    /// (eq 11), $\Delta\boldsymbol\beta$ (eq 12), $\Delta\hat{\boldsymbol\omega}$ (eq 13 in the
    /// [`Reading`]), $\Delta\omega = \lVert\Delta\hat{\boldsymbol\omega}\rVert_\infty$ (eq 14).
    ///
    /// # Reference
    /// Eq 7-14.
    ///
    /// # Errors
    /// [`CalibError::LengthMismatch`] unless there is one matrix per position;
    /// [`CalibError::Unidentifiable`] if $\mathbf A'$ is rank deficient.
    pub fn analyze(&self, delta_r: &[Matrix3<f64>]) -> Result<ErrorAnalysis, CalibError> {
        let p = self.parts(delta_r, true)?;
        let beta_hat_1 = p.beta_1.unwrap_or_else(|| unreachable!("need_both"));
        let beta_hat_2 = p.beta_2.unwrap_or_else(|| unreachable!("need_both"));
        Ok(ErrorAnalysis {
            axis: self.axis(),
            reading: self.reading,
            b1: p.b1,
            delta_beta: &beta_hat_1 - &beta_hat_2,
            beta_hat_1,
            beta_hat_2,
            delta_omega_rad_per_s: p.error.amax(),
            error_vector: p.error,
        })
    }

    /// $\Delta\omega$ (eq 14, rad/s) with one $\Delta\mathbf R$ per position; computes only what
    /// the reading needs.
    ///
    /// # Errors
    /// As [`analyze`](Self::analyze).
    pub fn delta_omega(&self, delta_r: &[Matrix3<f64>]) -> Result<f64, CalibError> {
        Ok(self.parts(delta_r, false)?.error.amax())
    }

    /// $\Delta\omega$ (eq 14, rad/s) when every position has the same orientation error
    /// (§2.2: a fixed $\Delta\psi$, $\Delta\theta$, $\Delta\gamma$).
    ///
    /// # Errors
    /// As [`analyze`](Self::analyze).
    pub fn delta_omega_for_angles(
        &self,
        angles: &OrientationAngles,
        kind: DeltaRKind,
    ) -> Result<f64, CalibError> {
        let m = angles.delta_r(kind);
        self.delta_omega(&vec![m; self.nominal.len()])
    }

    /// Eq 7-14 when every position has the same orientation error.
    ///
    /// # Errors
    /// As [`analyze`](Self::analyze).
    pub fn analyze_angles(
        &self,
        angles: &OrientationAngles,
        kind: DeltaRKind,
    ) -> Result<ErrorAnalysis, CalibError> {
        let m = angles.delta_r(kind);
        self.analyze(&vec![m; self.nominal.len()])
    }
}
