//! The direct allocation against the study's specifications (issue 34 item 6): the rows
//! each specification adds beside every output's accuracy
//! ([`e2e_verify::BudgetQuestions::specification_rows`]), with the verdict's law, noise and timing,
//! and the specifications no table can meet because their noise part alone fills the limit
//! (an answer, not an error).

use crate::Result;
use e2e_verify::EndToEnd;
use e2e_verify::budget::SpecificationContext;
use study::Study;

/// The specifications the direct allocation holds.
#[derive(Debug, Clone, Default)]
pub struct SpecifiedAllocation {
    /// The context of the specifications that leave the table some room (`None` when the
    /// study gives none, or none leaves room).
    pub context: Option<SpecificationContext>,
    /// Per specification whose noise part alone fills its limit: "no table suffices for
    /// `<spec>`: noise alone is X >= the limit L" (the study's names unescaped).
    pub no_table_suffices: Vec<String>,
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
            no_table_suffices.push(e.to_string());
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

/// The context of `specs` for `s` (its simulator `e2e`): the verdict's law
/// (`uncertainty.tolerance_distribution`), the study's noise and timing.
///
/// # Errors
/// The law's error for a unit tolerance (reported as the study's input).
pub(crate) fn context_of(
    s: &Study,
    e2e: &EndToEnd,
    specs: &[gw_model::spec::Specification],
) -> Result<SpecificationContext> {
    let law = s.uncertainty.tolerance_distribution;
    SpecificationContext::new(
        specs,
        &e2e.error_names(),
        |n, a| law.input(n, a),
        &s.noise,
        s.timing.as_ref(),
    )
    .map_err(|e| crate::error::library(e, s))
}
