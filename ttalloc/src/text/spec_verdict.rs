//! The text of the verdict against the study's specifications (`check-turntable`,
//! `end-to-end`, the report): every verdict names its rule. The verdict and its JSON view:
//! [`tt_lab::vendor::spec`].

use e2e_verify::budget::{ACCURACY_RULE, EvaluatedAt, PLAN_RULE, PlanVerdict};
use study::Study;
use study::fmt::num;
pub use tt_lab::vendor::spec::*;

/// Where a quantity was evaluated, in words.
fn at_text(at: EvaluatedAt) -> String {
    match at {
        EvaluatedAt::Coefficient => String::new(),
        EvaluatedAt::RangeEnd { positive } => {
            format!(" (at the {} end)", if positive { "+" } else { "-" })
        }
        EvaluatedAt::Position(i) => format!(" (at test position {i})"),
    }
}

/// The outputs whose noise is not in the budgets, by name.
fn unmodelled(s: &Study, v: &PlanVerdict) -> Vec<String> {
    let mut names: Vec<String> = v
        .budgets()
        .iter()
        .filter(|b| !b.noise_modelled())
        .map(|b| {
            s.sensor.outputs()[s.specifications[b.spec()].output()]
                .name
                .clone()
        })
        .collect();
    names.dedup();
    names
}

/// The verdict line of specification `i` of `v` (plain text, the study's names unescaped):
/// the quantity, U, u_c, k, p, the limit, the ratio, the verdict, the dominant input and
/// whether the output's noise is modelled.
pub(crate) fn spec_line(s: &Study, v: &PlanVerdict, i: usize) -> String {
    let b = &v.budgets()[i];
    let sp = &s.specifications[b.spec()];
    let f = sp.to_written();
    let o = b.output();
    let dominant = o.dominant().map_or(String::new(), |d| {
        let share = o.contributions()[d].powi(2) / o.combined().powi(2);
        format!(
            "; dominant: {} ({:.0}% of the variance)",
            b.result().rows()[d].name(),
            100.0 * share
        )
    });
    let unbounded = &v.unbounded()[b.spec()];
    let verdict = if !unbounded.is_empty() {
        format!(
            "does NOT meet: not bounded ({} has no tolerance and moves it)",
            unbounded.join(", ")
        )
    } else if b.check().meets() {
        "meets".to_string()
    } else {
        "does NOT meet".to_string()
    };
    let noise = if b.noise_modelled() {
        String::new()
    } else {
        "; noise not modelled for this output: the table's errors only".to_string()
    };
    format!(
        "{}{}: U = {} {u} (u_c {}, k = {}, p = {}%) against {} {u}, ratio {}: {verdict}{dominant}{noise}",
        sp.label(&s.sensor),
        at_text(b.at()),
        num(o.expanded() * f),
        num(o.combined() * f),
        num(o.coverage_factor()),
        num(100.0 * sp.coverage()),
        num(sp.written_limit()),
        num(b.check().ratio()),
        u = sp.unit(),
    )
}

/// The headline of `v` (plain text): met or not, how many, the noise and the rule.
pub(crate) fn headline(s: &Study, v: &PlanVerdict) -> String {
    let missing = unmodelled(s, v);
    let noise = if missing.is_empty() {
        "the noise modelled for every specified output".to_string()
    } else {
        format!(
            "noise not modelled for {} (no noise model or no [calibration.timing]): the table's errors only there",
            missing.join(", ")
        )
    };
    format!(
        "verdict: {} every specification ({} of {} met); {noise}; rule: {PLAN_RULE}",
        if v.meets_all() {
            "MEETS"
        } else {
            "does NOT meet"
        },
        (0..v.budgets().len()).filter(|&i| v.meets(i)).count(),
        v.budgets().len(),
    )
}

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
