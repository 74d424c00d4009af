//! The count of a seeded Monte Carlo yield and its 95% Wilson interval: the one yield count
//! of the workspace (this crate's runs and every yield of e2e-verify).

/// Standard normal quantile of 97.5% ($z$ of a two-sided 95% interval).
pub const Z_95: f64 = 1.959_963_984_540_054;

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
/// let (lo, hi) = mc_verify::wilson_interval_95(997, 1000);
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

/// The count of a seeded Monte Carlo yield: the draws, their seed, those meeting every
/// requirement and those meeting each one's. The one count every yield of the workspace
/// reports: a run of this crate ([`crate::McResult::count`]: the three angles' requirements)
/// and e2e-verify's yields (every output's accuracy: turntables from a box, turntables and
/// noise, simulated calibrations, a yield allocation's design draws, angle-dependent errors).
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct YieldCount {
    /// Draws.
    pub(crate) samples: u64,
    /// Seed of the streams.
    pub(crate) seed: u64,
    /// Draws meeting every requirement (every output's accuracy; all three angles').
    pub(crate) meeting: u64,
    /// Draws meeting each output's accuracy, or each angle's requirement (empty where only
    /// all together are counted: a yield allocation's design draws).
    pub(crate) meeting_per_output: Vec<u64>,
}

/// Read access to the fields (crate-private, so the type can grow without breaking callers).
impl YieldCount {
    /// Draws.
    #[must_use]
    pub fn samples(&self) -> u64 {
        self.samples
    }

    /// Seed of the streams.
    #[must_use]
    pub fn seed(&self) -> u64 {
        self.seed
    }

    /// Draws meeting every requirement (every output's accuracy; all three angles').
    #[must_use]
    pub fn meeting(&self) -> u64 {
        self.meeting
    }

    /// Draws meeting each output's accuracy, or each angle's requirement (empty where only
    /// all together are counted: a yield allocation's design draws).
    #[must_use]
    pub fn meeting_per_output(&self) -> &[u64] {
        &self.meeting_per_output
    }
}

impl YieldCount {
    /// `meeting` of `samples` draws seeded `seed` meet every requirement, `meeting_per_output`
    /// each one's (empty: not counted one by one). Counts, not checked: each is at most
    /// `samples`, `meeting` at most each per-output count.
    #[must_use]
    pub fn new(samples: u64, seed: u64, meeting: u64, meeting_per_output: Vec<u64>) -> Self {
        debug_assert!(
            meeting_per_output
                .iter()
                .all(|&m| meeting <= m && m <= samples)
        );
        debug_assert!(meeting <= samples);
        Self {
            samples,
            seed,
            meeting,
            meeting_per_output,
        }
    }

    /// The yield: the fraction of draws meeting every requirement.
    #[must_use]
    pub fn fraction(&self) -> f64 {
        self.meeting as f64 / self.samples as f64
    }

    /// Its 95% Wilson interval ([`wilson_interval_95`]).
    #[must_use]
    pub fn interval_95(&self) -> (f64, f64) {
        wilson_interval_95(self.meeting, self.samples)
    }
}
