//! The text of the verdict against the study's specifications (`check-turntable`,
//! `end-to-end`, the report): every verdict names its rule. The verdict and its JSON view:
//! [`tt_lab::vendor::spec`].

use e2e_verify::budget::{ACCURACY_RULE, PlanVerdict};
use study::Study;
pub use tt_lab::vendor::spec::*;

/// The verdict as text: one line per specification, then the headline with the rule
/// (`what` names the tolerances: "these tolerances", "the direct allocation's box").
#[must_use]
pub fn text(s: &Study, v: Option<&PlanVerdict>, what: &str) -> String {
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
