//! One calibration run of a turntable with geometric errors $\chi$: the exact orientation at
//! every test position, the outputs and the least-squares calibration of the chosen
//! [`Reading`] of eq 13, and the calibration error $\Delta\omega_k$ (eq 14) of every output.

use crate::error::{E2eError, finite};
use calib_lsq::{Calibration, ErrorAnalysis, ErrorWork, OrientationErrorAnalysis, Reading};
use gw_model::InputValues;
use mc_verify::simd::{HotLoop, SimdLevel, run_at};
use nalgebra::{Matrix3, Vector3};
use tt_kinematics::{
    ChainKind, Pose, ScheduleErrorModel, Turntable, TurntableErrors, TurntableSchedule,
};

/// An end-to-end calibration simulator: turntable, sensor (the truth), site, schedule and
/// reading fixed; the nominal regressions are factored once and the pose-dependent part of
/// the chain is computed once per position (never inside a Monte Carlo loop).
///
/// # Formula
/// For turntable errors $\chi$ and position $i$ with pose $\phi_i$,
/// $\Delta\mathbf R_i = \mathbf R_d^T\mathbf R_t$ (eq 23) by the segmented chain
/// ([`tt_kinematics::PoseFrames`]): the error segments $\mathbf E_s(\chi)$ once per turntable,
/// the nominal blocks once per position. Then eq 8-14 of calib-lsq with the chosen
/// [`Reading`]: actual inputs $\mathbf v_i' = \Delta\mathbf R_i^T\mathbf v_i$, outputs
/// $\mathbf b_1$, estimate, error vector $\Delta\hat{\boldsymbol\omega}$ and
/// $\Delta\omega = \lVert\Delta\hat{\boldsymbol\omega}\rVert_\infty$ per output.
///
/// The table is any [`ScheduleErrorModel`] (an error vector to $\Delta\mathbf R_i$ at every
/// position): a [`Turntable`] at its poses ([`TurntableSchedule`], the default type, with the
/// compiled segmented chain) through [`EndToEnd::new`], anything else through
/// [`EndToEnd::for_model`].
///
/// # Reference
/// Eq 7-14 (calibration) and eq 17-23 (turntable chain).
#[derive(Debug, Clone)]
pub struct EndToEnd<S = TurntableSchedule> {
    chain: S,
    calibration: Calibration,
    reading: Reading,
    /// $\mathbf a_i$ and $\boldsymbol\omega_i$ (g, deg/h) per position, nominal.
    nominal: Vec<[Vector3<f64>; 2]>,
    /// The fast path of a turntable: $\mathbf B_1\mathbf a_i$ and $\mathbf B_1\boldsymbol\omega_i$
    /// per position ([`ScheduleErrorModel::as_turntable_schedule`]).
    pre: Option<Vec<[Vector3<f64>; 2]>>,
    /// The static positions of a turntable laid out side by side (a turntable's schedule
    /// without rate steps only; [`crate::kernel`]).
    kernel: Option<crate::kernel::StaticChain>,
    /// Whether [`EndToEnd::kernel`] writes every input vector the coefficients' estimate reads
    /// (it writes only those the study's reading reads: the paper's reads the known terms').
    kernel_for_coefficients: bool,
    analyses: Vec<OrientationErrorAnalysis>,
    /// The first-order rotation vectors $\mathbf v_{ij}$ of every position $i$ and error $j$
    /// ([`ScheduleErrorModel::rotation_vectors`]), once.
    vectors: Vec<Vec<Vector3<f64>>>,
    /// [`EndToEnd::precisions`], once.
    precisions: Vec<f64>,
    /// The rate steps of the schedule and the errors they expose ([`crate::rate`]; a
    /// turntable's only).
    rate: crate::rate::RatePlan,
    /// The values of the extra errors.
    extra_values: Vec<f64>,
}

/// `value` when it exceeds `precision`, else 0: a computed value at or below the computation's
/// precision ([`EndToEnd::precisions`]) cannot be told from 0.
#[must_use]
pub fn resolved(value: f64, precision: f64) -> f64 {
    if value.abs() <= precision { 0.0 } else { value }
}

/// See [`EndToEnd::precisions`].
fn precisions(calibration: &Calibration) -> Vec<f64> {
    let n = calibration.schedule().len();
    calibration
        .outputs()
        .iter()
        .map(|o| {
            let out = o.output();
            let size = o
                .nominal_values()
                .iter()
                .map(|u| {
                    out.terms
                        .iter()
                        .map(|t| (t.value * t.regressor.eval(u)).abs())
                        .sum::<f64>()
                })
                .fold(0.0, f64::max);
            let (a, pinv) = (o.regression().matrix(), o.regression().pinv());
            // the row sums of |A| |A^+| as |A| (|A^+| 1): never the n x n product
            let pinv_sums: Vec<f64> = pinv
                .row_iter()
                .map(|r| r.iter().map(|v| v.abs()).sum())
                .collect();
            let amplification = a
                .row_iter()
                .map(|r| r.iter().zip(&pinv_sums).map(|(v, s)| v.abs() * s).sum())
                .fold(0.0, f64::max);
            let operations = (out.terms.len() + 3 + n + out.n_estimated()) as f64;
            operations * f64::EPSILON * (1.0 + amplification) * size
        })
        .collect()
}

/// The result of one simulated calibration run (reference path through calib-lsq).
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct EndToEndRun {
    /// $\Delta\mathbf R_i$ of every position (exact matrix chain).
    pub(crate) delta_r: Vec<Matrix3<f64>>,
    /// The full eq 7-14 analysis of every output.
    pub(crate) analyses: Vec<ErrorAnalysis>,
}

/// Read access to the fields (crate-private, so the type can grow without breaking callers).
impl EndToEndRun {
    /// $\Delta\mathbf R_i$ of every position (exact matrix chain).
    #[must_use]
    pub fn delta_r(&self) -> &[Matrix3<f64>] {
        &self.delta_r
    }

    /// The full eq 7-14 analysis of every output.
    #[must_use]
    pub fn analyses(&self) -> &[ErrorAnalysis] {
        &self.analyses
    }
}

impl EndToEndRun {
    /// $\Delta\omega_k$ of every output (output unit).
    #[must_use]
    pub fn delta_omega(&self) -> Vec<f64> {
        self.analyses.iter().map(|a| a.delta_omega()).collect()
    }
}

/// Scratch space of one simulated run on the fast path: sized once, reused for every draw.
#[derive(Debug, Clone)]
pub struct DrawWork {
    segments: Vec<Matrix3<f64>>,
    /// $\Delta\mathbf R_i$ of every position (the path of a model without the fast path).
    delta_r: Vec<Matrix3<f64>>,
    /// Every angular error's rotation (rate steps only).
    rotations: Vec<Matrix3<f64>>,
    actual: Vec<InputValues>,
    /// The actual inputs as columns (a turntable's static positions, [`crate::kernel`]).
    columns: calib_lsq::InputColumns,
    error: Vec<f64>,
    work: ErrorWork,
    /// $\Delta\omega_k$ of every output after [`EndToEnd::delta_omega_into`] (output unit).
    pub delta_omega: Vec<f64>,
    /// The instruction set the chain and the calibration are compiled for.
    level: SimdLevel,
}

impl DrawWork {
    /// The same scratch space with the per-draw chain and calibration compiled for `level`
    /// instead of the widest level of the CPU ([`SimdLevel::detected`], the default). The
    /// results are bit-identical on every level (see `mc_verify::simd`); this exists to prove
    /// it and to measure the levels against each other.
    ///
    /// # Errors
    /// [`E2eError::Bounds`] ([`mc_verify::McError::SimdUnavailable`]) if the CPU lacks
    /// `level`.
    pub fn with_simd_level(self, level: SimdLevel) -> Result<Self, E2eError> {
        Ok(Self {
            level: level.check()?,
            ..self
        })
    }

    /// The instruction set the chain and the calibration are compiled for.
    #[must_use]
    pub fn simd_level(&self) -> SimdLevel {
        self.level
    }
}

/// One draw's inputs and calibration ([`EndToEnd::inputs_into`], then the error vectors),
/// compiled for the work's [`SimdLevel`]: `vectors` `None` keeps only $\Delta\omega_k$
/// ([`EndToEnd::delta_omega_into`]), `Some` also writes each output's error vector.
struct Draw<'a, S: ScheduleErrorModel> {
    e2e: &'a EndToEnd<S>,
    chi: &'a [f64],
    extra: &'a [f64],
    work: &'a mut DrawWork,
    vectors: Option<&'a mut [Vec<f64>]>,
}

impl<S: ScheduleErrorModel> HotLoop for Draw<'_, S> {
    type Output = Result<(), E2eError>;

    #[inline(always)]
    fn run(self) -> Self::Output {
        let Draw {
            e2e,
            chi,
            extra,
            work,
            vectors,
        } = self;
        let columns = e2e.inputs_into(chi, extra, work)?;
        match vectors {
            None => e2e.finish_draw(work, columns),
            Some(out) => {
                for (k, v) in out.iter_mut().enumerate().take(e2e.n_outputs()) {
                    e2e.error_vector_into(k, columns, work, v)?;
                    work.delta_omega[k] = max_abs(v);
                }
                Ok(())
            }
        }
    }
}

impl<S: ScheduleErrorModel> EndToEnd<S> {
    /// [`Draw`] at the work's level.
    fn draw(
        &self,
        chi: &[f64],
        extra: &[f64],
        work: &mut DrawWork,
        vectors: Option<&mut [Vec<f64>]>,
    ) -> Result<(), E2eError> {
        let level = work.level;
        run_at(
            level,
            Draw {
                e2e: self,
                chi,
                extra,
                work,
                vectors,
            },
        )
    }
}

impl EndToEnd {
    /// Prepare the simulation of `calibration` (sensor, site and schedule, whose positions
    /// are `poses` of `turntable`) under `reading`.
    ///
    /// # Errors
    /// [`E2eError::Kinematics`] when a pose does not fit the turntable;
    /// [`E2eError::Field`] (out of range) naming `poses` unless there is one pose per position.
    pub fn new(
        turntable: &Turntable,
        calibration: &Calibration,
        poses: &[Pose],
        reading: Reading,
    ) -> Result<Self, E2eError> {
        if poses.len() != calibration.schedule().len() {
            return Err(E2eError::Field(tt_core::FieldError::OutOfRange {
                field: "poses".into(),
                value: poses.len() as f64,
                range: "one pose per position of the schedule".into(),
            }));
        }
        Self::for_model(
            TurntableSchedule::new(turntable, poses)?,
            calibration,
            reading,
        )
    }

    /// The turntable.
    #[must_use]
    pub fn turntable(&self) -> &Turntable {
        self.chain.turntable()
    }

    /// The turntable pose of every position.
    #[must_use]
    pub fn poses(&self) -> &[Pose] {
        self.chain.poses()
    }

    /// $\Delta\mathbf R_i$ of every position by the segmented chain (equal to
    /// [`EndToEnd::delta_r_reference`] to rounding).
    ///
    /// # Errors
    /// As [`EndToEnd::delta_r_reference`].
    pub fn delta_r_fast(&self, chi_rad: &[f64]) -> Result<Vec<Matrix3<f64>>, E2eError> {
        self.check_chi(chi_rad)?;
        let mut out = vec![Matrix3::identity(); self.len()];
        self.chain.delta_r_into(chi_rad, &mut out)?;
        Ok(out)
    }

    /// $\Delta\omega_k$ of every output (output unit) when the errors differ from position to
    /// position (errors that vary with a shaft angle, [`crate::angle`]): `chi_at(i, chi)`
    /// writes $\chi$ at position $i$ (rad) into `chi` (one per angular error, checked finite),
    /// the segmented chain is evaluated per position, then the reading as in
    /// [`EndToEnd::delta_omega_into`]. With the same $\chi$ at every position it equals that
    /// path exactly.
    ///
    /// # Errors
    /// As [`EndToEnd::delta_omega_into`].
    pub(crate) fn delta_omega_varying_into(
        &self,
        mut chi_at: impl FnMut(usize, &mut [f64]),
        chi: &mut [f64],
        work: &mut DrawWork,
    ) -> Result<(), E2eError> {
        self.static_only("errors that vary with a shaft angle")?;
        let pre = self.pre.as_deref().unwrap_or_default();
        for (i, (f, [a, w])) in self.chain.frames().iter().zip(pre).enumerate() {
            chi_at(i, chi);
            self.check_chi(chi)?;
            self.turntable()
                .segment_rotations(chi, &mut work.segments)?;
            let a = f.delta_r_transpose_times_pre(&work.segments, a);
            let w = f.delta_r_transpose_times_pre(&work.segments, w);
            for (q, v) in InputValues::new(&a, &w).0.into_iter().enumerate() {
                if let Some(c) = work.columns.column_mut(q).get_mut(i) {
                    *c = v;
                }
            }
        }
        self.finish_draw(work, true)
    }
}

impl<S: ScheduleErrorModel> EndToEnd<S> {
    /// Prepare the simulation of `calibration` (sensor, site and schedule) under `reading`
    /// for any table model with one position per position of the schedule: the end-to-end
    /// analysis of a model that is not a [`Turntable`].
    ///
    /// # Errors
    /// [`E2eError::Field`] (out of range) naming `positions` unless the model has one position
    /// per position of the schedule; [`E2eError::Calib`] for a reading the calibration cannot
    /// analyse.
    pub fn for_model(
        chain: S,
        calibration: &Calibration,
        reading: Reading,
    ) -> Result<Self, E2eError> {
        if chain.n_positions() != calibration.schedule().len() {
            return Err(E2eError::Field(tt_core::FieldError::OutOfRange {
                field: "positions".into(),
                value: chain.n_positions() as f64,
                range: format!("the schedule's {} positions", calibration.schedule().len()),
            }));
        }
        let nominal: Vec<[Vector3<f64>; 2]> = calibration
            .nominal_inputs()
            .iter()
            .map(InputValues::from_inputs)
            .map(|v| [v.specific_force_g(), v.rate_deg_per_h()])
            .collect();
        let pre: Option<Vec<[Vector3<f64>; 2]>> = chain.as_turntable_schedule().map(|t| {
            t.frames()
                .iter()
                .zip(&nominal)
                .map(|(f, [a, w])| [f.pre(a), f.pre(w)])
                .collect()
        });
        let analyses = (0..calibration.outputs().len())
            .map(|k| OrientationErrorAnalysis::new(calibration, k, reading))
            .collect::<Result<Vec<_>, _>>()?;
        let rate = match chain.as_turntable_schedule() {
            Some(t) => crate::rate::RatePlan::new(t.turntable(), calibration, t.poses())?,
            None if calibration.schedule().has_rate_steps() => {
                return Err(E2eError::Field(tt_core::FieldError::OutOfRange {
                    field: "calibration.rate_steps".into(),
                    value: calibration
                        .schedule()
                        .positions()
                        .iter()
                        .filter(|p| p.motion().is_some())
                        .count() as f64,
                    range: "no rate step: a table model that is not a turntable has static positions only".into(),
                }));
            }
            None => crate::rate::RatePlan::static_schedule(calibration.schedule().len()),
        };
        let vectors = (0..chain.n_positions())
            .map(|i| {
                let v = chain.rotation_vectors(i)?;
                tt_core::length("rotation vectors", chain.n_errors(), v.len())?;
                Ok(v)
            })
            .collect::<Result<Vec<_>, tt_kinematics::KinematicsError>>()?;
        let kernel = match (chain.as_turntable_schedule(), &pre) {
            (Some(t), Some(pre)) if !rate.is_active() => {
                crate::kernel::StaticChain::new(t, pre, vectors_read(calibration, reading))
            }
            _ => None,
        };
        // the estimate reads every term's inputs, whatever the reading's error vector reads
        let every = vectors_read(calibration, Reading::USER);
        let kernel_for_coefficients = kernel.as_ref().is_some_and(|k| {
            let w = k.writes();
            (w[0] || !every[0]) && (w[1] || !every[1])
        });
        Ok(Self {
            kernel,
            kernel_for_coefficients,
            extra_values: vec![0.0; rate.extra.len()],
            rate,
            vectors,
            chain,
            calibration: calibration.clone(),
            reading,
            nominal,
            pre,
            analyses,
            precisions: precisions(calibration),
        })
    }

    /// The table model.
    #[must_use]
    pub fn model(&self) -> &S {
        &self.chain
    }

    /// The first-order rotation vectors $\mathbf v_{ij}$ (x, y, z) of every position $i$ and
    /// error $j$: $\Delta\mathbf R_i \approx \mathbf I + [\sum_j\chi_j\mathbf v_{ij}]_\times$.
    #[must_use]
    pub fn rotation_vectors(&self) -> &[Vec<Vector3<f64>>] {
        &self.vectors
    }

    /// The errors' names, one per error of the model.
    #[must_use]
    pub fn error_names(&self) -> Vec<String> {
        self.chain.error_names()
    }

    /// The outputs' names, in the calibration's order.
    #[must_use]
    pub fn output_names(&self) -> Vec<String> {
        self.calibration()
            .outputs()
            .iter()
            .map(|o| o.output().name.clone())
            .collect()
    }

    /// The precision of every output's $\Delta\omega_k$ (output unit): a bound on the rounding
    /// error of its evaluation, so a computed $\Delta\omega_k$ at or below it cannot be told
    /// from 0 (a perfect turntable computes to about $10^{-14}$ deg/h on the paper's sensor, not
    /// 0). Values at or below it are reported as 0 ([`resolved`]) by [`EndToEnd::worst_case`]
    /// and [`crate::MonteCarloQuestions::rate_distribution`].
    ///
    /// # Formula
    /// $\Delta\hat{\boldsymbol\omega}$ is a difference of outputs of size
    /// $S_k = \max_i\sum_t|\beta_t r_t(\mathbf u_i)|$ (every term of the output, known ones
    /// included, at the nominal inputs). Each output sums $m_k$ terms of inputs rotated by a
    /// $3\times3$ matrix (rounding within $\gamma_{m_k+3}S_k$, $\gamma_N = N\epsilon$), and the
    /// least-squares step forms $\mathbf A(\mathbf A^+\mathbf b)$ with $n$ positions and $p_k$
    /// coefficients (within $\gamma_{n+p_k}\lVert|\mathbf A||\mathbf A^+|\rVert_\infty$ of the
    /// outputs' error and size). So
    /// $$P_k = (m_k + 3 + n + p_k)\,\epsilon\,\big(1 + \lVert|\mathbf A_k||\mathbf
    /// A_k^+|\rVert_\infty\big)\,S_k,$$
    /// Higham's first-order worst-case bound (N. J. Higham, *Accuracy and Stability of
    /// Numerical Algorithms*, 2nd ed., SIAM 2002, §3.1) for the readings with
    /// $\hat{\boldsymbol\beta}_1$; the readings with $\hat{\boldsymbol\beta}_2$ refactor
    /// $\mathbf A'$, which this does not bound. For the paper's sensor $P \approx 10^{-11}$
    /// deg/h against $\omega_m = 10^{-2}$.
    #[must_use]
    pub fn precisions(&self) -> &[f64] {
        &self.precisions
    }

    /// The calibration (sensor, site, schedule).
    #[must_use]
    pub fn calibration(&self) -> &Calibration {
        &self.calibration
    }

    /// The reading used.
    #[must_use]
    pub fn reading(&self) -> Reading {
        self.reading
    }

    /// Number of positions $n$.
    #[must_use]
    pub fn len(&self) -> usize {
        self.nominal.len()
    }

    /// Whether the schedule is empty (never for a constructed simulator).
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.nominal.is_empty()
    }

    /// Number of outputs.
    #[must_use]
    pub fn n_outputs(&self) -> usize {
        self.calibration.outputs().len()
    }

    /// Number of angular errors (length of $\chi$).
    #[must_use]
    pub fn n_errors(&self) -> usize {
        self.chain.n_errors()
    }

    /// The table errors only a rate step exposes (empty for a static schedule; see
    /// [`crate::rate`]), held at [`EndToEnd::extra_values`] wherever $\chi$ is evaluated.
    #[must_use]
    pub fn extra_errors(&self) -> &[crate::rate::ExtraError] {
        &self.rate.extra
    }

    /// The values of [`EndToEnd::extra_errors`] (m, relative), zero unless set by
    /// [`EndToEnd::with_extra_values`].
    #[must_use]
    pub fn extra_values(&self) -> &[f64] {
        &self.extra_values
    }

    /// The same simulator with the extra errors at `values` (one per
    /// [`EndToEnd::extra_errors`]).
    ///
    /// # Errors
    /// [`E2eError::Field`] for a wrong length or a non-finite value, naming the error.
    pub fn with_extra_values(&self, values: &[f64]) -> Result<Self, E2eError>
    where
        S: Clone,
    {
        self.check_extra(values)?;
        Ok(Self {
            extra_values: values.to_vec(),
            ..self.clone()
        })
    }

    pub(crate) fn check_extra(&self, values: &[f64]) -> Result<(), E2eError> {
        tt_core::length("extra errors", self.rate.extra.len(), values.len())
            .map_err(|e| E2eError::Kinematics(e.into()))?;
        for (name, v) in self.extra_names().into_iter().zip(values) {
            finite(name, *v)?;
        }
        Ok(())
    }

    /// The rate steps of the schedule ([`crate::rate`]).
    pub(crate) fn rate_plan(&self) -> &crate::rate::RatePlan {
        &self.rate
    }

    /// Whether the schedule has a rate step.
    #[must_use]
    pub fn has_rate_steps(&self) -> bool {
        self.rate.is_active()
    }

    /// The name of every extra error ([`crate::rate::ExtraError::name`]).
    #[must_use]
    pub fn extra_names(&self) -> Vec<String> {
        match self.chain.as_turntable_schedule() {
            Some(t) => self
                .rate
                .extra
                .iter()
                .map(|e| e.name(t.turntable()))
                .collect(),
            None => Vec::new(),
        }
    }

    /// Every output's accuracy $\omega_{m,k}$ (output unit).
    #[must_use]
    pub fn accuracies(&self) -> Vec<f64> {
        self.calibration
            .outputs()
            .iter()
            .map(|o| o.output().accuracy)
            .collect()
    }

    /// Scratch space for [`EndToEnd::delta_omega_into`].
    #[must_use]
    pub fn work(&self) -> DrawWork {
        let segments = self
            .chain
            .as_turntable_schedule()
            .map_or(0, |t| t.turntable().n_segments());
        DrawWork {
            segments: vec![Matrix3::identity(); segments],
            delta_r: if self.pre.is_some() {
                Vec::new()
            } else {
                vec![Matrix3::identity(); self.len()]
            },
            rotations: if self.rate.is_active() {
                vec![Matrix3::identity(); self.n_errors()]
            } else {
                Vec::new()
            },
            actual: Vec::with_capacity(self.len()),
            columns: calib_lsq::InputColumns::new(self.len()),
            error: vec![0.0; self.len()],
            work: ErrorWork::default(),
            delta_omega: vec![0.0; self.n_outputs()],
            level: SimdLevel::detected(),
        }
    }

    pub(crate) fn check_chi(&self, chi_rad: &[f64]) -> Result<(), E2eError> {
        if chi_rad.len() != self.n_errors() {
            return Err(E2eError::Kinematics(
                tt_core::FieldError::Length {
                    field: "chi".into(),
                    expected: self.n_errors(),
                    found: chi_rad.len(),
                }
                .into(),
            ));
        }
        if let Some(i) = chi_rad.iter().position(|v| !v.is_finite()) {
            finite(format!("chi.{}", self.error_names()[i]), chi_rad[i])?;
        }
        Ok(())
    }

    /// $\Delta\mathbf R_i$ of every position through the plain chain: for a turntable the
    /// plain matrix chain ([`Turntable::delta_r`], exact), for any other model its
    /// [`ScheduleErrorModel::delta_r_into`].
    ///
    /// # Errors
    /// [`E2eError::Field`] (not finite) naming the error of a non-finite $\chi$; a length error.
    pub fn delta_r_reference(&self, chi_rad: &[f64]) -> Result<Vec<Matrix3<f64>>, E2eError> {
        self.check_chi(chi_rad)?;
        if let Some(t) = self.chain.as_turntable_schedule() {
            let table = t.turntable();
            let errors =
                TurntableErrors::new(chi_rad.to_vec(), vec![0.0; table.n_translation_errors()])?;
            return t
                .poses()
                .iter()
                .map(|p| Ok(table.delta_r(p, &errors, ChainKind::Exact)?))
                .collect();
        }
        let mut out = vec![Matrix3::identity(); self.len()];
        self.chain.delta_r_into(chi_rad, &mut out)?;
        Ok(out)
    }

    /// One calibration run through calib-lsq's analysis (eq 7-14) with the plain exact chain:
    /// the reference path, with every intermediate result.
    ///
    /// # Errors
    /// [`E2eError::Field`] (not finite) for a non-finite $\chi$; [`E2eError::Calib`] if $\mathbf A'$ is
    /// rank deficient (only for readings that need $\hat{\boldsymbol\beta}_2$).
    pub fn run(&self, chi_rad: &[f64]) -> Result<EndToEndRun, E2eError> {
        let dr = self.delta_r_reference(chi_rad)?;
        let table = match self.chain.as_turntable_schedule() {
            Some(t) if self.rate.is_active() => t,
            _ => return self.run_with_delta_r(&dr),
        };
        // rate steps: their inputs by the plain chain split at the turning joint
        let turntable = table.turntable();
        let n_tr = turntable.n_translation_errors();
        let errors = TurntableErrors::new(chi_rad.to_vec(), self.extra_values[..n_tr].to_vec())?;
        let site = self.calibration.site();
        let actual = self
            .calibration
            .schedule()
            .positions()
            .iter()
            .zip(&dr)
            .zip(table.poses())
            .zip(&self.rate.entries)
            .map(|(((p, d), pose), entry)| match (p.motion(), entry) {
                (Some(m), Some(entry)) => {
                    let step = tt_kinematics::RateStep {
                        joint: m.joint,
                        rate_rad_per_s: m.rate_rad_per_s,
                        pose: pose.clone(),
                        revolutions: m.revolutions,
                    };
                    let k = entry.rate_index;
                    let re = tt_kinematics::RateErrorValues {
                        accuracy: self.extra_values[k],
                        ripple: [self.extra_values[k + 1], self.extra_values[k + 2]],
                    };
                    let avg = turntable.rate_step_average(&step, &errors, &re, &entry.env)?;
                    Ok(gw_model::Inputs {
                        specific_force_g: avg.specific_force_g,
                        rate_rad_per_s: avg.rate_rad_per_s,
                    })
                }
                _ => Ok(site.inputs_with_error(p.base_from_sensor(), d)),
            })
            .collect::<Result<Vec<_>, E2eError>>()?;
        Ok(EndToEndRun {
            analyses: self
                .analyses
                .iter()
                .map(|a| a.analyze_inputs(&actual))
                .collect::<Result<Vec<_>, _>>()?,
            delta_r: dr,
        })
    }

    /// One calibration run with one given $\Delta\mathbf R$ per position (reference path).
    ///
    /// # Errors
    /// As [`OrientationErrorAnalysis::analyze`].
    pub fn run_with_delta_r(&self, delta_r: &[Matrix3<f64>]) -> Result<EndToEndRun, E2eError> {
        Ok(EndToEndRun {
            analyses: self
                .analyses
                .iter()
                .map(|a| a.analyze(delta_r))
                .collect::<Result<Vec<_>, _>>()?,
            delta_r: delta_r.to_vec(),
        })
    }

    /// $\Delta\omega_k$ of every output (output unit) for turntable errors $\chi$, by the fast
    /// path, into `work.delta_omega`: no allocation once `work` is sized.
    ///
    /// # Errors
    /// [`E2eError::Field`] (not finite) or a length error for a bad $\chi$; [`E2eError::Calib`] when a
    /// reading that needs $\hat{\boldsymbol\beta}_2$ meets a rank-deficient $\mathbf A'$.
    pub fn delta_omega_into(&self, chi_rad: &[f64], work: &mut DrawWork) -> Result<(), E2eError> {
        self.check_chi(chi_rad)?;
        self.draw(chi_rad, &self.extra_values, work, None)
    }

    /// [`EndToEnd::delta_omega_into`] with the extra errors at `extra` (one per
    /// [`EndToEnd::extra_errors`]) instead of [`EndToEnd::extra_values`].
    ///
    /// # Errors
    /// As [`EndToEnd::delta_omega_into`]; a length error or a non-finite extra value.
    pub(crate) fn delta_omega_extra_into(
        &self,
        chi_rad: &[f64],
        extra: &[f64],
        work: &mut DrawWork,
    ) -> Result<(), E2eError> {
        self.check_chi(chi_rad)?;
        self.check_extra(extra)?;
        self.draw(chi_rad, extra, work, None)
    }

    /// The actual inputs at every position for the (checked) angular errors `chi` and extra
    /// errors `extra`: for a turntable whose positions are all static, by the compiled chain
    /// ([`crate::kernel`]) into `work.columns` (returns `true`); otherwise into `work.actual`
    /// (returns `false`): for a turntable, static positions by the segmented chain and rate
    /// steps by their compiled revolution averages ([`crate::rate`]); for any other model
    /// $\Delta\mathbf R_i^T$ of the nominal inputs.
    #[inline(always)]
    fn inputs_into(
        &self,
        chi: &[f64],
        extra: &[f64],
        work: &mut DrawWork,
    ) -> Result<bool, E2eError> {
        self.inputs_into_with(chi, extra, work, true)
    }

    /// [`EndToEnd::inputs_into`], by the compiled chain only where `use_kernel` (a caller
    /// that reads an input vector the kernel does not write, as the coefficient errors under
    /// a reading whose error vector needs fewer inputs, passes `false`).
    #[inline(always)]
    fn inputs_into_with(
        &self,
        chi: &[f64],
        extra: &[f64],
        work: &mut DrawWork,
        use_kernel: bool,
    ) -> Result<bool, E2eError> {
        match (self.chain.as_turntable_schedule(), &self.pre) {
            (Some(t), Some(pre)) => {
                let table = t.turntable();
                table.segment_rotations(chi, &mut work.segments)?;
                if let Some(kernel) = self.kernel.as_ref().filter(|_| use_kernel) {
                    kernel.columns_into(&work.segments, &mut work.columns);
                    return Ok(true);
                }
                work.actual.clear();
                if self.rate.is_active() {
                    table.error_rotations(chi, &mut work.rotations)?;
                }
                let n_tr = table.n_translation_errors();
                for ((f, [a, w]), entry) in t.frames().iter().zip(pre).zip(&self.rate.entries) {
                    if let Some(entry) = entry {
                        let u = self.rate.inputs(entry, &work.rotations, extra, n_tr)?;
                        work.actual.push(u);
                        continue;
                    }
                    let a = f.delta_r_transpose_times_pre(&work.segments, a);
                    let w = f.delta_r_transpose_times_pre(&work.segments, w);
                    work.actual.push(InputValues::new(&a, &w));
                }
            }
            _ => {
                work.actual.clear();
                self.chain.delta_r_into(chi, &mut work.delta_r)?;
                for (d, [a, w]) in work.delta_r.iter().zip(&self.nominal) {
                    let t = d.transpose();
                    work.actual.push(InputValues::new(&(t * a), &(t * w)));
                }
            }
        }
        Ok(false)
    }

    /// [`EndToEnd::inputs_into`], always into `work.actual`, by the compiled chain only
    /// where `use_kernel` ([`EndToEnd::inputs_into_with`]).
    fn actual_into_with(
        &self,
        chi: &[f64],
        extra: &[f64],
        work: &mut DrawWork,
        use_kernel: bool,
    ) -> Result<(), E2eError> {
        if self.inputs_into_with(chi, extra, work, use_kernel)? {
            work.actual.clear();
            work.actual
                .extend((0..work.columns.len()).map(|i| work.columns.value(i)));
        }
        Ok(())
    }

    /// Output `k`'s error vector into `out` from the inputs [`EndToEnd::inputs_into`] left in
    /// `work` (`columns` as it returned).
    #[inline(always)]
    fn error_vector_into(
        &self,
        k: usize,
        columns: bool,
        work: &mut DrawWork,
        out: &mut [f64],
    ) -> Result<(), E2eError> {
        let o = &self.calibration.outputs()[k];
        if columns {
            o.error_vector_columns(self.reading, &work.columns, &mut work.work, out)?;
        } else {
            o.error_vector_at(self.reading, &work.actual, &mut work.work, out)?;
        }
        Ok(())
    }

    /// Refuse `what` for a schedule with rate steps (a path built on one orientation error
    /// per position).
    pub(crate) fn static_only(&self, what: &str) -> Result<(), E2eError> {
        if self.rate.is_active() {
            return Err(E2eError::Field(tt_core::FieldError::OutOfRange {
                field: "calibration.rate_steps".into(),
                value: self.rate.entries.iter().flatten().count() as f64,
                range: format!("no rate step: {what} takes static positions only"),
            }));
        }
        Ok(())
    }

    /// The actual inputs' first variation at position `i` for a unit change of angular error
    /// `j` (`extra` false) or extra error `j` (`extra` true), at $\chi = 0$ and the extra
    /// errors at their values (g and deg/h per unit of the error), where it is not a rotation
    /// of the nominal inputs: `None` at a static position for an angular error (the analytic
    /// model applies there); zero at a static position for an extra error; central
    /// differences of the compiled rate step at a rate step (step `RATE_DERIVATIVE_STEP` of
    /// the error's unit: rad, m, relative).
    pub(crate) fn rate_input_derivative(
        &self,
        i: usize,
        j: usize,
        extra: bool,
    ) -> Option<[f64; 6]> {
        let entry = match &self.rate.entries.get(i) {
            Some(Some(e)) => e,
            _ => return extra.then_some([0.0; 6]),
        };
        // a rate entry exists only for a turntable
        let table = self.chain.as_turntable_schedule()?.turntable();
        let h = RATE_DERIVATIVE_STEP;
        let n_rot = table.n_rotation_errors();
        let mut chi = vec![0.0; n_rot];
        let mut x = self.extra_values.clone();
        let mut rot = vec![Matrix3::identity(); n_rot];
        let n_tr = table.n_translation_errors();
        let mut at = |v: f64| {
            if extra {
                x[j] = self.extra_values[j] + v;
            } else {
                chi[j] = v;
            }
            table.error_rotations(&chi, &mut rot).ok()?;
            self.rate.inputs(entry, &rot, &x, n_tr).ok()
        };
        let (plus, minus) = (at(h)?, at(-h)?);
        Some(std::array::from_fn(|q| {
            (plus.0[q] - minus.0[q]) / (2.0 * h)
        }))
    }

    /// The reading's $\Delta\omega_k$ of every output from the inputs
    /// [`EndToEnd::inputs_into`] left in `work` (`columns` as it returned).
    #[inline(always)]
    fn finish_draw(&self, work: &mut DrawWork, columns: bool) -> Result<(), E2eError> {
        let mut error = std::mem::take(&mut work.error);
        for k in 0..self.n_outputs() {
            let r = self.error_vector_into(k, columns, work, &mut error);
            if let Err(e) = r {
                work.error = error;
                return Err(e);
            }
            work.delta_omega[k] = max_abs(&error);
        }
        work.error = error;
        Ok(())
    }

    /// The error vectors $\Delta\hat{\boldsymbol\omega}$ of every output into `out[k]` (one
    /// entry per position, output unit) for turntable errors $\chi$ by the fast path, reusing
    /// `work` (no allocation once sized); `work.delta_omega` is set too.
    ///
    /// # Errors
    /// As [`EndToEnd::delta_omega_into`].
    pub(crate) fn error_vectors_into(
        &self,
        chi_rad: &[f64],
        work: &mut DrawWork,
        out: &mut [Vec<f64>],
    ) -> Result<(), E2eError> {
        self.check_chi(chi_rad)?;
        // each output's error vector once: Delta omega_k from it as finish_draw takes it
        self.draw(chi_rad, &self.extra_values, work, Some(out))?;
        Ok(())
    }

    /// $\Delta\omega_k$ of every output (output unit) for turntable errors $\chi$ (fast path,
    /// allocating its scratch space: use [`EndToEnd::delta_omega_into`] in loops).
    ///
    /// # Errors
    /// As [`EndToEnd::delta_omega_into`].
    pub fn delta_omega(&self, chi_rad: &[f64]) -> Result<Vec<f64>, E2eError> {
        let mut w = self.work();
        self.delta_omega_into(chi_rad, &mut w)?;
        Ok(w.delta_omega)
    }

    /// The error vectors $\Delta\hat{\boldsymbol\omega}$ of every output (output unit, one entry
    /// per position) for turntable errors $\chi$ (fast path).
    ///
    /// # Errors
    /// As [`EndToEnd::delta_omega_into`].
    pub fn error_vectors(&self, chi_rad: &[f64]) -> Result<Vec<Vec<f64>>, E2eError> {
        let mut w = self.work();
        let mut out = vec![vec![0.0; self.len()]; self.n_outputs()];
        self.error_vectors_into(chi_rad, &mut w, &mut out)?;
        Ok(out)
    }

    /// The estimated coefficients minus their true values, every estimated coefficient in
    /// study order, when the same errors $\chi$ act at every position, outputs are simulated at
    /// the actual orientation and calibrated at the intended one (eq 6, the user's estimate):
    /// what a calibrating engineer's coefficients are off by (allocating its scratch space:
    /// use [`EndToEnd::coefficient_errors_into`] in loops).
    ///
    /// # Errors
    /// As [`EndToEnd::delta_omega_into`].
    pub fn coefficient_errors(&self, chi_rad: &[f64]) -> Result<Vec<f64>, E2eError> {
        let mut out = vec![0.0; self.n_coefficients()];
        self.coefficient_errors_into(chi_rad, &mut self.work(), &mut out)?;
        Ok(out)
    }

    /// The number of estimated coefficients of every output together (the length of
    /// [`EndToEnd::coefficient_errors`]).
    #[must_use]
    pub fn n_coefficients(&self) -> usize {
        self.calibration
            .outputs()
            .iter()
            .map(|o| o.beta().len())
            .sum()
    }

    /// [`EndToEnd::coefficient_errors`] into `out` ([`EndToEnd::n_coefficients`] long) with
    /// the scratch space `work` (nothing allocated once it is sized): the actual inputs by the
    /// compiled chain where there is one, then each output's least squares through its
    /// pseudo-inverse, computed once ([`calib_lsq::OutputCalibration::coefficient_errors_at`]).
    ///
    /// # Errors
    /// As [`EndToEnd::delta_omega_into`]; [`E2eError::Field`] (length) for a wrong `out`.
    pub fn coefficient_errors_into(
        &self,
        chi_rad: &[f64],
        work: &mut DrawWork,
        out: &mut [f64],
    ) -> Result<(), E2eError> {
        self.check_chi(chi_rad)?;
        tt_core::length("coefficient errors", self.n_coefficients(), out.len())?;
        self.actual_into_with(
            chi_rad,
            &self.extra_values,
            work,
            self.kernel_for_coefficients,
        )?;
        let mut rest = out;
        for o in self.calibration.outputs() {
            let (head, tail) = rest.split_at_mut(o.beta().len());
            o.coefficient_errors_at(&work.actual, &mut work.work, head)?;
            rest = tail;
        }
        Ok(())
    }
}

impl<S: ScheduleErrorModel + Clone> EndToEnd<S> {
    /// The same simulator under another reading.
    ///
    /// # Errors
    /// As [`EndToEnd::for_model`].
    pub fn with_reading(&self, reading: Reading) -> Result<Self, E2eError> {
        Ok(Self {
            extra_values: self.extra_values.clone(),
            ..Self::for_model(self.chain.clone(), &self.calibration, reading)?
        })
    }
}

/// $\lVert\mathbf v\rVert_\infty$, a NaN entry skipped as [`f64::max`] skips it (the caller
/// tests the result for finiteness). A compare and a select per entry in [`MAX_LANES`]
/// running maxima, which the compiler vectorises; the largest of exact values does not
/// depend on the order, so the result is the sequential fold's.
#[inline(always)]
pub(crate) fn max_abs(v: &[f64]) -> f64 {
    let larger = |m: f64, x: f64| if x > m { x } else { m };
    let mut lanes = [0.0; MAX_LANES];
    let mut chunks = v.chunks_exact(MAX_LANES);
    for c in &mut chunks {
        for (m, x) in lanes.iter_mut().zip(c) {
            *m = larger(*m, x.abs());
        }
    }
    chunks
        .remainder()
        .iter()
        .map(|x| x.abs())
        .chain(lanes)
        .fold(0.0, larger)
}

/// Running maxima of [`max_abs`].
const MAX_LANES: usize = 8;

/// The step of the central differences of a rate step's inputs (unit of the error: rad, m,
/// relative): truncation $O(h^2) \approx 10^{-10}$ and rounding $\epsilon/h \approx
/// 2\cdot10^{-11}$ of the inputs' size.
pub(crate) const RATE_DERIVATIVE_STEP: f64 = 1e-5;

/// Whether any output of `calibration` reads the specific force (`[0]`) and the rate (`[1]`)
/// under `reading` ([`calib_lsq::OutputCalibration::inputs_used`]).
fn vectors_read(calibration: &Calibration, reading: Reading) -> [bool; 2] {
    let used = calibration
        .outputs()
        .iter()
        .map(|o| o.inputs_used(reading))
        .fold([false; 6], |a, b| std::array::from_fn(|q| a[q] || b[q]));
    [used[..3].contains(&true), used[3..].contains(&true)]
}
