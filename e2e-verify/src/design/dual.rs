//! Screening solver for one candidate schedule: the dual of the direct allocation, maximised
//! by pairwise Frank-Wolfe steps from the current schedule's multipliers, giving rigorous
//! lower and upper bounds on its $J$ (never the reported value: that comes from the shared
//! core).
//!
//! # Formula
//! With normalised rows $\mathbf a_r \ge 0$ ($|M_r|/\omega_m$) and every lower bound zero,
//! the direct allocation's dual over the simplex $\sum_r \mu_r = 1$ is
//! $$J = \max_{\mu \in \Delta} G(\mu)^3,\qquad G(\mu) = \sum_j \big(w_j c_j(\mu)\big)^{2/3},
//! \quad c_j(\mu) = \sum_r \mu_r a_{rj}$$
//! ($G$ is concave; strong duality holds since a small $\mathbf x$ is strictly feasible).
//! Every $\mu \in \Delta$ gives the lower bound $G(\mu)^3$; concavity gives
//! $G^* \le G(\mu) + \max_r \nabla_r G - \mu\cdot\nabla G$ (the Frank-Wolfe gap), an upper
//! bound. A pairwise step moves weight from the support row with the smallest gradient to
//! the row with the largest, with an exact line search (bisection on the monotone
//! derivative).

/// Pairwise Frank-Wolfe iterations at most per schedule.
pub(crate) const MAX_ITERATIONS: usize = 200;

/// Safeguarded Newton steps of the line search (bisection when Newton leaves the bracket).
const LINE_STEPS: usize = 30;

/// The line search stops when the bracket is this narrow relative to the step bound.
const LINE_TOL_REL: f64 = 1e-6;

/// Stop when the relative gap $(\mathrm{upper} - \mathrm{lower})/\mathrm{upper}$ is below
/// this (far below [`super::IMPROVEMENT_REL`]).
const GAP_REL: f64 = 1e-9;

/// Smallest $c_j$ used in the gradient $\propto c_j^{-1/3}$ (a variable no support row
/// touches then pulls every row that involves it to the top).
const C_FLOOR: f64 = 1e-300;

/// Bounds on $J$ (rad$^{-2}$) of the rows `rows` ($R \times m$): (lower, upper).
/// `mu0` is the warm start (row, weight $\ge 0$); the iteration stops early once
/// `lower >= stop_above` or `upper < stop_below`.
pub(crate) fn bounds(
    weights: &[f64],
    rows: &[f64],
    m: usize,
    mu0: &[(usize, f64)],
    stop_above: f64,
    stop_below: f64,
) -> (f64, f64) {
    let n_rows = rows.len() / m;
    if n_rows == 0 {
        return (0.0, f64::INFINITY);
    }
    // x^(2/3) = cbrt(x)^2 and x^(-1/3) = 1/cbrt(x): cube roots are several times cheaper
    // than `powf`, which dominated the screening
    let w23: Vec<f64> = weights.iter().map(|w| w.cbrt().powi(2)).collect();
    let mut mu = vec![0.0; n_rows];
    let total: f64 = mu0.iter().map(|t| t.1.max(0.0)).sum();
    if total > 0.0 {
        for &(r, v) in mu0 {
            mu[r] += v.max(0.0) / total;
        }
    } else {
        mu[0] = 1.0;
    }
    let mut c = vec![0.0; m];
    for (r, &v) in mu.iter().enumerate() {
        if v > 0.0 {
            for (cj, a) in c.iter_mut().zip(&rows[r * m..(r + 1) * m]) {
                *cj += v * a;
            }
        }
    }
    let g_of = |c: &[f64]| -> f64 {
        c.iter()
            .zip(&w23)
            .map(|(c, w)| w * c.max(0.0).cbrt().powi(2))
            .sum()
    };
    let (mut lower, mut upper): (f64, f64) = (0.0, f64::INFINITY);
    let mut grad = vec![0.0; n_rows];
    for _ in 0..MAX_ITERATIONS {
        let g = g_of(&c);
        // d G / d c_j = (2/3) w_j^{2/3} c_j^{-1/3}
        let dc: Vec<f64> = c
            .iter()
            .zip(&w23)
            .map(|(c, w)| (2.0 / 3.0) * w / c.max(C_FLOOR).cbrt())
            .collect();
        for (r, gr) in grad.iter_mut().enumerate() {
            *gr = rows[r * m..(r + 1) * m]
                .iter()
                .zip(&dc)
                .map(|(a, d)| a * d)
                .sum();
        }
        let (s, gs) = grad
            .iter()
            .copied()
            .enumerate()
            .fold(
                (0, f64::NEG_INFINITY),
                |b, (r, v)| if v > b.1 { (r, v) } else { b },
            );
        let inner: f64 = mu.iter().zip(&grad).map(|(m, g)| m * g).sum();
        lower = lower.max(g * g * g);
        let gu = g + (gs - inner).max(0.0);
        if gu.is_finite() {
            upper = upper.min(gu * gu * gu);
        }
        if lower >= stop_above || upper < stop_below || upper - lower <= GAP_REL * upper {
            break;
        }
        let (v, _) = mu
            .iter()
            .zip(&grad)
            .enumerate()
            .filter(|(_, (m, _))| **m > 0.0)
            .fold((usize::MAX, f64::INFINITY), |b, (r, (_, &gv))| {
                if gv < b.1 { (r, gv) } else { b }
            });
        if v == usize::MAX || v == s {
            break;
        }
        let gmax = mu[v];
        let d: Vec<f64> = (0..m).map(|j| rows[s * m + j] - rows[v * m + j]).collect();
        // phi(t) = G(c + t d) is concave: phi' decreases; safeguarded Newton on phi' = 0
        let derivs = |t: f64| -> (f64, f64) {
            let (mut d1, mut d2) = (0.0, 0.0);
            for j in 0..m {
                if d[j] == 0.0 {
                    continue;
                }
                let r = (c[j] + t * d[j]).max(C_FLOOR).cbrt();
                d1 += (2.0 / 3.0) * w23[j] / r * d[j];
                d2 -= (2.0 / 9.0) * w23[j] / (r * r * r * r) * d[j] * d[j];
            }
            (d1, d2)
        };
        let t = if derivs(gmax).0 >= 0.0 {
            gmax
        } else {
            let (mut lo, mut hi) = (0.0, gmax);
            let mut t = 0.0;
            for _ in 0..LINE_STEPS {
                let (d1, d2) = derivs(t);
                if d1 > 0.0 {
                    lo = t;
                } else {
                    hi = t;
                }
                let newton = if d2 < 0.0 { t - d1 / d2 } else { f64::NAN };
                t = if newton > lo && newton < hi {
                    newton
                } else {
                    0.5 * (lo + hi)
                };
                if hi - lo <= LINE_TOL_REL * gmax {
                    break;
                }
            }
            lo.max(t.min(hi))
        };
        if t <= 0.0 {
            break;
        }
        mu[v] -= t;
        if mu[v] < 1e-300 {
            mu[v] = 0.0;
        }
        mu[s] += t;
        for j in 0..m {
            c[j] = (c[j] + t * d[j]).max(0.0);
        }
    }
    (lower, upper)
}
