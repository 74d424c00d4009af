//! The Monte Carlo method of JCGM 101 (propagation of distributions) for any measurement
//! model with one or several outputs, run adaptively to a stated numerical tolerance, in
//! memory of one block whatever the number of trials, with the same answer for any thread
//! count; and the validation of a GUM result against it (JCGM 101 8).
//!
//! # The adaptive procedure (JCGM 101 7.9)
//! Blocks of $M = \max(\lceil 100/(1-p) \rceil, 10^4)$ trials ($p$ the coverage probability).
//! Each block $r$ gives, per output, the average $\bar y^{(r)}$, the standard deviation
//! $u^{(r)}$ (divisor $M - 1$, 7.6), and the endpoints of the probabilistically symmetric and of
//! the shortest $100p\,\%$ coverage interval (7.7: the sorted values $y_{(1)} \le \dots \le
//! y_{(M)}$, $q = pM$ rounded half up; symmetric $[y_{(r)}, y_{(r+q)}]$ with $r = (M-q)/2$, or
//! $\lfloor (M - q + 1)/2 \rfloor$ when that is not an integer; shortest: the $r$ of the least
//! $y_{(r+q)} - y_{(r)}$). After $h \ge 2$ blocks, with $s_z$ the standard deviation of the
//! average of the $h$ block values of each quantity $z$,
//! $s_z^2 = \frac{1}{h(h-1)} \sum_r (z^{(r)} - \bar z)^2$, the run has stabilized when
//! $2 s_z \le \delta$ for $y$, $u(y)$ and both endpoints of the interval stabilized
//! ([`McSettings::interval`], symmetric by default), for every output. The numerical tolerance $\delta$ of
//! $u(y)$ (7.9.2) writes $u(y) = c \times 10^{\ell}$ with $c$ an integer of $n_{\mathrm{dig}}$
//! digits (the significant digits asked, default 2) and is $\delta = \tfrac12 10^{\ell}$.
//!
//! The results are $y$, the average of all $hM$ values, $u(y)$ from all $hM$ values (exact,
//! pooled block sums), and the interval endpoints as the averages of the block endpoints
//! (the values of one block are kept, never all $hM$: the averages differ from the endpoints of
//! the $hM$ values by a few $s_z$ at most, below $\delta$ once stabilized).
//!
//! # Streams
//! Trial $t$ of block $b$ lies in chunk $c = \lfloor t / 512 \rfloor$, drawn from ChaCha8 keyed
//! by the seed (`seed_from_u64`) on stream $2^{20} b + c$; each input component consumes a
//! fixed number of uniforms per trial ([`crate::Distribution`]), so every trial's draw is fixed
//! by (seed, block, trial) whatever thread computes it.
//!
//! # Validation of a GUM result (JCGM 101 8.2)
//! The GUM interval $y \pm U_p$ against the Monte Carlo interval $[y_{\mathrm{low}},
//! y_{\mathrm{high}}]$: $d_{\mathrm{low}} = |y - U_p - y_{\mathrm{low}}|$, $d_{\mathrm{high}} =
//! |y + U_p - y_{\mathrm{high}}|$; validated when both are at most $\delta$.
//!
//! Inputs are independent; correlated inputs are a linear map of independent ones inside the
//! model (as for [`crate::Budget::evaluate_mapped`]). A normal input is sampled as a normal
//! (JCGM 101 6.4.7) whatever its degrees of freedom.
//!
//! # Reference
//! JCGM 101:2008, *Evaluation of measurement data - Supplement 1 to the GUM - Propagation of
//! distributions using a Monte Carlo method*, 6.4, 7.2, 7.6, 7.7, 7.9, 8.2.

use crate::error::MetrologyError;
use crate::input::Input;
use rand_chacha::ChaCha8Rng;
use rand_core::{Rng, SeedableRng};
use rayon::prelude::*;

/// The largest coverage probability of a Monte Carlo run: its blocks of $100/(1-p)$ trials
/// hold $10^7$ values per output.
pub(crate) const MAX_MC_COVERAGE: f64 = 0.999_99;

/// Trials per chunk (the unit of parallel work and of a ChaCha stream).
pub(crate) const CHUNK_TRIALS: usize = 512;

/// A measurement model: from one draw of the input components to the outputs.
pub trait Model: Sync {
    /// The number of outputs.
    fn outputs(&self) -> usize;
    /// Writes the outputs `y` (length [`Model::outputs`]) for the input components `x` (in the
    /// order of the inputs; a disc's $x$ then $y$).
    fn evaluate(&self, x: &[f64], y: &mut [f64]);
}

/// A model from a closure (see [`model_fn`]).
#[derive(Debug, Clone)]
pub struct FnModel<F> {
    outputs: usize,
    f: F,
}

impl<F: Fn(&[f64], &mut [f64]) + Sync> Model for FnModel<F> {
    fn outputs(&self) -> usize {
        self.outputs
    }
    fn evaluate(&self, x: &[f64], y: &mut [f64]) {
        (self.f)(x, y);
    }
}

/// A [`Model`] of `outputs` outputs computed by `f(x, y)`.
pub fn model_fn<F: Fn(&[f64], &mut [f64]) + Sync>(outputs: usize, f: F) -> FnModel<F> {
    FnModel { outputs, f }
}

/// The settings of an adaptive Monte Carlo run.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct McSettings {
    /// The coverage probability $p$ of the intervals, in (0, 1). Default 0.95.
    pub coverage: f64,
    /// $n_{\mathrm{dig}}$: significant digits of $u(y)$ that the run stabilizes, 1 to 6.
    /// Default 2.
    pub significant_digits: u32,
    /// The seed. Default 1.
    pub seed: u64,
    /// At most this many trials (rounded up to whole blocks): the run stops there unstabilized
    /// ([`McResult::stabilized`] false). Default $10^8$.
    pub max_trials: u64,
    /// The coverage interval whose endpoints the run stabilizes (both are reported).
    /// Default [`IntervalKind::Symmetric`]: the shortest interval's endpoints of a symmetric
    /// distribution wander along its flat optimum (the length is stable, the position is
    /// not), so stabilize on it only where it is the interval reported.
    pub interval: IntervalKind,
}

impl Default for McSettings {
    fn default() -> Self {
        McSettings {
            coverage: 0.95,
            significant_digits: 2,
            seed: 1,
            max_trials: 100_000_000,
            interval: IntervalKind::Symmetric,
        }
    }
}

/// The block size of JCGM 101 7.9.4 b): $\max(\lceil 100/(1-p) \rceil, 10^4)$.
#[must_use]
pub(crate) fn block_trials(coverage: f64) -> usize {
    ((100.0 / (1.0 - coverage)).ceil() as usize).max(10_000)
}

/// The numerical tolerance $\delta$ of a value $u$ stated to `digits` significant digits
/// (JCGM 101 7.9.2): $u = c \times 10^\ell$, $c$ of `digits` digits, $\delta = \tfrac12
/// 10^\ell$. Zero for $u = 0$.
///
/// ```
/// // JCGM 101 7.9.2 example: u(y) = 0.000 35 g to two digits: delta = 0.5e-5 g
/// approx::assert_relative_eq!(metrology::montecarlo::numerical_tolerance(0.00035, 2), 0.5e-5, max_relative = 1e-12);
/// approx::assert_relative_eq!(metrology::montecarlo::numerical_tolerance(2.0, 1), 0.5, max_relative = 1e-12);
/// ```
#[must_use]
pub fn numerical_tolerance(u: f64, digits: u32) -> f64 {
    if !(u > 0.0 && u.is_finite()) {
        return 0.0;
    }
    // c has `digits` digits: 10^(digits-1) <= c < 10^digits
    let mut ell = u.log10().floor() as i32 - (digits as i32 - 1);
    // guard the floor against rounding of log10 at powers of ten
    if u / 10f64.powi(ell) >= 10f64.powi(digits as i32) {
        ell += 1;
    } else if u / 10f64.powi(ell) < 10f64.powi(digits as i32 - 1) {
        ell -= 1;
    }
    0.5 * 10f64.powi(ell)
}

/// Mean and sum of squared deviations of a stream of values (Welford; Chan for merging).
#[derive(Debug, Clone, Copy, Default)]
struct Moments {
    n: f64,
    mean: f64,
    m2: f64,
}

impl Moments {
    fn push(&mut self, v: f64) {
        self.n += 1.0;
        let d = v - self.mean;
        self.mean += d / self.n;
        self.m2 += d * (v - self.mean);
    }

    fn merge(&mut self, o: &Moments) {
        let n = self.n + o.n;
        let d = o.mean - self.mean;
        self.mean += d * o.n / n;
        self.m2 += o.m2 + d * d * self.n * o.n / n;
        self.n = n;
    }

    /// Standard deviation of the values (divisor n - 1).
    fn sd(&self) -> f64 {
        (self.m2 / (self.n - 1.0)).max(0.0).sqrt()
    }

    /// Standard deviation of their average: $s / \sqrt{n}$.
    fn sd_of_mean(&self) -> f64 {
        self.sd() / self.n.sqrt()
    }
}

/// The six block quantities of an output: mean, u, symmetric and shortest endpoints.
const QUANTITIES: usize = 6;

/// The adaptive Monte Carlo of JCGM 101 7.9 of `model` over the independent `inputs`.
///
/// ```
/// use metrology::montecarlo::{McSettings, model_fn, run};
/// use metrology::Input;
/// // y = x1 + x2, both rectangular of half-width 1: a triangle on [-2, 2], u = sqrt(2/3)
/// let inputs = [Input::rectangular("x1", 0.0, 1.0)?, Input::rectangular("x2", 0.0, 1.0)?];
/// let settings = McSettings { significant_digits: 1, ..McSettings::default() };
/// let result = run(&inputs, &model_fn(1, |x, y| y[0] = x[0] + x[1]), &settings)?;
/// let y = &result.outputs()[0];
/// assert!(result.stabilized());
/// assert!((y.standard_uncertainty() - (2.0_f64 / 3.0).sqrt()).abs() < y.tolerance());
/// // the 95 % interval of the triangle: +-2(1 - sqrt(0.05)) = +-1.553
/// assert!((y.symmetric().1 - 1.5528).abs() < 2.0 * y.tolerance());
/// # Ok::<(), metrology::MetrologyError>(())
/// ```
///
/// # Errors
/// `coverage` outside (0, [`MAX_MC_COVERAGE`]], `significant_digits` outside 1..=6, `max_trials` zero, no
/// inputs or no outputs, or a model value that is not finite
/// ([`MetrologyError::NonFiniteModelValue`]).
pub fn run<M: Model>(
    inputs: &[Input],
    model: &M,
    settings: &McSettings,
) -> Result<McResult, MetrologyError> {
    // blocks of 100 / (1 - p) trials: p <= 1 - 1e-5 keeps a block within 1e7 values per output
    let p = tt_core::in_range(
        "coverage",
        settings.coverage,
        std::ops::Bound::Excluded(0.0),
        std::ops::Bound::Included(MAX_MC_COVERAGE),
        "",
    )?;
    tt_core::count(
        "significant_digits",
        u64::from(settings.significant_digits),
        6,
    )?;
    tt_core::count("max_trials", settings.max_trials, u64::MAX)?;
    tt_core::count("inputs", inputs.len() as u64, u64::MAX)?;
    let m_out = model.outputs();
    tt_core::count("model.outputs", m_out as u64, u64::MAX)?;
    let mb = block_trials(p);
    let q = {
        let pm = p * mb as f64;
        if (pm - pm.round()).abs() < 1e-9 {
            pm.round() as usize
        } else {
            (pm + 0.5).floor() as usize
        }
    }
    .min(mb - 1);
    // 0-based start of the symmetric interval: r - 1 of JCGM 101 7.7.2, with r = (M - q)/2
    // when even, (M - q + 1)/2 when odd: the ceiling of (M - q)/2 either way
    let sym_start = (mb - q).div_ceil(2).max(1) - 1;

    let components: usize = inputs.iter().map(Input::components).sum();
    let mut values = vec![0.0; mb * m_out]; // trial-major: values[t * m_out + j]
    let mut column = vec![0.0; mb];
    let mut total = vec![Moments::default(); m_out];
    let mut blocks = vec![[Moments::default(); QUANTITIES]; m_out];
    let mut h: u64 = 0;
    let stabilized = loop {
        draw_block(inputs, components, model, settings.seed, h, &mut values)?;
        h += 1;
        for j in 0..m_out {
            let mut mo = Moments::default();
            for (t, c) in column.iter_mut().enumerate() {
                *c = values[t * m_out + j];
                mo.push(*c);
            }
            column.sort_unstable_by(f64::total_cmp);
            let mut best = 0;
            for r in 1..mb - q {
                if column[r + q] - column[r] < column[best + q] - column[best] {
                    best = r;
                }
            }
            let block = [
                mo.mean,
                mo.sd(),
                column[sym_start],
                column[sym_start + q],
                column[best],
                column[best + q],
            ];
            for (acc, v) in blocks[j].iter_mut().zip(block) {
                acc.push(v);
            }
            total[j].merge(&mo);
        }
        if h >= 2 {
            // y, u(y) and the stabilized interval's endpoints
            let ends = match settings.interval {
                IntervalKind::Symmetric => [2, 3],
                IntervalKind::Shortest => [4, 5],
            };
            let done = (0..m_out).all(|j| {
                let delta = numerical_tolerance(total[j].sd(), settings.significant_digits);
                [0, 1, ends[0], ends[1]]
                    .iter()
                    .all(|&k| 2.0 * blocks[j][k].sd_of_mean() <= delta)
            });
            if done {
                break true;
            }
        }
        if h.saturating_mul(mb as u64) >= settings.max_trials {
            break false;
        }
    };
    let outputs = (0..m_out)
        .map(|j| {
            let b = &blocks[j];
            let u = total[j].sd();
            McOutput {
                estimate: total[j].mean,
                standard_uncertainty: u,
                symmetric: (b[2].mean, b[3].mean),
                shortest: (b[4].mean, b[5].mean),
                tolerance: numerical_tolerance(u, settings.significant_digits),
                block_sd: (h >= 2).then(|| std::array::from_fn(|k| b[k].sd_of_mean())),
            }
        })
        .collect();
    Ok(McResult {
        outputs,
        trials: h * mb as u64,
        block_trials: mb,
        stabilized,
        coverage: p,
        stored_values: values.len() + column.len(),
    })
}

/// Draws block `block`: `values[t * m + j]` is output `j` of trial `t`.
fn draw_block<M: Model>(
    inputs: &[Input],
    components: usize,
    model: &M,
    seed: u64,
    block: u64,
    values: &mut [f64],
) -> Result<(), MetrologyError> {
    let m = model.outputs();
    let block_start = block * (values.len() / m) as u64;
    let first_error = values
        .par_chunks_mut(CHUNK_TRIALS * m)
        .enumerate()
        .map(|(chunk, out)| {
            let mut rng = ChaCha8Rng::seed_from_u64(seed);
            rng.set_stream((block << 20) | chunk as u64);
            let mut x = vec![0.0; components];
            let mut w = [0.0; 2];
            for (t, y) in out.chunks_exact_mut(m).enumerate() {
                let mut k = 0;
                for input in inputs {
                    let d = input.distribution;
                    for wi in w.iter_mut().take(d.uniforms()) {
                        // (0, 1): never 0, so ln and sqrt stay finite
                        *wi = ((rng.next_u64() >> 11) as f64 + 0.5) * (1.0 / (1u64 << 53) as f64);
                    }
                    let c = d.components();
                    d.deviation(&w, &mut x[k..k + c]);
                    for (xi, e) in x[k..k + c].iter_mut().zip(input.estimate) {
                        *xi += e;
                    }
                    k += c;
                }
                model.evaluate(&x, y);
                if let Some((j, &v)) = y.iter().enumerate().find(|(_, v)| !v.is_finite()) {
                    return Some((block_start + (chunk * CHUNK_TRIALS + t) as u64, j, v));
                }
            }
            None
        })
        .flatten()
        .min_by_key(|e| e.0);
    match first_error {
        Some((t, output, value)) => Err(MetrologyError::NonFiniteModelValue {
            output,
            trial: t,
            value,
        }),
        None => Ok(()),
    }
}

/// The Monte Carlo result of one output.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct McOutput {
    pub(crate) estimate: f64,
    pub(crate) standard_uncertainty: f64,
    pub(crate) symmetric: (f64, f64),
    pub(crate) shortest: (f64, f64),
    pub(crate) tolerance: f64,
    pub(crate) block_sd: Option<[f64; QUANTITIES]>,
}

/// Read access to the fields (crate-private, so the type can grow without breaking callers).
impl McOutput {
    /// $y$: the average of all values.
    #[must_use]
    pub fn estimate(&self) -> f64 {
        self.estimate
    }

    /// $u(y)$: the standard deviation of all values.
    #[must_use]
    pub fn standard_uncertainty(&self) -> f64 {
        self.standard_uncertainty
    }

    /// The probabilistically symmetric coverage interval $(y_{\mathrm{low}},
    /// y_{\mathrm{high}})$.
    #[must_use]
    pub fn symmetric(&self) -> (f64, f64) {
        self.symmetric
    }

    /// The shortest coverage interval.
    #[must_use]
    pub fn shortest(&self) -> (f64, f64) {
        self.shortest
    }

    /// The numerical tolerance $\delta$ of $u(y)$ at the run's significant digits.
    #[must_use]
    pub fn tolerance(&self) -> f64 {
        self.tolerance
    }

    /// The standard deviations $s_z$ of the averages of the block values of $y$, $u(y)$, the
    /// symmetric and the shortest interval's endpoints (in that order): the run stabilized
    /// when twice those of $y$, $u(y)$ and the stabilized interval are at most $\delta$. `None` after a single block (no spread yet).
    #[must_use]
    pub fn block_sd(&self) -> Option<[f64; 6]> {
        self.block_sd
    }
}

/// The result of an adaptive Monte Carlo run.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct McResult {
    pub(crate) outputs: Vec<McOutput>,
    pub(crate) trials: u64,
    pub(crate) block_trials: usize,
    pub(crate) stabilized: bool,
    pub(crate) coverage: f64,
    pub(crate) stored_values: usize,
}

/// Read access to the fields (crate-private, so the type can grow without breaking callers).
impl McResult {
    /// One result per output of the model.
    #[must_use]
    pub fn outputs(&self) -> &[McOutput] {
        &self.outputs
    }

    /// The trials run ($hM$).
    #[must_use]
    pub fn trials(&self) -> u64 {
        self.trials
    }

    /// The block size $M$.
    #[must_use]
    pub fn block_trials(&self) -> usize {
        self.block_trials
    }

    /// Whether the run stabilized at the tolerance before `max_trials`.
    #[must_use]
    pub fn stabilized(&self) -> bool {
        self.stabilized
    }

    /// The coverage probability of the intervals.
    #[must_use]
    pub fn coverage(&self) -> f64 {
        self.coverage
    }

    /// The model values held at once: one block's ($M$ per output) and one column to sort
    /// ($M$), whatever the number of trials.
    #[must_use]
    pub fn stored_values(&self) -> usize {
        self.stored_values
    }
}

/// A Monte Carlo coverage interval: the one stabilized, or compared with a GUM interval.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub enum IntervalKind {
    /// The probabilistically symmetric interval (the GUM's is symmetric: the usual choice).
    Symmetric,
    /// The shortest interval.
    Shortest,
}

/// The validation of a GUM result by a Monte Carlo run (JCGM 101 8.2).
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct Validation {
    pub(crate) d_low: f64,
    pub(crate) d_high: f64,
    pub(crate) tolerance: f64,
    pub(crate) validated: bool,
}

/// Read access to the fields (crate-private, so the type can grow without breaking callers).
impl Validation {
    /// $d_{\mathrm{low}} = |y - U_p - y_{\mathrm{low}}|$.
    #[must_use]
    pub fn d_low(&self) -> f64 {
        self.d_low
    }

    /// $d_{\mathrm{high}} = |y + U_p - y_{\mathrm{high}}|$.
    #[must_use]
    pub fn d_high(&self) -> f64 {
        self.d_high
    }

    /// The numerical tolerance $\delta$ compared with.
    #[must_use]
    pub fn tolerance(&self) -> f64 {
        self.tolerance
    }

    /// Whether both $d$ are at most $\delta$: the GUM result is validated.
    #[must_use]
    pub fn validated(&self) -> bool {
        self.validated
    }
}

impl std::fmt::Display for Validation {
    /// `validated (JCGM 101 8.2): d_low = ..., d_high = ... <= delta = ...` or `not
    /// validated ...`.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let (verdict, rel) = if self.validated {
            ("validated", "<=")
        } else {
            ("not validated", "not both <=")
        };
        write!(
            f,
            "GUM result {verdict} by Monte Carlo (JCGM 101 8.2): d_low = {:.3e}, d_high = {:.3e} {rel} delta = {:.3e}",
            self.d_low, self.d_high, self.tolerance
        )
    }
}

/// Validates the GUM interval `estimate` $\pm$ `expanded` against the Monte Carlo output `mc`
/// (at the same coverage probability) at the run's tolerance $\delta$ (JCGM 101 8.2).
///
/// # Errors
/// A non-finite `estimate` or a negative or non-finite `expanded`.
pub fn validate(
    estimate: f64,
    expanded: f64,
    mc: &McOutput,
    kind: IntervalKind,
) -> Result<Validation, MetrologyError> {
    tt_core::finite("estimate", estimate)?;
    tt_core::non_negative("expanded", expanded)?;
    let (lo, hi) = match kind {
        IntervalKind::Symmetric => mc.symmetric,
        IntervalKind::Shortest => mc.shortest,
    };
    let d_low = (estimate - expanded - lo).abs();
    let d_high = (estimate + expanded - hi).abs();
    Ok(Validation {
        d_low,
        d_high,
        tolerance: mc.tolerance,
        validated: d_low <= mc.tolerance && d_high <= mc.tolerance,
    })
}
