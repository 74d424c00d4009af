//! The words every command uses for the noise part: the split between the table's part and
//! the noise's ("table 0.0061, noise 0.0047 at 3 sigma"), the combined yield, the note when
//! the study gives noise but no timing. The budget: [`tt_lab::end_to_end::noise_budget`].

use e2e_verify::{CombinedOutput, YieldCount};
use study::Study;
use tt_core::human::num;

/// One line when the study gives noise but no timing: the noise part needs the dwell.
#[must_use]
pub(crate) fn note(s: &Study) -> Option<String> {
    (s.noise.iter().any(Option::is_some) && s.timing.is_none()).then(|| {
        "  (the study gives noise but no [calibration.timing]: the noise part needs the dwell at each position, so only the table's part is answered)".to_string()
    })
}

/// The split in words: `table 0.0061, noise 0.0047 at 3 sigma, combined 0.0108 deg_per_h
/// (noise dominates)`.
#[must_use]
pub(crate) fn split_text(c: &CombinedOutput, unit: &str) -> String {
    format!(
        "table {}{}, noise {} at {} sigma (sigma {}), combined {} {unit} ({} dominates)",
        num(c.table_part()),
        if c.table_certified() {
            ""
        } else {
            " (not certified)"
        },
        num(c.k_sigma() * c.noise_sigma()),
        num(c.k_sigma()),
        num(c.noise_sigma()),
        num(c.combined()),
        c.dominant().name()
    )
}

/// The combined yield in words.
#[must_use]
pub(crate) fn yield_text(y: &YieldCount) -> String {
    let (lo, hi) = y.interval_95();
    format!(
        "yield over turntables and noise {:.2}% (95% interval {:.2}%-{:.2}%, {} calibrations, seed {})",
        100.0 * y.fraction(),
        100.0 * lo,
        100.0 * hi,
        y.samples(),
        y.seed()
    )
}
