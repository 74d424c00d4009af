//! The distributions the budget and the decision rules need: the standard normal distribution
//! function and its quantile, Student's $t$ distribution function and quantile for real
//! degrees of freedom, the regularized incomplete beta function and its quantile, and an
//! adaptive Gauss-Legendre quadrature.
//!
//! - $\Phi(x) = 1 - \tfrac12 Q(\tfrac12, x^2/2)$ for $x \ge 0$ (and $\tfrac12 Q$ for $x < 0$),
//!   with $Q$ the regularized upper incomplete gamma function of [`allan::chi2::gamma_pq`]
//!   (full precision in both tails).
//! - $\Phi^{-1}(p)$: Abramowitz and Stegun 26.2.23 (absolute error below $4.5\cdot10^{-4}$) as
//!   the start, then Halley steps on $\Phi$ to the last bit.
//! - $t$: the tail $\Pr(T > t) = \tfrac12 I_{\nu/(\nu + t^2)}(\nu/2, 1/2)$ (Abramowitz and
//!   Stegun 26.7.1, 26.5.27), the incomplete beta function by its continued fraction (modified
//!   Lentz); the quantile by safeguarded Newton steps on the tail, $\nu = 1$ and $\nu = 2$ in
//!   closed form, and for $\nu \ge 10^5$ (and $\nu = \infty$) the Cornish-Fisher expansion
//!   (A&S 26.7.5) to $\nu^{-4}$, whose error there is below $10^{-15}$.
//!
//! # Reference
//! M. Abramowitz, I. A. Stegun, *Handbook of Mathematical Functions*, NBS AMS 55 (1964),
//! 26.2.23, 26.5.8, 26.5.27, 26.7.1, 26.7.5; W. H. Press et al., *Numerical Recipes*, 3rd ed.
//! (2007), §6.4 (continued fraction of the incomplete beta function).

use allan::chi2::{gamma_pq, ln_gamma};
use std::f64::consts::PI;

/// The standard normal distribution function $\Phi(x)$.
///
/// ```
/// use approx::assert_relative_eq;
/// assert_relative_eq!(metrology::special::normal_cdf(1.959_963_984_540_054), 0.975, epsilon = 1e-15);
/// assert_relative_eq!(metrology::special::normal_cdf(-10.0), 7.619_853_024_160_527e-24, max_relative = 1e-13);
/// ```
#[must_use]
pub fn normal_cdf(x: f64) -> f64 {
    if x.is_nan() {
        return f64::NAN;
    }
    if x.abs() > 40.0 {
        return if x > 0.0 { 1.0 } else { 0.0 };
    }
    let half_q = 0.5 * gamma_pq(0.5, 0.5 * x * x).1;
    if x < 0.0 { half_q } else { 1.0 - half_q }
}

/// The standard normal density $\varphi(x)$.
#[must_use]
pub(crate) fn normal_pdf(x: f64) -> f64 {
    (-0.5 * x * x).exp() / (2.0 * PI).sqrt()
}

/// The standard normal quantile $\Phi^{-1}(p)$, $0 < p < 1$ (NaN outside).
///
/// ```
/// use approx::assert_relative_eq;
/// assert_relative_eq!(metrology::special::normal_quantile(0.975), 1.959_963_984_540_054, max_relative = 1e-15);
/// ```
#[must_use]
pub fn normal_quantile(p: f64) -> f64 {
    if !(p > 0.0 && p < 1.0) {
        return f64::NAN;
    }
    // lower tail probability and the sign of the answer
    let (pl, sign) = if p < 0.5 { (p, -1.0) } else { (1.0 - p, 1.0) };
    if pl >= 0.5 {
        return 0.0;
    }
    let t = (-2.0 * pl.ln()).sqrt();
    // A&S 26.2.23: the upper quantile of pl, as a negative lower quantile y
    let mut y = -(t
        - (2.515_517 + t * (0.802_853 + t * 0.010_328))
            / (1.0 + t * (1.432_788 + t * (0.189_269 + t * 0.001_308))));
    for _ in 0..8 {
        let e = normal_cdf(y) - pl;
        let u = e / normal_pdf(y);
        let step = u / (1.0 + 0.5 * y * u);
        y -= step;
        if step.abs() <= 2.0 * f64::EPSILON * y.abs() {
            break;
        }
    }
    -sign * y
}

/// $\ln\Gamma(a + \tfrac12) - \ln\Gamma(a)$ without the cancellation of two large logarithms.
fn ln_gamma_half_ratio(a: f64) -> f64 {
    if a < 10.0 {
        return ln_gamma(a + 0.5) - ln_gamma(a);
    }
    // Stirling: ln Gamma(z) = (z - 1/2) ln z - z + ln(2 pi)/2 + s(z)
    let s = |z: f64| {
        let iz = 1.0 / z;
        let iz2 = iz * iz;
        iz * (1.0 / 12.0 - iz2 * (1.0 / 360.0 - iz2 * (1.0 / 1260.0 - iz2 / 1680.0)))
    };
    0.5 * a.ln() + a * (0.5 / a).ln_1p() - 0.5 + s(a + 0.5) - s(a)
}

/// The continued fraction of the incomplete beta function (Numerical Recipes §6.4, modified
/// Lentz): $I_x(a, b) = x^a (1-x)^b / (a B(a, b)) \cdot$ `beta_cf(a, b, x)`.
fn beta_cf(a: f64, b: f64, x: f64) -> f64 {
    const TINY: f64 = 1e-300;
    let guard = |v: f64| if v.abs() < TINY { TINY } else { v };
    let (qab, qap, qam) = (a + b, a + 1.0, a - 1.0);
    let mut c = 1.0;
    let mut d = 1.0 / guard(1.0 - qab * x / qap);
    let mut h = d;
    for m in 1..100_000 {
        let m = f64::from(m);
        let m2 = 2.0 * m;
        // the even and the odd step of the fraction: d_k = 1/(1 + a_k d_{k-1}), c_k = 1 + a_k/c_{k-1}
        let even = m * (b - m) * x / ((qam + m2) * (a + m2));
        let odd = -(a + m) * (qab + m) * x / ((a + m2) * (qap + m2));
        let mut del = 1.0;
        for coef in [even, odd] {
            d = 1.0 / guard(1.0 + coef * d);
            c = guard(1.0 + coef / c);
            del = d * c;
            h *= del;
        }
        if (del - 1.0).abs() < 1e-16 {
            break;
        }
    }
    h
}

/// $I_x(a, b)$ given $\ln[x^a (1-x)^b / B(a, b)]$ (`ln_front`), $x$ and $y = 1 - x$.
fn inc_beta_with_front(a: f64, b: f64, x: f64, y: f64, ln_front: f64) -> f64 {
    if x <= 0.0 {
        return 0.0;
    }
    if y <= 0.0 {
        return 1.0;
    }
    if x < (a + 1.0) / (a + b + 2.0) {
        (ln_front.exp() * beta_cf(a, b, x) / a).min(1.0)
    } else {
        (1.0 - ln_front.exp() * beta_cf(b, a, y) / b).max(0.0)
    }
}

/// The regularized incomplete beta function $I_x(a, b)$, $a, b > 0$, $0 \le x \le 1$.
///
/// ```
/// use approx::assert_relative_eq;
/// // I_x(1, 1) = x; I_x(2, 1) = x^2
/// assert_relative_eq!(metrology::special::inc_beta(1.0, 1.0, 0.3), 0.3, epsilon = 1e-15);
/// assert_relative_eq!(metrology::special::inc_beta(2.0, 1.0, 0.3), 0.09, epsilon = 1e-15);
/// ```
#[must_use]
pub fn inc_beta(a: f64, b: f64, x: f64) -> f64 {
    if x <= 0.0 {
        return 0.0;
    }
    if x >= 1.0 {
        return 1.0;
    }
    let y = 1.0 - x;
    let ln_front = ln_gamma(a + b) - ln_gamma(a) - ln_gamma(b) + a * x.ln() + b * y.ln();
    inc_beta_with_front(a, b, x, y, ln_front)
}

/// The $x$ with $I_x(a, b) = p$, $0 \le p \le 1$ (bisection to the last bit).
#[must_use]
pub fn beta_quantile(a: f64, b: f64, p: f64) -> f64 {
    if p <= 0.0 {
        return 0.0;
    }
    if p >= 1.0 {
        return 1.0;
    }
    let (mut lo, mut hi) = (0.0_f64, 1.0_f64);
    for _ in 0..1100 {
        let mid = 0.5 * (lo + hi);
        if mid <= lo || mid >= hi {
            break;
        }
        if inc_beta(a, b, mid) < p {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

/// $\Pr(T_\nu > t)$ for $t \ge 0$.
fn t_upper_tail(t: f64, nu: f64) -> f64 {
    if t <= 0.0 {
        return 0.5;
    }
    if t.is_infinite() {
        return 0.0;
    }
    let t2 = t * t;
    let x = nu / (nu + t2);
    let y = t2 / (nu + t2);
    let a = 0.5 * nu;
    let ln_x = if y < 0.5 { (-y).ln_1p() } else { x.ln() };
    let ln_front = ln_gamma_half_ratio(a) - 0.5 * PI.ln() + a * ln_x + 0.5 * y.ln();
    0.5 * inc_beta_with_front(a, 0.5, x, y, ln_front)
}

/// The density of Student's $t$ with $\nu$ degrees of freedom.
fn t_pdf(t: f64, nu: f64) -> f64 {
    (ln_gamma_half_ratio(0.5 * nu) - 0.5 * (nu * PI).ln() - 0.5 * (nu + 1.0) * (t * t / nu).ln_1p())
        .exp()
}

/// Student's $t$ distribution function $\Pr(T_\nu \le t)$, $\nu > 0$ (real; infinite: the
/// normal).
///
/// ```
/// use approx::assert_relative_eq;
/// // one degree of freedom: the Cauchy distribution, 1/2 + atan(t)/pi
/// assert_relative_eq!(metrology::special::student_t_cdf(3.0, 1.0), 0.5 + 3.0_f64.atan() / std::f64::consts::PI, epsilon = 1e-15);
/// ```
#[must_use]
pub fn student_t_cdf(t: f64, nu: f64) -> f64 {
    if t.is_nan() || nu.is_nan() || nu <= 0.0 {
        return f64::NAN;
    }
    if nu.is_infinite() {
        return normal_cdf(t);
    }
    if t >= 0.0 {
        1.0 - t_upper_tail(t, nu)
    } else {
        t_upper_tail(-t, nu)
    }
}

/// Cornish-Fisher expansion of the $t$ quantile about the normal quantile $z$ (A&S 26.7.5).
fn t_cornish_fisher(z: f64, nu: f64) -> f64 {
    let z2 = z * z;
    let g1 = z * (z2 + 1.0) / 4.0;
    let g2 = z * ((5.0 * z2 + 16.0) * z2 + 3.0) / 96.0;
    let g3 = z * (((3.0 * z2 + 19.0) * z2 + 17.0) * z2 - 15.0) / 384.0;
    let g4 = z * ((((79.0 * z2 + 776.0) * z2 + 1482.0) * z2 - 1920.0) * z2 - 945.0) / 92_160.0;
    z + (g1 + (g2 + (g3 + g4 / nu) / nu) / nu) / nu
}

/// Student's $t$ quantile: the $t$ with $\Pr(T_\nu \le t) = p$, $0 < p < 1$, $\nu > 0$ real or
/// infinite (the normal quantile). NaN outside.
///
/// ```
/// use approx::assert_relative_eq;
/// // the 97.5 % point for 10 degrees of freedom (tables: 2.228)
/// assert_relative_eq!(metrology::special::student_t_quantile(0.975, 10.0), 2.228_138_851_986_274, max_relative = 1e-13);
/// ```
#[must_use]
pub fn student_t_quantile(p: f64, nu: f64) -> f64 {
    if !(p > 0.0 && p < 1.0) || nu.is_nan() || nu <= 0.0 {
        return f64::NAN;
    }
    if nu.is_infinite() {
        return normal_quantile(p);
    }
    // upper tail probability q < 1/2 and the sign
    let (q, sign) = if p > 0.5 { (1.0 - p, 1.0) } else { (p, -1.0) };
    if q >= 0.5 {
        return 0.0;
    }
    let t = if (nu - 1.0).abs() < f64::EPSILON {
        1.0 / (PI * q).tan()
    } else if (nu - 2.0).abs() < f64::EPSILON {
        // F(t) = 1/2 + t / (2 sqrt(2 + t^2)): t = (1 - 2q) / sqrt(2 q (1 - q))
        (1.0 - 2.0 * q) / (2.0 * q * (1.0 - q)).sqrt()
    } else if nu >= 1e5 {
        t_cornish_fisher(normal_quantile(1.0 - q), nu)
    } else {
        t_solve_tail(q, nu)
    };
    sign * t
}

/// The $t > 0$ with $\Pr(T_\nu > t) = q$, $0 < q < 1/2$: bracket, then Newton steps kept
/// inside the bracket (bisection where a step leaves it).
fn t_solve_tail(q: f64, nu: f64) -> f64 {
    let start = t_cornish_fisher(normal_quantile(1.0 - q), nu.max(1.0)).max(1e-3);
    let (mut lo, mut hi) = (0.0, start);
    while t_upper_tail(hi, nu) > q {
        lo = hi;
        hi *= 2.0;
        if hi.is_infinite() {
            return f64::INFINITY;
        }
    }
    let mut t = start.clamp(lo, hi);
    for _ in 0..200 {
        let f = t_upper_tail(t, nu) - q; // decreasing in t
        if f > 0.0 {
            lo = t;
        } else if f < 0.0 {
            hi = t;
        } else {
            return t;
        }
        let mut next = t + f / t_pdf(t, nu);
        if !(next > lo && next < hi) {
            next = 0.5 * (lo + hi);
        }
        if (next - t).abs() <= 4.0 * f64::EPSILON * t || hi - lo <= 4.0 * f64::EPSILON * hi {
            return next;
        }
        t = next;
    }
    t
}

/// Nodes and weights of the `n`-point Gauss-Legendre rule on $[-1, 1]$ (Newton on
/// $P_n$ from Chebyshev starts).
fn gauss_legendre(n: usize) -> Vec<(f64, f64)> {
    let nf = n as f64;
    let mut rule = Vec::with_capacity(n);
    for i in 0..n {
        let mut x = (PI * (i as f64 + 0.75) / (nf + 0.5)).cos();
        let mut dp = 1.0;
        for _ in 0..100 {
            // P_n(x) and P_n'(x) by the three-term recurrence
            let (mut p0, mut p1) = (1.0, x);
            for k in 2..=n {
                let kf = k as f64;
                let p2 = ((2.0 * kf - 1.0) * x * p1 - (kf - 1.0) * p0) / kf;
                p0 = p1;
                p1 = p2;
            }
            dp = nf * (x * p1 - p0) / (x * x - 1.0);
            let dx = p1 / dp;
            x -= dx;
            if dx.abs() < 1e-16 {
                break;
            }
        }
        rule.push((x, 2.0 / ((1.0 - x * x) * dp * dp)));
    }
    rule
}

/// Adaptive Gauss-Legendre quadrature of `f` over $[a, b]$: a panel is accepted when its 10-
/// and 20-point rules agree to `tol` (absolute), else halved (depth at most 40).
pub(crate) fn integrate(f: &dyn Fn(f64) -> f64, a: f64, b: f64, tol: f64) -> f64 {
    let g10 = gauss_legendre(10);
    let g20 = gauss_legendre(20);
    let rule = |r: &[(f64, f64)], a: f64, b: f64| {
        let (m, h) = (0.5 * (a + b), 0.5 * (b - a));
        h * r.iter().map(|&(x, w)| w * f(m + h * x)).sum::<f64>()
    };
    let mut total = 0.0;
    let mut stack = vec![(a, b, 0u32)];
    while let Some((lo, hi, depth)) = stack.pop() {
        let coarse = rule(&g10, lo, hi);
        let fine = rule(&g20, lo, hi);
        if (fine - coarse).abs() <= tol || depth >= 40 {
            total += fine;
        } else {
            let mid = 0.5 * (lo + hi);
            stack.push((lo, mid, depth + 1));
            stack.push((mid, hi, depth + 1));
        }
    }
    total
}
