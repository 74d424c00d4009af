//! Does a plan meet a specification? Two stated rules:
//!
//! - **by its expanded uncertainty** ([`SpecificationCheck`]): the plan meets the limit $L$
//!   of a specified quantity when the expanded uncertainty at the stated coverage probability
//!   is within it, $U_p \le L$; the ratio $U_p / L$ says by how much;
//! - **by its yield** ([`YieldCheck`]): $n_s$ of $n$ simulated calibrations meet every
//!   specification; the plan meets a required fraction $\pi$ at confidence $c$ when the
//!   lower end of the two-sided $100c\,\%$ interval of the fraction is at least $\pi$, does not
//!   when its upper end is below $\pi$, and is undecided otherwise (run more trials). The
//!   interval is Wilson's score interval
//!   $$\frac{\hat p + \frac{z^2}{2n} \pm z\sqrt{\frac{\hat p(1-\hat p)}{n} +
//!   \frac{z^2}{4n^2}}}{1 + z^2/n}, \qquad z = \Phi^{-1}\big(\tfrac{1+c}{2}\big),$$
//!   or the exact Clopper-Pearson interval
//!   $[B^{-1}(\tfrac{1-c}{2}; n_s, n - n_s + 1),\ B^{-1}(\tfrac{1+c}{2}; n_s + 1, n - n_s)]$
//!   ($B^{-1}$ the beta quantile; 0 and 1 at the ends).
//!
//! # Reference
//! E. B. Wilson, "Probable inference, the law of succession, and statistical inference",
//! J. Am. Stat. Assoc. 22 (1927) 209-212; C. J. Clopper, E. S. Pearson, "The use of
//! confidence or fiducial limits illustrated in the case of the binomial", Biometrika 26
//! (1934) 404-413; JCGM 106:2012 (conformity of a quantity with a specification).

use crate::budget::OutputUncertainty;
use crate::error::{MetrologyError, probability};
use crate::special::{beta_quantile, normal_quantile};
use std::fmt;
use tt_core::{non_negative, positive};

/// `v` to four significant digits, without an exponent between 1e-4 and 1e6.
fn sig4(v: f64) -> String {
    if !v.is_normal() {
        return format!("{v}");
    }
    let mag = v.abs().log10().floor() as i32;
    if (-4..6).contains(&mag) {
        let decimals = (3 - mag).max(0) as usize;
        format!("{v:.decimals$}")
    } else {
        format!("{v:.3e}")
    }
}

/// A plan's expanded uncertainty against a specification limit.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct SpecificationCheck {
    pub(crate) expanded: f64,
    pub(crate) coverage_factor: f64,
    pub(crate) coverage: f64,
    pub(crate) limit: f64,
}

impl SpecificationCheck {
    /// Expanded uncertainty `expanded` at coverage factor `k` and coverage probability
    /// `coverage`, against the specification limit `limit` (> 0, the same unit).
    ///
    /// ```
    /// use metrology::plan::SpecificationCheck;
    /// let check = SpecificationCheck::new(0.41, 2.07, 0.95, 0.5)?;
    /// assert!(check.meets());
    /// assert_eq!(
    ///     check.to_string(),
    ///     "meets: expanded uncertainty U = 0.4100 (k = 2.070, p = 95 %) within the specification 0.5000 (ratio 0.8200; rule: U <= specification)"
    /// );
    /// # Ok::<(), metrology::MetrologyError>(())
    /// ```
    ///
    /// # Errors
    /// `expanded` negative, `coverage_factor` or `limit` not positive, `coverage` outside
    /// (0, 1).
    pub fn new(expanded: f64, k: f64, coverage: f64, limit: f64) -> Result<Self, MetrologyError> {
        non_negative("expanded", expanded)?;
        positive("coverage_factor", k)?;
        probability("coverage", coverage)?;
        positive("limit", limit)?;
        Ok(SpecificationCheck {
            expanded,
            coverage_factor: k,
            coverage,
            limit,
        })
    }

    /// The check of one output of a budget at the budget's coverage probability.
    ///
    /// # Errors
    /// As [`SpecificationCheck::new`].
    pub fn of_output(
        output: &OutputUncertainty,
        coverage: f64,
        limit: f64,
    ) -> Result<Self, MetrologyError> {
        Self::new(output.expanded, output.coverage_factor, coverage, limit)
    }

    /// $U_p / L$.
    #[must_use]
    pub fn ratio(&self) -> f64 {
        self.expanded / self.limit
    }

    /// Whether $U_p \le L$.
    #[must_use]
    pub fn meets(&self) -> bool {
        self.expanded <= self.limit
    }

    /// $U_p$.
    #[must_use]
    pub fn expanded(&self) -> f64 {
        self.expanded
    }

    /// $L$.
    #[must_use]
    pub fn limit(&self) -> f64 {
        self.limit
    }
}

impl fmt::Display for SpecificationCheck {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let (verdict, relation) = if self.meets() {
            ("meets", "within")
        } else {
            ("does not meet", "exceeds")
        };
        write!(
            f,
            "{verdict}: expanded uncertainty U = {} (k = {}, p = {} %) {relation} the specification {} (ratio {}; rule: U <= specification)",
            sig4(self.expanded),
            sig4(self.coverage_factor),
            self.coverage * 100.0,
            sig4(self.limit),
            sig4(self.ratio())
        )
    }
}

/// The interval of a binomial fraction.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub enum IntervalMethod {
    /// Wilson's score interval.
    Wilson,
    /// The exact (conservative) Clopper-Pearson interval.
    ClopperPearson,
}

impl fmt::Display for IntervalMethod {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            IntervalMethod::Wilson => "Wilson",
            IntervalMethod::ClopperPearson => "Clopper-Pearson",
        })
    }
}

/// The verdict of a yield against a required fraction.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub enum YieldVerdict {
    /// The interval's lower end is at least the required fraction.
    Meets,
    /// The interval's upper end is below it.
    DoesNotMeet,
    /// The interval contains it: more trials decide.
    Undecided,
}

/// The interval `(lower, upper)` of a fraction of `successes` in `trials` (>= 1) at
/// confidence `confidence` by `method`.
///
/// ```
/// use metrology::plan::{fraction_interval, IntervalMethod};
/// // none of 10: Clopper-Pearson upper end 1 - 0.025^(1/10)
/// let (lo, hi) = fraction_interval(0, 10, 0.95, IntervalMethod::ClopperPearson)?;
/// assert!(lo == 0.0 && (hi - (1.0 - 0.025_f64.powf(0.1))).abs() < 1e-12);
/// # Ok::<(), metrology::MetrologyError>(())
/// ```
///
/// # Errors
/// `trials` zero, `successes` above `trials`, `confidence` outside (0, 1).
pub fn fraction_interval(
    successes: u64,
    trials: u64,
    confidence: f64,
    method: IntervalMethod,
) -> Result<(f64, f64), MetrologyError> {
    tt_core::count("trials", trials, u64::MAX)?;
    if successes > trials {
        return Err(tt_core::FieldError::OutOfRange {
            field: "successes".into(),
            value: successes as f64,
            range: format!("[0, trials = {trials}]"),
        }
        .into());
    }
    probability("confidence", confidence)?;
    let (k, n) = (successes as f64, trials as f64);
    let alpha = 1.0 - confidence;
    Ok(match method {
        IntervalMethod::Wilson => {
            let z = normal_quantile(1.0 - 0.5 * alpha);
            let p = k / n;
            let z2 = z * z;
            let denom = 1.0 + z2 / n;
            let centre = (p + z2 / (2.0 * n)) / denom;
            let half = z * (p * (1.0 - p) / n + z2 / (4.0 * n * n)).sqrt() / denom;
            ((centre - half).max(0.0), (centre + half).min(1.0))
        }
        IntervalMethod::ClopperPearson => {
            let lo = if successes == 0 {
                0.0
            } else {
                beta_quantile(k, n - k + 1.0, 0.5 * alpha)
            };
            let hi = if successes == trials {
                1.0
            } else {
                beta_quantile(k + 1.0, n - k, 1.0 - 0.5 * alpha)
            };
            (lo, hi)
        }
    })
}

/// A yield (the fraction of simulated calibrations that meet every specification) against a
/// required fraction.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct YieldCheck {
    pub(crate) successes: u64,
    pub(crate) trials: u64,
    pub(crate) required: f64,
    pub(crate) confidence: f64,
    pub(crate) method: IntervalMethod,
    pub(crate) interval: (f64, f64),
}

impl YieldCheck {
    /// `successes` of `trials` calibrations meet; the plan must have a fraction of at least
    /// `required` (in (0, 1]) meeting, at confidence `confidence`.
    ///
    /// ```
    /// use metrology::plan::{IntervalMethod, YieldCheck, YieldVerdict};
    /// let y = YieldCheck::new(958, 1000, 0.99, 0.95, IntervalMethod::ClopperPearson)?;
    /// assert_eq!(y.verdict(), YieldVerdict::DoesNotMeet);
    /// assert!(y.to_string().starts_with("does not meet: 958 of 1000 calibrations meet (95.80 %; 95 % Clopper-Pearson interval"));
    /// # Ok::<(), metrology::MetrologyError>(())
    /// ```
    ///
    /// # Errors
    /// As [`fraction_interval`]; `required` outside (0, 1].
    pub fn new(
        successes: u64,
        trials: u64,
        required: f64,
        confidence: f64,
        method: IntervalMethod,
    ) -> Result<Self, MetrologyError> {
        if !(required > 0.0 && required <= 1.0) {
            return Err(tt_core::FieldError::OutOfRange {
                field: "required".into(),
                value: required,
                range: "(0, 1]".into(),
            }
            .into());
        }
        let interval = fraction_interval(successes, trials, confidence, method)?;
        Ok(YieldCheck {
            successes,
            trials,
            required,
            confidence,
            method,
            interval,
        })
    }

    /// $\hat p = n_s / n$.
    #[must_use]
    pub fn estimate(&self) -> f64 {
        self.successes as f64 / self.trials as f64
    }

    /// The interval of the fraction.
    #[must_use]
    pub fn interval(&self) -> (f64, f64) {
        self.interval
    }

    /// The verdict.
    #[must_use]
    pub fn verdict(&self) -> YieldVerdict {
        if self.interval.0 >= self.required {
            YieldVerdict::Meets
        } else if self.interval.1 < self.required {
            YieldVerdict::DoesNotMeet
        } else {
            YieldVerdict::Undecided
        }
    }
}

impl fmt::Display for YieldCheck {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let verdict = match self.verdict() {
            YieldVerdict::Meets => "meets",
            YieldVerdict::DoesNotMeet => "does not meet",
            YieldVerdict::Undecided => "undecided (run more trials)",
        };
        write!(
            f,
            "{verdict}: {} of {} calibrations meet ({:.2} %; {} % {} interval {:.2} % to {:.2} %) against the required {} % (rule: the interval's lower end >= required)",
            self.successes,
            self.trials,
            100.0 * self.estimate(),
            100.0 * self.confidence,
            self.method,
            100.0 * self.interval.0,
            100.0 * self.interval.1,
            100.0 * self.required
        )
    }
}
