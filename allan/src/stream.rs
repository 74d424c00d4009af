//! The streaming estimator: samples in, one pass, memory bounded by the settings.

use crate::chi2;
use crate::edf;
use crate::error::AllanError;
use crate::fit::{self, FLICKER_FLOOR_FACTOR, GaussMarkovFit, Resolution, Term};
use crate::levels::{self, Level, Taus};
use crate::noise::{NoiseModel, PowerLaw};

/// Samples processed at a time (and averaged for the reference value removed from the
/// phase).
const BLOCK: usize = 4096;

/// The sample rates accepted, Hz: from one sample in 31.7 years to 1 THz (the cluster times
/// and the fit stay far inside a double's range).
pub const RATE_HZ: (f64, f64) = (1e-9, 1e12);

/// Largest overlap factor accepted.
pub(crate) const MAX_OVERLAP: u64 = 1 << 16;

/// Default overlap factor $R$ (evaluations per cluster time beyond full overlap).
pub const DEFAULT_OVERLAP: u64 = 256;

/// Settings of an analysis.
#[derive(Debug, Clone, PartialEq)]
pub struct Settings {
    rate_hz: f64,
    confidence: f64,
    noise: NoiseModel,
    overlap: u64,
    taus: Taus,
    gauss_markov: bool,
}

impl Settings {
    /// Samples at `rate_hz` (checked when the estimator is made), 1-sigma bands
    /// ([`chi2::ONE_SIGMA`]), noise types identified per cluster time, overlap factor
    /// [`DEFAULT_OVERLAP`].
    #[must_use]
    pub fn new(rate_hz: f64) -> Self {
        Self {
            rate_hz,
            confidence: chi2::ONE_SIGMA,
            noise: NoiseModel::Identify,
            overlap: DEFAULT_OVERLAP,
            taus: Taus::Octave,
            gauss_markov: true,
        }
    }

    /// Leave out the Gauss-Markov alternative fit ([`NoiseFit::gauss_markov`] is then
    /// `None`): a caller that reads only the power-law terms (white noise, floor) saves its
    /// grid search, about as long as the rest of an analysis; every other figure is
    /// unchanged, bit for bit (the power-law fit does not depend on it).
    #[must_use]
    pub fn without_gauss_markov(mut self) -> Self {
        self.gauss_markov = false;
        self
    }

    /// The cluster times of the curve ([`Taus::Octave`] by default).
    #[must_use]
    pub fn taus(mut self, taus: Taus) -> Self {
        self.taus = taus;
        self
    }

    /// The cluster sizes of a listed grid (empty for the others), checked: each cluster time
    /// a positive whole number of samples.
    fn list_sizes(&self) -> Result<Vec<u64>, AllanError> {
        let Taus::List(list) = &self.taus else {
            return Ok(Vec::new());
        };
        if list.is_empty() {
            return Err(AllanError::InvalidSetting {
                field: "taus",
                value: 0.0,
                expected: "at least one cluster time",
            });
        }
        list.iter()
            .map(|&tau_s| {
                let m = tau_s * self.rate_hz;
                let whole = m.round();
                let bad = |reason: String| AllanError::InvalidTau { tau_s, reason };
                if !(tau_s.is_finite() && tau_s > 0.0) {
                    return Err(bad("a cluster time is a positive finite number of seconds".into()));
                }
                if !(1.0..=(1u64 << 61) as f64).contains(&whole)
                    || (m - whole).abs() > 1e-9 * whole
                {
                    return Err(bad(format!(
                        "a cluster time is a whole number of samples from 1 to 2^61 (the sample interval is {} s); this one is {m} samples",
                        1.0 / self.rate_hz
                    )));
                }
                Ok(whole as u64)
            })
            .collect()
    }

    /// The confidence of the bands, in (0, 1).
    #[must_use]
    pub fn confidence(mut self, confidence: f64) -> Self {
        self.confidence = confidence;
        self
    }

    /// The noise type(s) the degrees of freedom assume.
    #[must_use]
    pub fn noise(mut self, noise: NoiseModel) -> Self {
        self.noise = noise;
        self
    }

    /// The overlap factor $R$, a power of two in $[1, 2^{16}]$: clusters of up to $R$ samples
    /// are evaluated at every sample (fully overlapping), longer clusters $m$ every $m/r$
    /// samples, $r$ the smallest divisor of $m$ from $R$ on ($R$ itself for the octaves;
    /// $R = 1$: not overlapping, every cluster evaluated once per cluster time).
    #[must_use]
    pub fn overlap(mut self, overlap: u64) -> Self {
        self.overlap = overlap;
        self
    }

    /// The sample rate, Hz.
    #[must_use]
    pub fn rate_hz(&self) -> f64 {
        self.rate_hz
    }

    fn validate(&self) -> Result<(), AllanError> {
        if !(self.rate_hz.is_finite() && (RATE_HZ.0..=RATE_HZ.1).contains(&self.rate_hz)) {
            return Err(AllanError::InvalidRate {
                value: self.rate_hz,
            });
        }
        if !(self.confidence > 0.0 && self.confidence <= 1.0 - 1e-9) {
            return Err(AllanError::InvalidSetting {
                field: "confidence",
                value: self.confidence,
                expected: "a probability in (0, 1 - 1e-9]",
            });
        }
        if !(1..=MAX_OVERLAP).contains(&self.overlap) || !self.overlap.is_power_of_two() {
            return Err(AllanError::InvalidSetting {
                field: "overlap",
                value: self.overlap as f64,
                expected: "a power of two in [1, 65536] (1: not overlapping)",
            });
        }
        Ok(())
    }
}

/// One cluster time of the curve.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[non_exhaustive]
pub struct AllanPoint {
    /// Cluster size $m$, samples.
    pub(crate) cluster: u64,
    /// Cluster time $\tau = m / f_s$, s.
    pub(crate) tau_s: f64,
    /// Overlapping Allan deviation, log unit.
    pub(crate) adev: f64,
    /// Lower end of the confidence band, log unit.
    pub(crate) lower: f64,
    /// Upper end of the confidence band, log unit.
    pub(crate) upper: f64,
    /// Equivalent degrees of freedom of the estimate.
    pub(crate) edf: f64,
    /// Number of second differences averaged ($M$).
    pub(crate) terms: u64,
    /// Samples between evaluations $s$ (1: fully overlapping).
    pub(crate) stride: u64,
    /// Noise type the degrees of freedom assume.
    pub(crate) noise: PowerLaw,
    /// Modified Allan deviation, log unit.
    pub(crate) mdev: f64,
    /// Overlapping Hadamard deviation, log unit.
    pub(crate) hdev: f64,
    /// Total deviation, log unit.
    pub(crate) totdev: f64,
}

/// Read access to the fields (crate-private, so the type can grow without breaking callers).
impl AllanPoint {
    /// Cluster size $m$, samples.
    #[must_use]
    pub fn cluster(&self) -> u64 {
        self.cluster
    }

    /// Cluster time $\tau = m / f_s$, s.
    #[must_use]
    pub fn tau_s(&self) -> f64 {
        self.tau_s
    }

    /// Overlapping Allan deviation, log unit.
    #[must_use]
    pub fn adev(&self) -> f64 {
        self.adev
    }

    /// Lower end of the confidence band, log unit.
    #[must_use]
    pub fn lower(&self) -> f64 {
        self.lower
    }

    /// Upper end of the confidence band, log unit.
    #[must_use]
    pub fn upper(&self) -> f64 {
        self.upper
    }

    /// Equivalent degrees of freedom of the estimate.
    #[must_use]
    pub fn edf(&self) -> f64 {
        self.edf
    }

    /// Number of second differences averaged ($M$).
    #[must_use]
    pub fn terms(&self) -> u64 {
        self.terms
    }

    /// Samples between evaluations $s$ (1: fully overlapping).
    #[must_use]
    pub fn stride(&self) -> u64 {
        self.stride
    }

    /// Noise type the degrees of freedom assume.
    #[must_use]
    pub fn noise(&self) -> PowerLaw {
        self.noise
    }

    /// Modified Allan deviation (NIST SP 1065 eq 14) at the same stride, log unit.
    #[must_use]
    pub fn mdev(&self) -> f64 {
        self.mdev
    }

    /// Overlapping Hadamard deviation (NIST SP 1065 eq 18) at the same stride, log unit.
    #[must_use]
    pub fn hdev(&self) -> f64 {
        self.hdev
    }

    /// Total deviation (NIST SP 1065 eq 25, the phase reflected at both ends; no bias
    /// correction) at the same stride, log unit.
    #[must_use]
    pub fn totdev(&self) -> f64 {
        self.totdev
    }
}

/// The noise parameters read from the curve (see [`crate::fit`]).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[non_exhaustive]
pub struct NoiseFit {
    /// White noise density $N$, log unit $/\sqrt{\mathrm{Hz}}$ (log unit $\cdot\sqrt{\mathrm s}$):
    /// the Allan deviation of the white part at $\tau = 1$ s (0 when the fit has no white
    /// term).
    pub(crate) white_noise: f64,
    /// Conservative standard uncertainty of `white_noise`, same unit (`None` when 0).
    pub(crate) white_noise_uncertainty: Option<f64>,
    /// Bias instability $B$: the floor (minimum) of the fitted Allan deviation at the
    /// measured cluster times divided by [`FLICKER_FLOOR_FACTOR`], log unit.
    pub(crate) bias_instability: f64,
    /// Conservative standard uncertainty of `bias_instability`, log unit (`None` when 0).
    pub(crate) bias_instability_uncertainty: Option<f64>,
    /// The measured Allan deviation at the floor's cluster time, log unit.
    pub(crate) floor_adev_measured: f64,
    /// Cluster time of the floor, s: a heuristic correlation time for a first-order
    /// Gauss-Markov bias model.
    pub(crate) floor_tau_s: f64,
    /// Whether the curve turns: false when the floor is the longest cluster time, so that
    /// `bias_instability` is an upper bound.
    pub(crate) floor_reached: bool,
    /// Rate random walk $K$, log unit $\cdot\sqrt{\mathrm{Hz}}$ (log unit / $\sqrt{\mathrm s}$),
    /// when the fit has a $+1/2$ term.
    pub(crate) rate_random_walk: Option<f64>,
    /// Conservative standard uncertainty of `rate_random_walk`.
    pub(crate) rate_random_walk_uncertainty: Option<f64>,
    /// Quantization $Q$, log unit $\cdot$ s, when the fit has a $-1$ term.
    pub(crate) quantization: Option<f64>,
    /// Rate ramp $R$, log unit / s, when the fit has a $+1$ term.
    pub(crate) rate_ramp: Option<f64>,
    /// The fitted power terms $C_n$, $n = -2 \dots 2$ (log unit$^2$ s$^{-n}$).
    pub(crate) coefficients: [f64; 5],
    /// $Q, N, B, K, R$ of the joint fit, each with its uncertainty and resolution.
    pub(crate) terms: [Term; 5],
    /// The Gauss-Markov alternative (`None` for an all-zero curve).
    pub(crate) gauss_markov: Option<GaussMarkovFit>,
}

/// Read access to the fields (crate-private, so the type can grow without breaking callers).
impl NoiseFit {
    /// White noise density $N$, log unit $/\sqrt{\mathrm{Hz}}$ (log unit $\cdot\sqrt{\mathrm s}$):
    /// the Allan deviation of the white part at $\tau = 1$ s (0 when the fit has no white
    /// term).
    #[must_use]
    pub fn white_noise(&self) -> f64 {
        self.white_noise
    }

    /// Conservative standard uncertainty of `white_noise`, same unit (`None` when 0).
    #[must_use]
    pub fn white_noise_uncertainty(&self) -> Option<f64> {
        self.white_noise_uncertainty
    }

    /// Bias instability $B$: the floor (minimum) of the fitted Allan deviation at the
    /// measured cluster times divided by [`FLICKER_FLOOR_FACTOR`], log unit.
    #[must_use]
    pub fn bias_instability(&self) -> f64 {
        self.bias_instability
    }

    /// Conservative standard uncertainty of `bias_instability`, log unit (`None` when 0).
    #[must_use]
    pub fn bias_instability_uncertainty(&self) -> Option<f64> {
        self.bias_instability_uncertainty
    }

    /// The measured Allan deviation at the floor's cluster time, log unit.
    #[must_use]
    pub fn floor_adev_measured(&self) -> f64 {
        self.floor_adev_measured
    }

    /// Cluster time of the floor, s: a heuristic correlation time for a first-order
    /// Gauss-Markov bias model.
    #[must_use]
    pub fn floor_tau_s(&self) -> f64 {
        self.floor_tau_s
    }

    /// Whether the curve turns: false when the floor is the longest cluster time, so that
    /// `bias_instability` is an upper bound.
    #[must_use]
    pub fn floor_reached(&self) -> bool {
        self.floor_reached
    }

    /// Rate random walk $K$, log unit $\cdot\sqrt{\mathrm{Hz}}$ (log unit / $\sqrt{\mathrm s}$),
    /// when the fit has a $+1/2$ term.
    #[must_use]
    pub fn rate_random_walk(&self) -> Option<f64> {
        self.rate_random_walk
    }

    /// Conservative standard uncertainty of `rate_random_walk`.
    #[must_use]
    pub fn rate_random_walk_uncertainty(&self) -> Option<f64> {
        self.rate_random_walk_uncertainty
    }

    /// Quantization $Q$, log unit $\cdot$ s, when the fit has a $-1$ term.
    #[must_use]
    pub fn quantization(&self) -> Option<f64> {
        self.quantization
    }

    /// Rate ramp $R$, log unit / s, when the fit has a $+1$ term.
    #[must_use]
    pub fn rate_ramp(&self) -> Option<f64> {
        self.rate_ramp
    }

    /// The fitted power terms $C_n$, $n = -2 \dots 2$ (log unit$^2$ s$^{-n}$).
    #[must_use]
    pub fn coefficients(&self) -> [f64; 5] {
        self.coefficients
    }

    /// Quantization $Q$ of the joint fit, log unit $\cdot$ s (angle quantization: slope $-1$).
    #[must_use]
    pub fn quantization_term(&self) -> Term {
        self.terms[0]
    }

    /// White noise $N$ of the joint fit, log unit $/\sqrt{\mathrm{Hz}}$.
    #[must_use]
    pub fn white_term(&self) -> Term {
        self.terms[1]
    }

    /// Bias instability $B$ as a flicker floor of the joint fit ($\sqrt{C_0}/0.664$), log
    /// unit; [`Resolution::BeyondLog`] when the curve still falls at the longest cluster
    /// time.
    #[must_use]
    pub fn flicker_term(&self) -> Term {
        self.terms[2]
    }

    /// Rate random walk $K$ of the joint fit, log unit $\cdot\sqrt{\mathrm{Hz}}$.
    #[must_use]
    pub fn rate_random_walk_term(&self) -> Term {
        self.terms[3]
    }

    /// Rate ramp $R$ of the joint fit, log unit / s.
    #[must_use]
    pub fn rate_ramp_term(&self) -> Term {
        self.terms[4]
    }

    /// The Gauss-Markov alternative ($Q, N, K, R$ and a Gauss-Markov bias of fitted
    /// correlation time; `None` for an all-zero curve, or when the settings leave it out:
    /// [`Settings::without_gauss_markov`]).
    #[must_use]
    pub fn gauss_markov(&self) -> Option<GaussMarkovFit> {
        self.gauss_markov
    }
}

/// The result of an analysis.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[non_exhaustive]
pub struct Analysis {
    /// Samples analysed.
    pub(crate) samples: u64,
    /// Sample rate, Hz.
    pub(crate) rate_hz: f64,
    /// Confidence of the bands.
    pub(crate) confidence: f64,
    /// The overlap factor $R$ (clusters longer than $R$ samples are evaluated every $m/R$).
    pub(crate) overlap: u64,
    /// The curve, by increasing cluster time ($m = 1, 2, 4, \dots$, $3m \le N$).
    pub(crate) points: Vec<AllanPoint>,
    /// The fitted noise parameters.
    pub(crate) fit: NoiseFit,
}

/// Read access to the fields (crate-private, so the type can grow without breaking callers).
impl Analysis {
    /// Samples analysed.
    #[must_use]
    pub fn samples(&self) -> u64 {
        self.samples
    }

    /// Sample rate, Hz.
    #[must_use]
    pub fn rate_hz(&self) -> f64 {
        self.rate_hz
    }

    /// Confidence of the bands.
    #[must_use]
    pub fn confidence(&self) -> f64 {
        self.confidence
    }

    /// The overlap factor $R$ (clusters longer than $R$ samples are evaluated every $m/R$).
    #[must_use]
    pub fn overlap(&self) -> u64 {
        self.overlap
    }

    /// The curve, by increasing cluster time ($m = 1, 2, 4, \dots$, $3m \le N$).
    #[must_use]
    pub fn points(&self) -> &[AllanPoint] {
        &self.points
    }

    /// The fitted noise parameters.
    #[must_use]
    pub fn fit(&self) -> NoiseFit {
        self.fit
    }
}

/// The streaming overlapping Allan deviation (see the crate documentation for the estimator)
/// with, at the same cluster times, the modified, overlapping Hadamard and total deviations.
///
/// ```
/// use allan::{Settings, StreamingAllan};
/// let mut a = StreamingAllan::new(Settings::new(100.0))?;
/// for i in 0..1000 {
///     a.push(if i % 2 == 0 { 0.1 } else { -0.1 })?;
/// }
/// let r = a.analyse()?;
/// // alternating samples: every second difference at m = 1 is +-0.2
/// assert!((r.points()[0].adev() - (0.04f64 / 2.0).sqrt()).abs() < 1e-12);
/// # Ok::<(), allan::AllanError>(())
/// ```
#[derive(Debug, Clone)]
pub struct StreamingAllan {
    settings: Settings,
    /// Samples accepted.
    samples: u64,
    /// Samples waiting for the next block.
    pending: Vec<f64>,
    /// The value removed from every sample (the mean of the first block).
    reference: Option<f64>,
    /// Phase history for the stride-1 levels: the last `keep` phases, ending with the phase
    /// after `processed` samples, followed by room for a block.
    work: Vec<f64>,
    /// Phases kept in `work` between blocks: $3 m_1 + 2$, $m_1$ the largest stride-1 cluster.
    keep: usize,
    /// The first $2 m_1 + 1$ phases (the total deviation's reflection at the start).
    head: Vec<f64>,
    /// Samples folded into the phase.
    processed: u64,
    /// The current phase (sum of the referenced samples).
    phase: f64,
    /// The cluster sizes, by increasing size.
    levels: Vec<Level>,
    /// Running sums of the block (scratch, reused).
    scratch: Vec<f64>,
}

impl StreamingAllan {
    /// A new estimator.
    ///
    /// # Errors
    /// [`AllanError::InvalidRate`] for a rate outside [`RATE_HZ`];
    /// [`AllanError::InvalidSetting`] naming `confidence` or `overlap`;
    /// [`AllanError::InvalidTau`] for a listed cluster time that is not a whole number of
    /// samples or that the estimator cannot decimate in bounded memory.
    pub fn new(settings: Settings) -> Result<Self, AllanError> {
        settings.validate()?;
        let sizes = settings.list_sizes()?;
        let pairs = levels::grid(&settings.taus, settings.overlap, &sizes).map_err(|i| {
            let Taus::List(list) = &settings.taus else {
                unreachable!("only a list has sizes")
            };
            AllanError::InvalidTau {
                tau_s: list[i],
                reason: format!(
                    "{} samples has no divisor between the overlap factor {} and {}: the streaming estimator cannot evaluate it in bounded memory; choose a nearby cluster time",
                    sizes[i],
                    settings.overlap,
                    levels::MAX_LIST_EVALUATIONS
                ),
            }
        })?;
        let m1 = pairs
            .iter()
            .filter(|p| p.1 == 1)
            .map(|p| p.0)
            .max()
            .unwrap_or(1) as usize;
        let keep = 3 * m1 + 2;
        let mut work = Vec::with_capacity(keep + BLOCK + 1);
        work.push(0.0);
        Ok(Self {
            settings,
            samples: 0,
            pending: Vec::with_capacity(BLOCK),
            reference: None,
            work,
            keep,
            head: vec![0.0],
            processed: 0,
            phase: 0.0,
            levels: pairs.into_iter().map(|(m, s)| Level::new(m, s)).collect(),
            scratch: Vec::with_capacity(BLOCK + 1),
        })
    }

    /// The settings.
    #[must_use]
    pub fn settings(&self) -> &Settings {
        &self.settings
    }

    /// Samples accepted so far.
    #[must_use]
    pub fn samples(&self) -> u64 {
        self.samples
    }

    /// Add one sample.
    ///
    /// # Errors
    /// [`AllanError::NonFiniteSample`] (with its index) for NaN or an infinity; the sample is
    /// not added.
    pub fn push(&mut self, y: f64) -> Result<(), AllanError> {
        if !y.is_finite() {
            return Err(AllanError::NonFiniteSample {
                index: self.samples,
                value: y,
            });
        }
        self.pending.push(y);
        self.samples += 1;
        if self.pending.len() == BLOCK {
            self.process_pending();
        }
        Ok(())
    }

    /// Add samples in order.
    ///
    /// # Errors
    /// [`AllanError::NonFiniteSample`] for the first NaN or infinity (its index counts every
    /// sample pushed before); then no sample of `ys` is added.
    pub fn extend(&mut self, ys: &[f64]) -> Result<(), AllanError> {
        if let Some(i) = ys.iter().position(|y| !y.is_finite()) {
            return Err(AllanError::NonFiniteSample {
                index: self.samples + i as u64,
                value: ys[i],
            });
        }
        let mut rest = ys;
        while !rest.is_empty() {
            let take = (BLOCK - self.pending.len()).min(rest.len());
            self.pending.extend_from_slice(&rest[..take]);
            self.samples += take as u64;
            rest = &rest[take..];
            if self.pending.len() == BLOCK {
                self.process_pending();
            }
        }
        Ok(())
    }

    /// Fold the pending samples into the phase and the level sums.
    fn process_pending(&mut self) {
        if self.pending.is_empty() {
            return;
        }
        let reference = *self
            .reference
            .get_or_insert_with(|| self.pending.iter().sum::<f64>() / self.pending.len() as f64);
        // work = [history (<= keep phases, the last one at index `base`)] + new phases
        let base = self.work.len() - 1;
        let mut x = self.phase;
        for &y in &self.pending {
            x += y - reference;
            self.work.push(x);
        }
        self.phase = x;
        let b = self.pending.len();
        let t0 = self.processed; // global phase index of work[base]
        let w0 = t0 - base as u64; // global phase index of work[0]
        let head_cap = (self.keep - 2) / 3 * 2 + 1;
        if self.head.len() < head_cap {
            let more = (head_cap - self.head.len()).min(b);
            self.head
                .extend_from_slice(&self.work[base + 1..base + 1 + more]);
        }
        let last_t = t0 + b as u64;
        // running sums of the whole work buffer, anchored at work[base] (the modified
        // deviation's third differences of the running sum ignore the anchor)
        let anchor = self.work[base];
        let pre = &mut self.scratch;
        pre.clear();
        pre.push(0.0);
        let mut acc = 0.0;
        for v in &self.work {
            acc += v - anchor;
            pre.push(acc);
        }
        for level in self.levels.iter_mut().filter(|l| l.stride == 1) {
            let m = level.m as usize;
            let mu = m as u64;
            // Allan: right ends t in [max(t0 + 1, 2m), last]
            let first_t = (t0 + 1).max(2 * mu);
            if first_t <= last_t {
                let start = (first_t - w0) as usize;
                let len = (last_t - first_t + 1) as usize;
                let a = &self.work[start..start + len];
                let p = &self.work[start - m..start - m + len];
                let q = &self.work[start - 2 * m..start - 2 * m + len];
                level.sums.adev.0 += sum_sq_second_diff(a, p, q);
                level.sums.adev.1 += len as u64;
            }
            // Hadamard: right ends t in [max(t0 + 1, 3m), last]
            let first_t = (t0 + 1).max(3 * mu);
            if first_t <= last_t {
                let start = (first_t - w0) as usize;
                let len = (last_t - first_t + 1) as usize;
                level.sums.hdev.0 += sum_sq_third_diff(&self.work, start, len, m);
                level.sums.hdev.1 += last_t - first_t + 1;
            }
            // modified Allan: running-sum ends e in [max(t0 + 2, 3m), last + 1]
            let first_e = (t0 + 2).max(3 * mu);
            if first_e <= last_t + 1 {
                let start = (first_e - w0) as usize;
                let len = (last_t + 2 - first_e) as usize;
                level.sums.mdev.0 += sum_sq_third_diff(pre, start, len, m);
                level.sums.mdev.1 += last_t + 2 - first_e;
            }
        }
        if self.levels.iter().any(|l| l.stride > 1) {
            // running sums of x_{t0} ..= x_{last} (unanchored: a level's B sums span blocks)
            pre.clear();
            pre.push(0.0);
            let mut acc = 0.0;
            for v in &self.work[base..] {
                acc += v;
                pre.push(acc);
            }
            let phases = &self.work[base..];
            for level in self.levels.iter_mut().filter(|l| l.stride > 1) {
                level.take_strided(t0, phases, pre);
            }
        }
        self.processed += b as u64;
        self.pending.clear();
        let drop = self.work.len().saturating_sub(self.keep);
        self.work.drain(..drop);
    }

    /// The curve and the fitted noise parameters of every sample so far. More samples may be
    /// pushed afterwards.
    ///
    /// # Errors
    /// [`AllanError::TooFewSamples`] below 3 samples; [`AllanError::ClusterTooLong`] for a
    /// listed cluster time longer than a third of the log; [`AllanError::Overflow`] when the
    /// samples are so large that a variance is not finite.
    pub fn analyse(&mut self) -> Result<Analysis, AllanError> {
        if self.samples < 3 {
            return Err(AllanError::TooFewSamples {
                samples: self.samples,
                needed: 3,
            });
        }
        self.process_pending();
        let n = self.samples;
        let rate = self.settings.rate_hz;
        let listed = matches!(self.settings.taus, Taus::List(_));
        // levels with at least three clusters: 3m <= N
        let mut raw = Vec::new();
        for level in &self.levels {
            let m = level.m;
            let tau_s = m as f64 / rate;
            if m.checked_mul(3).is_none_or(|t| t > n) {
                if listed {
                    return Err(AllanError::ClusterTooLong {
                        tau_s,
                        samples: n,
                        needed: 3 * m,
                    });
                }
                break;
            }
            let stride = level.stride;
            let mf = m as f64;
            let (sum, terms) = level.sums.adev;
            debug_assert_eq!(terms, edf::terms(n, m, stride));
            let avar = sum / (2.0 * mf * mf * terms as f64);
            let (hsum, hterms) = level.sums.hdev;
            let hvar = hsum / (6.0 * mf * mf * hterms as f64);
            let (msum, mterms) = level.sums.mdev;
            let mvar = msum / (2.0 * mf * mf * mf * mf * mterms as f64);
            let (tsum, tterms) = if stride == 1 {
                levels::total_sum(&self.head, &self.work, n, m, sum)
            } else {
                level.total_strided()
            };
            let tvar = tsum / (2.0 * mf * mf * tterms as f64);
            if [avar, hvar, mvar, tvar].iter().any(|v| !v.is_finite()) {
                return Err(AllanError::Overflow { tau_s });
            }
            raw.push(Raw {
                m,
                tau_s,
                avar,
                terms,
                stride,
                others: [mvar.sqrt(), hvar.sqrt(), tvar.sqrt()],
            });
        }
        let adevs: Vec<f64> = raw.iter().map(|p| p.avar.sqrt()).collect();
        let taus: Vec<f64> = raw.iter().map(|p| p.tau_s).collect();
        let noises: Vec<PowerLaw> = match self.settings.noise {
            NoiseModel::Fixed(p) => vec![p; raw.len()],
            NoiseModel::Identify => identify(&taus, &adevs),
        };
        let mut points = Vec::with_capacity(raw.len());
        for (i, p) in raw.iter().enumerate() {
            let noise = noises[i];
            let nu = edf::edf(noise, n, p.m, p.stride);
            let (lower, upper) = chi2::interval(adevs[i], nu, self.settings.confidence);
            for v in [lower, upper, nu] {
                if !v.is_finite() {
                    return Err(AllanError::Overflow { tau_s: p.tau_s });
                }
            }
            points.push(AllanPoint {
                cluster: p.m,
                tau_s: p.tau_s,
                adev: adevs[i],
                lower,
                upper,
                edf: nu,
                terms: p.terms,
                stride: p.stride,
                noise,
                mdev: p.others[0],
                hdev: p.others[1],
                totdev: p.others[2],
            });
        }
        let fit = noise_fit(&points, self.settings.gauss_markov)?;
        Ok(Analysis {
            samples: n,
            rate_hz: rate,
            confidence: self.settings.confidence,
            overlap: self.settings.overlap,
            points,
            fit,
        })
    }
}

/// One cluster time before its band.
struct Raw {
    m: u64,
    tau_s: f64,
    avar: f64,
    terms: u64,
    stride: u64,
    /// Modified, Hadamard and total deviations.
    others: [f64; 3],
}

/// $\sum_i (v_i - 3 v_{i-m} + 3 v_{i-2m} - v_{i-3m})^2$ for $i$ = `start` .. `start + len`,
/// in four lanes.
fn sum_sq_third_diff(v: &[f64], start: usize, len: usize, m: usize) -> f64 {
    let a = &v[start..start + len];
    let b = &v[start - m..start - m + len];
    let c = &v[start - 2 * m..start - 2 * m + len];
    let d = &v[start - 3 * m..start - 3 * m + len];
    let mut acc = [0.0f64; 4];
    let n4 = len / 4 * 4;
    for (((ca, cb), cc), cd) in a[..n4]
        .chunks_exact(4)
        .zip(b[..n4].chunks_exact(4))
        .zip(c[..n4].chunks_exact(4))
        .zip(d[..n4].chunks_exact(4))
    {
        for l in 0..4 {
            let t = ca[l] - 3.0 * cb[l] + 3.0 * cc[l] - cd[l];
            acc[l] += t * t;
        }
    }
    let mut tail = 0.0;
    for i in n4..len {
        let t = a[i] - 3.0 * b[i] + 3.0 * c[i] - d[i];
        tail += t * t;
    }
    (acc[0] + acc[1]) + (acc[2] + acc[3]) + tail
}

/// $\sum_i (a_i - 2 p_i + q_i)^2$ in four lanes.
fn sum_sq_second_diff(a: &[f64], p: &[f64], q: &[f64]) -> f64 {
    let mut acc = [0.0f64; 4];
    let n4 = a.len() / 4 * 4;
    for ((ca, cp), cq) in a[..n4]
        .chunks_exact(4)
        .zip(p[..n4].chunks_exact(4))
        .zip(q[..n4].chunks_exact(4))
    {
        for l in 0..4 {
            let d = ca[l] - 2.0 * cp[l] + cq[l];
            acc[l] += d * d;
        }
    }
    let mut tail = 0.0;
    for i in n4..a.len() {
        let d = a[i] - 2.0 * p[i] + q[i];
        tail += d * d;
    }
    (acc[0] + acc[1]) + (acc[2] + acc[3]) + tail
}

/// The noise type at every cluster time: the nearest to the local slope
/// ([`PowerLaw::nearest_to_slope`]), except that quantization (which dominates short cluster
/// times only: the slope of a sum of power laws never decreases) after the first other type
/// is read as white noise (a slope of $-1$ there is the scatter of the slope estimate).
fn identify(taus: &[f64], adevs: &[f64]) -> Vec<PowerLaw> {
    let mut out: Vec<PowerLaw> = (0..taus.len())
        .map(|i| PowerLaw::nearest_to_slope(local_slope(taus, adevs, i)))
        .collect();
    if let Some(first) = out.iter().position(|p| *p != PowerLaw::Quantization) {
        for p in &mut out[first..] {
            if *p == PowerLaw::Quantization {
                *p = PowerLaw::White;
            }
        }
    }
    out
}

/// Log-log slope at point `i`: least-squares line through it and its neighbours (non-positive
/// deviations left out); NaN when fewer than two points remain.
fn local_slope(taus: &[f64], adevs: &[f64], i: usize) -> f64 {
    let lo = i.saturating_sub(1);
    let hi = (i + 1).min(taus.len() - 1);
    let pts: Vec<(f64, f64)> = (lo..=hi)
        .filter(|&j| adevs[j] > 0.0)
        .map(|j| (taus[j].ln(), adevs[j].ln()))
        .collect();
    if pts.len() < 2 {
        return f64::NAN;
    }
    let nf = pts.len() as f64;
    let mx = pts.iter().map(|p| p.0).sum::<f64>() / nf;
    let my = pts.iter().map(|p| p.1).sum::<f64>() / nf;
    let sxy: f64 = pts.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum();
    let sxx: f64 = pts.iter().map(|p| (p.0 - mx) * (p.0 - mx)).sum();
    sxy / sxx
}

/// The noise parameters of a curve ([`crate::fit`]).
///
/// # Errors
/// [`AllanError::Overflow`] when a parameter is not a finite double (a log so large or so
/// small that its coefficients leave the range of a double).
fn noise_fit(points: &[AllanPoint], gauss_markov: bool) -> Result<NoiseFit, AllanError> {
    let triples: Vec<(f64, f64, f64)> = points
        .iter()
        .map(|p| (p.tau_s, p.adev * p.adev, p.edf))
        .collect();
    let pf = fit::fit_power_terms(&triples);
    let gm = if gauss_markov {
        fit::fit_gauss_markov(&triples, &pf)
    } else {
        None
    };
    let c = pf.coefficients();
    let mut terms = pf.terms();
    // floor: the smallest fitted deviation at a measured cluster time (the first on ties)
    let fitted: Vec<f64> = points.iter().map(|p| pf.avar(p.tau_s).max(0.0)).collect();
    let fi = fitted
        .iter()
        .enumerate()
        .fold(0, |bi, (i, v)| if *v < fitted[bi] { i } else { bi });
    let floor_avar = fitted[fi];
    let floor_sd = pf.avar_uncertainty(points[fi].tau_s);
    let floor_adev = floor_avar.sqrt();
    let floor_reached = fi + 1 < points.len();
    if !floor_reached && terms[2].value > 0.0 {
        terms[2].resolution = Resolution::BeyondLog;
    }
    let [_, white, _, k_rw, _] = terms;
    let fit = NoiseFit {
        white_noise: white.value,
        white_noise_uncertainty: white.uncertainty,
        bias_instability: floor_adev / FLICKER_FLOOR_FACTOR,
        bias_instability_uncertainty: (floor_adev > 0.0)
            .then(|| floor_sd / (2.0 * floor_adev) / FLICKER_FLOOR_FACTOR),
        floor_adev_measured: points[fi].adev,
        floor_tau_s: points[fi].tau_s,
        floor_reached,
        rate_random_walk: (k_rw.value > 0.0).then_some(k_rw.value),
        rate_random_walk_uncertainty: k_rw.uncertainty,
        quantization: (terms[0].value > 0.0).then_some(terms[0].value),
        rate_ramp: (terms[4].value > 0.0).then_some(terms[4].value),
        coefficients: c,
        terms,
        gauss_markov: gm,
    };
    let mut all: Vec<f64> = vec![
        fit.white_noise,
        fit.bias_instability,
        fit.floor_adev_measured,
        fit.floor_tau_s,
    ];
    all.extend(c);
    for t in terms.iter().chain(
        gm.iter()
            .flat_map(|g| {
                [
                    g.sigma,
                    g.correlation_s,
                    g.quantization,
                    g.white,
                    g.rate_random_walk,
                    g.rate_ramp,
                ]
            })
            .collect::<Vec<_>>()
            .iter(),
    ) {
        all.push(t.value);
        all.extend(t.uncertainty);
    }
    all.extend(fit.bias_instability_uncertainty);
    if let Some(v) = all.iter().find(|v| !v.is_finite()) {
        let _ = v;
        return Err(AllanError::Overflow {
            tau_s: points[points.len() - 1].tau_s,
        });
    }
    Ok(fit)
}

/// The analysis of a whole log held in memory (the same estimator as [`StreamingAllan`]).
///
/// # Errors
/// As [`StreamingAllan::new`], [`StreamingAllan::extend`] and [`StreamingAllan::analyse`].
pub fn analyse(samples: &[f64], settings: Settings) -> Result<Analysis, AllanError> {
    let mut a = StreamingAllan::new(settings)?;
    a.extend(samples)?;
    a.analyse()
}
