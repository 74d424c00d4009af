//! `design-schedule --time-budget-s SECONDS [--pareto-svg PATH]`: the positions and the dwell
//! chosen together under a total test-time budget with the noise counted
//! ([`tt_lab::design::budget`]); the Pareto front of total test time against J as a table and
//! a figure (its JSON, `time_budget` and `pareto`, is the library's view).

use crate::report::figures::{self, LIMIT, LinePanel, Mark, Series, colour};
use anyhow::Result;
use schedule_design::{BudgetDesign, BudgetPoint};
use study::Study;
use tt_core::human::{num, sig};
use tt_lab::design::budget::{Budgeted, NOISELESS_NOTE, origin, tolerances_text};

/// The budget's answer in words, with the Pareto front as a table.
pub(crate) fn text(s: &Study, b: &Budgeted) -> String {
    let d = match b {
        Budgeted::Noiseless { budget_s } => {
            return format!("time budget {} s: {NOISELESS_NOTE}\n\n", num(*budget_s));
        }
        Budgeted::Design(d) => d,
    };
    let mut t = format!(
        "time budget {} s ({} h; total = positions x (dwell + move)), noise counted at {} sigma: {} schedules at {} dwells each (J of the direct allocation with the noise part kept free, as end-to-end's trade-off)\n",
        num(d.budget_s()),
        sig(d.budget_s() / 3600.0, 4),
        num(d.k_sigma()),
        d.schedules().len(),
        d.dwells_s().len()
    );
    t.push_str(&format!(
        "  every proposed point keeps at least {} positions: the fewest that identify every output plus a redundancy of {} (--redundancy; the study's own schedule is evaluated whatever its count){}\n",
        d.fewest_positions(),
        d.redundancy(),
        if s.has_rate_steps() {
            "; every total counts the rate steps' whole-revolution windows and a move before each"
        } else {
            ""
        }
    ));
    t.push_str(&format!(
        "  numbers of positions designed for: {}{}\n",
        d.counts()
            .iter()
            .map(ToString::to_string)
            .collect::<Vec<_>>()
            .join(", "),
        if d.counts_skipped().is_empty() {
            String::new()
        } else {
            format!(
                " (no schedule within the condition bound found for {})",
                d.counts_skipped()
                    .iter()
                    .map(ToString::to_string)
                    .collect::<Vec<_>>()
                    .join(", ")
            )
        }
    ));
    match &d.chosen() {
        Some(p) => t.push_str(&format!(
            "  within the budget: {} positions x {} s ({} s in all), J = {} arcmin^-2 ({}); certified on the exact chain: {}\n",
            p.n_positions(),
            sig(p.dwell_s(), 4),
            sig(p.total_s(), 4),
            sig(p.objective_arcmin(), 6),
            origin(p.origin()),
            d.chosen_certified_arcmin()
                .map_or("no table suffices".to_string(), |j| format!("J = {}", sig(j, 6)))
        )),
        None => t.push_str(&match d.pareto().first() {
            Some(p) => format!(
                "  within the budget no table suffices (the noise fills an accuracy); the shortest test at which one does: {} s ({} positions x {} s)\n",
                sig(p.total_s(), 4),
                p.n_positions(),
                sig(p.dwell_s(), 4)
            ),
            None => format!(
                "  no table suffices at any dwell up to {} s per position: the noise fills an accuracy\n",
                num(study::limits::DWELL_S.1)
            ),
        }),
    }
    if !d.pareto().is_empty() {
        let names = s.turntable.rotation_error_names();
        t.push_str(&format!(
            "  Pareto front (the cheapest table for each total test time; outputs {}; under each point its tolerance box, the direct allocation with the noise part kept free):\n",
            s.sensor
                .outputs()
                .iter()
                .map(|o| o.name.as_str())
                .collect::<Vec<_>>()
                .join(", ")
        ));
        t.push_str(&format!(
            "  {:>12} {:>10} {:>12} {:>14}  {}\n",
            "total (s)", "positions", "dwell (s)", "J (arcmin^-2)", "schedule"
        ));
        for p in d.pareto() {
            t.push_str(&format!(
                "  {:>12} {:>10} {:>12} {:>14}  {}{}\n",
                sig(p.total_s(), 4),
                p.n_positions(),
                sig(p.dwell_s(), 4),
                sig(p.objective_arcmin(), 5),
                origin(p.origin()),
                if p.total_s() <= d.budget_s() {
                    ""
                } else {
                    " (over the budget)"
                }
            ));
            t.push_str(&format!(
                "  {:>12} tolerances (arcmin): {}\n",
                "",
                tolerances_text(p, &names)
            ));
        }
    }
    t.push('\n');
    t
}

/// Why `--pareto-svg` writes no figure when the front is empty (an answer, not an error).
pub(crate) const EMPTY_FRONT_NOTE: &str =
    "not written: the Pareto front is empty (no table suffices at any dwell), nothing to draw";

/// The Pareto front as a figure in the report's style (the report's line-figure code):
/// J against the total test time, both log10, with the chosen point; `None` when the front is
/// empty (no table suffices at any dwell: nothing to draw, [`EMPTY_FRONT_NOTE`]).
///
/// # Errors
/// When a value is not plottable.
pub(crate) fn svg(d: &BudgetDesign) -> Result<Option<String>> {
    if d.pareto().is_empty() {
        return Ok(None);
    }
    let xy = |p: &BudgetPoint| ((p.total_s() / 3600.0).log10(), p.objective_arcmin().log10());
    let mut series = vec![Series {
        label: "Pareto front: the cheapest table for each total test time".into(),
        points: d.pareto().iter().map(xy).collect(),
        mark: Mark::Line(colour(0), false),
    }];
    if let Some(p) = &d.chosen() {
        series.push(Series {
            label: format!(
                "chosen within the budget ({} h)",
                sig(d.budget_s() / 3600.0, 3)
            ),
            points: vec![xy(p)],
            mark: Mark::Dots(LIMIT),
        });
    }
    let panel = LinePanel {
        title: "Test time against the table's J".into(),
        x_label: "total test time, log10 (h)".into(),
        y_label: "log10 J (arcmin⁻²)".into(),
        series,
        hlines: Vec::new(),
        x_integer: false,
        y_from_zero: false,
    };
    Ok(Some(figures::line_figure(
        "Test time and the table",
        &[panel],
        1,
    )?))
}
