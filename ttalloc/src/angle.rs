//! Errors that vary with the shaft angle (issue 22) in the commands: a tolerance box checked
//! under the angle-dependent model beside the constant one.
//!
//! The model: the study's (`turntable.factors[i].varies`) when it declares one; otherwise
//! every error an arbitrary bounded function of the angle of the shaft it rides on (`any`,
//! [`tt_kinematics::on_shafts`]): what a sheet supports that bounds each error over the whole
//! revolution ("wobble <= 3 arcsec") and says nothing more. The constant model (the paper's)
//! is supported only by a table whose errors are known not to vary with the angle.

use anyhow::Result;
use e2e_verify::angle::{AngleOutputWorstCase, AngleYield};
use e2e_verify::{EndToEnd, TurntableCheck, Verdict};
use serde_json::{Value, json};
use study::Study;
use study::fmt::num;
use tt_kinematics::{ErrorVariation, Expansion};

/// The angle-dependent check of one reading.
#[derive(Debug, Clone)]
pub struct ReadingAngle {
    /// Per output.
    pub outputs: Vec<AngleOutputWorstCase>,
    /// The Monte Carlo yield under the model.
    pub yield_: AngleYield,
    /// The weakest of the outputs' verdicts.
    pub verdict: Verdict,
    /// With the sheet's magnitude bounds (discs): the linearised worst case per output.
    pub disc: Option<DiscWorst>,
}

/// The linearised worst case per output (output unit) when the sheet's magnitudes bound a disc,
/// not the square of the two components.
#[derive(Debug, Clone)]
pub struct DiscWorst {
    /// Constant errors.
    pub constant: Vec<f64>,
    /// Angle-dependent errors.
    pub angle: Vec<f64>,
}

/// The angle-dependent check of every reading (same order as the constant checks).
#[derive(Debug, Clone)]
pub struct AngleCheck {
    /// Whether the model is the study's (else `any` on every shaft).
    pub study_model: bool,
    /// Each error's model (order of chi).
    pub variations: Vec<ErrorVariation>,
    /// Per reading.
    pub readings: Vec<ReadingAngle>,
}

/// The model used: the study's, or `any` on every shaft with the models the sheet's vendor
/// quantities imply (an orthogonality is a constant).
#[must_use]
pub fn model_of(s: &Study, tol: &study::Tolerances) -> (bool, Vec<ErrorVariation>) {
    if s.has_angle_dependent_errors() {
        (true, s.variations.clone())
    } else {
        let mut v = tt_kinematics::on_shafts(&s.turntable, |j| ErrorVariation::Any {
            joint: j.to_string(),
        });
        for (x, i) in v.iter_mut().zip(&tol.implied) {
            if let Some(i) = i {
                *x = i.clone();
            }
        }
        (false, v)
    }
}

fn weakest(v: impl Iterator<Item = Verdict>) -> Verdict {
    let v: Vec<Verdict> = v.collect();
    if v.contains(&Verdict::Fails) {
        Verdict::Fails
    } else if v.iter().all(|x| *x == Verdict::Guaranteed) {
        Verdict::Guaranteed
    } else {
        Verdict::Likely
    }
}

/// Check the bounds `ub_rad` under the angle-dependent model for every simulator of
/// `checks`, with `samples` Monte Carlo turntables from `seed`.
///
/// # Errors
/// A library error located in the study.
pub fn check(
    s: &Study,
    checks: &[(EndToEnd, TurntableCheck)],
    tol: &study::Tolerances,
    samples: u64,
    seed: u64,
) -> Result<AngleCheck> {
    let ub_rad = &tol.ub_rad[..];
    let (study_model, variations) = model_of(s, tol);
    let discs: Vec<([usize; 2], f64)> = tol.discs.iter().map(|d| (d.errors, d.bound_rad)).collect();
    let mut readings = Vec::with_capacity(checks.len());
    for (e2e, _) in checks {
        let ex = Expansion::new(e2e.turntable(), &variations, e2e.poses())
            .map_err(|e| crate::input::library(e, s))?;
        let lin = e2e.linearization();
        let al = e2e
            .angle_linearization(&ex)
            .map_err(|e| crate::input::library(e, s))?;
        let outputs = e2e
            .angle_worst_case(&ex, &al, &lin, ub_rad)
            .map_err(|e| crate::input::library(e, s))?;
        let yield_ = e2e
            .angle_yield(&ex, ub_rad, samples, seed)
            .map_err(|e| crate::input::library(e, s))?;
        let verdict = weakest(outputs.iter().map(|o| o.verdict));
        let disc = if discs.is_empty() {
            None
        } else {
            let constant = Expansion::new(
                e2e.turntable(),
                &vec![ErrorVariation::Constant; e2e.n_errors()],
                e2e.poses(),
            )
            .map_err(|e| crate::input::library(e, s))?;
            Some(DiscWorst {
                constant: e2e_verify::angle::disc_worst_case(&constant, &lin, ub_rad, &discs),
                angle: e2e_verify::angle::disc_worst_case(&ex, &al.expanded, ub_rad, &discs),
            })
        };
        readings.push(ReadingAngle {
            outputs,
            yield_,
            verdict,
            disc,
        });
    }
    Ok(AngleCheck {
        study_model,
        variations,
        readings,
    })
}

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
pub fn text(
    e2e: &EndToEnd,
    constant: &TurntableCheck,
    a: &ReadingAngle,
    model: &AngleCheck,
) -> String {
    let mut s = format!("  angle-dependent errors ({}):\n", model_words(model));
    for o in &a.outputs {
        let out = e2e.calibration().outputs()[o.output].output();
        let ratio = if o.constant_linear_bound > 0.0 {
            format!(
                " ({:.2}x the constant model's {})",
                o.linear_bound / o.constant_linear_bound,
                num(o.constant_linear_bound)
            )
        } else {
            String::new()
        };
        s.push_str(&format!(
            "    output {}: worst case linearised {} {u}{ratio}, {} {u} on the exact chain at the worst errors found{}: {}\n",
            out.name,
            num(o.linear_bound),
            num(o.exact_at_worst),
            o.second_order_bound
                .map_or(String::new(), |t| format!(", proven below {}", num(o.linear_bound + t))),
            o.verdict.name(),
            u = out.unit,
        ));
    }
    let (lo, hi) = a.yield_.interval_95;
    s.push_str(&format!(
        "    verdict: constant errors {}, angle-dependent errors {}; Monte Carlo yield {:.2}% (95% interval {:.2}%-{:.2}%, {} turntables)\n",
        constant.verdict.name(),
        a.verdict.name(),
        100.0 * a.yield_.fraction(),
        100.0 * lo,
        100.0 * hi,
        a.yield_.samples
    ));
    if let Some(d) = &a.disc {
        for o in &a.outputs {
            let out = e2e.calibration().outputs()[o.output].output();
            s.push_str(&format!(
                "    output {}, the sheet's magnitudes as discs (sqrt(a_x^2 + a_y^2) <= w), not squares: linearised worst case {} {u} with constant errors (square {}), {} {u} with angle-dependent errors (square {})\n",
                out.name,
                num(d.constant[o.output]),
                num(constant.outputs[o.output].worst_case.linear_bound),
                num(d.angle[o.output]),
                num(o.linear_bound),
                u = out.unit,
            ));
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

/// The JSON object of one reading.
#[must_use]
pub fn reading_json(e2e: &EndToEnd, a: &ReadingAngle) -> Value {
    json!({
        "verdict": a.verdict.name(),
        "yield": a.yield_.fraction(),
        "yield_interval_95": [a.yield_.interval_95.0, a.yield_.interval_95.1],
        "samples": a.yield_.samples,
        "disc_worst_case_linear": a.disc.as_ref().map(|d| json!({"constant": d.constant, "angle_dependent": d.angle})),
        "outputs": a.outputs.iter().map(|o| {
            let out = e2e.calibration().outputs()[o.output].output();
            json!({
                "name": out.name,
                "worst_case_linear": o.linear_bound,
                "worst_case_linear_constant_model": o.constant_linear_bound,
                "worst_case_exact_at_worst": o.exact_at_worst,
                "second_order_bound": o.second_order_bound,
                "worst_position": o.position,
                "verdict": o.verdict.name(),
            })
        }).collect::<Vec<_>>(),
    })
}

/// The `angle_dependent` JSON key: the model and one object per reading (the study's, then the
/// user's when different).
#[must_use]
pub fn json(checks: &[(EndToEnd, TurntableCheck)], a: &AngleCheck) -> Value {
    let names = checks[0].0.turntable().rotation_error_names();
    json!({
        "model": if a.study_model { "study" } else { "any-on-shafts" },
        "sheet_supports": if a.study_model { "study" } else { "angle-dependent" },
        "errors": names.iter().zip(&a.variations).map(|(n, v)| {
            let (joint, orders) = match v {
                ErrorVariation::Harmonics { joint, orders } => (Some(joint.clone()), Some(orders.clone())),
                ErrorVariation::Any { joint } => (Some(joint.clone()), None),
                _ => (None, None),
            };
            json!({"error": n, "varies": v.name(), "of": joint, "harmonics": orders})
        }).collect::<Vec<_>>(),
        "readings": checks.iter().zip(&a.readings).map(|((e, _), r)| reading_json(e, r)).collect::<Vec<_>>(),
    })
}

/// The check of the compensated table: the measured errors are known inputs of the chain, so
/// their bound is their measurement uncertainty (the rest of the sheet unchanged).
#[derive(Debug, Clone)]
pub struct Compensated {
    /// The box that matters (rad, order of chi).
    pub ub_rad: Vec<f64>,
    /// The constant-model check of every reading.
    pub checks: Vec<TurntableCheck>,
    /// The angle-dependent check.
    pub angle: AngleCheck,
}

/// The compensated check when the study measures errors (`[[compensation.measured]]`), else
/// `None`.
///
/// # Errors
/// A library error located in the study.
pub fn compensated(
    s: &Study,
    checks: &[(EndToEnd, TurntableCheck)],
    tol: &study::Tolerances,
    settings: &e2e_verify::McSettings,
) -> Result<Option<Compensated>> {
    if s.measured.iter().all(Option::is_none) {
        return Ok(None);
    }
    let u: Vec<Option<f64>> = s
        .measured
        .iter()
        .map(|m| m.as_ref().map(|m| m.uncertainty_rad))
        .collect();
    let ub_rad = e2e_verify::angle::compensated_box(&tol.ub_rad, &u);
    let lb: Vec<f64> = s
        .lower_bounds_rad
        .iter()
        .zip(&ub_rad)
        .map(|(l, u)| l.min(*u))
        .collect();
    let mut out = Vec::with_capacity(checks.len());
    for (e2e, _) in checks {
        out.push(
            e2e.check_tolerances(&e2e.linearization(), &ub_rad, &lb, settings)
                .map_err(|e| crate::input::library(e, s))?,
        );
    }
    let mut t = tol.clone();
    t.ub_rad.clone_from(&ub_rad);
    let angle = check(s, checks, &t, settings.samples, settings.seed)?;
    Ok(Some(Compensated {
        ub_rad,
        checks: out,
        angle,
    }))
}

/// The compensated block of the text: per reading, the verdicts before and after.
#[must_use]
pub fn compensated_text(checks: &[(EndToEnd, TurntableCheck)], c: &Compensated) -> String {
    let mut s = String::from(
        "\ncompensated (the study's measured errors are known inputs of the chain; the bound that matters is their measurement uncertainty):\n",
    );
    for (((e2e, before), after), aa) in checks.iter().zip(&c.checks).zip(&c.angle.readings) {
        s.push_str(&format!("reading {}\n", e2e.reading()));
        for (o, a) in before.outputs.iter().zip(&after.outputs) {
            let out = e2e.calibration().outputs()[o.output].output();
            s.push_str(&format!(
                "  output {}: worst case linearised {} {u} before, {} {u} after compensation (constant errors); {} {u} after (angle-dependent errors)\n",
                out.name,
                num(o.worst_case.linear_bound),
                num(a.worst_case.linear_bound),
                num(aa.outputs[o.output].linear_bound),
                u = out.unit,
            ));
        }
        s.push_str(&format!(
            "  verdict before: {}; after compensation: {} (constant errors), {} (angle-dependent errors)\n",
            before.verdict.name(),
            after.verdict.name(),
            aa.verdict.name()
        ));
    }
    s
}

/// The `compensated` JSON key.
#[must_use]
pub fn compensated_json(checks: &[(EndToEnd, TurntableCheck)], c: &Compensated) -> Value {
    let names = checks[0].0.turntable().rotation_error_names();
    json!({
        "tolerances_arcmin": crate::out::arcmin_json(&names, &c.ub_rad),
        "readings": checks.iter().zip(&c.checks).zip(&c.angle.readings).map(|(((e2e, _), k), a)| json!({
            "reading": e2e.reading().to_string(),
            "verdict": k.verdict.name(),
            "worst_case_linear": k.outputs.iter().map(|o| o.worst_case.linear_bound).collect::<Vec<_>>(),
            "angle_dependent": reading_json(e2e, a),
        })).collect::<Vec<_>>(),
    })
}
