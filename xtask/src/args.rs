//! Flag value parsers shared by every command (one accepted form per kind of value).

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
        return Err(format!(
            "`{s}`: must be a whole number from 1 to {}",
            study::fmt::num(max as f64)
        ));
    }
    // exact for integers written in full; `1e6` forms are exact below 2^53
    Ok(t.parse::<u64>().unwrap_or(v as u64))
}

/// A Monte Carlo sample count (up to [`study::limits::MAX_SAMPLES`]).
///
/// # Errors
/// As [`count`].
pub fn samples(s: &str) -> Result<u64, String> {
    count(s, study::limits::MAX_SAMPLES)
}

/// A count of positions, bins or similar (up to 10^6).
///
/// # Errors
/// As [`count`].
pub fn small_count(s: &str) -> Result<u64, String> {
    count(s, 1_000_000)
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

/// A finite positive number in `(0, max]`.
///
/// # Errors
/// A message naming the value and the range.
pub fn positive(s: &str, max: f64) -> Result<f64, String> {
    let v: f64 = s
        .trim()
        .parse()
        .map_err(|_| format!("`{s}` is not a number"))?;
    if v.is_finite() && v > 0.0 && v <= max {
        Ok(v)
    } else {
        Err(format!("`{s}`: must lie in (0, {}]", study::fmt::num(max)))
    }
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
        assert!(
            samples("100000000000000000")
                .unwrap_err()
                .contains("from 1 to 1e12")
        );
    }
}
