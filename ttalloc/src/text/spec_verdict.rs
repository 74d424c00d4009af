//! The text of the verdict against the study's specifications (`check-turntable`,
//! `end-to-end`, the report): every verdict names its rule. The verdict and its JSON view:
//! [`tt_lab::vendor::spec`].

use e2e_verify::budget::{ACCURACY_RULE, PlanVerdict};
use study::Study;
pub(crate) use tt_lab::vendor::spec::*;

/// The verdict as text: one line per specification, then the headline with the rule
/// (`what` names the tolerances: "these tolerances", "the direct allocation's box").
#[must_use]
pub(crate) fn text(s: &Study, v: Option<&PlanVerdict>, what: &str) -> String {
    let Some(v) = v else {
        return format!("  decision rule: {ACCURACY_RULE}\n");
    };
    let mut t = format!("\nspecifications of the study, {what}:\n");
    for i in 0..v.budgets().len() {
        t.push_str(&format!("  {}\n", spec_line(s, v, i)));
    }
    t.push_str(&format!("  {}\n", headline(s, v)));
    t
}

/// What bounds a direct allocation held against the specifications: "limited by: <spec>
/// (<unit>)" for the specification rows at their limit, and each specification no table can
/// meet (its noise part alone fills it). Empty when the allocation holds no specification.
#[must_use]
pub(crate) fn limited_by(
    d: &e2e_verify::DirectAllocation,
    no_table_suffices: &[tt_lab::allocation::spec::NoTableSuffices],
) -> String {
    let mut t = String::new();
    if !d.spec_loads().is_empty() {
        let binding = d.limited_by();
        t.push_str(&format!(
            "  the direct allocation holds every specification{} beside each output's accuracy; limited by: {}\n",
            if no_table_suffices.is_empty() {
                ""
            } else {
                " a table can meet"
            },
            if binding.is_empty() {
                "the outputs' accuracies (eq 14) only".to_string()
            } else {
                binding
                    .iter()
                    .map(|b| tt_core::human::visible(b).into_owned())
                    .collect::<Vec<_>>()
                    .join(", ")
            }
        ));
    }
    for n in no_table_suffices {
        t.push_str(&format!(
            "  {} (left out of the direct and the yield-based allocations)\n",
            tt_core::human::visible(&n.to_string())
        ));
    }
    t
}
