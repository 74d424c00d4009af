//! Direct allocations on which the conic solver stalled (issue 19: `design-schedule --step-deg
//! 7`, `--step-deg 13`, `--positions 300` exited 1 with "conic solver failed on problem
//! direct: InsufficientProgress"). Each fixture is the first such problem of the command,
//! captured from e2e-verify. The core must solve each one, and the answer must be verified
//! independently of the solver: feasible for every row, and optimal by a Lagrangian lower
//! bound built from the KKT multipliers of its active rows.

use alloc_opt::solver::{Cut, FiniteCuts, InverseSquareProblem, solve_inverse_square};
use nalgebra::{DMatrix, DVector};

/// A row counts as active at the solution when its load is within this of 1 (dimensionless):
/// the solution is rescaled to a load in [1 - 1e-13, 1], inactive rows sit far below.
const ACTIVE_LOAD: f64 = 1e-7;

/// The objective may exceed the Lagrangian lower bound by this (relative): the optimum is
/// polished to rounding; the multipliers come from a least-squares fit of the stationarity
/// conditions, which holds to about 1e-12.
const OPTIMALITY_GAP_REL: f64 = 1e-8;

/// A load may exceed 1 by this (rounding of a sum of eight products).
const LOAD_SLACK: f64 = 1e-12;

struct Fixture {
    weights: Vec<f64>,
    lower: Vec<f64>,
    rows: Vec<Cut>,
}

fn fixture(name: &str) -> Fixture {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/fixtures")
        .join(name);
    let text = std::fs::read_to_string(&path).expect("fixture");
    let nums = |s: &str| -> Vec<f64> {
        s.split_whitespace()
            .map(|v| v.parse().expect("number"))
            .collect()
    };
    let (mut weights, mut lower, mut rows) = (Vec::new(), Vec::new(), Vec::new());
    for line in text.lines().filter(|l| !l.starts_with('#')) {
        let (key, rest) = line.split_once(' ').expect("key");
        match key {
            "weights" => weights = nums(rest),
            "lower" => lower = nums(rest),
            "row" => {
                let v = nums(rest);
                rows.push(Cut {
                    coefficients: v[1..].to_vec(),
                    bound: v[0],
                    tag: rows.len() as f64,
                });
            }
            other => panic!("unknown key {other}"),
        }
    }
    Fixture {
        weights,
        lower,
        rows,
    }
}

/// The Lagrangian lower bound $G(\mu)^3$, $G(\mu) = \sum_j (w_j c_j(\mu))^{2/3}$ with
/// $c_j = \sum_r \mu_r a_{rj}/b_r$, for multipliers $\mu \ge 0$ normalised to sum 1 (every
/// lower bound zero): the dual function of $\min \sum_j w_j^2/x_j^2$ s.t.
/// $a_r^T x / b_r \le 1$ (weak duality: a lower bound on the optimum for any such $\mu$).
fn dual_bound(f: &Fixture, mu: &[f64]) -> f64 {
    let total: f64 = mu.iter().sum();
    let n = f.weights.len();
    let g: f64 = (0..n)
        .map(|j| {
            let c: f64 = f
                .rows
                .iter()
                .zip(mu)
                .map(|(r, m)| m / total * r.coefficients[j] / r.bound)
                .sum();
            (f.weights[j] * c).powf(2.0 / 3.0)
        })
        .sum();
    g.powi(3)
}

/// Multipliers of the active rows from the stationarity conditions
/// $2 w_j^2 / x_j^3 = \sum_r \lambda_r a_{rj}/b_r$: the KKT multipliers need not be unique
/// when more rows are active than the columns they separate, so every subset of the active
/// rows is fitted (least squares) and the non-negative fits are returned; each gives a
/// lower bound on the optimum.
fn kkt_multipliers(f: &Fixture, x: &[f64]) -> Vec<Vec<f64>> {
    let n = x.len();
    let active: Vec<usize> = (0..f.rows.len())
        .filter(|&r| f.rows[r].load(x) >= 1.0 - ACTIVE_LOAD)
        .collect();
    assert!(active.len() <= 12, "{} active rows", active.len());
    let g = DVector::from_fn(n, |j, _| 2.0 * f.weights[j].powi(2) / x[j].powi(3));
    let mut out = Vec::new();
    for subset in 1..(1_u32 << active.len()) {
        let rows: Vec<usize> = (0..active.len())
            .filter(|k| subset & (1 << k) != 0)
            .map(|k| active[k])
            .collect();
        let a = DMatrix::from_fn(n, rows.len(), |j, k| {
            let r = &f.rows[rows[k]];
            r.coefficients[j] / r.bound
        });
        let Ok(lambda) = a.svd(true, true).solve(&g, 1e-14) else {
            continue;
        };
        if lambda.iter().all(|&l| l >= 0.0) {
            let mut mu = vec![0.0; f.rows.len()];
            for (k, &r) in rows.iter().enumerate() {
                mu[r] = lambda[k];
            }
            out.push(mu);
        }
    }
    out
}

#[test]
fn direct_allocations_that_stalled_the_conic_solver_are_solved_and_verified_optimal() {
    for name in [
        "stalled-direct-step-13.txt",
        "stalled-direct-step-7.txt",
        "stalled-direct-positions-300.txt",
        "stalled-direct-step-9.txt",
        "stalled-direct-positions-300-b.txt",
    ] {
        let f = fixture(name);
        assert!(
            f.lower.iter().all(|&l| l == 0.0),
            "{name}: the bound below assumes LB = 0"
        );
        let oracle = FiniteCuts::new(f.rows.clone());
        let n = f.weights.len();
        let p = InverseSquareProblem {
            label: "direct".into(),
            names: (0..n).map(|j| format!("e{j}")).collect(),
            weights: f.weights.clone(),
            lower: f.lower.clone(),
            initial_cuts: f.rows.clone(),
            oracle: &oracle,
        };
        let sol = solve_inverse_square(&p).unwrap_or_else(|e| panic!("{name}: {e}"));
        let worst = f.rows.iter().map(|r| r.load(sol.x())).fold(0.0, f64::max);
        assert!(
            worst <= 1.0 + LOAD_SLACK,
            "{name}: a row is loaded to {worst}"
        );
        let bound = kkt_multipliers(&f, sol.x())
            .iter()
            .map(|mu| dual_bound(&f, mu))
            .fold(0.0, f64::max);
        assert!(
            sol.objective() <= bound * (1.0 + OPTIMALITY_GAP_REL),
            "{name}: J = {} above the Lagrangian lower bound {bound}",
            sol.objective()
        );
        assert!(
            sol.objective() >= bound * (1.0 - OPTIMALITY_GAP_REL),
            "{name}: weak duality"
        );
    }
}
