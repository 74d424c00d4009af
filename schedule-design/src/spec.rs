//! The design objective against the study's specifications (issue 34 item 6): with a
//! [`SpecObjective`] every candidate schedule is answered by the direct allocation that holds
//! every specification ([`e2e_verify::EndToEnd::allocate_direct_specified`]: each
//! coefficient's specification in its unit, each end of an operating range, eq 14's rows),
//! with the noise part of each row from the candidate's own noise covariance (its positions,
//! the study's dwell, rate steps and their windows).

use crate::DesignProblem;
use calib_lsq::Position;
use e2e_verify::budget::SpecificationContext;
use e2e_verify::{DirectAllocation, E2eError, EndToEnd, Linearization};

/// What the designer needs to answer a schedule against the specifications: the context
/// (specifications, the table law's uncertainty per unit tolerance, noise, the study's
/// timing) and the rate steps every schedule carries after its static positions.
#[derive(Debug, Clone)]
pub struct SpecObjective {
    context: SpecificationContext,
    rate_steps: Vec<Position>,
}

impl SpecObjective {
    /// The objective of `context` (its timing that of the study: every dwell the same, so
    /// that it carries over to any number of positions; the rate steps' windows kept) with
    /// `rate_steps` after the static positions of every schedule.
    #[must_use]
    pub fn new(context: SpecificationContext, rate_steps: Vec<Position>) -> Self {
        Self {
            context,
            rate_steps,
        }
    }

    /// The specifications' context.
    #[must_use]
    pub fn context(&self) -> &SpecificationContext {
        &self.context
    }

    /// The context for a schedule of `n` static positions: the study's timing with `n`
    /// dwells.
    ///
    /// # Errors
    /// [`E2eError::Field`] naming `calibration.timing.dwell_s` when the study's dwells differ
    /// (a per-position dwell does not carry over to other positions).
    fn context_for(&self, n: usize) -> Result<SpecificationContext, E2eError> {
        match self.context.timing() {
            None => Ok(self.context.clone()),
            Some(t) if t.positions() == n && !t.is_uniform() => Ok(self.context.clone()),
            Some(t) => match t.with_len(n) {
                Some(t) => Ok(self.context.with_timing(Some(t))),
                None => Err(E2eError::Field(tt_core::FieldError::OutOfRange {
                    field: "calibration.timing.dwell_s".into(),
                    value: n as f64,
                    range:
                        "one dwell for every position (the designer carries it to other schedules)"
                            .into(),
                })),
            },
        }
    }
}

/// A schedule answered against the specifications.
pub(crate) struct SpecAnswer {
    /// The simulator of the schedule (static positions, then the rate steps).
    pub e2e: EndToEnd,
    /// Its linearisation (eq 14's rows of every entry).
    pub linear: Linearization,
    /// The specification rows.
    pub rows: Vec<e2e_verify::budget::SpecificationRow>,
    /// The specified direct allocation; `None` when no table suffices (the lower bounds alone
    /// break a row, or a specification's noise part fills its limit).
    pub allocation: Option<DirectAllocation>,
    /// The context the rows were computed with (the schedule's timing).
    pub context: SpecificationContext,
    /// The number of static positions (the rate steps' entries follow).
    pub n_static: usize,
}

impl DesignProblem {
    /// The same problem with `objective`: every schedule is then answered by the direct
    /// allocation that holds every specification ([`DesignProblem::evaluate`]).
    #[must_use]
    pub fn with_specifications(mut self, objective: Option<SpecObjective>) -> Self {
        self.specs = objective.map(std::sync::Arc::new);
        self
    }

    /// The specifications the design is for, if any.
    #[must_use]
    pub fn specifications(&self) -> Option<&SpecObjective> {
        self.specs.as_deref()
    }

    /// The schedule `positions_deg` (static positions, deg) answered against the
    /// specifications, through the same path as `end-to-end` (the schedule's simulator,
    /// [`EndToEnd::specification_rows`], [`EndToEnd::allocate_direct_specified`], with the
    /// problem's weights, which are [`EndToEnd::combined_weights`]); `None` without
    /// specifications.
    ///
    /// # Errors
    /// As [`DesignProblem::end_to_end_with_rate_steps`] and
    /// [`EndToEnd::specification_rows`]; the allocation's errors other than "no table
    /// suffices".
    pub(crate) fn spec_answer(
        &self,
        positions_deg: &[Vec<f64>],
    ) -> Result<Option<SpecAnswer>, E2eError> {
        let Some(spec) = self.specs.as_deref() else {
            return Ok(None);
        };
        let e2e = self.end_to_end_with_rate_steps(positions_deg, &spec.rate_steps)?;
        let ctx = spec.context_for(positions_deg.len())?;
        let rows = e2e.budget().specification_rows(&ctx)?;
        let linear = e2e.linearization();
        // the objective's weights depend on the turntable alone: the problem's, computed once
        // (the same as `e2e.combined_weights()`, bit for bit), not averaged again per schedule
        let allocation = match e2e.allocate_direct_specified_weighted(
            &self.weights,
            &linear,
            &self.lower_bounds_rad,
            &rows,
        ) {
            Ok(a) => Some(a),
            Err(E2eError::InfeasibleLowerBounds { .. } | E2eError::NoTableSuffices { .. }) => None,
            Err(e) => return Err(e),
        };
        Ok(Some(SpecAnswer {
            e2e,
            linear,
            rows,
            allocation,
            context: ctx,
            n_static: positions_deg.len(),
        }))
    }
}

/// One specification row with weights (a coefficient, an end of an operating range) as the
/// screening updates it after a swap: its output, its weights over that output's
/// coefficients, its factors divided by the limit and by the room of the answered schedule
/// (the exact row, for its multiplier), its limit and coverage factor (the room after a swap
/// is the limit less the swapped schedule's noise part).
#[derive(Debug, Clone)]
pub(crate) struct ScreenRow {
    pub output: usize,
    pub weights: Vec<f64>,
    pub per_limit: Vec<f64>,
    pub per_room: Vec<f64>,
    /// The limit $L$ and the coverage factor $k$ of the noise part.
    pub limit: f64,
    pub coverage: f64,
}

/// What the screening needs of a schedule answered against the specifications: per output
/// $\mathbf G = (\mathbf A^T\mathbf A)^{-1}$ of the whole schedule (rate steps included,
/// $p \times p$ row-major) and the coefficients' sensitivities $\mathbf H_s = \mathbf A^+
/// (d\mathbf G + d\mathbf E)$ ($p \times m$ row-major,
/// [`EndToEnd::coefficient_linearization`]), and the rows with weights. A swap updates
/// $\mathbf H_s$ by the same Woodbury formula as eq 14's rows.
#[derive(Debug, Clone)]
pub(crate) struct SpecScreen {
    pub gram_inv: Vec<Vec<f64>>,
    pub hs: Vec<Vec<f64>>,
    pub rows: Vec<ScreenRow>,
    /// Per output: the covariance of the entries' averages (white plus correlated, one per
    /// entry in the schedule's order, row-major; `None`: no noise), which depends on the
    /// timing only, so a swap (same slots, same windows) keeps it.
    pub sigma: Vec<Option<Vec<f64>>>,
    /// Per output: the regressor rows of the rate steps' entries ($p$ each, row-major).
    pub a_rate: Vec<Vec<f64>>,
    /// Eq 14's rows of the whole schedule, rate steps' entries included (`None` without rate
    /// steps: the screening's own rows are then the whole schedule's).
    pub whole: Option<WholeRows>,
}

/// Eq 14's rows of the whole schedule (the static positions, then the rate steps' entries),
/// the rows the specified allocation holds: row $q$ of output $k$ is
/// $(\mathbf b_q + d\,\mathbf a_q^T\mathbf H_s)/\omega_k$ with $\mathbf H_s = \mathbf A^+
/// (d\mathbf G + d\mathbf E)$ of the whole schedule ([`SpecScreen::hs`]) and $\mathbf b_q =
/// c_g\,d\mathbf g_q + c_e\,d\mathbf e_q$ (the reading's affine form), so that a swap changes
/// them through $\mathbf H_s'$ alone (the Woodbury update of the specification rows).
#[derive(Debug, Clone)]
pub(crate) struct WholeRows {
    /// $|\mathbf M|/\omega_k$ of every entry of the answered schedule, output-major (row
    /// $(k, q)$ at `(k * entries + q) * m`).
    pub rows: Vec<f64>,
    /// Per output: $\mathbf b_q/\omega_k$ of the rate steps' entries (signed, $m$ each,
    /// row-major), $\mathbf M$'s row less its projection part.
    pub b_rate: Vec<Vec<f64>>,
    /// Per output: $d/\omega_k$, the factor of $\mathbf a_q^T\mathbf H_s$ in a row.
    pub d_per_accuracy: Vec<f64>,
    /// The entries of the whole schedule (positions, then the rate steps' entries).
    pub entries: usize,
}

impl SpecScreen {
    /// The screening data of `a`, with $d$ of the reading's affine form and the outputs'
    /// accuracies $\omega_k$ (for the whole schedule's eq 14 rows).
    pub(crate) fn of(a: &SpecAnswer, d: f64, accuracies: &[f64]) -> Self {
        let outputs = a.e2e.calibration().outputs();
        let gram_inv = outputs
            .iter()
            .map(|o| {
                let pinv = o.regression().pinv();
                let g = pinv * pinv.transpose();
                g.transpose().as_slice().to_vec()
            })
            .collect();
        let hs: Vec<Vec<f64>> = a
            .e2e
            .coefficient_linearization()
            .iter()
            .map(|h| h.transpose().as_slice().to_vec())
            .collect();
        let n_static = a.n_static;
        let sigma = outputs
            .iter()
            .enumerate()
            .map(|(k, _)| {
                let t = a.context.timing()?;
                let m = a.context.noise().get(k)?.as_ref()?;
                let w = m.window_covariance(&t.windows(), t.sample_rate_hz()).ok()?;
                let total = w.white() + w.correlated();
                Some(total.transpose().as_slice().to_vec())
            })
            .collect();
        let a_rate = outputs
            .iter()
            .map(|o| {
                let a = o.regression().matrix();
                a.rows(n_static, a.nrows() - n_static)
                    .transpose()
                    .as_slice()
                    .to_vec()
            })
            .collect();
        let rows = a
            .rows
            .iter()
            .filter_map(|r| {
                let w = r.weights()?;
                let per = |d: f64| r.factors().iter().map(|f| f / d).collect::<Vec<f64>>();
                let room = r.room();
                Some(ScreenRow {
                    output: r.output(),
                    weights: w.to_vec(),
                    per_limit: per(r.limit()),
                    per_room: if room > 0.0 {
                        per(room)
                    } else {
                        per(r.limit())
                    },
                    limit: r.limit(),
                    coverage: r.coverage_factor(),
                })
            })
            .collect();
        let whole = (a.e2e.len() > n_static).then(|| WholeRows::of(a, &hs, d, accuracies));
        Self {
            gram_inv,
            hs,
            rows,
            sigma,
            a_rate,
            whole,
        }
    }

    /// Row `r` of the specifications for sensitivities `hs` (per output, $p \times m$),
    /// normalised by `per` (`per_limit` or `per_room`), in absolute value, into `out`.
    pub(crate) fn row(&self, r: usize, hs: &[Vec<f64>], limit: bool, out: &mut [f64]) {
        let row = &self.rows[r];
        let h = &hs[row.output];
        let m = out.len();
        out.fill(0.0);
        for (t, w) in row.weights.iter().enumerate() {
            if *w == 0.0 {
                continue;
            }
            for (v, hv) in out.iter_mut().zip(&h[t * m..(t + 1) * m]) {
                *v += w * hv;
            }
        }
        let per = if limit { &row.per_limit } else { &row.per_room };
        for (v, f) in out.iter_mut().zip(per) {
            *v = f * v.abs();
        }
    }
}

impl WholeRows {
    /// The rows of `a` (its sensitivities `hs`, per output $p \times m$ row-major).
    fn of(a: &SpecAnswer, hs: &[Vec<f64>], d: f64, accuracies: &[f64]) -> Self {
        let m = a.linear.matrix().ncols();
        let entries = a.linear.positions();
        let mut rows = Vec::with_capacity(a.linear.matrix().nrows() * m);
        for (r, row) in a.linear.matrix().row_iter().enumerate() {
            let w = 1.0 / accuracies[r / entries];
            rows.extend(row.iter().map(|v| v.abs() * w));
        }
        let d_per_accuracy: Vec<f64> = accuracies.iter().map(|w| d / w).collect();
        let mut b_rate = Vec::with_capacity(accuracies.len());
        for (k, o) in a.e2e.calibration().outputs().iter().enumerate() {
            let reg = o.regression().matrix();
            let h = &hs[k];
            let mut b = Vec::with_capacity((entries - a.n_static) * m);
            for q in a.n_static..entries {
                for j in 0..m {
                    let ah: f64 = reg
                        .row(q)
                        .iter()
                        .enumerate()
                        .map(|(t, v)| v * h[t * m + j])
                        .sum();
                    b.push(
                        a.linear.matrix()[(k * entries + q, j)] / accuracies[k]
                            - d_per_accuracy[k] * ah,
                    );
                }
            }
            b_rate.push(b);
        }
        Self {
            rows,
            b_rate,
            d_per_accuracy,
            entries,
        }
    }
}
