//! Streaming statistics of a run: extremes with their samples, moments, histograms, yield.
//!
//! Every statistic is merged from per-block and per-chunk partial results in a fixed order
//! (block order within a chunk, chunk order within the run), so the result is bit-identical
//! whatever the number of threads. Moments use the pairwise update of Chan, Golub and
//! LeVeque (1979): for parts $a, b$ with counts $n$, means $m$ and sums of squared
//! deviations $M_2$, with $\delta = m_b - m_a$ and $n = n_a + n_b$,
//! $$m = m_a + \delta\,\frac{n_b}{n}, \qquad M_2 = M_{2,a} + M_{2,b} + \delta^2\,\frac{n_a n_b}{n},$$
//! which is numerically stable (no cancellation between large sums of squares); each block's
//! $m, M_2$ come from one pass over the deviations $d = v - c$ from a shift $c$ near the mean
//! (the running mean, or the first value of the run), $m = c + \sum d / n$,
//! $M_2 = \sum d^2 - (\sum d)^2 / n$: with $|m - c|$ of the order of the block's spread the
//! cancellation costs under one bit.

use crate::sampler::{BLOCK_CAPACITY, SampleBlock, TurntableSampler};
use tt_kinematics::{OrientationAxis, Pose};

/// The draw that attains a maximum: its global index, its value, its errors $\chi$ and what
/// else its run keeps of it (`E`): the one worst-draw type of the workspace's Monte Carlos,
/// the largest $|\Delta|$ of one axis here (`E` its [`Pose`]; value in rad), and end to end
/// each output's largest calibration error and the largest ratio to its accuracy (`E = ()`;
/// value in the output unit, or the ratio).
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct WorstSample<E = Pose> {
    /// Global index of the draw in the run (see [`crate::chunk_rng`]).
    pub(crate) index: u64,
    /// Its value: the signed orientation error at that sample (rad) here; the run's unit
    /// elsewhere.
    pub(crate) value: f64,
    /// Its angular errors $\chi$, rad, order of $\chi$ (eq 25 for the paper's table).
    pub(crate) chi_rad: Vec<f64>,
    /// What else the run keeps of the draw: here its pose (every joint, including those that
    /// cancel); nothing (`()`, not serialised) end to end.
    #[cfg_attr(feature = "serde", serde(skip_serializing_if = "zero_sized"))]
    pub(crate) extra: E,
}

/// Whether a value carries no data (`()`): its field is then left out of the serialised form.
#[cfg(feature = "serde")]
fn zero_sized<E>(_: &E) -> bool {
    std::mem::size_of::<E>() == 0
}

/// Read access to the fields (crate-private, so the type can grow without breaking callers).
impl<E> WorstSample<E> {
    /// Global index of the draw in the run (see [`crate::chunk_rng`]).
    #[must_use]
    pub fn index(&self) -> u64 {
        self.index
    }

    /// Its value: the signed orientation error at that sample (rad) here; the run's unit
    /// elsewhere.
    #[must_use]
    pub fn value(&self) -> f64 {
        self.value
    }

    /// Its angular errors $\chi$, rad, order of $\chi$ (eq 25 for the paper's table).
    #[must_use]
    pub fn chi_rad(&self) -> &[f64] {
        &self.chi_rad
    }

    /// What else the run keeps of the draw: here its pose (every joint, including those that
    /// cancel); nothing (`()`, not serialised) end to end.
    #[must_use]
    pub fn extra(&self) -> &E {
        &self.extra
    }
}

impl<E> WorstSample<E> {
    /// The draw `index` of a run with its `value`, errors $\chi$ (rad) and `extra` data: for
    /// the Monte Carlos of other crates (end to end: `E = ()`).
    #[must_use]
    pub fn new(index: u64, value: f64, chi_rad: Vec<f64>, extra: E) -> Self {
        Self {
            index,
            value,
            chi_rad,
            extra,
        }
    }
}

impl WorstSample<Pose> {
    /// The pose of the draw (every joint, including those that cancel).
    #[must_use]
    pub fn pose(&self) -> &Pose {
        &self.extra
    }
}

/// A histogram with fixed, uniform bins on $[\ell, h)$ plus under- and overflow counts: the
/// one histogram of the workspace's Monte Carlos (the orientation errors here, on
/// $[-H, H)$ in rad; the calibration errors end to end, on $[0, H)$ in the output unit).
///
/// The edges are fixed before the run (from the bounds; see
/// [`crate::MonteCarlo::histogram_half_range_rad`]), so merging partial histograms is exact.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct Histogram {
    /// $\ell$, the lower end of the binned range (the values' unit: rad for the orientation
    /// Monte Carlo).
    pub(crate) lo: f64,
    /// $h$, the upper end of the binned range (the values' unit).
    pub(crate) hi: f64,
    /// Counts per bin; bin $j$ covers $[\ell + j w, \ell + (j+1) w)$ with
    /// $w = (h - \ell) / \text{bins}$.
    pub(crate) counts: Vec<u64>,
    /// Values below $\ell$ (and NaN).
    pub(crate) underflow: u64,
    /// Values at or above $h$.
    pub(crate) overflow: u64,
}

/// Read access to the fields (crate-private, so the type can grow without breaking callers).
impl Histogram {
    /// $\ell$, the lower end of the binned range (the values' unit: rad for the orientation
    /// Monte Carlo).
    #[must_use]
    pub fn lo(&self) -> f64 {
        self.lo
    }

    /// $h$, the upper end of the binned range (the values' unit).
    #[must_use]
    pub fn hi(&self) -> f64 {
        self.hi
    }

    /// Counts per bin; bin $j$ covers $[\ell + j w, \ell + (j+1) w)$ with
    /// $w = (h - \ell) / \text{bins}$.
    #[must_use]
    pub fn counts(&self) -> &[u64] {
        &self.counts
    }

    /// Values below $\ell$ (and NaN).
    #[must_use]
    pub fn underflow(&self) -> u64 {
        self.underflow
    }

    /// Values at or above $h$.
    #[must_use]
    pub fn overflow(&self) -> u64 {
        self.overflow
    }
}

impl Histogram {
    /// An empty histogram of `bins` uniform bins on $[\ell, h)$ (`bins` at least 1,
    /// $\ell < h$, both finite: the Monte Carlos check their configuration before).
    #[must_use]
    pub fn new(lo: f64, hi: f64, bins: usize) -> Self {
        Self {
            lo,
            hi,
            counts: vec![0; bins],
            underflow: 0,
            overflow: 0,
        }
    }

    /// Count one value.
    #[inline]
    pub fn add(&mut self, v: f64) {
        // NaN is counted below the range
        if v.is_nan() || v < self.lo {
            self.underflow += 1;
            return;
        }
        let b = ((v - self.lo) / (self.hi - self.lo) * self.counts.len() as f64) as usize;
        match self.counts.get_mut(b) {
            Some(c) => *c += 1,
            None => self.overflow += 1,
        }
    }

    /// Add another histogram's counts (the same edges).
    pub fn merge(&mut self, o: &Self) {
        debug_assert!(
            self.counts.len() == o.counts.len()
                && self.lo.to_bits() == o.lo.to_bits()
                && self.hi.to_bits() == o.hi.to_bits(),
            "merging histograms with different edges"
        );
        for (a, b) in self.counts.iter_mut().zip(&o.counts) {
            *a += b;
        }
        self.underflow += o.underflow;
        self.overflow += o.overflow;
    }

    /// Bin width $w$ (the values' unit).
    #[must_use]
    pub fn bin_width(&self) -> f64 {
        (self.hi - self.lo) / self.counts.len() as f64
    }

    /// The `bins + 1` bin edges, $\ell$ to $h$.
    #[must_use]
    pub fn edges(&self) -> Vec<f64> {
        let n = self.counts.len();
        (0..=n)
            .map(|j| self.lo + (self.hi - self.lo) * j as f64 / n as f64)
            .collect()
    }

    /// The bin centres.
    #[must_use]
    pub fn centres(&self) -> Vec<f64> {
        let n = self.counts.len();
        (0..n)
            .map(|j| self.lo + (self.hi - self.lo) * (j as f64 + 0.5) / n as f64)
            .collect()
    }

    /// Total count including under- and overflow.
    #[must_use]
    pub fn total(&self) -> u64 {
        self.counts.iter().sum::<u64>() + self.underflow + self.overflow
    }

    /// An upper bound of the empirical $p$-quantile of the values counted (the
    /// $\lceil pN\rceil$-th order statistic, $N$ = [`Histogram::total`]): the upper edge of its
    /// bin, at most `max` (the largest value counted, known to the caller); `max` when it
    /// falls in the overflow. $\ell$ when it falls in the underflow.
    #[must_use]
    pub fn quantile_upper(&self, p: f64, max: f64) -> f64 {
        let n = self.total();
        if n == 0 {
            return max;
        }
        let k = quantile_rank(p, n);
        let mut seen = self.underflow;
        if seen >= k {
            return self.lo;
        }
        let w = self.bin_width();
        for (b, c) in self.counts.iter().enumerate() {
            seen += c;
            if seen >= k {
                return (self.lo + (b + 1) as f64 * w).min(max.max(self.lo));
            }
        }
        max
    }
}

/// Index (1-based) of the empirical $p$-quantile among $n \ge 1$ values: the
/// $\lceil pn\rceil$-th order statistic, clamped to $[1, n]$.
#[must_use]
pub fn quantile_rank(p: f64, n: u64) -> u64 {
    ((p * n as f64).ceil() as u64).clamp(1, n)
}

/// Results for one orientation angle ($\Delta\psi$, $\Delta\theta$ or $\Delta\gamma$).
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct AxisSummary {
    /// Which angle.
    pub(crate) axis: OrientationAxis,
    /// $\max |\Delta|$ over the run, rad.
    pub(crate) max_abs_rad: f64,
    /// The first sample (lowest index) attaining it.
    pub(crate) worst: WorstSample,
    /// Sample mean, rad.
    pub(crate) mean_rad: f64,
    /// Sum of squared deviations from the mean, rad² ($M_2$; variance $= M_2/(n-1)$).
    pub(crate) m2_rad2: f64,
    /// The histogram (the data of one panel of Figure 9).
    pub(crate) histogram: Histogram,
}

/// Read access to the fields (crate-private, so the type can grow without breaking callers).
impl AxisSummary {
    /// Which angle.
    #[must_use]
    pub fn axis(&self) -> OrientationAxis {
        self.axis
    }

    /// $\max |\Delta|$ over the run, rad.
    #[must_use]
    pub fn max_abs_rad(&self) -> f64 {
        self.max_abs_rad
    }

    /// The first sample (lowest index) attaining it.
    #[must_use]
    pub fn worst(&self) -> &WorstSample {
        &self.worst
    }

    /// Sample mean, rad.
    #[must_use]
    pub fn mean_rad(&self) -> f64 {
        self.mean_rad
    }

    /// Sum of squared deviations from the mean, rad² ($M_2$; variance $= M_2/(n-1)$).
    #[must_use]
    pub fn m2_rad2(&self) -> f64 {
        self.m2_rad2
    }

    /// The histogram (the data of one panel of Figure 9).
    #[must_use]
    pub fn histogram(&self) -> &Histogram {
        &self.histogram
    }
}

impl AxisSummary {
    /// Unbiased sample variance $M_2/(n-1)$ (zero for one sample), rad².
    #[must_use]
    pub fn variance_rad2(&self, samples: u64) -> f64 {
        if samples > 1 {
            self.m2_rad2 / (samples - 1) as f64
        } else {
            0.0
        }
    }
}

/// Partial statistics of a block or chunk (the merge unit).
#[derive(Debug, Clone)]
pub(crate) struct Partial {
    pub n: u64,
    pub mean: [f64; 3],
    pub m2: [f64; 3],
    pub max_abs: [f64; 3],
    pub worst: [Option<WorstSample>; 3],
    pub within: [u64; 3],
    pub within_all: u64,
    pub half_range_rad: [f64; 3],
    /// Per axis `bins + 2` counts: underflow, the bins, overflow.
    pub hist: [Vec<u64>; 3],
    /// The first non-finite value met, if any: (sample, axis, value).
    pub non_finite: Option<(u64, OrientationAxis, f64)>,
}

/// $2^{52}$: adding it to $t \in [0, 2^{51})$ leaves $\operatorname{round}(t)$ in the low mantissa bits.
const TWO_POW_52: f64 = 4_503_599_627_370_496.0;

/// Lanes of the order-fixed partial sums (independent accumulators break the add latency
/// chain and let the compiler vectorise, while the summation order stays fixed).
const LANES: usize = 4;

/// $(\max_k |v_k|)$ with a fixed lane order.
#[inline(always)]
fn max_abs(v: &[f64]) -> f64 {
    let mut m = [f64::NEG_INFINITY; LANES];
    let mut chunks = v.chunks_exact(LANES);
    for c in &mut chunks {
        for j in 0..LANES {
            let a = c[j].abs();
            m[j] = if a > m[j] { a } else { m[j] };
        }
    }
    for (j, x) in chunks.remainder().iter().enumerate() {
        let a = x.abs();
        m[j] = if a > m[j] { a } else { m[j] };
    }
    m.into_iter()
        .fold(f64::NEG_INFINITY, |a, b| if b > a { b } else { a })
}

/// $(\sum_k d_k, \sum_k d_k^2)$ with $d_k = v_k - c$, in [`LANES`] accumulators combined
/// pairwise: a fixed order.
#[inline(always)]
fn lane_sums_shifted(v: &[f64], c: f64) -> (f64, f64) {
    let mut s1 = [0.0; LANES];
    let mut s2 = [0.0; LANES];
    let mut chunks = v.chunks_exact(LANES);
    for q in &mut chunks {
        for j in 0..LANES {
            let d = q[j] - c;
            s1[j] += d;
            s2[j] += d * d;
        }
    }
    for (j, &x) in chunks.remainder().iter().enumerate() {
        let d = x - c;
        s1[j] += d;
        s2[j] += d * d;
    }
    (
        (s1[0] + s1[1]) + (s1[2] + s1[3]),
        (s2[0] + s2[1]) + (s2[2] + s2[3]),
    )
}

impl Partial {
    pub(crate) fn new(half_range_rad: &[f64; 3], bins: usize) -> Self {
        Self {
            n: 0,
            mean: [0.0; 3],
            m2: [0.0; 3],
            max_abs: [f64::NEG_INFINITY; 3],
            worst: [None, None, None],
            within: [0; 3],
            within_all: 0,
            half_range_rad: *half_range_rad,
            hist: std::array::from_fn(|_| vec![0; bins + 2]),
            non_finite: None,
        }
    }

    /// Fold one block of values in (after everything folded so far). `out[k][..len]` are the
    /// values of axis `k` for the samples of `block`, whose first has global index `first`;
    /// `requirement_rad[k]` is the requirement of axis `k` (`+inf` for none: every finite
    /// value is within). A non-finite value is recorded in `non_finite` (the first one).
    #[inline(always)]
    pub(crate) fn add_block(
        &mut self,
        first: u64,
        block: &SampleBlock,
        sampler: &TurntableSampler,
        out: &[[f64; BLOCK_CAPACITY]; 3],
        requirement_rad: &[f64; 3],
    ) {
        let n = block.len();
        let nb = n as u64;
        let mut inside_all = [1u64; BLOCK_CAPACITY];
        let mut idx = [[0u64; BLOCK_CAPACITY]; 3];
        for k in 0..3 {
            let v = &out[k][..n];
            // extremes: the block maximum, then its first position only if it is a new record
            let m = max_abs(v);
            if m > self.max_abs[k] {
                self.max_abs[k] = m;
                if let Some(j) = v.iter().position(|x| x.abs().to_bits() == m.to_bits()) {
                    self.worst[k] = Some(WorstSample {
                        index: first + j as u64,
                        value: v[j],
                        // from the words: valid whether or not the block was decoded
                        chi_rad: (0..sampler.n_rotation_errors())
                            .map(|i| sampler.chi_from_word(i, block.word(i, j)))
                            .collect(),
                        extra: block.pose(j),
                    });
                }
            }
            // moments: one pass over the deviations d = x - c from a shift c close to the
            // mean (the running mean; the block's first value for the first block), then
            // Chan's merge; mean_b = c + sum(d)/n, M2_b = sum(d^2) - sum(d)^2/n
            let c = if self.n == 0 { v[0] } else { self.mean[k] };
            let (sd, sq) = lane_sums_shifted(v, c);
            // a NaN or an infinity anywhere makes a sum non-finite: one check per block
            if !(sd.is_finite() && sq.is_finite()) && self.non_finite.is_none() {
                if let Some(j) = v.iter().position(|x| !x.is_finite()) {
                    self.non_finite = Some((first + j as u64, OrientationAxis::ALL[k], v[j]));
                }
            }
            let mean_d = sd / n as f64;
            let m2_b = (sq - sd * mean_d).max(0.0);
            (self.mean[k], self.m2[k]) =
                merge_moments(self.n, self.mean[k], self.m2[k], nb, c + mean_d, m2_b);
            // requirement
            let req = requirement_rad[k];
            let mut within = 0u64;
            for (x, ok) in v.iter().zip(inside_all.iter_mut()) {
                let inside = u64::from(x.abs() <= req);
                within += inside;
                *ok &= inside;
            }
            self.within[k] += within;
            // histogram: slot 0 underflow, 1..=bins the bins, bins + 1 overflow
            // slot = floor((x + H) / w) + 1 clamped to 0..=bins+1, computed as round(t) with
            // t = (x + H) / w + 1/2 by the 2^52 trick (vectorisable, unlike a saturating cast).
            // A value exactly on a bin edge may go to either neighbour (deterministically).
            let bins = (self.hist[k].len() - 2) as f64;
            let half = self.half_range_rad[k];
            let inv_width = bins / (2.0 * half);
            let top = bins + 1.0;
            for (x, i) in v.iter().zip(idx[k].iter_mut()) {
                // compare-and-select, not `f64::max`/`min` (whose NaN rule costs instructions;
                // the values are finite)
                let t = (x + half) * inv_width + 0.5;
                let t = if t > 0.0 { t } else { 0.0 };
                let t = if t < top { t } else { top };
                *i = (t + TWO_POW_52).to_bits() - TWO_POW_52.to_bits();
            }
        }
        // one loop over the three histograms: three independent increment chains
        let [h0, h1, h2] = &mut self.hist;
        for k in 0..n {
            h0[idx[0][k] as usize] += 1;
            h1[idx[1][k] as usize] += 1;
            h2[idx[2][k] as usize] += 1;
        }
        self.within_all += inside_all[..n].iter().sum::<u64>();
        self.n += nb;
    }

    /// Fold a later partial in (`other` covers samples after all of `self`'s).
    pub(crate) fn merge(&mut self, other: &Partial) {
        for k in 0..3 {
            if other.max_abs[k] > self.max_abs[k] {
                self.max_abs[k] = other.max_abs[k];
                self.worst[k].clone_from(&other.worst[k]);
            }
            (self.mean[k], self.m2[k]) = merge_moments(
                self.n,
                self.mean[k],
                self.m2[k],
                other.n,
                other.mean[k],
                other.m2[k],
            );
            self.within[k] += other.within[k];
            for (a, b) in self.hist[k].iter_mut().zip(&other.hist[k]) {
                *a += b;
            }
        }
        self.within_all += other.within_all;
        self.n += other.n;
        if self.non_finite.is_none() {
            self.non_finite = other.non_finite;
        }
    }

    /// The public histogram of axis `k`.
    pub(crate) fn histogram(&self, k: usize) -> Histogram {
        let h = &self.hist[k];
        let bins = h.len() - 2;
        Histogram {
            lo: -self.half_range_rad[k],
            hi: self.half_range_rad[k],
            counts: h[1..=bins].to_vec(),
            underflow: h[0],
            overflow: h[bins + 1],
        }
    }
}
/// Chan-Golub-LeVeque merge of (count, mean, M2) pairs.
#[inline]
fn merge_moments(na: u64, ma: f64, m2a: f64, nb: u64, mb: f64, m2b: f64) -> (f64, f64) {
    if na == 0 {
        return (mb, m2b);
    }
    if nb == 0 {
        return (ma, m2a);
    }
    let n = (na + nb) as f64;
    let (na, nb) = (na as f64, nb as f64);
    let delta = mb - ma;
    (
        ma + delta * (nb / n),
        m2a + m2b + delta * delta * (na * nb / n),
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bounds::ErrorBox;
    use crate::sampler::chunk_rng;

    /// Relative agreement of the streamed mean and M2 with a two-pass reference. The block
    /// means carry absolute rounding errors of about eps * |offset|; Chan's merge squares
    /// their differences (about spread / sqrt(128)), so for offset / spread up to 1e6 the M2
    /// agrees to about 1e-10 relative. A plain sum of squares would be off by ~1e-3 at 1e6.
    const MOMENT_REL: f64 = 1e-9;

    /// The one histogram bins a one-sided range (end to end's $[0, H)$) and a symmetric one
    /// (the orientation errors' $[-H, H)$) alike: each value in the bin its edges name, below
    /// the range (and NaN) in the underflow, at or above it in the overflow; merging adds
    /// counts; the quantile bound is the upper edge of the rank's bin, capped by the maximum.
    #[test]
    fn histogram_bins_one_sided_and_symmetric_ranges_and_bounds_quantiles() {
        let mut h = Histogram::new(0.0, 4.0, 4);
        for v in [0.0, 0.5, 1.0, 3.99, 4.0, 7.0, -0.1, f64::NAN] {
            h.add(v);
        }
        assert_eq!(h.counts, [2, 1, 0, 1]);
        assert_eq!((h.underflow, h.overflow, h.total()), (2, 2, 8));
        assert_eq!(h.edges(), [0.0, 1.0, 2.0, 3.0, 4.0]);
        assert_eq!(h.centres(), [0.5, 1.5, 2.5, 3.5]);
        let mut s = Histogram::new(-2.0, 2.0, 4);
        for v in [-2.0, -0.5, 0.0, 1.999] {
            s.add(v);
        }
        assert_eq!(s.counts, [1, 1, 1, 1]);
        assert_eq!(s.edges(), [-2.0, -1.0, 0.0, 1.0, 2.0]);
        let mut m = s.clone();
        m.merge(&s);
        assert_eq!(m.counts, [2, 2, 2, 2]);
        // values 0.1, 0.2, 1.5, 2.5 on [0, 4): the median (2nd of 4) lies in bin 0, bound 1;
        // the maximum (4th) in bin 2, bound 3 capped by the largest value 2.5
        let mut q = Histogram::new(0.0, 4.0, 4);
        for v in [0.1, 0.2, 1.5, 2.5] {
            q.add(v);
        }
        // small integers and halves: every edge and bound is exact
        const EXACT: f64 = 0.0;
        approx::assert_abs_diff_eq!(q.quantile_upper(0.5, 2.5), 1.0, epsilon = EXACT);
        approx::assert_abs_diff_eq!(q.quantile_upper(1.0, 2.5), 2.5, epsilon = EXACT);
        assert_eq!(quantile_rank(0.5, 4), 2);
        assert_eq!(quantile_rank(0.0, 4), 1);
    }

    /// The one-pass shifted block moments and Chan's merge give the two-pass mean and M2,
    /// also for values far from zero relative to their spread (where a plain sum of squares
    /// would cancel catastrophically) and for a short last block.
    #[test]
    fn streamed_moments_match_two_pass_reference_even_far_from_zero() {
        let table = tt_kinematics::paper::table3();
        let bounds = ErrorBox::from_upper_rad(&table, vec![1e-4; 8]).unwrap();
        let sampler = TurntableSampler::new(&bounds, &table);
        let mut block = SampleBlock::new(&sampler);
        let mut rng = chunk_rng(3, 0);
        for offset in [0.0, 1.0, -1.0, 0.25] {
            let mut part = Partial::new(&[1.0; 3], 10);
            let mut all: Vec<f64> = Vec::new();
            let mut x: u64 = 99;
            for (b, n) in [BLOCK_CAPACITY, BLOCK_CAPACITY, 37].into_iter().enumerate() {
                sampler.fill_block(&mut rng, n, &mut block);
                let mut out = [[0.0; BLOCK_CAPACITY]; 3];
                let [o0, o1, o2] = &mut out;
                for ((a, b), c) in o0[..n].iter_mut().zip(&mut o1[..n]).zip(&mut o2[..n]) {
                    x = x
                        .wrapping_mul(6_364_136_223_846_793_005)
                        .wrapping_add(1_442_695_040_888_963_407);
                    let u = (x >> 11) as f64 / (1u64 << 53) as f64 - 0.5;
                    let v = offset + 1e-6 * u;
                    (*a, *b, *c) = (v, -v, 2.0 * v);
                    all.push(v);
                }
                part.add_block(
                    (b * BLOCK_CAPACITY) as u64,
                    &block,
                    &sampler,
                    &out,
                    &[1e9; 3],
                );
            }
            let n = all.len() as f64;
            let mean = all.iter().sum::<f64>() / n;
            let m2: f64 = all.iter().map(|v| (v - mean) * (v - mean)).sum();
            for (k, scale) in [1.0, -1.0, 2.0].into_iter().enumerate() {
                let (m, q) = (part.mean[k], part.m2[k]);
                assert!(
                    ((m - scale * mean) / (scale * mean).abs().max(1e-300)).abs() < MOMENT_REL
                        || (m - scale * mean).abs() < 1e-18,
                    "offset {offset} axis {k}: mean {m} vs {}",
                    scale * mean
                );
                let want = scale * scale * m2;
                assert!(
                    ((q - want) / want).abs() < MOMENT_REL,
                    "offset {offset} axis {k}: M2 {q} vs {want}"
                );
            }
        }
    }
}
