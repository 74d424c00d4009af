//! The one streaming CSV loop of the library's inputs (a noise log, turntables as rows): RFC
//! 4180 records read once with the `csv` crate (quoted fields, CRLF or LF line ends, a UTF-8
//! byte-order mark accepted, fields trimmed of surrounding spaces, blank lines skipped), no
//! record longer than [`MAX_LINE_BYTES`] (the reader's buffer stays bounded whatever the
//! input), each record's fields handed to the caller as text with the line it starts on.

use crate::error::InputError;
use std::collections::VecDeque;
use std::io::Read;

/// Longest record (a line, or the lines of one record with a quoted line break) accepted,
/// bytes.
pub const MAX_LINE_BYTES: usize = 1 << 20;

/// Where a byte stands in RFC 4180 quoting (to find where a record ends before the CSV
/// reader buffers it).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Quoting {
    /// Outside quotes; `true` at the start of a field (where a quote opens one).
    Unquoted(bool),
    /// Inside a quoted field.
    Quoted,
    /// A quote inside a quoted field: it closes the field or, doubled, is a literal quote.
    QuoteInQuoted,
}

/// A reader that fails once a record grows longer than [`MAX_LINE_BYTES`] (the CSV reader's
/// buffer stays bounded whatever the input) and notes where its lines end, so that a record's
/// line is its physical line (the CSV reader's own count skips blank lines).
struct RecordLimit<R> {
    inner: R,
    /// Bytes of the current record so far.
    bytes: usize,
    quoting: Quoting,
    /// Bytes read so far.
    offset: u64,
    /// Line ends read but not yet passed by a record: runs of consecutive line ends (only
    /// `\r` or `\n` between them) as (offset where the run's blank bytes begin, count), so
    /// that blank lines take one entry.
    ends: VecDeque<(u64, usize)>,
    /// The offset just after the last byte that is neither `\r` nor `\n`.
    blank_from: u64,
    /// Line ends passed by the records so far.
    passed: usize,
    /// Line ends read so far.
    lines_read: usize,
}

impl<R> RecordLimit<R> {
    fn new(inner: R) -> Self {
        Self {
            inner,
            bytes: 0,
            quoting: Quoting::Unquoted(true),
            offset: 0,
            ends: VecDeque::new(),
            blank_from: 0,
            passed: 0,
            lines_read: 0,
        }
    }

    /// Follow one byte; `true` when it ends a record.
    fn step(&mut self, b: u8) -> bool {
        use Quoting::{QuoteInQuoted, Quoted, Unquoted};
        let (next, ends) = match (self.quoting, b) {
            (Quoted, b'"') => (QuoteInQuoted, false),
            (Quoted, _) => (Quoted, false),
            (Unquoted(true), b'"') | (QuoteInQuoted, b'"') => (Quoted, false),
            (Unquoted(_) | QuoteInQuoted, b'\n') => (Unquoted(true), true),
            (Unquoted(_) | QuoteInQuoted, b',') => (Unquoted(true), false),
            (Unquoted(_) | QuoteInQuoted, _) => (Unquoted(false), false),
        };
        self.quoting = next;
        ends
    }

    /// Note a line end.
    fn line_end(&mut self) {
        self.lines_read += 1;
        match self.ends.back_mut() {
            Some((from, count)) if *from == self.blank_from => *count += 1,
            _ => self.ends.push_back((self.blank_from, 1)),
        }
    }

    /// The 1-based line of a record the CSV reader places at byte `at`: the reader's position
    /// before the blank lines it skips, so the record's first byte is the first after `at`
    /// that is neither `\r` nor `\n`; every run of line ends whose blank bytes begin at or
    /// before `at` lies before it.
    fn line_at(&mut self, at: u64) -> usize {
        while let Some(&(from, count)) = self.ends.front() {
            if from > at {
                break;
            }
            self.passed += count;
            self.ends.pop_front();
        }
        self.passed + 1
    }
}

impl<R: Read> Read for RecordLimit<R> {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        let n = self.inner.read(buf)?;
        for b in &buf[..n] {
            self.offset += 1;
            match *b {
                b'\n' => self.line_end(),
                b'\r' => {}
                _ => self.blank_from = self.offset,
            }
            if self.step(*b) {
                self.bytes = 0;
            } else {
                self.bytes += 1;
                if self.bytes > MAX_LINE_BYTES {
                    return Err(std::io::Error::other(format!(
                        "line longer than {MAX_LINE_BYTES} bytes"
                    )));
                }
            }
        }
        Ok(n)
    }
}

/// A record's fields as text, a field that is not UTF-8 named by its line and column.
fn fields<'r>(
    name: &str,
    line_no: usize,
    r: &'r csv::ByteRecord,
) -> Result<Vec<&'r str>, InputError> {
    r.iter()
        .enumerate()
        .map(|(c, f)| {
            std::str::from_utf8(f).map_err(|_| {
                InputError::new(
                    format!("{name}:{line_no} column {}", c + 1),
                    "not valid UTF-8",
                )
            })
        })
        .collect()
}

/// Read `input` (named `name` in messages) once, record by record, and hand every record
/// that is not blank to `visit` with the 1-based line it starts on and its fields (trimmed).
/// Stops at the first error.
///
/// # Errors
/// An [`InputError`] at `name:line` for an unreadable input, a record longer than
/// [`MAX_LINE_BYTES`] or malformed quoting; at `name:line column c` for a field that is not
/// UTF-8; or the first error `visit` returns.
pub(crate) fn for_each_record<R, F>(input: R, name: &str, mut visit: F) -> Result<(), InputError>
where
    R: Read,
    F: FnMut(usize, &[&str]) -> Result<(), InputError>,
{
    let mut reader = csv::ReaderBuilder::new()
        .has_headers(false)
        .flexible(true)
        .trim(csv::Trim::All)
        .from_reader(RecordLimit::new(input));
    let mut record = csv::ByteRecord::new();
    loop {
        let more = reader.read_byte_record(&mut record).map_err(|e| {
            let line = match (e.kind(), e.position()) {
                // the line being read
                (csv::ErrorKind::Io(_), _) | (_, None) => reader.get_ref().lines_read + 1,
                (_, Some(p)) => reader.get_mut().line_at(p.byte()),
            };
            let why = match e.kind() {
                csv::ErrorKind::Io(io) => format!("cannot read: {io}"),
                _ => e.to_string(),
            };
            InputError::new(format!("{name}:{line}"), why)
        })?;
        if !more {
            return Ok(());
        }
        let start = record.position().map_or(0, csv::Position::byte);
        let line_no = reader.get_mut().line_at(start);
        let cells = fields(name, line_no, &record)?;
        // a line of spaces is blank
        if cells.len() == 1 && cells[0].is_empty() {
            continue;
        }
        visit(line_no, &cells)?;
    }
}
