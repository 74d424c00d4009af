//! One answer for both error sources: the turntable's (deterministic, the certified worst case
//! over a tolerance box) and the sensor's noise averaged over the dwell at each position
//! (random, calib-lsq's covariance of the calibration).
//!
//! # The combined answer
//! For output $k$ at test position $i$ the calibration error is the table's part
//! $t_{k,i}(\chi)$ (eq 14's error vector, [`crate::EndToEnd::error_vectors`]) plus the noise part
//! $\nu_{k,i}$, the rate error $\mathbf A(\hat{\boldsymbol\beta} - \boldsymbol\beta)$ that noise
//! on the position averages leaves (calib-lsq's
//! [`RateErrorCovariance`](calib_lsq::RateErrorCovariance), white and Gauss-Markov in the
//! schedule's order; no second copy of the formula here). With
//! $\sigma_k = \max_i \mathrm{sd}(\nu_{k,i})$ ([`NoiseBudget::sigma`]) and the table part
//! $T_k$ (the certified worst case over the box where a second-order bound is derived, else
//! the exact chain at the worst vertex):
//! $$C_k = T_k + \kappa\,\sigma_k,\qquad \kappa = 3\ \text{by default } (\texttt{--k-sigma}),$$
//! and the output meets its accuracy when $C_k \le \omega_{m,k}$. The verdict is the table's
//! verdict ([`Verdict`]) with $\kappa\sigma_k$ added to both sides of its test: guaranteed
//! when the certified table part plus $\kappa\sigma_k$ is within the accuracy, fails when the
//! exact chain at the worst vertex plus $\kappa\sigma_k$ exceeds it, likely between. Without
//! noise ($\sigma_k = 0$) every answer is today's.
//!
//! # The combined yield
//! The fraction of calibrations meeting every accuracy over random turntables in the box
//! **and** random noise: per draw $\chi$ from the box (mc-verify's streams, exactly those of
//! [`crate::MonteCarloQuestions::rate_distribution`]) and a noise vector $\boldsymbol\nu_k = \mathbf A_k\mathbf
//! L_k\mathbf z$ per output ($\mathbf L_k\mathbf L_k^T$ the coefficients' covariance, from its
//! symmetric eigendecomposition; $\mathbf z$ standard normal from the same chunk's second
//! ChaCha stream, `NOISE_STREAM`), the draw meets when
//! $\max_i|t_{k,i} + \nu_{k,i}| \le \omega_{m,k}$ for every $k$. Chunks merge in chunk order:
//! the count is identical for any thread count. Outputs' noises are independent of each
//! other (separate sensors).

use crate::check::{OutputVerdict, Verdict, verdict_of};
use crate::error::E2eError;
use crate::linear::{Linearization, OutputWorstCase, WorstCase};
use crate::montecarlo::{McSettings, YieldCount};
use crate::{CertifyParams, DirectAllocation, answer::ReadingAnswer};
use calib_lsq::Timing;
use gw_model::noise::NoiseModel;
use mc_verify::driver::run_chunks;
use mc_verify::{ErrorBox, TurntableSampler, chunk_rng};
use nalgebra::{DMatrix, SymmetricEigen};
use rand_core::Rng;

/// Default confidence multiplier $\kappa$ of the noise part (3 sigma).
pub const DEFAULT_K_SIGMA: f64 = 3.0;

/// Largest accepted $\kappa$ (beyond 10 sigma a Gaussian tail is not a statement about a lab).
pub const MAX_K_SIGMA: f64 = 10.0;

/// The bit that turns chunk $c$'s turntable stream into its noise stream: noise of chunk $c$
/// is drawn from ChaCha stream `c | NOISE_STREAM` of the same key (turntable streams use
/// `c` < $2^{63}$), so the turntables are exactly those of the table-only Monte Carlo.
pub(crate) const NOISE_STREAM: u64 = 1 << 63;

/// The tuning of [`crate::NoiseQuestions::tradeoff_with`]: how finely the shortest dwell is bracketed
/// and where the time/table curve's points lie. `Default` gives the values `end-to-end` and
/// the report use.
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub struct TradeoffParams {
    /// Bisection steps of the shortest dwell (on $\log T$; default 48: $2^{-48}$ of the
    /// bracket's log width).
    pub min_dwell_bisection_steps: usize,
    /// Points of the trade-off curve and of the noise curve (default 24, at least 2).
    pub points: usize,
    /// The curve spans this factor of dwell times above the shortest one (default 1000,
    /// at least 1).
    pub span: f64,
    /// The curve's first point lies this factor above the shortest dwell (default 1.02; at
    /// the shortest dwell itself the table's share is 0 and $J$ infinite), at least 1.
    pub first: f64,
}

impl Default for TradeoffParams {
    fn default() -> Self {
        Self {
            min_dwell_bisection_steps: 48,
            points: 24,
            span: 1000.0,
            first: 1.02,
        }
    }
}

impl TradeoffParams {
    /// Check the parameters.
    ///
    /// # Errors
    /// [`E2eError::Field`] naming `points` (fewer than 2), `span` or `first` (not finite or
    /// below 1).
    pub fn checked(self) -> Result<Self, E2eError> {
        use std::ops::Bound::{Included, Unbounded};
        if self.points < 2 {
            return Err(E2eError::Field(tt_core::FieldError::OutOfRange {
                field: "points".into(),
                value: self.points as f64,
                range: "at least 2".into(),
            }));
        }
        for (field, v) in [("span", self.span), ("first", self.first)] {
            tt_core::in_range(field, v, Included(1.0), Unbounded, "").map_err(E2eError::Field)?;
        }
        Ok(self)
    }
}

/// What the time/table trade-off is asked ([`crate::NoiseQuestions::tradeoff`]; its
/// sensitivity to the noise model, [`crate::NoiseQuestions::noise_sensitivity`], is asked the
/// same): the table's linearisation and lower bounds, the sensor's noise with a timing whose
/// shape is kept (every dwell scaled alike, the move time and sample rate kept), $\kappa$ and
/// the dwells searched.
#[derive(Debug, Clone, Copy)]
pub struct TradeoffInputs<'a> {
    /// The linearisation of the table's errors ([`crate::EndToEnd::linearization`]).
    pub linear: &'a Linearization,
    /// The lower bounds (rad, order of $\chi$).
    pub lower_bounds_rad: &'a [f64],
    /// Per output, its noise model (`None`: no noise).
    pub noise: &'a [Option<NoiseModel>],
    /// The timing whose shape every dwell keeps.
    pub timing: &'a Timing,
    /// $\kappa$ of the noise part $\kappa\sigma_k$.
    pub k_sigma: f64,
    /// The dwells searched, `(shortest, longest)` (s; the mean dwell for a per-position
    /// timing).
    pub dwell_range_s: (f64, f64),
}

/// Point `i` of `points` spread evenly in $\log T$ from `first` to `last`.
fn log_spaced(first: f64, last: f64, i: usize, points: usize) -> f64 {
    let f = i as f64 / (points - 1) as f64;
    (first.ln() + f * (last.ln() - first.ln())).exp()
}

/// Check a confidence multiplier $\kappa$: finite, in $(0,$ [`MAX_K_SIGMA`]$]$.
///
/// # Errors
/// [`E2eError::Field`] naming `k_sigma`.
pub fn check_k_sigma(k_sigma: f64) -> Result<f64, E2eError> {
    use std::ops::Bound::{Excluded, Included};
    Ok(tt_core::in_range(
        "k_sigma",
        k_sigma,
        Excluded(0.0),
        Included(MAX_K_SIGMA),
        "",
    )?)
}

/// Two independent standard normal draws (Box-Muller on two 53-bit uniforms in $(0, 1]$).
#[inline]
pub(crate) fn standard_normal_pair<R: Rng + ?Sized>(rng: &mut R) -> (f64, f64) {
    const SCALE: f64 = 1.0 / (1u64 << 53) as f64;
    let u1 = ((rng.next_u64() >> 11) + 1) as f64 * SCALE;
    let u2 = (rng.next_u64() >> 11) as f64 * SCALE;
    let r = (-2.0 * u1.ln()).sqrt();
    let (s, c) = (std::f64::consts::TAU * u2).sin_cos();
    (r * c, r * s)
}

/// The noise of every output's calibration for one timing: the standard deviation of the rate
/// error at each test position (calib-lsq's covariance) and the factor that draws it.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct NoiseBudget {
    /// The timing it was computed for.
    pub(crate) timing: Timing,
    /// Per output: the rate error's standard deviation at every position (output unit; empty
    /// for an output without noise).
    pub(crate) per_position: Vec<Vec<f64>>,
    /// Per output: $\mathbf A_k\mathbf L_k$ ($n\times p_k$, noise at the positions =
    /// this times a standard normal vector); `None` without noise.
    factors: Vec<Option<DMatrix<f64>>>,
}

/// Read access to the fields (crate-private, so the type can grow without breaking callers).
impl NoiseBudget {
    /// The timing it was computed for.
    #[must_use]
    pub fn timing(&self) -> &Timing {
        &self.timing
    }

    /// Per output: the rate error's standard deviation at every position (output unit; empty
    /// for an output without noise).
    #[must_use]
    pub fn per_position(&self) -> &[Vec<f64>] {
        &self.per_position
    }
}

impl NoiseBudget {
    /// $\sigma_k$: the largest standard deviation over the positions (output unit; 0 for an
    /// output without noise).
    #[must_use]
    pub fn sigma(&self) -> Vec<f64> {
        self.per_position
            .iter()
            .map(|s| s.iter().copied().fold(0.0, f64::max))
            .collect()
    }

    /// Whether any output has noise.
    #[must_use]
    pub fn any(&self) -> bool {
        self.factors.iter().any(Option::is_some)
    }

    /// The noise part $\kappa\sigma_k$ of every output (output unit).
    #[must_use]
    pub fn margins(&self, k_sigma: f64) -> Vec<f64> {
        self.sigma().iter().map(|s| k_sigma * s).collect()
    }
}

/// Which error source dominates an output's combined answer.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Dominant {
    /// The table part is at least the noise part.
    Table,
    /// The noise part ($\kappa\sigma$) exceeds the table part.
    Noise,
}

impl Dominant {
    /// `table` or `noise`.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Dominant::Table => "table",
            Dominant::Noise => "noise",
        }
    }
}

/// What the answer for both error sources adds to an output's verdict ([`CombinedOutput`]).
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct CombinedDetail {
    /// The table part (output unit): the certified worst case over the box when a
    /// second-order bound is derived, else the exact chain at the worst vertex.
    pub(crate) table_part: f64,
    /// Whether [`CombinedOutput::table_part`] is certified (a rigorous bound).
    pub(crate) table_certified: bool,
    /// $\sigma_k$ (output unit).
    pub(crate) noise_sigma: f64,
    /// $\kappa$.
    pub(crate) k_sigma: f64,
    /// `table_part + k_sigma * noise_sigma` (output unit).
    pub(crate) combined: f64,
    /// Which part dominates.
    pub(crate) dominant: Dominant,
}

/// One output's answer for both error sources; its verdict is the table's with the noise part
/// added (see the [module](self)).
pub type CombinedOutput = OutputVerdict<CombinedDetail>;

/// Read access to the fields (crate-private, so the type can grow without breaking callers).
impl CombinedOutput {
    /// The table part (output unit): the certified worst case over the box when a
    /// second-order bound is derived, else the exact chain at the worst vertex.
    #[must_use]
    pub fn table_part(&self) -> f64 {
        self.detail.table_part
    }

    /// Whether [`CombinedOutput::table_part`] is certified (a rigorous bound).
    #[must_use]
    pub fn table_certified(&self) -> bool {
        self.detail.table_certified
    }

    /// $\sigma_k$ (output unit).
    #[must_use]
    pub fn noise_sigma(&self) -> f64 {
        self.detail.noise_sigma
    }

    /// $\kappa$.
    #[must_use]
    pub fn k_sigma(&self) -> f64 {
        self.detail.k_sigma
    }

    /// `table_part + k_sigma * noise_sigma` (output unit).
    #[must_use]
    pub fn combined(&self) -> f64 {
        self.detail.combined
    }

    /// Which part dominates.
    #[must_use]
    pub fn dominant(&self) -> Dominant {
        self.detail.dominant
    }
}

impl CombinedOutput {
    /// The combined answer of one output's worst case `w` with noise sigma `sigma`.
    #[must_use]
    pub fn of(w: &OutputWorstCase, accuracy: f64, sigma: f64, k_sigma: f64) -> Self {
        let noise = k_sigma * sigma;
        // an infinite second-order bound (an error the allocation leaves unbounded, e.g. one
        // of a combination the reading cannot see) certifies nothing: the table's part is
        // then the exact chain at the worst vertex, said to be not certified
        let certified = w.certified_bound().filter(|b| b.is_finite());
        let (table_part, table_certified) = match certified {
            Some(b) => (b, true),
            None => (w.exact_at_vertex, false),
        };
        Self {
            output: w.output,
            accuracy,
            verdict: verdict_of(w, accuracy, noise),
            detail: CombinedDetail {
                table_part,
                table_certified,
                noise_sigma: sigma,
                k_sigma,
                combined: table_part + noise,
                dominant: if noise > table_part {
                    Dominant::Noise
                } else {
                    Dominant::Table
                },
            },
        }
    }

    /// Whether the combined answer meets the accuracy.
    #[must_use]
    pub fn meets(&self) -> bool {
        self.detail.combined <= self.accuracy
    }
}

/// The weakest of several verdicts (fails, then likely, then guaranteed).
#[must_use]
pub fn weakest(verdicts: impl IntoIterator<Item = Verdict>) -> Verdict {
    let mut out = Verdict::Guaranteed;
    for v in verdicts {
        match v {
            Verdict::Fails => return Verdict::Fails,
            Verdict::Likely => out = Verdict::Likely,
            Verdict::Guaranteed => {}
        }
    }
    out
}

/// A box's answer for both error sources.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct CombinedBox {
    /// The box's name.
    pub(crate) name: String,
    /// One per output.
    pub(crate) outputs: Vec<CombinedOutput>,
    /// The weakest of the outputs' verdicts.
    pub(crate) verdict: Verdict,
    /// The yield over turntables and noise.
    pub(crate) combined_yield: YieldCount,
}

/// Read access to the fields (crate-private, so the type can grow without breaking callers).
impl CombinedBox {
    /// The box's name.
    #[must_use]
    pub fn name(&self) -> &str {
        &self.name
    }

    /// One per output.
    #[must_use]
    pub fn outputs(&self) -> &[CombinedOutput] {
        &self.outputs
    }

    /// The weakest of the outputs' verdicts.
    #[must_use]
    pub fn verdict(&self) -> Verdict {
        self.verdict
    }

    /// The yield over turntables and noise.
    #[must_use]
    pub fn combined_yield(&self) -> &YieldCount {
        &self.combined_yield
    }
}

/// The direct allocation with the noise part kept free, or why no table suffices.
#[derive(Debug, Clone, PartialEq)]
pub enum NoisyDirect {
    /// The table gets what the noise leaves: rows held to $\omega_{m,k} - \kappa\sigma_k$.
    Allocated {
        /// The allocation (its `second_order_margins` hold $\kappa\sigma_k$).
        allocation: Box<DirectAllocation>,
        /// Its box's combined answer.
        answer: CombinedBox,
    },
    /// Noise alone (with the lower bounds' table part) takes an output's whole accuracy: no
    /// table suffices at this dwell.
    NoTableSuffices {
        /// The outputs that cannot be met.
        outputs: Vec<NoRoom>,
    },
}

/// An output whose accuracy the noise part (with the lower bounds' table part) fills.
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub struct NoRoom {
    /// The output's index.
    pub(crate) output: usize,
    /// Its noise part $\kappa\sigma_k$ (output unit).
    pub(crate) noise_part: f64,
    /// What the lower bounds' table alone takes (the linearised worst row, output unit).
    pub(crate) lower_bounds_part: f64,
}

/// Read access to the fields (crate-private, so the type can grow without breaking callers).
impl NoRoom {
    /// The output's index.
    #[must_use]
    pub fn output(&self) -> usize {
        self.output
    }

    /// Its noise part $\kappa\sigma_k$ (output unit).
    #[must_use]
    pub fn noise_part(&self) -> f64 {
        self.noise_part
    }

    /// What the lower bounds' table alone takes (the linearised worst row, output unit).
    #[must_use]
    pub fn lower_bounds_part(&self) -> f64 {
        self.lower_bounds_part
    }
}

/// The direct allocation with the noise part kept free, or the outputs that leave no room.
pub type NoisyAllocation = Result<DirectAllocation, Vec<NoRoom>>;

/// One point of the time/table trade-off.
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub struct TradeoffPoint {
    /// Dwell per position (s; the mean dwell for a per-position timing, every dwell scaled
    /// alike).
    pub(crate) dwell_s: f64,
    /// Total test time (s).
    pub(crate) total_s: f64,
    /// $J$ of the direct allocation with the noise part kept free (rad$^{-2}$); `None` when no
    /// table suffices.
    pub(crate) objective: Option<f64>,
}

/// Read access to the fields (crate-private, so the type can grow without breaking callers).
impl TradeoffPoint {
    /// Dwell per position (s; the mean dwell for a per-position timing, every dwell scaled
    /// alike).
    #[must_use]
    pub fn dwell_s(&self) -> f64 {
        self.dwell_s
    }

    /// Total test time (s).
    #[must_use]
    pub fn total_s(&self) -> f64 {
        self.total_s
    }

    /// $J$ of the direct allocation with the noise part kept free (rad$^{-2}$); `None` when no
    /// table suffices.
    #[must_use]
    pub fn objective(&self) -> Option<f64> {
        self.objective
    }
}

/// The time/table trade-off: the table's $J$ against the dwell, the knee and the shortest
/// dwell at which some table suffices.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct Tradeoff {
    /// $\kappa$.
    pub(crate) k_sigma: f64,
    /// The shortest dwell (s) at which some table suffices (noise alone, with the lower
    /// bounds' table part, leaves room in every accuracy), found by bisection; `None` when
    /// no dwell in the searched range does (with a drift in the noise, whose part grows again
    /// at long dwells: none of the range's ends and the curve's log-spaced dwells between).
    pub(crate) min_dwell_s: Option<f64>,
    /// Whether the shortest dwell is the range's lower end (one sample per position already
    /// suffices).
    pub(crate) min_dwell_at_range_start: bool,
    /// The searched range of dwells (s).
    pub(crate) range_s: (f64, f64),
    /// The curve, dwell ascending.
    pub(crate) points: Vec<TradeoffPoint>,
    /// The knee: the dwell at which $d\ln J/d\ln T = -1$ (below it a longer dwell saves
    /// relatively more $J$ than it costs in time, above it less); interpolated on the curve,
    /// `None` when the curve does not cross $-1$.
    pub(crate) knee_dwell_s: Option<f64>,
    /// $J$ with no noise (rad$^{-2}$), the curve's limit for long dwells.
    pub(crate) noiseless_objective: f64,
    /// The noise part $\kappa\sigma_k$ of every output (output unit) on
    /// [`TradeoffParams::points`] dwells spread evenly in $\log T$ over the whole searched range: where it crosses the
    /// accuracy (less the lower bounds' table part) lies the shortest dwell.
    pub(crate) noise_curve: Vec<(f64, Vec<f64>)>,
}

/// Read access to the fields (crate-private, so the type can grow without breaking callers).
impl Tradeoff {
    /// $\kappa$.
    #[must_use]
    pub fn k_sigma(&self) -> f64 {
        self.k_sigma
    }

    /// The shortest dwell (s) at which some table suffices (noise alone, with the lower
    /// bounds' table part, leaves room in every accuracy), found by bisection; `None` when
    /// no dwell in the searched range does.
    #[must_use]
    pub fn min_dwell_s(&self) -> Option<f64> {
        self.min_dwell_s
    }

    /// Whether the shortest dwell is the range's lower end (one sample per position already
    /// suffices).
    #[must_use]
    pub fn min_dwell_at_range_start(&self) -> bool {
        self.min_dwell_at_range_start
    }

    /// The searched range of dwells (s).
    #[must_use]
    pub fn range_s(&self) -> (f64, f64) {
        self.range_s
    }

    /// The curve, dwell ascending.
    #[must_use]
    pub fn points(&self) -> &[TradeoffPoint] {
        &self.points
    }

    /// The knee: the dwell at which $d\ln J/d\ln T = -1$ (below it a longer dwell saves
    /// relatively more $J$ than it costs in time, above it less); interpolated on the curve,
    /// `None` when the curve does not cross $-1$.
    #[must_use]
    pub fn knee_dwell_s(&self) -> Option<f64> {
        self.knee_dwell_s
    }

    /// $J$ with no noise (rad$^{-2}$), the curve's limit for long dwells.
    #[must_use]
    pub fn noiseless_objective(&self) -> f64 {
        self.noiseless_objective
    }

    /// The noise part $\kappa\sigma_k$ of every output (output unit) on
    /// [`TradeoffParams::points`] dwells spread evenly in $\log T$ over the whole searched range: where it crosses the
    /// accuracy (less the lower bounds' table part) lies the shortest dwell.
    #[must_use]
    pub fn noise_curve(&self) -> &[(f64, Vec<f64>)] {
        &self.noise_curve
    }
}

impl<S: tt_kinematics::ScheduleErrorModel + Sync> crate::NoiseQuestions<'_, S> {
    /// The noise of every output's calibration for `timing` (`noise[k]` for output $k$,
    /// `None` for a noiseless one): calib-lsq's covariance of the rate error at the test
    /// positions, positions in the schedule's order.
    ///
    /// # Errors
    /// [`E2eError::Calib`] unless there is one noise entry per output and one dwell per
    /// position.
    pub fn noise_budget(
        &self,
        noise: &[Option<NoiseModel>],
        timing: &Timing,
    ) -> Result<NoiseBudget, E2eError> {
        let covs = self.calibration().noise_covariances(noise, timing)?;
        let mut per_position = Vec::with_capacity(covs.len());
        let mut factors = Vec::with_capacity(covs.len());
        for (o, c) in self.calibration().outputs().iter().zip(covs) {
            match c {
                None => {
                    per_position.push(Vec::new());
                    factors.push(None);
                }
                Some(c) => {
                    per_position.push(c.rate_error().sigma().iter().copied().collect());
                    let eig = SymmetricEigen::new(c.coefficients().total());
                    let mut l = eig.eigenvectors;
                    for (j, lambda) in eig.eigenvalues.iter().enumerate() {
                        let s = lambda.max(0.0).sqrt();
                        l.column_mut(j).scale_mut(s);
                    }
                    factors.push(Some(o.regression().matrix() * l));
                }
            }
        }
        Ok(NoiseBudget {
            timing: timing.clone(),
            per_position,
            factors,
        })
    }

    /// [`crate::NoiseQuestions::noise_budget`] with every static dwell of `timing` scaled alike so that
    /// their mean is `dwell_s` (the move time, sample rate and rate steps' windows kept: a rate
    /// step turns its whole revolutions whatever the dwell).
    ///
    /// # Errors
    /// As [`Timing::new`] (a dwell holding less than one sample) and
    /// [`crate::NoiseQuestions::noise_budget`].
    pub fn noise_budget_at_dwell(
        &self,
        noise: &[Option<NoiseModel>],
        timing: &Timing,
        dwell_s: f64,
    ) -> Result<NoiseBudget, E2eError> {
        let mean = timing.dwell_s().iter().sum::<f64>() / timing.positions() as f64;
        let scaled = timing.with_dwell_s(
            timing
                .dwell_s()
                .iter()
                .map(|d| d * dwell_s / mean)
                .collect(),
        )?;
        self.noise_budget(noise, &scaled)
    }

    /// The combined answer of a box's worst case `wc` with `budget`'s noise at $\kappa$.
    #[must_use]
    pub fn combine(
        &self,
        wc: &WorstCase,
        budget: &NoiseBudget,
        k_sigma: f64,
    ) -> Vec<CombinedOutput> {
        let acc = self.accuracies();
        let sigma = budget.sigma();
        wc.outputs
            .iter()
            .map(|w| CombinedOutput::of(w, acc[w.output], sigma[w.output], k_sigma))
            .collect()
    }

    /// The yield over turntables drawn from `bounds` and random noise of `budget` (see the
    /// [module](self)): identical for any thread count, memory independent of the count.
    ///
    /// # Errors
    /// As [`McSettings::validate`]; [`E2eError::Draw`] naming the first turntable whose
    /// calibration fails.
    pub fn combined_yield(
        &self,
        bounds: &ErrorBox,
        budget: &NoiseBudget,
        settings: &McSettings,
    ) -> Result<YieldCount, E2eError> {
        settings.validate()?;
        const WAVE_CHUNKS: u64 = 64;
        let sampler = TurntableSampler::for_joint_ranges(bounds, &self.model().joint_ranges_rad());
        let acc = self.accuracies();
        let outputs = acc.len();
        let cs = u64::from(settings.chunk_size);
        let chunks = settings.samples.div_ceil(cs);
        let mut meeting = 0;
        let mut per_output = vec![0u64; outputs];
        let chunk = |c: u64| -> Result<(u64, Vec<u64>), E2eError> {
            let mut noise_rng = chunk_rng(settings.seed, c | NOISE_STREAM);
            let mut z = Vec::new();
            let (mut all, mut each) = (0u64, vec![0u64; outputs]);
            let draw = (settings.seed, settings.samples, cs);
            self.for_each_draw(&sampler, draw, c, |index, vectors| {
                let mut ok_all = true;
                for (k, v) in vectors.iter_mut().enumerate() {
                    if let Some(f) = &budget.factors[k] {
                        normals(&mut noise_rng, f.ncols(), &mut z);
                        add_product(f, &z, v);
                    }
                    let worst = crate::simulate::max_abs(v);
                    if !worst.is_finite() {
                        return Err(E2eError::Draw {
                            sample: index,
                            reason: format!("non-finite calibration error {worst} on output {k}"),
                        });
                    }
                    if worst <= acc[k] {
                        each[k] += 1;
                    } else {
                        ok_all = false;
                    }
                }
                if ok_all {
                    all += 1;
                }
                Ok(())
            })?;
            Ok((all, each))
        };
        run_chunks(chunks, WAVE_CHUNKS, chunk, |(all, each)| {
            meeting += all;
            for (a, b) in per_output.iter_mut().zip(each) {
                *a += b;
            }
            Ok(())
        })?;
        Ok(YieldCount::new(
            settings.samples,
            settings.seed,
            meeting,
            per_output,
        ))
    }

    /// A box's answer for both error sources: its worst case `wc`
    /// ([`crate::EndToEnd::worst_case`] of the box `ub_rad`) combined with the noise, and the
    /// combined yield.
    ///
    /// # Errors
    /// [`E2eError::Field`] for a bad `k_sigma`; as [`crate::NoiseQuestions::combined_yield`].
    #[allow(clippy::too_many_arguments)]
    pub fn combined_box(
        &self,
        name: &str,
        wc: &WorstCase,
        ub_rad: &[f64],
        lower_bounds_rad: &[f64],
        budget: &NoiseBudget,
        k_sigma: f64,
        settings: &McSettings,
    ) -> Result<CombinedBox, E2eError> {
        check_k_sigma(k_sigma)?;
        let outputs = self.combine(wc, budget, k_sigma);
        let combined_yield =
            self.combined_yield(&self.box_of(ub_rad, lower_bounds_rad)?, budget, settings)?;
        Ok(CombinedBox {
            name: name.to_string(),
            verdict: weakest(outputs.iter().map(|o| o.verdict)),
            outputs,
            combined_yield,
        })
    }

    /// The outputs whose noise part (with the lower bounds' table part) leaves no room in the
    /// accuracy; empty when some table suffices.
    pub(crate) fn no_room(
        &self,
        linear: &Linearization,
        lower_bounds_rad: &[f64],
        margins: &[f64],
    ) -> Vec<NoRoom> {
        let n = self.len();
        let acc = self.accuracies();
        let lb_rows = linear.row_worst_cases(lower_bounds_rad);
        (0..acc.len())
            .filter_map(|k| {
                let lb = lb_rows.rows(k * n, n).max();
                (margins[k] >= acc[k] || lb > acc[k] - margins[k]).then_some(NoRoom {
                    output: k,
                    noise_part: margins[k],
                    lower_bounds_part: lb,
                })
            })
            .collect()
    }

    /// The direct allocation with the noise part kept free: rows held to
    /// $\omega_{m,k} - \kappa\sigma_k$ (the table gets what the noise leaves), or the answer
    /// that no table suffices at this dwell.
    ///
    /// With `certify`, the box is certified on the exact chain where the reading has a derived
    /// second-order bound ([`crate::EndToEnd::allocate_direct_certified_with`] with the noise
    /// part kept free as well, tuned by `certify`): every turntable of the box then has an
    /// exact-chain error within $\omega_{m,k} - \kappa\sigma_k$, so the box meets its own
    /// combined verdict. Where the reading has no derived bound, or no $\ell_1$ budget leaves
    /// room for it beside the noise, the first-order allocation is returned (its combined
    /// verdict, computed from its certified worst case, says whether it meets). The commands
    /// recommend `Some(&CertifyParams::default())`; the trade-off's curve is first-order
    /// (`None`).
    ///
    /// # Errors
    /// As [`crate::EndToEnd::allocate_direct`] (bad lower bounds, solver failure);
    /// [`E2eError::Field`] for a bad `k_sigma`.
    pub fn allocate_direct_with_noise(
        &self,
        linear: &Linearization,
        lower_bounds_rad: &[f64],
        budget: &NoiseBudget,
        k_sigma: f64,
        certify: Option<&CertifyParams>,
    ) -> Result<NoisyAllocation, E2eError> {
        check_k_sigma(k_sigma)?;
        crate::allocate::check_lower_bounds_named(self.error_names(), lower_bounds_rad)?;
        let margins = budget.margins(k_sigma);
        let blocked = self.no_room(linear, lower_bounds_rad, &margins);
        if !blocked.is_empty() {
            return Ok(Err(blocked));
        }
        let first_order = self.allocate_direct_keeping(linear, lower_bounds_rad, &margins)?;
        let Some(params) = certify else {
            return Ok(Ok(first_order));
        };
        match self.certified_keeping(linear, lower_bounds_rad, &margins, params) {
            Ok(d) => Ok(Ok(d)),
            Err(E2eError::NoSecondOrderBound { .. } | E2eError::NoConvergence { .. }) => {
                Ok(Ok(first_order))
            }
            Err(e) => Err(e),
        }
    }

    /// The answer of one reading for both error sources: every box of `r` combined with the
    /// noise (with its combined yield), and the direct allocation with the noise part kept
    /// free.
    ///
    /// # Errors
    /// As [`crate::NoiseQuestions::combined_box`] and [`crate::NoiseQuestions::allocate_direct_with_noise`].
    pub fn noise_answer(
        &self,
        r: &ReadingAnswer,
        lower_bounds_rad: &[f64],
        budget: &NoiseBudget,
        k_sigma: f64,
        settings: &McSettings,
    ) -> Result<NoiseAnswer, E2eError> {
        check_k_sigma(k_sigma)?;
        let linear = self.linearization();
        let mut boxes = Vec::new();
        for b in r.boxes.iter().chain([&r.direct_box, &r.yield_box]) {
            boxes.push(self.combined_box(
                &b.name,
                &b.worst_case,
                &b.upper_bounds_rad,
                lower_bounds_rad,
                budget,
                k_sigma,
                settings,
            )?);
        }
        let direct = match self.allocate_direct_with_noise(
            &linear,
            lower_bounds_rad,
            budget,
            k_sigma,
            Some(&CertifyParams::default()),
        )? {
            Ok(allocation) => {
                let answer = self.combined_box(
                    "direct with noise",
                    &self.worst_case(&linear, &allocation.upper_bounds_rad)?,
                    &allocation.upper_bounds_rad,
                    lower_bounds_rad,
                    budget,
                    k_sigma,
                    settings,
                )?;
                NoisyDirect::Allocated {
                    allocation: Box::new(allocation),
                    answer,
                }
            }
            Err(outputs) => NoisyDirect::NoTableSuffices { outputs },
        };
        Ok(NoiseAnswer {
            k_sigma,
            sigma: budget.sigma(),
            boxes,
            direct,
        })
    }

    /// The time/table trade-off for `inputs` ([`TradeoffInputs`]: the noise with the timing's
    /// shape, every dwell scaled alike, the move time and sample rate kept): the shortest
    /// dwell at which some table suffices (bisection on $\log T$ over
    /// [`TradeoffInputs::dwell_range_s`]), and $J$ of the direct allocation with the
    /// noise part kept free on [`TradeoffParams::points`] dwells from
    /// [`TradeoffParams::first`] to [`TradeoffParams::span`] times it (within the range), with
    /// the knee; [`TradeoffParams::default`]'s tuning (see [`crate::NoiseQuestions::tradeoff_with`]).
    ///
    /// # Errors
    /// [`E2eError::Field`] for a bad range or `k_sigma`; as
    /// [`crate::NoiseQuestions::allocate_direct_with_noise`].
    pub fn tradeoff(&self, inputs: &TradeoffInputs<'_>) -> Result<Tradeoff, E2eError> {
        self.tradeoff_with(inputs, &TradeoffParams::default())
    }

    /// [`crate::NoiseQuestions::tradeoff`] with its tuning given.
    ///
    /// # Errors
    /// As [`crate::NoiseQuestions::tradeoff`]; [`E2eError::Field`] for bad `params`
    /// ([`TradeoffParams::checked`]).
    pub fn tradeoff_with(
        &self,
        inputs: &TradeoffInputs<'_>,
        params: &TradeoffParams,
    ) -> Result<Tradeoff, E2eError> {
        let TradeoffInputs {
            linear,
            lower_bounds_rad,
            noise,
            timing,
            k_sigma,
            dwell_range_s,
        } = *inputs;
        let params = params.checked()?;
        check_k_sigma(k_sigma)?;
        let mean = timing.dwell_s().iter().sum::<f64>() / timing.positions() as f64;
        let shortest = timing
            .dwell_s()
            .iter()
            .copied()
            .fold(f64::INFINITY, f64::min);
        // every dwell must hold one sample: the mean dwell at least mean / shortest / f_s
        let lo = crate::error::positive("dwell_range_s.lo", dwell_range_s.0)?
            // (a relative 1e-9 above: the scaled shortest dwell must not round below one sample)
            .max(mean / shortest / timing.sample_rate_hz() * (1.0 + 1e-9));
        let hi = crate::error::positive("dwell_range_s.hi", dwell_range_s.1)?;
        if hi < lo {
            return Err(E2eError::Field(tt_core::FieldError::OutOfRange {
                field: "dwell_range_s".into(),
                value: hi,
                range: format!("at least the shortest dwell holding one sample, {lo} s"),
            }));
        }
        let at = |t: f64| self.noise_budget_at_dwell(noise, timing, t);
        let fits = |t: f64| -> Result<bool, E2eError> {
            Ok(self
                .no_room(linear, lower_bounds_rad, &at(t)?.margins(k_sigma))
                .is_empty())
        };
        let noiseless = self.allocate_direct(linear, lower_bounds_rad)?.objective;
        let (min_dwell_s, at_start) = if fits(lo)? {
            (Some(lo), true)
        } else {
            // A bracket [failing, fitting]. Without a drift the noise part falls with the
            // dwell, so the longest dwell fitting makes [lo, hi] one. A drift (rate random
            // walk, rate ramp) grows again at long dwells, so the longest may fail while a
            // middle one fits: then the first of the curve's log-spaced dwells that fits
            // closes the bracket (a fitting interval narrower than their spacing is missed).
            let bracket = if fits(hi)? {
                Some((lo, hi))
            } else {
                let mut below = lo;
                let mut found = None;
                for i in 1..params.points.saturating_sub(1) {
                    let t = log_spaced(lo, hi, i, params.points).clamp(lo, hi);
                    if fits(t)? {
                        found = Some((below, t));
                        break;
                    }
                    below = t;
                }
                found
            };
            match bracket {
                None => (None, false),
                Some((fail, fit)) => {
                    let (mut a, mut b) = (fail.ln(), fit.ln());
                    for _ in 0..params.min_dwell_bisection_steps {
                        let mid = 0.5 * (a + b);
                        if fits(mid.exp())? {
                            b = mid;
                        } else {
                            a = mid;
                        }
                    }
                    (Some(b.exp()), false)
                }
            }
        };
        let mut points = Vec::new();
        if let Some(t0) = min_dwell_s {
            let first = if at_start {
                t0
            } else {
                (t0 * params.first).min(hi)
            };
            let last = (t0 * params.span).min(hi).max(first);
            for i in 0..params.points {
                let t = log_spaced(first, last, i, params.points);
                let budget = at(t)?;
                let objective = self
                    .allocate_direct_with_noise(linear, lower_bounds_rad, &budget, k_sigma, None)?
                    .ok()
                    .map(|d| d.objective);
                points.push(TradeoffPoint {
                    dwell_s: t,
                    total_s: budget.timing.total_s(),
                    objective,
                });
            }
        }
        let mut noise_curve = Vec::with_capacity(params.points);
        for i in 0..params.points {
            let t = log_spaced(lo, hi, i, params.points).clamp(lo, hi);
            noise_curve.push((t, at(t)?.margins(k_sigma)));
        }
        Ok(Tradeoff {
            noise_curve,
            k_sigma,
            min_dwell_s,
            min_dwell_at_range_start: at_start,
            range_s: (lo, hi),
            knee_dwell_s: knee(&points),
            points,
            noiseless_objective: noiseless,
        })
    }
}

/// The dwell at which the curve's log-log slope crosses $-1$ (linear interpolation of the
/// slopes of consecutive segments, placed at their midpoints in $\ln T$).
fn knee(points: &[TradeoffPoint]) -> Option<f64> {
    let logs: Vec<(f64, f64)> = points
        .iter()
        .filter_map(|p| match p.objective {
            Some(j) if j > 0.0 && j.is_finite() => Some((p.dwell_s.ln(), j.ln())),
            _ => None,
        })
        .collect();
    let slopes: Vec<(f64, f64)> = logs
        .windows(2)
        .filter(|w| w[1].0 > w[0].0)
        .map(|w| {
            (
                0.5 * (w[0].0 + w[1].0),
                (w[1].1 - w[0].1) / (w[1].0 - w[0].0),
            )
        })
        .collect();
    slopes.windows(2).find_map(|w| {
        let ((x0, s0), (x1, s1)) = (w[0], w[1]);
        if s0 <= -1.0 && s1 > -1.0 {
            let f = (-1.0 - s0) / (s1 - s0);
            Some((x0 + f * (x1 - x0)).exp())
        } else {
            None
        }
    })
}

/// One reading's answer for both error sources.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct NoiseAnswer {
    /// $\kappa$.
    pub(crate) k_sigma: f64,
    /// $\sigma_k$ per output (output unit).
    pub(crate) sigma: Vec<f64>,
    /// Every box of the reading (the named boxes, then `direct`, then `yield-based`) combined
    /// with the noise.
    pub(crate) boxes: Vec<CombinedBox>,
    /// The direct allocation with the noise part kept free.
    pub(crate) direct: NoisyDirect,
}

/// Read access to the fields (crate-private, so the type can grow without breaking callers).
impl NoiseAnswer {
    /// $\kappa$.
    #[must_use]
    pub fn k_sigma(&self) -> f64 {
        self.k_sigma
    }

    /// $\sigma_k$ per output (output unit).
    #[must_use]
    pub fn sigma(&self) -> &[f64] {
        &self.sigma
    }

    /// Every box of the reading (the named boxes, then `direct`, then `yield-based`) combined
    /// with the noise.
    #[must_use]
    pub fn boxes(&self) -> &[CombinedBox] {
        &self.boxes
    }

    /// The direct allocation with the noise part kept free.
    #[must_use]
    pub fn direct(&self) -> &NoisyDirect {
        &self.direct
    }
}

/// `m` standard normal draws into `z`.
fn normals<R: Rng + ?Sized>(rng: &mut R, m: usize, z: &mut Vec<f64>) {
    z.clear();
    while z.len() < m {
        let (a, b) = standard_normal_pair(rng);
        z.push(a);
        if z.len() < m {
            z.push(b);
        }
    }
}

/// `v += F z`.
fn add_product(f: &DMatrix<f64>, z: &[f64], v: &mut [f64]) {
    for (j, zj) in z.iter().enumerate() {
        for (vi, fij) in v.iter_mut().zip(f.column(j).iter()) {
            *vi += fij * zj;
        }
    }
}
