//! Flag value parsers shared by every command (one accepted form per kind of value), and the
//! flag groups several commands share (`--study`, `--study` with `--json`, `--samples` and
//! `--seed`, `--k-sigma` with the JCGM 101 Monte Carlo's flags).

use std::path::{Path, PathBuf};

/// `--study`: the study file of a command that defaults to the paper's.
#[derive(Debug, clap::Args)]
pub(crate) struct StudyFile {
    /// Study file (default: `studies/gyrowheel-2017.toml`).
    #[arg(long)]
    pub(crate) study: Option<PathBuf>,
}

impl StudyFile {
    /// The path given, if any.
    pub(crate) fn path(&self) -> Option<&Path> {
        self.study.as_deref()
    }

    /// The study read from it (the paper's without `--study`).
    ///
    /// # Errors
    /// As [`crate::loaded::load`].
    pub(crate) fn load(&self) -> Result<study::Study, crate::InputError> {
        crate::loaded::load(self.path())
    }
}

/// `--study` then `--json`: a command that reads a study and prints text, or JSON instead.
#[derive(Debug, clap::Args)]
pub(crate) struct StudyJson {
    /// `--study` (default: the paper's).
    #[command(flatten)]
    pub study: StudyFile,
    /// Print JSON instead of text.
    #[arg(long)]
    pub json: bool,
}

/// `--samples` and `--seed`: the Monte Carlo's size and seed, the study's `monte_carlo` values
/// by default.
#[derive(Debug, clap::Args)]
pub(crate) struct Sampling {
    /// Monte Carlo turntables per box (default: the study's `monte_carlo.samples`; accepts
    /// `1e6`, `1000000`, `1_000_000`).
    #[arg(long, allow_negative_numbers = true, value_parser = samples)]
    pub samples: Option<u64>,
    /// Seed of the random streams (default: the study's `monte_carlo.seed`).
    #[arg(long, allow_negative_numbers = true, value_parser = seed)]
    pub seed: Option<u64>,
}

/// `--k-sigma`, `--jcgm101` and `--mc-digits`: the noise part's confidence multiplier and the
/// JCGM 101 Monte Carlo of every specification (the vendor check's and end to end's).
#[derive(Debug, clap::Args)]
pub(crate) struct Uncertainty {
    /// Confidence multiplier of the noise part (combined = table + k sigma), in (0, 10];
    /// used when the study gives noise and a timing.
    #[arg(long, allow_negative_numbers = true, default_value_t = e2e_verify::DEFAULT_K_SIGMA, value_parser = k_sigma)]
    pub k_sigma: f64,
    /// The JCGM 101 Monte Carlo of every specification (`--jcgm101`, `--mc-digits`).
    #[command(flatten)]
    pub jcgm101: crate::text::jcgm101::Flags,
}

/// A count: a whole number written as `1000000`, `1_000_000` or `1e6`, within `1..=max`.
///
/// # Errors
/// A message naming the value and the accepted range.
pub fn count(s: &str, max: u64) -> Result<u64, String> {
    let t = s.trim().replace('_', "");
    let v: f64 = t
        .parse()
        .map_err(|_| format!("`{s}` is not a count (write 1000000, 1_000_000 or 1e6)"))?;
    if !v.is_finite() || v.fract() != 0.0 || v < 1.0 || v > max as f64 {
        // the largest accepted value exactly: `1e12` for a power of ten, else every digit
        let shown = if max >= 10
            && max
                .to_string()
                .trim_start_matches('1')
                .bytes()
                .all(|b| b == b'0')
        {
            format!("1e{}", max.to_string().len() - 1)
        } else {
            max.to_string()
        };
        return Err(format!("`{s}`: must be a whole number from 1 to {shown}"));
    }
    // exact for integers written in full; `1e6` forms are exact below 2^53
    Ok(t.parse::<u64>().unwrap_or(v as u64))
}

/// A Monte Carlo sample count (up to [`study::limits::MAX_SAMPLES`]).
///
/// # Errors
/// As [`count`].
pub(crate) fn samples(s: &str) -> Result<u64, String> {
    count(s, study::limits::MAX_SAMPLES)
}

/// A number of test positions (up to [`study::limits::MAX_POSITIONS`], the limit of a
/// study's schedule).
///
/// # Errors
/// As [`count`].
pub(crate) fn positions(s: &str) -> Result<u64, String> {
    count(s, study::limits::MAX_POSITIONS as u64)
}

/// The significant digits of u(y) a JCGM 101 Monte Carlo stabilizes (1 to
/// [`tt_lab::budget_mc::MAX_DIGITS`]).
///
/// # Errors
/// As [`count`].
pub(crate) fn mc_digits(s: &str) -> Result<u32, String> {
    count(s, u64::from(tt_lab::budget_mc::MAX_DIGITS)).map(|v| v as u32)
}

/// A thread count (1 to 1024).
///
/// # Errors
/// As [`count`].
pub(crate) fn threads(s: &str) -> Result<u32, String> {
    count(s, 1024).map(|v| v as u32)
}

/// A count that fits `u32` (a chunk size).
///
/// # Errors
/// As [`count`].
pub(crate) fn count_u32(s: &str) -> Result<u32, String> {
    count(s, u64::from(u32::MAX)).map(|v| v as u32)
}

/// A fraction in the open interval (0, 1) (a yield target).
///
/// # Errors
/// A message naming the value and the range.
pub(crate) fn fraction(s: &str) -> Result<f64, String> {
    let v: f64 = s
        .trim()
        .parse()
        .map_err(|_| format!("`{s}` is not a number"))?;
    if v.is_finite() && v > 0.0 && v < 1.0 {
        Ok(v)
    } else {
        Err(format!("`{s}`: must lie in (0, 1)"))
    }
}

/// A seed: any whole number `0..=u64::MAX`.
///
/// # Errors
/// A message naming the value.
pub fn seed(s: &str) -> Result<u64, String> {
    s.trim().replace('_', "").parse().map_err(|_| {
        format!(
            "`{s}` is not a seed (a whole number from 0 to {})",
            u64::MAX
        )
    })
}

/// A finite number in `[lo, hi]` (`what` names it in the message).
///
/// # Errors
/// A message naming the value and the range (NaN and infinities are outside).
pub(crate) fn number_in(s: &str, lo: f64, hi: f64, what: &str) -> Result<f64, String> {
    let v: f64 = s
        .trim()
        .parse()
        .map_err(|_| format!("`{s}` is not a number"))?;
    if v.is_finite() && (lo..=hi).contains(&v) {
        Ok(v)
    } else {
        Err(format!(
            "`{s}`: {what} must lie in [{}, {}]",
            tt_core::human::num(lo),
            tt_core::human::num(hi)
        ))
    }
}

/// A finite positive number in `(0, max]`.
///
/// # Errors
/// A message naming the value and the range.
pub(crate) fn positive(s: &str, max: f64) -> Result<f64, String> {
    let v: f64 = s
        .trim()
        .parse()
        .map_err(|_| format!("`{s}` is not a number"))?;
    if v.is_finite() && v > 0.0 && v <= max {
        Ok(v)
    } else {
        Err(format!(
            "`{s}`: must lie in (0, {}]",
            tt_core::human::num(max)
        ))
    }
}

/// The confidence multiplier of the noise part (`--k-sigma`): finite, in
/// $(0,$ [`e2e_verify::noise::MAX_K_SIGMA`]$]$ (the library's own check).
///
/// # Errors
/// A message naming the value and the range.
pub(crate) fn k_sigma(s: &str) -> Result<f64, String> {
    let v: f64 = s
        .trim()
        .parse()
        .map_err(|_| format!("`{s}` is not a number"))?;
    e2e_verify::check_k_sigma(v).map_err(|_| {
        format!(
            "`{s}`: must lie in (0, {}]",
            tt_core::human::num(e2e_verify::noise::MAX_K_SIGMA)
        )
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn counts_accept_the_documented_forms_only() {
        assert_eq!(count("1000000", 1e12 as u64), Ok(1_000_000));
        assert_eq!(count("1_000_000", 1e12 as u64), Ok(1_000_000));
        assert_eq!(count("1e6", 1e12 as u64), Ok(1_000_000));
        assert_eq!(count("18446744073709551615", u64::MAX), Ok(u64::MAX));
        for bad in ["0", "-5", "1.5", "1e13", "x", "", "nan", "inf"] {
            assert!(count(bad, 1e12 as u64).is_err(), "{bad}");
        }
        // the largest value is quoted exactly
        assert!(
            count_u32("1e12")
                .unwrap_err()
                .contains("from 1 to 4294967295")
        );
        assert_eq!(count_u32("1e6"), Ok(1_000_000));
        assert!(threads("2000").unwrap_err().contains("from 1 to 1024"));
        assert!(
            samples("100000000000000000")
                .unwrap_err()
                .contains("from 1 to 1e10")
        );
    }
}
