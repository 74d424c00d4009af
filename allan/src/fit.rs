//! The noise parameters of a curve: weighted, non-negative least squares of the IEEE Std
//! 952-1997 / 1293-1998 terms in the Allan variance domain, and a first-order Gauss-Markov
//! alternative whose correlation time is fitted.
//!
//! The Allan variance of independent noise terms adds (IEEE Std 952-1997, Annex C, eq C.1;
//! IEEE Std 1293-1998 Annex for accelerometers; N. El-Sheimy, H. Hou, X. Niu, *Analysis and
//! Modeling of Inertial Sensors Using Allan Variance*, IEEE Trans. Instrum. Meas. 57(1), 2008,
//! Table I):
//! $$\sigma^2(\tau) = \frac{3Q^2}{\tau^2} + \frac{N^2}{\tau} + (0.664 B)^2 + \frac{K^2\tau}{3} +
//! \frac{R^2\tau^2}{2},$$
//! quantization $Q$ (slope $-1$), white noise $N$ (slope $-1/2$, the line's value at
//! $\tau = 1$ s), bias instability $B$ as a flicker floor (slope 0, $0.664 =
//! \sqrt{2\ln 2/\pi}$), rate random walk $K$ (slope $+1/2$, the line's value at $\tau = 3$ s)
//! and rate ramp $R$ (slope $+1$). The variance is linear in $Q^2, N^2, B^2, K^2, R^2$: the
//! coefficients $C_n$ of $\tau^n$ are fitted by least squares weighted with the inverse
//! variance of each point, $w_i = \nu_i / (2 \sigma_i^4)$ ($\nu_i$ the equivalent degrees of
//! freedom of [`crate::edf`], $\sigma_i^2$ the fitted curve, iterated from the measured one),
//! subject to $C_n \ge 0$ (exact: every subset of terms is solved and the best feasible kept).
//!
//! **Scale.** The fit works in units of the largest measured variance and of the geometric
//! mean cluster time, so that it gives the same relative answer for a log multiplied by any
//! factor or sampled at any rate (a log scaled by $10^{100}$ or $10^{-80}$, or a rate of
//! $10^{-9}$ Hz, fit as well as the unscaled one).
//!
//! **Uncertainty.** Each parameter's standard uncertainty comes from the covariance of the
//! fitted coefficients, $(X^\top W X)^{-1}$ over the terms in the fit, multiplied by the
//! reduced chi-square when it exceeds 1 (the scatter the weights did not predict) and by the
//! grid's density in points per octave when above 1 (neighbouring cluster times of a denser
//! grid share their data; the octave points are taken as independent). A parameter
//! $p = \sqrt{k C}$ has $u_p = p\,u_C / (2C)$.
//!
//! **What the log cannot resolve.** A term fitted at zero is not seen above the others at any
//! measured cluster time; a term whose coefficient is less than twice its uncertainty is not
//! significant (for $K$ and $R$: no cluster time is long enough for them); see
//! [`Resolution`].
//!
//! **Gauss-Markov alternative.** A first-order Gauss-Markov bias of stationary deviation
//! $\sigma$ and correlation time $T_c$ has the Allan variance
//! $\sigma^2\,(2u - 3 + 4e^{-u} - e^{-2u})/u^2$, $u = \tau/T_c$, which peaks near
//! $\tau = 1.89\,T_c$. With $Q, N, K, R$ and $\sigma^2$ fitted linearly at each trial $T_c$
//! (profiled out), $T_c$ minimizes the weighted residual over a logarithmic search (a grid of
//! [`GM_GRID`] points from a tenth of the shortest to ten times the longest cluster time,
//! refined by golden section); its uncertainty is where the profile residual rises by the
//! variance scale above (the usual profile-likelihood interval, halved in log). A minimum at
//! the longest end of the search means the log is too short for the correlation time
//! ([`Resolution::BeyondLog`]).

use gw_model::noise::GaussMarkov;

/// $\sqrt{2 \ln 2 / \pi}$: the Allan deviation of flicker noise of bias instability $B$ is
/// this times $B$ (IEEE Std 952-1997, eq C.9).
pub const FLICKER_FLOOR_FACTOR: f64 = 0.664_282_470_267_960_1;

/// The exponents $n$ of the terms $C_n \tau^n$, in order.
pub(crate) const EXPONENTS: [i32; 5] = [-2, -1, 0, 1, 2];

/// Points of the logarithmic correlation-time grid of the Gauss-Markov search.
pub(crate) const GM_GRID: usize = 97;

/// $k$ with parameter $= \sqrt{k\,C_n}$ for $n = -2 \dots 2$: $Q = \sqrt{C_{-2}/3}$,
/// $N = \sqrt{C_{-1}}$, $B = \sqrt{C_0}/0.664$, $K = \sqrt{3 C_1}$, $R = \sqrt{2 C_2}$.
const PARAMETER_FACTOR: [f64; 5] = [
    1.0 / 3.0,
    1.0,
    1.0 / (FLICKER_FLOOR_FACTOR * FLICKER_FLOOR_FACTOR),
    3.0,
    2.0,
];

/// Whether the log resolves a term.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "snake_case"))]
pub enum Resolution {
    /// Fitted, at least twice its uncertainty.
    Resolved,
    /// Fitted at zero: not seen above the other terms at any measured cluster time.
    AtZero,
    /// Fitted, but less than twice its uncertainty (for rate random walk and ramp: no
    /// cluster time is long enough).
    NotSignificant,
    /// The term lies beyond the log's length (a correlation time, or a floor, longer than
    /// the longest cluster time resolves).
    BeyondLog,
    /// The term lies below the shortest cluster time (a correlation time shorter than it:
    /// indistinguishable from white noise).
    BelowLog,
}

impl Resolution {
    /// Whether the value can be used.
    #[must_use]
    pub fn is_resolved(self) -> bool {
        self == Resolution::Resolved
    }

    /// Why not, in words (empty when resolved).
    #[must_use]
    pub fn explain(self) -> &'static str {
        match self {
            Resolution::Resolved => "",
            Resolution::AtZero => {
                "fitted at zero: not seen above the other terms at any measured cluster time"
            }
            Resolution::NotSignificant => {
                "less than twice its uncertainty: no measured cluster time shows it clearly"
            }
            Resolution::BeyondLog => "beyond the log's length: a longer log is needed",
            Resolution::BelowLog => {
                "shorter than the shortest cluster time: indistinguishable from white noise"
            }
        }
    }
}

/// One fitted parameter with its standard uncertainty.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[non_exhaustive]
pub struct Term {
    pub(crate) value: f64,
    pub(crate) uncertainty: Option<f64>,
    pub(crate) resolution: Resolution,
}

impl Term {
    /// The value (0 when fitted at zero).
    #[must_use]
    pub fn value(&self) -> f64 {
        self.value
    }

    /// Its standard uncertainty (`None` when fitted at zero).
    #[must_use]
    pub fn uncertainty(&self) -> Option<f64> {
        self.uncertainty
    }

    /// Whether the log resolves it.
    #[must_use]
    pub fn resolution(&self) -> Resolution {
        self.resolution
    }

    const ZERO: Term = Term {
        value: 0.0,
        uncertainty: None,
        resolution: Resolution::AtZero,
    };
}

/// The weighted least-squares fit of the power terms, in normalized units (variance over
/// `var_scale`, cluster time over `tau_scale`).
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct PowerFit {
    /// Normalized coefficients $c_n$ ($C_n = c_n\,A\,T^{-n}$) for $n = -2 \dots 2$.
    pub(crate) coefficients: [f64; 5],
    /// Their covariance (zero rows and columns for the terms not in the fit).
    pub(crate) covariance: [[f64; 5]; 5],
    /// $A$: the variance unit.
    pub(crate) var_scale: f64,
    /// $T$: the cluster-time unit, s.
    pub(crate) tau_scale: f64,
    /// The fitted normalized variance at every point (the weights' model).
    pub(crate) model: Vec<f64>,
    /// The variance scale of the covariance (reduced chi-square and grid density, >= 1).
    pub(crate) inflation: f64,
}

impl PowerFit {
    /// The fitted Allan variance at `tau_s`, log unit squared.
    #[must_use]
    pub(crate) fn avar(&self, tau_s: f64) -> f64 {
        let x = tau_s / self.tau_scale;
        self.var_scale * dot(&self.coefficients, &powers(x))
    }

    /// Standard uncertainty of the fitted Allan variance at `tau_s`, log unit squared.
    #[must_use]
    pub(crate) fn avar_uncertainty(&self, tau_s: f64) -> f64 {
        let g = powers(tau_s / self.tau_scale);
        let mut v = 0.0;
        for i in 0..5 {
            for j in 0..5 {
                v += g[i] * self.covariance[i][j] * g[j];
            }
        }
        self.var_scale * v.max(0.0).sqrt()
    }

    /// $C_n$ for $n = -2 \dots 2$, log unit$^2$ s$^{-n}$ (may overflow a double for extreme
    /// scales: the parameters do not).
    #[must_use]
    pub(crate) fn coefficients(&self) -> [f64; 5] {
        let mut c = [0.0; 5];
        for (k, n) in EXPONENTS.iter().enumerate() {
            c[k] = self.coefficients[k] * self.var_scale * self.tau_scale.powi(-n);
        }
        c
    }

    /// The parameters $Q, N, B, K, R$ with their uncertainties and resolution.
    #[must_use]
    pub(crate) fn terms(&self) -> [Term; 5] {
        let mut out = [Term::ZERO; 5];
        for (k, n) in EXPONENTS.iter().enumerate() {
            out[k] = term(
                self.coefficients[k],
                self.covariance[k][k].max(0.0).sqrt(),
                PARAMETER_FACTOR[k],
                self.var_scale,
                self.tau_scale.powf(-f64::from(*n) / 2.0),
            );
        }
        out
    }
}

/// The parameter $\sqrt{k c A}\,t$ of a normalized coefficient `c` with uncertainty `u`.
fn term(c: f64, u: f64, k: f64, var_scale: f64, tau_factor: f64) -> Term {
    if c <= 0.0 {
        return Term::ZERO;
    }
    let value = (k * c).sqrt() * var_scale.sqrt() * tau_factor;
    Term {
        value,
        uncertainty: Some(value * u / (2.0 * c)),
        resolution: if c >= 2.0 * u {
            Resolution::Resolved
        } else {
            Resolution::NotSignificant
        },
    }
}

/// The Gauss-Markov alternative: $Q, N, K, R$ and a first-order Gauss-Markov bias.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[non_exhaustive]
pub struct GaussMarkovFit {
    /// Stationary standard deviation $\sigma$, log unit (uncertainty at the fitted $T_c$).
    pub(crate) sigma: Term,
    /// Correlation time $T_c$, s.
    pub(crate) correlation_s: Term,
    /// Quantization, white noise, rate random walk and rate ramp of this model (as
    /// [`PowerFit::terms`], without the flicker floor).
    pub(crate) quantization: Term,
    pub(crate) white: Term,
    pub(crate) rate_random_walk: Term,
    pub(crate) rate_ramp: Term,
    /// Weighted residual sum of squares of this model and of the power-term model.
    pub(crate) rss: f64,
    pub(crate) power_rss: f64,
}

impl GaussMarkovFit {
    /// $\sigma$, log unit.
    #[must_use]
    pub fn sigma(&self) -> Term {
        self.sigma
    }
    /// $T_c$, s.
    #[must_use]
    pub fn correlation_s(&self) -> Term {
        self.correlation_s
    }
    /// $Q$ of this model, log unit times s.
    #[must_use]
    pub fn quantization(&self) -> Term {
        self.quantization
    }
    /// $N$ of this model, log unit per sqrt(Hz).
    #[must_use]
    pub fn white(&self) -> Term {
        self.white
    }
    /// $K$ of this model, log unit times sqrt(Hz).
    #[must_use]
    pub fn rate_random_walk(&self) -> Term {
        self.rate_random_walk
    }
    /// $R$ of this model, log unit per s.
    #[must_use]
    pub fn rate_ramp(&self) -> Term {
        self.rate_ramp
    }
    /// Weighted residual sum of squares of this model (same weights as the power terms').
    #[must_use]
    pub fn rss(&self) -> f64 {
        self.rss
    }
    /// Weighted residual sum of squares of the power-term model with the same weights.
    #[must_use]
    pub fn power_rss(&self) -> f64 {
        self.power_rss
    }
}

fn powers(x: f64) -> [f64; 5] {
    [x.powi(-2), x.powi(-1), 1.0, x, x * x]
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// Weighted non-negative least squares of `y` on the columns of `x` (rows weighted): every
/// subset of columns solved by its normal equations (scaled to unit diagonal, Cholesky); the
/// feasible one with the least residual wins (ties, within $10^{-12}$, to the earlier subset
/// in `order`). Returns coefficients (zero outside the subset), residual, and the inverse
/// normal matrix on the subset (zero elsewhere).
fn nnls<const P: usize>(
    x: &[[f64; P]],
    y: &[f64],
    order: &[Vec<usize>],
) -> Option<([f64; P], f64, [[f64; P]; P])> {
    let mut g = [[0.0; P]; P];
    let mut h = [0.0; P];
    for (row, yi) in x.iter().zip(y) {
        for a in 0..P {
            h[a] += row[a] * yi;
            for b in 0..P {
                g[a][b] += row[a] * row[b];
            }
        }
    }
    let mut best: Option<([f64; P], f64, [[f64; P]; P])> = None;
    for subset in order {
        let p = subset.len();
        if p > x.len() {
            continue;
        }
        let d: Vec<f64> = subset.iter().map(|&j| g[j][j].sqrt()).collect();
        if d.iter().any(|v| !(v.is_finite() && *v > 0.0)) {
            continue;
        }
        let mut a = vec![vec![0.0; p]; p];
        for (i, &ci) in subset.iter().enumerate() {
            for (j, &cj) in subset.iter().enumerate() {
                a[i][j] = g[ci][cj] / (d[i] * d[j]);
            }
        }
        let Some(inv) = invert_spd(&a) else {
            continue;
        };
        let mut coef = [0.0; P];
        let mut ok = true;
        for i in 0..p {
            let z: f64 = (0..p).map(|j| inv[i][j] * h[subset[j]] / d[j]).sum();
            let c = z / d[i];
            if !(c.is_finite() && c >= 0.0) {
                ok = false;
                break;
            }
            coef[subset[i]] = c;
        }
        if !ok {
            continue;
        }
        let rss: f64 = x
            .iter()
            .zip(y)
            .map(|(row, yi)| {
                let r = yi - dot(row, &coef);
                r * r
            })
            .sum();
        let better = match &best {
            None => true,
            Some((_, r, _)) => rss < *r - 1e-12 * r.max(f64::MIN_POSITIVE),
        };
        if better {
            let mut cov = [[0.0; P]; P];
            for i in 0..p {
                for j in 0..p {
                    cov[subset[i]][subset[j]] = inv[i][j] / (d[i] * d[j]);
                }
            }
            best = Some((coef, rss, cov));
        }
    }
    best
}

/// Inverse of a small symmetric positive definite matrix with unit diagonal (Cholesky),
/// `None` when it is numerically singular (a pivot below $10^{-12}$).
#[allow(clippy::needless_range_loop)]
fn invert_spd(a: &[Vec<f64>]) -> Option<Vec<Vec<f64>>> {
    let p = a.len();
    let mut l = vec![vec![0.0; p]; p];
    for i in 0..p {
        for j in 0..=i {
            let s: f64 = a[i][j] - (0..j).map(|k| l[i][k] * l[j][k]).sum::<f64>();
            if i == j {
                if s.is_nan() || s <= 1e-12 {
                    return None;
                }
                l[i][i] = s.sqrt();
            } else {
                l[i][j] = s / l[j][j];
            }
        }
    }
    // inverse of L, then L^-T L^-1
    let mut li = vec![vec![0.0; p]; p];
    for i in 0..p {
        li[i][i] = 1.0 / l[i][i];
        for j in 0..i {
            let s: f64 = (j..i).map(|k| l[i][k] * li[k][j]).sum();
            li[i][j] = -s / l[i][i];
        }
    }
    let mut inv = vec![vec![0.0; p]; p];
    for i in 0..p {
        for j in 0..p {
            inv[i][j] = (i.max(j)..p).map(|k| li[k][i] * li[k][j]).sum();
        }
    }
    Some(inv)
}

/// Subsets of `p` columns, white noise (column `white`) first, then by size.
fn subsets(p: usize, white: usize) -> Vec<Vec<usize>> {
    let mut s: Vec<Vec<usize>> = (1u32..(1 << p))
        .map(|mask| (0..p).filter(|b| mask & (1 << b) != 0).collect())
        .collect();
    s.sort_by_key(|v| (v.len(), !v.contains(&white), v.clone()));
    s
}

/// The normalized problem: cluster times over $T$, variances over $A$, and the weights.
struct Normalized {
    x: Vec<f64>,
    v: Vec<f64>,
    edf: Vec<f64>,
    tau_scale: f64,
    var_scale: f64,
    density: f64,
}

fn normalize(points: &[(f64, f64, f64)]) -> Option<Normalized> {
    let var_scale = points.iter().map(|p| p.1).fold(0.0, f64::max);
    if points.is_empty() || !(var_scale > 0.0 && var_scale.is_finite()) {
        return None;
    }
    let lo = points.iter().map(|p| p.0).fold(f64::INFINITY, f64::min);
    let hi = points.iter().map(|p| p.0).fold(0.0, f64::max);
    let tau_scale = (lo.sqrt()) * (hi.sqrt());
    let octaves = (hi / lo).log2();
    let density = if points.len() > 1 && octaves > 0.0 {
        ((points.len() - 1) as f64 / octaves).max(1.0)
    } else {
        1.0
    };
    Some(Normalized {
        x: points.iter().map(|p| p.0 / tau_scale).collect(),
        v: points.iter().map(|p| p.1 / var_scale).collect(),
        edf: points.iter().map(|p| p.2.max(1e-12)).collect(),
        tau_scale,
        var_scale,
        density,
    })
}

/// Floor of the weights' model relative to the largest variance.
const MODEL_FLOOR: f64 = 1e-30;

/// Row weights $\sqrt{\nu_i/2}/\mathrm{model}_i$.
fn weights(nz: &Normalized, model: &[f64]) -> Vec<f64> {
    nz.edf
        .iter()
        .zip(model)
        .map(|(e, m)| (0.5 * e).sqrt() / m.max(MODEL_FLOOR))
        .collect()
}

/// The variance scale of a covariance: reduced chi-square (when above 1) times the density.
fn inflation(rss: f64, n: usize, p: usize, density: f64) -> f64 {
    let birge = if n > p { rss / (n - p) as f64 } else { 1.0 };
    birge.max(1.0) * density
}

/// Fit the power terms to the points `(tau_s, avar, edf)`.
///
/// Weights are iterated from the measured variances to the fitted ones (up to 20 rounds).
/// Points with zero variance everywhere give a zero fit.
#[must_use]
pub(crate) fn fit_power_terms(points: &[(f64, f64, f64)]) -> PowerFit {
    let zero = |tau_scale: f64, var_scale: f64| PowerFit {
        coefficients: [0.0; 5],
        covariance: [[0.0; 5]; 5],
        var_scale,
        tau_scale,
        model: vec![0.0; points.len()],
        inflation: 1.0,
    };
    let Some(nz) = normalize(points) else {
        return zero(1.0, 0.0);
    };
    let order = subsets(5, 1);
    let mut model: Vec<f64> = nz.v.iter().map(|v| v.max(MODEL_FLOOR)).collect();
    let mut best = zero(nz.tau_scale, nz.var_scale);
    for _round in 0..20 {
        let w = weights(&nz, &model);
        let x: Vec<[f64; 5]> =
            nz.x.iter()
                .zip(&w)
                .map(|(xi, wi)| powers(*xi).map(|p| p * wi))
                .collect();
        let y: Vec<f64> = nz.v.iter().zip(&w).map(|(v, wi)| v * wi).collect();
        let Some((coef, rss, cov)) = nnls(&x, &y, &order) else {
            return best;
        };
        let p = coef.iter().filter(|c| **c > 0.0).count();
        let scale = inflation(rss, x.len(), p, nz.density);
        let new_model: Vec<f64> =
            nz.x.iter()
                .map(|xi| dot(&coef, &powers(*xi)).max(MODEL_FLOOR))
                .collect();
        let converged = new_model
            .iter()
            .zip(&model)
            .all(|(a, b)| (a - b).abs() <= 1e-12 * b.abs());
        best = PowerFit {
            coefficients: coef,
            covariance: cov.map(|r| r.map(|c| c * scale)),
            var_scale: nz.var_scale,
            tau_scale: nz.tau_scale,
            model: model.clone(),
            inflation: scale,
        };
        model = new_model;
        if converged {
            break;
        }
    }
    best
}

/// The columns of the Gauss-Markov model at normalized correlation time `u`: $Q, N, K, R$,
/// Gauss-Markov (the Allan variance of a process of unit variance,
/// [`GaussMarkov::allan_variance`]; NaN for a correlation time that is not finite and
/// positive).
fn gm_row(x: f64, u: f64) -> [f64; 5] {
    let gauss_markov = GaussMarkov::new(1.0, u).map_or(f64::NAN, |g| g.allan_variance(x));
    [x.powi(-2), x.powi(-1), x, x * x, gauss_markov]
}

/// Forty golden-section steps of `f` on `[a, b]`: the last two interior points with their
/// values, `(c, f(c))` and `(d, f(d))`.
fn golden_section(f: &dyn Fn(f64) -> f64, a: f64, b: f64) -> ((f64, f64), (f64, f64)) {
    let (mut a, mut b) = (a, b);
    let phi = 0.5 * (5f64.sqrt() - 1.0);
    let (mut c, mut d) = (b - phi * (b - a), a + phi * (b - a));
    let (mut fc, mut fd) = (f(c), f(d));
    for _ in 0..40 {
        if fc < fd {
            b = d;
            d = c;
            fd = fc;
            c = b - phi * (b - a);
            fc = f(c);
        } else {
            a = c;
            c = d;
            fc = fd;
            d = a + phi * (b - a);
            fd = f(d);
        }
    }
    ((c, fc), (d, fd))
}

/// The Gauss-Markov alternative to `power` (fitted to the same points): $\sigma$ and $T_c$ by
/// a search on $T_c$ with $Q, N, K, R, \sigma^2$ profiled out, with the power fit's weights.
/// `None` when the points are all zero.
#[must_use]
pub(crate) fn fit_gauss_markov(
    points: &[(f64, f64, f64)],
    power: &PowerFit,
) -> Option<GaussMarkovFit> {
    let nz = normalize(points)?;
    let order = subsets(5, 1);
    let w = weights(&nz, &power.model);
    let y: Vec<f64> = nz.v.iter().zip(&w).map(|(v, wi)| v * wi).collect();
    let solve = |log_u: f64| {
        let u = log_u.exp();
        let x: Vec<[f64; 5]> =
            nz.x.iter()
                .zip(&w)
                .map(|(xi, wi)| gm_row(*xi, u).map(|p| p * wi))
                .collect();
        nnls(&x, &y, &order)
    };
    let rss_at = |log_u: f64| solve(log_u).map_or(f64::INFINITY, |s| s.1);
    let power_rss = {
        let x: Vec<[f64; 5]> =
            nz.x.iter()
                .zip(&w)
                .map(|(xi, wi)| powers(*xi).map(|p| p * wi))
                .collect();
        nnls(&x, &y, &subsets(5, 1)).map_or(f64::INFINITY, |s| s.1)
    };
    let lo = nz.x.iter().copied().fold(f64::INFINITY, f64::min).ln() - 10f64.ln();
    let hi = nz.x.iter().copied().fold(0.0, f64::max).ln() + 10f64.ln();
    let grid: Vec<f64> = (0..GM_GRID)
        .map(|i| lo + (hi - lo) * i as f64 / (GM_GRID - 1) as f64)
        .collect();
    let profile: Vec<f64> = grid.iter().map(|g| rss_at(*g)).collect();
    let ib = (0..GM_GRID).fold(0, |b, i| if profile[i] < profile[b] { i } else { b });
    // golden section between the neighbours
    let (left, right) = golden_section(
        &rss_at,
        grid[ib.saturating_sub(1)],
        grid[(ib + 1).min(GM_GRID - 1)],
    );
    let (mut best_log_u, mut best_rss) = (grid[ib], profile[ib]);
    for (l, r) in [left, right] {
        if r < best_rss {
            best_log_u = l;
            best_rss = r;
        }
    }
    let (coef, rss, cov) = solve(best_log_u)?;
    let p = coef.iter().filter(|c| **c > 0.0).count() + 1;
    let scale = inflation(rss, nz.x.len(), p, nz.density);
    // the profile interval: where the residual rises by `scale`
    let threshold = rss + scale;
    let edge = |dir: f64| -> Option<f64> {
        let step = (hi - lo) / (GM_GRID - 1) as f64;
        let mut inside = best_log_u;
        let mut t = best_log_u;
        loop {
            t += dir * step;
            if (dir > 0.0 && t > hi) || (dir < 0.0 && t < lo) {
                return None;
            }
            if rss_at(t) > threshold {
                break;
            }
            inside = t;
        }
        // bisect between inside and t
        let (mut p_in, mut p_out) = (inside, t);
        for _ in 0..30 {
            let mid = 0.5 * (p_in + p_out);
            if rss_at(mid) > threshold {
                p_out = mid;
            } else {
                p_in = mid;
            }
        }
        Some(0.5 * (p_in + p_out))
    };
    let tc = best_log_u.exp() * nz.tau_scale;
    let cov = cov.map(|r| r.map(|c| c * scale));
    let sd = |k: usize| cov[k][k].max(0.0).sqrt();
    let gm_seen = coef[4] > 0.0;
    let (lower, upper) = if gm_seen {
        (edge(-1.0), edge(1.0))
    } else {
        (None, None)
    };
    let tc_u = match (lower, upper) {
        (Some(l), Some(u)) => Some(tc * 0.5 * (u - l)),
        _ => None,
    };
    let step = (hi - lo) / (GM_GRID - 1) as f64;
    let resolution = if !gm_seen {
        Resolution::AtZero
    } else if best_log_u > hi - step || upper.is_none() {
        Resolution::BeyondLog
    } else if best_log_u < lo + step || lower.is_none() {
        Resolution::BelowLog
    } else if coef[4] < 2.0 * sd(4) || tc_u.is_none_or(|u| 2.0 * u > tc) {
        Resolution::NotSignificant
    } else {
        Resolution::Resolved
    };
    let sigma = term(coef[4], sd(4), 1.0, nz.var_scale, 1.0);
    let exps = [-2, -1, 1, 2];
    let factors = [
        PARAMETER_FACTOR[0],
        PARAMETER_FACTOR[1],
        PARAMETER_FACTOR[3],
        PARAMETER_FACTOR[4],
    ];
    let lin: Vec<Term> = (0..4)
        .map(|k| {
            term(
                coef[k],
                sd(k),
                factors[k],
                nz.var_scale,
                nz.tau_scale.powf(-f64::from(exps[k]) / 2.0),
            )
        })
        .collect();
    Some(GaussMarkovFit {
        sigma: Term {
            resolution: if gm_seen {
                resolution
            } else {
                Resolution::AtZero
            },
            ..sigma
        },
        correlation_s: Term {
            value: if gm_seen { tc } else { 0.0 },
            uncertainty: if gm_seen { tc_u } else { None },
            resolution,
        },
        quantization: lin[0],
        white: lin[1],
        rate_random_walk: lin[2],
        rate_ramp: lin[3],
        rss,
        power_rss,
    })
}
