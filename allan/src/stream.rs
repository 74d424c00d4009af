//! The streaming estimator: samples in, one pass, memory bounded by the settings.

use crate::chi2;
use crate::edf;
use crate::error::AllanError;
use crate::fit::{self, FLICKER_FLOOR_FACTOR};
use crate::noise::{NoiseModel, PowerLaw};

/// Samples processed at a time (and averaged for the reference value removed from the
/// phase).
const BLOCK: usize = 4096;

/// Levels $k$ kept: cluster sizes $m = 2^k$ up to $2^{61}$ (any `u64` sample count).
const LEVELS: usize = 62;

/// Largest overlap factor accepted.
pub const MAX_OVERLAP: u64 = 1 << 16;

/// Default overlap factor $R$ (evaluations per cluster time beyond full overlap).
pub const DEFAULT_OVERLAP: u64 = 256;

/// Settings of an analysis.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Settings {
    rate_hz: f64,
    confidence: f64,
    noise: NoiseModel,
    overlap: u64,
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
        }
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

    /// The overlap factor $R$, a power of two in $[2, 2^{16}]$: clusters of up to $R$ samples
    /// are evaluated at every sample (fully overlapping), longer clusters $m$ every $m/R$
    /// samples.
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

    /// The confidence of the bands.
    #[must_use]
    pub fn confidence_level(&self) -> f64 {
        self.confidence
    }

    /// The noise model of the degrees of freedom.
    #[must_use]
    pub fn noise_model(&self) -> NoiseModel {
        self.noise
    }

    /// The overlap factor $R$.
    #[must_use]
    pub fn overlap_factor(&self) -> u64 {
        self.overlap
    }

    fn validate(&self) -> Result<(), AllanError> {
        if !(self.rate_hz.is_finite() && self.rate_hz > 0.0) {
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
        if !(2..=MAX_OVERLAP).contains(&self.overlap) || !self.overlap.is_power_of_two() {
            return Err(AllanError::InvalidSetting {
                field: "overlap",
                value: self.overlap as f64,
                expected: "a power of two in [2, 65536]",
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

/// A level of decimated evaluation: phase samples every `stride` samples in a ring.
#[derive(Debug, Clone)]
struct Ring {
    stride: u64,
    data: Vec<f64>,
    head: usize,
}

/// The streaming overlapping Allan deviation (see the crate documentation for the estimator).
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
    /// Phase history for the fully overlapping levels: the last `2R + 1` phases, ending with
    /// the phase after `processed` samples, followed by room for a block.
    work: Vec<f64>,
    /// Samples folded into the phase.
    processed: u64,
    /// The current phase (sum of the referenced samples).
    phase: f64,
    /// Per level: sum of squared second differences and their count.
    sum_sq: Vec<f64>,
    count: Vec<u64>,
    /// Decimated levels (index k - log2 R - 1).
    rings: Vec<Ring>,
}

impl StreamingAllan {
    /// A new estimator.
    ///
    /// # Errors
    /// [`AllanError::InvalidRate`] for a rate that is not positive and finite;
    /// [`AllanError::InvalidSetting`] naming `confidence` or `overlap`.
    pub fn new(settings: Settings) -> Result<Self, AllanError> {
        settings.validate()?;
        let r = settings.overlap;
        let full_levels = r.trailing_zeros() as usize + 1;
        let rings = (full_levels..LEVELS)
            .map(|k| Ring {
                stride: (1u64 << k) / r,
                data: Vec::new(),
                head: 0,
            })
            .collect();
        let mut work = Vec::with_capacity(2 * r as usize + 1 + BLOCK);
        work.push(0.0);
        Ok(Self {
            settings,
            samples: 0,
            pending: Vec::with_capacity(BLOCK),
            reference: None,
            work,
            processed: 0,
            phase: 0.0,
            sum_sq: vec![0.0; LEVELS],
            count: vec![0; LEVELS],
            rings,
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
        let r = self.settings.overlap as usize;
        let keep = 2 * r + 1;
        // work = [history (<= 2R + 1 phases, the last one at index `base`)] + new phases
        let base = self.work.len() - 1;
        let mut x = self.phase;
        for &y in &self.pending {
            x += y - reference;
            self.work.push(x);
        }
        self.phase = x;
        let b = self.pending.len();
        let t0 = self.processed; // global phase index of work[base]
        // fully overlapping levels: m = 1, 2, ..., R
        let mut k = 0;
        let mut m = 1usize;
        while m <= r {
            // new phase indices t = t0 + 1 ..= t0 + b; a term needs t >= 2m
            let first_t = (t0 + 1).max(2 * m as u64);
            let last_t = t0 + b as u64;
            if first_t <= last_t {
                let start = base + (first_t - t0) as usize;
                let len = (last_t - first_t + 1) as usize;
                let a = &self.work[start..start + len];
                let p = &self.work[start - m..start - m + len];
                let q = &self.work[start - 2 * m..start - 2 * m + len];
                self.sum_sq[k] += sum_sq_second_diff(a, p, q);
                self.count[k] += len as u64;
            }
            k += 1;
            m *= 2;
        }
        // decimated levels: phases at multiples of the stride
        let cap = 2 * r + 1;
        for (ring, level) in self.rings.iter_mut().zip(k..) {
            let s = ring.stride;
            // phase index 0 (before any sample) belongs to every level
            let mut t = if t0 == 0 && ring.data.is_empty() {
                0
            } else {
                (t0 / s + 1) * s
            };
            while t <= t0 + b as u64 {
                let v = self.work[base + (t - t0) as usize];
                if ring.data.len() < cap {
                    ring.data.push(v);
                } else {
                    ring.data[ring.head] = v;
                    ring.head = (ring.head + 1) % cap;
                }
                if ring.data.len() == cap {
                    // oldest at head, newest just before it
                    let newest = (ring.head + cap - 1) % cap;
                    let mid = (ring.head + r) % cap;
                    let d = ring.data[newest] - 2.0 * ring.data[mid] + ring.data[ring.head];
                    self.sum_sq[level] += d * d;
                    self.count[level] += 1;
                }
                t += s;
            }
        }
        self.processed += b as u64;
        self.pending.clear();
        let drop = self.work.len().saturating_sub(keep);
        self.work.drain(..drop);
    }

    /// The curve and the fitted noise parameters of every sample so far. More samples may be
    /// pushed afterwards.
    ///
    /// # Errors
    /// [`AllanError::TooFewSamples`] below 3 samples; [`AllanError::Overflow`] when the
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
        let r = self.settings.overlap;
        // levels with at least three clusters: 3m <= N
        let mut raw = Vec::new();
        for k in 0..LEVELS {
            let m = 1u64 << k;
            if m.checked_mul(3).is_none_or(|t| t > n) {
                break;
            }
            let stride = if m <= r { 1 } else { m / r };
            let terms = self.count[k];
            debug_assert_eq!(terms, edf::terms(n, m, stride));
            let avar = self.sum_sq[k] / (2.0 * (m as f64) * (m as f64) * terms as f64);
            let tau_s = m as f64 / rate;
            if !avar.is_finite() {
                return Err(AllanError::Overflow { tau_s });
            }
            raw.push((m, tau_s, avar, terms, stride));
        }
        let adevs: Vec<f64> = raw.iter().map(|p| p.2.sqrt()).collect();
        let taus: Vec<f64> = raw.iter().map(|p| p.1).collect();
        let noises: Vec<PowerLaw> = match self.settings.noise {
            NoiseModel::Fixed(p) => vec![p; raw.len()],
            NoiseModel::Identify => identify(&taus, &adevs),
        };
        let mut points = Vec::with_capacity(raw.len());
        for (i, &(m, tau_s, _, terms, stride)) in raw.iter().enumerate() {
            let noise = noises[i];
            let nu = edf::edf(noise, n, m, stride);
            let (lower, upper) = chi2::interval(adevs[i], nu, self.settings.confidence);
            for v in [lower, upper, nu] {
                if !v.is_finite() {
                    return Err(AllanError::Overflow { tau_s });
                }
            }
            points.push(AllanPoint {
                cluster: m,
                tau_s,
                adev: adevs[i],
                lower,
                upper,
                edf: nu,
                terms,
                stride,
                noise,
            });
        }
        let fit = noise_fit(&points);
        Ok(Analysis {
            samples: n,
            rate_hz: rate,
            confidence: self.settings.confidence,
            overlap: r,
            points,
            fit,
        })
    }
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
fn noise_fit(points: &[AllanPoint]) -> NoiseFit {
    let triples: Vec<(f64, f64, f64)> = points
        .iter()
        .map(|p| (p.tau_s, p.adev * p.adev, p.edf))
        .collect();
    let pf = fit::fit_power_terms(&triples);
    let c = pf.coefficients;
    let u = pf.uncertainty;
    let white = c[1].sqrt();
    let k_rw = (c[3] > 0.0).then(|| (3.0 * c[3]).sqrt());
    // floor: the smallest fitted deviation at a measured cluster time (the first on ties)
    let fitted: Vec<f64> = points.iter().map(|p| pf.avar(p.tau_s).max(0.0)).collect();
    let fi = fitted
        .iter()
        .enumerate()
        .fold(0, |bi, (i, v)| if *v < fitted[bi] { i } else { bi });
    let floor_avar = fitted[fi];
    let floor_sd = pf.avar_uncertainty(points[fi].tau_s);
    let floor_adev = floor_avar.sqrt();
    NoiseFit {
        white_noise: white,
        white_noise_uncertainty: (white > 0.0).then(|| u[1] / (2.0 * white)),
        bias_instability: floor_adev / FLICKER_FLOOR_FACTOR,
        bias_instability_uncertainty: (floor_adev > 0.0)
            .then(|| floor_sd / (2.0 * floor_adev) / FLICKER_FLOOR_FACTOR),
        floor_adev_measured: points[fi].adev,
        floor_tau_s: points[fi].tau_s,
        floor_reached: fi + 1 < points.len(),
        rate_random_walk: k_rw,
        rate_random_walk_uncertainty: k_rw.map(|k| 3.0 * u[3] / (2.0 * k)),
        quantization: (c[0] > 0.0).then(|| (c[0] / 3.0).sqrt()),
        rate_ramp: (c[4] > 0.0).then(|| (2.0 * c[4]).sqrt()),
        coefficients: c,
    }
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
