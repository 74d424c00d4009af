//! The yield counted against the specifications (issue 34): a turntable drawn from a box
//! meets when every output's accuracy (eq 14) holds **and** every specification row
//! ([`SpecificationRow`]) holds in the direct allocation's own convention: the quantity's
//! table part on the exact chain (the least-squares estimate's error for this draw,
//! [`EndToEnd::coefficient_errors`], or eq 14's error at the row's position,
//! [`EndToEnd::error_vectors`]) within the limit less the budget's noise part,
//! $|q(\boldsymbol\chi)| \le L - k\,u_{\text{noise}}$ ([`SpecificationRow::room`]). A
//! specification meets when every one of its rows does.
//!
//! The draws are those of [`crate::MonteCarloQuestions::meeting_count`] (the same streams and
//! chunks: seeded, the same answer for any thread count, memory independent of the count); the
//! per-draw scratch space is the JCGM 101 Monte Carlo's ([`crate::budget_mc`]).

use crate::budget::SpecificationRow;
use crate::budget_mc::Scratch;
use crate::error::E2eError;
use crate::montecarlo::{McSettings, YieldCount};
use crate::simulate::EndToEnd;
use mc_verify::ErrorBox;
use tt_kinematics::ScheduleErrorModel;

/// What the yield of a specified allocation counts (the verdict's words).
pub const SPECIFIED_YIELD_COUNTS: &str = "draws meeting every accuracy and every specification";

/// What the yield of an allocation without specifications counts.
pub const ACCURACY_YIELD_COUNTS: &str = "draws meeting every accuracy";

/// A seeded count of turntables drawn from a box against every accuracy and (with
/// specifications) every specification: the re-measured count of
/// [`crate::ReadingAnswer::yield_recheck`] and the design count of a yield-based allocation
/// ([`crate::YieldAllocation::counted`]).
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct SpecifiedCount {
    /// The draws, their seed, those meeting every accuracy and every specification
    /// (`meeting`) and those meeting each output's accuracy (`meeting_per_output`, where
    /// counted).
    #[cfg_attr(feature = "serde", serde(flatten))]
    pub(crate) count: YieldCount,
    /// Per specification (study order): its label with its unit, and the draws meeting it;
    /// empty without specifications.
    #[cfg_attr(feature = "serde", serde(skip_serializing_if = "Vec::is_empty"))]
    pub(crate) per_specification: Vec<(String, u64)>,
}

impl SpecifiedCount {
    /// The draws, their seed, those meeting every accuracy and every specification
    /// ([`YieldCount::meeting`]) and those meeting each output's accuracy.
    #[must_use]
    pub fn count(&self) -> &YieldCount {
        &self.count
    }

    /// Per specification (study order): its label with its unit (`gx bg_x (bias) in
    /// deg_per_h`) and the draws meeting it; empty without specifications.
    #[must_use]
    pub fn per_specification(&self) -> &[(String, u64)] {
        &self.per_specification
    }

    /// What [`SpecifiedCount::count`] counts: [`SPECIFIED_YIELD_COUNTS`] with
    /// specifications, [`ACCURACY_YIELD_COUNTS`] without.
    #[must_use]
    pub fn counts(&self) -> &'static str {
        if self.per_specification.is_empty() {
            ACCURACY_YIELD_COUNTS
        } else {
            SPECIFIED_YIELD_COUNTS
        }
    }
}

/// The rows of every specification, evaluated per draw.
pub(crate) struct SpecCheck<'a, S: ScheduleErrorModel> {
    e2e: &'a EndToEnd<S>,
    rows: &'a [SpecificationRow],
    offsets: Vec<usize>,
    needs_coefficients: bool,
    needs_vectors: bool,
    labels: Vec<String>,
}

/// One chunk's scratch space: the chain's and the specifications met by the draw.
pub(crate) struct SpecScratch {
    draw: Scratch,
    met: Vec<bool>,
}

impl<S: ScheduleErrorModel> EndToEnd<S> {
    /// The index of each output's first coefficient in [`EndToEnd::coefficient_errors`].
    pub(crate) fn coefficient_offsets(&self) -> Vec<usize> {
        let mut offsets = Vec::with_capacity(self.n_outputs());
        let mut next = 0;
        for o in self.calibration().outputs() {
            offsets.push(next);
            next += o.output().estimated().count();
        }
        offsets
    }
}

impl<'a, S: ScheduleErrorModel + Sync> SpecCheck<'a, S> {
    /// The check of `rows` (not empty) on `e2e`.
    pub(crate) fn new(e2e: &'a EndToEnd<S>, rows: &'a [SpecificationRow]) -> Self {
        let n_specs = rows.iter().map(|r| r.spec() + 1).max().unwrap_or(0);
        let mut labels = vec![String::new(); n_specs];
        for r in rows {
            if labels[r.spec()].is_empty() {
                labels[r.spec()] = format!("{} in {}", r.label(), r.unit());
            }
        }
        Self {
            e2e,
            rows,
            offsets: e2e.coefficient_offsets(),
            needs_coefficients: rows.iter().any(|r| r.weights().is_some()),
            needs_vectors: rows.iter().any(|r| r.weights().is_none()),
            labels,
        }
    }

    fn scratch(&self) -> SpecScratch {
        SpecScratch {
            draw: Scratch::new(self.e2e),
            met: vec![true; self.labels.len()],
        }
    }

    /// The largest ratio of a row's table part to its room at `chi` (`s.met` set per
    /// specification): at most 1 when every specification is met.
    fn evaluate(&self, s: &mut SpecScratch, index: u64, chi: &[f64]) -> Result<f64, E2eError> {
        let failed = |e: E2eError| E2eError::Draw {
            sample: index,
            reason: e.to_string(),
        };
        if self.needs_coefficients {
            s.draw.coefficients_at(self.e2e, chi).map_err(failed)?;
        }
        if self.needs_vectors {
            s.draw.vectors_at(self.e2e, chi).map_err(failed)?;
        }
        s.met.fill(true);
        let mut ratio: f64 = 0.0;
        for r in self.rows {
            let v = r
                .exact(&s.draw.coefficients, &self.offsets, &s.draw.vectors)
                .abs();
            if !v.is_finite() {
                return Err(E2eError::Draw {
                    sample: index,
                    reason: format!("non-finite error of specification {}", r.label()),
                });
            }
            if v > r.room() {
                s.met[r.spec()] = false;
            }
            ratio = ratio.max(v / r.room());
        }
        Ok(ratio)
    }

    /// The draws of `settings` from `bounds` meeting every accuracy and every specification,
    /// and each specification.
    ///
    /// # Errors
    /// As [`crate::MonteCarloQuestions::meeting_count`]; [`E2eError::Draw`] naming the first
    /// draw whose specified quantity cannot be computed.
    pub(crate) fn count(
        &self,
        bounds: &ErrorBox,
        settings: &McSettings,
    ) -> Result<SpecifiedCount, E2eError> {
        let acc = self.e2e.accuracies();
        let outputs = acc.len();
        let specs = self.labels.len();
        // (meeting every limit, per output, per specification)
        type Tally = (u64, Vec<u64>, Vec<u64>);
        let (meeting, per_output, per_spec): Tally = self.e2e.drive_with(
            bounds,
            settings,
            || self.scratch(),
            || (0, vec![0; outputs], vec![0; specs]),
            |(all, per_output, per_spec), s, index, chi, dw| {
                self.evaluate(s, index, chi)?;
                let mut every = true;
                for ((v, a), m) in dw.iter().zip(&acc).zip(per_output.iter_mut()) {
                    if v <= a {
                        *m += 1;
                    } else {
                        every = false;
                    }
                }
                for (met, m) in s.met.iter().zip(per_spec.iter_mut()) {
                    if *met {
                        *m += 1;
                    } else {
                        every = false;
                    }
                }
                if every {
                    *all += 1;
                }
                Ok(())
            },
            |a, b| {
                a.0 += b.0;
                for (x, y) in a.1.iter_mut().zip(&b.1) {
                    *x += y;
                }
                for (x, y) in a.2.iter_mut().zip(&b.2) {
                    *x += y;
                }
            },
        )?;
        Ok(SpecifiedCount {
            count: YieldCount::new(settings.samples, settings.seed, meeting, per_output),
            per_specification: self.labels.iter().cloned().zip(per_spec).collect(),
        })
    }

    /// The exact empirical $p$-quantile of $r = \max(\max_k \Delta\omega_k/\omega_{m,k},
    /// \max_{\text{rows}} |q|/(L - k\,u_{\text{noise}}))$ over the draws of `settings`
    /// ([`crate::MonteCarloQuestions::ratio_quantile`] with the specification rows): a draw
    /// meets every limit when $r \le 1$, and $r$ is homogeneous of degree 1 in $\chi$ to
    /// first order, so the yield's fixed point applies unchanged.
    ///
    /// # Errors
    /// As [`SpecCheck::count`]; as [`crate::MonteCarloQuestions::ratio_quantile`].
    pub(crate) fn ratio_quantile(
        &self,
        bounds: &ErrorBox,
        settings: &McSettings,
        p: f64,
    ) -> Result<f64, E2eError> {
        let acc = self.e2e.accuracies();
        self.e2e.monte_carlo().ratio_quantile_by(
            bounds,
            settings,
            p,
            || self.scratch(),
            |s, index, chi, dw| {
                let rows = self.evaluate(s, index, chi)?;
                Ok(dw.iter().zip(&acc).fold(rows, |m, (v, a)| m.max(v / a)))
            },
        )
    }
}
