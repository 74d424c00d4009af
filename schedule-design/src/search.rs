//! The search: per-schedule state for cheap swap screening (rank-one and rank-two updates of
//! $(\mathbf A^T\mathbf A)^{-1}$, rigorous dual lower bounds, a fixed-shape upper bound),
//! the greedy construction and the exchange.

use super::dual;
use super::problem::DesignProblem;
use super::{DUAL_SWEEPS, Evaluation, ExchangeOutcome, ExchangeStop, SINGULAR_RATIO};
use e2e_verify::E2eError;
use e2e_verify::Linearization;
use nalgebra::DMatrix;
use rayon::prelude::*;

/// Per output: $\mathbf G = (\mathbf A^T\mathbf A)^{-1}$, $\mathbf G\mathbf a_c$ for every
/// candidate and $\mathbf H = \mathbf A^+\mathbf C_1$ (so that $\mathbf P\mathbf C_1$ row $q$ is
/// $\mathbf a_q^T\mathbf H$).
#[derive(Debug, Clone)]
pub(crate) struct Factor {
    /// $\mathbf G\mathbf a_c$ for every candidate ($C \times p$).
    ga: Vec<f64>,
    /// $\mathbf H$ ($p \times m$, row-major); empty for static rows.
    h: Vec<f64>,
}

/// The current schedule with its exact evaluation and everything the screening of its
/// neighbours needs.
#[derive(Debug, Clone)]
pub(crate) struct State {
    pub s: Vec<usize>,
    pub in_s: Vec<bool>,
    pub eval: Evaluation,
    /// $J$ (rad$^{-2}$).
    pub j: f64,
    /// $\mathrm{UB}$ (rad; `+inf` for an error no output depends on).
    pub x: Vec<f64>,
    /// $|\mathbf M|/\omega_m$ row $(k, q)$ at `(k * n + q) * m`.
    rows: Vec<f64>,
    /// Load of every row at $\mathrm{UB}$.
    loads: Vec<f64>,
    /// Multipliers $\mu_{kq} \ge 0$ of the rows (any non-negative values give valid bounds;
    /// these are fitted to the KKT conditions at $\mathrm{UB}$), then one per specification
    /// row of `spec` (after the $R$ rows of eq 14).
    mu: Vec<f64>,
    factors: Vec<Factor>,
    /// The specifications' part of the screening (`None` without specifications).
    spec: Option<SpecState>,
}

/// The specification rows' part of a state: the screening data of its exact answer and
/// $\mathbf G\mathbf a_c$ per output for every candidate with that answer's $\mathbf G$
/// (rate steps included).
#[derive(Debug, Clone)]
struct SpecState {
    screen: std::sync::Arc<crate::spec::SpecScreen>,
    ga: Vec<Vec<f64>>,
    /// $\mathbf G\mathbf w$ of every specification row (its output's $\mathbf G$).
    gw: Vec<Vec<f64>>,
    /// Per output: whether a specification row reads it (the others' $\mathbf H_s'$ is not
    /// updated after a swap: no row reads it).
    specified: Vec<bool>,
    /// With rate steps: the multipliers of the whole schedule's rows ([`crate::spec::WholeRows`]: eq 14 at
    /// every entry, then the specification rows over their room) fitted to the KKT
    /// conditions at $\mathrm{UB}$; empty without rate steps or without a table.
    whole_mu: Vec<f64>,
}

/// Relative margin of the whole schedule's bound ([`Search::whole_bound`]) before it prunes
/// a swap (dimensionless): the bound is exact in real arithmetic on rows recomputed by other
/// sums than the exact answer's (rounding ~1e-13 relative), and an error whose rows are all
/// at their rounding level gets no bound in the exact answer while its rounding-level
/// entries add at most ~1e-9 of $J$ to the dual bound; far below the exchange's 1e-6.
const WHOLE_BOUND_MARGIN_REL: f64 = 1e-8;

/// Relative reduction of a specification row's noise part after a swap before it is taken
/// off the limit (dimensionless): the noise part is recomputed by other sums than the exact
/// answer's, and a bound must not exceed J by rounding.
const NOISE_ROUNDING_REL: f64 = 1e-9;

/// $\mathbf H' = \mathbf T - \mathbf G\mathbf U\mathbf K^{-1}\mathbf U^T\mathbf T$ with
/// $\mathbf T = \mathbf H + \mathbf u_1\mathbf b_c^T - \mathbf u_2\mathbf b_i^T$ (the
/// Woodbury update of $\mathbf H = \mathbf A^+\mathbf B$ when row $\mathbf a_i$ with right-hand
/// row $\mathbf b_i$ leaves and $\mathbf a_c$ with $\mathbf b_c$ enters; $\mathbf u =
/// \mathbf G\mathbf a$, $\mathbf h$ is $p \times m$ row-major) into `out`.
#[allow(clippy::too_many_arguments)]
fn woodbury_swap(
    h: &[f64],
    (ac, ai): (&[f64], &[f64]),
    (u1, u2): (&[f64], &[f64]),
    (c1c, c1i): (&[f64], &[f64]),
    m: usize,
    out: &mut Vec<f64>,
    (r1, r2): (&mut Vec<f64>, &mut Vec<f64>),
) {
    let pk = ac.len();
    let (dc, di, dic) = (dot(ac, u1), dot(ai, u2), dot(ai, u1));
    // T = H + u1 c1_c^T - u2 c1_i^T and, row by row of T, the right-hand sides
    // (a_c^T T, a_i^T T) of K y (one pass; each entry summed in the same order as two passes)
    r1.clear();
    r1.resize(m, 0.0);
    r2.clear();
    r2.resize(m, 0.0);
    out.resize(h.len(), 0.0);
    for r in 0..pk {
        let (hr, row) = (&h[r * m..(r + 1) * m], &mut out[r * m..(r + 1) * m]);
        let (ur1, ur2, acr, air) = (u1[r], u2[r], ac[r], ai[r]);
        for jj in 0..m {
            let t = hr[jj] + (ur1 * c1c[jj] - ur2 * c1i[jj]);
            row[jj] = t;
            r1[jj] += acr * t;
            r2[jj] += air * t;
        }
    }
    // K = [[1 + dc, dic], [dic, -1 + di]]; solve K y = (a_c^T T, a_i^T T)
    let (k11, k12, k22) = (1.0 + dc, dic, -1.0 + di);
    let det = k11 * k22 - k12 * k12;
    for jj in 0..m {
        let y1 = (k22 * r1[jj] - k12 * r2[jj]) / det;
        let y2 = (k11 * r2[jj] - k12 * r1[jj]) / det;
        for r in 0..pk {
            out[r * m + jj] -= u1[r] * y1 + u2[r] * y2;
        }
    }
}

use super::SwapBound as Screened;

/// The searcher of one problem with its settings.
#[derive(Debug)]
pub(crate) struct Search<'a> {
    pub p: &'a DesignProblem,
    pub max_condition: f64,
    /// Whether every lower bound of the errors is zero (closed-form dual bound).
    zero_lower: bool,
    /// $w_j^{2/3}$ for the screening solver ([`dual::weights_23`]).
    w23: Vec<f64>,
}

/// Working memory of one screening thread, reused from swap to swap (no arithmetic changes).
#[derive(Debug, Default)]
struct SwapScratch {
    /// $\mathbf H'$ of every output after the swap.
    hs: Vec<Vec<f64>>,
    /// The multiplier-weighted sum of the retained rows (the cheap bound's $c$).
    cc: Vec<f64>,
    /// Every row after the swap (`R x m`).
    rows: Vec<f64>,
    /// The right-hand sides of the Woodbury solve.
    r1: Vec<f64>,
    r2: Vec<f64>,
    dual: dual::Scratch,
    /// $\mathbf H_s'$ of every output after the swap (specifications).
    hs_spec: Vec<Vec<f64>>,
    /// $d\mathbf g + d\mathbf e$ of the candidate in and of the one out.
    bc: Vec<f64>,
    bi: Vec<f64>,
    /// $\mathbf G'\mathbf w$ and $\mathbf v = \mathbf A'\mathbf G'\mathbf w$ of a
    /// specification row after the swap (its noise part).
    gw: Vec<f64>,
    v: Vec<f64>,
    /// The screening solver's final multipliers of the previous swap of the same chunk
    /// ([`SCREEN_CHUNK`]): the warm start of the pre-solve ([`PRE_SOLVE_ITERATIONS`]).
    carry: Vec<(usize, f64)>,
    /// The whole schedule's rows after the swap ([`Search::whole_bound`]), the specification
    /// rows' part of them and the solver's memory for them.
    whole_rows: Vec<f64>,
    whole_spec: Vec<f64>,
    whole_dual: dual::Scratch,
}

/// Swaps of one slot screened in a row by one thread, each pre-solved from the previous
/// one's multipliers ([`PRE_SOLVE_ITERATIONS`]). The chunks are fixed by the candidates'
/// order, not by the threads, so every verdict is the same for any thread count.
const SCREEN_CHUNK: usize = 64;

/// Iterations at most of the pre-solve: the screening solver from the previous swap's final
/// multipliers (a neighbouring candidate's, usually near this swap's optimum), which prunes a
/// swap whose lower bound reaches the threshold there. A swap it does not prune is screened
/// exactly as without it (the solver from the state's multipliers: the same bounds, so the
/// same estimates and order of exact evaluations); any non-negative multipliers give a
/// rigorous lower bound, so a pruned swap cannot improve $J$ by more than $\epsilon$.
const PRE_SOLVE_ITERATIONS: usize = 3;

/// Most errors for the pre-solve's first bound from its support's rows alone (computed on
/// the stack; with more errors only the pre-solve runs).
const PRE_ROW_MAX: usize = 64;

/// The parts of the screening shared by every swap of one slot.
#[derive(Debug)]
struct SlotScreen {
    slot: usize,
    /// $J(1 - \epsilon)$: a swap is kept when its lower bound is below this.
    threshold: f64,
    static_rows: bool,
    /// The cheap bound of every swap with static rows.
    static_lower: f64,
    /// The cheap bound's $c$ of the retained rows before the swap (static rows).
    base_c: Vec<f64>,
    /// $\Lambda$ of the cheap bound (the retained rows' multipliers).
    base_mu: f64,
    /// The screening solver's warm start.
    mu0: Vec<(usize, f64)>,
    /// The whole schedule's solver's warm start (the state's `whole_mu` but the slot's rows).
    whole_mu0: Vec<(usize, f64)>,
}

/// What one slot of the exchange did ([`Search::exchange_at`]).
#[derive(Debug, Default, Clone, Copy, PartialEq, Eq)]
struct SlotOutcome {
    /// Whether a swap was taken (the state moved).
    moved: bool,
    /// Swaps kept by the screening whose exact evaluation could not be made.
    unevaluated: usize,
    /// Exact evaluations (a conic solve each; the unevaluated swaps included).
    exact: usize,
    /// Swaps screened by a bound (every candidate outside the schedule; 0 when the slot was
    /// skipped whole).
    screened: usize,
}

/// The screening of swap `c` pruned by the bound `lower` (not below the threshold): no
/// estimate, final.
fn pruned(c: usize, lower: f64) -> (Screened, bool) {
    let screened = Screened {
        candidate: c,
        lower,
        estimate: f64::INFINITY,
    };
    (screened, true)
}

/// $\det\mathbf A'^T\mathbf A'/\det\mathbf A^T\mathbf A = (1 + \mathbf a_c^T\mathbf u_c)
/// (1 - \mathbf a_i^T\mathbf u_i) + (\mathbf a_i^T\mathbf u_c)^2$ when row $\mathbf a_i$ leaves
/// and $\mathbf a_c$ enters ($\mathbf u = \mathbf G\mathbf a$; Fedorov's $\Delta$).
#[inline]
fn swap_ratio((ac, ai): (&[f64], &[f64]), (u1, u2): (&[f64], &[f64])) -> f64 {
    let (dc, di, dic) = (dot(ac, u1), dot(ai, u2), dot(ai, u1));
    (1.0 + dc) * (1.0 - di) + dic * dic
}

#[inline]
fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// Load of a normalised row at `x` with the convention of
/// [`Linearization::row_worst_cases`]: a zero coefficient contributes nothing even against an
/// infinite bound.
#[inline]
fn load(row: &[f64], x: &[f64]) -> f64 {
    row.iter()
        .zip(x)
        .map(|(a, u)| if *a == 0.0 { 0.0 } else { a * u })
        .sum()
}

impl<'a> Search<'a> {
    pub(crate) fn new(p: &'a DesignProblem, max_condition: f64) -> Self {
        Self {
            p,
            max_condition,
            zero_lower: p.lower_bounds_rad.iter().all(|&l| l == 0.0),
            w23: dual::weights_23(&p.weights),
        }
    }

    /// Whether an evaluation is a feasible schedule: identifiable, condition numbers within
    /// the bound, lower bounds compatible.
    pub(crate) fn feasible(&self, e: &Evaluation) -> bool {
        e.is_feasible(self.max_condition)
    }

    /// The state of an evaluated, identifiable schedule.
    pub(crate) fn state(&self, eval: Evaluation) -> Result<State, E2eError> {
        let p = self.p;
        let s = eval.schedule.clone();
        let n = s.len();
        let m = p.errors;
        let mut in_s = vec![false; p.n_candidates()];
        for &c in &s {
            in_s[c] = true;
        }
        let linear = eval.linear.as_ref().ok_or(E2eError::NoConvergence {
            what: "schedule state (unidentifiable schedule)",
            iterations: 0,
            change: f64::NAN,
        })?;
        let mut rows = Vec::with_capacity(p.outputs.len() * n * m);
        for (r, row) in linear.matrix().row_iter().enumerate() {
            let w = 1.0 / p.accuracies[r / n];
            rows.extend(row.iter().map(|v| v.abs() * w));
        }
        let (j, x) = match &eval.allocation {
            Some(a) => (a.objective(), a.upper_bounds_rad().to_vec()),
            None => (f64::INFINITY, vec![f64::INFINITY; m]),
        };
        let loads: Vec<f64> = rows.chunks(m).map(|r| load(r, &x)).collect();
        let mut spec = eval.spec_screen.clone().map(|screen| SpecState {
            whole_mu: Vec::new(),
            specified: (0..p.outputs.len())
                .map(|k| screen.rows.iter().any(|r| r.output == k))
                .collect(),
            gw: screen
                .rows
                .iter()
                .map(|r| {
                    let g = &screen.gram_inv[r.output];
                    let pk = r.weights.len();
                    (0..pk)
                        .map(|i| dot(&g[i * pk..(i + 1) * pk], &r.weights))
                        .collect()
                })
                .collect(),
            ga: p
                .outputs
                .iter()
                .zip(&screen.gram_inv)
                .map(|(o, g)| {
                    (0..p.n_candidates())
                        .flat_map(|c| {
                            let a = o.a_row(c);
                            (0..o.p)
                                .map(|r| dot(&g[r * o.p..(r + 1) * o.p], a))
                                .collect::<Vec<_>>()
                        })
                        .collect()
                })
                .collect(),
            screen,
        });
        let mu = match (&spec, j.is_finite()) {
            (_, false) => {
                vec![0.0; rows.len() / m + spec.as_ref().map_or(0, |t| t.screen.rows.len())]
            }
            (None, true) => self.multipliers(&rows, &loads, &x),
            (Some(t), true) => self.multipliers_with_spec(t, rows.clone(), &x),
        };
        if let Some(t) = spec.as_mut().filter(|_| j.is_finite()) {
            if let Some(whole) = &t.screen.whole {
                t.whole_mu = self.multipliers_with_spec(t, whole.rows.clone(), &x);
            }
        }
        let regs = p.regressions(&s)?;
        let factors = p
            .outputs
            .iter()
            .zip(&regs)
            .map(|(o, reg)| {
                let pinv = reg.pinv();
                let g = pinv * pinv.transpose();
                let gv: Vec<f64> = (0..o.p)
                    .flat_map(|r| (0..o.p).map(move |c| (r, c)))
                    .map(|(r, c)| g[(r, c)])
                    .collect();
                let ga: Vec<f64> = (0..p.n_candidates())
                    .flat_map(|c| {
                        let a = o.a_row(c);
                        (0..o.p)
                            .map(|r| dot(&gv[r * o.p..(r + 1) * o.p], a))
                            .collect::<Vec<_>>()
                    })
                    .collect();
                let h = if p.affine.is_static() {
                    Vec::new()
                } else {
                    let c1 = DMatrix::from_fn(n, m, |i, jj| o.c1[s[i] * m + jj]);
                    let hm = pinv * c1;
                    (0..o.p)
                        .flat_map(|r| (0..m).map(move |c| (r, c)))
                        .map(|(r, c)| hm[(r, c)])
                        .collect()
                };
                Factor { ga, h }
            })
            .collect();
        Ok(State {
            s,
            in_s,
            eval,
            j,
            x,
            rows,
            loads,
            mu,
            factors,
            spec,
        })
    }

    /// [`Search::multipliers`] of eq 14's rows `eq14` followed by the specification rows as
    /// the allocation holds them (over their room), so that the binding ones take their
    /// multipliers.
    fn multipliers_with_spec(&self, t: &SpecState, mut eq14: Vec<f64>, x: &[f64]) -> Vec<f64> {
        let m = self.p.errors;
        let mut row = vec![0.0; m];
        for r in 0..t.screen.rows.len() {
            t.screen.row(r, &t.screen.hs, false, &mut row);
            eq14.extend_from_slice(&row);
        }
        let loads: Vec<f64> = eq14.chunks(m).map(|r| load(r, x)).collect();
        self.multipliers(&eq14, &loads, x)
    }

    /// Multipliers of the rows fitted to the KKT conditions at `x`: on the rows at full load,
    /// $\sum_r \mu_r |M_{rj}|/\omega = 2w_j^2/x_j^3$ for every error above its lower bound,
    /// by projected coordinate descent on the non-negative least-squares problem.
    fn multipliers(&self, rows: &[f64], loads: &[f64], x: &[f64]) -> Vec<f64> {
        let p = self.p;
        let m = p.errors;
        let free: Vec<usize> = (0..m)
            .filter(|&j| x[j].is_finite() && x[j] > p.lower_bounds_rad[j] * (1.0 + 1e-7))
            .collect();
        let tight: Vec<usize> = (0..loads.len())
            .filter(|&r| loads[r] >= 1.0 - 1e-9)
            .collect();
        let mut mu = vec![0.0; loads.len()];
        if free.is_empty() || tight.is_empty() {
            return mu;
        }
        let g: Vec<f64> = free
            .iter()
            .map(|&j| 2.0 * p.weights[j].powi(2) / x[j].powi(3))
            .collect();
        // columns of B: tight rows restricted to the free errors
        let b: Vec<Vec<f64>> = tight
            .iter()
            .map(|&r| free.iter().map(|&j| rows[r * m + j]).collect())
            .collect();
        let q: Vec<Vec<f64>> = b
            .iter()
            .map(|u| b.iter().map(|v| dot(u, v)).collect())
            .collect();
        let rhs: Vec<f64> = b.iter().map(|u| dot(u, &g)).collect();
        let mut v = vec![0.0; tight.len()];
        for _ in 0..DUAL_SWEEPS {
            let mut change: f64 = 0.0;
            for t in 0..v.len() {
                if q[t][t] <= 0.0 {
                    continue;
                }
                let grad = dot(&q[t], &v) - rhs[t];
                let new = (v[t] - grad / q[t][t]).max(0.0);
                change = change.max((new - v[t]).abs());
                v[t] = new;
            }
            if change <= 1e-15 * v.iter().copied().fold(0.0, f64::max) {
                break;
            }
        }
        for (t, &r) in tight.iter().enumerate() {
            mu[r] = v[t];
        }
        mu
    }

    /// The Lagrangian dual bound: for multipliers $\mu \ge 0$ on some rows of a schedule,
    /// with $c_j = \sum_r \mu_r |M_{rj}|/\omega$ and $\Lambda = \sum_r \mu_r$,
    /// $J \ge \max_{t \ge 0} \sum_j h_j(t c_j) - t\Lambda$,
    /// $h_j(c) = \min_{x \ge \ell_j} w_j^2/x^2 + c x$; with $\ell = 0$ this is
    /// $\big(\sum_j (w_j c_j)^{2/3}\big)^3/\Lambda^2$.
    pub(crate) fn dual_bound(&self, c: &[f64], lambda: f64) -> f64 {
        if lambda.is_nan() || lambda <= 0.0 {
            return 0.0;
        }
        let w = &self.p.weights;
        if self.zero_lower {
            let a: f64 = c
                .iter()
                .zip(w)
                .map(|(c, w)| (w * c.max(0.0)).powf(2.0 / 3.0))
                .sum();
            return a * a * a / (lambda * lambda);
        }
        let l = &self.p.lower_bounds_rad;
        let phi = |t: f64| -> f64 {
            let mut v = -t * lambda;
            for j in 0..c.len() {
                let cj = t * c[j].max(0.0);
                if cj <= 0.0 {
                    continue;
                }
                let xu = (2.0 * w[j] * w[j] / cj).cbrt();
                let x = xu.max(l[j]);
                v += (w[j] / x).powi(2) + cj * x;
            }
            v
        };
        // the closed-form optimum for l = 0 brackets the maximiser of this concave function
        let a: f64 = c
            .iter()
            .zip(w)
            .map(|(c, w)| (w * c.max(0.0)).powf(2.0 / 3.0))
            .sum();
        let kappa = 3.0 / 2f64.powf(2.0 / 3.0);
        let t0 = (2.0 * kappa * a / (3.0 * lambda)).powi(3);
        let (mut lo, mut hi) = (0.0, 8.0 * t0.max(1e-300));
        let g = 0.5 * (5f64.sqrt() - 1.0);
        for _ in 0..80 {
            let (m1, m2) = (hi - g * (hi - lo), lo + g * (hi - lo));
            if phi(m1) < phi(m2) {
                lo = m1;
            } else {
                hi = m2;
            }
        }
        phi(0.5 * (lo + hi)).max(0.0)
    }

    /// Rows of output `k` at slot `q` of `st` after replacing the candidate in slot `slot`
    /// by `c`: $\mathbf C_0 + \mathbf a^T\mathbf H'$ (normalised, signed) into `out`.
    #[inline]
    fn row_after(&self, k: usize, cand: usize, h: &[f64], out: &mut [f64]) {
        let o = &self.p.outputs[k];
        let m = self.p.errors;
        let c0 = &o.c0[cand * m..(cand + 1) * m];
        out.copy_from_slice(c0);
        if !h.is_empty() {
            let a = o.a_row(cand);
            for (r, ar) in a.iter().enumerate() {
                let hr = &h[r * m..(r + 1) * m];
                for (v, hv) in out.iter_mut().zip(hr) {
                    *v += ar * hv;
                }
            }
        }
    }

    /// $\mathbf H'$ after the swap (slot's candidate `ci` out, `c` in) by the Woodbury formula
    /// with $\mathbf U = (\mathbf a_c, \mathbf a_i)$, $\mathbf D = \operatorname{diag}(1, -1)$;
    /// `None` when the swap makes $\mathbf A$ (nearly) rank deficient. Also returns the ratio
    /// $\det\mathbf A'^T\mathbf A'/\det\mathbf A^T\mathbf A$ (Fedorov's $\Delta$).
    fn h_after_swap(
        &self,
        st: &State,
        k: usize,
        ci: usize,
        c: usize,
        out: &mut Vec<f64>,
        (r1, r2): (&mut Vec<f64>, &mut Vec<f64>),
    ) -> Option<f64> {
        let o = &self.p.outputs[k];
        let f = &st.factors[k];
        let (pk, m) = (o.p, self.p.errors);
        let (ac, ai) = (o.a_row(c), o.a_row(ci));
        let (u1, u2) = (&f.ga[c * pk..(c + 1) * pk], &f.ga[ci * pk..(ci + 1) * pk]);
        let ratio = swap_ratio((ac, ai), (u1, u2));
        if ratio.is_nan() || ratio <= SINGULAR_RATIO {
            return None;
        }
        if f.h.is_empty() {
            out.clear();
            return Some(ratio);
        }
        let (c1c, c1i) = (&o.c1[c * m..(c + 1) * m], &o.c1[ci * m..(ci + 1) * m]);
        woodbury_swap(&f.h, (ac, ai), (u1, u2), (c1c, c1i), m, out, (r1, r2));
        Some(ratio)
    }

    /// $\mathbf H_s'$ of output `k` after the swap of `ci` for `c` into `out`: the Woodbury
    /// update of the answered schedule's $\mathbf H_s = \mathbf A^+(d\mathbf G + d\mathbf E)$
    /// on its Gram matrix (rate steps included), with `b` and `r` working memory.
    fn hs_after_swap(
        &self,
        spec: &SpecState,
        k: usize,
        (ci, c): (usize, usize),
        out: &mut Vec<f64>,
        (bc, bi): (&mut Vec<f64>, &mut Vec<f64>),
        r: (&mut Vec<f64>, &mut Vec<f64>),
    ) {
        let m = self.p.errors;
        let o = &self.p.outputs[k];
        let pk = o.p;
        let ga = &spec.ga[k];
        let b = |x: usize, v: &mut Vec<f64>| {
            v.clear();
            v.extend(
                o.de[x * m..(x + 1) * m]
                    .iter()
                    .zip(&o.dg[x * m..(x + 1) * m])
                    .map(|(e, g)| e + g),
            );
        };
        b(c, bc);
        b(ci, bi);
        woodbury_swap(
            &spec.screen.hs[k],
            (o.a_row(c), o.a_row(ci)),
            (&ga[c * pk..(c + 1) * pk], &ga[ci * pk..(ci + 1) * pk]),
            (bc, bi),
            m,
            out,
            r,
        );
    }

    /// The specification rows after the swap of the slot's candidate for `c` (the swap known
    /// not to be rank deficient) into `out` ($S \times m$), in absolute value, normalised by
    /// their room: the limit less the noise part after the swap, $k\sqrt{\mathbf v^T
    /// \boldsymbol\Sigma\mathbf v}$ with $\mathbf v = \mathbf A'\mathbf G'\mathbf w$ (the
    /// entries' covariance $\boldsymbol\Sigma$ is the schedule's timing's, unchanged by a swap;
    /// $\mathbf G'\mathbf w$ by the Woodbury formula), reduced by [`NOISE_ROUNDING_REL`].
    /// Their sensitivities $\mathbf H_s'$ are left in `sc.hs_spec`. `false` when a row's noise
    /// part alone fills its limit (no table suffices: $J = +\infty$).
    fn spec_rows_after_swap(
        &self,
        st: &State,
        spec: &SpecState,
        (slot, c): (usize, usize),
        sc: &mut SwapScratch,
        out: &mut [f64],
    ) -> bool {
        let m = self.p.errors;
        let ci = st.s[slot];
        let SwapScratch {
            hs_spec,
            r1,
            r2,
            bc,
            bi,
            gw,
            v,
            ..
        } = sc;
        hs_spec.resize_with(self.p.outputs.len(), Vec::new);
        for (k, h) in hs_spec.iter_mut().enumerate() {
            if spec.specified[k] {
                self.hs_after_swap(spec, k, (ci, c), h, (bc, bi), (r1, r2));
            }
        }
        let n = st.s.len();
        for (r, row) in out.chunks_exact_mut(m).enumerate() {
            let sr = &spec.screen.rows[r];
            let k = sr.output;
            let o = &self.p.outputs[k];
            let pk = o.p;
            // G' w = G w - (u1 y1 + u2 y2), K y = (u1 . w, u2 . w)
            let noise = match &spec.screen.sigma[k] {
                None => 0.0,
                Some(sigma) => {
                    let (ac, ai) = (o.a_row(c), o.a_row(ci));
                    let ga = &spec.ga[k];
                    let (u1, u2) = (&ga[c * pk..(c + 1) * pk], &ga[ci * pk..(ci + 1) * pk]);
                    let (dc, di, dic) = (dot(ac, u1), dot(ai, u2), dot(ai, u1));
                    let (k11, k12, k22) = (1.0 + dc, dic, -1.0 + di);
                    let det = k11 * k22 - k12 * k12;
                    let (z1, z2) = (dot(u1, &sr.weights), dot(u2, &sr.weights));
                    let y1 = (k22 * z1 - k12 * z2) / det;
                    let y2 = (k11 * z2 - k12 * z1) / det;
                    gw.clear();
                    gw.extend((0..pk).map(|t| spec.gw[r][t] - (u1[t] * y1 + u2[t] * y2)));
                    let rate = &spec.screen.a_rate[k];
                    v.clear();
                    v.extend(
                        (0..n)
                            .map(|q| dot(o.a_row(if q == slot { c } else { st.s[q] }), gw))
                            .chain(rate.chunks_exact(pk).map(|a| dot(a, gw))),
                    );
                    let nt = v.len();
                    let quad: f64 = (0..nt)
                        .map(|i| v[i] * dot(&sigma[i * nt..(i + 1) * nt], v))
                        .sum();
                    sr.coverage * quad.max(0.0).sqrt() * (1.0 - NOISE_ROUNDING_REL)
                }
            };
            let room = sr.limit - noise;
            if room <= 0.0 {
                return false;
            }
            spec.screen.row(r, hs_spec, true, row);
            // `row` is f |c| / L: rescale to the room
            let scale = sr.limit / room;
            for v in row.iter_mut() {
                *v *= scale;
            }
        }
        true
    }

    /// What the screening of every swap of `slot` shares: the threshold, the cheap bound's
    /// parts that do not depend on the candidate and the solver's warm start.
    fn slot_screen(&self, st: &State, slot: usize) -> SlotScreen {
        let p = self.p;
        let n = st.s.len();
        let m = p.errors;
        let static_rows = p.affine.is_static();
        // static rows: the bound without the slot's rows is the same for every candidate
        let mut base_c = vec![0.0; m];
        let mut base_mu = 0.0;
        for k in 0..p.outputs.len() {
            for q in 0..n {
                let r = k * n + q;
                if q == slot {
                    continue;
                }
                if st.mu[r] > 0.0 {
                    base_mu += st.mu[r];
                    for (b, v) in base_c.iter_mut().zip(&st.rows[r * m..(r + 1) * m]) {
                        *b += st.mu[r] * v;
                    }
                }
            }
        }
        let static_lower = self.dual_bound(&base_c, base_mu);
        // the screening solver's warm start: the state's multipliers except the slot's rows
        // (every specification row is kept: it is recomputed after the swap)
        let eq14_rows = p.outputs.len() * n;
        let mu0: Vec<(usize, f64)> = st
            .mu
            .iter()
            .copied()
            .enumerate()
            .filter(|&(r, v)| v > 0.0 && (r >= eq14_rows || r % n != slot))
            .collect();
        // the same for the whole schedule's rows (its entries: the positions, then the rate
        // steps' entries; only a position's slot is swapped)
        let whole_mu0 = match &st.spec {
            Some(t) if !t.whole_mu.is_empty() => {
                let entries = t.screen.whole.as_ref().map_or(n, |w| w.entries);
                let eq14_whole = p.outputs.len() * entries;
                t.whole_mu
                    .iter()
                    .copied()
                    .enumerate()
                    .filter(|&(r, v)| v > 0.0 && (r >= eq14_whole || r % entries != slot))
                    .collect()
            }
            _ => Vec::new(),
        };
        SlotScreen {
            slot,
            threshold: st.j * (1.0 - self.p.search.improvement_rel),
            static_rows,
            static_lower,
            base_c,
            base_mu,
            mu0,
            whole_mu0,
        }
    }

    /// A rigorous lower bound on the specified $J$ after swapping candidate `c` into the
    /// slot, from the rows the specified allocation holds ([`crate::spec::WholeRows`]): eq 14's rows of
    /// every position and of every rate step's entry, each $|\mathbf b_q + d\,\mathbf a_q^T
    /// \mathbf H_s'|/\omega_k$ with $\mathbf H_s'$ after the swap by the Woodbury update on the
    /// whole schedule's Gram matrix, and the specification rows over their room after the
    /// swap ([`Search::spec_rows_after_swap`]). With every lower bound of the errors zero, the
    /// screening solver from the state's multipliers of those rows (the slot's rows dropped),
    /// stopped once its lower bound reaches `stop_above` or its upper bound is below
    /// `stop_below`; otherwise the dual bound of those multipliers. `None` without rate steps,
    /// without a table or when the swap makes the whole schedule (nearly) rank deficient;
    /// `+inf` when a specification's noise part fills its limit after the swap.
    fn whole_bound(
        &self,
        st: &State,
        ss: &SlotScreen,
        c: usize,
        sc: &mut SwapScratch,
        (stop_above, stop_below): (f64, f64),
    ) -> Option<f64> {
        let spec = st.spec.as_ref()?;
        let whole = spec.screen.whole.as_ref()?;
        if spec.whole_mu.is_empty() {
            return None;
        }
        let p = self.p;
        let m = p.errors;
        let ci = st.s[ss.slot];
        for (k, o) in p.outputs.iter().enumerate() {
            let pk = o.p;
            let ga = &spec.ga[k];
            let (ac, ai) = (o.a_row(c), o.a_row(ci));
            let (u1, u2) = (&ga[c * pk..(c + 1) * pk], &ga[ci * pk..(ci + 1) * pk]);
            let ratio = swap_ratio((ac, ai), (u1, u2));
            if ratio.is_nan() || ratio <= SINGULAR_RATIO {
                return None;
            }
        }
        let mut spec_rows = std::mem::take(&mut sc.whole_spec);
        spec_rows.clear();
        spec_rows.resize(spec.screen.rows.len() * m, 0.0);
        let room = self.spec_rows_after_swap(st, spec, (ss.slot, c), sc, &mut spec_rows);
        if !room {
            sc.whole_spec = spec_rows;
            return Some(f64::INFINITY);
        }
        let SwapScratch {
            hs_spec,
            bc,
            bi,
            r1,
            r2,
            whole_rows: rows,
            whole_spec,
            whole_dual,
            cc,
            ..
        } = sc;
        for (k, h) in hs_spec.iter_mut().enumerate() {
            if !spec.specified[k] && whole.d_per_accuracy[k] != 0.0 {
                self.hs_after_swap(spec, k, (ci, c), h, (bc, bi), (r1, r2));
            }
        }
        let entries = whole.entries;
        let eq14 = p.outputs.len() * entries;
        let row_of = |r: usize, out: &mut [f64]| {
            if r < eq14 {
                self.whole_row(
                    st,
                    (ss.slot, c),
                    (spec, whole),
                    &hs_spec[r / entries],
                    r,
                    out,
                );
            } else {
                out.copy_from_slice(&spec_rows[(r - eq14) * m..(r - eq14 + 1) * m]);
            }
        };
        // the dual bound of the state's multipliers from their rows alone (few: the binding
        // ones), before every row is computed
        cc.clear();
        cc.resize(m, 0.0);
        let mut lambda = 0.0;
        rows.clear();
        rows.resize(m, 0.0);
        for &(r, w) in &ss.whole_mu0 {
            row_of(r, rows);
            lambda += w;
            for (b, v) in cc.iter_mut().zip(rows.iter()) {
                *b += w * v;
            }
        }
        let cheap = self.dual_bound(cc, lambda);
        if cheap >= stop_above || !self.zero_lower {
            *whole_spec = spec_rows;
            return Some(cheap);
        }
        rows.clear();
        rows.resize((eq14 + spec.screen.rows.len()) * m, 0.0);
        for (r, out) in rows.chunks_exact_mut(m).enumerate() {
            row_of(r, out);
        }
        *whole_spec = spec_rows;
        let (lower, _) = dual::bounds_with(
            whole_dual,
            &self.w23,
            rows,
            m,
            &ss.whole_mu0,
            stop_above,
            stop_below,
        );
        Some(cheap.max(lower))
    }

    /// Row `r` (output `r / entries`, entry `r % entries`) of eq 14's rows of the whole
    /// schedule after swapping `c` into `slot`, normalised and in absolute value, with
    /// $\mathbf H_s'$ of its output `h` ([`Search::whole_bound`]) into `out`.
    fn whole_row(
        &self,
        st: &State,
        (slot, c): (usize, usize),
        (spec, whole): (&SpecState, &crate::spec::WholeRows),
        h: &[f64],
        r: usize,
        out: &mut [f64],
    ) {
        let m = self.p.errors;
        let n = st.s.len();
        let (k, q) = (r / whole.entries, r % whole.entries);
        let o = &self.p.outputs[k];
        let (dk, pk) = (whole.d_per_accuracy[k], o.p);
        let (base, a) = if q < n {
            let cand = if q == slot { c } else { st.s[q] };
            (&o.c0[cand * m..(cand + 1) * m], o.a_row(cand))
        } else {
            let i = q - n;
            (
                &whole.b_rate[k][i * m..(i + 1) * m],
                &spec.screen.a_rate[k][i * pk..(i + 1) * pk],
            )
        };
        out.copy_from_slice(base);
        if dk != 0.0 {
            for (t, at) in a.iter().enumerate() {
                for (v, hv) in out.iter_mut().zip(&h[t * m..(t + 1) * m]) {
                    *v += dk * at * hv;
                }
            }
        }
        for v in out.iter_mut() {
            *v = v.abs();
        }
    }

    /// Whether row `r` of the state's order is computed for the cheap bound (and kept, signed,
    /// for the solver's rows).
    #[inline]
    fn cheap_row(st: &State, ss: &SlotScreen, r: usize) -> bool {
        !ss.static_rows && r % st.s.len() != ss.slot && st.mu[r] > 0.0
    }

    /// The cheap bound of swapping candidate `c` into the slot: the dual lower bound with the
    /// state's multipliers (the slot's rows dropped; the rows of the retained positions
    /// recomputed for the new projection); `+inf` when the swap makes an output
    /// unidentifiable. Leaves $\mathbf H'$ and the rows it computed in `sc`.
    fn screen_cheap(&self, st: &State, ss: &SlotScreen, c: usize, sc: &mut SwapScratch) -> f64 {
        let p = self.p;
        let n = st.s.len();
        let m = p.errors;
        let ci = st.s[ss.slot];
        let SwapScratch {
            hs, rows, r1, r2, ..
        } = sc;
        hs.resize_with(p.outputs.len(), Vec::new);
        for (k, h) in hs.iter_mut().enumerate() {
            if self.h_after_swap(st, k, ci, c, h, (r1, r2)).is_none() {
                return f64::INFINITY;
            }
        }
        let eq14_rows = p.outputs.len() * n;
        let n_spec = st.spec.as_ref().map_or(0, |t| t.screen.rows.len());
        rows.clear();
        rows.resize((eq14_rows + n_spec) * m, 0.0);
        // eq 14's retained rows alone (the specification rows' multipliers at zero)
        let eq14_lower = if ss.static_rows {
            ss.static_lower
        } else {
            self.cheap_eq14(st, ss, sc)
        };
        let Some(spec) = &st.spec else {
            return eq14_lower;
        };
        // the specified J is the minimum over fewer tables (eq 14's rows and the
        // specification rows), so eq 14's bound is a lower bound on it too: where it prunes,
        // the specification rows after the swap are not needed. The exchange takes the same
        // swap: one pruned here has its specified J not below the threshold, so it was either
        // pruned before too or evaluated and not taken (one fewer exact evaluation)
        if eq14_lower >= ss.threshold {
            return eq14_lower;
        }
        // the specification rows after the swap (at their limits), then the cheap bound with
        // their multipliers beside eq 14's retained rows
        let mut tail = std::mem::take(&mut sc.rows);
        let room =
            self.spec_rows_after_swap(st, spec, (ss.slot, c), sc, &mut tail[eq14_rows * m..]);
        sc.rows = tail;
        if !room {
            return f64::INFINITY;
        }
        let (mut c_all, mut lambda) = if ss.static_rows {
            (ss.base_c.clone(), ss.base_mu)
        } else {
            (sc.cc.clone(), ss.base_mu)
        };
        for (r, row) in sc.rows[eq14_rows * m..].chunks_exact(m).enumerate() {
            let mu = st.mu[eq14_rows + r];
            if mu > 0.0 {
                lambda += mu;
                for (b, v) in c_all.iter_mut().zip(row) {
                    *b += mu * v;
                }
            }
        }
        self.dual_bound(&c_all, lambda)
    }

    /// The cheap bound from eq 14's retained rows after the swap (rows with $\mathbf H'$ in
    /// `sc.hs`), leaving them in `sc.rows` and their weighted sum in `sc.cc`.
    fn cheap_eq14(&self, st: &State, ss: &SlotScreen, sc: &mut SwapScratch) -> f64 {
        let p = self.p;
        let n = st.s.len();
        let m = p.errors;
        let SwapScratch { hs, cc, rows, .. } = sc;
        cc.clear();
        cc.resize(m, 0.0);
        for (k, h) in hs.iter().enumerate() {
            for q in 0..n {
                let r = k * n + q;
                if !Self::cheap_row(st, ss, r) {
                    continue;
                }
                let out = &mut rows[r * m..(r + 1) * m];
                self.row_after(k, st.s[q], h, out);
                for (b, v) in cc.iter_mut().zip(out.iter()) {
                    *b += st.mu[r] * v.abs();
                }
            }
        }
        self.dual_bound(cc, ss.base_mu)
    }

    /// The full screening of candidate `c` after [`Search::screen_cheap`] (which gave `lower`
    /// and left its work in `sc`): where the cheap bound does not prune, the screening
    /// solver's bounds on every row after the swap (rigorous lower bound and, as estimate,
    /// rigorous upper bound; for nonzero lower bounds of the errors the fixed-shape estimate
    /// $J\,L^2$ with $L$ the largest load of the new rows at the current $\mathrm{UB}$).
    ///
    /// With `until_kept` the solver also stops once its upper bound is below the threshold
    /// (the swap is then kept whatever the remaining iterations give): the estimate is not
    /// final then, and the second value is `false` ([`Search::resolve`] gives the final one).
    /// With `pre_solve` the solver first runs from `sc.carry` (the previous swap's
    /// multipliers; [`PRE_SOLVE_ITERATIONS`]) and `sc.carry` takes this swap's.
    #[allow(clippy::too_many_arguments)]
    fn screen_rest(
        &self,
        st: &State,
        ss: &SlotScreen,
        c: usize,
        lower: f64,
        sc: &mut SwapScratch,
        until_kept: bool,
        pre_solve: bool,
    ) -> (Screened, bool) {
        if lower >= ss.threshold {
            return pruned(c, lower);
        }
        let n = st.s.len();
        let m = self.p.errors;
        let SwapScratch {
            hs,
            rows,
            dual: dual_scratch,
            carry,
            cc,
            ..
        } = sc;
        if self.zero_lower && pre_solve && !carry.is_empty() && m <= PRE_ROW_MAX {
            // the pre-solve's first lower bound from the rows of its support alone (before
            // every row is computed): the dual bound of those multipliers
            let eq14_rows = self.p.outputs.len() * n;
            cc.clear();
            cc.resize(m, 0.0);
            let mut lambda = 0.0;
            let mut buf = [0.0; PRE_ROW_MAX];
            let buf = &mut buf[..m];
            for &(r, w) in carry.iter() {
                let out = if r < eq14_rows && !Self::cheap_row(st, ss, r) {
                    let (k, q) = (r / n, r % n);
                    let cand = if q == ss.slot { c } else { st.s[q] };
                    self.row_after(k, cand, &hs[k], buf);
                    &*buf
                } else {
                    &rows[r * m..(r + 1) * m]
                };
                lambda += w;
                for (b, v) in cc.iter_mut().zip(out) {
                    *b += w * v.abs();
                }
            }
            let pre = self.dual_bound(cc, lambda);
            if pre >= ss.threshold {
                return pruned(c, lower.max(pre));
            }
        }
        // every row of the schedule after the swap, in the state's order (k, q),
        // normalised and in absolute value
        for (k, h) in hs.iter().enumerate() {
            for q in 0..n {
                let r = k * n + q;
                let out = &mut rows[r * m..(r + 1) * m];
                if !Self::cheap_row(st, ss, r) {
                    let cand = if q == ss.slot { c } else { st.s[q] };
                    self.row_after(k, cand, h, out);
                }
                for v in out.iter_mut() {
                    *v = v.abs();
                }
            }
        }
        // rigorous bounds on J after the swap from the dual screening solver warm-started at
        // the state's multipliers (except the slot's rows); only for zero lower bounds (the
        // dual's closed form)
        let stop_below = if until_kept { ss.threshold } else { 0.0 };
        if self.zero_lower && pre_solve && !carry.is_empty() {
            // the pre-solve from the previous swap's multipliers: prunes, or changes nothing
            // (it stops once its upper bound shows the swap kept)
            let (pre, _) = dual::bounds_within(
                dual_scratch,
                &self.w23,
                rows,
                m,
                carry,
                (ss.threshold, ss.threshold),
                PRE_SOLVE_ITERATIONS,
            );
            if pre >= ss.threshold {
                dual_scratch.support(carry);
                return pruned(c, lower.max(pre));
            }
        }
        let (lower2, upper) = if self.zero_lower {
            dual::bounds_with(
                dual_scratch,
                &self.w23,
                rows,
                m,
                &ss.mu0,
                ss.threshold,
                stop_below,
            )
        } else {
            (0.0, f64::INFINITY)
        };
        if pre_solve {
            dual_scratch.support(carry);
        }
        let lower = lower.max(lower2);
        if lower >= ss.threshold {
            // pruned by the solver's lower bound (which stops before its last upper bound)
            return pruned(c, lower);
        }
        let estimate = if upper.is_finite() {
            upper
        } else {
            st.j * max_load(rows, &st.x, m).powi(2)
        };
        let screened = Screened {
            candidate: c,
            lower,
            estimate,
        };
        (screened, upper >= stop_below)
    }

    /// Screen every swap of `slot` with every candidate not in the schedule: the dual lower
    /// bound with the state's multipliers (the slot's rows dropped; the rows of the retained
    /// positions recomputed for the new projection) and, where it does not prune, the
    /// screening solver's bounds ([`Search::screen_rest`]).
    pub(crate) fn screen_swaps(&self, st: &State, slot: usize) -> Vec<Screened> {
        self.screen_swaps_with(st, &self.slot_screen(st, slot), false)
            .into_iter()
            .map(|t| t.0)
            .collect()
    }

    /// [`Search::screen_swaps`], with `until_kept` stopping the solver of a kept swap as soon
    /// as its upper bound is below the threshold (`false` beside such a swap: its estimate is
    /// not final; [`Search::resolve`]).
    fn screen_swaps_with(
        &self,
        st: &State,
        ss: &SlotScreen,
        until_kept: bool,
    ) -> Vec<(Screened, bool)> {
        let outside: Vec<usize> = (0..self.p.n_candidates())
            .filter(|&c| !st.in_s[c])
            .collect();
        let chunks: Vec<Vec<(Screened, bool)>> = outside
            .par_chunks(SCREEN_CHUNK)
            .map_init(SwapScratch::default, |sc, chunk| {
                sc.carry.clear();
                chunk
                    .iter()
                    .map(|&c| {
                        // the whole schedule's rows (rate steps' entries included) prune where
                        // they bind, first (they are the tighter bound there); a swap they keep
                        // is screened as without them, so its bounds and estimate, and the
                        // order of the exact evaluations, are the same
                        let stop = ss.threshold / (1.0 - WHOLE_BOUND_MARGIN_REL);
                        match self.whole_bound(st, ss, c, sc, (stop, ss.threshold)) {
                            Some(w) if w * (1.0 - WHOLE_BOUND_MARGIN_REL) >= ss.threshold => {
                                pruned(c, w)
                            }
                            _ => {
                                let lower = self.screen_cheap(st, ss, c, sc);
                                self.screen_rest(st, ss, c, lower, sc, until_kept, true)
                            }
                        }
                    })
                    .collect()
            })
            .collect();
        chunks.into_iter().flatten().collect()
    }

    /// The final screening of one swap whose estimate [`Search::screen_swaps_with`] left
    /// unresolved: the same computation as [`Search::screen_swaps`] for that candidate (the
    /// solver is deterministic and runs from the same warm start), so the same bits.
    fn resolve(&self, st: &State, ss: &SlotScreen, c: usize, sc: &mut SwapScratch) -> Screened {
        let lower = self.screen_cheap(st, ss, c, sc);
        self.screen_rest(st, ss, c, lower, sc, false, false).0
    }

    /// Screen adding each candidate not in the schedule (greedy construction): the
    /// fixed-shape estimate of $J$ after the addition and the information gain
    /// $\sum_k \ln(1 + \mathbf a_c^T\mathbf G_k\mathbf a_c)$ (the D-optimal criterion's
    /// increase) as tie-break.
    pub(crate) fn screen_additions(&self, st: &State) -> Vec<(usize, f64, f64)> {
        let p = self.p;
        let n = st.s.len();
        let m = p.errors;
        let static_rows = p.affine.is_static();
        let max_now = st.loads.iter().copied().fold(0.0, f64::max);
        (0..p.n_candidates())
            .into_par_iter()
            .filter(|&c| !st.in_s[c])
            .map(|c| {
                let mut gain = 0.0;
                let mut worst: f64 = if static_rows { max_now.max(1.0) } else { 0.0 };
                let mut row = vec![0.0; m];
                let mut h = Vec::new();
                for (k, o) in p.outputs.iter().enumerate() {
                    let f = &st.factors[k];
                    let a = o.a_row(c);
                    let u = &f.ga[c * o.p..(c + 1) * o.p];
                    let kappa = 1.0 + dot(a, u);
                    gain += kappa.ln();
                    if !static_rows {
                        // H' = T - u (a^T T)/kappa, T = H + u c1_c^T
                        let c1 = &o.c1[c * m..(c + 1) * m];
                        h.clear();
                        h.extend_from_slice(&f.h);
                        for r in 0..o.p {
                            for jj in 0..m {
                                h[r * m + jj] += u[r] * c1[jj];
                            }
                        }
                        let mut at = vec![0.0; m];
                        for r in 0..o.p {
                            for jj in 0..m {
                                at[jj] += a[r] * h[r * m + jj];
                            }
                        }
                        for r in 0..o.p {
                            for jj in 0..m {
                                h[r * m + jj] -= u[r] * at[jj] / kappa;
                            }
                        }
                        for q in 0..n {
                            self.row_after(k, st.s[q], &h, &mut row);
                            worst = worst.max(abs_load(&row, &st.x));
                        }
                    }
                    self.row_after(k, c, &h, &mut row);
                    worst = worst.max(abs_load(&row, &st.x));
                }
                (c, st.j * worst * worst, gain)
            })
            .collect()
    }

    /// $J$ and $\mathrm{UB}$ of the schedule without `slot` (static rows only: a lower bound
    /// on $J$ of every swap of that slot, since rows only add constraints).
    fn without_slot(&self, st: &State, slot: usize) -> Result<Option<(f64, Vec<f64>)>, E2eError> {
        let n = st.s.len();
        if n < 2 {
            return Ok(None);
        }
        let linear = st.eval.linear.as_ref().map(|l| {
            let keep: Vec<usize> = (0..l.matrix().nrows()).filter(|r| r % n != slot).collect();
            let mat = l.matrix().select_rows(keep.iter());
            Linearization::from_parts(mat, n - 1, l.outputs(), l.rounding().clone())
        });
        let Some(linear) = linear else {
            return Ok(None);
        };
        match self.p.allocate(&linear) {
            Ok(a) => Ok(Some((a.objective(), a.upper_bounds_rad().to_vec()))),
            Err(E2eError::InfeasibleLowerBounds { .. }) => Ok(None),
            Err(e) => Err(e),
        }
    }

    /// The schedule with `slot` replaced by `c`.
    fn swapped(st: &State, slot: usize, c: usize) -> Vec<usize> {
        let mut s = st.s.clone();
        s[slot] = c;
        s
    }

    /// Exchange from a feasible start: for each slot in turn, screen every swap, prune those
    /// whose rigorous lower bound is not below $J(1 - \epsilon)$, evaluate the others exactly
    /// in the order of their estimate and take the first that is feasible and improves $J$ by
    /// more than $\epsilon$ (relative); stop after $N$ slots in a row without an exchange
    /// (then no feasible single exchange improves $J$ by more than $\epsilon$) or at
    /// [`crate::SearchParams::max_exchanges_per_position`] $\times N$ exchanges.
    ///
    /// The slots are taken in cyclic order, so the last pass ends at the slot of the last
    /// exchange: the slots after it were screened against the same schedule already. A full
    /// last pass would find nothing there either, so the schedule, $J$, `passes` (the passes
    /// begun) and `local_optimum` are those of the full-pass rule; `screened_swaps`,
    /// `exact_evaluations` and `unevaluated_swaps` count the work actually done.
    pub(crate) fn exchange(&self, start: Evaluation) -> Result<ExchangeOutcome, E2eError> {
        let start_objective = start.objective;
        let mut st = self.state(start)?;
        let n = st.s.len();
        let max_exchanges = self.p.search.max_exchanges_per_position * n;
        let (mut exchanges, mut exact, mut screened, mut passes, mut unevaluated) = (0, 0, 0, 0, 0);
        let mut certified = false;
        // slots screened since the last exchange (all against the current schedule) and the
        // swaps among them that could not be evaluated
        let (mut quiet, mut quiet_unevaluated) = (0, 0);
        let mut slot = 0;
        loop {
            if quiet == n {
                certified = quiet_unevaluated == 0;
                break;
            }
            if slot == 0 {
                passes += 1;
            }
            if exchanges >= max_exchanges {
                break;
            }
            let at = self.exchange_at(&mut st, slot)?;
            exact += at.exact;
            screened += at.screened;
            unevaluated += at.unevaluated;
            if at.moved {
                exchanges += 1;
                (quiet, quiet_unevaluated) = (0, 0);
            } else {
                quiet += 1;
                quiet_unevaluated += at.unevaluated;
            }
            slot = (slot + 1) % n;
        }
        Ok(ExchangeOutcome {
            start_objective,
            evaluation: st.eval,
            stop: ExchangeStop {
                exchanges,
                passes,
                local_optimum: certified,
            },
            exact_evaluations: exact,
            screened_swaps: screened,
            unevaluated_swaps: unevaluated,
        })
    }

    /// One slot of [`Self::exchange`]: screen every swap of `slot`, evaluate the survivors in
    /// the order of their estimate and take the first feasible one that improves $J$ by more
    /// than $\epsilon$ (relative) into `st`, with the slot's work in counts.
    fn exchange_at(&self, st: &mut State, slot: usize) -> Result<SlotOutcome, E2eError> {
        let mut out = SlotOutcome::default();
        let threshold = st.j * (1.0 - self.p.search.improvement_rel);
        if self.p.affine.is_static() {
            // rows are fixed: J(swap) >= J(schedule without the slot) for every swap
            if let Some((j_minus, _)) = self.without_slot(st, slot)? {
                if j_minus >= threshold {
                    return Ok(out);
                }
            }
        }
        let ss = self.slot_screen(st, slot);
        let mut list = self.screen_swaps_with(st, &ss, true);
        out.screened = list.len();
        list.retain(|s| s.0.lower < threshold);
        if list.is_empty() {
            return Ok(out);
        }
        let mut order = LazyOrder::new(list, threshold);
        let mut sc = SwapScratch::default();
        while let Some(cand) = order.next(|c| self.resolve(st, &ss, c, &mut sc)) {
            out.exact += 1;
            let Some(e) = self
                .p
                .evaluate_or_skip(&Self::swapped(st, slot, cand.candidate), self.max_condition)?
            else {
                out.unevaluated += 1;
                continue;
            };
            if self.feasible(&e) && e.objective < threshold {
                *st = self.state(e)?;
                out.moved = true;
                return Ok(out);
            }
        }
        Ok(out)
    }

    /// Each candidate's own cost: the largest over its rows of the single-row optimum
    /// $\big(\sum_j (w_j |c_{0,j}|)^{2/3}\big)^3$ (the exact $J$ of a schedule made of that row
    /// alone when $\mathrm{LB} = 0$; with the schedule-independent part $\mathbf C_0$ of the
    /// rows, exact for static rows and a heuristic otherwise), and the candidates in
    /// increasing order of it (ties: index).
    pub(crate) fn level_order(&self) -> Vec<usize> {
        let p = self.p;
        let m = p.errors;
        let score: Vec<f64> = (0..p.n_candidates())
            .map(|c| {
                p.outputs
                    .iter()
                    .map(|o| {
                        let a: f64 = o.c0[c * m..(c + 1) * m]
                            .iter()
                            .zip(&p.weights)
                            .map(|(v, w)| (w * v.abs()).powf(2.0 / 3.0))
                            .sum();
                        a * a * a
                    })
                    .fold(0.0, f64::max)
            })
            .collect();
        let mut order: Vec<usize> = (0..p.n_candidates()).collect();
        order.sort_by(|&a, &b| score[a].total_cmp(&score[b]).then(a.cmp(&b)));
        order
    }

    fn conditions_ok(&self, s: &[usize]) -> bool {
        self.p
            .regressions(s)
            .is_ok_and(|r| r.iter().all(|g| g.condition_number() <= self.max_condition))
    }

    /// The level set: the shortest prefix of [`Search::level_order`] (found by bisection on
    /// its length) from which the greedy D-optimal construction of `n` positions meets the
    /// condition bound, with that construction; `None` when even all candidates do not.
    pub(crate) fn level_set(&self, n: usize) -> Result<Option<(usize, Vec<usize>)>, E2eError> {
        let order = self.level_order();
        let total = order.len();
        let test = |len: usize| -> Result<Option<Vec<usize>>, E2eError> {
            let s = super::dopt::greedy_d_among(self.p, &order[..len], n)?;
            Ok(self.conditions_ok(&s).then_some(s))
        };
        let Some(mut best) = test(total)? else {
            return Ok(None);
        };
        let (mut lo, mut hi) = (n, total);
        if let Some(s) = test(lo)? {
            return Ok(Some((lo, s)));
        }
        while hi - lo > 1 {
            let mid = lo + (hi - lo) / 2;
            match test(mid)? {
                Some(s) => {
                    hi = mid;
                    best = s;
                }
                None => lo = mid,
            }
        }
        Ok(Some((hi, best)))
    }

    /// Greedy construction: a core (the shortest prefix of the level set's greedy D-optimal
    /// sequence that identifies every output; with `keep_feasible`, that meets the condition
    /// bound if one does), then one candidate at a time from all candidates, the one with the
    /// smallest fixed-shape estimate of $J$ (ties: the largest information gain), with
    /// `keep_feasible` the best one that keeps a feasible schedule within the condition
    /// bound, each step evaluated exactly.
    pub(crate) fn greedy(
        &self,
        n: usize,
        keep_feasible: bool,
    ) -> Result<Option<Evaluation>, E2eError> {
        let sequence = match self.level_set(n)? {
            Some((_, s)) => s,
            None => super::dopt::greedy_d(self.p, n)?,
        };
        // the core: the shortest prefix that meets the condition bound, else the shortest
        // that identifies every output
        let first = self.p.min_positions().min(n);
        let feasible_core = if keep_feasible {
            (first..=n).find(|&k| self.conditions_ok(&sequence[..k]))
        } else {
            None
        };
        let core = feasible_core
            .or_else(|| (first..=n).find(|&k| self.p.regressions(&sequence[..k]).is_ok()))
            .unwrap_or(n);
        let Some(mut e) = self.p.evaluate_or_skip(&sequence[..core], f64::INFINITY)? else {
            return Ok(None);
        };
        if e.unidentifiable.is_some() {
            return Ok(Some(e));
        }
        while e.schedule.len() < n {
            let feasible_now = keep_feasible && e.max_condition() <= self.max_condition;
            let st = self.state(e)?;
            let grams = self.grams(&st.s);
            let mut ranked = self.screen_additions(&st);
            ranked.sort_by(|a, b| {
                a.1.total_cmp(&b.1)
                    .then(b.2.total_cmp(&a.2))
                    .then(a.0.cmp(&b.0))
            });
            // keep a feasible schedule feasible: the best-ranked addition within the bound
            if feasible_now {
                if let Some(pos) = ranked
                    .iter()
                    .position(|t| self.condition_with(&grams, t.0) <= self.max_condition)
                {
                    ranked[..=pos].rotate_right(1);
                }
            }
            let mut next = None;
            for (c, _, _) in ranked {
                let mut s = st.s.clone();
                s.push(c);
                if let Some(ev) = self.p.evaluate_or_skip(&s, f64::INFINITY)? {
                    next = Some(ev);
                    break;
                }
            }
            match next {
                Some(ev) => e = ev,
                None => return Ok(None),
            }
        }
        Ok(Some(e))
    }

    /// $\mathbf A_k^T\mathbf A_k$ of every output for schedule `s`.
    fn grams(&self, s: &[usize]) -> Vec<DMatrix<f64>> {
        self.p
            .outputs
            .iter()
            .map(|o| {
                let mut g = DMatrix::zeros(o.p, o.p);
                for &c in s {
                    let a = o.a_row(c);
                    for r in 0..o.p {
                        for q in 0..o.p {
                            g[(r, q)] += a[r] * a[q];
                        }
                    }
                }
                g
            })
            .collect()
    }

    /// The largest condition number $\sqrt{\lambda_{max}/\lambda_{min}}$ of
    /// $\mathbf A_k^T\mathbf A_k + \mathbf a_c\mathbf a_c^T$ over the outputs (a screen; the
    /// exact check is [`calib_lsq::Regression`]'s).
    fn condition_with(&self, grams: &[DMatrix<f64>], c: usize) -> f64 {
        self.p
            .outputs
            .iter()
            .zip(grams)
            .map(|(o, g)| {
                let a = o.a_row(c);
                let mut g = g.clone();
                for r in 0..o.p {
                    for q in 0..o.p {
                        g[(r, q)] += a[r] * a[q];
                    }
                }
                let ev = g.symmetric_eigenvalues();
                let (lo, hi) = (ev.min(), ev.max());
                if lo > 0.0 {
                    (hi / lo).sqrt()
                } else {
                    f64::INFINITY
                }
            })
            .fold(0.0, f64::max)
    }
}

/// The kept swaps of one slot in increasing order of (estimate, candidate), the order of
/// their exact evaluations, with the estimates that the screening left unresolved computed
/// only when they could come next.
///
/// An unresolved swap's solver stopped at a lower bound $\ell$ with its upper bound below the
/// threshold; its final estimate (the solver's upper bound at convergence) is at least $J^*
/// \ge \ell$. So a resolved swap with estimate $E$ comes before every unresolved one whose
/// key $\ell(1 - 10^{-12})$ (the margin far above the rounding of the solver's sums) exceeds
/// $E$; otherwise the unresolved swap with the smallest key is resolved first. The order is
/// then that of sorting the final estimates of every kept swap, while a slot whose first
/// evaluations find an exchange resolves only a few.
struct LazyOrder {
    /// Resolved swaps, by decreasing (estimate, candidate): the next one is last.
    ready: Vec<Screened>,
    /// Unresolved swaps by decreasing key: the next one to resolve is last.
    pending: Vec<(f64, usize)>,
    /// $J(1 - \epsilon)$: a resolved swap whose lower bound is not below it is dropped (as
    /// the screening's list drops it).
    threshold: f64,
}

/// The relative margin of [`LazyOrder`]'s keys below the solver's lower bounds.
const LAZY_KEY_MARGIN: f64 = 1e-12;

impl LazyOrder {
    fn new(list: Vec<(Screened, bool)>, threshold: f64) -> Self {
        let mut ready = Vec::new();
        let mut pending = Vec::new();
        for (s, resolved) in list {
            if resolved {
                ready.push(s);
            } else {
                pending.push((s.lower * (1.0 - LAZY_KEY_MARGIN), s.candidate));
            }
        }
        ready.sort_by(|a, b| Self::cmp(b, a));
        pending.sort_by(|a, b| b.0.total_cmp(&a.0).then(b.1.cmp(&a.1)));
        Self {
            ready,
            pending,
            threshold,
        }
    }

    fn cmp(a: &Screened, b: &Screened) -> std::cmp::Ordering {
        a.estimate
            .total_cmp(&b.estimate)
            .then(a.candidate.cmp(&b.candidate))
    }

    /// The next swap in order, resolving with `resolve` (candidate to its final screening)
    /// the unresolved swaps that could come before it.
    fn next(&mut self, mut resolve: impl FnMut(usize) -> Screened) -> Option<Screened> {
        while let Some(&(key, c)) = self.pending.last() {
            let before = self
                .ready
                .last()
                .is_none_or(|r| key.total_cmp(&r.estimate).is_le());
            if !before {
                break;
            }
            self.pending.pop();
            let s = resolve(c);
            if s.lower >= self.threshold {
                continue;
            }
            let at = self.ready.partition_point(|r| Self::cmp(r, &s).is_gt());
            self.ready.insert(at, s);
        }
        self.ready.pop()
    }
}

/// The largest load of the rows (`R x m`) at `x`.
fn max_load(rows: &[f64], x: &[f64], m: usize) -> f64 {
    rows.chunks(m).map(|r| load(r, x)).fold(0.0, f64::max)
}

/// Load of a signed row (absolute values taken) at `x`.
#[inline]
fn abs_load(row: &[f64], x: &[f64]) -> f64 {
    row.iter()
        .zip(x)
        .map(|(a, u)| if *a == 0.0 { 0.0 } else { a.abs() * u })
        .sum()
}

#[cfg(test)]
mod whole_tests;

#[cfg(test)]
mod tests {
    use super::*;
    use rand_chacha::ChaCha8Rng;
    use rand_core::{Rng, SeedableRng};

    /// [`LazyOrder`] gives the kept swaps in the order of sorting their final estimates (ties:
    /// candidate), as the exchange evaluated them before, on seeded random lists: resolved
    /// and unresolved swaps mixed, final estimates at least the unresolved swaps' lower bounds
    /// (equal ones, ties of estimates, and resolutions whose lower bound reaches the threshold
    /// included), for every prefix the exchange may stop after.
    #[test]
    fn lazy_order_is_the_sorted_order_of_the_final_estimates() {
        let mut rng = ChaCha8Rng::seed_from_u64(21);
        let threshold = 100.0;
        for case in 0..500 {
            let len = 1 + (rng.next_u32() % 40) as usize;
            // (screened as the lazy screening returns it, resolved?, final screening)
            let mut swaps = Vec::new();
            for c in 0..len {
                let lower = f64::from(rng.next_u32() % 50);
                // few distinct values: ties of estimates and of keys
                let estimate = lower + f64::from(rng.next_u32() % 8) * 5.0;
                let resolved = rng.next_u32() % 3 == 0;
                let final_lower = if rng.next_u32() % 20 == 0 {
                    threshold
                } else {
                    lower
                };
                let fin = Screened {
                    candidate: c,
                    lower: final_lower,
                    estimate,
                };
                let early = Screened {
                    candidate: c,
                    lower,
                    estimate: if resolved { estimate } else { estimate + 7.0 },
                };
                swaps.push((early, resolved, fin));
            }
            let mut want: Vec<Screened> = swaps
                .iter()
                .filter(|t| t.1 || t.2.lower < threshold)
                .map(|t| if t.1 { t.0 } else { t.2 })
                .collect();
            want.sort_by(LazyOrder::cmp);
            let stop = (rng.next_u32() as usize) % (want.len() + 1);
            let mut order = LazyOrder::new(swaps.iter().map(|t| (t.0, t.1)).collect(), threshold);
            let mut got = Vec::new();
            while got.len() < stop {
                let Some(s) = order.next(|c| swaps[c].2) else {
                    break;
                };
                got.push(s);
            }
            let key = |s: &Screened| (s.estimate.to_bits(), s.candidate, s.lower.to_bits());
            assert_eq!(
                got.iter().map(key).collect::<Vec<_>>(),
                want[..stop].iter().map(key).collect::<Vec<_>>(),
                "case {case}"
            );
        }
    }
}
