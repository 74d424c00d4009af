//! What sensor noise does to a calibration: the covariance of the least-squares estimate
//! and of the rate error it leaves at the test positions, for white noise and for noise
//! correlated between positions (a Gauss-Markov bias seen in the schedule's time order).
//!
//! # Formulas
//! The calibration of eq 6 is ordinary least squares on the position averages,
//! $\hat{\boldsymbol\beta} = \mathbf A^+(\mathbf b_1 - \mathbf b_2)$ with
//! $\mathbf A^+ = \mathbf R^{-1}\mathbf Q^T$ (the [`Regression`]'s pseudo-inverse, computed
//! once). Noise adds $\boldsymbol\nu$ to $\mathbf b_1$, the vector of the positions'
//! averages, with covariance $\boldsymbol\Sigma$ (`gw_model::noise::WindowCovariance`: the
//! position averages' white and Gauss-Markov parts). The estimate moves by
//! $\mathbf A^+\boldsymbol\nu$, so
//! $$\mathrm{Cov}\,\hat{\boldsymbol\beta} = \mathbf A^+\boldsymbol\Sigma\,\mathbf A^{+T}$$
//! (the covariance of the OLS estimate under a general error covariance: C. R. Rao,
//! *Linear Statistical Inference and its Applications*, 2nd ed., Wiley 1973, §4a.2;
//! D. C. Montgomery, E. A. Peck, G. G. Vining, *Introduction to Linear Regression Analysis*,
//! 5th ed., Wiley 2012, §5.5, generalized least squares). Special cases:
//! - **white noise**, position $i$ averaged for $T_i$: $\boldsymbol\Sigma =
//!   \mathrm{diag}(\sigma_i^2)$, $\sigma_i^2 = N^2/T_i + q^2/(12 f_s T_i)$, and
//!   $\mathrm{Cov} = \mathbf A^+\mathrm{diag}(\sigma_i^2)\mathbf A^{+T}$; with equal dwell
//!   $T$, $\mathrm{Cov} = \frac{\sigma^2}{T}(\mathbf A^T\mathbf A)^{-1}$ with
//!   $\sigma^2 = N^2 + q^2/(12 f_s)$, because
//!   $\mathbf A^+\mathbf A^{+T} = \mathbf R^{-1}\mathbf R^{-T} = (\mathbf A^T\mathbf A)^{-1}$;
//! - **Gauss-Markov bias** $(\sigma_b, T_c)$, autocovariance $\sigma_b^2 e^{-|\Delta t|/T_c}$:
//!   $\Sigma_{ij}$ is the covariance of the averages over the windows of positions $i$ and
//!   $j$ (closed form in `gw_model::noise`), which depends on where the windows lie in time:
//!   on the dwell and move times ([`Timing`]) and on the **order** the positions are taken
//!   in. The white part does not depend on the order (it is diagonal, each position keeps its
//!   dwell); the correlated part does: a slow bias wander looks like a regressor that varies
//!   with time, and it leaks into the coefficients whose regressors vary along the visiting
//!   order. [`OutputCalibration::noise_covariance_in_order`] evaluates any order with the
//!   same regression (the estimate does not depend on the order; only the windows move).
//!
//! The calibration is not re-weighted: generalised least squares,
//! $(\mathbf A^T\boldsymbol\Sigma^{-1}\mathbf A)^{-1}$, would be the best linear unbiased
//! estimate, but eq 6 is what a lab computes and what this covariance describes.
//!
//! **Rate error at the test positions.** The noise part of eq 13-14's error vector (the
//! compensated output at the test positions, with the estimated coefficients in place of the
//! true ones) is $\mathbf A(\hat{\boldsymbol\beta} - \boldsymbol\beta)$, of covariance
//! $\mathbf A\,\mathrm{Cov}\,\hat{\boldsymbol\beta}\,\mathbf A^T$; its diagonal gives the
//! standard deviation of each position's entry, the noise sigma behind eq 14's
//! $\lVert\Delta\hat{\boldsymbol\omega}\rVert_\infty$ at each position
//! ([`RateErrorCovariance::sigma`], the largest by [`RateErrorCovariance::max_sigma`]).
//!
//! # Cost
//! One $k\times n$ by $n\times n$ product and one $k\times n$ by $n\times k$ product per part,
//! with the pseudo-inverse the regression already holds: no second solve.

use super::Regression;
use crate::calibration::{Calibration, OutputCalibration};
use crate::error::CalibError;
use crate::timing::Timing;
use gw_model::noise::{NoiseModel, Window, WindowCovariance};
use nalgebra::{DMatrix, DVector};

/// The covariance of one output's estimated coefficients under noise, split into the white
/// part (white noise and quantization) and the correlated part (Gauss-Markov bias), each
/// $k\times k$ in coefficient order (output unit per regressor unit, squared).
#[derive(Debug, Clone, PartialEq)]
pub struct CoefficientCovariance {
    names: Vec<String>,
    white: DMatrix<f64>,
    correlated: DMatrix<f64>,
}

impl CoefficientCovariance {
    /// The coefficients' names (rows and columns).
    #[must_use]
    pub fn names(&self) -> &[String] {
        &self.names
    }

    /// The white part, $\mathbf A^+\boldsymbol\Sigma_w\mathbf A^{+T}$.
    #[must_use]
    pub fn white(&self) -> &DMatrix<f64> {
        &self.white
    }

    /// The correlated part, $\mathbf A^+\boldsymbol\Sigma_b\mathbf A^{+T}$.
    #[must_use]
    pub fn correlated(&self) -> &DMatrix<f64> {
        &self.correlated
    }

    /// The whole covariance.
    #[must_use]
    pub fn total(&self) -> DMatrix<f64> {
        &self.white + &self.correlated
    }

    /// Standard deviation of each coefficient, every part.
    #[must_use]
    pub fn sigma(&self) -> DVector<f64> {
        diag_sqrt(&(&self.white + &self.correlated))
    }

    /// Standard deviation of each coefficient, white part only.
    #[must_use]
    pub fn white_sigma(&self) -> DVector<f64> {
        diag_sqrt(&self.white)
    }

    /// Standard deviation of each coefficient, correlated part only.
    #[must_use]
    pub fn correlated_sigma(&self) -> DVector<f64> {
        diag_sqrt(&self.correlated)
    }
}

/// The covariance of the noise part of the rate error at the test positions,
/// $\mathbf A\,\mathrm{Cov}\,\hat{\boldsymbol\beta}\,\mathbf A^T$ ($n\times n$, output unit
/// squared), white and correlated parts. The per-position standard deviations are computed
/// at once ($\sigma_i^2 = \mathbf a_i^T\mathrm{Cov}\,\mathbf a_i$, $O(nk^2)$); the
/// $n\times n$ matrices only when asked for.
#[derive(Debug, Clone, PartialEq)]
pub struct RateErrorCovariance {
    a: DMatrix<f64>,
    white: DMatrix<f64>,
    correlated: DMatrix<f64>,
    white_variance: DVector<f64>,
    correlated_variance: DVector<f64>,
}

impl RateErrorCovariance {
    /// The white part, $\mathbf A\,\mathrm{Cov}_w\mathbf A^T$ ($n\times n$).
    #[must_use]
    pub fn white(&self) -> DMatrix<f64> {
        sandwich(&self.a, &self.white)
    }

    /// The correlated part, $\mathbf A\,\mathrm{Cov}_b\mathbf A^T$ ($n\times n$).
    #[must_use]
    pub fn correlated(&self) -> DMatrix<f64> {
        sandwich(&self.a, &self.correlated)
    }

    /// The whole covariance ($n\times n$).
    #[must_use]
    pub fn total(&self) -> DMatrix<f64> {
        sandwich(&self.a, &(&self.white + &self.correlated))
    }

    /// Standard deviation of the rate error at each test position (the noise sigma of that
    /// position's entry of eq 14's infinity norm), output unit.
    #[must_use]
    pub fn sigma(&self) -> DVector<f64> {
        (&self.white_variance + &self.correlated_variance).map(|v| v.max(0.0).sqrt())
    }

    /// Standard deviation at each test position, white part only.
    #[must_use]
    pub fn white_sigma(&self) -> DVector<f64> {
        self.white_variance.map(|v| v.max(0.0).sqrt())
    }

    /// Standard deviation at each test position, correlated part only.
    #[must_use]
    pub fn correlated_sigma(&self) -> DVector<f64> {
        self.correlated_variance.map(|v| v.max(0.0).sqrt())
    }

    /// The largest per-position standard deviation and its position.
    #[must_use]
    pub fn max_sigma(&self) -> (usize, f64) {
        self.sigma()
            .iter()
            .copied()
            .enumerate()
            .fold((0, f64::NEG_INFINITY), |best, (i, s)| {
                if s > best.1 { (i, s) } else { best }
            })
    }
}

/// Both covariances of one output under noise.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct NoiseCovariance {
    /// Of the estimated coefficients.
    pub(crate) coefficients: CoefficientCovariance,
    /// Of the rate error at the test positions.
    pub(crate) rate_error: RateErrorCovariance,
}

/// Read access to the fields (crate-private, so the type can grow without breaking callers).
impl NoiseCovariance {
    /// Of the estimated coefficients.
    #[must_use]
    pub fn coefficients(&self) -> &CoefficientCovariance {
        &self.coefficients
    }

    /// Of the rate error at the test positions.
    #[must_use]
    pub fn rate_error(&self) -> &RateErrorCovariance {
        &self.rate_error
    }
}

fn diag_sqrt(m: &DMatrix<f64>) -> DVector<f64> {
    DVector::from_iterator(m.nrows(), m.diagonal().iter().map(|v| v.max(0.0).sqrt()))
}

/// $\mathbf B\mathbf C\mathbf B^T$, symmetrised (rounding would otherwise leave it
/// asymmetric in the last bits).
fn sandwich(b: &DMatrix<f64>, c: &DMatrix<f64>) -> DMatrix<f64> {
    let m = b * c * b.transpose();
    (&m + m.transpose()) * 0.5
}

/// $\mathbf P\mathbf C\mathbf P^T$ for a symmetric $n\times n$ $\mathbf C$ and $\mathbf P$
/// given transposed (`pt`, $n\times k$, columns contiguous): a diagonal $\mathbf C$ in
/// $O(nk^2)$, a dense one as $k$ products $\mathbf C\mathbf p_r$ (contiguous dot products,
/// using the symmetry) and $k^2$ dot products.
fn sandwich_symmetric(pt: &DMatrix<f64>, c: &DMatrix<f64>) -> DMatrix<f64> {
    let (n, k) = pt.shape();
    // column-major storage: column j of an n-row matrix is [j n, (j + 1) n)
    let (p, cs) = (pt.as_slice(), c.as_slice());
    let diagonal = cs
        .chunks_exact(n)
        .enumerate()
        .all(|(j, col)| col.iter().enumerate().all(|(i, &v)| i == j || v == 0.0));
    let mut out = DMatrix::zeros(k, k);
    if diagonal {
        for i in 0..n {
            let d = cs[i * n + i];
            if d == 0.0 {
                continue;
            }
            for r in 0..k {
                let pr = p[r * n + i] * d;
                for s in 0..=r {
                    out[(r, s)] += pr * p[s * n + i];
                }
            }
        }
    } else {
        // cp = C P^T (n x k), by symmetry (C p_r)_j = column j of C . p_r
        let mut cp = vec![0.0; n * k];
        for r in 0..k {
            let pr = &p[r * n..(r + 1) * n];
            for (j, col) in cs.chunks_exact(n).enumerate() {
                cp[r * n + j] = dot(col, pr);
            }
        }
        for r in 0..k {
            for s in 0..=r {
                out[(r, s)] = dot(&p[r * n..(r + 1) * n], &cp[s * n..(s + 1) * n]);
            }
        }
    }
    for r in 0..k {
        for s in 0..r {
            out[(s, r)] = out[(r, s)];
        }
    }
    out
}

/// $\mathbf x\cdot\mathbf y$ with eight independent partial sums (a single running sum is a
/// chain of dependent additions, several times slower for the $n = 128$ of a long schedule).
fn dot(x: &[f64], y: &[f64]) -> f64 {
    const LANES: usize = 8;
    let mut acc = [0.0; LANES];
    let (xc, yc) = (x.chunks_exact(LANES), y.chunks_exact(LANES));
    let tail: f64 = xc
        .remainder()
        .iter()
        .zip(yc.remainder())
        .map(|(a, b)| a * b)
        .sum();
    for (a, b) in xc.zip(yc) {
        for l in 0..LANES {
            acc[l] += a[l] * b[l];
        }
    }
    acc.iter().sum::<f64>() + tail
}

/// $\mathbf a_i^T\mathbf C\mathbf a_i$ for every row $i$ of $\mathbf A$.
fn row_quadratic_forms(a: &DMatrix<f64>, c: &DMatrix<f64>) -> DVector<f64> {
    let ac = a * c;
    DVector::from_iterator(a.nrows(), (0..a.nrows()).map(|i| ac.row(i).dot(&a.row(i))))
}

impl Regression {
    /// The covariance of the estimated coefficients when the outputs at the positions (the
    /// rows of $\mathbf A$) carry noise of covariance `positions` ($n\times n$, white and
    /// correlated parts): $\mathbf A^+\boldsymbol\Sigma\mathbf A^{+T}$ per part.
    ///
    /// # Errors
    /// [`CalibError::Field`] ([`tt_core::FieldError::Length`]) unless both parts are $n\times n$.
    pub fn coefficient_covariance(
        &self,
        positions: &WindowCovariance,
    ) -> Result<CoefficientCovariance, CalibError> {
        let n = self.a.nrows();
        for m in [&positions.white(), &positions.correlated()] {
            if m.shape() != (n, n) {
                return Err(CalibError::Field(tt_core::FieldError::Length {
                    field: "position covariance (rows and columns)".into(),
                    expected: n,
                    found: if m.nrows() == n { m.ncols() } else { m.nrows() },
                }));
            }
        }
        let pt = self.pinv.transpose();
        Ok(CoefficientCovariance {
            names: self.names.clone(),
            white: sandwich_symmetric(&pt, positions.white()),
            correlated: sandwich_symmetric(&pt, positions.correlated()),
        })
    }

    /// The covariance of the rate error at the test positions,
    /// $\mathbf A\,\mathrm{Cov}\,\hat{\boldsymbol\beta}\,\mathbf A^T$ per part.
    ///
    /// # Errors
    /// [`CalibError::Field`] ([`tt_core::FieldError::Length`]) unless `coefficients` is $k\times k$.
    pub fn rate_error_covariance(
        &self,
        coefficients: &CoefficientCovariance,
    ) -> Result<RateErrorCovariance, CalibError> {
        let k = self.a.ncols();
        if coefficients.white.shape() != (k, k) {
            return Err(CalibError::Field(tt_core::FieldError::Length {
                field: "coefficient covariance (rows)".into(),
                expected: k,
                found: coefficients.white.nrows(),
            }));
        }
        Ok(RateErrorCovariance {
            a: self.a.clone(),
            white_variance: row_quadratic_forms(&self.a, &coefficients.white),
            correlated_variance: row_quadratic_forms(&self.a, &coefficients.correlated),
            white: coefficients.white.clone(),
            correlated: coefficients.correlated.clone(),
        })
    }

    /// Both covariances for noise of covariance `positions` at the positions.
    ///
    /// # Errors
    /// As [`coefficient_covariance`](Self::coefficient_covariance).
    pub fn noise_covariance(
        &self,
        positions: &WindowCovariance,
    ) -> Result<NoiseCovariance, CalibError> {
        let coefficients = self.coefficient_covariance(positions)?;
        let rate_error = self.rate_error_covariance(&coefficients)?;
        Ok(NoiseCovariance {
            coefficients,
            rate_error,
        })
    }
}

impl OutputCalibration {
    /// The noise covariances of this output's calibration with the positions taken in the
    /// schedule's order.
    ///
    /// # Errors
    /// [`CalibError::Field`] ([`tt_core::FieldError::Length`]) unless `timing` has one dwell per position.
    pub fn noise_covariance(
        &self,
        noise: &NoiseModel,
        timing: &Timing,
    ) -> Result<NoiseCovariance, CalibError> {
        self.check_timing(timing)?;
        self.covariance_for_windows(noise, &timing.windows(), timing.sample_rate_hz())
    }

    /// The noise covariances with the positions visited in `order` (`order[r]` is the
    /// schedule index of the position taken $r$-th; each keeps its dwell). Only the
    /// correlated part can change: compare with
    /// [`noise_covariance`](Self::noise_covariance) to see what the order does.
    ///
    /// # Errors
    /// [`CalibError::Field`] ([`tt_core::FieldError::Length`]) unless `timing` has one dwell per position and `order`
    /// is a permutation of the positions.
    pub fn noise_covariance_in_order(
        &self,
        noise: &NoiseModel,
        timing: &Timing,
        order: &[usize],
    ) -> Result<NoiseCovariance, CalibError> {
        self.check_timing(timing)?;
        self.covariance_for_windows(
            noise,
            &timing.windows_in_order(order)?,
            timing.sample_rate_hz(),
        )
    }

    fn check_timing(&self, timing: &Timing) -> Result<(), CalibError> {
        let n = self.regression().matrix().nrows();
        if timing.len() == n {
            Ok(())
        } else {
            Err(CalibError::Field(tt_core::FieldError::Length {
                field: "averaging windows (one per position and rate step)".into(),
                expected: n,
                found: timing.len(),
            }))
        }
    }

    fn covariance_for_windows(
        &self,
        noise: &NoiseModel,
        windows: &[Window],
        sample_rate_hz: f64,
    ) -> Result<NoiseCovariance, CalibError> {
        let positions = noise.window_covariance(windows, sample_rate_hz)?;
        self.regression().noise_covariance(&positions)
    }
}

impl Calibration {
    /// The noise covariances of every output with a noise model (`noise[k]` for output $k$,
    /// study order; `None` for a noiseless output), positions in the schedule's order.
    ///
    /// # Errors
    /// [`CalibError::Field`] ([`tt_core::FieldError::Length`]) unless there is one entry per output and one dwell per
    /// position.
    pub fn noise_covariances(
        &self,
        noise: &[Option<NoiseModel>],
        timing: &Timing,
    ) -> Result<Vec<Option<NoiseCovariance>>, CalibError> {
        if noise.len() != self.outputs().len() {
            return Err(CalibError::Field(tt_core::FieldError::Length {
                field: "noise models (one per output)".into(),
                expected: self.outputs().len(),
                found: noise.len(),
            }));
        }
        self.outputs()
            .iter()
            .zip(noise)
            .map(|(o, m)| {
                m.as_ref()
                    .map(|m| o.noise_covariance(m, timing))
                    .transpose()
            })
            .collect()
    }
}
