//! Numbers and text for people: sensible significant digits in messages and human-readable
//! output (JSON and CSV keep full precision), and text from a file made safe to show
//! ([`visible`], [`terminal`]).

use std::borrow::Cow;

/// `v` with at most `sig` significant digits: fixed notation for magnitudes in
/// $[10^{-4}, 10^6)$ (trailing zeros dropped), exponent notation otherwise (`1e308`,
/// `2.5e-7`); `NaN` and infinities spelled out.
#[must_use]
pub fn sig(v: f64, sig: usize) -> String {
    if !v.is_finite() {
        return format!("{v}");
    }
    if v == 0.0 {
        return "0".into();
    }
    let sig = sig.max(1);
    let a = v.abs();
    if (1e-4..1e6).contains(&a) {
        let exp = a.log10().floor() as i32;
        let decimals = (sig as i32 - 1 - exp).max(0) as usize;
        let s = format!("{v:.decimals$}");
        let s = if s.contains('.') {
            s.trim_end_matches('0').trim_end_matches('.').to_string()
        } else {
            s
        };
        if s == "-0" { "0".into() } else { s }
    } else {
        let s = format!("{v:.prec$e}", prec = sig - 1);
        // 1.500000e-7 -> 1.5e-7
        match s.split_once('e') {
            Some((m, e)) => {
                let m = if m.contains('.') {
                    m.trim_end_matches('0').trim_end_matches('.')
                } else {
                    m
                };
                format!("{m}e{e}")
            }
            None => s,
        }
    }
}

/// [`sig`] with 6 significant digits: the default for messages.
#[must_use]
pub fn num(v: f64) -> String {
    sig(v, 6)
}

/// Whether `c` must never reach a terminal, a report or a shell line raw: a control character
/// (C0, DEL, C1: ESC, BEL, CR, NUL, ...), a line or paragraph separator, or a bidirectional
/// formatting character (which reorders what a reader sees).
#[must_use]
pub fn is_unsafe_char(c: char) -> bool {
    c.is_control()
        || matches!(
            c,
            '\u{061c}' | '\u{200e}' | '\u{200f}' | '\u{2028}' | '\u{2029}' | '\u{202a}'
                ..='\u{202e}' | '\u{2066}'..='\u{2069}'
        )
}

fn escape_unsafe<'a>(s: &'a str, keep: &[char]) -> Cow<'a, str> {
    if !s.chars().any(|c| is_unsafe_char(c) && !keep.contains(&c)) {
        return Cow::Borrowed(s);
    }
    let mut out = String::with_capacity(s.len() + 8);
    for c in s.chars() {
        if is_unsafe_char(c) && !keep.contains(&c) {
            // `\n`, `\r`, `\t`, `\0`, otherwise `\u{1b}`
            match c {
                '\0' => out.push_str("\\0"),
                _ => out.extend(c.escape_default()),
            }
        } else {
            out.push(c);
        }
    }
    Cow::Owned(out)
}

/// Text from a file (a study's description, a unit, a tolerance sheet's name, a path) made
/// safe to show on one line: every character of [`is_unsafe_char`] (newlines included) is
/// written as a visible escape (`\u{1b}`, `\n`, `\r`, `\t`, `\0`); everything else is kept.
/// The one escaping helper for free text: the terminal, the reports and the shell lines use it.
///
/// ```
/// assert_eq!(tt_core::human::visible("a\u{1b}[31mb\r"), "a\\u{1b}[31mb\\r");
/// assert_eq!(tt_core::human::visible("deg/h"), "deg/h");
/// ```
#[must_use]
pub fn visible(s: &str) -> Cow<'_, str> {
    escape_unsafe(s, &[])
}

/// A whole block of output made safe for a terminal: as [`visible`], but line feeds and tabs
/// (the output's own layout) are kept. Every command passes its standard output and its error
/// messages through this.
#[must_use]
pub fn terminal(s: &str) -> Cow<'_, str> {
    escape_unsafe(s, &['\n', '\t'])
}

/// `v` exactly: the shortest digits that read back as the same `f64` (Rust's round-trip
/// formatting), in fixed notation for magnitudes in $[10^{-5}, 10^{16})$ and zero, in
/// exponent notation otherwise (`1e-300`, not a 300-character field; `1.7976931348623157e308`).
/// For CSV and JSON-like output at full precision, and for a value a message must show as the
/// user gave it (`600.0000001` is not `600`).
#[must_use]
pub fn exact(v: f64) -> String {
    let a = v.abs();
    if !v.is_finite() || a == 0.0 || (1e-5..1e16).contains(&a) {
        format!("{v}")
    } else {
        format!("{v:e}")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Full precision in a short field: every value reads back as the same f64, and no field
    /// is longer than the 24 characters of the longest exponent form.
    #[test]
    fn exact_numbers_round_trip_in_a_short_field() {
        assert_eq!(exact(1e-300), "1e-300");
        assert_eq!(exact(600.0000001), "600.0000001");
        assert_eq!(exact(0.1), "0.1");
        assert_eq!(exact(-2.5e-7), "-2.5e-7");
        assert_eq!(exact(1e16), "1e16");
        assert_eq!(exact(0.0), "0");
        for v in [
            1e-300,
            -1e-300,
            f64::MIN_POSITIVE,
            5e-324,
            f64::MAX,
            -f64::MAX,
            1.0 / 3.0,
            0.026938049684760747,
            123_456_789_012_345.6,
            1e16 - 2.0,
            1e-5,
            9.99999999999e-6,
        ] {
            let s = exact(v);
            assert!(s.len() <= 24, "{v}: {s}");
            assert_eq!(s.parse::<f64>().unwrap().to_bits(), v.to_bits(), "{s}");
        }
    }

    #[test]
    fn control_and_bidi_characters_are_escaped_visibly() {
        assert_eq!(visible("x\u{1b}]0;t\u{7}y"), "x\\u{1b}]0;t\\u{7}y");
        assert_eq!(visible("a\nb\tc\rd\0"), "a\\nb\\tc\\rd\\0");
        assert_eq!(visible("\u{202e}evil\u{9b}"), "\\u{202e}evil\\u{9b}");
        assert_eq!(visible("ω_m µg/°"), "ω_m µg/°");
        assert_eq!(terminal("a\n\tb\u{1b}c\r"), "a\n\tb\\u{1b}c\\r");
        assert!(matches!(terminal("plain\n"), Cow::Borrowed(_)));
    }

    #[test]
    fn numbers_are_short_and_exact_enough() {
        assert_eq!(num(1e308), "1e308");
        assert_eq!(num(29.999999999999996), "30");
        assert_eq!(num(0.0002700000000000002), "0.00027");
        assert_eq!(num(0.026938049684760747), "0.026938");
        assert_eq!(num(-93.3), "-93.3");
        assert_eq!(num(1e-6), "1e-6");
        assert_eq!(num(0.001), "0.001");
        assert_eq!(num(123456.7), "123457");
        assert_eq!(num(0.0), "0");
        assert_eq!(num(f64::NAN), "NaN");
        assert_eq!(sig(7.2921159e-5, 8), "7.2921159e-5");
        assert_eq!(sig(-2.5e-7, 3), "-2.5e-7");
    }
}
