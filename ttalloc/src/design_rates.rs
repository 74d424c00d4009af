//! `design-schedule --rates-deg-per-s R1,R2,...` (issue 23): the rate of the study's rate steps
//! chosen among candidate rates, with the designed positions.
//!
//! For each candidate rate R every rate step of the study turns at R (its sign, joint, angles
//! and revolutions kept), the static positions are the designed ones or the study's (the
//! position search takes the static positions alone, so its design need not be the better one
//! once the rate steps count), and each schedule is answered by the direct allocation
//! of the angles and the rate tolerances together ([`e2e_verify::EndToEnd::allocate_direct_rate`],
//! J over both, arcmin^-2, as `end-to-end --json` reports `rate_allocation.objective_arcmin`).
//! The pair (positions, rate) with the least J is chosen and written by `--write-study`. The rate changes
//! how the rate accuracy, the ripple and the centripetal terms reach the outputs (the
//! centripetal acceleration grows as the rate squared), so the best rate depends on the
//! sensor, the table and the schedule.

use anyhow::Result;
use study::Study;
use study::fmt::num;
pub use tt_lab::design::rates::{FLAG, MAX_RATE_DEG_PER_S, RateChoice};

/// One candidate rate, finite and in (0, [`MAX_RATE_DEG_PER_S`]] (deg/s).
///
/// # Errors
/// A message for clap (exit 2 naming the flag).
pub fn rate(s: &str) -> Result<f64, String> {
    crate::args::positive(s, MAX_RATE_DEG_PER_S)
}

/// The study text `text` with every `[[calibration.rate_steps]]`'s `rate_deg_per_s` at `rate`
/// (deg/s, each step's sign kept), checked by parsing it back.
///
/// # Errors
/// An internal error when the text does not parse back to those rates.
pub fn text_with_rate(s: &Study, text: &str, rate: f64) -> Result<String> {
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
        anyhow::anyhow!("internal: the study with the chosen rate does not parse: {e}")
    })?;
    let expected: Vec<f64> = s
        .rate_steps
        .iter()
        .map(|r| rate.copysign(r.rate_deg_per_s))
        .collect();
    let got: Vec<f64> = back.rate_steps.iter().map(|r| r.rate_deg_per_s).collect();
    if got != expected {
        anyhow::bail!(
            "internal: the written study's rates {got:?} are not the chosen {expected:?}"
        );
    }
    Ok(out)
}

/// The choice as text.
#[must_use]
pub fn text(c: &RateChoice) -> String {
    let j = |v: Option<f64>| v.map_or("no table suffices".into(), |v| format!("J = {}", num(v)));
    let list: Vec<String> = c
        .candidates()
        .iter()
        .zip(c.study_positions())
        .map(|((r, v), t)| format!("{} deg/s {} (study's positions: {})", num(*r), j(*v), j(*t)))
        .collect();
    format!(
        "\nrate of the rate steps, chosen among candidates with the designed or the study's positions (direct allocation of the angles and the rate tolerances together, arcmin^-2): with the designed positions {}; the study's rates with the designed positions: {}; chosen: {}\n",
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

/// [`tt_lab::design::rates::check`] as the command's result.
///
/// # Errors
/// As the library's.
pub fn check(s: &Study, rates: &[f64]) -> Result<()> {
    Ok(tt_lab::design::rates::check(s, rates)?)
}
