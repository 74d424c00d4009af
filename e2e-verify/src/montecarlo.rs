//! Monte Carlo over turntables drawn from a tolerance box: the distribution of the
//! end-to-end rate errors and the yield $P(\Delta\omega_x \le \omega_m \wedge \Delta\omega_y \le
//! \omega_m)$ with a Wilson confidence interval.
//!
//! Draws reuse mc-verify's streams and sampler: chunk $c$ of a run seeded $s$ uses
//! [`mc_verify::chunk_rng`]`(s, c)` and [`mc_verify::TurntableSampler::fill_block`] in blocks of
//! [`mc_verify::BLOCK_CAPACITY`] (uniform magnitudes in $[\mathrm{LB}_i, \mathrm{UB}_i]$, fair
//! signs; the pose it also draws is not used: the calibration positions are the schedule's).
//! With `chunk_size` = [`mc_verify::DEFAULT_CHUNK_SIZE`] the turntables are exactly those of a
//! [`mc_verify::MonteCarlo`] run with the same seed; the default here is smaller
//! ([`DEFAULT_CHUNK_SIZE`]) so that a few ten thousand draws still spread over threads. Chunks run on rayon threads and are
//! concatenated in chunk order, so results are bit-identical for any thread count.

use crate::error::{E2eError, positive};
use crate::simulate::EndToEnd;
use gw_model::units::rad_per_s_to_deg_per_h;
use mc_verify::{BLOCK_CAPACITY, ErrorBox, SampleBlock, TurntableSampler, chunk_rng};
use rayon::prelude::*;
use tt_kinematics::CHI_LEN;

/// Standard normal quantile of 97.5% ($z$ of a two-sided 95% interval).
pub const Z_95: f64 = 1.959_963_984_540_054;

/// Default number of samples per chunk (one random stream each).
pub const DEFAULT_CHUNK_SIZE: u32 = 1024;

/// Default number of histogram bins.
pub const DEFAULT_BINS: usize = 40;

/// Probabilities at which [`RateDistribution::quantiles`] are reported.
pub const REPORTED_QUANTILES: [f64; 6] = [0.5, 0.9, 0.99, 0.9973, 0.999, 1.0];

/// How many turntables to draw and from which random streams.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct McSettings {
    /// Number of turntables.
    pub samples: u64,
    /// Seed of the streams.
    pub seed: u64,
    /// Turntables per chunk (stream).
    pub chunk_size: u32,
    /// Histogram bins.
    pub histogram_bins: usize,
}

impl McSettings {
    /// `samples` turntables from seed `seed`, default chunk size and bins.
    #[must_use]
    pub fn new(samples: u64, seed: u64) -> Self {
        Self {
            samples,
            seed,
            chunk_size: DEFAULT_CHUNK_SIZE,
            histogram_bins: DEFAULT_BINS,
        }
    }

    /// Check the counts.
    ///
    /// # Errors
    /// [`E2eError::ZeroSamples`] naming `samples`, `chunk_size` or `histogram_bins`.
    pub fn validate(&self) -> Result<(), E2eError> {
        if self.samples == 0 {
            return Err(E2eError::ZeroSamples { field: "samples" });
        }
        if self.chunk_size == 0 {
            return Err(E2eError::ZeroSamples {
                field: "chunk_size",
            });
        }
        if self.histogram_bins == 0 {
            return Err(E2eError::ZeroSamples {
                field: "histogram_bins",
            });
        }
        Ok(())
    }
}

/// A two-sided 95% Wilson score interval for a binomial proportion.
///
/// # Formula
/// $$\frac{\hat p + \frac{z^2}{2n} \pm z\sqrt{\frac{\hat p(1-\hat p)}{n} + \frac{z^2}{4n^2}}}
/// {1 + \frac{z^2}{n}},\qquad z = 1.96.$$
///
/// # Reference
/// E. B. Wilson, "Probable inference, the law of succession, and statistical inference",
/// J. Am. Stat. Assoc. 22 (1927).
///
/// ```
/// let (lo, hi) = e2e_verify::wilson_interval_95(997, 1000);
/// assert!(lo < 0.997 && 0.997 < hi && hi < 1.0);
/// ```
#[must_use]
pub fn wilson_interval_95(successes: u64, trials: u64) -> (f64, f64) {
    if trials == 0 {
        return (0.0, 1.0);
    }
    let n = trials as f64;
    let p = successes as f64 / n;
    let z2 = Z_95 * Z_95;
    let denom = 1.0 + z2 / n;
    let centre = (p + z2 / (2.0 * n)) / denom;
    let half = Z_95 * (p * (1.0 - p) / n + z2 / (4.0 * n * n)).sqrt() / denom;
    ((centre - half).max(0.0), (centre + half).min(1.0))
}

/// One drawn turntable and its end-to-end rate errors.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TurntableDraw {
    /// $(\Delta\omega_x, \Delta\omega_y)$, rad/s.
    pub delta_omega_rad_per_s: [f64; 2],
    /// $\chi$, rad (order of eq 25).
    pub chi_rad: [f64; CHI_LEN],
}

impl TurntableDraw {
    /// $\max(\Delta\omega_x, \Delta\omega_y)$, rad/s.
    #[must_use]
    pub fn max_rad_per_s(&self) -> f64 {
        self.delta_omega_rad_per_s[0].max(self.delta_omega_rad_per_s[1])
    }

    /// Whether both axes meet $\omega_m$ (rad/s).
    #[must_use]
    pub fn meets(&self, omega_m_rad_per_s: f64) -> bool {
        self.max_rad_per_s() <= omega_m_rad_per_s
    }
}

/// One quantile of the rate errors.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RateQuantile {
    /// Probability $p$.
    pub p: f64,
    /// Empirical $p$-quantiles of $\Delta\omega_x$, $\Delta\omega_y$ and
    /// $\max(\Delta\omega_x, \Delta\omega_y)$ (rad/s): the $\lceil pN\rceil$-th order statistic.
    pub rad_per_s: [f64; 3],
}

/// The distribution of the end-to-end rate errors over turntables drawn from a box.
#[derive(Debug, Clone, PartialEq)]
pub struct RateDistribution {
    /// Turntables drawn.
    pub samples: u64,
    /// Seed of the streams.
    pub seed: u64,
    /// The requirement $\omega_m$ (rad/s).
    pub omega_m_rad_per_s: f64,
    /// Turntables with $\Delta\omega_x \le \omega_m$ and $\Delta\omega_y \le \omega_m$.
    pub meeting: u64,
    /// Largest $\Delta\omega_x$, $\Delta\omega_y$ drawn (rad/s).
    pub max_rad_per_s: [f64; 2],
    /// $\chi$ (rad) of the turntable with the largest $\max(\Delta\omega_x, \Delta\omega_y)$.
    pub worst_chi_rad: [f64; CHI_LEN],
    /// Quantiles at [`REPORTED_QUANTILES`].
    pub quantiles: Vec<RateQuantile>,
    /// Histogram bin edges (rad/s), `bins + 1` values from 0 to at least $\omega_m$ and the
    /// largest value drawn.
    pub histogram_edges_rad_per_s: Vec<f64>,
    /// Counts per bin of $\Delta\omega_x$, $\Delta\omega_y$ and their maximum.
    pub histogram_counts: [Vec<u64>; 3],
}

impl RateDistribution {
    /// The yield: fraction of turntables meeting $\omega_m$ on both axes.
    #[must_use]
    pub fn yield_fraction(&self) -> f64 {
        self.meeting as f64 / self.samples as f64
    }

    /// 95% Wilson interval of the yield.
    #[must_use]
    pub fn yield_interval_95(&self) -> (f64, f64) {
        wilson_interval_95(self.meeting, self.samples)
    }

    /// Largest $\Delta\omega_x$, $\Delta\omega_y$ drawn, deg/h.
    #[must_use]
    pub fn max_deg_per_h(&self) -> [f64; 2] {
        self.max_rad_per_s.map(rad_per_s_to_deg_per_h)
    }
}

impl EndToEnd {
    /// $(\Delta\omega_x, \Delta\omega_y)$ (rad/s) and $\chi$ of every turntable drawn from
    /// `bounds`, in sample order (deterministic for any thread count).
    ///
    /// # Errors
    /// As [`McSettings::validate`].
    pub fn sample_rates(
        &self,
        bounds: &ErrorBox,
        settings: &McSettings,
    ) -> Result<Vec<TurntableDraw>, E2eError> {
        settings.validate()?;
        let sampler = TurntableSampler::new(bounds);
        let cs = u64::from(settings.chunk_size);
        let chunks = settings.samples.div_ceil(cs);
        let per_chunk: Vec<Vec<TurntableDraw>> = (0..chunks)
            .into_par_iter()
            .map(|c| {
                let mut rng = chunk_rng(settings.seed, c);
                let mut remaining = cs.min(settings.samples - c * cs) as usize;
                let mut block = SampleBlock::default();
                let mut out = Vec::with_capacity(remaining);
                while remaining > 0 {
                    let m = remaining.min(BLOCK_CAPACITY);
                    sampler.fill_block(&mut rng, m, &mut block);
                    out.extend((0..m).map(|k| {
                        let chi = block.chi_rad(k);
                        // The sampler's chi is always finite: the fallback is unreachable.
                        TurntableDraw {
                            delta_omega_rad_per_s: self.delta_omega(&chi).unwrap_or([f64::NAN; 2]),
                            chi_rad: chi,
                        }
                    }));
                    remaining -= m;
                }
                out
            })
            .collect();
        Ok(per_chunk.into_iter().flatten().collect())
    }

    /// The distribution of $\Delta\omega_x$, $\Delta\omega_y$ over turntables drawn from
    /// `bounds` and the yield against $\omega_m$ (rad/s).
    ///
    /// # Errors
    /// [`E2eError::NotPositive`] naming `omega_m`; as [`McSettings::validate`].
    pub fn rate_distribution(
        &self,
        bounds: &ErrorBox,
        omega_m_rad_per_s: f64,
        settings: &McSettings,
    ) -> Result<RateDistribution, E2eError> {
        positive("omega_m", omega_m_rad_per_s)?;
        let draws = self.sample_rates(bounds, settings)?;
        Ok(summarise(&draws, omega_m_rad_per_s, settings))
    }
}

/// Index of the empirical $p$-quantile (the $\lceil pN\rceil$-th order statistic, 0-based).
pub(crate) fn quantile_index(p: f64, n: usize) -> usize {
    ((p * n as f64).ceil() as usize).clamp(1, n) - 1
}

fn summarise(draws: &[TurntableDraw], omega_m: f64, settings: &McSettings) -> RateDistribution {
    let n = draws.len();
    let mut cols: [Vec<f64>; 3] = [
        draws.iter().map(|d| d.delta_omega_rad_per_s[0]).collect(),
        draws.iter().map(|d| d.delta_omega_rad_per_s[1]).collect(),
        draws.iter().map(TurntableDraw::max_rad_per_s).collect(),
    ];
    let meeting = draws.iter().filter(|d| d.meets(omega_m)).count() as u64;
    let worst = draws
        .iter()
        .enumerate()
        .fold((0, f64::NEG_INFINITY), |b, (i, d)| {
            let m = d.max_rad_per_s();
            if m > b.1 { (i, m) } else { b }
        })
        .0;
    let hi = cols[2].iter().copied().fold(omega_m, f64::max);
    let bins = settings.histogram_bins;
    let width = hi / bins as f64;
    let edges: Vec<f64> = (0..=bins).map(|b| b as f64 * width).collect();
    let counts = cols.clone().map(|c| {
        let mut h = vec![0_u64; bins];
        for v in c {
            let b = ((v / width) as usize).min(bins - 1);
            h[b] += 1;
        }
        h
    });
    for c in &mut cols {
        c.sort_by(f64::total_cmp);
    }
    let quantiles = REPORTED_QUANTILES
        .iter()
        .map(|&p| {
            let k = quantile_index(p, n);
            RateQuantile {
                p,
                rad_per_s: [cols[0][k], cols[1][k], cols[2][k]],
            }
        })
        .collect();
    RateDistribution {
        samples: n as u64,
        seed: settings.seed,
        omega_m_rad_per_s: omega_m,
        meeting,
        max_rad_per_s: [cols[0][n - 1], cols[1][n - 1]],
        worst_chi_rad: draws[worst].chi_rad,
        quantiles,
        histogram_edges_rad_per_s: edges,
        histogram_counts: counts,
    }
}
