//! The paper's extras of `reproduce-paper`: the paper's printed values beside ours, the claims
//! (evaluated by `e2e_verify::paper::registry`, each under both readings of eq 13 where the
//! verdict depends on it), and what the paper leaves open. Only this module speaks of the
//! paper's site, its printed numbers and its tables.

use crate::Doc;
use crate::compute::{Computed, PaperExtras};
use crate::render::{Sections, d, greek};
use e2e_verify::paper::registry;
use serde::Serialize;
use tt_core::human::{num, sig};
use tt_core::units::objective_to_arcmin;
use tt_core::units::rad_to_deg;

/// One printed number of the paper beside ours.
#[derive(Debug, Clone, Serialize)]
pub(crate) struct Comparison {
    /// What it is.
    pub quantity: String,
    /// The paper's value.
    pub paper: f64,
    /// Ours.
    pub ours: f64,
    /// Unit of both.
    pub unit: &'static str,
    /// Why they differ (or agree).
    pub reason: String,
}

/// The paper's printed values beside ours.
#[must_use]
pub(crate) fn comparisons(c: &Computed, x: &PaperExtras) -> Vec<Comparison> {
    let mut out = Vec::new();
    let s = &c.study;
    if let Ok(r) = &c.requirement.computed {
        for k in 0..3 {
            if let Some(v) = r.requirement().to_array()[k] {
                out.push(Comparison {
                    quantity: format!("eq 16: I_{}", greek(k)),
                    paper: alloc_opt::paper::REQUIREMENT_DEG,
                    ours: rad_to_deg(v),
                    unit: "deg",
                    reason: format!(
                        "agrees after rounding to the paper's 3 decimals; the paper gives neither latitude nor positions (we use Harbin, {} deg N, the authors' site, and a {}-position schedule)",
                        num(s.site.latitude_deg()),
                        s.positions_deg.len()
                    ),
                });
            }
        }
    }
    let names = s.turntable.rotation_error_names();
    let idx = |n: &str| names.iter().position(|m| *m == n);
    let expected = tt_kinematics::paper::figure8_expected();
    if let (Some(i), Some(j)) = (idx("dphi_y1"), idx("dalpha_x2")) {
        out.push(Comparison {
            quantity: "Figure 8: sensitivity of a sin/cos term (dphi_y1 in Δγ)".into(),
            paper: expected[2][i],
            ours: c.sensitivity[i][2],
            unit: "-",
            reason:
                "2/π, implied by eq 26 and eq 28 (the mean of |sin|); the figure prints no values"
                    .into(),
        });
        out.push(Comparison {
            quantity: "Figure 8: sensitivity of a constant term (dalpha_x2 in Δγ)".into(),
            paper: expected[2][j],
            ours: c.sensitivity[j][2],
            unit: "-",
            reason: "1, implied by eq 26 and eq 28".into(),
        });
    }
    if let Some(t) = &c.two_step {
        let ours = t.ours.upper_bounds_arcmin();
        let t4 = alloc_opt::paper::table4_rad();
        let used = alloc_opt::Certificate::compute(
            t.problem.model(),
            t.problem.limits(),
            t.problem.lower_bounds_rad(),
            &t4,
        )
        .map(|cert| {
            cert.axes()
                .iter()
                .map(|a| {
                    a.share()
                        .map_or("-".into(), |v| format!("{:.1}%", 100.0 * v))
                })
                .collect::<Vec<_>>()
                .join(" / ")
        })
        .unwrap_or_else(|e| format!("unknown: {e}"));
        for (i, n) in names.iter().enumerate() {
            out.push(Comparison {
                quantity: format!("Table 4: {n}"),
                paper: alloc_opt::paper::TABLE4_ARCMIN[i],
                ours: ours[i],
                unit: "arcmin",
                reason: format!("Table 4 uses only part of the requirement ({used}); ours is the optimum of (31)-(34), using all of it"),
            });
        }
        let w = alloc_opt::Weights::inverse_average_sensitivity(t.problem.model());
        out.push(Comparison {
            quantity: "objective J of the allocation".into(),
            paper: objective_to_arcmin(w.objective(&alloc_opt::paper::table4_rad())),
            ours: t.ours.objective_arcmin(),
            unit: "arcmin⁻²",
            reason: "the paper does not print J; its value is computed from Table 4 with the paper's weights".into(),
        });
    }
    let bound = x.table4_monte_carlo.half_range_rad();
    for (k, b) in bound.iter().enumerate() {
        if let Some(i) = x.table4_result.requirement().to_array()[k] {
            out.push(Comparison {
                quantity: format!("Figure 9: bound on |{}| of Table 4 turntables", d(k)),
                paper: rad_to_deg(i),
                ours: rad_to_deg(*b),
                unit: "deg",
                reason: format!(
                    "the paper shows every sample inside ±I; ours is the proven worst case over the whole box ({:.1}% of I); our largest of {} draws is {} deg",
                    100.0 * b / i,
                    x.table4_result.count().samples(),
                    sig(rad_to_deg(x.table4_result.axes()[k].max_abs_rad()), 5)
                ),
            });
        }
    }
    out
}

/// Where a claim is shown (a figure or a section of this report).
fn see(sec: &Sections<'_>, id: &str) -> Option<String> {
    let key = match id {
        "fig4-1" | "fig4-3" => "cuts",
        "fig4-2" => "surfaces",
        "eq16" => "lines",
        "fig8" => "sensitivities",
        "fig9" => "monte_carlo",
        "e2e" => "end_to_end",
        _ => {
            return Some("[allocation](#two-step-allocation)".into())
                .filter(|_| matches!(id, "lemma1" | "table4" | "conclusion1" | "conclusion2"));
        }
    };
    sec.figure(key).map(|f| format!("[figure](#{f})"))
}

/// The paper-versus-ours and claims sections, as their own document (spliced in near the
/// top of the report).
#[must_use]
pub(crate) fn sections(sec: &Sections<'_>, x: &PaperExtras, rows: &[Comparison]) -> Doc {
    let mut doc = Doc::default();
    doc.h(2, "Paper versus ours");
    doc.table(
        &["quantity", "paper", "ours", "difference", "unit", "reason"],
        rows.iter()
            .enumerate()
            .map(|(i, r)| {
                // a reason repeated from the row above is not printed again
                let reason = if i > 0 && rows[i - 1].reason == r.reason {
                    "as above".to_string()
                } else {
                    r.reason.clone()
                };
                vec![
                    r.quantity.clone(),
                    sig(r.paper, 6),
                    sig(r.ours, 6),
                    format!("{:+.6}", r.ours - r.paper),
                    r.unit.into(),
                    reason,
                ]
            })
            .collect(),
    );
    doc.h(2, "Claims");
    doc.p(
        "Each claim of the paper is evaluated by the library function of the crate that owns its science and proven by the named test (`cargo test -p CRATE --test paper_claims NAME`). Eq 13 is ambiguous (NOTES item 3): a claim that involves it is evaluated under both readings, the paper's (outputs simulated at the intended orientation, `intended/beta1/printed`, which reproduces §2) and the user's (outputs at the actual orientation, `actual/beta1/printed`, what a calibrating lab measures).",
    );
    doc.callout_list(
        format!("**{}** Those that do not:", registry::count_line(&x.claims)),
        registry::failing(&x.claims),
    );
    let verdict = |b: bool| {
        if b {
            "**yes**".to_string()
        } else {
            "**no**".to_string()
        }
    };
    let rows = x
        .claims
        .iter()
        .map(|c| {
            let (user, evidence) = match &c.user {
                Some(u) => (
                    verdict(u.holds),
                    format!("intended: {}. actual: {}", c.paper.evidence, u.evidence),
                ),
                None => ("same (no eq 13)".into(), c.paper.evidence.clone()),
            };
            let statement = match see(sec, c.info.id) {
                Some(link) => format!("{} ({link})", c.info.statement),
                None => c.info.statement.to_string(),
            };
            vec![
                format!("{} ({})", c.info.id, c.info.section),
                statement,
                verdict(c.paper.holds),
                user,
                evidence,
                format!("`{}`", c.info.test),
            ]
        })
        .collect();
    doc.table(
        &[
            "claim",
            "statement",
            "holds, paper's reading",
            "holds, user's reading",
            "evidence (this run)",
            "proven by",
        ],
        rows,
    );
    doc
}

/// What the paper leaves open and how the study settles it (NOTES items).
pub(crate) fn open_points(doc: &mut Doc, c: &Computed) {
    let s = &c.study;
    doc.h(2, "What the paper leaves open, and our choices");
    doc.list(vec![
        "Eq 4 is garbled and eq 2 lists D(x)_y twice: the regressors are read from eq 1 (NOTES 1-2); Table 1 labels the y-axis cross term D(y)_xy, eq 1 names it D(y)_yx (`dy_yx`).".into(),
        format!("Eq 13 is ambiguous (NOTES 3): the study uses `{}`; `cargo xtask requirement --all-readings` lists all 18 readings; the claims above are evaluated under the paper's and the user's.", s.reading),
        format!(
            "Latitude {} deg N (Harbin, the authors' site) and earth rate {} rad/s (WGS-84): not given (NOTES 8-9).",
            num(s.site.latitude_deg()),
            sig(s.site.earth_rate_rad_per_s(), 8)
        ),
        format!("Calibration positions: not given (NOTES 10); {} positions from the study file, which identify every coefficient.", s.positions_deg.len()),
        "Lower bounds LB_i: not given (NOTES 11); the study's values (0 arcmin).".into(),
        "Figure 8's values: not printed (NOTES 12); they follow from eq 26 and eq 28 (2/π and 1).".into(),
        format!(
            "Eq 16 is rounded (NOTES 13); the allocation uses eq 16 as printed ({} deg), our unrounded requirement is reported beside it.",
            alloc_opt::paper::REQUIREMENT_DEG
        ),
        "Table 4's first column is garbled (NOTES 6): rows in the order of χ in eq 25.".into(),
        "The Monte Carlo distribution is not stated (NOTES 15): |χ_i| uniform in [LB_i, UB_i], fair random signs, pose uniform.".into(),
        "Eq 24 reads angles off the elements of ΔR, exact only to first order (NOTES 7); the exact chain uses it as the paper does.".into(),
    ]);
}
