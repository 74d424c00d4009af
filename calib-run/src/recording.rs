//! Reading a recording: a CSV file (or any reader) with a header line, streamed once; memory
//! does not depend on its length.
//!
//! Columns: a time column (`t_s` or `time_s` in seconds, or `sample` / `index`, a sample
//! index that needs the sample rate), one column per study output (named as the output, or
//! mapped with [`RecordingOptions::columns`]), and optionally the table's logged angles, one
//! column `<joint>_deg` per joint (all of them or none). Other columns are ignored.
//!
//! Every data cell used must be a finite number; time must increase by a steady step (a step
//! more than [`GAP_FACTOR`] times the first, or less than 1 / [`GAP_FACTOR`] of it, is a gap
//! or an irregular sample). Each problem is a [`RunError::Input`] naming the line and the
//! column.

use crate::error::RunError;
use sha2::{Digest, Sha256};
use std::cell::RefCell;
use std::io::Read;
use std::rc::Rc;
use std::sync::mpsc;

/// A time step more than this many times the first step (or less than its inverse) is a gap.
pub(crate) const GAP_FACTOR: f64 = 1.5;

/// How to read a recording's columns.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct RecordingOptions {
    /// The time column's header (default: the first of `t_s`, `time_s`, `sample`, `index`).
    pub time_column: Option<String>,
    /// Output name to column header, for outputs whose column is not named as the output.
    pub columns: Vec<(String, String)>,
    /// The sample rate, Hz: needed with a sample-index time column (default: the study's
    /// timing), else checked against the time column's step.
    pub sample_rate_hz: Option<f64>,
    /// The outputs' measuring range: a value with a magnitude at or above it is saturated
    /// (counted and flagged; a segment holding one is flagged).
    pub range: Option<f64>,
    /// The sample rate a sample-index time column assumes when `sample_rate_hz` is not given
    /// (the study's timing), Hz.
    pub index_sample_rate_hz: Option<f64>,
}

/// One data row.
#[derive(Debug, Clone, Copy)]
pub struct Row<'a> {
    /// 1-based line in the source.
    pub line: u64,
    /// 0-based sample index (data rows only).
    pub index: u64,
    /// Time, s.
    pub t_s: f64,
    /// The outputs, study order, each in its unit.
    pub values: &'a [f64],
    /// The table's logged angles, deg, joint order.
    pub angles_deg: Option<&'a [f64]>,
    /// Whether any output is saturated in this row.
    pub saturated: bool,
}

/// Saturated samples of one column.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub(crate) struct Saturation {
    /// The column's header.
    pub column: String,
    /// Saturated samples.
    pub count: u64,
    /// The first one's line.
    pub first_line: u64,
}

/// What reading the whole recording found.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct RecordingSummary {
    /// The source's name as given.
    pub source: String,
    /// SHA-256 of the bytes read, hex.
    pub sha256: String,
    /// Data rows.
    pub samples: u64,
    /// The sample interval, s.
    pub dt_s: f64,
    /// First to last sample plus one interval, s.
    pub duration_s: f64,
    /// Whether the table's angles were logged.
    pub angles_logged: bool,
    /// Saturated samples per output column (empty without a range).
    pub(crate) saturated: Vec<Saturation>,
}

/// SHA-256 of bytes, hex.
#[must_use]
pub fn sha256_hex(bytes: &[u8]) -> String {
    hex(&Sha256::digest(bytes))
}

fn hex(d: &[u8]) -> String {
    d.iter().map(|b| format!("{b:02x}")).collect()
}

fn parse_cell(source: &str, line: u64, header: &str, cell: &[u8]) -> Result<f64, RunError> {
    let text = std::str::from_utf8(cell.trim_ascii())
        .map_err(|_| RunError::input(source, Some(line), Some(header), "not UTF-8"))?
        .trim();
    let v: f64 = text.parse().map_err(|_| {
        RunError::input(
            source,
            Some(line),
            Some(header),
            if text.is_empty() {
                "empty cell: a number is required".to_string()
            } else {
                format!("`{text}` is not a number")
            },
        )
    })?;
    if !v.is_finite() {
        return Err(RunError::input(
            source,
            Some(line),
            Some(header),
            format!("`{text}` is not a finite number"),
        ));
    }
    Ok(v)
}

/// Read `reader` once, row by row, handing each row to `visit`: `outputs` are the study's
/// output names (their columns found by name or by `options.columns`), `joints` the table's
/// joint names (columns `<joint>_deg`, optional as a whole).
///
/// Two threads: this one reads the bytes and calls `visit`; a second one hashes the bytes,
/// parses the CSV and checks every cell and time step. They pass bounded blocks (at most
/// [`CHUNKS_IN_FLIGHT`] chunks of [`CHUNK_BYTES`] bytes one way, [`BLOCKS_IN_FLIGHT`] blocks
/// of [`BLOCK_ROWS`] rows the other), so memory does not depend on the recording's length;
/// `visit` sees the rows in order, and an error is returned after the rows before it, as one
/// thread would.
///
/// # Errors
/// [`RunError::Input`] naming the line and column: a missing column, a cell that is not a
/// finite number, a row of the wrong length, time that does not increase, a gap, an
/// irregular step, a time step that disagrees with `options.sample_rate_hz`;
/// [`RunError::Option`] for a mapping naming an unknown output; whatever `visit` returns.
pub fn read_rows<R, F>(
    mut reader: R,
    source: &str,
    outputs: &[&str],
    joints: &[&str],
    options: &RecordingOptions,
    mut visit: F,
) -> Result<RecordingSummary, RunError>
where
    R: Read,
    F: FnMut(&Row<'_>) -> Result<(), RunError>,
{
    for (out, _) in &options.columns {
        if !outputs.contains(&out.as_str()) {
            return Err(RunError::option(
                "--column",
                format!(
                    "`{out}` is not an output of the study (outputs: {})",
                    outputs.join(", ")
                ),
            ));
        }
    }
    let (byte_tx, byte_rx) = mpsc::sync_channel::<std::io::Result<Vec<u8>>>(CHUNKS_IN_FLIGHT);
    let (block_tx, block_rx) = mpsc::sync_channel::<Block>(BLOCKS_IN_FLIGHT);
    // used chunks and visited blocks go back to be filled again (no allocation per chunk or
    // block; their number is bounded by the ones in flight)
    let (chunk_back_tx, chunk_back_rx) = mpsc::channel::<Vec<u8>>();
    let (block_back_tx, block_back_rx) = mpsc::channel::<Block>();
    let n_out = outputs.len();
    std::thread::scope(|scope| {
        let worker = scope.spawn(move || {
            let pending = Rc::new(Pending {
                rows: RefCell::new(Block::default()),
                spare: block_back_rx,
                hasher: RefCell::new(Sha256::new()),
            });
            let input = ChannelRead {
                rx: byte_rx,
                back: chunk_back_tx,
                chunk: Vec::new(),
                pos: 0,
                pending: Rc::clone(&pending),
                tx: block_tx.clone(),
            };
            let parsed = parse_rows(input, source, outputs, joints, options, |row| {
                let full = {
                    let mut b = pending.rows.borrow_mut();
                    b.push(row);
                    b.line.len() >= BLOCK_ROWS
                };
                if full {
                    let full = pending.take();
                    // the reading thread stopped (its visit failed, its error is returned):
                    // stop parsing
                    block_tx.send(full).map_err(|_| {
                        RunError::input(source, None, None, "the reading thread stopped")
                    })?;
                }
                Ok(())
            });
            let rest = pending.take();
            if parsed.is_ok() || !rest.line.is_empty() {
                // rows before an error are still visited; a closed channel is the reader's
                // own error, returned there
                let _ = block_tx.send(rest);
            }
            let hash = pending.hasher.replace(Sha256::new());
            parsed.map(|p| (p, hex(&hash.finalize())))
        });
        let pumped = pump(
            &mut reader,
            byte_tx,
            &block_rx,
            &chunk_back_rx,
            &block_back_tx,
            n_out,
            &mut visit,
        );
        drop(block_rx);
        let parsed = worker
            .join()
            .unwrap_or_else(|p| std::panic::resume_unwind(p));
        pumped?;
        let (p, sha256) = parsed?;
        Ok(RecordingSummary {
            source: source.to_string(),
            sha256,
            samples: p.samples,
            dt_s: p.dt_s,
            duration_s: p.duration_s,
            angles_logged: p.angles_logged,
            saturated: p.saturated,
        })
    })
}

/// Bytes the reading thread reads at a time.
pub const CHUNK_BYTES: usize = 1 << 16;
/// Chunks read and not yet parsed, at most.
pub const CHUNKS_IN_FLIGHT: usize = 8;
/// Rows the parsing thread hands over at a time.
pub const BLOCK_ROWS: usize = 1024;
/// Blocks parsed and not yet visited, at most.
pub const BLOCKS_IN_FLIGHT: usize = 4;

/// The parsing thread's rows not yet handed over, and the visited blocks to fill again.
struct Pending {
    rows: RefCell<Block>,
    spare: mpsc::Receiver<Block>,
    /// SHA-256 of the bytes parsed.
    hasher: RefCell<Sha256>,
}

impl Pending {
    /// The rows so far, replaced by an empty block (a visited one if there is one).
    fn take(&self) -> Block {
        let fresh = self.spare.try_recv().unwrap_or_default();
        std::mem::replace(&mut *self.rows.borrow_mut(), fresh)
    }
}

/// Parsed rows, flat.
#[derive(Default)]
struct Block {
    line: Vec<u64>,
    index: Vec<u64>,
    t_s: Vec<f64>,
    values: Vec<f64>,
    angles: Option<Vec<f64>>,
    saturated: Vec<bool>,
}

impl Block {
    fn push(&mut self, r: &Row<'_>) {
        self.line.push(r.line);
        self.index.push(r.index);
        self.t_s.push(r.t_s);
        self.values.extend_from_slice(r.values);
        if let Some(a) = r.angles_deg {
            self.angles
                .get_or_insert_with(Vec::new)
                .extend_from_slice(a);
        }
        self.saturated.push(r.saturated);
    }

    fn clear(&mut self) {
        self.line.clear();
        self.index.clear();
        self.t_s.clear();
        self.values.clear();
        if let Some(a) = self.angles.as_mut() {
            a.clear();
        }
        self.saturated.clear();
    }

    fn visit<F>(&self, n_out: usize, visit: &mut F) -> Result<(), RunError>
    where
        F: FnMut(&Row<'_>) -> Result<(), RunError>,
    {
        let n = self.line.len();
        let n_ang = self.angles.as_ref().map_or(0, |a| a.len() / n.max(1));
        for i in 0..n {
            visit(&Row {
                line: self.line[i],
                index: self.index[i],
                t_s: self.t_s[i],
                values: &self.values[i * n_out..(i + 1) * n_out],
                angles_deg: self.angles.as_ref().map(|a| &a[i * n_ang..(i + 1) * n_ang]),
                saturated: self.saturated[i],
            })?;
        }
        Ok(())
    }
}

/// The parsing thread's input: the chunks the reading thread sends. Before it waits for a
/// chunk it hands over the rows parsed so far (the reading thread may be waiting for them).
struct ChannelRead {
    rx: mpsc::Receiver<std::io::Result<Vec<u8>>>,
    back: mpsc::Sender<Vec<u8>>,
    chunk: Vec<u8>,
    pos: usize,
    pending: Rc<Pending>,
    tx: mpsc::SyncSender<Block>,
}

impl Read for ChannelRead {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        while self.pos == self.chunk.len() {
            let next = match self.rx.try_recv() {
                Ok(c) => Some(c),
                Err(mpsc::TryRecvError::Empty) => {
                    let rows = self.pending.take();
                    if self.tx.send(rows).is_err() {
                        return Ok(0);
                    }
                    self.rx.recv().ok()
                }
                Err(mpsc::TryRecvError::Disconnected) => None,
            };
            match next {
                None => return Ok(0),
                Some(c) => {
                    let c = c?;
                    self.pending.hasher.borrow_mut().update(&c);
                    let used = std::mem::replace(&mut self.chunk, c);
                    // the reading thread may have stopped: then the chunk is dropped here
                    let _ = self.back.send(used);
                    self.pos = 0;
                }
            }
        }
        let n = buf.len().min(self.chunk.len() - self.pos);
        buf[..n].copy_from_slice(&self.chunk[self.pos..self.pos + n]);
        self.pos += n;
        Ok(n)
    }
}

/// The reading thread: read and send chunks; visit the parsed blocks as they come (and
/// whenever the chunk channel is full); after the end, visit the rest.
fn pump<R, F>(
    reader: &mut R,
    byte_tx: mpsc::SyncSender<std::io::Result<Vec<u8>>>,
    block_rx: &mpsc::Receiver<Block>,
    chunk_back: &mpsc::Receiver<Vec<u8>>,
    block_back: &mpsc::Sender<Block>,
    n_out: usize,
    visit: &mut F,
) -> Result<(), RunError>
where
    R: Read,
    F: FnMut(&Row<'_>) -> Result<(), RunError>,
{
    'read: loop {
        let mut buf = chunk_back.try_recv().unwrap_or_default();
        buf.resize(CHUNK_BYTES, 0);
        let mut msg = match reader.read(&mut buf) {
            Ok(0) => break,
            Ok(n) => {
                buf.truncate(n);
                Ok(buf)
            }
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => continue,
            Err(e) => Err(e),
        };
        let failed = msg.is_err();
        loop {
            match byte_tx.try_send(msg) {
                Ok(()) => break,
                Err(mpsc::TrySendError::Full(m)) => {
                    msg = m;
                    match block_rx.recv() {
                        Ok(b) => visit_block(b, n_out, visit, block_back)?,
                        Err(_) => break 'read,
                    }
                }
                Err(mpsc::TrySendError::Disconnected(_)) => break 'read,
            }
        }
        if failed {
            break;
        }
    }
    drop(byte_tx);
    for b in block_rx {
        visit_block(b, n_out, visit, block_back)?;
    }
    Ok(())
}

/// Visit a block's rows and send it back to be filled again.
fn visit_block<F>(
    mut b: Block,
    n_out: usize,
    visit: &mut F,
    back: &mpsc::Sender<Block>,
) -> Result<(), RunError>
where
    F: FnMut(&Row<'_>) -> Result<(), RunError>,
{
    b.visit(n_out, visit)?;
    b.clear();
    // the parsing thread may have ended: then the block is dropped here
    let _ = back.send(b);
    Ok(())
}

/// What the parsing thread found.
struct Parsed {
    samples: u64,
    dt_s: f64,
    duration_s: f64,
    angles_logged: bool,
    saturated: Vec<Saturation>,
}

/// Where a recording's header puts what the parser reads: the time column (an index or
/// seconds), each output's column, the joint angles' columns (all or none), and the sample
/// rate a time index is divided by.
struct Layout {
    headers: Vec<String>,
    time: usize,
    time_is_index: bool,
    output_cols: Vec<usize>,
    angle_cols: Option<Vec<usize>>,
    rate: Option<f64>,
}

impl Layout {
    /// Find the columns of `outputs` and `joints` among `headers` (trimmed, without a BOM).
    fn locate(
        headers: Vec<String>,
        source: &str,
        outputs: &[&str],
        joints: &[&str],
        options: &RecordingOptions,
    ) -> Result<Self, RunError> {
        let find = |name: &str| headers.iter().position(|h| h == name);
        let missing = |what: String| RunError::input(source, Some(1), None, what);
        let (time, time_is_index) = match &options.time_column {
            Some(t) => (
                find(t)
                    .ok_or_else(|| missing(format!("no column `{t}` (given as the time column)")))?,
                t == "sample" || t == "index",
            ),
            None => ["t_s", "time_s", "sample", "index"]
                .iter()
                .find_map(|n| find(n).map(|i| (i, *n == "sample" || *n == "index")))
                .ok_or_else(|| {
                    missing("no time column: name one `t_s` (seconds) or `sample` (index), or give the time column".into())
                })?,
        };
        let output_cols = outputs
            .iter()
            .map(|o| {
                let col = options
                    .columns
                    .iter()
                    .find(|(n, _)| n == o)
                    .map_or(*o, |(_, c)| c.as_str());
                find(col).ok_or_else(|| {
                    missing(format!(
                        "no column `{col}` for output `{o}` (name a column as the output, or map it)"
                    ))
                })
            })
            .collect::<Result<Vec<_>, _>>()?;
        let angle_names: Vec<String> = joints.iter().map(|j| format!("{j}_deg")).collect();
        let found: Vec<Option<usize>> = angle_names.iter().map(|n| find(n)).collect();
        let angle_cols = if found.iter().all(Option::is_some) && !found.is_empty() {
            Some(
                found
                    .iter()
                    .map(|c| c.unwrap_or_default())
                    .collect::<Vec<_>>(),
            )
        } else if found.iter().any(Option::is_some) {
            let absent: Vec<&str> = angle_names
                .iter()
                .zip(&found)
                .filter(|(_, f)| f.is_none())
                .map(|(n, _)| n.as_str())
                .collect();
            return Err(missing(format!(
                "the table's angles are logged for some joints only: no column {}",
                absent.join(", ")
            )));
        } else {
            None
        };
        let rate = if time_is_index {
            options.sample_rate_hz.or(options.index_sample_rate_hz)
        } else {
            options.sample_rate_hz
        };
        if time_is_index && rate.is_none() {
            return Err(RunError::option(
                "--sample-rate-hz",
                "a sample-index time column needs the sample rate (the study has no timing)",
            ));
        }
        Ok(Self {
            headers,
            time,
            time_is_index,
            output_cols,
            angle_cols,
            rate,
        })
    }
}

/// The time column's checks row by row: time increases, the first step agrees with the
/// sample rate, no later step is a gap or irregular against the first.
#[derive(Default)]
struct Clock {
    t0: f64,
    t_prev: f64,
    dt: f64,
}

impl Clock {
    /// Take row `n`'s time `t` (s); the reason when it fails a check.
    fn step(&mut self, n: u64, t: f64, layout: &Layout) -> Result<(), String> {
        if n == 0 {
            self.t0 = t;
        } else {
            let (t_prev, step) = (self.t_prev, t - self.t_prev);
            if step <= 0.0 {
                return Err(format!("time does not increase ({t_prev} then {t} s)"));
            }
            if n == 1 {
                self.dt = step;
                let dt = self.dt;
                if let Some(f) = layout.rate {
                    if !layout.time_is_index && (dt * f - 1.0).abs() > 0.01 {
                        return Err(format!(
                            "the time step {dt} s disagrees with the sample rate {f} Hz"
                        ));
                    }
                }
            } else if step > GAP_FACTOR * self.dt {
                return Err(format!(
                    "a gap of {} s after {t_prev} s (the step is {} s): samples are missing",
                    step - self.dt,
                    self.dt
                ));
            } else if step < self.dt / GAP_FACTOR {
                return Err(format!(
                    "an irregular step of {step} s (the step is {} s)",
                    self.dt
                ));
            }
        }
        self.t_prev = t;
        Ok(())
    }
}

/// Parse and check the CSV from `reader`, handing each row to `visit` (the body of
/// [`read_rows`] on the parsing thread).
fn parse_rows<R, F>(
    reader: R,
    source: &str,
    outputs: &[&str],
    joints: &[&str],
    options: &RecordingOptions,
    mut visit: F,
) -> Result<Parsed, RunError>
where
    R: Read,
    F: FnMut(&Row<'_>) -> Result<(), RunError>,
{
    // No `csv::Trim`: the csv crate trims a record by copying it into a new one (two
    // allocations per row); headers are trimmed here and each cell in `parse_cell`.
    let mut csv = csv::ReaderBuilder::new()
        .has_headers(true)
        .comment(Some(b'#'))
        .from_reader(reader);
    let headers = csv
        .byte_headers()
        .map_err(|e| csv_error(source, &e))?
        .iter()
        .map(|h| {
            String::from_utf8_lossy(h.trim_ascii())
                .trim_start_matches('\u{feff}')
                .to_string()
        })
        .collect::<Vec<_>>();
    let layout = Layout::locate(headers, source, outputs, joints, options)?;
    let headers = &layout.headers;
    let mut values = vec![0.0; outputs.len()];
    let mut angles = vec![0.0; layout.angle_cols.as_ref().map_or(0, Vec::len)];
    let mut saturated: Vec<Saturation> = layout
        .output_cols
        .iter()
        .map(|&c| Saturation {
            column: headers[c].clone(),
            count: 0,
            first_line: 0,
        })
        .collect();
    let mut record = csv::ByteRecord::new();
    let mut clock = Clock::default();
    let mut n = 0u64;
    loop {
        match csv.read_byte_record(&mut record) {
            Ok(true) => {}
            Ok(false) => break,
            Err(e) => return Err(csv_error(source, &e)),
        }
        let line = record.position().map_or(0, csv::Position::line);
        let cell = |c: usize| parse_cell(source, line, &headers[c], &record[c]);
        let raw_t = cell(layout.time)?;
        let t = if layout.time_is_index {
            raw_t / layout.rate.unwrap_or(1.0)
        } else {
            raw_t
        };
        clock.step(n, t, &layout).map_err(|reason| {
            RunError::input(source, Some(line), Some(&headers[layout.time]), reason)
        })?;
        let mut sat = false;
        for (k, &c) in layout.output_cols.iter().enumerate() {
            let v = cell(c)?;
            if let Some(r) = options.range {
                if v.abs() >= r {
                    sat = true;
                    let s = &mut saturated[k];
                    if s.count == 0 {
                        s.first_line = line;
                    }
                    s.count += 1;
                }
            }
            values[k] = v;
        }
        if let Some(cols) = &layout.angle_cols {
            for (j, &c) in cols.iter().enumerate() {
                angles[j] = cell(c)?;
            }
        }
        visit(&Row {
            line,
            index: n,
            t_s: t,
            values: &values,
            angles_deg: layout.angle_cols.as_ref().map(|_| angles.as_slice()),
            saturated: sat,
        })?;
        n += 1;
    }
    drop(csv);
    if n < 2 {
        return Err(RunError::input(
            source,
            None,
            None,
            format!("{n} data rows: a recording has at least two"),
        ));
    }
    Ok(Parsed {
        samples: n,
        dt_s: clock.dt,
        duration_s: clock.t_prev - clock.t0 + clock.dt,
        angles_logged: layout.angle_cols.is_some(),
        saturated: saturated.into_iter().filter(|s| s.count > 0).collect(),
    })
}

fn csv_error(source: &str, e: &csv::Error) -> RunError {
    let line = e.position().map(csv::Position::line);
    let reason = match e.kind() {
        csv::ErrorKind::UnequalLengths {
            expected_len, len, ..
        } => {
            format!("{len} fields where the header has {expected_len}")
        }
        csv::ErrorKind::Io(io) => format!("cannot read: {io}"),
        _ => e.to_string(),
    };
    RunError::input(source, line, None, reason)
}
