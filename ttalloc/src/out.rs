//! Standard output: written at once, at the end; a closed pipe (`| head`) ends the program
//! quietly, as Unix tools do.

use std::io::Write;

/// Marks an error as "the reader closed standard output": the program ends quietly.
#[derive(Debug)]
pub(crate) struct BrokenPipe;

impl std::fmt::Display for BrokenPipe {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("standard output closed")
    }
}

impl std::error::Error for BrokenPipe {}

/// Map an I/O error of standard output: a broken pipe becomes [`BrokenPipe`].
pub(crate) fn io(e: std::io::Error) -> anyhow::Error {
    if e.kind() == std::io::ErrorKind::BrokenPipe {
        anyhow::Error::new(BrokenPipe)
    } else {
        anyhow::Error::new(e).context("writing standard output")
    }
}

/// Write `text` to standard output and flush. Control characters (from a study's text: ESC,
/// BEL, CR, ...) are shown escaped ([`tt_core::human::terminal`]): nothing a file says can drive
/// the terminal.
///
/// # Errors
/// `BrokenPipe` when the reader is gone; other I/O errors.
pub fn print(text: &str) -> anyhow::Result<()> {
    let mut out = std::io::stdout().lock();
    out.write_all(tt_core::human::terminal(text).as_bytes())
        .map_err(io)?;
    out.flush().map_err(io)
}

pub(crate) use tt_lab::end_to_end::precision_note;
