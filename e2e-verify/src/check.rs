//! "The vendor's sheet says these tolerances: will my calibration meet its accuracy, and
//! which error dominates?" The end-to-end check of a given tolerance box.

use crate::error::E2eError;
use crate::linear::{Linearization, OutputWorstCase};
use crate::montecarlo::{McSettings, RateDistribution};
use crate::sheet::ToleranceSheet;

/// How sure the answer is that every turntable within the tolerances meets an accuracy.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize),
    serde(rename_all = "snake_case")
)]
pub enum Verdict {
    /// Proven: the linearised worst case plus the derived second-order bound is within the
    /// accuracy, so every turntable of the box meets it on the exact chain.
    Guaranteed,
    /// The worst vertex meets the accuracy on the exact chain, but no rigorous bound proves it
    /// for the whole box (the reading has no derived second-order bound, or the linearised
    /// worst case plus that bound exceeds the accuracy): likely, not proven.
    Likely,
    /// A turntable within the tolerances (the worst vertex) misses the accuracy on the exact
    /// chain.
    Fails,
}

impl Verdict {
    /// `guaranteed`, `likely` or `fails`.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Verdict::Guaranteed => "guaranteed",
            Verdict::Likely => "likely",
            Verdict::Fails => "fails",
        }
    }
}

/// One error's contribution to an output's worst case, or the contribution of a group of
/// errors that act only together ([`tt_kinematics::ErrorGroup`]: one rotation to first order,
/// so no check can split the share between them).
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct Contribution {
    /// The error's index in $\chi$ (the group's first error).
    pub(crate) error: usize,
    /// The group of errors that act only together, [`Contribution::error`] first (one error
    /// when it acts alone).
    pub(crate) group: tt_kinematics::ErrorGroup,
    /// Share of the linearised worst case at the worst row:
    /// $|M_{rj}|\mathrm{UB}_j / \sum_i |M_{ri}|\mathrm{UB}_i$, summed over the group.
    pub(crate) worst_share: f64,
    /// Share of the variance of the linearised error at the worst row for errors drawn as the
    /// Monte Carlo draws them ($|\chi_j|$ uniform on $[\mathrm{LB}_j, \mathrm{UB}_j]$, random
    /// sign: $E\chi_j^2 = (\mathrm{UB}^3 - \mathrm{LB}^3)/(3(\mathrm{UB} - \mathrm{LB}))$),
    /// summed over the group.
    pub(crate) variance_share: f64,
}

/// Read access to the fields (crate-private, so the type can grow without breaking callers).
impl Contribution {
    /// The error's index in $\chi$ (the group's first error).
    #[must_use]
    pub fn error(&self) -> usize {
        self.error
    }

    /// The group of errors that act only together, [`Contribution::error`] first (one error
    /// when it acts alone).
    #[must_use]
    pub fn group(&self) -> &tt_kinematics::ErrorGroup {
        &self.group
    }

    /// Share of the linearised worst case at the worst row:
    /// $|M_{rj}|\mathrm{UB}_j / \sum_i |M_{ri}|\mathrm{UB}_i$, summed over the group.
    #[must_use]
    pub fn worst_share(&self) -> f64 {
        self.worst_share
    }

    /// Share of the variance of the linearised error at the worst row for errors drawn as the
    /// Monte Carlo draws them ($|\chi_j|$ uniform on $[\mathrm{LB}_j, \mathrm{UB}_j]$, random
    /// sign: $E\chi_j^2 = (\mathrm{UB}^3 - \mathrm{LB}^3)/(3(\mathrm{UB} - \mathrm{LB}))$),
    /// summed over the group.
    #[must_use]
    pub fn variance_share(&self) -> f64 {
        self.variance_share
    }
}

/// One output's verdict against its accuracy, with what the question adds (`D`): the buyer's
/// check of a box ([`OutputCheck`]: the worst case and every error's contribution) or the
/// answer for both error sources ([`crate::CombinedOutput`]: the table and the noise parts).
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct OutputVerdict<D> {
    /// The output's index.
    pub(crate) output: usize,
    /// Its accuracy (output unit).
    pub(crate) accuracy: f64,
    /// The verdict for this output.
    pub(crate) verdict: Verdict,
    /// What the question adds.
    #[cfg_attr(feature = "serde", serde(flatten))]
    pub(crate) detail: D,
}

/// Read access to the fields (crate-private, so the type can grow without breaking callers).
impl<D> OutputVerdict<D> {
    /// The output's index.
    #[must_use]
    pub fn output(&self) -> usize {
        self.output
    }

    /// Its accuracy (output unit).
    #[must_use]
    pub fn accuracy(&self) -> f64 {
        self.accuracy
    }

    /// The verdict for this output.
    #[must_use]
    pub fn verdict(&self) -> Verdict {
        self.verdict
    }
}

/// The verdict of one output's worst case `w` against `accuracy` with `noise_part` (output
/// unit; 0 for the table alone) added to both sides of its test: fails when the exact chain at
/// the worst vertex plus the noise part exceeds the accuracy, guaranteed when the (finite)
/// certified bound plus it is within, likely between.
pub(crate) fn verdict_of(w: &OutputWorstCase, accuracy: f64, noise_part: f64) -> Verdict {
    if w.exact_at_vertex + noise_part > accuracy {
        Verdict::Fails
    } else {
        match w.certified_bound().filter(|b| b.is_finite()) {
            Some(b) if b + noise_part <= accuracy => Verdict::Guaranteed,
            _ => Verdict::Likely,
        }
    }
}

/// What the buyer's check adds to an output's verdict ([`OutputCheck`]).
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct CheckDetail {
    /// The worst case over the tolerance box.
    pub(crate) worst_case: OutputWorstCase,
    /// Every group's contribution ([`tt_kinematics::Turntable::error_groups`]: one per error
    /// that acts alone, one per group of errors that act only together), in the order of
    /// their first error in $\chi$.
    pub(crate) contributions: Vec<Contribution>,
}

/// The check of one output.
pub type OutputCheck = OutputVerdict<CheckDetail>;

/// Read access to the fields (crate-private, so the type can grow without breaking callers).
impl OutputCheck {
    /// The worst case over the tolerance box.
    #[must_use]
    pub fn worst_case(&self) -> &OutputWorstCase {
        &self.detail.worst_case
    }

    /// Every group's contribution ([`tt_kinematics::Turntable::error_groups`]: one per error
    /// that acts alone, one per group of errors that act only together), in the order of
    /// their first error in $\chi$.
    #[must_use]
    pub fn contributions(&self) -> &[Contribution] {
        &self.detail.contributions
    }

    /// The `n` contributions with the largest worst-case share, largest first (a stable sort:
    /// ties keep the order in $\chi$), without those that do not contribute (share 0): the
    /// dominant errors a check or a report names.
    #[must_use]
    pub fn dominant(&self, n: usize) -> Vec<&Contribution> {
        let mut top: Vec<&Contribution> = self.detail.contributions.iter().collect();
        top.sort_by(|a, b| b.worst_share.total_cmp(&a.worst_share));
        top.into_iter()
            .take(n)
            .filter(|k| k.worst_share > 0.0)
            .collect()
    }
}

/// The check of a tolerance box against every output's accuracy.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct TurntableCheck {
    /// The tolerances (rad).
    pub(crate) upper_bounds_rad: Vec<f64>,
    /// One per output.
    pub(crate) outputs: Vec<OutputCheck>,
    /// The Monte Carlo over the box: yield with its 95% interval.
    pub(crate) distribution: RateDistribution,
    /// The overall verdict: the weakest of the outputs'.
    pub(crate) verdict: Verdict,
}

/// Read access to the fields (crate-private, so the type can grow without breaking callers).
impl TurntableCheck {
    /// The tolerances (rad).
    #[must_use]
    pub fn upper_bounds_rad(&self) -> &[f64] {
        &self.upper_bounds_rad
    }

    /// One per output.
    #[must_use]
    pub fn outputs(&self) -> &[OutputCheck] {
        &self.outputs
    }

    /// The Monte Carlo over the box: yield with its 95% interval.
    #[must_use]
    pub fn distribution(&self) -> &RateDistribution {
        &self.distribution
    }

    /// The overall verdict: the weakest of the outputs'.
    #[must_use]
    pub fn verdict(&self) -> Verdict {
        self.verdict
    }
}

impl crate::VendorQuestions<'_> {
    /// Check a vendor's sheet: [`crate::VendorQuestions::check_tolerances`] of its bounds with its lower
    /// bounds, on this simulator's linearisation.
    ///
    /// # Errors
    /// As [`crate::VendorQuestions::check_tolerances`].
    pub fn check_sheet(
        &self,
        sheet: &ToleranceSheet,
        settings: &McSettings,
    ) -> Result<TurntableCheck, E2eError> {
        self.check_tolerances(
            &self.linearization(),
            sheet.upper_bounds_rad(),
            sheet.lower_bounds_rad(),
            settings,
        )
    }

    /// Check tolerances `ub_rad` (with lower bounds `lower_bounds_rad`) against every output's
    /// accuracy: the worst case per output (linearised, confirmed on the exact chain at the
    /// worst vertex, with its second-order bound), each error's contribution (one per group of
    /// errors that act only together), the Monte Carlo yield and a verdict.
    ///
    /// # Errors
    /// As [`crate::EndToEnd::worst_case`] and [`crate::MonteCarloQuestions::rate_distribution`].
    pub fn check_tolerances(
        &self,
        linear: &Linearization,
        ub_rad: &[f64],
        lower_bounds_rad: &[f64],
        settings: &McSettings,
    ) -> Result<TurntableCheck, E2eError> {
        let wc = self.worst_case(linear, ub_rad)?;
        let bounds = self.box_of(ub_rad, lower_bounds_rad)?;
        let distribution = self
            .monte_carlo()
            .rate_distribution(linear, &bounds, settings)?;
        let acc = self.accuracies();
        let groups = self.turntable().error_groups();
        let mut outputs = Vec::with_capacity(acc.len());
        for (k, w) in wc.outputs.into_iter().enumerate() {
            let row = linear.row(k, w.position);
            let worst_terms: Vec<f64> = row
                .iter()
                .zip(ub_rad)
                .map(|(m, u)| if u.is_finite() { m.abs() * u } else { 0.0 })
                .collect();
            let second: Vec<f64> = row
                .iter()
                .zip(ub_rad.iter().zip(lower_bounds_rad))
                .map(|(m, (u, l))| {
                    if !u.is_finite() {
                        return 0.0;
                    }
                    let e2 = if u > l {
                        (u.powi(3) - l.powi(3)) / (3.0 * (u - l))
                    } else {
                        u * u
                    };
                    m * m * e2
                })
                .collect();
            let (ws, vs): (f64, f64) = (worst_terms.iter().sum(), second.iter().sum());
            let contributions = groups
                .iter()
                .map(|g| Contribution {
                    error: g.errors[0],
                    group: g.clone(),
                    worst_share: if ws > 0.0 {
                        g.sum(&worst_terms) / ws
                    } else {
                        0.0
                    },
                    variance_share: if vs > 0.0 { g.sum(&second) / vs } else { 0.0 },
                })
                .collect();
            outputs.push(OutputCheck {
                output: k,
                accuracy: acc[k],
                verdict: verdict_of(&w, acc[k], 0.0),
                detail: CheckDetail {
                    worst_case: w,
                    contributions,
                },
            });
        }
        let verdict = crate::noise::weakest(outputs.iter().map(|o| o.verdict));
        Ok(TurntableCheck {
            upper_bounds_rad: ub_rad.to_vec(),
            outputs,
            distribution,
            verdict,
        })
    }
}
