//! The text of the angle-dependent parts (`check-turntable`, `allocate`, `end-to-end`): the
//! check with errors that vary with the shaft angle, the compensated check, a sheet's pairs
//! allocated as discs. The results and their JSON views: [`tt_lab::vendor::angle`].

use e2e_verify::{DirectAllocation, EndToEnd, TurntableCheck, Verdict};
use tt_core::human::num;
use tt_kinematics::ErrorVariation;
pub(crate) use tt_lab::vendor::angle::*;

fn describe(v: &ErrorVariation) -> String {
    match v {
        ErrorVariation::Constant => "constant".into(),
        ErrorVariation::Harmonics { joint, orders } => format!("harmonics {:?} of {joint}", orders),
        ErrorVariation::Any { joint } => format!("any function of {joint}"),
    }
}

fn model_words(a: &AngleCheck) -> &'static str {
    if a.study_model {
        "the study's angle-dependent model"
    } else {
        "every error any function of its shaft's angle, bounded over the whole revolution (what a sheet that bounds each error over the revolution supports)"
    }
}

/// The block printed after a reading's constant-model check.
#[must_use]
pub(crate) fn text(
    e2e: &EndToEnd,
    constant: &TurntableCheck,
    constant_counted: Verdict,
    a: &ReadingAngle,
    model: &AngleCheck,
) -> String {
    let mut s = format!("  angle-dependent errors ({}):\n", model_words(model));
    for (o, counted) in a.outputs.iter().zip(&a.output_verdicts) {
        let out = e2e.calibration().outputs()[o.output()].output();
        let ratio = if o.constant_linear_bound() > 0.0 {
            format!(
                " ({:.2}x the constant model's {})",
                o.linear_bound() / o.constant_linear_bound(),
                num(o.constant_linear_bound())
            )
        } else {
            String::new()
        };
        let verdict = match &model.noise {
            Some(n) => format!(
                "table alone {}; with the noise part {} {u} ({} sigma) added: {}",
                o.verdict().name(),
                num(n.margin(o.output())),
                num(n.k_sigma),
                counted.name(),
                u = out.unit,
            ),
            None => counted.name().to_string(),
        };
        s.push_str(&format!(
            "    output {}: worst case linearised {} {u}{ratio}, {} {u} on the exact chain at the worst errors found{}: {verdict}\n",
            out.name,
            num(o.linear_bound()),
            num(o.exact_at_vertex()),
            o.second_order_bound()
                .map_or(String::new(), |t| format!(", proven below {}", num(o.linear_bound() + t))),
            u = out.unit,
        ));
    }
    let (lo, hi) = a.yield_.count().interval_95();
    let yield_words = format!(
        "Monte Carlo yield {:.2}% (95% interval {:.2}%-{:.2}%, {} turntables{})",
        100.0 * a.yield_.count().fraction(),
        100.0 * lo,
        100.0 * hi,
        a.yield_.count().samples(),
        if model.noise.is_some() {
            "; the table's part alone, no noise drawn"
        } else {
            ""
        }
    );
    match (&model.noise, a.table_verdict) {
        (Some(n), Some(table)) => s.push_str(&format!(
            "    verdict ({}): constant errors {}, angle-dependent errors {}; table alone: constant errors {}, angle-dependent errors {}; {yield_words}\n",
            n.rule(),
            constant_counted.name(),
            a.verdict.name(),
            constant.verdict().name(),
            table.name(),
        )),
        _ => s.push_str(&format!(
            "    verdict: constant errors {}, angle-dependent errors {}; {yield_words}\n",
            constant_counted.name(),
            a.verdict.name(),
        )),
    }
    if let Some(d) = &a.disc {
        for o in &a.outputs {
            let out = e2e.calibration().outputs()[o.output()].output();
            s.push_str(&format!(
                "    output {}, the sheet's magnitudes as discs (sqrt(a_x^2 + a_y^2) <= w), not squares: linearised worst case {} {u} with constant errors (square {}), {} {u} with angle-dependent errors (square {})\n",
                out.name,
                num(d.constant[o.output()]),
                num(constant.outputs()[o.output()].worst_case().linear_bound()),
                num(d.angle[o.output()]),
                num(o.linear_bound()),
                u = out.unit,
            ));
        }
    }
    if let Some(d) = &a.disc {
        let (lo, hi) = d.yield_.count().interval_95();
        let (clo, chi) = d.constant_yield.count().interval_95();
        s.push_str(&format!(
            "    Monte Carlo with every pair drawn in its disc: yield {:.2}% (95% interval {:.2}%-{:.2}%, {} turntables) with angle-dependent errors, {:.2}% ({:.2}%-{:.2}%) with constant errors\n",
            100.0 * d.yield_.count().fraction(),
            100.0 * lo,
            100.0 * hi,
            d.yield_.count().samples(),
            100.0 * d.constant_yield.count().fraction(),
            100.0 * clo,
            100.0 * chi,
        ));
        if let Some(al) = &d.allocation {
            s.push_str(&disc_allocation_text(e2e, al));
        }
    }
    let names = e2e.turntable().rotation_error_names();
    for g in e2e.turntable().error_groups() {
        let models: Vec<&ErrorVariation> = g.errors.iter().map(|&i| &model.variations[i]).collect();
        if g.errors.len() > 1 && models.iter().any(|m| *m != models[0]) {
            s.push_str(&format!(
                "    {}: one rotation when the errors are constant, distinct once they vary with the shaft angle ({})\n",
                g.names(&names).join(" and "),
                g.errors
                    .iter()
                    .map(|&i| format!("{} {}", names[i], describe(&model.variations[i])))
                    .collect::<Vec<_>>()
                    .join(", ")
            ));
        }
    }
    s.push_str(if model.study_model {
        "    the study declares how its errors vary: its model is the one to trust\n"
    } else {
        "    a sheet that bounds each error over the whole revolution supports the angle-dependent verdict; the constant one holds only for a table whose errors do not vary with the shaft angle\n"
    });
    s
}

fn j_words(d: &DirectAllocation) -> String {
    if d.no_bound_needed() {
        "no bound needed".into()
    } else {
        format!("J = {}", tt_core::human::sig(d.objective_arcmin(), 5))
    }
}

fn certified_words(d: &std::result::Result<DirectAllocation, String>) -> String {
    match d {
        Ok(d) => format!("certified {}", j_words(d)),
        Err(why) => format!("not certified: {why}"),
    }
}

/// The text of the allocations with one tolerance per pair.
pub(crate) fn disc_allocation_text(e2e: &EndToEnd, al: &DiscAllocation) -> String {
    let names = e2e.turntable().rotation_error_names();
    let arcmin = |u: f64| {
        if u.is_finite() {
            tt_core::human::sig(tt_core::units::rad_to_arcmin(u), 4)
        } else {
            "none".into()
        }
    };
    let mut s = format!(
        "    allocation with one tolerance per pair of the sheet (arcmin^-2): constant errors {} as discs, {} as squares; angle-dependent errors {} as discs ({}), {} as squares ({})\n",
        j_words(&al.constant_disc),
        j_words(&al.constant_square),
        j_words(&al.angle_disc),
        certified_words(&al.angle_disc_certified),
        j_words(&al.angle_square),
        certified_words(&al.angle_square_certified),
    );
    let mut seen = vec![false; names.len()];
    let mut parts = Vec::new();
    for (j, u) in al.angle_disc.upper_bounds_rad().iter().enumerate() {
        if seen[j] {
            continue;
        }
        let partner = (j + 1..names.len()).find(|&b| {
            !seen[b]
                && al.angle_disc.upper_bounds_rad()[b].to_bits() == u.to_bits()
                && al.angle_square.upper_bounds_rad()[b].to_bits()
                    == al.angle_square.upper_bounds_rad()[j].to_bits()
                && al.constant_disc.upper_bounds_rad()[b].to_bits()
                    == al.constant_disc.upper_bounds_rad()[j].to_bits()
        });
        seen[j] = true;
        let label = match partner {
            Some(b) => {
                seen[b] = true;
                format!("{}/{}", names[j], names[b])
            }
            None => names[j].to_string(),
        };
        parts.push(format!(
            "{label} {} (square {})",
            arcmin(*u),
            arcmin(al.angle_square.upper_bounds_rad()[j])
        ));
    }
    s.push_str(&format!(
        "      angle-dependent bounds as discs (arcmin): {}\n",
        parts.join(", ")
    ));
    s
}

/// The sheet allocations' text block.
#[must_use]
pub(crate) fn sheet_allocations_text(path: &str, a: &[(EndToEnd, DiscAllocation)]) -> String {
    if a.is_empty() {
        return format!(
            "\n{path} states no magnitude (wobble, orthogonality): no pair of errors to allocate one tolerance\n"
        );
    }
    let mut t = format!(
        "\nthe pairs of {path} (each wobble and orthogonality one tolerance, a magnitude sqrt(a_x^2 + a_y^2) <= w, beside the square around it):\n"
    );
    for (e2e, al) in a {
        t.push_str(&format!("reading {}\n", e2e.reading()));
        t.push_str(&disc_allocation_text(e2e, al));
    }
    t
}

/// The compensated block of the text: per reading, the verdicts before and after, every
/// modelled source counted (`before_counted`: the main check's verdict of each reading, the
/// noise counted).
#[must_use]
pub(crate) fn compensated_text(
    checks: &[(EndToEnd, TurntableCheck)],
    c: &Compensated,
    before_counted: &[Verdict],
) -> String {
    let mut s = String::from(
        "\ncompensated (the study's measured errors are known inputs of the chain; the bound that matters is their measurement uncertainty, or the sheet's bound plus the measured value's magnitude when that is smaller):\n",
    );
    for n in &c.notes {
        s.push_str(&format!("  note: {n}\n"));
    }
    let noise = c.angle.noise.as_ref();
    for ((((e2e, before), after), aa), counted) in checks
        .iter()
        .zip(&c.checks)
        .zip(&c.angle.readings)
        .zip(before_counted)
    {
        s.push_str(&format!("reading {}\n", e2e.reading()));
        for (o, a) in before.outputs().iter().zip(after.outputs()) {
            let out = e2e.calibration().outputs()[o.output()].output();
            s.push_str(&format!(
                "  output {}: worst case linearised {} {u} before, {} {u} after compensation (constant errors); {} {u} after (angle-dependent errors)\n",
                out.name,
                num(o.worst_case().linear_bound()),
                num(a.worst_case().linear_bound()),
                num(aa.outputs[o.output()].linear_bound()),
                u = out.unit,
            ));
        }
        match (noise, aa.table_verdict) {
            (Some(n), Some(table)) => s.push_str(&format!(
                "  verdict ({}): before {}; after compensation: {} (constant errors), {} (angle-dependent errors); table alone: before {}, after {} (constant errors), {} (angle-dependent errors)\n",
                n.rule(),
                counted.name(),
                constant_counted(after, noise).name(),
                aa.verdict.name(),
                before.verdict().name(),
                after.verdict().name(),
                table.name(),
            )),
            _ => s.push_str(&format!(
                "  verdict before: {}; after compensation: {} (constant errors), {} (angle-dependent errors)\n",
                counted.name(),
                after.verdict().name(),
                aa.verdict.name()
            )),
        }
    }
    s
}
