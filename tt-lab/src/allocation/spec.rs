//! The direct allocation against the study's specifications (issue 34 item 6): the rows
//! each specification adds beside every output's accuracy
//! ([`e2e_verify::BudgetQuestions::specification_rows`]), with the verdict's law, noise and timing,
//! and the specifications no table can meet because their noise part alone fills the limit
//! (an answer, not an error).

use crate::Result;
use e2e_verify::budget::SpecificationContext;
use e2e_verify::{E2eError, EndToEnd};
use study::Study;

/// The specifications the direct allocation holds.
#[derive(Debug, Clone, Default)]
pub struct SpecifiedAllocation {
    /// The context of the specifications that leave the table some room (`None` when the
    /// study gives none, or none leaves room).
    pub context: Option<SpecificationContext>,
    /// Per specification whose noise part alone fills its limit, in the study's order.
    pub no_table_suffices: Vec<NoTableSuffices>,
}

/// A specification no table can meet: its noise part alone (its coverage factor times the
/// noise's standard uncertainty at the study's dwell) fills its limit, so it is left out of the
/// direct and the yield-based allocations. Figures in the specification's unit; its
/// [`Display`](std::fmt::Display) is the sentence the text and the report list, "no table
/// suffices for `<spec>`: noise alone is X >= the limit L" (the study's names unescaped), and
/// its JSON view (`end-to-end --json` `readings[].yield_based.not_counted[]`) has the same
/// figures unrounded.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct NoTableSuffices {
    /// The specification's label (`gx bg_x (bias)`).
    specification: String,
    /// Its unit, as written (`deg_per_h`).
    unit: String,
    /// Its noise part $k\,u_{\text{noise}}$, the specification's unit.
    noise_part: f64,
    /// Its limit, the specification's unit.
    limit: f64,
}

impl NoTableSuffices {
    /// The library's error for the same specification, whose message is the sentence.
    fn error(&self) -> E2eError {
        E2eError::NoTableSuffices {
            spec: self.specification.clone(),
            noise: self.noise_part,
            limit: self.limit,
            unit: self.unit.clone(),
        }
    }
}

impl std::fmt::Display for NoTableSuffices {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        self.error().fmt(f)
    }
}

/// The specifications of `s` the direct allocation holds, with the verdict's law
/// (`uncertainty.tolerance_distribution`), noise and timing.
///
/// # Errors
/// As [`e2e_verify::BudgetQuestions::specification_rows`] (reported as the study's input).
pub fn context(s: &Study, e2e: &EndToEnd) -> Result<SpecifiedAllocation> {
    if s.specifications.is_empty() {
        return Ok(SpecifiedAllocation::default());
    }
    let make = |specs: &[gw_model::spec::Specification]| context_of(s, e2e, specs);
    let all = make(&s.specifications)?;
    let rows = e2e
        .budget()
        .specification_rows(&all)
        .map_err(|e| crate::error::library(e, s))?;
    let mut blocked = vec![false; s.specifications.len()];
    let mut no_table_suffices = Vec::new();
    for r in &rows {
        if let Err(e) = r.check_room()
            && !blocked[r.spec()]
        {
            blocked[r.spec()] = true;
            no_table_suffices.push(no_room(e, s)?);
        }
    }
    let kept: Vec<_> = s
        .specifications
        .iter()
        .zip(&blocked)
        .filter(|(_, b)| !**b)
        .map(|(sp, _)| sp.clone())
        .collect();
    let context = if kept.is_empty() {
        None
    } else if kept.len() == s.specifications.len() {
        Some(all)
    } else {
        Some(make(&kept)?)
    };
    Ok(SpecifiedAllocation {
        context,
        no_table_suffices,
    })
}

/// The figures of [`e2e_verify::budget::SpecificationRow::check_room`]'s error.
///
/// # Errors
/// Any other error of the library (a defect: `check_room` gives only that one).
fn no_room(e: E2eError, s: &Study) -> Result<NoTableSuffices> {
    match e {
        E2eError::NoTableSuffices {
            spec,
            noise,
            limit,
            unit,
        } => Ok(NoTableSuffices {
            specification: spec,
            unit,
            noise_part: noise,
            limit,
        }),
        other => Err(crate::error::library(other, s)),
    }
}

/// The context of `specs` for `s` (its simulator `e2e`): the verdict's law
/// (`uncertainty.tolerance_distribution`), the study's noise and timing
/// ([`study::Study::specification_context`]).
///
/// # Errors
/// The law's error for a unit tolerance (reported as the study's input).
pub(crate) fn context_of(
    s: &Study,
    e2e: &EndToEnd,
    specs: &[gw_model::spec::Specification],
) -> Result<SpecificationContext> {
    s.specification_context(specs, &e2e.error_names())
        .map_err(|e| crate::error::library(e, s))
}
