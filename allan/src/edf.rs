//! Equivalent degrees of freedom of the Allan variance estimator at one cluster time.
//!
//! The estimator at cluster $m$ and stride $s$ (see [`crate::StreamingAllan`]) is a quadratic
//! form $A = \frac{1}{2 m^2 M} \sum_{i=0}^{M-1} d_{is}^2$ of Gaussian second differences
//! $d_t = x_{t+2m} - 2x_{t+m} + x_t$ of the phase (the integrated log). Its equivalent
//! degrees of freedom are Satterthwaite's
//! $$\nu = \frac{2\,\mathrm E(A)^2}{\operatorname{Var}(A)},$$
//! so that $\nu A / \sigma^2$ is approximately $\chi^2_\nu$. With $S = m/s$ evaluations per
//! cluster time (the stride factor: $S = m$ fully overlapping, $S = 1$ not overlapping) and
//! the autocovariance of $d$ at a lag of $t$ cluster times written $s_z(t)$,
//! $$\frac{1}{\nu} = \frac{1}{s_z(0)^2\, M}\Big[s_z(0)^2 + \big(1 - \tfrac JM\big)\,
//! s_z(J/S)^2 + 2\sum_{j=1}^{J-1}\big(1 - \tfrac jM\big)\, s_z(j/S)^2\Big],\qquad
//! J = \min(M, 3S),$$
//! the "basic sum" of C. A. Greenhall and W. J. Riley, *Uncertainty of stability variances
//! based on finite differences*, Proc. 35th PTTI (2003), eq (10), with
//! $s_z(t) = 6 s_x(t) - 4 s_x(t-1) - 4 s_x(t+1) + s_x(t-2) + s_x(t+2)$ (their eq (9), $d = 2$)
//! and $s_x$ the generalized autocovariance of the phase for the power law:
//! $-|t|$ (white), $t^2 \ln|t|$ (flicker), $|t|^3$ (random walk). This is their
//! algorithm with the phase taken as point samples of the integrated rate ($F = \infty$ in
//! their notation), exact for logs whose samples are averages of the rate over the sample
//! interval (an integrating gyro or accelerometer); it is evaluated in full at every $J$
//! (no table approximation of large $J$). For white, quantization and random-walk noise $s_z$
//! vanishes beyond lag 2 and the sum is exact; for flicker noise the tail beyond lag 3 is
//! left out as in Greenhall and Riley.
//!
//! Quantization noise (white noise of the phase samples) is discrete: the second differences
//! correlate only at lags $0, m, 2m$ (covariances $6, -4, 1$), so
//! $$\frac 1\nu = \frac{36 M + 32 \max(M - S, 0) + 2 \max(M - 2S, 0)}{36 M^2},$$
//! which is Greenhall and Riley's case 4 ($1/\nu = (35/18 - S/M)/M$ for $M > 2S$) extended to
//! $M \le 2S$.

use crate::noise::PowerLaw;

/// The number of terms $M = \lfloor (N - 2m)/s \rfloor + 1$ of the estimator at cluster `m`
/// and stride `stride` over `samples` samples (0 when $N < 2m$).
#[must_use]
pub fn terms(samples: u64, m: u64, stride: u64) -> u64 {
    match samples.checked_sub(2 * m) {
        Some(rest) if stride > 0 => rest / stride + 1,
        _ => 0,
    }
}

/// Generalized autocovariance of the phase at a lag of `t` cluster times ($s_x$).
fn sx(noise: PowerLaw, t: f64) -> f64 {
    let a = t.abs();
    match noise {
        PowerLaw::White => -a,
        PowerLaw::Flicker => {
            if a == 0.0 {
                0.0
            } else {
                a * a * a.ln()
            }
        }
        PowerLaw::RandomWalk => a * a * a,
        // not used: quantization has the discrete closed form
        PowerLaw::Quantization => {
            if a == 0.0 {
                1.0
            } else {
                0.0
            }
        }
    }
}

/// Autocovariance of the second differences at a lag of `t` cluster times ($s_z$, $d = 2$).
fn sz(noise: PowerLaw, t: f64) -> f64 {
    6.0 * sx(noise, t) - 4.0 * sx(noise, t - 1.0) - 4.0 * sx(noise, t + 1.0)
        + sx(noise, t - 2.0)
        + sx(noise, t + 2.0)
}

/// Equivalent degrees of freedom $\nu$ of the Allan variance at cluster `m` (samples), stride
/// `stride` (samples; a divisor of `m`) over `samples` samples, for the power law `noise`.
/// Returns 0 when the estimator has no term ($N < 2m$).
#[must_use]
pub fn edf(noise: PowerLaw, samples: u64, m: u64, stride: u64) -> f64 {
    let terms = terms(samples, m, stride);
    if terms == 0 || m == 0 {
        return 0.0;
    }
    let big_m = terms as f64;
    let s_factor = (m / stride.max(1)).max(1);
    let s = s_factor as f64;
    if noise == PowerLaw::Quantization {
        let inv = (36.0 * big_m + 32.0 * (big_m - s).max(0.0) + 2.0 * (big_m - 2.0 * s).max(0.0))
            / (36.0 * big_m * big_m);
        return 1.0 / inv;
    }
    let j_max = terms.min(3 * s_factor);
    let z0 = sz(noise, 0.0);
    let mut sum = z0 * z0;
    let zj = sz(noise, j_max as f64 / s);
    sum += (1.0 - j_max as f64 / big_m) * zj * zj;
    for j in 1..j_max {
        let z = sz(noise, j as f64 / s);
        sum += 2.0 * (1.0 - j as f64 / big_m) * z * z;
    }
    z0 * z0 * big_m / sum
}
