//! The Monte Carlo driver: chunks, blocks, threads and the order-fixed reduction.

use crate::bounds::ErrorBox;
use crate::error::McError;
use crate::fast::{
    TIER_ANY, TIER_MEDIUM, TIER_SHORT, delta_block_sample, delta_from_t, short_tan_coefficients,
    sin_cos_turn_with, tier_for, turn_table,
};
use crate::sampler::{BLOCK_CAPACITY, SampleBlock, TurntableSampler, chunk_rng, fill_words};
use crate::simd::{HotLoop, SimdLevel, run_at};
use crate::stats::{AxisSummary, Partial};
use rayon::prelude::*;
use tt_kinematics::units::RAD_PER_DEG;
use tt_kinematics::{
    CHI_LEN, LinearModel, OrientationAxis, OrientationErrorModel, TurntableErrors,
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

/// The paper's orientation requirement, eq 16: $|\Delta\psi|, |\Delta\theta|, |\Delta\gamma|
/// \le 0.027°$, in degrees.
pub const PAPER_REQUIREMENT_DEG: f64 = 0.027;

/// What to run: sample count, seed, chunking, requirement and histogram layout.
///
/// The result is a function of (bounds, `samples`, `seed`, `chunk_size`) and the model only:
/// not of the thread count.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct McConfig {
    /// Number of random turntables, at least 1.
    pub samples: u64,
    /// Seed of the random streams.
    pub seed: u64,
    /// Samples per random stream (chunk), at least 1.
    pub chunk_size: u32,
    /// The requirement $I$ per axis ($\psi, \theta, \gamma$), rad.
    pub requirement_rad: [f64; 3],
    /// Histogram bins per axis, in `1..=MAX_HISTOGRAM_BINS`.
    pub histogram_bins: usize,
    /// Histogram half-ranges $H$ per axis, rad; `None` derives them from the bounds
    /// ([`MonteCarlo::histogram_half_range_rad`]).
    pub histogram_half_range_rad: Option<[f64; 3]>,
}

impl McConfig {
    /// `samples` draws with `seed`, the paper's requirement (eq 16) and default chunking and
    /// histograms.
    #[must_use]
    pub fn new(samples: u64, seed: u64) -> Self {
        Self {
            samples,
            seed,
            chunk_size: DEFAULT_CHUNK_SIZE,
            requirement_rad: [PAPER_REQUIREMENT_DEG * RAD_PER_DEG; 3],
            histogram_bins: DEFAULT_HISTOGRAM_BINS,
            histogram_half_range_rad: None,
        }
    }

    /// The same configuration with another requirement (degrees, the unit of eq 16).
    #[must_use]
    pub fn with_requirement_deg(self, psi: f64, theta: f64, gamma: f64) -> Self {
        Self {
            requirement_rad: [psi, theta, gamma].map(|d| d * RAD_PER_DEG),
            ..self
        }
    }
}

/// The outcome of a run.
#[derive(Debug, Clone, PartialEq)]
pub struct McResult {
    /// Number of samples evaluated.
    pub samples: u64,
    /// The seed.
    pub seed: u64,
    /// The chunk size used.
    pub chunk_size: u32,
    /// The requirement $I$, rad.
    pub requirement_rad: [f64; 3],
    /// Per-axis results, in the order $\Delta\psi, \Delta\theta, \Delta\gamma$.
    pub axes: [AxisSummary; 3],
    /// Samples with all three angles inside the requirement.
    pub within_requirement_all: u64,
}

impl McResult {
    /// The summary of one axis.
    #[must_use]
    pub fn axis(&self, axis: OrientationAxis) -> &AxisSummary {
        &self.axes[axis.index()]
    }

    /// Fraction of samples with all three angles inside the requirement.
    #[must_use]
    pub fn within_requirement_fraction(&self) -> f64 {
        self.within_requirement_all as f64 / self.samples as f64
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
            .map(|a| a.variance_rad2(self.samples).sqrt())
    }
}

/// A validated Monte Carlo verification of a tolerance box (paper §4.3, Figure 9).
#[derive(Debug, Clone)]
pub struct MonteCarlo {
    bounds: ErrorBox,
    config: McConfig,
    sampler: TurntableSampler,
    half_range_rad: [f64; 3],
}

impl MonteCarlo {
    /// Validate `config` against `bounds`: errors name the field at fault.
    pub fn new(bounds: ErrorBox, config: McConfig) -> Result<Self, McError> {
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
        for axis in OrientationAxis::ALL {
            let value = config.requirement_rad[axis.index()];
            if !(value.is_finite() && value > 0.0) {
                return Err(McError::Requirement {
                    axis: axis.name(),
                    value,
                });
            }
        }
        let half_range_rad = match config.histogram_half_range_rad {
            Some(h) => {
                for axis in OrientationAxis::ALL {
                    let value = h[axis.index()];
                    if !(value.is_finite() && value > 0.0) {
                        return Err(McError::HistogramRange {
                            axis: axis.name(),
                            value,
                        });
                    }
                }
                h
            }
            None => Self::histogram_half_range_rad(&bounds),
        };
        Ok(Self {
            bounds,
            config,
            sampler: TurntableSampler::new(&bounds),
            half_range_rad,
        })
    }

    /// The default histogram half-range $H_k$ for a box: a rigorous bound on $|\Delta_k|$,
    /// $$H_k = \max_{\phi_2} \sum_i \mathrm{UB}_i |c_{ki}(\phi_2)| + (e^S - 1 - S),\quad
    ///   S = \textstyle\sum_i \mathrm{UB}_i,$$
    /// the exact maximum of the first-order model (eq 26) plus a bound on the remainder:
    /// $\Delta\mathbf R$ is a product of eight rotations $e^{A_j}$ with $\|A_j\|_2 = |\chi_j|$,
    /// and $\|\prod_j e^{A_j} - I - \sum_j A_j\|_2 \le e^S - 1 - S$. So no sample of the exact
    /// chain falls outside (the overflow counts stay zero; tested).
    #[must_use]
    pub fn histogram_half_range_rad(bounds: &ErrorBox) -> [f64; 3] {
        let model = LinearModel::paper_eq26();
        let ub = bounds.ub_rad();
        let s = bounds.sum_ub_rad();
        let remainder = s.exp_m1() - s;
        OrientationAxis::ALL.map(|axis| {
            let first = model
                .max_abs_weighted(axis, &ub, 0.0, std::f64::consts::TAU)
                .value;
            // a degenerate (all-zero) box still gets a valid, tiny range
            (first + remainder).max(f64::MIN_POSITIVE)
        })
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

    /// The sampler (its draws are those of the run: see [`crate::chunk_rng`]).
    #[must_use]
    pub fn sampler(&self) -> &TurntableSampler {
        &self.sampler
    }

    /// Chunks per wave: as many as the histogram budget allows, 8 to 256.
    fn wave_chunks(&self) -> u64 {
        let per_chunk = 3 * (self.config.histogram_bins + 2) * std::mem::size_of::<u64>();
        (WAVE_HISTOGRAM_BYTES / per_chunk).clamp(8, 256) as u64
    }

    fn chunks(&self) -> u64 {
        self.config
            .samples
            .div_ceil(u64::from(self.config.chunk_size))
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
        let n_chunks = self.chunks();
        let mut start = 0;
        while start < n_chunks {
            let end = (start + self.wave_chunks()).min(n_chunks);
            let parts: Vec<Result<Partial, McError>> =
                (start..end).into_par_iter().map(&chunk).collect();
            for p in parts {
                acc.merge(&p?);
            }
            progress(acc.n);
            start = end;
        }
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
        } = acc;
        let axes = OrientationAxis::ALL.map(|axis| {
            let k = axis.index();
            AxisSummary {
                axis,
                max_abs_rad: max_abs[k],
                // samples >= 1 is validated, so every axis has a worst sample
                worst: worst[k].unwrap_or_else(|| unreachable!("a run has at least one sample")),
                mean_rad: mean[k],
                m2_rad2: m2[k],
                within_requirement: within[k],
                histogram: acc.histogram(k),
            }
        });
        McResult {
            samples: n,
            seed: self.config.seed,
            chunk_size: self.config.chunk_size,
            requirement_rad: self.config.requirement_rad,
            axes,
            within_requirement_all: within_all,
        }
    }

    /// Run with the default evaluator: the exact chain with the eq-24 read-out, by the fast
    /// quaternion path ([`crate::FastChain`]), on the current rayon thread pool.
    #[must_use]
    pub fn run(&self) -> McResult {
        self.run_with_progress(&|_| {})
    }

    /// [`MonteCarlo::run`], calling `progress(samples_done)` after each batch of chunks.
    #[must_use]
    pub fn run_with_progress(&self, progress: &(dyn Fn(u64) + Sync)) -> McResult {
        self.run_fast(SimdLevel::detected(), progress)
    }

    /// [`MonteCarlo::run`] with the hot loop compiled for `level` instead of the widest level
    /// of the CPU ([`SimdLevel::detected`]). The result is bit-identical on every level (see
    /// [`crate::simd`]); this exists to prove it and to measure the levels against each other.
    ///
    /// Fails with [`McError::SimdUnavailable`] if the CPU lacks `level`.
    pub fn run_with_simd(&self, level: SimdLevel) -> Result<McResult, McError> {
        Ok(self.run_fast(level.check()?, &|_| {}))
    }

    fn run_fast(&self, level: SimdLevel, progress: &(dyn Fn(u64) + Sync)) -> McResult {
        let zero_lb = self.bounds.lb_rad().iter().all(|&lb| lb <= 0.0);
        let sampler = &self.sampler;
        match tier_for(self.bounds.max_ub_rad()) {
            TIER_SHORT if zero_lb => {
                let coeffs = short_tan_coefficients(sampler.scale_rad());
                self.drive_kernel(level, progress, &ZeroLbShortKernel { coeffs })
            }
            TIER_SHORT => self.drive_kernel(level, progress, &TierKernel::<TIER_SHORT> { sampler }),
            TIER_MEDIUM => {
                self.drive_kernel(level, progress, &TierKernel::<TIER_MEDIUM> { sampler })
            }
            _ => self.drive_kernel(level, progress, &TierKernel::<TIER_ANY> { sampler }),
        }
    }

    /// Every chunk through `kernel`, with the hot loop compiled for `level`.
    fn drive_kernel<K: BlockKernel + Sync>(
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
        self.drive(progress, chunk)
            .unwrap_or_else(|_| unreachable!("the fast path has no failure"))
    }

    /// Run with any orientation-error model (for example the plain dense-matrix
    /// [`tt_kinematics::ExactChain`]); same samples as [`MonteCarlo::run`].
    ///
    /// Fails only if the model returns a non-finite angle.
    pub fn run_model<M: OrientationErrorModel + Sync>(
        &self,
        model: &M,
    ) -> Result<McResult, McError> {
        self.run_model_with_progress(model, &|_| {})
    }

    /// [`MonteCarlo::run_model`] with a progress callback.
    pub fn run_model_with_progress<M: OrientationErrorModel + Sync>(
        &self,
        model: &M,
        progress: &(dyn Fn(u64) + Sync),
    ) -> Result<McResult, McError> {
        self.drive(progress, |c| self.model_chunk(model, c))
    }

    /// Draw every sample of the run and nothing else: the random words of each block and
    /// their decoding into the sample's ten numbers, $\chi$ ([`TurntableSampler::fill_block`])
    /// and the pose angles $\phi_1, \phi_2$ (rad), with the loop compiled
    /// for the same SIMD level as [`MonteCarlo::run`]. This is the work of producing the
    /// run's random turntables before evaluating anything: the limit set by the generator,
    /// the baseline of the "half the generator" goal. Returns the number of samples drawn.
    #[must_use]
    pub fn draw_only(&self) -> u64 {
        self.draw(true)
    }

    /// [`MonteCarlo::draw_only`] without the decoding: only the generator's words (40 bytes
    /// per sample) are produced. The strictest baseline: no run can be faster.
    #[must_use]
    pub fn draw_words_only(&self) -> u64 {
        self.draw(false)
    }

    fn draw(&self, decode: bool) -> u64 {
        let level = SimdLevel::detected();
        let n_chunks = self.chunks();
        let mut drawn = 0u64;
        let mut start = 0;
        while start < n_chunks {
            let end = (start + self.wave_chunks()).min(n_chunks);
            drawn += (start..end)
                .into_par_iter()
                .map(|chunk| {
                    if decode {
                        run_at(level, DrawChunk::<true> { mc: self, chunk })
                    } else {
                        run_at(level, DrawChunk::<false> { mc: self, chunk })
                    }
                })
                .sum::<u64>();
            start = end;
        }
        drawn
    }

    fn model_chunk<M: OrientationErrorModel + Sync>(
        &self,
        model: &M,
        chunk: u64,
    ) -> Result<Partial, McError> {
        let mut part = Partial::new(&self.half_range_rad, self.config.histogram_bins);
        let mut rng = chunk_rng(self.config.seed, chunk);
        let mut block = Box::<SampleBlock>::default();
        let mut out = Box::new([[0.0; BLOCK_CAPACITY]; 3]);
        let first = chunk * u64::from(self.config.chunk_size);
        let len = self.chunk_len(chunk);
        let mut done = 0;
        while done < len {
            let n = (len - done).min(BLOCK_CAPACITY);
            self.sampler.fill_block(&mut rng, n, &mut block);
            for k in 0..n {
                // the sampler's values are finite by construction
                let errors = TurntableErrors::from_rad(block.chi_rad(k), 0.0)
                    .unwrap_or_else(|_| unreachable!("finite draws"));
                let d = model.orientation_error(&block.pose(k), &errors).to_array();
                for (axis, &v) in OrientationAxis::ALL.iter().zip(&d) {
                    if !v.is_finite() {
                        return Err(McError::NonFiniteModelOutput {
                            sample: first + (done + k) as u64,
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
                &self.config.requirement_rad,
            );
            done += n;
        }
        Ok(part)
    }
}

/// The per-sample work of a fast path. Every method is `#[inline(always)]` in every
/// implementation so that it is compiled into the loop of each SIMD level (a closure would be
/// compiled once, for the portable level, and called per sample).
trait BlockKernel {
    /// Turn the `n` drawn samples of `block` into the kernel's eight inputs per sample
    /// (`inputs[i][k]` for error component `i` of sample `k`), column by column.
    fn prepare(&self, block: &SampleBlock, n: usize, inputs: &mut [[f64; BLOCK_CAPACITY]; CHI_LEN]);
    /// `[dpsi, dtheta, dgamma]` of sample `k` with `(sin phi2, cos phi2) = (s2, c2)`.
    fn eval(
        &self,
        s2: f64,
        c2: f64,
        inputs: &[[f64; BLOCK_CAPACITY]; CHI_LEN],
        k: usize,
    ) -> [f64; 3];
}

/// All lower bounds zero, short-series tier: unnormalised quaternions from the words'
/// half-integers ([`crate::fast::short_tan_coefficients`]).
struct ZeroLbShortKernel {
    coeffs: [[f64; 2]; CHI_LEN],
}

impl BlockKernel for ZeroLbShortKernel {
    #[inline(always)]
    fn prepare(
        &self,
        block: &SampleBlock,
        n: usize,
        inputs: &mut [[f64; BLOCK_CAPACITY]; CHI_LEN],
    ) {
        for (i, t) in inputs.iter_mut().enumerate() {
            for (x, w) in t[..n].iter_mut().zip(block.column_words(i)) {
                *x = f64::from(w as i32) + 0.5;
            }
        }
    }

    #[inline(always)]
    fn eval(&self, s2: f64, c2: f64, t: &[[f64; BLOCK_CAPACITY]; CHI_LEN], k: usize) -> [f64; 3] {
        delta_from_t(s2, c2, std::array::from_fn(|i| t[i][k]), &self.coeffs)
    }
}

/// Any box: decoded $\chi$ ([`TurntableSampler::chi_from_word`]), half-angle functions of
/// tier `TIER`.
struct TierKernel<'a, const TIER: u8> {
    sampler: &'a TurntableSampler,
}

impl<const TIER: u8> BlockKernel for TierKernel<'_, TIER> {
    #[inline(always)]
    fn prepare(
        &self,
        block: &SampleBlock,
        n: usize,
        inputs: &mut [[f64; BLOCK_CAPACITY]; CHI_LEN],
    ) {
        for (i, chi) in inputs.iter_mut().enumerate() {
            self.sampler
                .decode_chi(i, block.column_words(i), &mut chi[..n]);
        }
    }

    #[inline(always)]
    fn eval(&self, s2: f64, c2: f64, chi: &[[f64; BLOCK_CAPACITY]; CHI_LEN], k: usize) -> [f64; 3] {
        delta_block_sample::<TIER>(s2, c2, std::array::from_fn(|i| chi[i][k]))
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
        let mut rng = chunk_rng(mc.config.seed, chunk);
        let mut block = Box::<SampleBlock>::default();
        let mut angles = Box::new([[0.0; BLOCK_CAPACITY]; 2]);
        let len = mc.chunk_len(chunk);
        let mut done = 0;
        while done < len {
            let n = (len - done).min(BLOCK_CAPACITY);
            if DECODE {
                mc.sampler.fill_block(&mut rng, n, &mut block);
                for (j, col) in angles.iter_mut().enumerate() {
                    for (a, w) in col[..n].iter_mut().zip(block.column_words(8 + j)) {
                        *a = TurntableSampler::angle_from_word(w);
                    }
                }
                std::hint::black_box(&angles);
            } else {
                fill_words(&mut rng, n, &mut block);
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
        let mut block = Box::<SampleBlock>::default();
        let mut inputs = Box::new([[0.0; BLOCK_CAPACITY]; CHI_LEN]);
        let mut out = Box::new([[0.0; BLOCK_CAPACITY]; 3]);
        let mut sc = Box::new([[0.0; BLOCK_CAPACITY]; 2]);
        let first = chunk * u64::from(mc.config.chunk_size);
        let len = mc.chunk_len(chunk);
        let mut done = 0;
        while done < len {
            let n = (len - done).min(BLOCK_CAPACITY);
            fill_words(&mut rng, n, &mut block);
            kernel.prepare(&block, n, &mut inputs);
            let table = turn_table();
            let [sin2, cos2] = &mut *sc;
            for ((s, c), w) in sin2[..n]
                .iter_mut()
                .zip(&mut cos2[..n])
                .zip(block.column_words(9))
            {
                (*s, *c) = sin_cos_turn_with(table, w);
            }
            for k in 0..n {
                let d = kernel.eval(sc[0][k], sc[1][k], &inputs, k);
                out[0][k] = d[0];
                out[1][k] = d[1];
                out[2][k] = d[2];
            }
            part.add_block(
                first + done as u64,
                &block,
                &mc.sampler,
                &out,
                &mc.config.requirement_rad,
            );
            done += n;
        }
        part
    }
}
