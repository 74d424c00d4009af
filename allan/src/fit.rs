//! The noise parameters of a curve: a weighted, non-negative least-squares fit of the power
//! terms of IEEE Std 952-1997 Annex C and the floor of the curve.
//!
//! The Allan variance of independent noise terms adds (IEEE Std 952-1997, Annex C, eq C.1;
//! IEEE Std 1293-1998 Annex for accelerometers; N. El-Sheimy, H. Hou, X. Niu, *Analysis and
//! Modeling of Inertial Sensors Using Allan Variance*, IEEE Trans. Instrum. Meas. 57(1), 2008,
//! Table I):
//! $$\sigma^2(\tau) = \frac{3Q^2}{\tau^2} + \frac{N^2}{\tau} + C_0 + \frac{K^2\tau}{3} +
//! \frac{R^2\tau^2}{2},$$
//! quantization $Q$ (slope $-1$), white noise $N$ (slope $-1/2$: $\sigma(\tau) = N/\sqrt\tau$,
//! so $N$ is the line's value at $\tau = 1$ s), a flat part $C_0$ (flicker: slope 0), rate
//! random walk $K$ (slope $+1/2$: $K$ is the line's value at $\tau = 3$ s) and a rate ramp
//! $R$ (slope $+1$). The coefficients $C_n$ of $\tau^n$ are fitted to every cluster time by
//! least squares weighted with the inverse variance of each point,
//! $w_i = \nu_i / (2 \sigma_i^4)$ ($\nu_i$ the equivalent degrees of freedom, $\sigma_i^2$ the
//! fitted curve, iterated from the measured one), subject to $C_n \ge 0$ (the exact
//! non-negative solution: every subset of terms is solved and the best feasible kept). The
//! slope lines are read off the fit: $N = \sqrt{C_{-1}}$, $K = \sqrt{3 C_1}$; reading them
//! jointly keeps the other terms from biasing them where the slopes overlap.
//!
//! Bias instability is read from the floor of the curve: for flicker noise of two-sided
//! density $B^2/(2\pi f)$, $\sigma^2 = (2 \ln 2/\pi) B^2$ (IEEE Std 952 eq C.9), so
//! $$B = \min_{\tau_i} \sigma_{\mathrm{fit}}(\tau_i) \,\Big/\, \sqrt{2\ln 2/\pi},\qquad
//! \sqrt{2 \ln 2/\pi} = 0.6643,$$
//! the minimum of the fitted curve over the measured cluster times $\tau_i$. The fitted curve
//! averages the floor over every point by its degrees of freedom; the minimum of the measured
//! points instead would pick the lowest of several statistically equal points of the floor
//! (biased low, mostly by the few-degree-of-freedom points at long $\tau$). Where the curve
//! has no flat part (white noise and rate random walk only) the floor is the bottom of the
//! bend between the $-1/2$ and $+1/2$ lines, $\sqrt{2NK/\sqrt3}$, as the method gives. The
//! cluster time of the minimum is reported as a heuristic correlation time of a first-order
//! Gauss-Markov model of the bias (a Gauss-Markov process of correlation time $T$ has its
//! Allan deviation peak near $\tau = 1.89\,T$; a flicker floor has no single time); when
//! the minimum is the longest cluster time the curve has not turned and $B$ is an upper
//! bound.
//!
//! Uncertainty of $N$ and $K$: each fitted coefficient is a linear combination
//! $\sum_i a_i \hat\sigma_i^2$ of the measured points; whatever their correlation,
//! $\operatorname{sd} \le \sum_i |a_i| \operatorname{sd}(\hat\sigma_i^2)$ with
//! $\operatorname{sd}(\hat\sigma_i^2) = \sigma_i^2\sqrt{2/\nu_i}$: a conservative standard
//! uncertainty (for the fitted subset of terms).

/// $\sqrt{2 \ln 2 / \pi}$: the Allan deviation of flicker noise of bias instability $B$ is
/// this times $B$ (IEEE Std 952-1997, eq C.9).
pub const FLICKER_FLOOR_FACTOR: f64 = 0.664_282_470_267_960_1;

/// The exponents $n$ of the terms $C_n \tau^n$, in order.
pub const EXPONENTS: [i32; 5] = [-2, -1, 0, 1, 2];

/// The least-squares fit of the power terms.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct PowerFit {
    /// $C_n$ for $n = -2 \dots 2$ ([`EXPONENTS`]), log unit$^2$ s$^{-n}$; zero when a term is
    /// not in the fitted subset.
    pub(crate) coefficients: [f64; 5],
    /// Conservative standard uncertainty of each $C_n$ (0 for a term not fitted).
    pub(crate) uncertainty: [f64; 5],
    /// Per point $i$: $\partial C_n / \partial \hat\sigma_i^2$ times the standard deviation
    /// of $\hat\sigma_i^2$ (the linear estimator on standardized points).
    pub(crate) sensitivity: Vec<[f64; 5]>,
}

/// Read access to the fields (crate-private, so the type can grow without breaking callers).
impl PowerFit {
    /// $C_n$ for $n = -2 \dots 2$ ([`EXPONENTS`]), log unit$^2$ s$^{-n}$; zero when a term is
    /// not in the fitted subset.
    #[must_use]
    pub fn coefficients(&self) -> [f64; 5] {
        self.coefficients
    }

    /// Conservative standard uncertainty of each $C_n$ (0 for a term not fitted).
    #[must_use]
    pub fn uncertainty(&self) -> [f64; 5] {
        self.uncertainty
    }

    /// Per point $i$: $\partial C_n / \partial \hat\sigma_i^2$ times the standard deviation
    /// of $\hat\sigma_i^2$ (the linear estimator on standardized points).
    #[must_use]
    pub fn sensitivity(&self) -> &[[f64; 5]] {
        &self.sensitivity
    }
}

impl PowerFit {
    /// The fitted Allan variance at `tau_s`.
    #[must_use]
    pub fn avar(&self, tau_s: f64) -> f64 {
        self.coefficients
            .iter()
            .zip(EXPONENTS)
            .map(|(c, n)| c * tau_s.powi(n))
            .sum()
    }

    /// Conservative standard uncertainty of the fitted Allan variance at `tau_s`:
    /// $\sum_i |\sum_n \tau^n\, \partial C_n/\partial \hat\sigma_i^2|\,
    /// \operatorname{sd}(\hat\sigma_i^2)$.
    #[must_use]
    pub fn avar_uncertainty(&self, tau_s: f64) -> f64 {
        self.sensitivity
            .iter()
            .map(|s| {
                s.iter()
                    .zip(EXPONENTS)
                    .map(|(d, n)| d * tau_s.powi(n))
                    .sum::<f64>()
                    .abs()
            })
            .sum()
    }
}

/// A least-squares solution: coefficients, residual sum of squares, linear operator.
type Solution = (Vec<f64>, f64, Vec<Vec<f64>>);

/// Least squares of `y` on the columns `cols` of `x` (rows already weighted), by Householder
/// QR on scaled columns. Returns the coefficients (in `cols` order), the residual sum of
/// squares and the linear operator (coefficients = op * y), or `None` when rank deficient.
#[allow(clippy::needless_range_loop)]
fn least_squares(x: &[[f64; 5]], y: &[f64], cols: &[usize]) -> Option<Solution> {
    let n = x.len();
    let p = cols.len();
    if p == 0 || p > n {
        return None;
    }
    // scaled columns
    let mut scale = vec![0.0; p];
    let mut a = vec![vec![0.0; p]; n];
    for (j, &c) in cols.iter().enumerate() {
        let norm = x.iter().map(|r| r[c] * r[c]).sum::<f64>().sqrt();
        if !(norm > 0.0 && norm.is_finite()) {
            return None;
        }
        scale[j] = norm;
        for i in 0..n {
            a[i][j] = x[i][c] / norm;
        }
    }
    // Q^T applied to the identity alongside (n x n, n <= 64)
    let mut qt: Vec<Vec<f64>> = (0..n)
        .map(|i| (0..n).map(|k| if i == k { 1.0 } else { 0.0 }).collect())
        .collect();
    for j in 0..p {
        let norm = (j..n).map(|i| a[i][j] * a[i][j]).sum::<f64>().sqrt();
        if norm < 1e-12 {
            return None;
        }
        let alpha = if a[j][j] > 0.0 { -norm } else { norm };
        let mut v: Vec<f64> = (j..n).map(|i| a[i][j]).collect();
        v[0] -= alpha;
        let vnorm2: f64 = v.iter().map(|t| t * t).sum();
        if vnorm2 == 0.0 {
            continue;
        }
        for k in j..p {
            let dot: f64 = (j..n).map(|i| v[i - j] * a[i][k]).sum();
            let f = 2.0 * dot / vnorm2;
            for i in j..n {
                a[i][k] -= f * v[i - j];
            }
        }
        for k in 0..n {
            let dot: f64 = (j..n).map(|i| v[i - j] * qt[i][k]).sum();
            let f = 2.0 * dot / vnorm2;
            for i in j..n {
                qt[i][k] -= f * v[i - j];
            }
        }
    }
    // R is a[0..p][0..p]; op = R^-1 (Q^T)[0..p]
    let mut op = vec![vec![0.0; n]; p];
    for k in 0..n {
        for j in (0..p).rev() {
            let mut s = qt[j][k];
            for l in j + 1..p {
                s -= a[j][l] * op[l][k];
            }
            op[j][k] = s / a[j][j];
        }
    }
    let mut coef = vec![0.0; p];
    for j in 0..p {
        coef[j] = op[j].iter().zip(y).map(|(o, v)| o * v).sum::<f64>() / scale[j];
        for k in 0..n {
            op[j][k] /= scale[j];
        }
    }
    let rss = x
        .iter()
        .zip(y)
        .map(|(r, v)| {
            let fitted: f64 = cols.iter().zip(&coef).map(|(&c, b)| r[c] * b).sum();
            (v - fitted) * (v - fitted)
        })
        .sum();
    Some((coef, rss, op))
}

/// Fit the power terms to the points `(tau_s, avar, edf)`.
///
/// Every subset of the five terms is solved; among those with all coefficients non-negative
/// the one with the least weighted residual wins (ties, within $10^{-12}$ of the residual,
/// go to the fewer terms, then to the earlier subset with white noise first). Weights are
/// iterated from the measured variances to the fitted ones (up to 20 rounds). Points with
/// zero variance everywhere give a zero fit.
#[must_use]
pub fn fit_power_terms(points: &[(f64, f64, f64)]) -> PowerFit {
    let zero = PowerFit {
        coefficients: [0.0; 5],
        uncertainty: [0.0; 5],
        sensitivity: vec![[0.0; 5]; points.len()],
    };
    let peak = points.iter().map(|p| p.1).fold(0.0, f64::max);
    if points.is_empty() || peak <= 0.0 {
        return zero;
    }
    let floor = peak * 1e-30;
    // subsets, white noise first, then by size
    let mut subsets: Vec<Vec<usize>> = (1u32..32)
        .map(|mask| {
            (0..5)
                .filter(|b| mask & (1 << b) != 0)
                .collect::<Vec<usize>>()
        })
        .collect();
    subsets.sort_by_key(|s| (s.len(), !s.contains(&1), s.clone()));
    let mut model: Vec<f64> = points.iter().map(|p| p.1.max(floor)).collect();
    let mut best = zero.clone();
    let mut last_support: Option<Vec<usize>> = None;
    for _round in 0..20 {
        let w: Vec<f64> = points
            .iter()
            .zip(&model)
            .map(|(p, m)| (0.5 * p.2.max(1e-12)).sqrt() / m.max(floor))
            .collect();
        let x: Vec<[f64; 5]> = points
            .iter()
            .zip(&w)
            .map(|(p, wi)| {
                let mut r = [0.0; 5];
                for (k, n) in EXPONENTS.iter().enumerate() {
                    r[k] = wi * p.0.powi(*n);
                }
                r
            })
            .collect();
        let y: Vec<f64> = points.iter().zip(&w).map(|(p, wi)| wi * p.1).collect();
        let mut chosen: Option<(Vec<usize>, Solution)> = None;
        for s in &subsets {
            let Some((coef, rss, op)) = least_squares(&x, &y, s) else {
                continue;
            };
            if coef.iter().any(|c| *c < 0.0 || !c.is_finite()) {
                continue;
            }
            let better = match &chosen {
                None => true,
                Some((_, (_, r, _))) => rss < *r - 1e-12 * r.max(f64::MIN_POSITIVE),
            };
            if better {
                chosen = Some((s.clone(), (coef, rss, op)));
            }
        }
        let Some((support, (coef, _, op))) = chosen else {
            return zero;
        };
        let mut fit = zero.clone();
        for (j, &c) in support.iter().enumerate() {
            fit.coefficients[c] = coef[j];
            // sd of each weighted y_i is sqrt(nu/2)/m * m*sqrt(2/nu) = 1: sum of |op|
            fit.uncertainty[c] = op[j].iter().map(|o| o.abs()).sum();
            for (i, o) in op[j].iter().enumerate() {
                fit.sensitivity[i][c] = *o;
            }
        }
        let new_model: Vec<f64> = points.iter().map(|p| fit.avar(p.0).max(floor)).collect();
        let converged = last_support.as_ref() == Some(&support)
            && new_model
                .iter()
                .zip(&model)
                .all(|(a, b)| (a - b).abs() <= 1e-12 * b.abs());
        model = new_model;
        best = fit;
        last_support = Some(support);
        if converged {
            break;
        }
    }
    best
}
