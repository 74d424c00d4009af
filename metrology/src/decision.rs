//! Decision rules for a statement of conformity (ILAC-G8:09/2019) and their risks (JCGM 106).
//!
//! A measured value $y$ with expanded uncertainty $U = k u$ against a tolerance interval
//! $C$ (an upper limit $T_U$, a lower limit $T_L$, or both):
//!
//! - **binary, simple acceptance** (ILAC-G8 4.2.1, $w = 0$): accept when $y$ lies in $C$;
//!   the specific probability of false accept reaches 50 % at a limit;
//! - **binary with guard band** (4.2.2): accept when $y$ lies in the acceptance interval
//!   $A$, $C$ shrunk by $w$ at each limit: $w = U$ ([`DecisionRule::GuardBandExpanded`];
//!   specific probability of false accept at most $1 - \Phi(k)$, 2.5 % for $k = 1.96$), or
//!   the $w$ for which the specific probability of false accept at the acceptance limit is a
//!   stated maximum $\alpha$ ([`DecisionRule::GuardBandRisk`]: $w = z_{1-\alpha} u$ at one
//!   limit; at two limits the $w$ with $\Pr(Y \notin C \mid y = A_U) = \alpha$, both tails
//!   counted);
//! - **non-binary with guard band $w = U$** (4.2.3): pass ($y$ in $A$), conditional pass
//!   ($y$ in $C$, not in $A$), conditional fail ($y$ outside $C$ by at most $w$), fail.
//!
//! # Risks (JCGM 106 9)
//! With a normal measurement $Y_m \mid Y = \eta \sim N(\eta, u_m^2)$:
//! - the **specific** risk of one decision (JCGM 106 9.3, flat prior): if accepted, the
//!   probability of false accept $\Pr(Y \notin C \mid y) = \Phi((T_L - y)/u) + 1 -
//!   \Phi((T_U - y)/u)$; if rejected, the probability of false reject $\Pr(Y \in C \mid y)$;
//!   with a normal prior $N(y_0, u_0^2)$ of the units the same with the posterior
//!   $N\big(\frac{y u_0^2 + y_0 u_m^2}{u_0^2 + u_m^2}, \frac{u_0^2 u_m^2}{u_0^2 + u_m^2}\big)$;
//! - the **global** risks over the units (JCGM 106 9.5) for a prior $N(y_0, u_0^2)$: the
//!   consumer's risk $R_C = \int_{\eta \notin C} \varphi_0(\eta)\, P_A(\eta)\, d\eta$ and the
//!   producer's risk $R_P = \int_{\eta \in C} \varphi_0(\eta)\, [1 - P_A(\eta)]\, d\eta$ with
//!   $P_A(\eta) = \Phi((A_U - \eta)/u_m) - \Phi((A_L - \eta)/u_m)$: the double integral over
//!   $(\eta, \eta_m)$ with the inner one in closed form; the outer one by adaptive
//!   Gauss-Legendre quadrature split at the limits, to $10^{-15}$ per panel over $y_0 \pm 12
//!   u_0$.
//!
//! # Reference
//! ILAC-G8:09/2019, *Guidelines on Decision Rules and Statements of Conformity*, 4.2.1-4.2.3;
//! JCGM 106:2012, *Evaluation of measurement data - The role of measurement uncertainty in
//! conformity assessment*, 7-9.

use crate::error::{MetrologyError, probability};
use crate::special::{integrate, normal_cdf, normal_quantile};
use std::fmt;
use tt_core::{finite, non_negative, positive};

/// A tolerance interval $C$: an upper limit, a lower limit, or both.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct Tolerance {
    lower: Option<f64>,
    upper: Option<f64>,
}

impl Tolerance {
    /// $Y \le T_U$.
    ///
    /// # Errors
    /// `tolerance.upper` not finite.
    pub fn upper(upper: f64) -> Result<Self, MetrologyError> {
        finite("tolerance.upper", upper)?;
        Ok(Tolerance {
            lower: None,
            upper: Some(upper),
        })
    }

    /// $Y \ge T_L$.
    ///
    /// # Errors
    /// `tolerance.lower` not finite.
    pub fn lower(lower: f64) -> Result<Self, MetrologyError> {
        finite("tolerance.lower", lower)?;
        Ok(Tolerance {
            lower: Some(lower),
            upper: None,
        })
    }

    /// $T_L \le Y \le T_U$.
    ///
    /// # Errors
    /// Either limit not finite, or `tolerance.upper` not above `tolerance.lower`.
    pub fn two_sided(lower: f64, upper: f64) -> Result<Self, MetrologyError> {
        finite("tolerance.lower", lower)?;
        finite("tolerance.upper", upper)?;
        if upper <= lower {
            return Err(tt_core::FieldError::OutOfRange {
                field: "tolerance.upper".into(),
                value: upper,
                range: format!("(tolerance.lower = {lower}, inf)"),
            }
            .into());
        }
        Ok(Tolerance {
            lower: Some(lower),
            upper: Some(upper),
        })
    }

    /// $T_L$, if any.
    #[must_use]
    pub fn lower_limit(&self) -> Option<f64> {
        self.lower
    }

    /// $T_U$, if any.
    #[must_use]
    pub fn upper_limit(&self) -> Option<f64> {
        self.upper
    }

    /// Whether `y` lies in $C$.
    #[must_use]
    pub fn contains(&self, y: f64) -> bool {
        self.lower.is_none_or(|l| y >= l) && self.upper.is_none_or(|u| y <= u)
    }

    /// $\Pr(Y \notin C)$ for $Y \sim N(\mu, \sigma^2)$ ($\sigma = 0$: 0 or 1).
    fn outside(&self, mu: f64, sigma: f64) -> f64 {
        if sigma <= 0.0 {
            return if self.contains(mu) { 0.0 } else { 1.0 };
        }
        self.lower.map_or(0.0, |l| normal_cdf((l - mu) / sigma))
            + self.upper.map_or(0.0, |u| normal_cdf((mu - u) / sigma))
    }
}

/// A measured value with its expanded uncertainty $U = k u$.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct Measured {
    value: f64,
    expanded: f64,
    coverage_factor: f64,
}

impl Measured {
    /// `value` with expanded uncertainty `expanded` (>= 0) at coverage factor `k` (> 0).
    ///
    /// # Errors
    /// `measured.value` not finite, `measured.expanded` negative, `measured.coverage_factor`
    /// not positive.
    pub fn new(value: f64, expanded: f64, k: f64) -> Result<Self, MetrologyError> {
        finite("measured.value", value)?;
        non_negative("measured.expanded", expanded)?;
        positive("measured.coverage_factor", k)?;
        Ok(Measured {
            value,
            expanded,
            coverage_factor: k,
        })
    }

    /// $y$.
    #[must_use]
    pub fn value(&self) -> f64 {
        self.value
    }

    /// $U$.
    #[must_use]
    pub fn expanded(&self) -> f64 {
        self.expanded
    }

    /// $u = U / k$.
    #[must_use]
    pub fn standard_uncertainty(&self) -> f64 {
        self.expanded / self.coverage_factor
    }
}

/// A normal prior $N(y_0, u_0^2)$ of the units' true values (a production process).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct Prior {
    mean: f64,
    sd: f64,
}

impl Prior {
    /// Mean `mean`, standard deviation `sd` (> 0: a prior without a spread says nothing
    /// about risk).
    ///
    /// # Errors
    /// `prior.mean` not finite; `prior.sd` zero, negative or not finite.
    pub fn new(mean: f64, sd: f64) -> Result<Self, MetrologyError> {
        finite("prior.mean", mean)?;
        positive("prior.sd", sd)?;
        Ok(Prior { mean, sd })
    }
}

/// A decision rule of ILAC-G8:09/2019 4.2.
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub enum DecisionRule {
    /// $w = 0$ (4.2.1).
    SimpleAcceptance,
    /// $w = U$ (4.2.2).
    GuardBandExpanded,
    /// $w$ such that the specific probability of false accept at the acceptance limit is
    /// `max_false_accept` (4.2.2; JCGM 106 8.3).
    GuardBandRisk {
        /// $\alpha$, in (0, 1).
        max_false_accept: f64,
    },
}

impl DecisionRule {
    /// The guard band for a maximum specific probability of false accept `alpha`.
    ///
    /// # Errors
    /// `max_false_accept` outside (0, 1).
    pub fn guard_band_for_risk(alpha: f64) -> Result<Self, MetrologyError> {
        probability("max_false_accept", alpha)?;
        Ok(DecisionRule::GuardBandRisk {
            max_false_accept: alpha,
        })
    }

    /// The acceptance interval for tolerance `tol` and a measurement of standard uncertainty
    /// `u` and expanded uncertainty `expanded`.
    #[must_use]
    pub fn acceptance(&self, tol: &Tolerance, u: f64, expanded: f64) -> Acceptance {
        let w = match *self {
            DecisionRule::SimpleAcceptance => 0.0,
            DecisionRule::GuardBandExpanded => expanded,
            DecisionRule::GuardBandRisk { max_false_accept } => {
                guard_for_risk(tol, u, max_false_accept)
            }
        };
        let lower = tol.lower.map(|l| l + w);
        let upper = tol.upper.map(|h| h - w);
        let empty = matches!((lower, upper), (Some(l), Some(h)) if l > h);
        Acceptance {
            interval: Tolerance { lower, upper },
            guard_band: w,
            empty,
        }
    }
}

/// The $w$ with a specific false-accept probability `alpha` at the acceptance limit
/// (infinite when no value is accepted at that risk).
fn guard_for_risk(tol: &Tolerance, u: f64, alpha: f64) -> f64 {
    if u <= 0.0 {
        return 0.0;
    }
    match (tol.lower, tol.upper) {
        (Some(l), Some(h)) => {
            let mid = 0.5 * (l + h);
            // risk at y: increasing for y from the middle to the upper limit
            if tol.outside(mid, u) > alpha {
                return f64::INFINITY;
            }
            let (mut lo, mut hi) = (mid, h);
            for _ in 0..200 {
                let y = 0.5 * (lo + hi);
                if tol.outside(y, u) > alpha {
                    hi = y;
                } else {
                    lo = y;
                }
            }
            h - lo
        }
        _ => u * normal_quantile(1.0 - alpha),
    }
}

impl fmt::Display for DecisionRule {
    /// The rule with its clause: `simple acceptance (w = 0; ILAC-G8:09/2019 4.2.1)`.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            DecisionRule::SimpleAcceptance => {
                write!(f, "simple acceptance (w = 0; ILAC-G8:09/2019 4.2.1)")
            }
            DecisionRule::GuardBandExpanded => {
                write!(f, "guard band w = U (ILAC-G8:09/2019 4.2.2)")
            }
            DecisionRule::GuardBandRisk { max_false_accept } => write!(
                f,
                "guard band w for a specific probability of false accept <= {} % (ILAC-G8:09/2019 4.2.2, JCGM 106 8.3)",
                max_false_accept * 100.0
            ),
        }
    }
}

/// An acceptance interval $A$: the tolerance shrunk by the guard band $w$ at each limit.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct Acceptance {
    interval: Tolerance,
    guard_band: f64,
    empty: bool,
}

impl Acceptance {
    /// The limits $A_L$, $A_U$ (those the tolerance has; $A_L > A_U$ when empty).
    #[must_use]
    pub fn interval(&self) -> &Tolerance {
        &self.interval
    }

    /// $w$ (infinite when no value can be accepted at the stated risk).
    #[must_use]
    pub fn guard_band(&self) -> f64 {
        self.guard_band
    }

    /// Whether no value is accepted (the guard bands overlap).
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.empty
    }

    /// Whether `y` is accepted.
    #[must_use]
    pub fn contains(&self, y: f64) -> bool {
        !self.empty && self.interval.contains(y)
    }

    /// $P_A(\eta) = \Pr(Y_m \in A \mid Y = \eta)$ for $Y_m \sim N(\eta, u_m^2)$.
    fn probability_accept(&self, eta: f64, um: f64) -> f64 {
        if self.empty {
            return 0.0;
        }
        let cdf = |x: f64| {
            if um > 0.0 {
                normal_cdf((x - eta) / um)
            } else if x >= eta {
                1.0
            } else {
                0.0
            }
        };
        self.interval.upper.map_or(1.0, cdf) - self.interval.lower.map_or(0.0, cdf)
    }
}

/// A binary decision: the rule, the acceptance interval, the verdict and its specific risk.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct Decision {
    pub(crate) rule: DecisionRule,
    pub(crate) acceptance: Acceptance,
    pub(crate) measured: Measured,
    pub(crate) accepted: bool,
    pub(crate) specific_risk: f64,
}

/// Read access to the fields (crate-private, so the type can grow without breaking callers).
impl Decision {
    /// The rule applied.
    #[must_use]
    pub fn rule(&self) -> DecisionRule {
        self.rule
    }

    /// The acceptance interval.
    #[must_use]
    pub fn acceptance(&self) -> Acceptance {
        self.acceptance
    }

    /// Whether the unit is accepted.
    #[must_use]
    pub fn accepted(&self) -> bool {
        self.accepted
    }

    /// The specific risk of this decision (flat prior): the probability of false accept if
    /// accepted, of false reject if rejected.
    #[must_use]
    pub fn specific_risk(&self) -> f64 {
        self.specific_risk
    }
}

impl fmt::Display for Decision {
    /// `accept: measured 9.8 (U = 0.4) in the acceptance interval (-inf, 10] by simple
    /// acceptance (w = 0; ILAC-G8:09/2019 4.2.1); specific probability of false accept 0.0 %`.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let a = &self.acceptance;
        let (verdict, place, risk) = if self.accepted {
            ("accept", "in", "false accept")
        } else {
            ("reject", "outside", "false reject")
        };
        let lo = a
            .interval
            .lower
            .map_or("-inf".to_string(), |v| format!("{v}"));
        let hi = a
            .interval
            .upper
            .map_or("inf".to_string(), |v| format!("{v}"));
        write!(
            f,
            "{verdict}: measured {} (U = {}) {place} the acceptance interval [{lo}, {hi}] by {}; specific probability of {risk} {:.3} %",
            self.measured.value,
            self.measured.expanded,
            self.rule,
            self.specific_risk * 100.0
        )
    }
}

/// The binary decision on `measured` against `tol` by `rule`, with its specific risk.
///
/// ```
/// use metrology::decision::{decide, DecisionRule, Measured, Tolerance};
/// // a bias specified at <= 0.5 deg/h, measured 0.42 deg/h with U = 0.1 deg/h (k = 2)
/// let tol = Tolerance::upper(0.5)?;
/// let m = Measured::new(0.42, 0.1, 2.0)?;
/// let simple = decide(DecisionRule::SimpleAcceptance, &tol, &m);
/// assert!(simple.accepted());
/// let guarded = decide(DecisionRule::GuardBandExpanded, &tol, &m);
/// assert!(!guarded.accepted()); // 0.42 > 0.5 - 0.1
/// // probability that the true bias is within 0.5 after all: Phi(0.08 / 0.05)
/// assert!((guarded.specific_risk() - 0.945_200_708).abs() < 1e-8);
/// # Ok::<(), metrology::MetrologyError>(())
/// ```
#[must_use]
pub fn decide(rule: DecisionRule, tol: &Tolerance, measured: &Measured) -> Decision {
    let u = measured.standard_uncertainty();
    let acceptance = rule.acceptance(tol, u, measured.expanded);
    let accepted = acceptance.contains(measured.value);
    let outside = tol.outside(measured.value, u);
    Decision {
        rule,
        acceptance,
        measured: *measured,
        accepted,
        specific_risk: if accepted { outside } else { 1.0 - outside },
    }
}

/// The specific probability that the true value lies outside `tol` given the measurement,
/// with a normal prior of the units (`None`: flat prior).
#[must_use]
pub fn probability_outside(tol: &Tolerance, measured: &Measured, prior: Option<&Prior>) -> f64 {
    let (y, u) = (measured.value, measured.standard_uncertainty());
    match prior {
        None => tol.outside(y, u),
        Some(p) => {
            let (v0, vm) = (p.sd * p.sd, u * u);
            let mean = (y * v0 + p.mean * vm) / (v0 + vm);
            tol.outside(mean, (v0 * vm / (v0 + vm)).sqrt())
        }
    }
}

/// An ILAC-G8:09/2019 4.2.3 non-binary statement (guard band $w = U$).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub enum Statement {
    /// $y$ in the acceptance interval.
    Pass,
    /// $y$ in the tolerance, within $U$ of a limit.
    ConditionalPass,
    /// $y$ outside the tolerance by at most $U$.
    ConditionalFail,
    /// $y$ outside the tolerance by more than $U$.
    Fail,
}

impl fmt::Display for Statement {
    /// `pass`, `conditional pass`, `conditional fail`, `fail`.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Statement::Pass => "pass",
            Statement::ConditionalPass => "conditional pass",
            Statement::ConditionalFail => "conditional fail",
            Statement::Fail => "fail",
        })
    }
}

/// The non-binary statement of ILAC-G8:09/2019 4.2.3 (guard band $w = U$) on `measured`
/// against `tol`.
///
/// ```
/// use metrology::decision::{statement, Measured, Statement, Tolerance};
/// let tol = Tolerance::two_sided(-1.0, 1.0)?;
/// let at = |y| statement(&tol, &Measured::new(y, 0.2, 2.0).unwrap());
/// assert_eq!(at(0.5), Statement::Pass);
/// assert_eq!(at(0.9), Statement::ConditionalPass);
/// assert_eq!(at(-1.1), Statement::ConditionalFail);
/// assert_eq!(at(1.3), Statement::Fail);
/// # Ok::<(), metrology::MetrologyError>(())
/// ```
#[must_use]
pub fn statement(tol: &Tolerance, measured: &Measured) -> Statement {
    let (y, w) = (measured.value, measured.expanded);
    let shrunk = DecisionRule::GuardBandExpanded.acceptance(tol, 0.0, w);
    if shrunk.contains(y) {
        Statement::Pass
    } else if tol.contains(y) {
        Statement::ConditionalPass
    } else if tol.lower.is_none_or(|l| y >= l - w) && tol.upper.is_none_or(|u| y <= u + w) {
        Statement::ConditionalFail
    } else {
        Statement::Fail
    }
}

/// Global risks of a decision rule over a population of units (JCGM 106 9.5).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct GlobalRisk {
    pub(crate) false_accept: f64,
    pub(crate) false_reject: f64,
    pub(crate) conforming: f64,
}

/// Read access to the fields (crate-private, so the type can grow without breaking callers).
impl GlobalRisk {
    /// $R_C$: the probability that a unit is outside the tolerance and accepted (consumer's
    /// risk).
    #[must_use]
    pub fn false_accept(&self) -> f64 {
        self.false_accept
    }

    /// $R_P$: the probability that a unit is in the tolerance and rejected (producer's risk).
    #[must_use]
    pub fn false_reject(&self) -> f64 {
        self.false_reject
    }

    /// $\Pr(Y \in C)$: the prior probability of conformity.
    #[must_use]
    pub fn conforming(&self) -> f64 {
        self.conforming
    }
}

/// The global probabilities of false accept and false reject of accepting in `acceptance`
/// units of prior `prior` against `tol`, measured with standard uncertainty `um`.
///
/// ```
/// use metrology::decision::{global_risks, DecisionRule, Prior, Tolerance};
/// // prior centred on the limit: R_C = 1/4 - asin(rho)/(2 pi), rho = u0 / sqrt(u0^2 + um^2)
/// let tol = Tolerance::upper(0.0)?;
/// let a = DecisionRule::SimpleAcceptance.acceptance(&tol, 0.5, 1.0);
/// let r = global_risks(&tol, &a, &Prior::new(0.0, 1.0)?, 0.5)?;
/// let rho = 1.0 / 1.25_f64.sqrt();
/// assert!((r.false_accept() - (0.25 - rho.asin() / std::f64::consts::TAU)).abs() < 1e-12);
/// # Ok::<(), metrology::MetrologyError>(())
/// ```
///
/// # Errors
/// `um` negative or not finite (`measured.standard_uncertainty`).
pub fn global_risks(
    tol: &Tolerance,
    acceptance: &Acceptance,
    prior: &Prior,
    um: f64,
) -> Result<GlobalRisk, MetrologyError> {
    non_negative("measured.standard_uncertainty", um)?;
    let (mu, s) = (prior.mean, prior.sd);
    let (lo, hi) = (mu - 12.0 * s, mu + 12.0 * s);
    let density = |eta: f64| {
        let z = (eta - mu) / s;
        (-0.5 * z * z).exp() / (s * (std::f64::consts::TAU).sqrt())
    };
    // break points: the limits of C and A inside the range
    let mut cuts = vec![lo, hi];
    let a = &acceptance.interval;
    for v in [tol.lower, tol.upper, a.lower, a.upper]
        .into_iter()
        .flatten()
    {
        if v > lo && v < hi {
            cuts.push(v);
        }
    }
    cuts.sort_by(f64::total_cmp);
    let (mut false_accept, mut false_reject) = (0.0, 0.0);
    for pair in cuts.windows(2) {
        let (a, b) = (pair[0], pair[1]);
        if b <= a {
            continue;
        }
        if tol.contains(0.5 * (a + b)) {
            let f = |eta: f64| density(eta) * (1.0 - acceptance.probability_accept(eta, um));
            false_reject += integrate(&f, a, b, 1e-15);
        } else {
            let f = |eta: f64| density(eta) * acceptance.probability_accept(eta, um);
            false_accept += integrate(&f, a, b, 1e-15);
        }
    }
    Ok(GlobalRisk {
        false_accept,
        false_reject,
        conforming: 1.0 - tol.outside(mu, s),
    })
}
