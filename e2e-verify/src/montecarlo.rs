//! Monte Carlo over turntables drawn from a tolerance box: the distribution of the end-to-end
//! calibration errors, the yield $P(\Delta\omega_k \le \omega_{m,k}\ \forall k)$ with a Wilson
//! confidence interval, and exact order statistics, all with memory independent of the number
//! of draws.
//!
//! Draws reuse mc-verify's streams and sampler: chunk $c$ of a run seeded $s$ uses
//! [`mc_verify::chunk_rng`]`(s, c)` and [`mc_verify::TurntableSampler::fill_block`] in blocks of
//! [`mc_verify::BLOCK_CAPACITY`] (uniform magnitudes in $[\mathrm{LB}_i, \mathrm{UB}_i]$, fair
//! signs; the pose it also draws is not used: the calibration positions are the schedule's).
//! With `chunk_size` = [`mc_verify::DEFAULT_CHUNK_SIZE`] the turntables are exactly those of a
//! [`mc_verify::MonteCarlo`] run with the same seed; the default here is smaller
//! ([`DEFAULT_CHUNK_SIZE`]) so that a few ten thousand draws still spread over threads.
//! Chunks run on rayon threads in waves and their partial statistics are merged in chunk
//! order, so results are bit-identical for any thread count.
//!
//! # Streaming statistics
//! Per output: the largest $\Delta\omega_k$ with its turntable, the count meeting the
//! accuracy, a histogram on fixed edges $[0, H_k]$ with $H_k$ = the linearised worst case of
//! the box plus its second-order bound (or twice the linearised worst case when no bound is
//! derived), at least the accuracy, and an overflow count. The same for the largest ratio
//! $r = \max_k \Delta\omega_k/\omega_{m,k}$ (the turntable meets every accuracy when
//! $r \le 1$). Reported quantiles ([`REPORTED_QUANTILES`]) are upper bin edges of fine
//! histograms ([`QUANTILE_BINS`] bins; the exact maximum when the rank falls in the overflow),
//! so they are upper bounds with a stated resolution; [`crate::MonteCarloQuestions::ratio_quantile`] gives the
//! exact order statistic by re-drawing the same turntables and narrowing the bin
//! (at most `QUANTILE_PASSES` passes, then a sort of at most `QUANTILE_COLLECT` values).
//! The largest values and quantiles at or below the computation's precision
//! ([`EndToEnd::precisions`]) are reported as 0; counts and histograms use the values as
//! computed.

use crate::error::{E2eError, positive};
use crate::linear::Linearization;
use crate::simulate::EndToEnd;
use mc_verify::driver::{chunk_len, run_chunks};
use mc_verify::{
    BLOCK_CAPACITY, ErrorBox, Histogram, SampleBlock, TurntableSampler, WorstSample, chunk_rng,
    quantile_rank,
};
use tt_kinematics::ScheduleErrorModel;

/// The workspace's one yield count and its interval (mc-verify's), for this crate's modules.
pub(crate) use mc_verify::{YieldCount, Z_95, wilson_interval_95};

/// Default number of samples per chunk (one random stream each).
pub const DEFAULT_CHUNK_SIZE: u32 = 1024;

/// Default number of histogram bins (the figure's histogram).
pub(crate) const DEFAULT_BINS: usize = 40;

/// Largest number of figure histogram bins.
pub const MAX_BINS: usize = 10_000;

/// Bins of the fine histograms behind the reported quantiles.
pub const QUANTILE_BINS: usize = 4096;

/// Largest number of draws of one distribution: at the measured 10^6 draws per second on two
/// cores, about three hours.
pub const MAX_SAMPLES: u64 = 10_000_000_000;

/// Probabilities at which [`RateDistribution::quantiles`] are reported.
pub const REPORTED_QUANTILES: [f64; 6] = [0.5, 0.9, 0.99, 0.9973, 0.999, 1.0];

/// Passes of the exact order statistic before it falls back to a bin edge.
pub(crate) const QUANTILE_PASSES: usize = 6;

/// Values collected in the last pass of the exact order statistic.
pub(crate) const QUANTILE_COLLECT: usize = 1 << 16;

/// Chunks evaluated per wave (bounds the memory of the partial statistics held at once).
const WAVE_CHUNKS: u64 = 64;

/// How many turntables to draw and from which random streams.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct McSettings {
    /// Number of turntables.
    pub samples: u64,
    /// Seed of the streams.
    pub seed: u64,
    /// Turntables per chunk (stream).
    pub chunk_size: u32,
    /// Histogram bins of the figure histograms.
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
    /// [`E2eError::Field`] (a count) naming `samples` (1 to [`MAX_SAMPLES`]), `chunk_size` or
    /// `histogram_bins` (1 to [`MAX_BINS`]).
    pub fn validate(&self) -> Result<(), E2eError> {
        let check = |field, value: u64, max: u64| tt_core::count(field, value, max);
        check("samples", self.samples, MAX_SAMPLES)?;
        check(
            "chunk_size",
            u64::from(self.chunk_size),
            u64::from(u32::MAX),
        )?;
        check(
            "histogram_bins",
            self.histogram_bins as u64,
            MAX_BINS as u64,
        )?;
        Ok(())
    }
}

/// The turntable attaining a maximum: the Monte Carlos' one worst draw, here with nothing
/// beyond its index, its value (output unit, or the ratio for the ratio's worst draw) and its
/// errors $\chi$ (rad).
pub type WorstDraw = WorstSample<()>;

/// One quantile of the calibration errors.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct RateQuantile {
    /// Probability $p$.
    pub(crate) p: f64,
    /// Upper bounds of the empirical $p$-quantiles of every output's $\Delta\omega_k$ (output
    /// unit), resolution one [`QUANTILE_BINS`]-th of the histogram range.
    pub(crate) per_output: Vec<f64>,
    /// The same for the ratio $\max_k \Delta\omega_k/\omega_{m,k}$.
    pub(crate) ratio: f64,
}

/// Read access to the fields (crate-private, so the type can grow without breaking callers).
impl RateQuantile {
    /// Probability $p$.
    #[must_use]
    pub fn p(&self) -> f64 {
        self.p
    }

    /// Upper bounds of the empirical $p$-quantiles of every output's $\Delta\omega_k$ (output
    /// unit), resolution one [`QUANTILE_BINS`]-th of the histogram range.
    #[must_use]
    pub fn per_output(&self) -> &[f64] {
        &self.per_output
    }

    /// The same for the ratio $\max_k \Delta\omega_k/\omega_{m,k}$.
    #[must_use]
    pub fn ratio(&self) -> f64 {
        self.ratio
    }
}

/// The distribution of the end-to-end calibration errors over turntables drawn from a box.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct RateDistribution {
    /// Turntables drawn and meeting the accuracies, with the seed.
    #[cfg_attr(feature = "serde", serde(flatten))]
    pub(crate) count: YieldCount,
    /// Every output's accuracy (output unit).
    pub(crate) accuracies: Vec<f64>,
    /// Largest $\Delta\omega_k$ drawn per output, with its turntable.
    pub(crate) worst: Vec<WorstDraw>,
    /// Largest ratio $\max_k \Delta\omega_k/\omega_{m,k}$ drawn, with its turntable.
    pub(crate) worst_ratio: WorstDraw,
    /// Quantiles at [`REPORTED_QUANTILES`].
    pub(crate) quantiles: Vec<RateQuantile>,
    /// Figure histograms per output ($\Delta\omega_k$, output unit).
    pub(crate) histograms: Vec<Histogram>,
    /// Figure histogram of the ratio.
    pub(crate) ratio_histogram: Histogram,
    /// Every output's precision ([`EndToEnd::precisions`], output unit): the largest values
    /// and quantiles at or below it are reported as 0 (the ratio's when every output's are).
    pub(crate) precisions: Vec<f64>,
}

/// Read access to the fields (crate-private, so the type can grow without breaking callers).
impl RateDistribution {
    /// Turntables drawn and meeting the accuracies, with the seed.
    #[must_use]
    pub fn count(&self) -> &YieldCount {
        &self.count
    }

    /// Every output's accuracy (output unit).
    #[must_use]
    pub fn accuracies(&self) -> &[f64] {
        &self.accuracies
    }

    /// Largest $\Delta\omega_k$ drawn per output, with its turntable.
    #[must_use]
    pub fn worst(&self) -> &[WorstDraw] {
        &self.worst
    }

    /// Largest ratio $\max_k \Delta\omega_k/\omega_{m,k}$ drawn, with its turntable.
    #[must_use]
    pub fn worst_ratio(&self) -> &WorstDraw {
        &self.worst_ratio
    }

    /// Quantiles at [`REPORTED_QUANTILES`].
    #[must_use]
    pub fn quantiles(&self) -> &[RateQuantile] {
        &self.quantiles
    }

    /// Figure histograms per output ($\Delta\omega_k$, output unit).
    #[must_use]
    pub fn histograms(&self) -> &[Histogram] {
        &self.histograms
    }

    /// Figure histogram of the ratio.
    #[must_use]
    pub fn ratio_histogram(&self) -> &Histogram {
        &self.ratio_histogram
    }

    /// Every output's precision ([`EndToEnd::precisions`], output unit): the largest values
    /// and quantiles at or below it are reported as 0 (the ratio's when every output's are).
    #[must_use]
    pub fn precisions(&self) -> &[f64] {
        &self.precisions
    }
}

impl RateDistribution {
    /// Largest $\Delta\omega_k$ drawn per output (output unit).
    #[must_use]
    pub fn max(&self) -> Vec<f64> {
        self.worst.iter().map(WorstDraw::value).collect()
    }
}

/// Partial statistics of a chunk (merged in chunk order).
#[derive(Debug, Clone)]
struct Partial {
    n: u64,
    meeting: u64,
    meeting_per_output: Vec<u64>,
    worst: Vec<Option<WorstDraw>>,
    worst_ratio: Option<WorstDraw>,
    hist: Vec<Histogram>,
    fine: Vec<Histogram>,
}

impl Partial {
    fn new(ranges: &[f64], bins: usize) -> Self {
        Self {
            n: 0,
            meeting: 0,
            meeting_per_output: vec![0; ranges.len() - 1],
            worst: vec![None; ranges.len() - 1],
            worst_ratio: None,
            hist: ranges
                .iter()
                .map(|&r| Histogram::new(0.0, r, bins))
                .collect(),
            fine: ranges
                .iter()
                .map(|&r| Histogram::new(0.0, r, QUANTILE_BINS))
                .collect(),
        }
    }

    fn merge(&mut self, o: Partial) {
        self.n += o.n;
        self.meeting += o.meeting;
        for (a, b) in self
            .meeting_per_output
            .iter_mut()
            .zip(&o.meeting_per_output)
        {
            *a += b;
        }
        let better = |mine: &mut Option<WorstDraw>, theirs: Option<WorstDraw>| {
            if let Some(t) = theirs {
                if mine.as_ref().is_none_or(|m| t.value() > m.value()) {
                    *mine = Some(t);
                }
            }
        };
        for (a, b) in self.worst.iter_mut().zip(o.worst) {
            better(a, b);
        }
        better(&mut self.worst_ratio, o.worst_ratio);
        for (a, b) in self.hist.iter_mut().zip(&o.hist) {
            a.merge(b);
        }
        for (a, b) in self.fine.iter_mut().zip(&o.fine) {
            a.merge(b);
        }
    }
}

impl<S: ScheduleErrorModel + Sync> EndToEnd<S> {
    /// Draw the turntables of chunk `c` (chunks of `chunk_size`, `samples` in all; the
    /// chunk's table stream [`chunk_rng`]`(seed, c)`) from `sampler`, compute each one's error
    /// vectors (one per output, one entry per position) and give them to
    /// `each(sample index, vectors)`: the per-chunk draw set-up of the Monte Carlos that add
    /// noise to the table's part (combined yield, time-domain simulation).
    ///
    /// # Errors
    /// [`E2eError::Draw`] naming the first turntable whose calibration fails; what `each`
    /// returns.
    pub(crate) fn for_each_draw(
        &self,
        sampler: &TurntableSampler,
        (seed, samples, chunk_size): (u64, u64, u64),
        c: u64,
        mut each: impl FnMut(u64, &mut [Vec<f64>]) -> Result<(), E2eError>,
    ) -> Result<(), E2eError> {
        let mut rng = chunk_rng(seed, c);
        let mut remaining = chunk_len(samples, chunk_size, c);
        let mut block = SampleBlock::new(sampler);
        let mut work = self.work();
        let mut chi = vec![0.0; self.n_errors()];
        let mut vectors = vec![vec![0.0; self.len()]; self.n_outputs()];
        let mut index = c * chunk_size;
        while remaining > 0 {
            let m = remaining.min(BLOCK_CAPACITY);
            sampler.fill_block(&mut rng, m, &mut block);
            for s in 0..m {
                block.chi_rad_into(s, &mut chi);
                self.error_vectors_into(&chi, &mut work, &mut vectors)
                    .map_err(|e| E2eError::Draw {
                        sample: index,
                        reason: e.to_string(),
                    })?;
                each(index, &mut vectors)?;
                index += 1;
            }
            remaining -= m;
        }
        Ok(())
    }

    /// Draw every turntable of `settings` from `bounds` and give each draw to `visit` (the
    /// chunk's part, its scratch space made by `scratch`, index, $\chi$, $\Delta\omega_k$ per
    /// output), folding chunk results with `merge` in chunk order: the one Monte Carlo driver
    /// of the crate (memory independent of the count). The first error of a visitor, in chunk
    /// order, is returned; a scratch space serves visitors that evaluate more of the draw than
    /// $\Delta\omega_k$ (the specified yield's coefficient errors).
    pub(crate) fn drive_with<P, W, Wn, N, V, M>(
        &self,
        bounds: &ErrorBox,
        settings: &McSettings,
        scratch: Wn,
        new: N,
        visit: V,
        merge: M,
    ) -> Result<P, E2eError>
    where
        P: Send,
        Wn: Fn() -> W + Sync,
        N: Fn() -> P + Sync,
        V: Fn(&mut P, &mut W, u64, &[f64], &[f64]) -> Result<(), E2eError> + Sync,
        M: Fn(&mut P, P),
    {
        settings.validate()?;
        let sampler = TurntableSampler::for_joint_ranges(bounds, &self.model().joint_ranges_rad());
        let cs = u64::from(settings.chunk_size);
        let chunks = settings.samples.div_ceil(cs);
        let mut acc = new();
        let chunk = |c: u64| -> Result<P, E2eError> {
            let mut part = new();
            let mut own = scratch();
            let mut rng = chunk_rng(settings.seed, c);
            let mut remaining = chunk_len(settings.samples, cs, c);
            let mut block = SampleBlock::new(&sampler);
            let mut work = self.work();
            let mut chi = vec![0.0; self.n_errors()];
            let mut index = c * cs;
            while remaining > 0 {
                let m = remaining.min(BLOCK_CAPACITY);
                sampler.fill_block(&mut rng, m, &mut block);
                for k in 0..m {
                    block.chi_rad_into(k, &mut chi);
                    self.delta_omega_into(&chi, &mut work)
                        .map_err(|e| E2eError::Draw {
                            sample: index,
                            reason: e.to_string(),
                        })?;
                    if let Some((o, v)) = work
                        .delta_omega
                        .iter()
                        .enumerate()
                        .find(|(_, v)| !v.is_finite())
                    {
                        return Err(E2eError::Draw {
                            sample: index,
                            reason: format!("non-finite calibration error {v} on output {o}"),
                        });
                    }
                    visit(&mut part, &mut own, index, &chi, &work.delta_omega)?;
                    index += 1;
                }
                remaining -= m;
            }
            Ok(part)
        };
        run_chunks(chunks, WAVE_CHUNKS, chunk, |p| {
            merge(&mut acc, p);
            Ok(())
        })?;
        Ok(acc)
    }

    /// Histogram ranges $H_k$ per output and for the ratio (last): see the [module](self).
    pub(crate) fn histogram_ranges(
        &self,
        linear: &Linearization,
        bounds: &ErrorBox,
    ) -> Result<Vec<f64>, E2eError> {
        let ub = bounds.ub_rad();
        let rows = linear.row_worst_cases(ub);
        let n = self.len();
        let s: f64 = ub.iter().sum();
        let acc = self.accuracies();
        let mut ranges = Vec::with_capacity(acc.len() + 1);
        let mut ratio: f64 = 1.0;
        for (k, a) in acc.iter().enumerate() {
            let lin = rows.rows(k * n, n).max();
            let h = match self.second_order_bound(k, s)? {
                Some(t) => lin + t,
                None => 2.0 * lin,
            };
            let h = h.max(*a) * (1.0 + 1e-9);
            ratio = ratio.max(h / a);
            ranges.push(h);
        }
        ranges.push(ratio);
        Ok(ranges)
    }
}

impl<S: ScheduleErrorModel + Sync> crate::MonteCarloQuestions<'_, S> {
    /// The distribution of every output's $\Delta\omega_k$ over turntables drawn from `bounds`
    /// and the yield against the outputs' accuracies (see the [module](self)).
    ///
    /// # Errors
    /// As [`McSettings::validate`]; [`E2eError::Draw`] naming the first turntable whose
    /// calibration fails (never dropped).
    pub fn rate_distribution(
        &self,
        linear: &Linearization,
        bounds: &ErrorBox,
        settings: &McSettings,
    ) -> Result<RateDistribution, E2eError> {
        let ranges = self.histogram_ranges(linear, bounds)?;
        let acc = self.accuracies();
        let outputs = acc.len();
        let p = self.drive_with(
            bounds,
            settings,
            || (),
            || Partial::new(&ranges, settings.histogram_bins),
            |part, _, index, chi, dw| {
                part.n += 1;
                let mut ratio: f64 = 0.0;
                for k in 0..outputs {
                    let v = dw[k];
                    if v <= acc[k] {
                        part.meeting_per_output[k] += 1;
                    }
                    ratio = ratio.max(v / acc[k]);
                    if part.worst[k].as_ref().is_none_or(|w| v > w.value()) {
                        part.worst[k] = Some(WorstDraw::new(index, v, chi.to_vec(), ()));
                    }
                    part.hist[k].add(v);
                    part.fine[k].add(v);
                }
                if ratio <= 1.0 {
                    part.meeting += 1;
                }
                if part.worst_ratio.as_ref().is_none_or(|w| ratio > w.value()) {
                    part.worst_ratio = Some(WorstDraw::new(index, ratio, chi.to_vec(), ()));
                }
                part.hist[outputs].add(ratio);
                part.fine[outputs].add(ratio);
                Ok(())
            },
            Partial::merge,
        )?;
        let precisions = self.precisions().to_vec();
        // a ratio at or below every output's precision (over its accuracy) is rounding
        let ratio_precision = precisions
            .iter()
            .zip(&acc)
            .map(|(p, a)| p / a)
            .fold(f64::INFINITY, f64::min);
        let worst: Vec<WorstDraw> = p
            .worst
            .into_iter()
            .zip(&precisions)
            .map(|(w, &e)| {
                let w = w.unwrap_or_else(|| unreachable!("at least one draw"));
                WorstDraw::new(
                    w.index(),
                    crate::resolved(w.value(), e),
                    w.chi_rad().to_vec(),
                    (),
                )
            })
            .collect();
        let worst_ratio = p
            .worst_ratio
            .map(|w| {
                let value = crate::resolved(w.value(), ratio_precision);
                WorstDraw::new(w.index(), value, w.chi_rad().to_vec(), ())
            })
            .unwrap_or_else(|| unreachable!("at least one draw"));
        let quantiles = REPORTED_QUANTILES
            .iter()
            .map(|&q| RateQuantile {
                p: q,
                per_output: (0..outputs)
                    .map(|k| {
                        crate::resolved(
                            p.fine[k].quantile_upper(q, worst[k].value()),
                            precisions[k],
                        )
                    })
                    .collect(),
                ratio: crate::resolved(
                    p.fine[outputs].quantile_upper(q, worst_ratio.value()),
                    ratio_precision,
                ),
            })
            .collect();
        let mut histograms = p.hist;
        let ratio_histogram = histograms
            .pop()
            .unwrap_or_else(|| unreachable!("ratio histogram"));
        Ok(RateDistribution {
            count: YieldCount::new(p.n, settings.seed, p.meeting, p.meeting_per_output),
            accuracies: acc,
            worst,
            worst_ratio,
            quantiles,
            histograms,
            ratio_histogram,
            precisions,
        })
    }

    /// The errors $\chi$ of the turntables of `settings` drawn from `bounds`, in draw order (for
    /// small counts: the result holds every draw).
    ///
    /// # Errors
    /// As [`McSettings::validate`]; [`E2eError::Field`] (a count) above 10^6 draws.
    pub fn sample_chi(
        &self,
        bounds: &ErrorBox,
        settings: &McSettings,
    ) -> Result<Vec<Vec<f64>>, E2eError> {
        const MAX: u64 = 1_000_000;
        tt_core::count("samples", settings.samples, MAX)?;
        self.drive_with(
            bounds,
            settings,
            || (),
            Vec::new,
            |v, _, _, chi, _| {
                v.push(chi.to_vec());
                Ok(())
            },
            |a, mut b| a.append(&mut b),
        )
    }

    /// The number of turntables drawn from `bounds` that meet every accuracy.
    ///
    /// # Errors
    /// As [`crate::MonteCarloQuestions::rate_distribution`].
    pub fn meeting_count(&self, bounds: &ErrorBox, settings: &McSettings) -> Result<u64, E2eError> {
        let acc = self.accuracies();
        self.drive_with(
            bounds,
            settings,
            || (),
            || 0u64,
            |count, _, _, _, dw| {
                if dw.iter().zip(&acc).all(|(v, a)| v <= a) {
                    *count += 1;
                }
                Ok(())
            },
            |a, b| *a += b,
        )
    }

    /// The exact empirical $p$-quantile (the $\lceil pN\rceil$-th order statistic) of the ratio
    /// $r = \max_k \Delta\omega_k/\omega_{m,k}$ over the draws of `settings`, with memory
    /// independent of $N$: the same turntables are drawn again while the bin holding the rank
    /// narrows (see the [module](self)).
    ///
    /// # Errors
    /// [`E2eError::Field`] (out of range) unless $0 < p \le 1$ (`quantile`); as
    /// [`crate::MonteCarloQuestions::rate_distribution`].
    pub fn ratio_quantile(
        &self,
        bounds: &ErrorBox,
        settings: &McSettings,
        p: f64,
    ) -> Result<f64, E2eError> {
        let acc = self.accuracies();
        self.ratio_quantile_by(
            bounds,
            settings,
            p,
            || (),
            |_, _, _, dw| Ok(dw.iter().zip(&acc).fold(0.0_f64, |m, (v, a)| m.max(v / a))),
        )
    }

    /// [`crate::MonteCarloQuestions::ratio_quantile`] of the ratio `ratio(scratch, index, chi, dw)` of
    /// each draw (a scratch space per chunk made by `scratch`; the first error in chunk order
    /// is returned).
    pub(crate) fn ratio_quantile_by<W, Wn, R>(
        &self,
        bounds: &ErrorBox,
        settings: &McSettings,
        p: f64,
        scratch: Wn,
        ratio: R,
    ) -> Result<f64, E2eError>
    where
        Wn: Fn() -> W + Sync,
        R: Fn(&mut W, u64, &[f64], &[f64]) -> Result<f64, E2eError> + Sync,
    {
        tt_core::in_range(
            "quantile",
            p,
            std::ops::Bound::Excluded(0.0),
            std::ops::Bound::Included(1.0),
            "",
        )?;
        settings.validate()?;
        let rank = quantile_rank(p, settings.samples);
        // (count below lo, histogram of [lo, hi), count >= hi, max)
        type Pass = (u64, Vec<u64>, u64, f64);
        let (mut lo, mut hi) = (0.0_f64, f64::INFINITY);
        for _ in 0..QUANTILE_PASSES {
            let width = if hi.is_finite() {
                hi - lo
            } else {
                f64::INFINITY
            };
            let bins = QUANTILE_BINS;
            let scan: Pass = self.drive_with(
                bounds,
                settings,
                &scratch,
                || (0, vec![0; bins], 0, 0.0),
                |(below, h, above, max), w, index, chi, dw| {
                    let r = ratio(w, index, chi, dw)?;
                    *max = f64::max(*max, r);
                    if r < lo {
                        *below += 1;
                    } else if r >= hi || !width.is_finite() {
                        *above += 1;
                    } else {
                        let b = (((r - lo) / width) * bins as f64) as usize;
                        h[b.min(bins - 1)] += 1;
                    }
                    Ok(())
                },
                |a, b| {
                    a.0 += b.0;
                    for (x, y) in a.1.iter_mut().zip(&b.1) {
                        *x += y;
                    }
                    a.2 += b.2;
                    a.3 = a.3.max(b.3);
                },
            )?;
            let (below, h, _, max) = scan;
            if !width.is_finite() {
                // first pass: only the maximum is known; bin [0, max] next
                hi = max * (1.0 + 1e-12) + f64::MIN_POSITIVE;
                continue;
            }
            let mut seen = below;
            let mut chosen = None;
            for (b, c) in h.iter().enumerate() {
                if seen + c >= rank {
                    chosen = Some((b, seen, *c));
                    break;
                }
                seen += c;
            }
            let Some((b, before, count)) = chosen else {
                return Ok(max);
            };
            let (blo, bhi) = (
                lo + width * b as f64 / bins as f64,
                lo + width * (b + 1) as f64 / bins as f64,
            );
            if count as usize <= QUANTILE_COLLECT {
                let mut values = self.drive_with(
                    bounds,
                    settings,
                    &scratch,
                    Vec::new,
                    |v, w, index, chi, dw| {
                        let r = ratio(w, index, chi, dw)?;
                        if r >= blo && r < bhi {
                            v.push(r);
                        }
                        Ok(())
                    },
                    |a, mut b| a.append(&mut b),
                )?;
                values.sort_by(f64::total_cmp);
                let i = (rank - before - 1) as usize;
                let found = values.len() as f64;
                return values.get(i).copied().ok_or(E2eError::NoConvergence {
                    what: "exact quantile (re-drawn values in the bin)",
                    iterations: QUANTILE_PASSES,
                    change: found,
                });
            }
            lo = blo;
            hi = bhi;
        }
        Ok(hi)
    }
}

impl<S: ScheduleErrorModel + Sync> EndToEnd<S> {
    /// Check a positive accuracy scale (internal helper for callers of the yield allocation).
    pub(crate) fn check_positive(field: &str, v: f64) -> Result<f64, E2eError> {
        Ok(positive(field, v)?)
    }
}
