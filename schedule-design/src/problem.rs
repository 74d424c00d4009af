//! The candidate set with everything precomputed, and the exact evaluation of a schedule.

use super::Evaluation;
use calib_lsq::{CalibError, Reading, ReadingWork, Regression};
use e2e_verify::E2eError;
use e2e_verify::Linearization;
use e2e_verify::internals::DirectSetup;
use e2e_verify::internals::{DerivativeTerms, directional};
use gw_model::{InputValues, SensorModel, Site};
use nalgebra::{DMatrix, Vector3};
use tt_kinematics::{LinearModel, Pose, Turntable};

/// The first-order error vector of every reading is affine in the per-position derivative
/// blocks: $\mathbf M = c_g\,d\mathbf G + c_e\,d\mathbf E + d\,\mathbf P(d\mathbf G + d\mathbf E)$
/// with $\mathbf P = \mathbf A\mathbf A^+$ (see the [module](super) docs). The three scalars
/// are read off the one evaluation of the readings ([`Reading::error_vector`]) on a
/// two-position probe, never re-derived by hand.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Affine {
    pub c_g: f64,
    pub c_e: f64,
    pub d: f64,
}

impl Affine {
    /// Probe `reading` with $\mathbf A = (1, 0)^T$, so $\mathbf P = \operatorname{diag}(1, 0)$:
    /// position 2 gives $c_g$ and $c_e$, position 1 gives $c_g + d$.
    pub(crate) fn of(reading: Reading) -> Self {
        let a = DMatrix::from_column_slice(2, 1, &[1.0, 0.0]);
        let pinv = DMatrix::from_row_slice(1, 2, &[1.0, 0.0]);
        let eval = |dg: [f64; 2], de: [f64; 2]| -> [f64; 2] {
            let t = DerivativeTerms {
                a: &a,
                pinv: &pinv,
                de: de.to_vec(),
                dg: dg.to_vec(),
            };
            let mut out = [0.0; 2];
            reading.error_vector(&t, &mut ReadingWork::default(), &mut out);
            out
        };
        let c_g = eval([0.0, 1.0], [0.0, 0.0])[1];
        let c_e = eval([0.0, 0.0], [0.0, 1.0])[1];
        let d = eval([1.0, 0.0], [0.0, 0.0])[0] - c_g;
        Self { c_g, c_e, d }
    }

    /// Whether $\mathbf M$ does not depend on the schedule ($d = 0$): each position's rows are
    /// then fixed, and $J$ can only grow when positions are added.
    pub(crate) fn is_static(&self) -> bool {
        self.d == 0.0
    }
}

/// Per output: the candidates' regressor rows and derivative blocks.
#[derive(Debug, Clone)]
pub(crate) struct OutputData {
    /// Number of estimated coefficients $p$.
    pub p: usize,
    /// Regressor rows $\mathbf a_c$ at the nominal inputs, candidate-major ($C \times p$).
    pub a: Vec<f64>,
    /// $d\mathbf e_c$: the known part's first variation per angular error ($C \times m$).
    pub de: Vec<f64>,
    /// $d\mathbf g_c$: the estimated part's first variation per angular error ($C \times m$).
    pub dg: Vec<f64>,
    /// $(c_g\,d\mathbf g_c + c_e\,d\mathbf e_c)/\omega_m$ ($C \times m$).
    pub c0: Vec<f64>,
    /// $d\,(d\mathbf g_c + d\mathbf e_c)/\omega_m$ ($C \times m$).
    pub c1: Vec<f64>,
}

impl OutputData {
    #[inline]
    pub(crate) fn a_row(&self, c: usize) -> &[f64] {
        &self.a[c * self.p..(c + 1) * self.p]
    }
}

/// A schedule design problem: a turntable, a sensor at a site, a reading of eq 13, lower
/// bounds and a candidate set of positions, with everything that does not change between
/// schedules computed once per candidate (nominal orientation and inputs, regressor rows,
/// first-order rotation vectors of every error, derivative blocks of every output).
#[derive(Debug, Clone)]
pub struct DesignProblem {
    pub(crate) turntable: Turntable,
    pub(crate) sensor: SensorModel,
    pub(crate) site: Site,
    pub(crate) reading: Reading,
    pub(crate) lower_bounds_rad: Vec<f64>,
    pub(crate) weights: Vec<f64>,
    pub(crate) accuracies: Vec<f64>,
    pub(crate) output_names: Vec<String>,
    pub(crate) coefficient_names: Vec<Vec<String>>,
    pub(crate) candidates_deg: Vec<Vec<f64>>,
    pub(crate) errors: usize,
    pub(crate) outputs: Vec<OutputData>,
    pub(crate) affine: Affine,
    pub(crate) search: crate::SearchParams,
    /// The specifications every schedule is answered against (`None`: eq 14's rows only).
    pub(crate) specs: Option<std::sync::Arc<crate::spec::SpecObjective>>,
}

impl DesignProblem {
    /// Prepare the design over `candidates_deg` (joint angles in degrees, joint order).
    ///
    /// # Errors
    /// [`E2eError::EmptyCandidates`]; [`E2eError::Field`] (out of range) naming `candidates` above
    /// [`super::MAX_CANDIDATES`]; [`E2eError::Kinematics`] for a candidate that does
    /// not fit the turntable (wrong length, non-finite); [`E2eError::CandidateOutsideRange`]
    /// outside a joint range;
    /// [`E2eError::UnidentifiableCandidates`] naming the first output and the coefficients
    /// that no schedule drawn from the candidates can identify; [`E2eError::Bounds`] for bad
    /// lower bounds.
    pub fn new(
        turntable: &Turntable,
        sensor: &SensorModel,
        site: &Site,
        reading: Reading,
        lower_bounds_rad: &[f64],
        candidates_deg: Vec<Vec<f64>>,
    ) -> Result<Self, E2eError> {
        if candidates_deg.is_empty() {
            return Err(E2eError::EmptyCandidates);
        }
        if candidates_deg.len() > super::MAX_CANDIDATES {
            return Err(E2eError::Field(tt_core::FieldError::OutOfRange {
                field: "candidates".into(),
                value: candidates_deg.len() as f64,
                range: "at most 50000 candidate positions".into(),
            }));
        }
        e2e_verify::internals::check_lower_bounds(turntable, lower_bounds_rad)?;
        let ranges = turntable.joint_ranges_rad();
        let model = LinearModel::new(turntable);
        let errors = turntable.n_rotation_errors();
        let mut nominal = Vec::with_capacity(candidates_deg.len());
        let mut vectors = Vec::with_capacity(candidates_deg.len());
        for (c, deg) in candidates_deg.iter().enumerate() {
            let pose = Pose::from_deg(deg)?;
            turntable.check_pose(&pose)?;
            for (j, (&a, [lo, hi])) in pose.angles_rad().iter().zip(&ranges).enumerate() {
                if a < lo - 1e-12 || a > hi + 1e-12 {
                    return Err(E2eError::CandidateOutsideRange {
                        candidate: c,
                        joint: turntable.joint_names()[j].to_string(),
                        angle_deg: deg[j],
                    });
                }
            }
            let rd = turntable.nominal_rotation(&pose)?;
            nominal.push(InputValues::from_inputs(&site.inputs(&rd)));
            vectors.push(model.rotation_vectors(&pose)?);
        }
        let affine = Affine::of(reading);
        let mut outputs = Vec::with_capacity(sensor.n_outputs());
        let mut coefficient_names = Vec::with_capacity(sensor.n_outputs());
        for o in sensor.outputs() {
            let p = o.n_estimated();
            let names: Vec<String> = o.estimated_names().into_iter().map(String::from).collect();
            let n_c = candidates_deg.len();
            let mut a = Vec::with_capacity(n_c * p);
            let (mut de, mut dg) = (
                Vec::with_capacity(n_c * errors),
                Vec::with_capacity(n_c * errors),
            );
            for (u, v) in nominal.iter().zip(&vectors) {
                a.extend(o.regressor_row(u));
                for delta in v.iter().take(errors) {
                    let du = input_variation(u, delta);
                    de.push(directional(o, true, u, &du));
                    dg.push(directional(o, false, u, &du));
                }
            }
            // Identifiable from the whole candidate set at all?
            let all = DMatrix::from_row_slice(n_c, p, &a);
            if let Err(CalibError::Unidentifiable {
                output,
                coefficients,
                ..
            }) = Regression::new(&o.name, names.clone(), all)
            {
                return Err(E2eError::UnidentifiableCandidates {
                    output,
                    coefficients,
                    candidates: n_c,
                });
            }
            let w = 1.0 / o.accuracy;
            let c0 = dg
                .iter()
                .zip(&de)
                .map(|(g, e)| (affine.c_g * g + affine.c_e * e) * w)
                .collect();
            let c1 = dg
                .iter()
                .zip(&de)
                .map(|(g, e)| affine.d * (g + e) * w)
                .collect();
            outputs.push(OutputData {
                p,
                a,
                de,
                dg,
                c0,
                c1,
            });
            coefficient_names.push(names);
        }
        let weights = alloc_opt::Weights::inverse_average_sensitivity(&model).combined();
        Ok(Self {
            turntable: turntable.clone(),
            sensor: sensor.clone(),
            site: *site,
            reading,
            lower_bounds_rad: lower_bounds_rad.to_vec(),
            weights,
            accuracies: sensor.outputs().iter().map(|o| o.accuracy).collect(),
            output_names: sensor.outputs().iter().map(|o| o.name.clone()).collect(),
            coefficient_names,
            candidates_deg,
            errors,
            outputs,
            affine,
            search: crate::SearchParams::default(),
            specs: None,
        })
    }

    /// The same problem searched with `params` instead of [`crate::SearchParams::default`].
    #[must_use]
    pub fn with_search_params(mut self, params: crate::SearchParams) -> Self {
        self.search = params;
        self
    }

    /// The exchange's knobs of this problem.
    #[must_use]
    pub fn search_params(&self) -> &crate::SearchParams {
        &self.search
    }

    /// The candidates (joint angles, deg), in index order.
    #[must_use]
    pub fn candidates_deg(&self) -> &[Vec<f64>] {
        &self.candidates_deg
    }

    /// Number of candidates $C$.
    #[must_use]
    pub fn n_candidates(&self) -> usize {
        self.candidates_deg.len()
    }

    /// The index of a candidate with exactly these joint angles (deg), if any.
    #[must_use]
    pub fn index_of(&self, position_deg: &[f64]) -> Option<usize> {
        self.candidates_deg
            .iter()
            .position(|c| c.as_slice() == position_deg)
    }

    /// The reading of eq 13 the design is for.
    #[must_use]
    pub fn reading(&self) -> Reading {
        self.reading
    }

    /// Whether the reading's error rows are fixed per position (they do not depend on the
    /// rest of the schedule), as for [`Reading::PAPER`]: then $J$ never decreases when
    /// positions are added.
    #[must_use]
    pub fn rows_are_static(&self) -> bool {
        self.affine.is_static()
    }

    /// The most estimated coefficients of any output: no schedule with fewer positions
    /// identifies the sensor.
    #[must_use]
    pub fn min_positions(&self) -> usize {
        self.outputs.iter().map(|o| o.p).max().unwrap_or(0)
    }

    /// The regression of every output on schedule `s` (candidate indices), factored as a
    /// [`calib_lsq::Calibration`] would (same matrix, same QR, same condition number).
    ///
    /// # Errors
    /// [`CalibError::Unidentifiable`] naming the output and coefficients.
    pub(crate) fn regressions(&self, s: &[usize]) -> Result<Vec<Regression>, CalibError> {
        self.outputs
            .iter()
            .enumerate()
            .map(|(k, o)| {
                let mut a = DMatrix::zeros(s.len(), o.p);
                for (i, &c) in s.iter().enumerate() {
                    for (j, v) in o.a_row(c).iter().enumerate() {
                        a[(i, j)] = *v;
                    }
                }
                Regression::new(&self.output_names[k], self.coefficient_names[k].clone(), a)
            })
            .collect()
    }

    /// $\mathbf M$ of schedule `s` from the precomputed derivative blocks, through the same
    /// dispatch as [`e2e_verify::EndToEnd::linearization`] (bit-identical for the same schedule).
    pub(crate) fn linearization_with(&self, s: &[usize], regs: &[Regression]) -> Linearization {
        let n = s.len();
        let m = self.errors;
        let mut mat = DMatrix::zeros(self.outputs.len() * n, m);
        let mut noise = DMatrix::zeros(self.outputs.len(), m);
        let mut work = ReadingWork::default();
        let mut col = vec![0.0; n];
        for (k, (o, reg)) in self.outputs.iter().zip(regs).enumerate() {
            for j in 0..m {
                let terms = DerivativeTerms {
                    a: reg.matrix(),
                    pinv: reg.pinv(),
                    de: s.iter().map(|&c| o.de[c * m + j]).collect(),
                    dg: s.iter().map(|&c| o.dg[c * m + j]).collect(),
                };
                noise[(k, j)] = e2e_verify::internals::rounding_level(
                    &terms.de,
                    &terms.dg,
                    reg.condition_number(),
                );
                self.reading.error_vector(&terms, &mut work, &mut col);
                for (i, v) in col.iter().enumerate() {
                    mat[(k * n + i, j)] = *v;
                }
            }
        }
        Linearization::from_parts(mat, n, self.outputs.len(), noise)
    }

    /// $\mathbf M$ of schedule `s` (candidate indices) from the precomputed blocks.
    ///
    /// # Errors
    /// [`E2eError::Calib`] when the schedule does not identify an output.
    pub fn linearization(&self, s: &[usize]) -> Result<Linearization, E2eError> {
        self.check_schedule(s)?;
        let regs = self.regressions(s)?;
        Ok(self.linearization_with(s, &regs))
    }

    /// The direct allocation of a linearisation with the shared core.
    pub(crate) fn allocate(
        &self,
        linear: &Linearization,
    ) -> Result<e2e_verify::DirectAllocation, E2eError> {
        let names: Vec<&str> = self.output_names.iter().map(String::as_str).collect();
        let error_names: Vec<String> = self
            .turntable
            .rotation_error_names()
            .into_iter()
            .map(str::to_string)
            .collect();
        DirectSetup {
            error_names: &error_names,
            weights: &self.weights,
            accuracies: &self.accuracies,
            output_names: &names,
        }
        .allocate(
            linear,
            &self.lower_bounds_rad,
            &vec![0.0; self.outputs.len()],
            None,
        )
    }

    pub(crate) fn check_schedule(&self, s: &[usize]) -> Result<(), E2eError> {
        if s.is_empty() {
            return Err(E2eError::TooFewPositions {
                positions: 0,
                output: self.output_names[0].clone(),
                coefficients: self.outputs[0].p,
            });
        }
        if let Some(&c) = s.iter().find(|&&c| c >= self.n_candidates()) {
            return Err(E2eError::Field(tt_core::FieldError::OutOfRange {
                field: "schedule".into(),
                value: c as f64,
                range: "candidate indices".into(),
            }));
        }
        let mut seen = vec![false; self.n_candidates()];
        for &c in s {
            if std::mem::replace(&mut seen[c], true) {
                return Err(E2eError::RepeatedCandidate { candidate: c });
            }
        }
        Ok(())
    }

    /// The exact evaluation of schedule `s` (candidate indices): identifiability and condition
    /// number of every output, $\mathbf M$ from the precomputed blocks and the direct
    /// allocation by the shared core, so $J$ equals [`e2e_verify::EndToEnd::allocate_direct`] on the
    /// same schedule.
    ///
    /// # Errors
    /// [`E2eError::RepeatedCandidate`] or an index error for a bad schedule;
    /// [`E2eError::Alloc`] if the solver fails. An unidentifiable schedule or one whose lower
    /// bounds alone break an accuracy is not an error: it is reported as infeasible.
    pub fn evaluate(&self, s: &[usize]) -> Result<Evaluation, E2eError> {
        self.evaluate_within(s, f64::INFINITY)
    }

    /// [`DesignProblem::evaluate`], without the allocation (objective `+inf`) when a
    /// condition number exceeds `max_condition`: such a schedule is infeasible whatever its
    /// $J$, and the conic solve is the expensive part.
    pub(crate) fn evaluate_within(
        &self,
        s: &[usize],
        max_condition: f64,
    ) -> Result<Evaluation, E2eError> {
        self.check_schedule(s)?;
        let regs = match self.regressions(s) {
            Ok(r) => r,
            Err(CalibError::Unidentifiable {
                output,
                coefficients,
                ..
            }) => {
                return Ok(Evaluation::unidentifiable(
                    s,
                    output,
                    coefficients,
                    self.outputs.len(),
                ));
            }
            Err(e) => return Err(e.into()),
        };
        let condition_numbers: Vec<f64> = regs.iter().map(Regression::condition_number).collect();
        if condition_numbers.iter().any(|&k| k > max_condition) {
            return Ok(Evaluation {
                schedule: s.to_vec(),
                condition_numbers,
                unidentifiable: None,
                objective: f64::INFINITY,
                allocation: None,
                linear: None,
                spec_screen: None,
            });
        }
        let linear = self.linearization_with(s, &regs);
        let (allocation, spec_screen) = match self.spec_answer(&self.positions_deg(s))? {
            Some(a) => {
                let screen = std::sync::Arc::new(crate::spec::SpecScreen::of(
                    &a,
                    self.affine.d,
                    &self.accuracies,
                ));
                (a.allocation, Some(screen))
            }
            None => match self.allocate(&linear) {
                Ok(a) => (Some(a), None),
                Err(E2eError::InfeasibleLowerBounds { .. }) => (None, None),
                Err(e) => return Err(e),
            },
        };
        Ok(Evaluation {
            schedule: s.to_vec(),
            condition_numbers,
            unidentifiable: None,
            objective: allocation.as_ref().map_or(f64::INFINITY, |a| a.objective()),
            allocation,
            linear: Some(linear),
            spec_screen,
        })
    }
}

impl DesignProblem {
    /// [`DesignProblem::evaluate_within`], with a failure of the conic solver on this
    /// schedule reported as `None` (the search then never takes it) instead of an error.
    pub(crate) fn evaluate_or_skip(
        &self,
        s: &[usize],
        max_condition: f64,
    ) -> Result<Option<Evaluation>, E2eError> {
        match self.evaluate_within(s, max_condition) {
            Ok(e) => Ok(Some(e)),
            Err(E2eError::Alloc(
                alloc_opt::AllocError::Solver { .. } | alloc_opt::AllocError::NoConvergence { .. },
            )) => Ok(None),
            Err(e) => Err(e),
        }
    }
}

/// $d\mathbf u = (\mathbf a \times \boldsymbol\delta, \boldsymbol\omega \times \boldsymbol\delta)$:
/// the first variation of the inputs for the rotation vector $\boldsymbol\delta$ (eq 8).
fn input_variation(u: &InputValues, delta: &Vector3<f64>) -> [f64; 6] {
    let da = u.specific_force_g().cross(delta);
    let dw = u.rate_deg_per_h().cross(delta);
    [da.x, da.y, da.z, dw.x, dw.y, dw.z]
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Relative agreement of the affine form with the dispatch (dimensionless): rounding of
    /// two evaluations of the same first-order rows.
    const AFFINE_REL: f64 = 1e-10;

    /// The screening's affine form $\mathbf C_0 + \mathbf P\mathbf C_1$ (three scalars probed
    /// from the dispatch of eq 13) gives the rows of [`DesignProblem::linearization`] for
    /// every reading, so the bounds are computed on the true rows.
    #[test]
    fn affine_form_reproduces_the_dispatch_for_every_reading() {
        let table = tt_kinematics::paper::table3();
        let grid = super::super::grid_positions_deg(&table, 60.0).unwrap();
        for reading in Reading::all() {
            let p = DesignProblem::new(
                &table,
                &gw_model::paper::gyrowheel(),
                &gw_model::paper::site(),
                reading,
                &[0.0; 8],
                grid.clone(),
            )
            .unwrap();
            let s = super::super::dopt::greedy_d(&p, 12).unwrap();
            let regs = p.regressions(&s).unwrap();
            let lin = p.linearization_with(&s, &regs);
            let (n, m) = (s.len(), p.errors);
            let scale = lin.matrix().amax().max(1.0);
            for (k, (o, reg)) in p.outputs.iter().zip(&regs).enumerate() {
                let proj = reg.matrix() * reg.pinv();
                for q in 0..n {
                    for j in 0..m {
                        let affine = o.c0[s[q] * m + j]
                            + (0..n)
                                .map(|i| proj[(q, i)] * o.c1[s[i] * m + j])
                                .sum::<f64>();
                        let dispatch = lin.matrix()[(k * n + q, j)] / p.accuracies[k];
                        assert!(
                            (affine - dispatch).abs() <= AFFINE_REL * scale / p.accuracies[k],
                            "{reading}: row ({k}, {q}) error {j}: {affine} vs {dispatch}"
                        );
                    }
                }
            }
        }
    }

    /// Readings whose rows depend on the schedule are exactly those with a projection term.
    #[test]
    fn static_rows_are_the_readings_without_projection() {
        assert!(Affine::of(Reading::PAPER).is_static());
        assert!(!Affine::of(Reading::USER).is_static());
        assert_eq!(
            Affine::of(Reading::USER),
            Affine {
                c_g: 1.0,
                c_e: 0.0,
                d: -1.0
            }
        );
        assert_eq!(
            Affine::of(Reading::PAPER),
            Affine {
                c_g: 0.0,
                c_e: -1.0,
                d: 0.0
            }
        );
    }
}
