//! The Monte Carlo driver: chunks, blocks, threads and the order-fixed reduction.

use crate::bounds::ErrorBox;
use crate::count::YieldCount;
use crate::error::McError;
use crate::fast::{
    BlockKernel, CompiledPlan, PlanKernel, TIER_ANY, TIER_MEDIUM, TIER_SHORT, TIER_TANGENT, Tier,
};
use crate::sampler::{BLOCK_CAPACITY, SampleBlock, TurntableSampler, chunk_rng, fill_words};
use crate::simd::{HotLoop, SimdLevel, run_at};
use crate::stats::{AxisSummary, Partial};
use rayon::prelude::*;
use std::sync::{Arc, Mutex};
use tt_core::{Pose, Requirement};
use tt_kinematics::{
    LinearModel, OrientationAxis, OrientationErrorModel, Turntable, TurntableErrors,
};

/// Default samples per chunk (one random stream each; part of the determinism contract).
pub const DEFAULT_CHUNK_SIZE: u32 = 1 << 16;

/// Default number of histogram bins per axis.
pub const DEFAULT_HISTOGRAM_BINS: usize = 200;

/// Largest accepted number of histogram bins per axis (bounds the memory of a run).
pub const MAX_HISTOGRAM_BINS: usize = 10_000;

/// Memory budget (bytes) of the partial histograms held between two in-order reductions; it
/// sets how many chunks run in parallel per wave (8 to 256) and has no effect on the result.
const WAVE_HISTOGRAM_BYTES: usize = 8 << 20;

/// Cap of the default histogram half-range, unitless (rad of an element of a rotation
/// matrix): every element of $\Delta\mathbf R$ lies in $[-1, 1]$, and its computed value
/// within a few $10^{-16}$ of it, so $1 + 2^{-20}$ bounds every computed read-out. It takes
/// over only for huge boxes, where the series bound $e^S - 1 - S$ exceeds 1 (or overflows).
const READOUT_ABS_CAP: f64 = 1.0 + 1.0 / 1_048_576.0;

/// Rounding allowance of the default histogram half-range, rad: an evaluator's computed
/// read-out differs from the exact one by rounding, a few $10^{-16}$ for the fast path and
/// up to about $10^{-15}$ for a dense chain of a dozen 3x3 products (the plain chain gives
/// $5.6\cdot10^{-17}$ for an all-zero box). It replaces the remainder term $e^S - 1 - S$
/// where that is smaller (boxes with $S$ below about $1.4\cdot10^{-7}$ rad); larger
/// remainder terms already hold far more than the rounding (they would be tight only with
/// every error rotation aligned), and keep the half-range of earlier versions to the bit.
const READOUT_ROUNDING_RAD: f64 = 1e-14;

/// Number of (turntable, upper bounds) half-ranges remembered
/// ([`MonteCarlo::histogram_half_range_rad`] costs up to seconds for a table with two free
/// joints: a branch and bound).
const HALF_RANGE_CACHE_LEN: usize = 32;

/// A remembered half-range: (turntable, bits of the upper bounds, half-ranges in rad).
type HalfRangeEntry = (Turntable, Vec<u64>, [f64; 3]);

/// What to run: sample count, seed, chunking, requirement and histogram layout.
///
/// The result is a function of (turntable, bounds, `samples`, `seed`, `chunk_size`) and the
/// model only: not of the thread count nor of the SIMD level.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct McConfig {
    /// Number of random turntables, at least 1.
    pub samples: u64,
    /// Seed of the random streams.
    pub seed: u64,
    /// Samples per random stream (chunk), at least 1.
    pub chunk_size: u32,
    /// The requirement $|\Delta_k| \le I_k$ per axis ($\psi, \theta, \gamma$), rad; an axis
    /// without requirement counts every sample as within.
    pub requirement: Requirement,
    /// Histogram bins per axis, in `1..=MAX_HISTOGRAM_BINS`.
    pub histogram_bins: usize,
    /// Histogram half-ranges $H$ per axis, rad; `None` derives them from the turntable and
    /// the bounds ([`MonteCarlo::histogram_half_range_rad`]).
    pub histogram_half_range_rad: Option<[f64; 3]>,
}

impl McConfig {
    /// `samples` draws with `seed` and the `requirement` (an angle without one counts every
    /// sample as within), default chunking and histograms.
    ///
    /// ```
    /// // 0.03 deg on all three angles
    /// let i = tt_core::Requirement::uniform_deg(0.03)?;
    /// let cfg = mc_verify::McConfig::new(1_000_000, 2017, i);
    /// assert_eq!(cfg.chunk_size, mc_verify::DEFAULT_CHUNK_SIZE);
    /// # Ok::<(), tt_core::FieldError>(())
    /// ```
    #[must_use]
    pub fn new(samples: u64, seed: u64, requirement: Requirement) -> Self {
        Self {
            samples,
            seed,
            chunk_size: DEFAULT_CHUNK_SIZE,
            requirement,
            histogram_bins: DEFAULT_HISTOGRAM_BINS,
            histogram_half_range_rad: None,
        }
    }

    /// The same configuration with another requirement.
    #[must_use]
    pub fn with_requirement(self, requirement: Requirement) -> Self {
        Self {
            requirement,
            ..self
        }
    }
}

/// The outcome of a run.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct McResult {
    /// Samples evaluated, the seed, the samples with all three angles inside the requirement
    /// and those with each angle inside its own ($\psi, \theta, \gamma$; every sample for an
    /// angle without one).
    pub(crate) count: YieldCount,
    /// The chunk size used.
    pub(crate) chunk_size: u32,
    /// The requirement $I$, rad.
    pub(crate) requirement: Requirement,
    /// Per-axis results, in the order $\Delta\psi, \Delta\theta, \Delta\gamma$.
    pub(crate) axes: [AxisSummary; 3],
}

/// Read access to the fields (crate-private, so the type can grow without breaking callers).
impl McResult {
    /// Samples evaluated, the seed, the samples with all three angles inside the requirement
    /// (the fraction and its 95% interval) and those with each angle inside its own
    /// ($\psi, \theta, \gamma$; every sample for an angle without one).
    #[must_use]
    pub fn count(&self) -> &YieldCount {
        &self.count
    }

    /// The chunk size used.
    #[must_use]
    pub fn chunk_size(&self) -> u32 {
        self.chunk_size
    }

    /// The requirement $I$, rad.
    #[must_use]
    pub fn requirement(&self) -> Requirement {
        self.requirement
    }

    /// Per-axis results, in the order $\Delta\psi, \Delta\theta, \Delta\gamma$.
    #[must_use]
    pub fn axes(&self) -> &[AxisSummary; 3] {
        &self.axes
    }
}

impl McResult {
    /// The summary of one axis.
    #[must_use]
    pub fn axis(&self, axis: OrientationAxis) -> &AxisSummary {
        &self.axes[axis.index()]
    }

    /// $\max|\Delta\psi|, \max|\Delta\theta|, \max|\Delta\gamma|$, rad.
    #[must_use]
    pub fn max_abs_rad(&self) -> [f64; 3] {
        self.axes.each_ref().map(|a| a.max_abs_rad)
    }

    /// Sample standard deviations ($\sqrt{M_2/(n-1)}$), rad.
    #[must_use]
    pub fn std_rad(&self) -> [f64; 3] {
        self.axes
            .each_ref()
            .map(|a| a.variance_rad2(self.count.samples).sqrt())
    }
}

/// The serde form of earlier versions: `samples`, `seed`, `chunk_size`, `requirement`, `axes`
/// (each axis with its `within_requirement`) and `within_requirement_all`.
#[cfg(feature = "serde")]
impl serde::Serialize for McResult {
    fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        /// One axis: its summary and the samples with it inside its requirement.
        #[derive(serde::Serialize)]
        struct AxisView<'a> {
            #[serde(flatten)]
            summary: &'a AxisSummary,
            within_requirement: u64,
        }
        /// The result.
        #[derive(serde::Serialize)]
        struct View<'a> {
            samples: u64,
            seed: u64,
            chunk_size: u32,
            requirement: Requirement,
            axes: [AxisView<'a>; 3],
            within_requirement_all: u64,
        }
        let c = &self.count;
        View {
            samples: c.samples(),
            seed: c.seed(),
            chunk_size: self.chunk_size,
            requirement: self.requirement,
            axes: OrientationAxis::ALL.map(|a| AxisView {
                summary: self.axis(a),
                within_requirement: c.meeting_per_output()[a.index()],
            }),
            within_requirement_all: c.meeting(),
        }
        .serialize(serializer)
    }
}

/// Poses per joint of the grid [`MonteCarlo::for_model`] estimates a model's histogram range
/// on (at most [`MODEL_RANGE_MAX_POSES`] poses in all).
const MODEL_RANGE_POINTS_PER_JOINT: usize = 65;

/// Most poses of that grid (the points per joint shrink for many joints).
const MODEL_RANGE_MAX_POSES: usize = 1 << 14;

/// Relative margin of a model's histogram range over its grid estimate (the grid can miss a
/// maximum between its points by a second-order amount; a draw beyond the range is counted
/// in the overflow bins, never lost).
const MODEL_RANGE_MARGIN: f64 = 0.05;

/// What a Monte Carlo evaluates.
// One per Monte Carlo, never in a collection: the size difference costs nothing, and the plan
// stays inline for the hot loop.
#[allow(clippy::large_enum_variant)]
#[derive(Clone)]
enum Source {
    /// A described turntable: the exact chain by its compiled plan ([`crate::fast`]).
    Table {
        turntable: Turntable,
        plan: CompiledPlan,
    },
    /// Any orientation-error model over joint ranges, evaluated sample by sample.
    Model {
        model: Arc<dyn OrientationErrorModel + Send + Sync>,
        joint_ranges_rad: Vec<[f64; 2]>,
    },
}

impl std::fmt::Debug for Source {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Source::Table { turntable, .. } => f
                .debug_struct("Table")
                .field("turntable", turntable)
                .finish_non_exhaustive(),
            Source::Model {
                joint_ranges_rad, ..
            } => f
                .debug_struct("Model")
                .field("joint_ranges_rad", joint_ranges_rad)
                .finish_non_exhaustive(),
        }
    }
}

/// A validated Monte Carlo verification of a tolerance box of a turntable (paper §4.3,
/// Figure 9), or of any [`OrientationErrorModel`] ([`MonteCarlo::for_model`]).
#[derive(Debug, Clone)]
pub struct MonteCarlo {
    source: Source,
    bounds: ErrorBox,
    config: McConfig,
    sampler: TurntableSampler,
    half_range_rad: [f64; 3],
    /// The requirement per axis, `+inf` for none.
    requirement_cmp_rad: [f64; 3],
}

impl MonteCarlo {
    /// Validate `bounds` against `turntable` and `config`: errors name the field at fault.
    ///
    /// # Errors
    /// [`McError::BoundsForAnotherTurntable`] if the box was made for another turntable;
    /// [`McError::ZeroSamples`], [`McError::ZeroChunkSize`], [`McError::HistogramBins`],
    /// [`McError::HistogramRange`] for a bad configuration;
    /// [`McError::Kinematics`] if the default histogram range cannot be computed.
    pub fn new(turntable: &Turntable, bounds: ErrorBox, config: McConfig) -> Result<Self, McError> {
        check_fit(turntable, &bounds)?;
        check_config(&config)?;
        let half_range_rad = match config.histogram_half_range_rad {
            Some(h) => h,
            None => Self::histogram_half_range_rad(turntable, &bounds)?,
        };
        Ok(Self::of_parts(
            Source::Table {
                turntable: turntable.clone(),
                plan: CompiledPlan::new(turntable),
            },
            TurntableSampler::new(&bounds, turntable),
            bounds,
            config,
            half_range_rad,
        ))
    }

    /// A run of `source` drawing by `sampler` (validated by the caller).
    fn of_parts(
        source: Source,
        sampler: TurntableSampler,
        bounds: ErrorBox,
        config: McConfig,
        half_range_rad: [f64; 3],
    ) -> Self {
        Self {
            sampler,
            source,
            bounds,
            requirement_cmp_rad: config
                .requirement
                .to_array()
                .map(|r| r.unwrap_or(f64::INFINITY)),
            config,
            half_range_rad,
        }
    }

    /// A Monte Carlo of any orientation-error `model` (no turntable needed): the pose drawn
    /// uniformly over `joint_ranges_rad` (one `[lo, hi]` per joint), $\chi$ in the box
    /// `bounds` (its names are the model's errors, [`ErrorBox::with_names`]); running it
    /// evaluates the model itself, sample by sample, on the same draws as a turntable's run.
    ///
    /// The default histogram half-range is estimated from the model's own first order
    /// ([`OrientationErrorModel::first_order`]) on a grid of poses:
    /// $H_k = (1 + 0.05)\max_{\phi}\sum_j \mathrm{UB}_j|c_{kj}(\phi)| + (e^S - 1 - S)$: an
    /// estimate, not a proof, so a draw beyond it is counted in the histogram's overflow
    /// (never lost); give [`McConfig::histogram_half_range_rad`] to fix it.
    ///
    /// # Errors
    /// As [`MonteCarlo::new`] for the configuration; [`McError::ModelErrorCount`] (both sizes)
    /// or [`McError::BoundsForAnotherTurntable`] when the box does not have the model's error
    /// count or names ([`OrientationErrorModel::error_names`]); [`McError::Model`] (sample 0)
    /// when the model rejects a pose of these ranges;
    /// [`McError::Kinematics`] naming `joint_ranges` for a non-finite or reversed range.
    pub fn for_model<M: OrientationErrorModel + Send + Sync + 'static>(
        model: M,
        joint_ranges_rad: Vec<[f64; 2]>,
        bounds: ErrorBox,
        config: McConfig,
    ) -> Result<Self, McError> {
        check_config(&config)?;
        check_model_fit(&model, &bounds)?;
        for (j, &[lo, hi]) in joint_ranges_rad.iter().enumerate() {
            if !(lo.is_finite() && hi.is_finite() && lo <= hi) {
                return Err(McError::Kinematics(
                    tt_core::FieldError::OutOfRange {
                        field: format!("joint_ranges[{j}]"),
                        value: if lo.is_finite() { hi } else { lo },
                        range: "finite, lower end at most the upper end".into(),
                    }
                    .into(),
                ));
            }
        }
        let half_range_rad = match config.histogram_half_range_rad {
            Some(h) => h,
            None => model_half_range_rad(&model, &joint_ranges_rad, &bounds)?,
        };
        let sampler = TurntableSampler::for_joint_ranges(&bounds, &joint_ranges_rad);
        Ok(Self::of_parts(
            Source::Model {
                model: Arc::new(model),
                joint_ranges_rad,
            },
            sampler,
            bounds,
            config,
            half_range_rad,
        ))
    }

    /// The default histogram half-range $H_k$ for a box of a turntable: a rigorous bound on
    /// $|\Delta_k|$,
    /// $$H_k = \max_{\phi} \sum_i \mathrm{UB}_i |c_{ki}(\phi)| + (e^S - 1 - S),\quad
    ///   S = \textstyle\sum_i \mathrm{UB}_i,$$
    /// the worst case of the first-order model over the joint ranges, as a certified upper
    /// bound ([`LinearModel::worst_pose_certified`]: exact for one free joint, a branch and
    /// bound otherwise), plus a bound on the remainder: $\Delta\mathbf R$ is a product of
    /// rotations $e^{A_j}$ (conjugated error rotations) with $\|A_j\|_2 = |\chi_j|$, and
    /// $\|\prod_j e^{A_j} - I - \sum_j A_j\|_2 \le e^S - 1 - S$. So no sample of the exact
    /// chain falls outside (the overflow counts stay zero; tested). Capped at $1 + 2^{-20}$
    /// (every element of a rotation matrix lies in $[-1, 1]$) for huge boxes; at least
    /// $10^{-300}$ for an all-zero box. Remembered per (turntable, upper
    /// bounds) for the process: a branch and bound can take seconds.
    ///
    /// # Errors
    /// [`McError::BoundsForAnotherTurntable`] if the box does not belong to the turntable.
    pub fn histogram_half_range_rad(
        turntable: &Turntable,
        bounds: &ErrorBox,
    ) -> Result<[f64; 3], McError> {
        check_fit(turntable, bounds)?;
        static CACHE: Mutex<Vec<HalfRangeEntry>> = Mutex::new(Vec::new());
        let key: Vec<u64> = bounds.ub_rad().iter().map(|u| u.to_bits()).collect();
        let cached = |cache: &Vec<HalfRangeEntry>| {
            cache
                .iter()
                .find(|(t, k, _)| *k == key && t == turntable)
                .map(|e| e.2)
        };
        if let Some(h) = CACHE.lock().ok().and_then(|c| cached(&c)) {
            return Ok(h);
        }
        let model = LinearModel::new(turntable);
        let ub = bounds.ub_rad();
        let s = bounds.sum_ub_rad();
        let remainder = (s.exp_m1() - s).max(READOUT_ROUNDING_RAD);
        let firsts: Vec<Result<f64, McError>> = OrientationAxis::ALL
            .par_iter()
            .map(|&axis| {
                let w = model.worst_pose_certified(axis, ub, true, None)?;
                // |c_ki| <= 1 (components of unit vectors): sum UB is a bound too
                Ok(w.upper_bound().min(s))
            })
            .collect();
        let mut h = [0.0; 3];
        for (hk, first) in h.iter_mut().zip(firsts) {
            // `min` returns the cap for a NaN (an overflowing remainder)
            *hk = (first? + remainder).min(READOUT_ABS_CAP);
        }
        if let Ok(mut cache) = CACHE.lock() {
            if cached(&cache).is_none() {
                if cache.len() >= HALF_RANGE_CACHE_LEN {
                    cache.remove(0);
                }
                cache.push((turntable.clone(), key, h));
            }
        }
        Ok(h)
    }

    /// The turntable, for a Monte Carlo of one (`None` for [`MonteCarlo::for_model`]).
    #[must_use]
    pub fn turntable(&self) -> Option<&Turntable> {
        match &self.source {
            Source::Table { turntable, .. } => Some(turntable),
            Source::Model { .. } => None,
        }
    }

    /// The joint ranges the poses are drawn over (rad).
    #[must_use]
    pub fn joint_ranges_rad(&self) -> Vec<[f64; 2]> {
        match &self.source {
            Source::Table { turntable, .. } => turntable.joint_ranges_rad(),
            Source::Model {
                joint_ranges_rad, ..
            } => joint_ranges_rad.clone(),
        }
    }

    /// The bounds.
    #[must_use]
    pub fn bounds(&self) -> &ErrorBox {
        &self.bounds
    }

    /// The configuration.
    #[must_use]
    pub fn config(&self) -> &McConfig {
        &self.config
    }

    /// The histogram half-ranges in use, rad.
    #[must_use]
    pub fn half_range_rad(&self) -> [f64; 3] {
        self.half_range_rad
    }

    /// The sampler (its draws are those of the run: see [`crate::chunk_rng`]).
    #[must_use]
    pub fn sampler(&self) -> &TurntableSampler {
        &self.sampler
    }

    /// How [`MonteCarlo::run`] evaluates the error angles' half-angle functions (chosen from
    /// the box).
    #[must_use]
    pub fn tier(&self) -> Tier {
        Tier::for_box(&self.bounds)
    }

    /// Number of chunks of the run.
    #[must_use]
    pub fn chunks(&self) -> u64 {
        self.config
            .samples
            .div_ceil(u64::from(self.config.chunk_size))
    }

    /// Chunks per wave: as many as the histogram budget allows, 8 to 256.
    fn wave_chunks(&self) -> u64 {
        let per_chunk = 3 * (self.config.histogram_bins + 2) * std::mem::size_of::<u64>();
        (WAVE_HISTOGRAM_BYTES / per_chunk).clamp(8, 256) as u64
    }

    fn chunk_len(&self, chunk: u64) -> usize {
        let cs = u64::from(self.config.chunk_size);
        (self.config.samples - chunk * cs).min(cs) as usize
    }

    /// Evaluate all chunks in waves on the current rayon pool, reducing in chunk order.
    fn drive<F>(&self, progress: &(dyn Fn(u64) + Sync), chunk: F) -> Result<McResult, McError>
    where
        F: Fn(u64) -> Result<Partial, McError> + Sync,
    {
        let mut acc = Partial::new(&self.half_range_rad, self.config.histogram_bins);
        crate::driver::run_chunks(self.chunks(), self.wave_chunks(), chunk, |p| {
            acc.merge(&p);
            if let Some((sample, axis, value)) = acc.non_finite {
                return Err(McError::NonFiniteModelOutput {
                    sample,
                    axis: axis.name(),
                    value,
                });
            }
            progress(acc.n);
            Ok(())
        })?;
        Ok(self.finish(acc))
    }

    fn finish(&self, acc: Partial) -> McResult {
        let Partial {
            n,
            mean,
            m2,
            max_abs,
            worst,
            within,
            within_all,
            ..
        } = &acc;
        let mut worst = worst.clone();
        let axes = OrientationAxis::ALL.map(|axis| {
            let k = axis.index();
            AxisSummary {
                axis,
                max_abs_rad: max_abs[k],
                // samples >= 1 is validated, so every axis has a worst sample
                worst: worst[k]
                    .take()
                    .unwrap_or_else(|| unreachable!("a run has at least one sample")),
                mean_rad: mean[k],
                m2_rad2: m2[k],
                histogram: acc.histogram(k),
            }
        });
        McResult {
            count: YieldCount::new(*n, self.config.seed, *within_all, within.to_vec()),
            chunk_size: self.config.chunk_size,
            requirement: self.config.requirement,
            axes,
        }
    }

    /// Run with the default evaluator: for a turntable the exact chain with the eq-24
    /// read-out, by the turntable's compiled plan ([`crate::fast`]), on the current rayon
    /// thread pool and the widest SIMD level of the CPU; for [`MonteCarlo::for_model`] the
    /// model itself.
    ///
    /// # Panics
    /// Only for [`MonteCarlo::for_model`], when the model fails on a drawn sample (use
    /// [`MonteCarlo::try_run`] there); a turntable's run cannot fail.
    #[must_use]
    pub fn run(&self) -> McResult {
        self.run_with_progress(&|_| {})
    }

    /// [`MonteCarlo::run`], calling `progress(samples_done)` after each batch of chunks.
    ///
    /// # Panics
    /// As [`MonteCarlo::run`].
    #[must_use]
    pub fn run_with_progress(&self, progress: &(dyn Fn(u64) + Sync)) -> McResult {
        self.try_run_with_progress(progress)
            .unwrap_or_else(|e| panic!("mc-verify: the model failed (use try_run): {e}"))
    }

    /// [`MonteCarlo::run`] returning the model's failure as an error.
    ///
    /// # Errors
    /// [`McError::Model`] or [`McError::NonFiniteModelOutput`] naming the first failing
    /// sample of a model's run.
    pub fn try_run(&self) -> Result<McResult, McError> {
        self.try_run_with_progress(&|_| {})
    }

    /// [`MonteCarlo::try_run`] with a progress callback.
    ///
    /// # Errors
    /// As [`MonteCarlo::try_run`].
    pub(crate) fn try_run_with_progress(
        &self,
        progress: &(dyn Fn(u64) + Sync),
    ) -> Result<McResult, McError> {
        match &self.source {
            Source::Table { .. } => Ok(self.run_fast(SimdLevel::detected(), progress)),
            Source::Model { model, .. } => self.run_model_with_progress(model.as_ref(), progress),
        }
    }

    /// [`MonteCarlo::run`] with the hot loop compiled for `level` instead of the widest level
    /// of the CPU ([`SimdLevel::detected`]). The result is bit-identical on every level (see
    /// [`crate::simd`]); this exists to prove it and to measure the levels against each other.
    ///
    /// # Errors
    /// [`McError::SimdUnavailable`] if the CPU lacks `level`.
    pub fn run_with_simd(&self, level: SimdLevel) -> Result<McResult, McError> {
        let level = level.check()?;
        match &self.source {
            Source::Table { .. } => Ok(self.run_fast(level, &|_| {})),
            Source::Model { .. } => self.try_run(),
        }
    }

    fn run_fast(&self, level: SimdLevel, progress: &(dyn Fn(u64) + Sync)) -> McResult {
        self.with_plan_kernel(RunAll {
            mc: self,
            level,
            progress,
        })
        .unwrap_or_else(|| unreachable!("run_fast is called for a turntable's run only"))
    }

    /// Call `user` with the plan kernel of this run's tier.
    fn with_plan_kernel<U: KernelUser>(&self, user: U) -> Option<U::Output> {
        let Source::Table { plan, .. } = &self.source else {
            return None;
        };
        let sampler = &self.sampler;
        match self.tier() {
            Tier::Tangent => Some(user.with(&PlanKernel::<TIER_TANGENT>::new(plan, sampler))),
            Tier::Short => Some(user.with(&PlanKernel::<TIER_SHORT>::new(plan, sampler))),
            Tier::Medium => Some(user.with(&PlanKernel::<TIER_MEDIUM>::new(plan, sampler))),
            Tier::Any => Some(user.with(&PlanKernel::<TIER_ANY>::new(plan, sampler))),
        }
    }

    /// Every chunk through `kernel`, with the hot loop compiled for `level`. A non-finite
    /// value cannot come out of the crate's kernels (finite bounded inputs, bounded
    /// quaternion arithmetic); were it to, this reports it rather than return it.
    pub(crate) fn drive_kernel<K: BlockKernel>(
        &self,
        level: SimdLevel,
        progress: &(dyn Fn(u64) + Sync),
        kernel: &K,
    ) -> McResult {
        let chunk = |chunk| {
            Ok(run_at(
                level,
                KernelChunk {
                    mc: self,
                    chunk,
                    kernel,
                },
            ))
        };
        self.drive(progress, chunk).unwrap_or_else(|e| {
            panic!("mc-verify: a fast kernel produced a non-finite value (a bug): {e}")
        })
    }

    /// The values $(\Delta\psi, \Delta\theta, \Delta\gamma)$ (rad) that [`MonteCarlo::run`]
    /// computes for every sample of chunk `chunk`, in sample order (a run never stores them;
    /// this is for checks and for inspecting a chunk). Empty for a chunk past the end, and
    /// for a Monte Carlo of a model ([`MonteCarlo::for_model`]), whose values come from the
    /// model's own evaluation in [`MonteCarlo::try_run`].
    #[must_use]
    pub fn chunk_values_rad(&self, chunk: u64) -> Vec<[f64; 3]> {
        if chunk >= self.chunks() {
            return Vec::new();
        }
        self.with_plan_kernel(ChunkValues { mc: self, chunk })
            .unwrap_or_default()
    }

    /// Run with any orientation-error model (for example the plain dense-matrix
    /// [`tt_kinematics::ExactChain`]); same samples as [`MonteCarlo::run`]. The model gets
    /// every joint angle and $\chi$; error translations are zero (the Monte Carlo draws
    /// orientation errors only).
    ///
    /// # Errors
    /// [`McError::ModelErrorCount`] or [`McError::BoundsForAnotherTurntable`] when the box
    /// does not have the model's error count or names; [`McError::Model`] if the model returns
    /// an error, [`McError::NonFiniteModelOutput`] if it returns a non-finite angle, each
    /// naming the first such sample (and the axis).
    pub fn run_model<M: OrientationErrorModel + Sync + ?Sized>(
        &self,
        model: &M,
    ) -> Result<McResult, McError> {
        self.run_model_with_progress(model, &|_| {})
    }

    /// [`MonteCarlo::run_model`] with a progress callback.
    ///
    /// # Errors
    /// As [`MonteCarlo::run_model`].
    pub(crate) fn run_model_with_progress<M: OrientationErrorModel + Sync + ?Sized>(
        &self,
        model: &M,
        progress: &(dyn Fn(u64) + Sync),
    ) -> Result<McResult, McError> {
        check_model_fit(model, &self.bounds)?;
        self.drive(progress, |c| self.model_chunk(model, c))
    }

    /// Draw every sample of the run and nothing else: the random words of each block and
    /// their decoding into the sample's numbers, $\chi$ ([`TurntableSampler::fill_block`])
    /// and every joint angle (rad), with the loop compiled for the same SIMD level as
    /// [`MonteCarlo::run`]. This is the work of producing the run's random turntables before
    /// evaluating anything: the limit set by the generator, the baseline of the throughput
    /// goals. Returns the number of samples drawn.
    #[must_use]
    pub fn draw_only(&self) -> u64 {
        self.draw(true)
    }

    /// [`MonteCarlo::draw_only`] without the decoding: only the generator's words
    /// ([`TurntableSampler::words_per_sample`] per sample) are produced. The strictest
    /// baseline: no run can be faster.
    #[must_use]
    pub fn draw_words_only(&self) -> u64 {
        self.draw(false)
    }

    fn draw(&self, decode: bool) -> u64 {
        let level = SimdLevel::detected();
        let mut drawn = 0u64;
        let chunk = |chunk| {
            Ok::<u64, std::convert::Infallible>(if decode {
                run_at(level, DrawChunk::<true> { mc: self, chunk })
            } else {
                run_at(level, DrawChunk::<false> { mc: self, chunk })
            })
        };
        let Ok(()) = crate::driver::run_chunks(self.chunks(), self.wave_chunks(), chunk, |n| {
            drawn += n;
            Ok(())
        });
        drawn
    }

    fn model_chunk<M: OrientationErrorModel + Sync + ?Sized>(
        &self,
        model: &M,
        chunk: u64,
    ) -> Result<Partial, McError> {
        let mut part = Partial::new(&self.half_range_rad, self.config.histogram_bins);
        let mut rng = chunk_rng(self.config.seed, chunk);
        let mut block = SampleBlock::new(&self.sampler);
        let mut out = Box::new([[0.0; BLOCK_CAPACITY]; 3]);
        let first = chunk * u64::from(self.config.chunk_size);
        let len = self.chunk_len(chunk);
        let n_translations = match &self.source {
            Source::Table { turntable, .. } => turntable.n_translation_errors(),
            Source::Model { model, .. } => model.n_translation_errors(),
        };
        let mut done = 0;
        while done < len {
            let n = (len - done).min(BLOCK_CAPACITY);
            self.sampler.fill_block(&mut rng, n, &mut block);
            for k in 0..n {
                let sample = first + (done + k) as u64;
                // the sampler's values are finite by construction
                let errors = TurntableErrors::new(block.chi_rad(k), vec![0.0; n_translations])
                    .unwrap_or_else(|_| unreachable!("finite draws"));
                let d = model
                    .orientation_error(&block.pose(k), &errors)
                    .map_err(|source| McError::Model { sample, source })?
                    .to_array();
                for (axis, &v) in OrientationAxis::ALL.iter().zip(&d) {
                    if !v.is_finite() {
                        return Err(McError::NonFiniteModelOutput {
                            sample,
                            axis: axis.name(),
                            value: v,
                        });
                    }
                    out[axis.index()][k] = v;
                }
            }
            part.add_block(
                first + done as u64,
                &block,
                &self.sampler,
                &out,
                &self.requirement_cmp_rad,
            );
            done += n;
        }
        Ok(part)
    }
}

/// Check a configuration: samples, chunk size, histogram bins and range.
fn check_config(config: &McConfig) -> Result<(), McError> {
    if config.samples == 0 {
        return Err(McError::ZeroSamples);
    }
    if config.chunk_size == 0 {
        return Err(McError::ZeroChunkSize);
    }
    if config.histogram_bins == 0 || config.histogram_bins > MAX_HISTOGRAM_BINS {
        return Err(McError::HistogramBins {
            bins: config.histogram_bins,
            max: MAX_HISTOGRAM_BINS,
        });
    }
    if let Some(h) = config.histogram_half_range_rad {
        for axis in OrientationAxis::ALL {
            let value = h[axis.index()];
            let inv_width = config.histogram_bins as f64 / (2.0 * value);
            if !(value.is_finite() && value > 0.0 && inv_width.is_finite()) {
                return Err(McError::HistogramRange {
                    axis: axis.name(),
                    value,
                });
            }
        }
    }
    Ok(())
}

/// The default histogram half-range of a model ([`MonteCarlo::for_model`]): its own first
/// order on a grid of poses, plus the remainder bound, with a margin.
fn model_half_range_rad<M: OrientationErrorModel + ?Sized>(
    model: &M,
    joint_ranges_rad: &[[f64; 2]],
    bounds: &ErrorBox,
) -> Result<[f64; 3], McError> {
    let ub = bounds.ub_rad();
    let s = bounds.sum_ub_rad();
    let remainder = (s.exp_m1() - s).max(READOUT_ROUNDING_RAD);
    let joints = joint_ranges_rad.len();
    let mut per = MODEL_RANGE_POINTS_PER_JOINT;
    while joints > 0 && per > 2 && per.pow(joints as u32) > MODEL_RANGE_MAX_POSES {
        per -= 1;
    }
    let total = if joints == 0 {
        1
    } else {
        per.pow(joints as u32)
    };
    let zero = TurntableErrors::zero(ub.len(), model.n_translation_errors());
    let mut first = [0.0_f64; 3];
    for cell in 0..total {
        let mut rest = cell;
        let pose: Vec<f64> = joint_ranges_rad
            .iter()
            .map(|&[lo, hi]| {
                let i = rest % per;
                rest /= per;
                lo + (hi - lo) * i as f64 / (per - 1).max(1) as f64
            })
            .collect();
        let pose = Pose::new(pose).map_err(|e| McError::Kinematics(e.into()))?;
        let c = model
            .first_order(&pose, &zero)
            .map_err(|source| McError::Model { sample: 0, source })?;
        for (k, f) in first.iter_mut().enumerate() {
            let v: f64 = (0..ub.len()).map(|j| ub[j] * c[(k, j)].abs()).sum();
            *f = f.max(v);
        }
    }
    Ok(first.map(|f| {
        let h = ((1.0 + MODEL_RANGE_MARGIN) * f + remainder).min(READOUT_ABS_CAP);
        if h.is_finite() && h > 0.0 {
            h
        } else {
            READOUT_ABS_CAP
        }
    }))
}

/// [`McError::BoundsForAnotherTurntable`] unless the box's error names are the turntable's.
fn check_fit(turntable: &Turntable, bounds: &ErrorBox) -> Result<(), McError> {
    check_names(&turntable.rotation_error_names(), bounds)
}

/// `bounds` against a model's errors: its count first (naming both sizes), then its names.
fn check_model_fit<M: OrientationErrorModel + ?Sized>(
    model: &M,
    bounds: &ErrorBox,
) -> Result<(), McError> {
    let names = model.error_names();
    if names.len() != bounds.len() {
        return Err(McError::ModelErrorCount {
            expected: names.len(),
            found: bounds.len(),
            names: names.join(", "),
        });
    }
    check_names(
        &names.iter().map(String::as_str).collect::<Vec<_>>(),
        bounds,
    )
}

/// The box's error names against `expected`, position by position.
fn check_names(expected: &[&str], bounds: &ErrorBox) -> Result<(), McError> {
    let found = bounds.names();
    for position in 0..expected.len().max(found.len()) {
        let (e, f) = (
            expected.get(position).copied().unwrap_or(""),
            found.get(position).map_or("", String::as_str),
        );
        if e != f {
            return Err(McError::BoundsForAnotherTurntable {
                position,
                expected: e.to_string(),
                found: f.to_string(),
            });
        }
    }
    Ok(())
}

/// Something done with a block kernel whose type is chosen at run time (the tier): the
/// generic method is monomorphised per kernel.
pub(crate) trait KernelUser {
    type Output;
    fn with<K: BlockKernel>(self, kernel: &K) -> Self::Output;
}

/// The whole run through a kernel.
struct RunAll<'a> {
    mc: &'a MonteCarlo,
    level: SimdLevel,
    progress: &'a (dyn Fn(u64) + Sync),
}

impl KernelUser for RunAll<'_> {
    type Output = McResult;
    fn with<K: BlockKernel>(self, kernel: &K) -> McResult {
        self.mc.drive_kernel(self.level, self.progress, kernel)
    }
}

/// The values of one chunk through a kernel.
struct ChunkValues<'a> {
    mc: &'a MonteCarlo,
    chunk: u64,
}

impl KernelUser for ChunkValues<'_> {
    type Output = Vec<[f64; 3]>;
    fn with<K: BlockKernel>(self, kernel: &K) -> Vec<[f64; 3]> {
        let Self { mc, chunk } = self;
        let mut rng = chunk_rng(mc.config.seed, chunk);
        let mut block = SampleBlock::new(&mc.sampler);
        let mut scratch = kernel.scratch();
        let mut out = Box::new([[0.0; BLOCK_CAPACITY]; 3]);
        let len = mc.chunk_len(chunk);
        let mut values = Vec::with_capacity(len);
        let mut done = 0;
        while done < len {
            let n = (len - done).min(BLOCK_CAPACITY);
            fill_words(&mc.sampler, &mut rng, n, &mut block);
            kernel.eval_block(&block, n, &mut scratch, &mut out);
            values.extend((0..n).map(|k| [out[0][k], out[1][k], out[2][k]]));
            done += n;
        }
        values
    }
}

/// Drawing one chunk (with or without decoding $\chi$ and the pose), as a [`HotLoop`]: the
/// baselines.
struct DrawChunk<'a, const DECODE: bool> {
    mc: &'a MonteCarlo,
    chunk: u64,
}

impl<const DECODE: bool> HotLoop for DrawChunk<'_, DECODE> {
    type Output = u64;

    #[inline(always)]
    fn run(self) -> u64 {
        let Self { mc, chunk } = self;
        let sampler = &mc.sampler;
        let mut rng = chunk_rng(mc.config.seed, chunk);
        let mut block = SampleBlock::new(sampler);
        let mut angles = vec![[0.0; BLOCK_CAPACITY]; sampler.n_joints()];
        let n_chi = sampler.n_rotation_errors();
        let len = mc.chunk_len(chunk);
        let mut done = 0;
        while done < len {
            let n = (len - done).min(BLOCK_CAPACITY);
            if DECODE {
                sampler.fill_block(&mut rng, n, &mut block);
                for ((j, col), law) in angles.iter_mut().enumerate().zip(sampler.joint_laws()) {
                    law.decode(block.column_words(n_chi + j), &mut col[..n]);
                }
                std::hint::black_box(&angles);
            } else {
                fill_words(sampler, &mut rng, n, &mut block);
            }
            std::hint::black_box(&block);
            done += n;
        }
        done as u64
    }
}

/// One chunk of a fast path, as a [`HotLoop`] compiled per SIMD level.
struct KernelChunk<'a, K> {
    mc: &'a MonteCarlo,
    chunk: u64,
    kernel: &'a K,
}

impl<K: BlockKernel> HotLoop for KernelChunk<'_, K> {
    type Output = Partial;

    #[inline(always)]
    fn run(self) -> Partial {
        let Self { mc, chunk, kernel } = self;
        let mut part = Partial::new(&mc.half_range_rad, mc.config.histogram_bins);
        let mut rng = chunk_rng(mc.config.seed, chunk);
        let mut block = SampleBlock::new(&mc.sampler);
        let mut scratch = kernel.scratch();
        let mut out = Box::new([[0.0; BLOCK_CAPACITY]; 3]);
        let first = chunk * u64::from(mc.config.chunk_size);
        let len = mc.chunk_len(chunk);
        let mut done = 0;
        while done < len {
            let n = (len - done).min(BLOCK_CAPACITY);
            fill_words(&mc.sampler, &mut rng, n, &mut block);
            kernel.eval_block(&block, n, &mut scratch, &mut out);
            part.add_block(
                first + done as u64,
                &block,
                &mc.sampler,
                &out,
                &mc.requirement_cmp_rad,
            );
            done += n;
        }
        part
    }
}
