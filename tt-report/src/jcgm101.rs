//! `report --jcgm101` (issue 34 item 3 in the report): the JCGM 101 Monte Carlo of every
//! specification ([`tt_lab::budget_mc`], the call `check-turntable` and `end-to-end` make) over
//! the same tolerances as the GUM budgets of the specifications section (the direct
//! allocation's box under the study's reading), rendered as a subsection under that section,
//! a figure of the intervals against each limit, and the `jcgm101` key of `results.json`
//! ([`tt_lab::budget_mc::Jcgm101Json`], the commands' `--json` shape). Without the option
//! nothing here adds a byte to the report.

use crate::compute::Computed;
use crate::render::Sections;
use crate::{Error, Result, doc, figures};
use e2e_verify::EndToEnd;
use e2e_verify::budget::PlanVerdict;
use serde_json::Value;
use study::Study;
use tt_core::human::{num, sig};
use tt_lab::budget_mc::{Jcgm101, Jcgm101Json, MC_RULE, Options};

/// The name of the figure of the intervals against the limits.
pub(crate) const FIGURE: &str = "jcgm101_intervals.svg";

/// The Monte Carlo of `decision`'s specifications when `options` asks for it (`--jcgm101`)
/// and the study has specifications; `None` otherwise. `seed` is the report's seed (the
/// study's unless `--seed`), as `check-turntable --seed` seeds it.
///
/// # Errors
/// As [`tt_lab::budget_mc::compute`] (an input error naming `--mc-digits`).
pub(crate) fn compute(
    s: &Study,
    e2e: &EndToEnd,
    decision: Option<&(Vec<f64>, PlanVerdict)>,
    options: Option<&Options>,
    seed: u64,
) -> Result<Option<Jcgm101>> {
    let (Some(o), Some((ub_rad, verdict))) = (options, decision) else {
        return Ok(None);
    };
    let o = Options {
        seed: Some(o.seed.unwrap_or(seed)),
        ..*o
    };
    Ok(Some(tt_lab::budget_mc::compute(
        s, e2e, ub_rad, verdict, &o,
    )?))
}

/// The reproducing command's flags of the option (empty without it).
pub(crate) fn flags(c: &Computed) -> String {
    match &c.options.jcgm101 {
        Some(o) => format!(" --jcgm101 --mc-digits {}", o.significant_digits),
        None => String::new(),
    }
}

/// `results.json` gains `jcgm101` (the commands' `--json` key) when the Monte Carlo ran.
///
/// # Errors
/// [`Error::Internal`] for a non-finite figure (nothing is written).
pub(crate) fn add_results(c: &Computed, json: &mut Value) -> Result<()> {
    let (Some(mc), Some(map)) = (&c.jcgm101, json.as_object_mut()) else {
        return Ok(());
    };
    let view = Jcgm101Json::new(&c.study, mc);
    let finite = view.specifications.iter().all(|j| {
        [
            j.mean,
            j.standard_uncertainty,
            j.numerical_tolerance,
            j.symmetric_interval[0],
            j.symmetric_interval[1],
            j.shortest_interval[0],
            j.shortest_interval[1],
        ]
        .iter()
        .all(|v| v.is_finite())
    });
    if !finite {
        return Err(Error::Internal(format!(
            "a non-finite Monte Carlo figure reached the report of {}; nothing was written",
            c.study.path
        )));
    }
    map.insert("jcgm101".into(), serde_json::to_value(view)?);
    Ok(())
}

/// The subsection (after the specifications section, so under it): one table row per
/// specification, the headline with its rule, the figure. A note when the option was given
/// to a study without specifications; nothing without the option.
///
/// # Errors
/// When the figure cannot be drawn.
pub(crate) fn section(sec: &mut Sections<'_>) -> Result<()> {
    let c = sec.c;
    if c.options.jcgm101.is_none() {
        return Ok(());
    }
    let Some(mc) = &c.jcgm101 else {
        sec.doc.h(2, "JCGM 101 Monte Carlo");
        sec.doc.p(
            "Not run: the study gives no `[[specifications]]`, so there is no quantity to draw.",
        );
        return Ok(());
    };
    let s = &c.study;
    let j = Jcgm101Json::new(s, mc);
    sec.doc.h(3, "JCGM 101 Monte Carlo of each specification");
    sec.doc.p(format!(
        "The same specifications over the same tolerances, by the Monte Carlo method of JCGM 101 (as `ttalloc end-to-end --jcgm101` states it): each table error drawn from its law on its tolerance and propagated through the exact chain, each noise term drawn with the budget's standard uncertainty, the estimator run on every trial. The adaptive procedure (JCGM 101 7.9) stops when {} significant digits of u(y) are stable; seed {}. Each row: the mean and u(y) of the quantity, the probabilistically symmetric and the shortest coverage intervals at the specification's coverage probability, the trials, whether the run stabilized, whether the GUM interval 0 ± U is validated against the symmetric interval at the numerical tolerance δ (JCGM 101 8.2), and the verdict. Rule: {}.",
        j.significant_digits,
        j.seed,
        doc::text(MC_RULE),
    ));
    let interval = |v: [f64; 2]| format!("[{}, {}]", sig(v[0], 4), sig(v[1], 4));
    let rows = j
        .specifications
        .iter()
        .map(|m| {
            let u = doc::text(&m.unit);
            vec![
                doc::text(&m.quantity),
                format!("{} {u}", sig(m.mean, 4)),
                format!("{} {u}", sig(m.standard_uncertainty, 4)),
                format!("{} {u}", interval(m.symmetric_interval)),
                format!("{} {u}", interval(m.shortest_interval)),
                format!("{}%", num(100.0 * m.coverage)),
                m.trials.to_string(),
                if m.stabilized { "yes" } else { "**no**" }.to_string(),
                format!(
                    "{} (δ = {} {u})",
                    if m.gum_validated { "yes" } else { "**no**" },
                    sig(m.numerical_tolerance, 2)
                ),
                format!("{} {u}", num(m.limit)),
                if m.meets {
                    "meets"
                } else {
                    "**does NOT meet**"
                }
                .to_string(),
            ]
        })
        .collect();
    sec.doc.table(
        &[
            "quantity",
            "mean",
            "u(y)",
            "symmetric interval",
            "shortest interval",
            "p",
            "trials",
            "stabilized",
            "GUM validated",
            "limit",
            "verdict",
        ],
        rows,
    );
    sec.doc.p(doc::text(&tt_lab::budget_mc::headline(mc)));
    let svg = intervals_figure(&j, c)?;
    let id = sec.doc.figure(
        FIGURE,
        "Per specification, in percent of its limit: the GUM budget's expanded uncertainty U and the largest end (in magnitude) of the Monte Carlo's symmetric and shortest coverage intervals; the red line is the limit. A specification is met by the Monte Carlo's rule when its symmetric bar ends at or before the line.",
        svg,
    );
    sec.figure_ids.push(("jcgm101", id));
    Ok(())
}

/// The figure: per specification, U and each interval's largest end as a share of the limit.
fn intervals_figure(j: &Jcgm101Json, c: &Computed) -> Result<String> {
    let gum = c
        .decision
        .as_ref()
        .map(|(_, v)| tt_lab::vendor::spec::SpecVerdictJson::new(&c.study, Some(v)));
    let reach = |v: [f64; 2]| v[0].abs().max(v[1].abs());
    let categories: Vec<String> = j
        .specifications
        .iter()
        .map(|m| m.quantity.clone())
        .collect();
    let pct = |v: f64, limit: f64| {
        if limit > 0.0 { 100.0 * v / limit } else { 0.0 }
    };
    // one run per specification in the study's order, as the budgets
    let gum_u: Vec<f64> = j
        .specifications
        .iter()
        .enumerate()
        .map(|(i, m)| {
            gum.as_ref()
                .and_then(|g| g.specifications.get(i))
                .map_or(0.0, |g| pct(g.expanded, m.limit))
        })
        .collect();
    let series = vec![
        ("GUM: U".to_string(), gum_u),
        (
            "Monte Carlo: symmetric interval".to_string(),
            j.specifications
                .iter()
                .map(|m| pct(reach(m.symmetric_interval), m.limit))
                .collect(),
        ),
        (
            "Monte Carlo: shortest interval".to_string(),
            j.specifications
                .iter()
                .map(|m| pct(reach(m.shortest_interval), m.limit))
                .collect(),
        ),
    ];
    figures::hbar_figure_with_limit(
        "GUM U and the Monte Carlo coverage intervals against each limit",
        &categories,
        &series,
        "largest |end| in percent of the limit",
        Some(("the limit (100 %)", 100.0)),
    )
}
