//! Chi-squared quantiles for real degrees of freedom, and the confidence interval of a
//! deviation from its equivalent degrees of freedom.
//!
//! The interval of a deviation $\hat\sigma$ with $\nu$ degrees of freedom at confidence $c$ is
//! $$\Big[\hat\sigma \sqrt{\nu / \chi^2_{\nu}(1 - p)},\ \hat\sigma \sqrt{\nu / \chi^2_{\nu}(p)}\Big],
//! \qquad p = (1 - c)/2$$
//! (NIST SP 1065, eq 45). The quantiles invert the regularized incomplete gamma functions
//! $P(a, x)$ and $Q(a, x)$ ($a = \nu/2$, $x = \chi^2/2$): a series below $x = a + 1$, a
//! continued fraction above (Numerical Recipes, §6.2), with the prefactor
//! $x^a e^{-x}/\Gamma(a+1)$ computed as $\exp\{a[\ln(1+u) - u] - \tfrac12\ln(2\pi a) - c(a)\}$,
//! $u = x/a - 1$, $c$ Stirling's correction, so that it keeps full precision for the
//! $\nu \sim 10^8$ of a long log; safeguarded Newton steps from the Wilson-Hilferty start.

/// $\operatorname{erf}(1/\sqrt2)$: the confidence of a one-sigma interval.
pub const ONE_SIGMA: f64 = 0.682_689_492_137_085_9;

/// $\ln\Gamma(x)$ for $x > 0$ (Lanczos, $g = 7$, 9 terms; relative error about $10^{-15}$).
#[must_use]
pub fn ln_gamma(x: f64) -> f64 {
    const G: f64 = 7.0;
    const C: [f64; 9] = [
        0.999_999_999_999_809_9,
        676.520_368_121_885_1,
        -1_259.139_216_722_402_8,
        771.323_428_777_653_1,
        -176.615_029_162_140_6,
        12.507_343_278_686_905,
        -0.138_571_095_265_720_12,
        9.984_369_578_019_572e-6,
        1.505_632_735_149_311_6e-7,
    ];
    if x < 0.5 {
        // reflection
        let pi = std::f64::consts::PI;
        return (pi / (pi * x).sin()).ln() - ln_gamma(1.0 - x);
    }
    let x = x - 1.0;
    let mut a = C[0];
    let t = x + G + 0.5;
    for (i, c) in C.iter().enumerate().skip(1) {
        a += c / (x + i as f64);
    }
    0.5 * (2.0 * std::f64::consts::PI).ln() + (x + 0.5) * t.ln() - t + a.ln()
}

/// $\ln(1 + u) - u$ without cancellation for small $u$.
fn log1pmx(u: f64) -> f64 {
    if u.abs() < 0.1 {
        // -u^2/2 + u^3/3 - u^4/4 + ...
        let mut term = u;
        let mut sum = 0.0;
        let mut k = 2.0;
        loop {
            term *= -u;
            let add = term / k;
            sum += add;
            if add.abs() <= 1e-17 * sum.abs() {
                break;
            }
            k += 1.0;
        }
        sum
    } else {
        u.ln_1p() - u
    }
}

/// $\ln\big(x^a e^{-x} / \Gamma(a + 1)\big)$.
fn ln_prefactor(a: f64, x: f64) -> f64 {
    if a < 10.0 {
        return a * x.ln() - x - ln_gamma(a + 1.0);
    }
    let ia = 1.0 / a;
    let ia2 = ia * ia;
    // Stirling: ln Gamma(a+1) = a ln a - a + ln(2 pi a)/2 + c(a)
    let c = ia
        * (1.0 / 12.0
            - ia2 * (1.0 / 360.0 - ia2 * (1.0 / 1260.0 - ia2 * (1.0 / 1680.0 - ia2 / 1188.0))));
    a * log1pmx((x - a) / a) - 0.5 * (2.0 * std::f64::consts::PI * a).ln() - c
}

/// Regularized incomplete gamma functions $(P(a, x), Q(a, x))$, $a > 0$, $x \ge 0$.
#[must_use]
pub fn gamma_pq(a: f64, x: f64) -> (f64, f64) {
    if x <= 0.0 {
        return (0.0, 1.0);
    }
    let ln_d = ln_prefactor(a, x);
    if x < a + 1.0 {
        // P = D * sum_n x^n / ((a+1)...(a+n))
        let mut term = 1.0;
        let mut sum = 1.0;
        let mut n = 1.0;
        while n < 1e9 {
            term *= x / (a + n);
            sum += term;
            if term < sum * 1e-17 {
                break;
            }
            n += 1.0;
        }
        let p = (ln_d + sum.ln()).exp().min(1.0);
        (p, 1.0 - p)
    } else {
        // Q = D * a * CF (modified Lentz)
        const TINY: f64 = 1e-300;
        let mut b = x + 1.0 - a;
        let mut c = 1.0 / TINY;
        let mut d = 1.0 / b;
        let mut h = d;
        let mut i = 1.0;
        while i < 1e9 {
            let an = -i * (i - a);
            b += 2.0;
            d = an * d + b;
            if d.abs() < TINY {
                d = TINY;
            }
            c = b + an / c;
            if c.abs() < TINY {
                c = TINY;
            }
            d = 1.0 / d;
            let del = d * c;
            h *= del;
            if (del - 1.0).abs() < 1e-16 {
                break;
            }
            i += 1.0;
        }
        let q = (ln_d + (a * h).ln()).exp().min(1.0);
        (1.0 - q, q)
    }
}

/// The standard normal quantile (Acklam's rational approximation, relative error about
/// $10^{-9}$: a starting value only).
fn normal_quantile(p: f64) -> f64 {
    const A: [f64; 6] = [
        -3.969_683_028_665_376e1,
        2.209_460_984_245_205e2,
        -2.759_285_104_469_687e2,
        1.383_577_518_672_69e2,
        -3.066_479_806_614_716e1,
        2.506_628_277_459_239,
    ];
    const B: [f64; 5] = [
        -5.447_609_879_822_406e1,
        1.615_858_368_580_409e2,
        -1.556_989_798_598_866e2,
        6.680_131_188_771_972e1,
        -1.328_068_155_288_572e1,
    ];
    const C: [f64; 6] = [
        -7.784_894_002_430_293e-3,
        -3.223_964_580_411_365e-1,
        -2.400_758_277_161_838,
        -2.549_732_539_343_734,
        4.374_664_141_464_968,
        2.938_163_982_698_783,
    ];
    const D: [f64; 4] = [
        7.784_695_709_041_462e-3,
        3.224_671_290_700_398e-1,
        2.445_134_137_142_996,
        3.754_408_661_907_416,
    ];
    let lo = 0.024_25;
    if p < lo {
        let q = (-2.0 * p.ln()).sqrt();
        (((((C[0] * q + C[1]) * q + C[2]) * q + C[3]) * q + C[4]) * q + C[5])
            / ((((D[0] * q + D[1]) * q + D[2]) * q + D[3]) * q + 1.0)
    } else if p <= 1.0 - lo {
        let q = p - 0.5;
        let r = q * q;
        (((((A[0] * r + A[1]) * r + A[2]) * r + A[3]) * r + A[4]) * r + A[5]) * q
            / (((((B[0] * r + B[1]) * r + B[2]) * r + B[3]) * r + B[4]) * r + 1.0)
    } else {
        -normal_quantile(1.0 - p)
    }
}

/// The $x$ with $P(a, x) = p$ (`upper` false) or $Q(a, x) = p$ (`upper` true), $0 < p < 1$.
fn gamma_quantile(a: f64, p: f64, upper: bool) -> f64 {
    let f = |x: f64| {
        let (pp, qq) = gamma_pq(a, x);
        if upper { p - qq } else { pp - p }
    };
    // increasing in x either way
    let z = normal_quantile(if upper { 1.0 - p } else { p });
    let wh = a * (1.0 - 1.0 / (9.0 * a) + z / (3.0 * a.sqrt())).powi(3);
    let mut x = if wh > 0.0 {
        wh
    } else {
        // small x: P ~ x^a / Gamma(a + 1)
        let pl = if upper { 1.0 - p } else { p };
        ((pl.ln() + ln_gamma(a + 1.0)) / a).exp()
    };
    if !(x.is_finite() && x > 0.0) {
        x = a.max(1e-3);
    }
    // bracket
    let (mut lo, mut hi) = (x, x);
    let mut guard = 0;
    while f(lo) > 0.0 && guard < 2000 {
        lo *= 0.5;
        guard += 1;
    }
    guard = 0;
    while f(hi) < 0.0 && guard < 2000 {
        hi *= 2.0;
        guard += 1;
    }
    for _ in 0..200 {
        let fx = f(x);
        if fx == 0.0 {
            return x;
        }
        if fx < 0.0 {
            lo = x;
        } else {
            hi = x;
        }
        // density dP/dx = x^(a-1) e^-x / Gamma(a) = exp(ln_prefactor) * a / x
        let dens = (ln_prefactor(a, x)).exp() * a / x;
        let mut next = x - fx / dens;
        if !(next.is_finite() && next > lo && next < hi) {
            next = if lo > 0.0 { (lo * hi).sqrt() } else { 0.5 * hi };
        }
        if (next - x).abs() <= 4.0 * f64::EPSILON * x || hi - lo <= 4.0 * f64::EPSILON * hi {
            return next;
        }
        x = next;
    }
    x
}

/// The quantile of the chi-squared distribution with `nu` (> 0, real) degrees of freedom:
/// the $x$ with $\Pr[\chi^2_\nu \le x] = p$, $0 < p < 1$.
#[must_use]
pub fn chi2_quantile(nu: f64, p: f64) -> f64 {
    if p <= 0.5 {
        2.0 * gamma_quantile(0.5 * nu, p, false)
    } else {
        2.0 * gamma_quantile(0.5 * nu, 1.0 - p, true)
    }
}

/// The confidence interval `(lower, upper)` of a deviation `dev` with `edf` equivalent degrees
/// of freedom at confidence `confidence` in (0, 1) (NIST SP 1065 eq 45). A zero deviation has
/// the interval (0, 0).
#[must_use]
pub fn interval(dev: f64, edf: f64, confidence: f64) -> (f64, f64) {
    if dev == 0.0 {
        return (0.0, 0.0);
    }
    let p = 0.5 * (1.0 - confidence);
    let lo_q = 2.0 * gamma_quantile(0.5 * edf, p, false);
    let hi_q = 2.0 * gamma_quantile(0.5 * edf, p, true);
    (dev * (edf / hi_q).sqrt(), dev * (edf / lo_q).sqrt())
}
