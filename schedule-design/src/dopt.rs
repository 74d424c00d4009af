//! The D-optimal baseline: $\max \sum_k \ln\det(\mathbf A_k^T\mathbf A_k)$ over schedules of
//! the same candidates, by greedy construction and Fedorov's exchange.

use super::problem::DesignProblem;
use super::{DOptimalOutcome, ExchangeStop, SINGULAR_RATIO};
use e2e_verify::E2eError;
use nalgebra::DMatrix;
use rayon::prelude::*;

/// Relative ridge $\delta$ of the greedy construction: $\mathbf G = (\mathbf A^T\mathbf A +
/// \delta\bar a^2\mathbf I)^{-1}$ with $\bar a^2$ the mean squared regressor-row norm, so that
/// the first steps (fewer rows than coefficients) are defined. Dimensionless.
const GREEDY_RIDGE_REL: f64 = 1e-8;

/// $\sum_k \ln\det(\mathbf A_k^T\mathbf A_k)$ of schedule `s` (`-inf` when an output is rank
/// deficient), by Cholesky of each Gram matrix.
pub(crate) fn log_det(p: &DesignProblem, s: &[usize]) -> f64 {
    p.outputs
        .iter()
        .map(|o| {
            let mut g = DMatrix::<f64>::zeros(o.p, o.p);
            for &c in s {
                let a = o.a_row(c);
                for r in 0..o.p {
                    for q in 0..o.p {
                        g[(r, q)] += a[r] * a[q];
                    }
                }
            }
            match g.cholesky() {
                Some(ch) => 2.0 * ch.l().diagonal().iter().map(|d| d.ln()).sum::<f64>(),
                None => f64::NEG_INFINITY,
            }
        })
        .sum()
}

/// Per output $\mathbf G = (\mathbf A^T\mathbf A + \rho\mathbf I)^{-1}$ of schedule `s`
/// (row-major), or `None` when singular.
fn gram_inverses(p: &DesignProblem, s: &[usize], ridge: &[f64]) -> Option<Vec<DMatrix<f64>>> {
    p.outputs
        .iter()
        .zip(ridge)
        .map(|(o, &rho)| {
            let mut g = DMatrix::<f64>::identity(o.p, o.p) * rho;
            for &c in s {
                let a = o.a_row(c);
                for r in 0..o.p {
                    for q in 0..o.p {
                        g[(r, q)] += a[r] * a[q];
                    }
                }
            }
            g.cholesky().map(|ch| ch.inverse())
        })
        .collect()
}

/// Whether `b` beats `a`: a larger value, ties to the smaller index (a total order, so the
/// parallel reductions give the same result for any number of threads).
fn better(b: (usize, f64), a: (usize, f64)) -> bool {
    match b.1.total_cmp(&a.1) {
        std::cmp::Ordering::Greater => true,
        std::cmp::Ordering::Equal => b.0 < a.0,
        std::cmp::Ordering::Less => false,
    }
}

fn quad(g: &DMatrix<f64>, a: &[f64], b: &[f64]) -> f64 {
    let mut v = 0.0;
    for r in 0..a.len() {
        for q in 0..b.len() {
            v += a[r] * g[(r, q)] * b[q];
        }
    }
    v
}

/// The greedy D-optimal sequence of `n` candidates: each step adds the candidate with the
/// largest $\sum_k \ln(1 + \mathbf a_c^T\mathbf G_k\mathbf a_c)$ (ties: the smallest index);
/// every prefix is the greedy schedule of its size.
///
/// # Errors
/// [`E2eError::TooManyPositions`] when `n` exceeds the candidates.
pub(crate) fn greedy_d(p: &DesignProblem, n: usize) -> Result<Vec<usize>, E2eError> {
    let all: Vec<usize> = (0..p.n_candidates()).collect();
    greedy_d_among(p, &all, n)
}

/// [`greedy_d`] choosing only among `allowed` (candidate indices, at least `n`).
pub(crate) fn greedy_d_among(
    p: &DesignProblem,
    allowed: &[usize],
    n: usize,
) -> Result<Vec<usize>, E2eError> {
    let c_count = p.n_candidates();
    if n > allowed.len() {
        return Err(E2eError::TooManyPositions {
            positions: n,
            candidates: allowed.len(),
        });
    }
    let ridge: Vec<f64> = p
        .outputs
        .iter()
        .map(|o| GREEDY_RIDGE_REL * o.a.iter().map(|v| v * v).sum::<f64>() / c_count as f64)
        .map(|r| if r > 0.0 { r } else { GREEDY_RIDGE_REL })
        .collect();
    let mut s = Vec::with_capacity(n);
    let mut in_s = vec![false; c_count];
    while s.len() < n {
        let g = gram_inverses(p, &s, &ridge).ok_or(E2eError::NoConvergence {
            what: "greedy D-optimal construction (singular ridge matrix)",
            iterations: s.len(),
            change: f64::NAN,
        })?;
        let best = allowed
            .par_iter()
            .copied()
            .filter(|&c| !in_s[c])
            .map(|c| {
                let gain: f64 = p
                    .outputs
                    .iter()
                    .zip(&g)
                    .map(|(o, g)| (1.0 + quad(g, o.a_row(c), o.a_row(c))).ln())
                    .sum();
                (c, gain)
            })
            .reduce(
                || (usize::MAX, f64::NEG_INFINITY),
                |a, b| {
                    if better(b, a) { b } else { a }
                },
            );
        s.push(best.0);
        in_s[best.0] = true;
    }
    Ok(s)
}

/// Fedorov's exchange for the D-criterion from `start`: for each slot the swap with the
/// largest $\sum_k \ln\big((1 + d_c)(1 - d_i) + d_{ic}^2\big)$ (with $d_{uv} = \mathbf a_u^T
/// \mathbf G\mathbf a_v$, the exact determinant ratio of a rank-two update) is taken when it
/// is above $\epsilon$; passes repeat until none is. The start must identify every output. `stop` ends the exchange early after
/// any accepted swap (used to repair a start's condition numbers).
pub(crate) fn exchange_d(
    p: &DesignProblem,
    start: Vec<usize>,
    stop: &dyn Fn(&[usize]) -> bool,
) -> Result<DOptimalOutcome, E2eError> {
    let c_count = p.n_candidates();
    let mut s = start;
    let mut in_s = vec![false; c_count];
    for &c in &s {
        in_s[c] = true;
    }
    let zero = vec![0.0; p.outputs.len()];
    let mut value = log_det(p, &s);
    if !value.is_finite() {
        return Err(E2eError::NoConvergence {
            what: "D-optimal exchange (the start does not identify every output)",
            iterations: 0,
            change: value,
        });
    }
    let mut exchanges = 0;
    let mut passes = 0;
    let max_passes = 4 * s.len() + 16;
    let local_optimum = 'passes: loop {
        passes += 1;
        let mut moved = false;
        for slot in 0..s.len() {
            let Some(g) = gram_inverses(p, &s, &zero) else {
                return Err(E2eError::NoConvergence {
                    what: "D-optimal exchange (singular Gram matrix)",
                    iterations: passes,
                    change: f64::NAN,
                });
            };
            let ci = s[slot];
            let best = (0..c_count)
                .into_par_iter()
                .filter(|&c| !in_s[c])
                .map(|c| {
                    let mut total = 0.0;
                    for (o, g) in p.outputs.iter().zip(&g) {
                        let (ac, ai) = (o.a_row(c), o.a_row(ci));
                        let (dc, di, dic) = (quad(g, ac, ac), quad(g, ai, ai), quad(g, ai, ac));
                        let ratio = (1.0 + dc) * (1.0 - di) + dic * dic;
                        if ratio.is_nan() || ratio <= SINGULAR_RATIO {
                            return (c, f64::NEG_INFINITY);
                        }
                        total += ratio.ln();
                    }
                    (c, total)
                })
                .reduce(
                    || (usize::MAX, f64::NEG_INFINITY),
                    |a, b| {
                        if better(b, a) { b } else { a }
                    },
                );
            if best.1 > p.search.improvement_rel {
                let mut trial = s.clone();
                trial[slot] = best.0;
                let v = log_det(p, &trial);
                // accept only a real improvement of the criterion recomputed from scratch
                if v > value + p.search.improvement_rel {
                    in_s[ci] = false;
                    in_s[best.0] = true;
                    s = trial;
                    value = v;
                    exchanges += 1;
                    moved = true;
                    if stop(&s) {
                        break 'passes false;
                    }
                }
            }
        }
        if !moved || passes >= max_passes {
            break !moved;
        }
    };
    Ok(DOptimalOutcome {
        schedule: s,
        log_det: value,
        stop: ExchangeStop {
            exchanges,
            passes,
            local_optimum,
        },
    })
}
