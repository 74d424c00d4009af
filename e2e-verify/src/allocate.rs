//! Allocation against the calibration accuracy itself: direct (worst case of
//! $\Delta\omega$ over the box $\le \omega_m$ at every position) and yield-based (a chosen
//! fraction of the turntables in the box meet $\omega_m$).

use crate::answer::objective_to_arcmin;
use crate::error::{E2eError, fraction, positive};
use crate::linear::Linearization;
use crate::montecarlo::{McSettings, quantile_index, wilson_interval_95};
use crate::simulate::{AXES, EndToEnd};
use alloc_opt::solver::{Cut, FiniteCuts, InverseSquareProblem, solve_inverse_square};
use alloc_opt::{TIGHT_REL, Weights};
use gw_model::SensingAxis;
use mc_verify::ErrorBox;
use tt_kinematics::units::rad_to_arcmin;
use tt_kinematics::{CHI_LEN, ErrorComponent, LinearModel};

/// Bisection steps on the scale when the lower bounds are positive (relative bracket
/// $2^{-40} \approx 10^{-12}$).
pub const YIELD_BISECTION_STEPS: usize = 40;

/// Maximum solves of [`EndToEnd::allocate_direct_certified`] (two suffice: the bound shrinks
/// with the box).
pub const CERTIFY_STEPS: usize = 6;

/// Maximum fixed-point steps of the scale when $\mathrm{LB} = 0$ (each one Monte Carlo pass;
/// two or three reach $10^{-12}$).
pub const YIELD_FIXED_POINT_STEPS: usize = 4;

/// Relative margin taken off the fixed-point scale so that the draw at the quantile lands on
/// the safe side of $\omega_m$ despite rounding (dimensionless).
pub const YIELD_SCALE_MARGIN: f64 = 1e-9;

/// The default yield target: 99.73% (the $3\sigma$ fraction of a normal law).
pub const DEFAULT_YIELD_FRACTION: f64 = 0.9973;

/// The paper's combined weights $w_j = \sqrt{\sum_k W_{kj}^2}$ with
/// $W_{kj} = 1/\overline{|\partial f_k/\partial\chi_j|}$ (eq 28, Figure 8): then
/// $\sum_j w_j^2/\mathrm{UB}_j^2$ equals alloc-opt's $J = J_\psi + J_\theta + J_\gamma$
/// ([`Weights::objective`]), so a component that appears in two angles (e.g.
/// $\Delta\phi_{y1}$ in $\psi$ and $\gamma$) counts twice, exactly as in the two-step
/// allocation, and the objectives are comparable. For eq 26: $w = \pi/\sqrt2$ for the four
/// shared components, 1 for the others.
#[must_use]
pub fn paper_combined_weights() -> [f64; CHI_LEN] {
    let w = Weights::inverse_average_sensitivity(&LinearModel::paper_eq26()).matrix();
    std::array::from_fn(|j| w.column(j).norm())
}

/// $J(\mathrm{UB}) = \sum_j w_j^2/\mathrm{UB}_j^2$ with [`paper_combined_weights`]
/// (rad$^{-2}$ for bounds in radians).
#[must_use]
pub fn paper_objective(ub_rad: &[f64; CHI_LEN]) -> f64 {
    paper_combined_weights()
        .iter()
        .zip(ub_rad)
        .map(|(w, u)| (w / u).powi(2))
        .sum()
}

/// $J$ in arcmin$^{-2}$ (bounds in arcminutes, the scale of Table 4).
#[must_use]
pub fn paper_objective_arcmin(ub_rad: &[f64; CHI_LEN]) -> f64 {
    objective_to_arcmin(paper_objective(ub_rad))
}

/// One row (axis, position) of the direct allocation's constraints.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RowLoad {
    /// The axis.
    pub axis: SensingAxis,
    /// Position index in the schedule.
    pub position: usize,
    /// $\sum_j |M_{rj}|\,\mathrm{UB}_j / \omega_m$ (1 = the whole requirement used).
    pub load: f64,
}

/// The direct allocation's result.
#[derive(Debug, Clone, PartialEq)]
pub struct DirectAllocation {
    /// $\mathrm{UB}$ (rad, order of eq 25).
    pub upper_bounds_rad: [f64; CHI_LEN],
    /// The lower bounds used (rad).
    pub lower_bounds_rad: [f64; CHI_LEN],
    /// $\omega_m$ (rad/s).
    pub omega_m_rad_per_s: f64,
    /// $J$ (rad$^{-2}$), see [`paper_objective`].
    pub objective: f64,
    /// The load of every row, $x$ rows then $y$ rows.
    pub loads: Vec<RowLoad>,
    /// Sum of the Lagrange multipliers of the rows (units of $J$).
    pub multiplier: f64,
    /// Conic solves of the exchange method.
    pub iterations: usize,
    /// Room kept for the exact chain's second-order terms, rad/s: the rows are constrained to
    /// $\omega_m - $ this (0 for [`EndToEnd::allocate_direct`]; the derived bound $\tau$ of
    /// [`EndToEnd::second_order_bound`] for [`EndToEnd::allocate_direct_certified`]).
    pub second_order_margin_rad_per_s: f64,
}

impl DirectAllocation {
    /// $\mathrm{UB}$ in arcminutes.
    #[must_use]
    pub fn upper_bounds_arcmin(&self) -> [f64; CHI_LEN] {
        self.upper_bounds_rad.map(rad_to_arcmin)
    }

    /// $J$ in arcmin$^{-2}$.
    #[must_use]
    pub fn objective_arcmin(&self) -> f64 {
        objective_to_arcmin(self.objective)
    }

    /// The active rows: load $\ge 1 -$ [`TIGHT_REL`].
    #[must_use]
    pub fn active_rows(&self) -> Vec<RowLoad> {
        self.loads
            .iter()
            .copied()
            .filter(|r| r.load >= 1.0 - TIGHT_REL)
            .collect()
    }
}

/// The yield-based allocation's result.
#[derive(Debug, Clone, PartialEq)]
pub struct YieldAllocation {
    /// $\mathrm{UB} = s^*\,\mathrm{UB}_{shape}$ (rad).
    pub upper_bounds_rad: [f64; CHI_LEN],
    /// The shape (rad): the direct allocation's bounds.
    pub shape_rad: [f64; CHI_LEN],
    /// The scale $s^*$.
    pub scale: f64,
    /// The target fraction $p$.
    pub target: f64,
    /// $J$ (rad$^{-2}$).
    pub objective: f64,
    /// Design draws.
    pub samples: u64,
    /// Seed of the design draws.
    pub seed: u64,
    /// Design draws meeting $\omega_m$ at $s^*$ (re-evaluated on the exact chain).
    pub meeting: u64,
    /// The 95% Wilson interval of the yield at $s^*$ (from the design draws): the stated
    /// confidence of the allocation.
    pub interval_95: (f64, f64),
}

impl YieldAllocation {
    /// $\mathrm{UB}$ in arcminutes.
    #[must_use]
    pub fn upper_bounds_arcmin(&self) -> [f64; CHI_LEN] {
        self.upper_bounds_rad.map(rad_to_arcmin)
    }

    /// $J$ in arcmin$^{-2}$.
    #[must_use]
    pub fn objective_arcmin(&self) -> f64 {
        objective_to_arcmin(self.objective)
    }

    /// The design yield at $s^*$.
    #[must_use]
    pub fn yield_fraction(&self) -> f64 {
        self.meeting as f64 / self.samples as f64
    }
}

impl EndToEnd {
    /// Direct allocation against $\omega_m$ itself.
    ///
    /// # Formula
    /// $$\min_{\mathrm{UB}} \sum_j \frac{w_j^2}{\mathrm{UB}_j^2}\quad\text{s.t.}\quad
    /// \sum_j |M_{rj}|\,\mathrm{UB}_j \le \omega_m\ \ \forall r \in \{x, y\}\times\{1..n\},
    /// \qquad \mathrm{UB} \ge \mathrm{LB},$$
    /// with the paper's weights ([`paper_combined_weights`]) and the linearised rate errors
    /// $\mathbf M$: $2n$ linear constraints with non-negative coefficients, solved by
    /// alloc-opt's power-cone core ([`solve_inverse_square`] with [`FiniteCuts`]).
    ///
    /// # Reference
    /// The objective of problems (31)-(33) (eq 28 weights) with the requirement of eq 14 in
    /// place of eq 15; an extension of the paper.
    ///
    /// # Errors
    /// [`E2eError::NotPositive`] naming `omega_m`; [`E2eError::Bounds`] for bad lower bounds;
    /// [`E2eError::InfeasibleLowerBounds`] naming the row; [`E2eError::Alloc`] if the solver
    /// fails or a component is unconstrained.
    pub fn allocate_direct(
        &self,
        linear: &Linearization,
        omega_m_rad_per_s: f64,
        lower_bounds_rad: &[f64; CHI_LEN],
    ) -> Result<DirectAllocation, E2eError> {
        let omega_m = positive("omega_m", omega_m_rad_per_s)?;
        ErrorBox::new(*lower_bounds_rad, lower_bounds_rad.map(|v| v.max(0.0)))?;
        let n = self.len();
        let lb_rows = linear.row_worst_cases(lower_bounds_rad);
        for (r, v) in lb_rows.iter().enumerate() {
            if *v > omega_m {
                return Err(E2eError::InfeasibleLowerBounds {
                    axis: AXES[r / n].name(),
                    position: r % n,
                    worst_rad_per_s: *v,
                    omega_m_rad_per_s: omega_m,
                });
            }
        }
        let rows: Vec<Cut> = linear
            .matrix()
            .row_iter()
            .enumerate()
            .map(|(r, row)| Cut {
                coefficients: row.iter().map(|v| v.abs()).collect(),
                bound: omega_m,
                tag: r as f64,
            })
            .collect();
        let oracle = FiniteCuts::new(rows.clone());
        let problem = InverseSquareProblem {
            label: "direct".into(),
            names: ErrorComponent::ALL
                .iter()
                .map(|c| c.name().to_string())
                .collect(),
            weights: paper_combined_weights().to_vec(),
            lower: lower_bounds_rad.to_vec(),
            initial_cuts: rows,
            oracle: &oracle,
        };
        let sol = solve_inverse_square(&problem)?;
        let mut ub = [0.0; CHI_LEN];
        ub.copy_from_slice(&sol.x);
        let loads = linear
            .row_worst_cases(&ub)
            .iter()
            .enumerate()
            .map(|(r, v)| RowLoad {
                axis: AXES[r / n],
                position: r % n,
                load: v / omega_m,
            })
            .collect();
        Ok(DirectAllocation {
            upper_bounds_rad: ub,
            lower_bounds_rad: *lower_bounds_rad,
            omega_m_rad_per_s: omega_m,
            objective: paper_objective(&ub),
            loads,
            multiplier: sol.multiplier,
            iterations: sol.iterations,
            second_order_margin_rad_per_s: 0.0,
        })
    }

    /// Direct allocation certified on the exact chain: the linearised rows are held to
    /// $\omega_m - \tau$, with $\tau$ the derived second-order bound
    /// ([`EndToEnd::second_order_bound`], larger of the two axes) at $s = \sum_j
    /// \mathrm{UB}_j$ of the previous iterate, until $\max_r \sum_j |M_{rj}|\mathrm{UB}_j +
    /// \tau(\sum_j\mathrm{UB}_j) \le \omega_m$: then every turntable of the box meets
    /// $\omega_m$ on the exact chain, not only to first order. $\tau$ shrinks with the bounds,
    /// so the iteration is monotone; it stops after at most [`CERTIFY_STEPS`] solves.
    ///
    /// # Errors
    /// As [`allocate_direct`](Self::allocate_direct); [`E2eError::OutOfRange`] naming
    /// `reading` when the reading has no derived bound.
    pub fn allocate_direct_certified(
        &self,
        linear: &Linearization,
        omega_m_rad_per_s: f64,
        lower_bounds_rad: &[f64; CHI_LEN],
    ) -> Result<DirectAllocation, E2eError> {
        let omega_m = positive("omega_m", omega_m_rad_per_s)?;
        let tau_of = |ub: &[f64; CHI_LEN]| -> Result<f64, E2eError> {
            let s: f64 = ub.iter().sum();
            let mut t = 0.0_f64;
            for axis in AXES {
                t = t.max(self.second_order_bound(axis, s)?.ok_or(E2eError::OutOfRange {
                    field: "reading",
                    value: f64::NAN,
                    range: "readings with a derived second-order bound (user's estimate beta1, printed or nominal-rate form, or intended outputs)",
                })?);
            }
            Ok(t)
        };
        let mut d = self.allocate_direct(linear, omega_m, lower_bounds_rad)?;
        for _ in 0..CERTIFY_STEPS {
            let tau = tau_of(&d.upper_bounds_rad)?;
            let worst = linear.row_worst_cases(&d.upper_bounds_rad).max();
            if worst + tau <= omega_m {
                break;
            }
            d = self.allocate_direct(linear, omega_m - tau, lower_bounds_rad)?;
            d.second_order_margin_rad_per_s = tau;
        }
        // Loads against the real omega_m.
        for r in &mut d.loads {
            r.load *= d.omega_m_rad_per_s / omega_m;
        }
        d.omega_m_rad_per_s = omega_m;
        Ok(d)
    }

    /// Yield-based allocation: keep the shape $\mathrm{UB}_{shape}$ (e.g. the direct
    /// allocation) and take the largest scale $s^*$ whose estimated yield is at least
    /// `target`.
    ///
    /// # Formula
    /// With $\mathrm{LB} = 0$ the box scales with $s$ and the draws of a stream scale with it
    /// ($\chi(s) = s\,\chi(1)$ for the same random words), and the rate errors are homogeneous
    /// of degree 1 in $\chi$ to first order, so $s^* = \omega_m / q_p$ where $q_p$ is the
    /// empirical $p$-quantile (the $\lceil pN\rceil$-th order statistic) of
    /// $\max(\Delta\omega_x, \Delta\omega_y)$ over $N$ draws at $s = 1$ on the exact chain;
    /// the exact chain's second-order curvature is absorbed by iterating
    /// $s \leftarrow s\,\omega_m/q_p(s)$ ([`YIELD_FIXED_POINT_STEPS`]) and taking
    /// [`YIELD_SCALE_MARGIN`] off, so that at least $\lceil pN\rceil$ design draws meet
    /// $\omega_m$.
    /// With positive lower bounds the scale is bisected ([`YIELD_BISECTION_STEPS`] steps) with
    /// common random numbers (same seed at every $s$) on
    /// $s \in [\max_j \mathrm{LB}_j/\mathrm{UB}_{shape,j}, s_{hi}]$. The yield at $s^*$ is
    /// re-evaluated on the design draws and stated with its 95% Wilson interval.
    ///
    /// # Errors
    /// [`E2eError::FractionOutOfRange`] naming `yield_fraction`; [`E2eError::NotPositive`]
    /// naming `omega_m` or `shape.<component>`; [`E2eError::Bounds`];
    /// [`E2eError::YieldUnreachable`]; as [`McSettings::validate`].
    pub fn allocate_yield(
        &self,
        shape_rad: &[f64; CHI_LEN],
        lower_bounds_rad: &[f64; CHI_LEN],
        omega_m_rad_per_s: f64,
        target: f64,
        settings: &McSettings,
    ) -> Result<YieldAllocation, E2eError> {
        let p = fraction("yield_fraction", target)?;
        let omega_m = positive("omega_m", omega_m_rad_per_s)?;
        for c in ErrorComponent::ALL {
            positive(&format!("shape.{}", c.name()), shape_rad[c.index()])?;
        }
        settings.validate()?;
        ErrorBox::new(*lower_bounds_rad, lower_bounds_rad.map(|v| v.max(0.0)))?;
        let scaled = |s: f64| -> [f64; CHI_LEN] { std::array::from_fn(|j| s * shape_rad[j]) };
        let count = |s: f64| -> Result<u64, E2eError> {
            let b = ErrorBox::new(*lower_bounds_rad, scaled(s))?;
            Ok(self
                .sample_rates(&b, settings)?
                .iter()
                .filter(|d| d.meets(omega_m))
                .count() as u64)
        };
        let need = (p * settings.samples as f64).ceil() as u64;
        let scale = if lower_bounds_rad.iter().all(|&l| l == 0.0) {
            // Fixed point s <- s * omega_m / q_p(s): q_p(s) / s is constant to first order, so
            // one step is exact to second order and a few more absorb the exact chain's
            // curvature; then a hair of margin so that the boundary draw counts.
            let mut s = 1.0;
            for _ in 0..YIELD_FIXED_POINT_STEPS {
                let b = ErrorBox::from_upper_rad(scaled(s))?;
                let mut q: Vec<f64> = self
                    .sample_rates(&b, settings)?
                    .iter()
                    .map(crate::montecarlo::TurntableDraw::max_rad_per_s)
                    .collect();
                q.sort_by(f64::total_cmp);
                let next = s * omega_m / q[quantile_index(p, q.len())];
                let done = (next / s - 1.0).abs() < 1e-12;
                s = next;
                if done {
                    break;
                }
            }
            let mut s = s * (1.0 - YIELD_SCALE_MARGIN);
            while count(s)? < need && s > 0.0 {
                s *= 1.0 - 1e3 * YIELD_SCALE_MARGIN;
            }
            s
        } else {
            let s_lo = (0..CHI_LEN)
                .map(|j| lower_bounds_rad[j] / shape_rad[j])
                .fold(0.0, f64::max);
            let best = count(s_lo)?;
            if best < need {
                return Err(E2eError::YieldUnreachable {
                    target: p,
                    best: best as f64 / settings.samples as f64,
                });
            }
            let mut hi = s_lo.max(1.0);
            while count(hi)? >= need {
                hi *= 2.0;
            }
            let mut lo = s_lo;
            for _ in 0..YIELD_BISECTION_STEPS {
                let mid = 0.5 * (lo + hi);
                if count(mid)? >= need {
                    lo = mid;
                } else {
                    hi = mid;
                }
            }
            lo
        };
        let ub = scaled(scale);
        let meeting = count(scale)?;
        Ok(YieldAllocation {
            upper_bounds_rad: ub,
            shape_rad: *shape_rad,
            scale,
            target: p,
            objective: paper_objective(&ub),
            samples: settings.samples,
            seed: settings.seed,
            meeting,
            interval_95: wilson_interval_95(meeting, settings.samples),
        })
    }
}
