//! Standard output: written at once, at the end; a closed pipe (`| head`) ends the program
//! quietly, as Unix tools do.

use std::io::Write;

/// Marks an error as "the reader closed standard output": the program ends quietly.
#[derive(Debug)]
pub struct BrokenPipe;

impl std::fmt::Display for BrokenPipe {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("standard output closed")
    }
}

impl std::error::Error for BrokenPipe {}

/// Map an I/O error of standard output: a broken pipe becomes [`BrokenPipe`].
pub fn io(e: std::io::Error) -> anyhow::Error {
    if e.kind() == std::io::ErrorKind::BrokenPipe {
        anyhow::Error::new(BrokenPipe)
    } else {
        anyhow::Error::new(e).context("writing standard output")
    }
}

/// Write `text` to standard output and flush. Control characters (from a study's text: ESC,
/// BEL, CR, ...) are shown escaped ([`study::fmt::terminal`]): nothing a file says can drive
/// the terminal.
///
/// # Errors
/// [`BrokenPipe`] when the reader is gone; other I/O errors.
pub fn print(text: &str) -> anyhow::Result<()> {
    let mut out = std::io::stdout().lock();
    out.write_all(study::fmt::terminal(text).as_bytes())
        .map_err(io)?;
    out.flush().map_err(io)
}

/// A CSV field (RFC 4180) from a file's text (a unit): control characters shown escaped
/// ([`study::fmt::visible`]), in double quotes when it holds a comma or a quote.
#[must_use]
pub fn csv_field(s: &str) -> String {
    let v = study::fmt::visible(s);
    if v.contains([',', '"']) {
        format!("\"{}\"", v.replace('"', "\"\""))
    } else {
        v.into_owned()
    }
}

/// The note for values printed as 0 because they lie at or below the computation's precision
/// ([`e2e_verify::EndToEnd::precisions`]): `None` when no output in `zeroed` (name, unit,
/// precision) had one.
#[must_use]
pub fn precision_note(zeroed: &[(&str, &str, f64)]) -> Option<String> {
    (!zeroed.is_empty()).then(|| {
        format!(
            "0 = at or below the computation's precision ({})",
            zeroed
                .iter()
                .map(|(n, u, p)| format!("{n} {} {u}", study::fmt::sig(*p, 2)))
                .collect::<Vec<_>>()
                .join(", ")
        )
    })
}
