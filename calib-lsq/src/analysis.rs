//! The orientation-error analysis of eq 7-14 and the readings of eq 13, for any sensor.
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
//! - [`ErrorForm`]: which regressors and known terms form the error vector.
//!
//! Here $\mathbf A$ holds the estimated terms' regressors and $\mathbf b_2$ the known terms
//! (the rate input for a gyro), primes at the actual orientation. With
//! $\mathbf e = \mathbf b_2' - \mathbf b_2$ (known-term perturbation, the earth rate for eq 1),
//! $\mathbf g = (\mathbf A' - \mathbf A)\boldsymbol\beta$ (regressor perturbation, gravity for
//! eq 1) and $\mathbf P = \mathbf A\mathbf A^+$, the readings give, to first order in the angles:
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
//! Only the known-term-only readings ($\pm\mathbf e$) reproduce all four statements of
//! §2.2-2.3; the paper's reading, [`Reading::PAPER`], is the first row: eq 13 as printed with
//! $\hat{\boldsymbol\beta}_1$ in place of $\hat{\boldsymbol\beta}_2$ (the estimate the text
//! speaks of) and outputs simulated at the intended orientation.
//!
//! # One evaluation for every use
//! [`Reading::error_vector`] is the only place the 18 readings are evaluated. It asks a
//! [`ReadingTerms`] for the building blocks ($\mathbf b_1$, $\mathbf b_2^{(\prime)}$,
//! $\hat{\boldsymbol\beta}$, $\mathbf A^{(\prime)}\hat{\boldsymbol\beta}$). The reference analysis
//! ([`OrientationErrorAnalysis`]) supplies them with matrices and QR; a fast path (for
//! example the end-to-end Monte Carlo) with a precomputed $\mathbf A^+$; a linearisation with
//! their first variations. Because the error vector is linear in the blocks, the same
//! dispatch gives the value and the derivative.

use crate::calibration::{
    Calibration, FastOutput, OutputCalibration, design_matrix, known_vector, simulate_outputs,
};
use crate::error::CalibError;
use crate::lsq::{QrSolve, Regression};
use gw_model::{InputValues, Inputs};
use nalgebra::{DVector, Matrix3};
use std::fmt;
use std::str::FromStr;
use tt_core::{DeltaRKind, OrientationError};

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

/// Which regressors and known terms form the error vector $\Delta\hat{\boldsymbol\omega}$.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum ErrorForm {
    /// $(\mathbf b_1 - \mathbf A\hat{\boldsymbol\beta}) - \mathbf b_2'$: eq 13 as printed.
    Printed,
    /// $(\mathbf b_1 - \mathbf A\hat{\boldsymbol\beta}) - \mathbf b_2$: nominal known terms.
    NominalRate,
    /// $(\mathbf b_1 - \mathbf A'\hat{\boldsymbol\beta}) - \mathbf b_2'$: actual regressors.
    ActualRegressors,
    /// $(\mathbf b_1 - \mathbf A'\hat{\boldsymbol\beta}) - \mathbf b_2$: actual regressors,
    /// nominal known terms.
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

impl Reading {
    /// The reading that reproduces §2.2-2.3 (claims 1-4): outputs at the intended orientation,
    /// $\hat{\boldsymbol\beta}_1$, eq 13's printed form. Its error vector is exactly
    /// $-(\mathbf b_2' - \mathbf b_2)$, the known-term (earth-rate) perturbation.
    pub const PAPER: Reading = Reading {
        outputs: OutputsAt::Intended,
        estimate: Estimate::Beta1,
        form: ErrorForm::Printed,
    };

    /// Eq 13 exactly as printed with physically simulated outputs: outputs at the actual
    /// orientation, $\hat{\boldsymbol\beta}_2$ (which then equals $\boldsymbol\beta$). Its error
    /// vector is exactly the regressor perturbation $(\mathbf A' - \mathbf A)\boldsymbol\beta$.
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

    /// Whether the reading uses the outputs simulated at the actual orientation.
    #[must_use]
    pub fn needs_actual_outputs(&self) -> bool {
        self.outputs == OutputsAt::Actual
    }

    /// Whether the reading uses the known terms at the actual orientation ($\mathbf b_2'$).
    #[must_use]
    pub(crate) fn needs_actual_known(&self) -> bool {
        self.needs_beta_2() || matches!(self.form, ErrorForm::Printed | ErrorForm::ActualRegressors)
    }

    /// Whether the reading needs $\hat{\boldsymbol\beta}_2$ (a factorisation of $\mathbf A'$
    /// per evaluation).
    #[must_use]
    pub(crate) fn needs_beta_2(&self) -> bool {
        self.estimate == Estimate::Beta2 || self.form == ErrorForm::DeltaBeta
    }

    /// The error vector $\Delta\hat{\boldsymbol\omega}$ of this reading from the building blocks
    /// `t`, into `out` (one entry per position); `work` holds the intermediate vectors (no
    /// allocation once sized). The only evaluation of the readings in the workspace (see the
    /// [module](self)).
    pub fn error_vector<T: ReadingTerms + ?Sized>(
        &self,
        t: &T,
        work: &mut ReadingWork,
        out: &mut [f64],
    ) {
        let (n, k) = (t.positions(), t.coefficients());
        work.size(n, k);
        let ReadingWork {
            b1,
            b2,
            beta,
            beta2,
            pred,
            pred2,
        } = work;
        t.outputs(self.outputs, b1);
        if self.form == ErrorForm::DeltaBeta {
            t.estimate(Estimate::Beta1, b1, beta);
            t.estimate(Estimate::Beta2, b1, beta2);
            t.predict(false, beta, pred);
            t.predict(false, beta2, pred2);
            for i in 0..n {
                out[i] = pred[i] - pred2[i];
            }
            return;
        }
        t.estimate(self.estimate, b1, beta);
        let (actual_regressors, actual_known) = match self.form {
            ErrorForm::Printed => (false, true),
            ErrorForm::NominalRate => (false, false),
            ErrorForm::ActualRegressors => (true, true),
            ErrorForm::ActualRegressorsNominalRate => (true, false),
            ErrorForm::DeltaBeta => unreachable!("handled above"),
        };
        t.predict(actual_regressors, beta, pred);
        t.known(actual_known, b2);
        for i in 0..n {
            out[i] = b1[i] - pred[i] - b2[i];
        }
    }
}

/// Scratch vectors of [`Reading::error_vector`] (sized on first use, reused after).
#[derive(Debug, Clone, Default)]
pub struct ReadingWork {
    b1: Vec<f64>,
    b2: Vec<f64>,
    beta: Vec<f64>,
    beta2: Vec<f64>,
    pred: Vec<f64>,
    pred2: Vec<f64>,
}

impl ReadingWork {
    fn size(&mut self, n: usize, k: usize) {
        for v in [&mut self.b1, &mut self.b2, &mut self.pred, &mut self.pred2] {
            v.resize(n, 0.0);
        }
        for v in [&mut self.beta, &mut self.beta2] {
            v.resize(k, 0.0);
        }
    }
}

/// The building blocks of eq 13 for one output, supplied to [`Reading::error_vector`]: by
/// values (the reference analysis, a fast path) or by first variations (a linearisation).
pub trait ReadingTerms {
    /// Number of positions $n$.
    fn positions(&self) -> usize;
    /// Number of estimated coefficients $k$.
    fn coefficients(&self) -> usize;
    /// $\mathbf b_1$ simulated as `at` says.
    fn outputs(&self, at: OutputsAt, out: &mut [f64]);
    /// $\mathbf b_2'$ (`actual`) or $\mathbf b_2$.
    fn known(&self, actual: bool, out: &mut [f64]);
    /// $\hat{\boldsymbol\beta}_1 = \mathbf A^+(\mathbf b_1 - \mathbf b_2)$ or
    /// $\hat{\boldsymbol\beta}_2 = \mathbf A'^+(\mathbf b_1 - \mathbf b_2')$ from the given
    /// $\mathbf b_1$.
    fn estimate(&self, which: Estimate, b1: &[f64], out: &mut [f64]);
    /// $\mathbf A'\boldsymbol\beta$ (`actual`) or $\mathbf A\boldsymbol\beta$ for the given
    /// coefficients.
    fn predict(&self, actual: bool, beta: &[f64], out: &mut [f64]);
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

/// The building blocks by value, with matrices: the reference path.
struct ReferenceTerms<'a> {
    cal: &'a OutputCalibration,
    a_prime: nalgebra::DMatrix<f64>,
    b2_prime: DVector<f64>,
    b1_actual: DVector<f64>,
    /// $\mathbf A'$ factored (only when the reading needs $\hat{\boldsymbol\beta}_2$).
    a_prime_qr: Option<Regression>,
}

impl ReferenceTerms<'_> {
    fn beta2(&self, y: &DVector<f64>) -> DVector<f64> {
        self.a_prime_qr
            .as_ref()
            .unwrap_or_else(|| unreachable!("factored when the reading needs beta2"))
            .estimate(y)
            .unwrap_or_else(|_| unreachable!("lengths match"))
    }
}

impl ReadingTerms for ReferenceTerms<'_> {
    fn positions(&self) -> usize {
        self.b2_prime.len()
    }
    fn coefficients(&self) -> usize {
        self.cal.beta().len()
    }
    fn outputs(&self, at: OutputsAt, out: &mut [f64]) {
        let v = match at {
            OutputsAt::Actual => self.b1_actual.clone(),
            OutputsAt::Intended => self.cal.a_beta() + self.cal.b2(),
        };
        out.copy_from_slice(v.as_slice());
    }
    fn known(&self, actual: bool, out: &mut [f64]) {
        out.copy_from_slice(if actual {
            self.b2_prime.as_slice()
        } else {
            self.cal.b2().as_slice()
        });
    }
    fn estimate(&self, which: Estimate, b1: &[f64], out: &mut [f64]) {
        let b1 = DVector::from_column_slice(b1);
        let beta = match which {
            Estimate::Beta1 => self
                .cal
                .regression()
                .estimate(&(b1 - self.cal.b2()))
                .unwrap_or_else(|_| unreachable!("lengths match")),
            Estimate::Beta2 => self.beta2(&(b1 - &self.b2_prime)),
        };
        out.copy_from_slice(beta.as_slice());
    }
    fn predict(&self, actual: bool, beta: &[f64], out: &mut [f64]) {
        let beta = DVector::from_column_slice(beta);
        let v = if actual {
            &self.a_prime * beta
        } else {
            self.cal.regression().matrix() * beta
        };
        out.copy_from_slice(v.as_slice());
    }
}

/// Scratch space of [`OutputCalibration::error_vector_at`]: sized on first use, reused after
/// (no allocation in a hot loop).
#[derive(Debug, Clone, Default)]
pub struct ErrorWork {
    reading: ReadingWork,
    /// Actual regressor rows, row-major $n \times k$ (when the reading needs them).
    rows: Vec<f64>,
    pub(crate) b1_actual: Vec<f64>,
    pub(crate) b2_actual: Vec<f64>,
    pub(crate) y: Vec<f64>,
    /// The actual inputs as columns (the fast readings from input values).
    columns: crate::columns::InputColumns,
    /// The actual inputs as values (the other readings from columns).
    pub(crate) values: Vec<InputValues>,
}

/// The building blocks at given actual input values, with the precomputed row-major
/// $\mathbf A$ and $\mathbf A^+$ of the nominal regression: the fast path.
struct ActualTerms<'a> {
    cal: &'a OutputCalibration,
    k: usize,
    rows: &'a [f64],
    b1_actual: &'a [f64],
    b2_actual: &'a [f64],
    /// $\mathbf A'$ factored, only for readings that need $\hat{\boldsymbol\beta}_2$.
    a_prime: Option<QrSolve>,
    y: std::cell::RefCell<&'a mut Vec<f64>>,
}

#[inline(always)]
fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// $\mathbf b_1 - \mathbf A\hat{\boldsymbol\beta}_1$ at the intended orientation
/// ([`FastOutput::intended_residual`]) for an output with $k$ estimated coefficients and known
/// part `b2` ($\mathbf b_2$): $y_i = b_{1,i} - b_{2,i}$, $\hat\beta_j = \sum_i A^+_{ji}y_i$,
/// entry $i$ = $b_{1,i} - \sum_j A_{ij}\hat\beta_j$, each step as [`ActualTerms`] and
/// [`Reading::error_vector`] take it (same operations in the same order, so the same bits).
pub(crate) fn intended_residual(fast: &FastOutput, b2: &[f64], k: usize) -> Vec<f64> {
    let b1 = &fast.b1_intended;
    let n = b1.len();
    let y: Vec<f64> = b1.iter().zip(b2).map(|(b, k)| b - k).collect();
    let row = |m: &'_ [f64], i: usize, len: usize| -> Vec<f64> {
        m.get(i * len..(i + 1) * len).unwrap_or_default().to_vec()
    };
    let beta: Vec<f64> = (0..k)
        .map(|j| dot(&row(&fast.pinv_rows, j, n), &y))
        .collect();
    b1.iter()
        .enumerate()
        .map(|(i, b)| b - dot(&row(&fast.a_rows, i, k), &beta))
        .collect()
}

impl ReadingTerms for ActualTerms<'_> {
    fn positions(&self) -> usize {
        self.cal.fast.b1_intended.len()
    }
    fn coefficients(&self) -> usize {
        self.k
    }
    fn outputs(&self, at: OutputsAt, out: &mut [f64]) {
        match at {
            OutputsAt::Actual => out.copy_from_slice(self.b1_actual),
            OutputsAt::Intended => out.copy_from_slice(&self.cal.fast.b1_intended),
        }
    }
    fn known(&self, actual: bool, out: &mut [f64]) {
        out.copy_from_slice(if actual {
            self.b2_actual
        } else {
            self.cal.b2().as_slice()
        });
    }
    fn estimate(&self, which: Estimate, b1: &[f64], out: &mut [f64]) {
        let mut y = self.y.borrow_mut();
        y.clear();
        match which {
            Estimate::Beta1 => {
                y.extend(b1.iter().zip(self.cal.b2().iter()).map(|(b, k)| b - k));
                let n = y.len();
                for (j, o) in out.iter_mut().enumerate() {
                    *o = dot(&self.cal.fast.pinv_rows[j * n..(j + 1) * n], &y);
                }
            }
            Estimate::Beta2 => {
                y.extend(b1.iter().zip(self.b2_actual).map(|(b, k)| b - k));
                let r = self
                    .a_prime
                    .as_ref()
                    .unwrap_or_else(|| unreachable!("factored when the reading needs beta2"));
                let beta = r.estimate(&DVector::from_column_slice(&y));
                out.copy_from_slice(beta.as_slice());
            }
        }
    }
    fn predict(&self, actual: bool, beta: &[f64], out: &mut [f64]) {
        let rows = if actual {
            self.rows
        } else {
            &self.cal.fast.a_rows
        };
        for (i, p) in out.iter_mut().enumerate() {
            *p = dot(&rows[i * self.k..(i + 1) * self.k], beta);
        }
    }
}

impl OutputCalibration {
    /// The reading's error vector $\Delta\hat{\boldsymbol\omega}$ (eq 13) when the positions
    /// are realised with the actual input values `actual` (one per position, from eq 8), into
    /// `out`. The fast path: $\hat{\boldsymbol\beta}_1$ through the precomputed
    /// $\mathbf A^+$, compiled regressors, only the blocks the reading needs, nothing allocated
    /// once `work` is sized; readings with $\hat{\boldsymbol\beta}_2$ factor $\mathbf A'$.
    ///
    /// # Errors
    /// [`CalibError::Field`] ([`tt_core::FieldError::Length`]) unless there is one value per position (and `out` as
    /// long); [`CalibError::Unidentifiable`] when $\mathbf A'$ is rank deficient (readings with
    /// $\hat{\boldsymbol\beta}_2$ only).
    pub fn error_vector_at(
        &self,
        reading: Reading,
        actual: &[InputValues],
        work: &mut ErrorWork,
        out: &mut [f64],
    ) -> Result<(), CalibError> {
        self.check_lengths(actual.len(), out.len())?;
        if self.reads_columns(reading) {
            // the fast readings have one implementation, on columns
            let mut columns = std::mem::take(&mut work.columns);
            columns.set_values(actual);
            let r = self.error_vector_columns(reading, &columns, work, out);
            work.columns = columns;
            return r;
        }
        self.error_vector_generic(reading, actual, work, out)
    }

    /// The estimated coefficients' errors $\hat{\boldsymbol\beta}_1 - \boldsymbol\beta$ (eq 6,
    /// estimated-term order) when the outputs are the sensor's at the actual input values
    /// `actual` (one per position, from eq 8) and the estimate uses the intended inputs:
    /// $\mathbf A^+(\mathbf b_1' - \mathbf b_2) - \boldsymbol\beta$, with the regression's
    /// pseudo-inverse computed once and the compiled monomials, nothing allocated once `work`
    /// is sized. [`crate::Calibration::calibrate`] of the same outputs solves the same least
    /// squares by QR (equal to rounding).
    ///
    /// # Errors
    /// [`CalibError::Field`] ([`tt_core::FieldError::Length`]) unless there is one value per
    /// position and one entry of `out` per estimated coefficient.
    #[doc(hidden)]
    pub fn coefficient_errors_at(
        &self,
        actual: &[InputValues],
        work: &mut ErrorWork,
        out: &mut [f64],
    ) -> Result<(), CalibError> {
        let f = &self.fast;
        let n = self.b2().len();
        tt_core::length("actual inputs", n, actual.len())?;
        tt_core::length("coefficient errors", f.estimated.len(), out.len())?;
        let beta = self.beta().as_slice();
        work.y.clear();
        work.y
            .extend(actual.iter().zip(self.b2().iter()).map(|(v, b2)| {
                let est: f64 = f
                    .estimated
                    .iter()
                    .zip(beta)
                    .map(|(m, b)| m.eval(&v.0) * b)
                    .sum();
                let known: f64 = f.known.iter().map(|(c, m)| c * m.eval(&v.0)).sum();
                known + est - b2
            }));
        for ((o, p), b) in out
            .iter_mut()
            .zip(f.pinv_rows.chunks_exact(n.max(1)))
            .zip(beta)
        {
            *o = dot(p, &work.y) - b;
        }
        Ok(())
    }

    /// The number of positions $n$, after checking that there are `actual` input values and
    /// `out` error-vector entries, one per position.
    ///
    /// # Errors
    /// [`CalibError::Field`] ([`tt_core::FieldError::Length`]) naming the one that differs.
    pub(crate) fn check_lengths(&self, actual: usize, out: usize) -> Result<usize, CalibError> {
        let n = self.b2().len();
        for (what, len) in [("actual inputs", actual), ("error vector", out)] {
            tt_core::length(what, n, len)?;
        }
        Ok(n)
    }

    /// Which of the six input values ($a_x, a_y, a_z, \omega_x, \omega_y, \omega_z$)
    /// [`OutputCalibration::error_vector_at`] reads under `reading`: those of the known terms
    /// for the readings with outputs at the intended orientation, $\hat{\boldsymbol\beta}_1$
    /// and eq 13 as printed (only $\mathbf b_2'$ depends on the actual inputs there), those
    /// of every term otherwise. A caller may leave the others unset.
    #[doc(hidden)]
    #[must_use]
    pub fn inputs_used(&self, reading: Reading) -> [bool; 6] {
        let mut used = [false; 6];
        let known_only = matches!(
            (reading.outputs, reading.estimate, reading.form),
            (OutputsAt::Intended, Estimate::Beta1, ErrorForm::Printed)
        );
        for (_, m) in &self.fast.known {
            m.mark_inputs(&mut used);
        }
        if !known_only {
            for m in &self.fast.estimated {
                m.mark_inputs(&mut used);
            }
        }
        used
    }

    /// [`OutputCalibration::error_vector_at`] for any reading and any output (lengths checked
    /// by the caller).
    pub(crate) fn error_vector_generic(
        &self,
        reading: Reading,
        actual: &[InputValues],
        work: &mut ErrorWork,
        out: &mut [f64],
    ) -> Result<(), CalibError> {
        let n = self.b2().len();
        let f = &self.fast;
        let k = f.estimated.len();
        let need_b1 = reading.needs_actual_outputs();
        let need_rows = need_b1
            || reading.needs_beta_2()
            || matches!(
                reading.form,
                ErrorForm::ActualRegressors | ErrorForm::ActualRegressorsNominalRate
            );
        let need_b2 = need_b1 || reading.needs_actual_known();
        work.rows.clear();
        work.b1_actual.clear();
        work.b2_actual.clear();
        let beta = self.beta().as_slice();
        for v in actual {
            if need_rows {
                let start = work.rows.len();
                work.rows.extend(f.estimated.iter().map(|m| m.eval(&v.0)));
                if need_b1 {
                    let est = dot(&work.rows[start..], beta);
                    let known: f64 = f.known.iter().map(|(c, m)| c * m.eval(&v.0)).sum();
                    work.b2_actual.push(known);
                    work.b1_actual.push(known + est);
                    continue;
                }
            }
            if need_b2 {
                work.b2_actual
                    .push(f.known.iter().map(|(c, m)| c * m.eval(&v.0)).sum());
            }
        }
        let a_prime = if reading.needs_beta_2() {
            let m = nalgebra::DMatrix::from_row_slice(n, k, &work.rows);
            Some(QrSolve::new(
                &self.output().name,
                self.regression().names(),
                m,
            )?)
        } else {
            None
        };
        let ErrorWork {
            reading: rw,
            rows,
            b1_actual,
            b2_actual,
            y,
            ..
        } = work;
        let terms = ActualTerms {
            cal: self,
            k,
            rows,
            b1_actual,
            b2_actual,
            a_prime,
            y: std::cell::RefCell::new(y),
        };
        reading.error_vector(&terms, rw, out);
        Ok(())
    }
}

/// The full result of eq 7-14 for one output.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct ErrorAnalysis {
    /// The output's name.
    pub(crate) output: String,
    /// The reading used.
    pub(crate) reading: Reading,
    /// Simulated outputs $\mathbf b_1$ (as the reading says).
    pub(crate) b1: DVector<f64>,
    /// $\hat{\boldsymbol\beta}_1$ (eq 6).
    pub(crate) beta_hat_1: DVector<f64>,
    /// $\hat{\boldsymbol\beta}_2$ (eq 11).
    pub(crate) beta_hat_2: DVector<f64>,
    /// $\Delta\boldsymbol\beta = \hat{\boldsymbol\beta}_1 - \hat{\boldsymbol\beta}_2$ (eq 12).
    pub(crate) delta_beta: DVector<f64>,
    /// $\Delta\hat{\boldsymbol\omega}$ (eq 13 in the chosen reading), one per position, in the
    /// output's unit.
    pub(crate) error_vector: DVector<f64>,
    /// $\Delta\omega = \lVert\Delta\hat{\boldsymbol\omega}\rVert_\infty$ (eq 14), output unit.
    pub(crate) delta_omega: f64,
}

/// Read access to the fields (crate-private, so the type can grow without breaking callers).
impl ErrorAnalysis {
    /// The output's name.
    #[must_use]
    pub fn output(&self) -> &str {
        &self.output
    }

    /// The reading used.
    #[must_use]
    pub fn reading(&self) -> Reading {
        self.reading
    }

    /// Simulated outputs $\mathbf b_1$ (as the reading says).
    #[must_use]
    pub fn b1(&self) -> &DVector<f64> {
        &self.b1
    }

    /// $\hat{\boldsymbol\beta}_1$ (eq 6).
    #[must_use]
    pub fn beta_hat_1(&self) -> &DVector<f64> {
        &self.beta_hat_1
    }

    /// $\hat{\boldsymbol\beta}_2$ (eq 11).
    #[must_use]
    pub fn beta_hat_2(&self) -> &DVector<f64> {
        &self.beta_hat_2
    }

    /// $\Delta\boldsymbol\beta = \hat{\boldsymbol\beta}_1 - \hat{\boldsymbol\beta}_2$ (eq 12).
    #[must_use]
    pub fn delta_beta(&self) -> &DVector<f64> {
        &self.delta_beta
    }

    /// $\Delta\hat{\boldsymbol\omega}$ (eq 13 in the chosen reading), one per position, in the
    /// output's unit.
    #[must_use]
    pub fn error_vector(&self) -> &DVector<f64> {
        &self.error_vector
    }

    /// $\Delta\omega = \lVert\Delta\hat{\boldsymbol\omega}\rVert_\infty$ (eq 14), output unit.
    #[must_use]
    pub fn delta_omega(&self) -> f64 {
        self.delta_omega
    }
}

/// A prepared orientation-error analysis of one output: true coefficients, schedule, site and
/// reading fixed; the nominal regression is factored once.
#[derive(Debug, Clone)]
pub struct OrientationErrorAnalysis {
    cal: OutputCalibration,
    schedule: crate::Schedule,
    site: gw_model::Site,
    reading: Reading,
}

impl OrientationErrorAnalysis {
    /// Prepare the analysis of output `k` of a calibration under `reading`.
    ///
    /// # Errors
    /// [`CalibError::Field`] ([`tt_core::FieldError::Length`]) naming `output index` when there is no output `k`.
    pub fn new(calibration: &Calibration, k: usize, reading: Reading) -> Result<Self, CalibError> {
        let cal = calibration
            .outputs()
            .get(k)
            .ok_or(CalibError::Field(tt_core::FieldError::Length {
                field: "output index".into(),
                expected: calibration.outputs().len(),
                found: k,
            }))?
            .clone();
        Ok(Self {
            cal,
            schedule: calibration.schedule().clone(),
            site: *calibration.site(),
            reading,
        })
    }

    /// The output's name.
    #[must_use]
    pub fn output(&self) -> &str {
        &self.cal.output().name
    }

    /// The output's calibration data.
    #[must_use]
    pub fn calibration(&self) -> &OutputCalibration {
        &self.cal
    }

    /// The reading used.
    #[must_use]
    pub fn reading(&self) -> Reading {
        self.reading
    }

    /// Number of positions.
    #[must_use]
    pub fn positions(&self) -> usize {
        self.schedule.len()
    }

    fn terms(
        &self,
        actual: &[Inputs],
        need_beta_2: bool,
    ) -> Result<ReferenceTerms<'_>, CalibError> {
        let o = self.cal.output();
        let a_prime = design_matrix(o, actual);
        let a_prime_qr = if need_beta_2 {
            // A' is within the orientation error of A: full rank unless A is near-singular,
            // which the rank check then reports by name.
            Some(Regression::new(
                &o.name,
                o.estimated_names().into_iter().map(String::from).collect(),
                a_prime.clone(),
            )?)
        } else {
            None
        };
        Ok(ReferenceTerms {
            cal: &self.cal,
            b2_prime: known_vector(o, actual),
            b1_actual: simulate_outputs(o, actual),
            a_prime,
            a_prime_qr,
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
    /// [`CalibError::Field`] ([`tt_core::FieldError::Length`]) unless there is one matrix per position;
    /// [`CalibError::Unidentifiable`] if $\mathbf A'$ is rank deficient.
    pub fn analyze(&self, delta_r: &[Matrix3<f64>]) -> Result<ErrorAnalysis, CalibError> {
        let actual = self.schedule.actual_inputs(&self.site, delta_r)?;
        self.analyze_inputs(&actual)
    }

    /// Eq 9-14 with the actual inputs of every position given (for a schedule whose entries
    /// are not all a rotation of the nominal inputs, such as a rate step's revolution
    /// averages); [`analyze`](Self::analyze) is this with eq 8's inputs.
    ///
    /// # Errors
    /// [`CalibError::Field`] ([`tt_core::FieldError::Length`]) unless there are inputs for
    /// every position; [`CalibError::Unidentifiable`] if $\mathbf A'$ is rank deficient.
    pub fn analyze_inputs(&self, actual: &[gw_model::Inputs]) -> Result<ErrorAnalysis, CalibError> {
        if actual.len() != self.positions() {
            return Err(CalibError::Field(tt_core::FieldError::Length {
                field: "actual inputs".into(),
                expected: self.positions(),
                found: actual.len(),
            }));
        }
        let t = self.terms(actual, true)?;
        let n = actual.len();
        let k = t.coefficients();
        let mut b1 = vec![0.0; n];
        t.outputs(self.reading.outputs, &mut b1);
        let (mut beta1, mut beta2) = (vec![0.0; k], vec![0.0; k]);
        t.estimate(Estimate::Beta1, &b1, &mut beta1);
        t.estimate(Estimate::Beta2, &b1, &mut beta2);
        let mut error = vec![0.0; n];
        self.reading
            .error_vector(&t, &mut ReadingWork::default(), &mut error);
        let error_vector = DVector::from_vec(error);
        let (beta_hat_1, beta_hat_2) = (DVector::from_vec(beta1), DVector::from_vec(beta2));
        Ok(ErrorAnalysis {
            output: self.output().to_string(),
            reading: self.reading,
            b1: DVector::from_vec(b1),
            delta_beta: &beta_hat_1 - &beta_hat_2,
            beta_hat_1,
            beta_hat_2,
            delta_omega: error_vector.amax(),
            error_vector,
        })
    }

    /// The error vector $\Delta\hat{\boldsymbol\omega}$ (eq 13) only, computing what the reading
    /// needs.
    ///
    /// # Errors
    /// As [`analyze`](Self::analyze).
    pub fn error_vector(&self, delta_r: &[Matrix3<f64>]) -> Result<DVector<f64>, CalibError> {
        let actual = self.schedule.actual_inputs(&self.site, delta_r)?;
        let t = self.terms(&actual, self.reading.needs_beta_2())?;
        let mut error = vec![0.0; actual.len()];
        self.reading
            .error_vector(&t, &mut ReadingWork::default(), &mut error);
        Ok(DVector::from_vec(error))
    }

    /// $\Delta\omega$ (eq 14, output unit) with one $\Delta\mathbf R$ per position.
    ///
    /// # Errors
    /// As [`analyze`](Self::analyze).
    pub fn delta_omega(&self, delta_r: &[Matrix3<f64>]) -> Result<f64, CalibError> {
        Ok(self.error_vector(delta_r)?.amax())
    }

    /// $\Delta\omega$ (eq 14) when every position has the same orientation error (§2.2: a
    /// fixed $\Delta\psi$, $\Delta\theta$, $\Delta\gamma$).
    ///
    /// # Errors
    /// As [`analyze`](Self::analyze).
    pub fn delta_omega_for_angles(
        &self,
        angles: &OrientationError,
        kind: DeltaRKind,
    ) -> Result<f64, CalibError> {
        self.delta_omega(&self.same_at_every_position(angles, kind))
    }

    /// Eq 7-14 when every position has the same orientation error.
    ///
    /// # Errors
    /// As [`analyze`](Self::analyze).
    pub fn analyze_angles(
        &self,
        angles: &OrientationError,
        kind: DeltaRKind,
    ) -> Result<ErrorAnalysis, CalibError> {
        self.analyze(&self.same_at_every_position(angles, kind))
    }

    /// The orientation error of `angles` at every position (§2.2's fixed error).
    fn same_at_every_position(
        &self,
        angles: &OrientationError,
        kind: DeltaRKind,
    ) -> Vec<Matrix3<f64>> {
        vec![angles.delta_r(kind); self.positions()]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The user's reading's path for outputs of degree at most 2, and the paper's reading's
    /// (precomputed residual), perform the generic path's operations in the same order: the
    /// same bits, on perturbed inputs at every position of the paper's schedule (32
    /// positions, a whole number of lanes) and of a 3 x 7 grid (21, five positions past the
    /// lanes), both outputs.
    #[test]
    fn user_reading_quadratic_path_equals_the_generic_path_bit_for_bit() {
        let grid = crate::paper::grid(
            &[0.0, 90.0, 180.0],
            &[0.0, 45.0, 90.0, 135.0, 180.0, 225.0, 270.0],
        )
        .expect("a valid grid");
        for schedule in [crate::paper::schedule(), grid] {
            check_user_reading_paths(&schedule);
        }
    }

    /// The nominal inputs of output `k` with every value moved by up to 1e-4 (a fixed
    /// pattern per position, input and output).
    fn perturbed(o: &OutputCalibration, k: usize) -> Vec<InputValues> {
        o.nominal_values()
            .iter()
            .enumerate()
            .map(|(i, v)| {
                let mut u = v.0;
                for (q, x) in u.iter_mut().enumerate() {
                    *x += 1e-4 * ((i * 7 + q * 3 + k) as f64).sin();
                }
                InputValues(u)
            })
            .collect()
    }

    fn check_user_reading_paths(schedule: &crate::Schedule) {
        let cal = Calibration::new(
            &gw_model::paper::gyrowheel(),
            &gw_model::paper::site(),
            schedule,
        )
        .expect("the schedule identifies every coefficient");
        for (k, o) in cal.outputs().iter().enumerate() {
            assert!(o.fast.quadratic.is_some(), "the GyroWheel is quadratic");
            let actual = perturbed(o, k);
            let n = actual.len();
            // the user's reading (compiled quadratic terms) and the paper's (the residual at
            // the intended orientation precomputed, only b2' per draw)
            for reading in [Reading::USER, Reading::PAPER] {
                let (mut fast, mut generic) = (vec![0.0; n], vec![0.0; n]);
                let mut work = ErrorWork::default();
                o.error_vector_at(reading, &actual, &mut work, &mut fast)
                    .expect("lengths match");
                o.error_vector_generic(reading, &actual, &mut work, &mut generic)
                    .expect("lengths match");
                let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
                assert_eq!(bits(&fast), bits(&generic), "output {k}, {reading}");
                assert!(fast.iter().any(|&x| x != 0.0), "a non-trivial error vector");
            }
        }
    }

    /// The coefficients' errors through the precomputed pseudo-inverse equal those of the QR
    /// solve of [`Calibration::calibrate`] on the outputs simulated at the same perturbed
    /// inputs, minus the true coefficients, for every output of the paper's sensor and schedule.
    #[test]
    fn coefficient_errors_through_the_pseudo_inverse_equal_the_qr_calibration() {
        // two solvers of the same least squares (condition number < 10 here) differ by
        // rounding of the outputs (~1 in the output unit): 1e-12 of the largest coefficient
        const SOLVERS_AGREE_REL: f64 = 1e-12;
        let cal = Calibration::new(
            &gw_model::paper::gyrowheel(),
            &gw_model::paper::site(),
            &crate::paper::schedule(),
        )
        .expect("the schedule identifies every coefficient");
        for (k, o) in cal.outputs().iter().enumerate() {
            let actual = perturbed(o, k);
            let b1: Vec<f64> = actual.iter().map(|v| o.output().value(v)).collect();
            let qr = cal.calibrate(k, &b1).expect("finite outputs");
            let mut fast = vec![0.0; o.beta().len()];
            o.coefficient_errors_at(&actual, &mut ErrorWork::default(), &mut fast)
                .expect("lengths match");
            let scale = o.beta().amax();
            let moved = qr
                .solution()
                .beta()
                .iter()
                .zip(o.beta().iter())
                .zip(&fast)
                .map(|((est, truth), f)| {
                    approx::assert_abs_diff_eq!(
                        est - truth,
                        *f,
                        epsilon = SOLVERS_AGREE_REL * scale
                    );
                    f.abs()
                })
                .fold(0.0, f64::max);
            assert!(
                moved > 1e3 * SOLVERS_AGREE_REL * scale,
                "output {k}: the perturbation moves the estimate"
            );
            let mut short = vec![0.0; o.beta().len() + 1];
            assert!(
                o.coefficient_errors_at(&actual, &mut ErrorWork::default(), &mut short)
                    .is_err()
            );
        }
    }
}
