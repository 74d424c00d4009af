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
/// this (far below [`crate::SearchParams::improvement_rel`]).
const GAP_REL: f64 = 1e-9;

/// Smallest $c_j$ used in the gradient $\propto c_j^{-1/3}$ (a variable no support row
/// touches then pulls every row that involves it to the top).
const C_FLOOR: f64 = 1e-300;

/// Working memory of [`bounds_with`], reused across calls (the screening runs the solver
/// millions of times; reusing the buffers changes no arithmetic).
#[derive(Debug, Default, Clone)]
pub(crate) struct Scratch {
    mu: Vec<f64>,
    cols: Vec<f64>,
    c: Vec<f64>,
    grad: Vec<f64>,
    root: Vec<f64>,
    dc: Vec<f64>,
    d: Vec<f64>,
    /// The last argument (bits) of the cube root per error and its value: the same argument
    /// recurs (an error the step does not move keeps its $c_j$; a full step ends where the
    /// line search evaluated), and the cube root is a pure function, so the value is reused.
    memo_in: Vec<u64>,
    memo_out: Vec<f64>,
}

impl Scratch {
    /// Ready for [`bounds_with`] on `rows` ($R \times m$, $R \ge 1$): $\mu$ the warm start
    /// `mu0` normalised (row 0 alone without one), the rows by column, $c = \mu^T A$, the
    /// other vectors zero and the cube-root memo empty.
    fn start(&mut self, rows: &[f64], m: usize, mu0: &[(usize, f64)]) {
        let n_rows = rows.len() / m;
        let reset = |v: &mut Vec<f64>, len: usize| {
            v.clear();
            v.resize(len, 0.0);
        };
        let Scratch {
            mu,
            cols,
            c,
            memo_in,
            ..
        } = self;
        reset(mu, n_rows);
        reset(c, m);
        warm_start(mu, c, rows, mu0);
        // the rows by column: built at the first gradient ([`Scratch::columns`]), which a
        // solve stopped at its warm start's lower bound never needs
        cols.clear();
        memo_in.clear();
        // an argument never seen: a NaN pattern (the arguments are maxima with 0 or
        // C_FLOOR, never NaN)
        memo_in.resize(m, u64::MAX);
        reset(&mut self.grad, n_rows);
        // cbrt(max(c_j, C_FLOOR)) of the current c (shared by G, its gradient and the line
        // search's first step: one cube root per error per iteration fewer than recomputing)
        reset(&mut self.root, m);
        reset(&mut self.dc, m);
        reset(&mut self.d, m);
        reset(&mut self.memo_out, m);
    }
}

/// The rows by column (`cols[j * n_rows + r]`) into `cols` when it is empty: the gradient is
/// then a sum over `j` of whole columns, each row's terms added in the same order as a
/// row-wise dot product (so the same bits) but vectorised across rows.
fn columns(cols: &mut Vec<f64>, rows: &[f64], m: usize) {
    if !cols.is_empty() {
        return;
    }
    let n_rows = rows.len() / m;
    cols.resize(rows.len(), 0.0);
    for (r, row) in rows.chunks_exact(m).enumerate() {
        for (j, &a) in row.iter().enumerate() {
            cols[j * n_rows + r] = a;
        }
    }
}

/// The warm start into the zeroed `mu` (one weight per row of `rows`) and `c` (one per
/// error): $\mu$ the weights of `mu0` (row, weight; negative ones as 0) normalised to sum 1,
/// row 0 alone without a positive one; $c = \mu^T A$.
fn warm_start(mu: &mut [f64], c: &mut [f64], rows: &[f64], mu0: &[(usize, f64)]) {
    let m = c.len();
    let total: f64 = mu0.iter().map(|t| t.1.max(0.0)).sum();
    if total > 0.0 {
        for &(r, v) in mu0 {
            mu[r] += v.max(0.0) / total;
        }
    } else {
        mu[0] = 1.0;
    }
    for (r, &v) in mu.iter().enumerate() {
        if v > 0.0 {
            for (cj, a) in c.iter_mut().zip(&rows[r * m..(r + 1) * m]) {
                *cj += v * a;
            }
        }
    }
}

impl Scratch {
    /// The multipliers of the last solve's final iterate, (row, weight) for every row with a
    /// positive weight, into `out` (a warm start for another solve: any non-negative weights
    /// give rigorous bounds).
    pub(crate) fn support(&self, out: &mut Vec<(usize, f64)>) {
        out.clear();
        out.extend(
            self.mu
                .iter()
                .copied()
                .enumerate()
                .filter(|&(_, v)| v > 0.0),
        );
    }
}

/// $w_j^{2/3}$ as [`bounds_with`] takes it (computed once per problem).
pub(crate) fn weights_23(weights: &[f64]) -> Vec<f64> {
    // x^(2/3) = cbrt(x)^2 and x^(-1/3) = 1/cbrt(x): cube roots are several times cheaper
    // than `powf`, which dominated the screening
    weights.iter().map(|w| w.cbrt().powi(2)).collect()
}

/// The cube root of a non-negative finite `x` to within 0.667 ulp (FreeBSD's and musl's
/// `s_cbrt.c`: a bit-level first guess, a degree-4 polynomial to 23 bits, rounding to 21
/// bits so that $t^2$ is exact, and one Halley step in double), about twice as fast as the
/// correctly rounded `f64::cbrt` (a port of CORE-MATH) that dominated the screening. Zero,
/// subnormal, infinite and NaN arguments take `f64::cbrt`. The screening's bounds carry the
/// rounding of their sums anyway (relative $10^{-16}$ against the $10^{-6}$ that decides an
/// exchange), and $J$ itself always comes from the shared allocation core.
///
/// # Reference
/// S. L. Moshier / Bruce D. Evans, FreeBSD `lib/msun/src/s_cbrt.c` (as in musl's
/// `src/math/cbrt.c`).
#[inline]
pub(crate) fn cbrt_fast(x: f64) -> f64 {
    // B1 = (1023 - 1023/3 - 0.03306235651) * 2^20: the exponent's third, biased
    const B1: u64 = 715_094_163;
    // |1/cbrt(x) - p(x)| < 2^-23.5 on the reduced range
    // (the bit patterns of FreeBSD's source)
    const P0: f64 = f64::from_bits(0x3ffe_03e6_0f61_e692);
    const P1: f64 = f64::from_bits(0xbffe_28e0_92f0_2420);
    const P2: f64 = f64::from_bits(0x3ff9_f160_4a49_d6c2);
    const P3: f64 = f64::from_bits(0xbfe8_44cb_bee7_51d9);
    const P4: f64 = f64::from_bits(0x3fc2_b000_d4e4_edd7);
    let bits = x.to_bits();
    let hx = bits >> 32;
    if !(0x0010_0000..0x7ff0_0000).contains(&hx) {
        return x.cbrt();
    }
    let mut t = f64::from_bits((hx / 3 + B1) << 32);
    let r = (t * t) * (t / x);
    t *= (P0 + r * (P1 + r * P2)) + ((r * r) * r) * (P3 + r * P4);
    t = f64::from_bits((t.to_bits() + 0x8000_0000) & 0xffff_ffff_c000_0000);
    let s = t * t;
    let r = x / s;
    let w = t + t;
    t + t * ((r - t) / (w + r))
}

/// The cube root ([`cbrt_fast`]) of `x` through the memo of error `j` (bit-identical to
/// `cbrt_fast(x)`).
#[inline]
fn cbrt_memo(memo_in: &mut [u64], memo_out: &mut [f64], j: usize, x: f64) -> f64 {
    let bits = x.to_bits();
    if memo_in[j] == bits {
        memo_out[j]
    } else {
        let r = cbrt_fast(x);
        memo_in[j] = bits;
        memo_out[j] = r;
        r
    }
}

/// Bounds on $J$ (rad$^{-2}$) of the rows `rows` ($R \times m$): (lower, upper), for the
/// weights as $w_j^{2/3}$ (`w23`, [`weights_23`]) and with the working memory `sc` reused.
/// `mu0` is the warm start (row, weight $\ge 0$); the iteration stops early once
/// `lower >= stop_above` (before the iterate's gradient: the upper bound is then the previous
/// iterate's) or `upper < stop_below`.
pub(crate) fn bounds_with(
    sc: &mut Scratch,
    w23: &[f64],
    rows: &[f64],
    m: usize,
    mu0: &[(usize, f64)],
    stop_above: f64,
    stop_below: f64,
) -> (f64, f64) {
    bounds_within(
        sc,
        w23,
        rows,
        m,
        mu0,
        (stop_above, stop_below),
        MAX_ITERATIONS,
    )
}

/// [`bounds_with`] stopped after `iterations` iterations at most (the bounds of the
/// iterates reached: as rigorous, less tight); with [`MAX_ITERATIONS`] the same bits.
pub(crate) fn bounds_within(
    sc: &mut Scratch,
    w23: &[f64],
    rows: &[f64],
    m: usize,
    mu0: &[(usize, f64)],
    (stop_above, stop_below): (f64, f64),
    iterations: usize,
) -> (f64, f64) {
    let n_rows = rows.len() / m;
    if n_rows == 0 {
        return (0.0, f64::INFINITY);
    }
    sc.start(rows, m, mu0);
    let Scratch {
        mu,
        cols,
        c,
        grad,
        root,
        dc,
        d,
        memo_in,
        memo_out,
    } = sc;
    let floor_root = cbrt_fast(C_FLOOR);
    let (mut lower, mut upper): (f64, f64) = (0.0, f64::INFINITY);
    for _ in 0..iterations {
        let mut g = 0.0;
        for j in 0..m {
            let cz = c[j].max(0.0);
            let r0 = cbrt_memo(memo_in, memo_out, j, cz);
            g += w23[j] * r0.powi(2);
            // c.max(C_FLOOR) is c itself when c >= C_FLOOR, else C_FLOOR
            root[j] = if cz >= C_FLOOR { r0 } else { floor_root };
        }
        // the lower bound alone decides `stop_above`: test it before the gradient (the
        // iteration's largest cost), which only the upper bound and the step need. The loop
        // stops at the same iteration with the same lower bound as when the test came after
        // the gradient; only the upper bound returned then is the previous iterate's (as
        // rigorous, and unused by the search: such a swap is pruned)
        lower = lower.max(g * g * g);
        if lower >= stop_above {
            break;
        }
        for j in 0..m {
            // d G / d c_j = (2/3) w_j^{2/3} c_j^{-1/3}
            dc[j] = (2.0 / 3.0) * w23[j] / root[j];
        }
        columns(cols, rows, m);
        grad.fill(0.0);
        for (j, &dj) in dc.iter().enumerate() {
            let col = &cols[j * n_rows..(j + 1) * n_rows];
            for (gr, a) in grad.iter_mut().zip(col) {
                *gr += a * dj;
            }
        }
        let (s, gs) = entering(grad);
        upper = upper.min(upper_bound(g, gs, mu, grad));
        if upper < stop_below || upper - lower <= GAP_REL * upper {
            break;
        }
        let Some(v) = leaving(mu, grad, s) else {
            break;
        };
        let gmax = mu[v];
        for (j, dj) in d.iter_mut().enumerate() {
            *dj = rows[s * m + j] - rows[v * m + j];
        }
        // phi(t) = G(c + t d) is concave: phi' decreases; safeguarded Newton on phi' = 0
        let mut derivs = |t: f64| -> (f64, f64) {
            let (mut d1, mut d2) = (0.0, 0.0);
            for j in 0..m {
                if d[j] == 0.0 {
                    continue;
                }
                // at t = 0, c + 0 d = c exactly: the cube root is already known
                let r = if t == 0.0 {
                    root[j]
                } else {
                    cbrt_memo(memo_in, memo_out, j, (c[j] + t * d[j]).max(C_FLOOR))
                };
                d1 += (2.0 / 3.0) * w23[j] / r * d[j];
                d2 -= (2.0 / 9.0) * w23[j] / (r * r * r * r) * d[j] * d[j];
            }
            (d1, d2)
        };
        let t = line_step(gmax, &mut derivs);
        if t <= 0.0 {
            break;
        }
        take_step(mu, c, d, (v, s), t);
    }
    (lower, upper)
}

/// The row that enters the support: the largest gradient entry `(s, grad[s])` (the first of
/// equal ones).
fn entering(grad: &[f64]) -> (usize, f64) {
    grad.iter().copied().enumerate().fold(
        (0, f64::NEG_INFINITY),
        |b, (r, v)| if v > b.1 { (r, v) } else { b },
    )
}

/// The duality bound's cube $(G + \max(0, g_s - \mu^T g))^3$ at the iterate ($G$: `g`, the
/// largest gradient entry `gs`), `+inf` when it is not finite (no bound).
fn upper_bound(g: f64, gs: f64, mu: &[f64], grad: &[f64]) -> f64 {
    let inner: f64 = mu.iter().zip(grad).map(|(m, g)| m * g).sum();
    let gu = g + (gs - inner).max(0.0);
    if gu.is_finite() {
        gu * gu * gu
    } else {
        f64::INFINITY
    }
}

/// The row of the support (`mu > 0`) with the smallest gradient entry (the first of equal
/// ones), which gives weight to the entering row `s`; `None` when the support is empty or is
/// that row (no swap).
fn leaving(mu: &[f64], grad: &[f64], s: usize) -> Option<usize> {
    let (v, _) = mu
        .iter()
        .zip(grad)
        .enumerate()
        .filter(|(_, (m, _))| **m > 0.0)
        .fold((usize::MAX, f64::INFINITY), |b, (r, (_, &gv))| {
            if gv < b.1 { (r, gv) } else { b }
        });
    (v != usize::MAX && v != s).then_some(v)
}

/// The step `t` in `[0, gmax]` that maximises the concave `phi(t) = G(c + t d)` along a swap
/// direction, given `derivs(t) = (phi'(t), phi''(t))`: the whole step when `phi'` is still
/// non-negative at `gmax`, else a safeguarded Newton iteration on `phi' = 0` (a bisection of
/// the bracket where Newton's step leaves it) to [`LINE_TOL_REL`] of `gmax`, at most
/// [`LINE_STEPS`] steps.
fn line_step(gmax: f64, mut derivs: impl FnMut(f64) -> (f64, f64)) -> f64 {
    if derivs(gmax).0 >= 0.0 {
        return gmax;
    }
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
}

/// Move weight `t` from row `v` to row `s` (`(v, s)`): `mu[v] -= t` (flushed to zero below
/// 1e-300), `mu[s] += t`, and `c += t d` (clamped at zero).
fn take_step(mu: &mut [f64], c: &mut [f64], d: &[f64], (v, s): (usize, usize), t: f64) {
    mu[v] -= t;
    if mu[v] < 1e-300 {
        mu[v] = 0.0;
    }
    mu[s] += t;
    for (cj, dj) in c.iter_mut().zip(d) {
        *cj = (*cj + t * dj).max(0.0);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand_chacha::ChaCha8Rng;
    use rand_core::{Rng, SeedableRng};

    /// `cbrt_fast` is within 1 ulp of the correctly rounded cube root (FreeBSD's bound is
    /// 0.667 ulp) on 2e6 seeded doubles spread over every exponent of the normal range, at the
    /// screening's floor 1e-300 and at the ends of the range; zero, subnormals, infinity and NaN
    /// take `f64::cbrt` exactly.
    #[test]
    fn fast_cube_root_is_within_one_ulp_of_the_correctly_rounded_one() {
        let ulps = |a: f64, b: f64| (a.to_bits() as i64 - b.to_bits() as i64).unsigned_abs();
        let mut rng = ChaCha8Rng::seed_from_u64(3);
        let mut worst = 0;
        let special = [
            C_FLOOR,
            f64::MIN_POSITIVE,
            f64::MAX,
            1.0,
            8.0,
            27.0,
            0.125,
            1e-3,
        ];
        for i in 0..2_000_000u64 {
            let x = if (i as usize) < special.len() {
                special[i as usize]
            } else {
                // uniform bits over the normal positive range
                f64::from_bits(
                    rng.next_u64() % (0x7fef_ffff_ffff_ffff - 0x0010_0000_0000_0000)
                        + 0x0010_0000_0000_0000,
                )
            };
            worst = worst.max(ulps(cbrt_fast(x), x.cbrt()));
        }
        assert!(worst <= 1, "worst {worst} ulp");
        for x in [0.0, 5e-324, 1e-310, f64::INFINITY] {
            assert_eq!(cbrt_fast(x).to_bits(), x.cbrt().to_bits(), "{x}");
        }
        assert!(cbrt_fast(f64::NAN).is_nan());
    }

    /// The row-wise formulation [`bounds_with`] had before its gradient went by columns and its
    /// cube roots were shared (kept verbatim as the reference).
    fn bounds_row_wise(
        problem: &Problem,
        mu0: &[(usize, f64)],
        stop_above: f64,
        stop_below: f64,
    ) -> (f64, f64) {
        let Problem { m, weights, rows } = problem;
        let m = *m;
        let n_rows = rows.len() / m;
        if n_rows == 0 {
            return (0.0, f64::INFINITY);
        }
        // x^(2/3) = cbrt(x)^2 and x^(-1/3) = 1/cbrt(x): cube roots are several times cheaper
        // than `powf`, which dominated the screening
        let w23: Vec<f64> = weights.iter().map(|w| w.cbrt().powi(2)).collect();
        let mut mu = vec![0.0; n_rows];
        let mut c = vec![0.0; m];
        warm_start(&mut mu, &mut c, rows, mu0);
        let g_of = |c: &[f64]| -> f64 {
            c.iter()
                .zip(&w23)
                .map(|(c, w)| w * cbrt_fast(c.max(0.0)).powi(2))
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
                .map(|(c, w)| (2.0 / 3.0) * w / cbrt_fast(c.max(C_FLOOR)))
                .collect();
            for (r, gr) in grad.iter_mut().enumerate() {
                *gr = rows[r * m..(r + 1) * m]
                    .iter()
                    .zip(&dc)
                    .map(|(a, d)| a * d)
                    .sum();
            }
            let (s, gs) = entering(&grad);
            lower = lower.max(g * g * g);
            upper = upper.min(upper_bound(g, gs, &mu, &grad));
            if lower >= stop_above || upper < stop_below || upper - lower <= GAP_REL * upper {
                break;
            }
            let Some(v) = leaving(&mu, &grad, s) else {
                break;
            };
            let gmax = mu[v];
            let d: Vec<f64> = (0..m).map(|j| rows[s * m + j] - rows[v * m + j]).collect();
            // phi(t) = G(c + t d) is concave: phi' decreases; safeguarded Newton on phi' = 0
            let derivs = |t: f64| -> (f64, f64) {
                let (mut d1, mut d2) = (0.0, 0.0);
                for j in 0..m {
                    if d[j] == 0.0 {
                        continue;
                    }
                    let r = cbrt_fast((c[j] + t * d[j]).max(C_FLOOR));
                    d1 += (2.0 / 3.0) * w23[j] / r * d[j];
                    d2 -= (2.0 / 9.0) * w23[j] / (r * r * r * r) * d[j] * d[j];
                }
                (d1, d2)
            };
            let t = line_step(gmax, derivs);
            if t <= 0.0 {
                break;
            }
            take_step(&mut mu, &mut c, &d, (v, s), t);
        }
        (lower, upper)
    }

    /// Relative slack of a rigorous lower bound against the optimum it bounds
    /// (dimensionless): both are sums of a few hundred rounded products.
    const BOUND_ROUNDING_REL: f64 = 1e-12;

    /// The screening's pre-solve is a lower bound whatever its warm start: on seeded random
    /// rows, from random multipliers (a previous swap's, as the search carries them) and for
    /// every iteration count from the warm start alone (0) to a few, [`bounds_within`]'s lower
    /// bound is at most the optimum (the converged solve's upper bound from the default
    /// start) and its upper bound at least it; with [`MAX_ITERATIONS`] it is [`bounds_with`]
    /// bit for bit, and a solve after a stopped one on the same working memory (the columns
    /// rebuilt) gives the same bits as on fresh memory.
    #[test]
    fn pre_solve_from_any_warm_start_is_a_lower_bound_of_the_optimum() {
        let mut rng = ChaCha8Rng::seed_from_u64(34);
        let mut scratch = Scratch::default();
        let mut checked = 0;
        for case in 0..300 {
            let problem = Problem::draw(&mut rng);
            let (m, n_rows, rows) = (problem.m, problem.n_rows(), problem.rows.as_slice());
            let w23 = weights_23(&problem.weights);
            let optimum = bounds_with(
                &mut Scratch::default(),
                &w23,
                rows,
                m,
                &[],
                f64::INFINITY,
                0.0,
            );
            let carry: Vec<(usize, f64)> = (0..1 + (rng.next_u32() % 5) as usize)
                .map(|_| ((rng.next_u32() as usize) % n_rows, uniform(&mut rng)))
                .collect();
            for iterations in 0..4 {
                let (lower, upper) = bounds_within(
                    &mut scratch,
                    &w23,
                    rows,
                    m,
                    &carry,
                    (f64::INFINITY, 0.0),
                    iterations,
                );
                assert!(lower >= 0.0, "case {case}");
                assert!(
                    lower <= optimum.1 * (1.0 + BOUND_ROUNDING_REL),
                    "case {case}, {iterations} iterations: lower {lower} above {}",
                    optimum.1
                );
                assert!(
                    upper >= optimum.0 * (1.0 - BOUND_ROUNDING_REL),
                    "case {case}, {iterations} iterations: upper {upper} below {}",
                    optimum.0
                );
                checked += 1;
            }
            let full = bounds_within(
                &mut scratch,
                &w23,
                rows,
                m,
                &carry,
                (f64::INFINITY, 0.0),
                MAX_ITERATIONS,
            );
            let fresh = bounds_with(
                &mut Scratch::default(),
                &w23,
                rows,
                m,
                &carry,
                f64::INFINITY,
                0.0,
            );
            assert_eq!(full.0.to_bits(), fresh.0.to_bits(), "case {case}");
            assert_eq!(full.1.to_bits(), fresh.1.to_bits(), "case {case}");
        }
        assert_eq!(checked, 1200);
    }

    /// A random problem of the solver: $m$ errors' weights and the rows ($R \times m$,
    /// row-major).
    struct Problem {
        m: usize,
        weights: Vec<f64>,
        rows: Vec<f64>,
    }

    impl Problem {
        /// $m$ in 1..=13, $R$ in 1..=40, weights uniform in [0.1, 1.1), rows [`random_rows`].
        fn draw(rng: &mut ChaCha8Rng) -> Self {
            let m = 1 + (rng.next_u32() % 13) as usize;
            let n_rows = 1 + (rng.next_u32() % 40) as usize;
            let weights = (0..m).map(|_| 0.1 + uniform(rng)).collect();
            let rows = random_rows(rng, n_rows * m);
            Self { m, weights, rows }
        }

        /// $R$.
        fn n_rows(&self) -> usize {
            self.rows.len() / self.m
        }
    }

    /// `count` row entries: a third of them zero, the others uniform over 7 decades.
    fn random_rows(rng: &mut ChaCha8Rng, count: usize) -> Vec<f64> {
        (0..count)
            .map(|_| {
                if rng.next_u32() % 3 == 0 {
                    0.0
                } else {
                    uniform(rng) * 10f64.powi((rng.next_u32() % 7) as i32 - 3)
                }
            })
            .collect()
    }

    fn uniform(rng: &mut ChaCha8Rng) -> f64 {
        (rng.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }

    /// The column-wise gradient and the shared cube roots are a reordering of the same
    /// floating-point operations: [`bounds_with`] on fresh working memory gives the same bits
    /// as the row-wise reference for random rows (with zero entries, so that errors no support
    /// row touches take the floor path), random warm starts and stopping levels, so the
    /// search's screening, its order of exact evaluations and every answer of
    /// `design-schedule` are unchanged; so does it with its working memory and cube-root memo
    /// reused across cases.
    /// The one difference: stopped by `stop_above` (a pruned swap), the upper bound is the
    /// previous iterate's, at least the reference's.
    #[test]
    fn bounds_are_bit_identical_to_the_row_wise_formula() {
        let mut rng = ChaCha8Rng::seed_from_u64(21);
        let mut scratch = Scratch::default();
        for case in 0..300 {
            let problem = Problem::draw(&mut rng);
            let (m, n_rows, rows) = (problem.m, problem.n_rows(), problem.rows.as_slice());
            let mu0: Vec<(usize, f64)> = (0..(rng.next_u32() % 4) as usize)
                .map(|_| ((rng.next_u32() as usize) % n_rows, uniform(&mut rng)))
                .collect();
            let (reference_lower, reference_upper) =
                bounds_row_wise(&problem, &mu0, f64::INFINITY, 0.0);
            let stop_above = if case % 2 == 0 {
                f64::INFINITY
            } else {
                reference_lower * (0.5 + uniform(&mut rng))
            };
            let want = bounds_row_wise(&problem, &mu0, stop_above, 0.0);
            let w23 = weights_23(&problem.weights);
            let mut fresh = Scratch::default();
            let got = bounds_with(&mut fresh, &w23, rows, m, &mu0, stop_above, 0.0);
            assert_eq!(want.0.to_bits(), got.0.to_bits(), "lower, case {case}");
            // stopped by `stop_above`, the solver skips that iterate's gradient: its upper
            // bound is the previous iterate's (the reference's running minimum before its last
            // update)
            let upper_eq = |want: (f64, f64), got: (f64, f64)| {
                if want.0 >= stop_above {
                    got.1 >= want.1 && got.1 >= got.0
                } else {
                    want.1.to_bits() == got.1.to_bits()
                }
            };
            assert!(upper_eq(want, got), "upper, case {case}");
            // the working memory (and its cube-root memo) carried over from the other cases,
            // with different sizes, changes nothing
            let reused = bounds_with(&mut scratch, &w23, rows, m, &mu0, stop_above, 0.0);
            assert_eq!(want.0.to_bits(), reused.0.to_bits(), "lower, case {case}");
            assert!(upper_eq(want, reused), "upper, case {case}");
            assert!(reference_lower <= reference_upper, "case {case}");
        }
    }
}
