//! The study `design-schedule --write-study` writes, and the words it shares with the printed
//! answer: the positions chosen (designed, the study's kept, or the time budget's choice with
//! its dwell) and the chosen rate, under a comment saying how they were made and the tolerances
//! recommended for exactly them; the comparison with the noise counted and the rate choice in
//! words.

use crate::design::budget::{Budgeted, Designed, origin};
use crate::design::rates::RateChoice;
use crate::design::schedule::{CombinedChoice, NoiseCounted, ScheduleAnswer};
use crate::error::{LabError, Result};
use e2e_verify::noise::DEFAULT_K_SIGMA;
use schedule_design::{BudgetPoint, ScheduleReport};
use study::Study;
use tt_core::human::{num, sig};
use tt_core::units::rad_to_arcmin;

/// The combined comparison (the study's schedule against the designed one with the noise
/// counted) in words, one line.
#[must_use]
pub fn combined_text(c: &CombinedChoice) -> String {
    let j = |v: Option<f64>| {
        v.map_or("no table suffices".to_string(), |v| {
            format!("J = {}", num(v))
        })
    };
    let standing = c.both_fail().map_or(String::new(), |(st, de)| {
        let dwell = |d: Option<f64>| {
            d.map_or("none up to the longest accepted dwell".to_string(), |d| {
                format!("{} s", num(d))
            })
        };
        format!(
            " (neither leaves room for a table at the study's dwell: largest noise part / accuracy {} for the study's schedule, {} designed; shortest dwell at which some table suffices {} for the study's, {} designed)",
            num(st.noise_over_accuracy()),
            num(de.noise_over_accuracy()),
            dwell(st.min_dwell_s()),
            dwell(de.min_dwell_s())
        )
    });
    format!(
        "with the noise counted ({} sigma, the study's timing; certified direct allocation with the noise part kept free): study's schedule {}, designed {}{standing}: {}\n",
        num(DEFAULT_K_SIGMA),
        j(c.study().objective_arcmin()),
        j(c.designed().objective_arcmin()),
        if c.designed_recommended() {
            "the designed schedule does not lose on the combined answer"
        } else {
            "the designed schedule LOSES on the combined answer; keep the study's schedule (it is the one recommended and written)"
        }
    )
}

/// A schedule's condition numbers by output, for the written study's comment.
fn condition_list(s: &Study, r: &ScheduleReport) -> String {
    s.sensor
        .outputs()
        .iter()
        .zip(r.condition_numbers())
        .map(|(o, c)| format!("{} {}", o.name, num(*c)))
        .collect::<Vec<_>>()
        .join(", ")
}

/// `v` rounded down to `digits` significant digits, printed: a tolerance read back from the
/// text is never looser than the one computed.
#[must_use]
pub fn sig_down(v: f64, digits: usize) -> String {
    if !(v.is_finite() && v > 0.0) {
        return sig(v, digits);
    }
    let scale = 10f64.powi(digits as i32 - 1 - v.log10().floor() as i32);
    let mut m = (v * scale).floor();
    loop {
        let shown = sig(m / scale, digits);
        if m <= 0.0 || shown.parse::<f64>().is_ok_and(|x| x <= v) {
            return shown;
        }
        m -= 1.0;
    }
}

/// `ub` (rad) by error name in arcmin, `shown` formatting each finite bound; `free` where
/// there is none.
#[must_use]
pub fn bound_list(s: &Study, ub: &[f64], shown: &dyn Fn(f64) -> String) -> String {
    s.turntable
        .rotation_error_names()
        .iter()
        .zip(ub)
        .map(|(n, u)| {
            format!(
                "{n} {}",
                if u.is_finite() {
                    shown(rad_to_arcmin(*u))
                } else {
                    "free".into()
                }
            )
        })
        .collect::<Vec<_>>()
        .join(", ")
}

/// The tolerances recommended with the noise counted (`n`) in words: what is proven (the
/// table's part, on the exact chain) and what the noise adds; `None` for the bounds when no
/// table suffices.
#[must_use]
pub fn noise_counted_words(n: &NoiseCounted) -> (String, Option<&[f64]>) {
    let k = num(DEFAULT_K_SIGMA);
    match n.allocation() {
        None => (
            format!(
                "with the noise counted ({k} sigma, the study's timing): none: no table suffices at the study's dwell (the noise part alone fills an accuracy)"
            ),
            None,
        ),
        Some(a) if n.certified() => (
            format!(
                "with the noise counted ({k} sigma, the study's timing), certified on the exact chain (J = {}; rounded down): every turntable within them is proven to stay within each accuracy less the noise part ({k} sigma of the calibration's noise, a statistical bound, not a proof), so table and noise together meet every accuracy at {k} sigma, as `check-turntable` on the written study finds",
                sig(a.objective_arcmin(), 6)
            ),
            Some(a.upper_bounds_rad()),
        ),
        Some(a) => (
            format!(
                "with the noise counted ({k} sigma, the study's timing), first order only (J = {}; rounded down; not certifiable on the exact chain for this reading): the table's part within each accuracy less the noise part ({k} sigma) to first order, not proven",
                sig(a.objective_arcmin(), 6)
            ),
            Some(a.upper_bounds_rad()),
        ),
    }
}

/// The lines the written study puts above the positions the time budget chose (`p`, chosen
/// in `d`).
#[must_use]
pub(crate) fn chosen_comment(d: &Designed, p: &BudgetPoint) -> String {
    format!(
        "With --time-budget-s {}: these {} positions ({}) and dwell_s = {} s at each\n({} s of test in all) were chosen together; J = {} arcmin^-2 with the noise part\nkept free at {} sigma (linearised), {} certified on the exact chain (end-to-end's\ndirect_with_noise objective on this file). The dwell_s of [calibration.timing] below is\nthis one; the comments there describe the study's original timing.",
        num(d.budget_s()),
        p.n_positions(),
        origin(p.origin()),
        num(p.dwell_s()),
        sig(p.total_s(), 6),
        num(p.objective_arcmin()),
        num(d.k_sigma()),
        d.chosen_certified_arcmin()
            .map_or("no table suffices".to_string(), |j| format!(
                "J = {}",
                num(j)
            )),
    )
}

/// The rate choice (`--rates-deg-per-s`) as text.
#[must_use]
pub fn rates_text(c: &RateChoice) -> String {
    let j = |v: Option<f64>| v.map_or("no table suffices".into(), |v| format!("J = {}", num(v)));
    let list: Vec<String> = c
        .candidates()
        .iter()
        .zip(c.study_positions())
        .map(|((r, v), t)| format!("{} deg/s {} (study's positions: {})", num(*r), j(*v), j(*t)))
        .collect();
    let loads = c.specification_loads().map_or(String::new(), |(d, t)| {
        let load = |v: &Option<f64>| v.map_or("no table suffices".into(), num);
        let per: Vec<String> = c
            .candidates()
            .iter()
            .zip(d.iter().zip(t))
            .map(|((r, _), (d, t))| {
                format!(
                    "{} deg/s {} (study's positions: {})",
                    num(*r),
                    load(d),
                    load(t)
                )
            })
            .collect();
        format!(
            "chosen by the largest specification load, not by J (rule: {}): {}\n",
            c.rule(),
            per.join(", ")
        )
    });
    format!(
        "\nrate of the rate steps, chosen among candidates with the designed or the study's positions (direct allocation of the angles and the rate tolerances together, arcmin^-2): with the designed positions {}; the study's rates with the designed positions: {}; chosen: {}\n{loads}",
        list.join(", "),
        j(c.study_rates_objective_arcmin()),
        c.chosen().map_or(
            "none (no candidate's table suffices)".into(),
            |(r, v)| format!(
                "{} deg/s with the {} positions (J = {})",
                num(r),
                if c.chosen_study_positions() {
                    "study's"
                } else {
                    "designed"
                },
                num(v)
            )
        )
    )
}

/// A failure that is not the caller's: the written text does not read back as chosen.
fn internal(what: String) -> LabError {
    LabError::Library(what.into())
}

/// The study text `text` with every `[[calibration.rate_steps]]`'s `rate_deg_per_s` at `rate`
/// (deg/s, each step's sign kept), checked by parsing it back.
///
/// # Errors
/// An internal error when the text does not parse back to those rates.
pub(crate) fn text_with_rate(s: &Study, text: &str, rate: f64) -> Result<String> {
    let mut out = String::with_capacity(text.len());
    let mut in_step = false;
    for line in text.split_inclusive('\n') {
        let t = line.trim_start();
        if t.starts_with('[') {
            in_step = t.starts_with("[[calibration.rate_steps]]");
        }
        match t.strip_prefix("rate_deg_per_s") {
            Some(rest) if in_step && rest.trim_start().starts_with('=') => {
                let value = rest.trim_start()[1..]
                    .split('#')
                    .next()
                    .unwrap_or_default()
                    .trim();
                let sign = if value.starts_with('-') { -1.0 } else { 1.0 };
                let indent = &line[..line.len() - t.len()];
                out.push_str(&format!(
                    "{indent}rate_deg_per_s = {:?}\n",
                    rate.copysign(sign)
                ));
            }
            _ => out.push_str(line),
        }
    }
    let back = Study::parse(&s.path, &out).map_err(|e| {
        internal(format!(
            "internal: the study with the chosen rate does not parse: {e}"
        ))
    })?;
    let expected: Vec<f64> = s
        .rate_steps
        .iter()
        .map(|r| rate.copysign(r.rate_deg_per_s))
        .collect();
    let got: Vec<f64> = back.rate_steps.iter().map(|r| r.rate_deg_per_s).collect();
    if got != expected {
        return Err(internal(format!(
            "internal: the written study's rates {got:?} are not the chosen {expected:?}"
        )));
    }
    Ok(out)
}

/// The study `--write-study` writes (shown as `shown`; `command` the command line that
/// reproduces the run): the positions chosen (designed, the study's kept, or the budget's
/// choice, with its dwell) and the chosen rate, under a comment saying how they were made and
/// the tolerances recommended for exactly them; checked by parsing it back.
///
/// # Errors
/// An internal error when the text does not parse back to what was chosen.
pub fn study_text(
    s: &Study,
    answer: &ScheduleAnswer,
    command: &str,
    shown: &str,
) -> Result<String> {
    let design = answer.design();
    let combined = answer.combined();
    let keep_study = answer.keep_study();
    let rate_keeps_study = answer
        .rates()
        .is_some_and(|r| r.chosen().is_some() && r.chosen_study_positions());
    // with a time budget and noise: the count, positions and dwell it chose
    let chosen = match answer.budget() {
        Some(Budgeted::Design(d)) => d.chosen().map(|p| (d, p)),
        _ => None,
    };
    let study_kept = keep_study || rate_keeps_study;
    // the comment describes what is written: which positions, their J and the
    // tolerances recommended for exactly them (with the noise counted when the
    // study gives noise)
    let (positions, which, counted): (&[Vec<f64>], String, Option<&NoiseCounted>) = match chosen {
        Some((d, p)) => (p.positions_deg(), chosen_comment(d, p), d.chosen_counted()),
        None if study_kept => (
            design.study().positions_deg(),
            format!(
                "The study's own positions are kept ({}): J = {} arcmin^-2 (direct allocation, table alone, reading {}; designed: {}), condition numbers {}.",
                if keep_study {
                    "the designed ones lose once the noise is counted"
                } else {
                    "with the chosen rate they give the least J"
                },
                num(design.study().allocation().objective_arcmin()),
                s.reading,
                num(design.designed().allocation().objective_arcmin()),
                condition_list(s, design.study())
            ),
            combined.map(CombinedChoice::study),
        ),
        None => (
            design.designed().positions_deg(),
            format!(
                "Designed positions: J = {} arcmin^-2 (direct allocation, table alone, reading {}; the study's schedule: {}, D-optimal: {}),\ncondition numbers {}, best of {} restarts over {} candidates.",
                num(design.designed().allocation().objective_arcmin()),
                s.reading,
                num(design.study().allocation().objective_arcmin()),
                num(design.d_optimal().allocation().objective_arcmin()),
                condition_list(s, design.designed()),
                design.search().restarts().len(),
                answer.candidates()
            ),
            combined.map(CombinedChoice::designed),
        ),
    };
    let tolerances = match counted {
        Some(n) => {
            let (words, ub) = noise_counted_words(n);
            format!(
                "Tolerances for these positions (arcmin) {}{}.",
                words.replacen("the study's timing", "this file's timing", 1),
                ub.map_or(String::new(), |ub| format!(
                    ":\n{}",
                    bound_list(s, ub, &|v| sig_down(v, 3))
                ))
            )
        }
        None => {
            let r = if study_kept {
                design.study()
            } else {
                design.designed()
            };
            match r.certified() {
                Some(c) => format!(
                    "Tolerances certified on the exact chain for these positions (arcmin, rounded down; every turntable within them meets every accuracy: `check-turntable` proves them):\n{}.",
                    bound_list(s, c.upper_bounds_rad(), &|v| sig_down(v, 3))
                ),
                None => format!(
                    "Tolerances certified on the exact chain for these positions: none ({}).",
                    r.certified_note().unwrap_or("not certifiable")
                ),
            }
        }
    };
    let mut comment = format!(
        "The positions below replace the schedule described above. Made by\n`{command}`.\n{which}\n{tolerances}"
    );
    if let (Some(c), None) = (combined, chosen) {
        comment.push('\n');
        comment.push_str(combined_text(c).trim_end());
    }
    if let Some(r) = answer.rates() {
        comment.push('\n');
        comment.push_str(rates_text(r).trim());
    }
    if let Some(Budgeted::Design(d)) = answer.budget() {
        if d.chosen().is_none() {
            comment.push_str(&format!(
                "\nWith --time-budget-s {}: no table suffices within the budget (the noise fills an accuracy),\nso the positions below are those chosen without the budget, and the study's dwell is kept.",
                num(d.budget_s())
            ));
        }
    }
    let chosen = chosen.map(|(_, p)| p);
    let text = match chosen {
        Some(p) => s.text_with_dwell(positions, p.dwell_s(), &comment),
        None => s.text_with_positions(positions, &comment),
    }?;
    let text = match answer.rates().and_then(RateChoice::chosen) {
        Some((rate, _)) => text_with_rate(s, &text, rate)?,
        None => text,
    };
    let back = Study::parse(shown, &text)
        .map_err(|e| internal(format!("internal: the written study does not parse: {e}")))?;
    if back.positions_deg.as_slice() != positions {
        return Err(internal(
            "internal: the written study's positions differ from the designed ones".into(),
        ));
    }
    if let Some(p) = chosen {
        let dwells = back.timing.as_ref().map(calib_lsq::Timing::dwell_s);
        if !dwells.is_some_and(|d| d.iter().all(|t| t.to_bits() == p.dwell_s().to_bits())) {
            return Err(internal(format!(
                "internal: the written study's dwell differs from the chosen {} s",
                p.dwell_s()
            )));
        }
    }
    Ok(text)
}
