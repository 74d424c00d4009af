//! Reading turntable CSV input (a file, a pipe or FIFO, or standard input, `-`) record by record
//! with memory that does not grow with the input. Every input is read exactly once (a pipe,
//! FIFO, `<(...)` or `/dev/stdin` cannot be read twice): each row is evaluated as it is read
//! and its result line goes to an anonymous temporary file until the whole input is known to
//! be valid. Nothing is written to standard output before that.

use crate::InputError;
use std::io::{BufRead, BufReader, Read};
use std::path::{Path, PathBuf};
use study::csv::{JointColumns, TurntableRow};
use tt_kinematics::Turntable;

/// Where the CSV comes from.
#[derive(Debug, Clone)]
pub(crate) enum Source {
    /// A file, FIFO or other named input (read once).
    File(PathBuf),
    /// Standard input (read once).
    Stdin,
}

impl Source {
    /// `None` or `-` is standard input.
    #[must_use]
    pub(crate) fn from_arg(arg: Option<&Path>) -> Self {
        match arg {
            Some(p) if p != Path::new("-") => Source::File(p.to_path_buf()),
            _ => Source::Stdin,
        }
    }

    /// Its name in messages.
    #[must_use]
    pub(crate) fn name(&self) -> String {
        match self {
            Source::File(p) => p.display().to_string(),
            Source::Stdin => "<stdin>".into(),
        }
    }

    pub(crate) fn open(&self) -> Result<Box<dyn BufRead>, InputError> {
        match self {
            Source::File(p) => {
                let meta = std::fs::metadata(p)
                    .map_err(|e| InputError::new(self.name(), format!("cannot read: {e}")))?;
                if meta.is_dir() {
                    return Err(InputError::new(self.name(), "cannot read: a directory"));
                }
                let f = std::fs::File::open(p)
                    .map_err(|e| InputError::new(self.name(), format!("cannot read: {e}")))?;
                Ok(Box::new(BufReader::new(f)))
            }
            Source::Stdin => Ok(Box::new(BufReader::new(std::io::stdin()))),
        }
    }
}

/// Visit every data row of the CSV (header mapped to `turntable`), in order, with its line
/// number; blank lines are skipped. Stops at the first error.
///
/// # Errors
/// An [`InputError`] at `source:line` (and column) for an unreadable input, invalid UTF-8, a
/// record longer than [`tt_lab::records::MAX_LINE_BYTES`], malformed quoting, a bad header or
/// row, or an empty input.
pub(crate) fn for_each_row<F>(
    source: &Source,
    turntable: &Turntable,
    joints: JointColumns,
    visit: F,
) -> Result<(), InputError>
where
    F: FnMut(usize, TurntableRow) -> Result<(), InputError>,
{
    let reader = source.open()?;
    for_each_row_in(reader, &source.name(), turntable, joints, visit)
}

/// `for_each_row` on any reader (`name` names it in messages): the one CSV loop
/// ([`tt_lab::rows::read_rows`]), also driven by the fuzz harness.
///
/// # Errors
/// As `for_each_row`.
pub fn for_each_row_in<R, F>(
    reader: R,
    name: &str,
    turntable: &Turntable,
    joints: JointColumns,
    visit: F,
) -> Result<(), InputError>
where
    R: Read,
    F: FnMut(usize, TurntableRow) -> Result<(), InputError>,
{
    tt_lab::rows::read_rows(reader, name, turntable, joints, visit)
}

/// Evaluate every row and write `header` then one line per row to standard output, only
/// once the whole input is known to be valid: the input is read once, each row evaluated as
/// it comes, its line spooled to an anonymous temporary file (removed by the system when
/// closed) and copied out at the end. Memory does not grow with the input.
///
/// # Errors
/// The first [`InputError`] of the input or of `eval` (nothing written then); I/O errors of
/// standard output (a closed pipe ends quietly, see [`crate::out`]).
pub(crate) fn run_rows<F>(
    source: &Source,
    turntable: &Turntable,
    joints: JointColumns,
    header: &str,
    mut eval: F,
) -> anyhow::Result<()>
where
    F: FnMut(usize, TurntableRow) -> Result<String, InputError>,
{
    use std::io::{Seek, Write};
    let name = source.name();
    let file = tempfile::tempfile()
        .map_err(|e| anyhow::Error::new(e).context("creating a temporary file for the results"))?;
    let mut spill = std::io::BufWriter::new(file);
    let mut io_error = None;
    let read = for_each_row(source, turntable, joints, |line, row| {
        let text = eval(line, row)?;
        writeln!(spill, "{text}").map_err(|e| {
            io_error = Some(e);
            InputError::new(name.clone(), "writing the temporary file failed")
        })
    });
    if let Some(e) = io_error {
        return Err(anyhow::Error::new(e).context("writing the temporary file"));
    }
    read?;
    let mut file = spill
        .into_inner()
        .map_err(|e| anyhow::Error::new(e.into_error()))?;
    file.rewind()?;
    let mut out = std::io::BufWriter::new(std::io::stdout().lock());
    writeln!(out, "{header}").map_err(crate::out::io)?;
    std::io::copy(&mut file, &mut out).map_err(crate::out::io)?;
    out.flush().map_err(crate::out::io)
}
