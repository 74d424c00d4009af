//! `cargo xtask fuzz [--cases N] [--seed S] [--findings DIR]`: mutation fuzzing of the two
//! parsers that take user files, the study schema (with tolerance sheets) and turntable CSV,
//! on stable Rust.
//!
//! Each case takes a seed input (a shipped study, a shipped tolerance sheet, a valid CSV for a
//! shipped study's turntable) and applies one to four random mutations: a line deleted,
//! duplicated, swapped or repeated thousands of times (huge counts: schedules beyond
//! [`study::limits::MAX_POSITIONS`], CSV files of many rows); a value replaced by an extreme
//! or ill-typed one (`1e308`, `-0`, `nan`, `inf`, `1e-320`, `1e13`, a 30-digit integer, `""`,
//! `true`, `[1, 2]`, `{a = 1}`); a key renamed or its value retyped; the text truncated at a
//! random byte; random bytes inserted (including invalid UTF-8 and NUL); a CSV cell replaced
//! or a separator dropped. CSV cases are also read through a non-seekable reader that returns
//! short reads, as a pipe or FIFO does ([`Target::CsvPipe`]): it must give exactly what the
//! file gives. The case then asserts the contract of the input layer:
//!
//! - never a panic (caught and reported with the input);
//! - never longer than [`CASE_TIME_LIMIT`] (reported);
//! - either a valid value, whose numbers are finite and whose schedule identifies every
//!   coefficient, or a typed error that names the source and where in it (a key, a line, a
//!   column): an error without a location is a finding.
//!
//! Cases are independent and seeded by (seed, case number), so a run is reproducible for any
//! thread count and a finding can be replayed alone. They run in blocks of [`BLOCK`] cases
//! whose outcomes are folded into counters and discarded: memory does not grow with `--cases`
//! (up to 10^12). Each finding is written when its block ends, as `case-<n>.<ext>` with a
//! line in `findings.txt`, to `--findings DIR` (default `target/fuzz-findings` of the
//! workspace, found like the default study), a new directory: an existing path, even a
//! dangling symbolic link, is refused before any case runs; the directory is created at the
//! first finding only.
//!
//! # Adding a target
//! A new input kind (study names, report manifests, ...) is a [`Target`] variant with its
//! seed inputs in `seeds` and its check in `run_case` (which returns an [`Outcome`]); the
//! mutations, the blocks, the counters and the findings are shared.

use crate::InputError;
use crate::csvio::for_each_row_in;
use anyhow::{Context, Result};
use clap::Parser;
use rand_chacha::ChaCha8Rng;
use rand_core::{Rng, SeedableRng};
use rayon::prelude::*;
use std::panic::AssertUnwindSafe;
use std::path::PathBuf;
use std::time::{Duration, Instant};
use study::csv::JointColumns;
use study::{Study, StudyError, Tolerances};

/// The longest a single case may take.
pub const CASE_TIME_LIMIT: Duration = Duration::from_secs(1);

/// Cases per block: run in parallel, folded into the counters, then dropped.
pub const BLOCK: u64 = 4096;

/// Default largest text a repeated line adds to a case, KiB (enough for a schedule beyond
/// [`study::limits::MAX_POSITIONS`]; small beside [`study::limits::MAX_FILE_BYTES`]). A line
/// is repeated only in an input shorter than this, so no case exceeds about twice it: the
/// memory of a case, and so of a run, is bounded whatever the number of cases (`--repeat-kib`).
pub const REPEAT_KIB: usize = 128;

/// Findings listed in the command's output (all of them are in `findings.txt`).
pub const LISTED_FINDINGS: usize = 20;

/// The default findings directory, relative to the workspace root.
pub const DEFAULT_FINDINGS: &str = "target/fuzz-findings";

/// Arguments of `fuzz`.
#[derive(Debug, Parser)]
pub struct Args {
    /// Number of cases (accepts `1e5`, `100000`, `100_000`; up to 1e12).
    #[arg(long, allow_negative_numbers = true, default_value = "10000", value_parser = crate::args::samples)]
    pub cases: u64,
    /// Seed of the mutations.
    #[arg(long, allow_negative_numbers = true, default_value_t = 1, value_parser = crate::args::seed)]
    pub seed: u64,
    /// A new directory for the inputs of findings (default: `target/fuzz-findings` of the
    /// workspace; refused if it exists; created at the first finding).
    #[arg(long)]
    pub findings: Option<PathBuf>,
    /// Largest text one repeated line adds to a case, KiB (huge counts: schedules beyond the
    /// position limit, long CSV files). It bounds the memory of one case, and so of the run.
    #[arg(long, default_value_t = REPEAT_KIB, value_parser = repeat_kib)]
    pub repeat_kib: usize,
}

/// `--repeat-kib`: a whole number of KiB in 1..=4096.
fn repeat_kib(s: &str) -> std::result::Result<usize, String> {
    match s.parse::<usize>() {
        Ok(k) if (1..=4096).contains(&k) => Ok(k),
        _ => Err(format!(
            "must be a whole number of KiB from 1 to 4096, found `{s}`"
        )),
    }
}

/// Which parser a case drives.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Target {
    /// `Study::parse`.
    Study,
    /// `Tolerances::parse` against a shipped study's turntable.
    Tolerances,
    /// The turntable CSV loop (`orientation-error`), joint columns required.
    CsvPoses,
    /// The turntable CSV loop without joint columns (`calibration-error`).
    CsvErrors,
    /// The turntable CSV loop (joint columns required) through a non-seekable reader that
    /// returns short reads, as a pipe or FIFO does: the outcome and the rows must be those of
    /// the same bytes read as a file.
    CsvPipe,
}

impl Target {
    fn ext(self) -> &'static str {
        match self {
            Target::Study | Target::Tolerances => "toml",
            Target::CsvPoses | Target::CsvErrors | Target::CsvPipe => "csv",
        }
    }

    fn is_csv(self) -> bool {
        matches!(self, Target::CsvPoses | Target::CsvErrors | Target::CsvPipe)
    }
}

/// A seed input.
struct Seed {
    target: Target,
    /// Index of the study whose turntable a tolerance sheet or CSV belongs to.
    study: usize,
    bytes: Vec<u8>,
}

/// The outcome of one case.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Outcome {
    /// The input parsed into a valid value.
    Valid,
    /// A typed error naming where.
    Rejected,
    /// A contract violation: what happened.
    Finding(String),
}

/// One finding: the case, its target, what happened and the input.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Finding {
    /// The case number (replay with the same seed).
    pub case: u64,
    /// The parser driven.
    pub target: Target,
    /// What went wrong.
    pub what: String,
    /// The mutated input.
    pub input: Vec<u8>,
}

/// The summary of a run: counters only (the findings went to the sink as found).
#[derive(Debug, Clone, Default)]
pub struct Summary {
    /// Cases run.
    pub cases: u64,
    /// Valid inputs.
    pub valid: u64,
    /// Rejected with a located error.
    pub rejected: u64,
    /// Findings (each handed to the sink).
    pub findings: u64,
    /// The slowest case, seconds.
    pub slowest_s: f64,
}

const EXTREMES: [&str; 20] = [
    "1e308",
    "-1e308",
    "1e-320",
    "-0",
    "0",
    "nan",
    "inf",
    "-inf",
    "123456789012345678901234567890",
    "\"\"",
    "true",
    "[1, 2]",
    "{ a = 1 }",
    "\"x\"",
    "-1",
    "1e300",
    "1e12",
    "1e13",
    "1_000_000_000_000",
    "18446744073709551616",
];

fn pick<'a, T>(rng: &mut ChaCha8Rng, v: &'a [T]) -> &'a T {
    &v[(rng.next_u64() % v.len() as u64) as usize]
}

fn below(rng: &mut ChaCha8Rng, n: usize) -> usize {
    if n == 0 {
        0
    } else {
        (rng.next_u64() % n as u64) as usize
    }
}

/// One random mutation of `bytes` (text-level where the input is text).
fn mutate(rng: &mut ChaCha8Rng, bytes: &[u8], csv: bool, repeat_bytes: usize) -> Vec<u8> {
    let text = String::from_utf8_lossy(bytes).into_owned();
    let mut lines: Vec<String> = text.lines().map(String::from).collect();
    let n = lines.len();
    match rng.next_u32() % 11 {
        0 if n > 0 => {
            lines.remove(below(rng, n));
        }
        1 if n > 0 => {
            let i = below(rng, n);
            let l = lines[i].clone();
            lines.insert(below(rng, n + 1), l);
        }
        2 if n > 1 => {
            let (i, j) = (below(rng, n), below(rng, n));
            lines.swap(i, j);
        }
        3 | 4 if n > 0 => {
            // replace a value: after `=` in TOML, a cell in CSV
            let i = below(rng, n);
            let sep = if csv { ',' } else { '=' };
            let l = &lines[i];
            let parts: Vec<&str> = l.split(sep).collect();
            if parts.len() > 1 {
                let k = 1 + below(rng, parts.len() - 1);
                let mut p: Vec<String> = parts.iter().map(|s| (*s).to_string()).collect();
                p[k] = format!(" {}", pick(rng, &EXTREMES));
                lines[i] = p.join(&sep.to_string());
            }
        }
        5 if n > 0 => {
            // rename a key / column
            let i = below(rng, n);
            if let Some(pos) = lines[i].find(if csv { ',' } else { '=' }) {
                let insert = *pick(rng, &["x", "_", "Z", "é", " ", "."]);
                let at = below(rng, pos + 1);
                if lines[i].is_char_boundary(at) {
                    lines[i].insert_str(at, insert);
                }
            }
        }
        6 if n > 0 && csv => {
            let i = below(rng, n);
            if let Some(pos) = lines[i].find(',') {
                lines[i].remove(pos);
            }
        }
        7 => {
            let mut b = bytes.to_vec();
            b.truncate(below(rng, b.len() + 1));
            return b;
        }
        9 if n > 0 && bytes.len() < repeat_bytes && rng.next_u32() % 8 == 0 => {
            // a huge count: one line repeated thousands of times (a schedule of more
            // positions than allowed, a CSV file of many rows), at most `repeat_bytes` in all
            // so that a case's memory stays bounded
            let i = below(rng, n);
            let l = lines[i].clone();
            let times = (1000 + below(rng, 20_000)).min(repeat_bytes / (l.len() + 1));
            let extra: Vec<String> = (0..times).map(|_| l.clone()).collect();
            lines.splice(i..i, extra);
        }
        8 => {
            let mut b = bytes.to_vec();
            let at = below(rng, b.len() + 1);
            let junk: Vec<u8> = (0..1 + below(rng, 8))
                .map(|_| (rng.next_u32() & 0xff) as u8)
                .collect();
            b.splice(at..at, junk);
            return b;
        }
        _ if n > 0 => {
            // retype: quote a value or strip quotes
            let i = below(rng, n);
            if let Some((k, v)) = lines[i].split_once('=') {
                let v = v.trim();
                lines[i] = if v.starts_with('"') {
                    format!("{k}= {}", v.trim_matches('"'))
                } else {
                    format!("{k}= \"{v}\"")
                };
            }
        }
        _ => {}
    }
    let mut out = lines.join("\n");
    out.push('\n');
    out.into_bytes()
}

/// A located error: it names the source and, unless it concerns the whole file (unreadable,
/// empty), a key, a line or a column.
fn located(e: &StudyError, source: &str) -> bool {
    e.location.contains(source) && !e.reason.trim().is_empty()
}

fn check_study(s: &Study) -> Option<String> {
    let finite = s.positions_deg.iter().flatten().all(|v| v.is_finite())
        && s.lower_bounds_rad
            .iter()
            .all(|v| v.is_finite() && *v >= 0.0)
        && s.sensor
            .outputs()
            .iter()
            .all(|o| o.accuracy.is_finite() && o.accuracy > 0.0);
    if !finite {
        return Some("a valid study holds a non-finite or out-of-range number".into());
    }
    if s.calibration
        .outputs()
        .iter()
        .any(|o| o.regression().rank() < o.regression().names().len())
    {
        return Some("a valid study does not identify every coefficient".into());
    }
    None
}

/// Run one case on `bytes`.
fn run_case(target: Target, bytes: &[u8], study: &Study) -> Outcome {
    let source = "fuzz-input";
    guarded(|| -> Outcome {
        match target {
            Target::Study => {
                let Ok(text) = std::str::from_utf8(bytes) else {
                    // the file reader refuses invalid UTF-8 with the file named; the parser takes &str
                    return Outcome::Rejected;
                };
                match Study::parse(source, text) {
                    Ok(s) => check_study(&s).map_or(Outcome::Valid, Outcome::Finding),
                    Err(e) if located(&e, source) => Outcome::Rejected,
                    Err(e) => Outcome::Finding(format!("error without a location: {e}")),
                }
            }
            Target::Tolerances => {
                let Ok(text) = std::str::from_utf8(bytes) else {
                    return Outcome::Rejected;
                };
                let t = &study.turntable;
                match Tolerances::parse(source, text, t) {
                    Ok(tol) if tol.ub_rad.iter().all(|u| u.is_finite() && *u >= 0.0) => {
                        Outcome::Valid
                    }
                    Ok(_) => Outcome::Finding(
                        "valid tolerances with a non-finite or negative bound".into(),
                    ),
                    Err(e) if located(&e, source) => Outcome::Rejected,
                    Err(e) => Outcome::Finding(format!("error without a location: {e}")),
                }
            }
            Target::CsvPoses | Target::CsvErrors => {
                let joints = if target == Target::CsvPoses {
                    JointColumns::Required
                } else {
                    JointColumns::Absent
                };
                csv_outcome(std::io::Cursor::new(bytes), source, study, joints).0
            }
            Target::CsvPipe => {
                let file = csv_outcome(
                    std::io::Cursor::new(bytes),
                    source,
                    study,
                    JointColumns::Required,
                );
                let pipe = csv_outcome(
                    std::io::BufReader::with_capacity(7, ShortReads::new(bytes)),
                    source,
                    study,
                    JointColumns::Required,
                );
                if file == pipe {
                    pipe.0
                } else {
                    Outcome::Finding(format!(
                        "read as a pipe, the input gives {:?} ({} rows), as a file {:?} ({} rows)",
                        pipe.0, pipe.1, file.0, file.1
                    ))
                }
            }
        }
    })
}

/// A non-seekable reader that returns short reads (1 to 13 bytes, in a fixed pattern), as a
/// pipe or FIFO may.
struct ShortReads<'a> {
    bytes: &'a [u8],
    at: usize,
    step: usize,
}

impl<'a> ShortReads<'a> {
    fn new(bytes: &'a [u8]) -> Self {
        Self {
            bytes,
            at: 0,
            step: 0,
        }
    }
}

impl std::io::Read for ShortReads<'_> {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        self.step = self.step % 13 + 1;
        let n = self.step.min(buf.len()).min(self.bytes.len() - self.at);
        buf[..n].copy_from_slice(&self.bytes[self.at..self.at + n]);
        self.at += n;
        Ok(n)
    }
}

/// The outcome of the CSV loop on `reader` and a digest of the rows it accepted (their count
/// and the bits of every value), so that two ways of reading the same bytes can be compared.
fn csv_outcome<R: std::io::BufRead>(
    reader: R,
    source: &str,
    study: &Study,
    joints: JointColumns,
) -> (Outcome, u64, u64) {
    let mut bad = None;
    let (mut rows, mut digest) = (0_u64, 0_u64);
    let r = for_each_row_in(reader, source, &study.turntable, joints, |_, row| {
        let values = row
            .chi_rad
            .iter()
            .chain(&row.pose_rad)
            .chain(&row.translations_m);
        for v in values.clone() {
            digest = digest.rotate_left(7) ^ v.to_bits();
        }
        rows += 1;
        if values.clone().any(|v| !v.is_finite()) {
            bad = Some("a valid row holds a non-finite number".to_string());
        }
        Ok(())
    });
    let outcome = match (r, bad) {
        (_, Some(f)) => Outcome::Finding(f),
        (Ok(()), None) => Outcome::Valid,
        (Err(InputError { location, reason }), None) => {
            if location.contains(source) && !reason.is_empty() {
                Outcome::Rejected
            } else {
                Outcome::Finding(format!("error without a location: {location}: {reason}"))
            }
        }
    };
    (outcome, rows, digest)
}

/// Run `f`, turning a panic into a finding that carries the panic message.
fn guarded(f: impl FnOnce() -> Outcome) -> Outcome {
    std::panic::catch_unwind(AssertUnwindSafe(f)).unwrap_or_else(|p| {
        let msg = p
            .downcast_ref::<&str>()
            .map(|s| (*s).to_string())
            .or_else(|| p.downcast_ref::<String>().cloned())
            .unwrap_or_default();
        Outcome::Finding(format!("panic: {msg}"))
    })
}

fn seeds(root: &std::path::Path) -> Result<(Vec<Seed>, Vec<Study>)> {
    let names = ["gyrowheel-2017", "three-axis-example", "imu-triad-example"];
    let mut studies = Vec::new();
    let mut seeds = Vec::new();
    for (i, n) in names.iter().enumerate() {
        let path = root.join(format!("studies/{n}.toml"));
        let text = std::fs::read(&path)?;
        let s = Study::load(&path).map_err(InputError::from)?;
        seeds.push(Seed {
            target: Target::Study,
            study: i,
            bytes: text,
        });
        let header = study::csv::expected_header(&s.turntable);
        let cells = header.split(',').count();
        let row: Vec<String> = (0..cells)
            .map(|k| format!("{}", 0.1 * (k as f64 + 1.0)))
            .collect();
        let poses = format!("{header}\n{}\n{}\n", row.join(","), row.join(",")).into_bytes();
        seeds.push(Seed {
            target: Target::CsvPipe,
            study: i,
            bytes: poses.clone(),
        });
        seeds.push(Seed {
            target: Target::CsvPoses,
            study: i,
            bytes: poses,
        });
        let eh = study::csv::expected_header_for(&s.turntable, JointColumns::Absent);
        let ecells = eh.split(',').count();
        let erow: Vec<String> = (0..ecells)
            .map(|k| format!("{}", 0.05 * (k as f64 + 1.0)))
            .collect();
        seeds.push(Seed {
            target: Target::CsvErrors,
            study: i,
            bytes: format!("{eh}\n{}\n", erow.join(",")).into_bytes(),
        });
        studies.push(s);
    }
    for (file, study) in [("table4.toml", 0), ("three-axis-navigation-grade.toml", 1)] {
        seeds.push(Seed {
            target: Target::Tolerances,
            study,
            bytes: std::fs::read(root.join("studies/tolerances").join(file))?,
        });
    }
    Ok((seeds, studies))
}

/// Run case `case` of the run seeded `seed`: its target, outcome, duration (s) and input.
fn one_case(
    seeds: &[Seed],
    studies: &[Study],
    seed: u64,
    case: u64,
    repeat_bytes: usize,
) -> (Target, Outcome, f64, Vec<u8>) {
    let mut rng = ChaCha8Rng::seed_from_u64(seed ^ case.wrapping_mul(0x9E37_79B9_7F4A_7C15));
    let s = &seeds[below(&mut rng, seeds.len())];
    let mut bytes = s.bytes.clone();
    for _ in 0..1 + below(&mut rng, 4) {
        bytes = mutate(&mut rng, &bytes, s.target.is_csv(), repeat_bytes);
    }
    let t = Instant::now();
    let mut outcome = run_case(s.target, &bytes, &studies[s.study]);
    let dt = t.elapsed();
    if dt > CASE_TIME_LIMIT && !matches!(outcome, Outcome::Finding(_)) {
        outcome = Outcome::Finding(format!("took {:.2} s", dt.as_secs_f64()));
    }
    (s.target, outcome, dt.as_secs_f64(), bytes)
}

/// Run `cases` cases from `seed` on the shipped inputs under `root`, in blocks of [`BLOCK`]:
/// each block's outcomes are folded into the counters and dropped, its findings handed to
/// `sink` in case order. Memory does not grow with `cases`.
///
/// # Errors
/// When a seed input cannot be read (a broken checkout); the sink's first error.
pub fn fuzz(
    root: &std::path::Path,
    cases: u64,
    seed: u64,
    repeat_kib: usize,
    sink: &mut dyn FnMut(Finding) -> Result<()>,
) -> Result<Summary> {
    let (seeds, studies) = seeds(root)?;
    let mut sum = Summary {
        cases,
        ..Summary::default()
    };
    let mut first = 0;
    while first < cases {
        let last = first.saturating_add(BLOCK).min(cases);
        let block: Vec<(u64, Target, Outcome, f64, Vec<u8>)> = (first..last)
            .into_par_iter()
            .map(|case| {
                let (target, outcome, dt, bytes) =
                    one_case(&seeds, &studies, seed, case, repeat_kib << 10);
                let keep = if matches!(outcome, Outcome::Finding(_)) {
                    bytes
                } else {
                    Vec::new()
                };
                (case, target, outcome, dt, keep)
            })
            .collect();
        for (case, target, outcome, dt, input) in block {
            sum.slowest_s = sum.slowest_s.max(dt);
            match outcome {
                Outcome::Valid => sum.valid += 1,
                Outcome::Rejected => sum.rejected += 1,
                Outcome::Finding(what) => {
                    sum.findings += 1;
                    sink(Finding {
                        case,
                        target,
                        what,
                        input,
                    })?;
                }
            }
        }
        first = last;
    }
    Ok(sum)
}

/// The findings directory: the user's path as given (relative to the current directory), or
/// [`DEFAULT_FINDINGS`] under the workspace root (found like the default study, never
/// relative to wherever the command runs).
fn findings_dir(given: Option<&std::path::Path>, root: &std::path::Path) -> PathBuf {
    given.map_or_else(|| root.join(DEFAULT_FINDINGS), std::path::Path::to_path_buf)
}

/// Refuse a findings path that exists in any form (a file, a directory, a dangling symbolic
/// link): nothing is ever written into or over it.
fn check_findings_path(dir: &std::path::Path) -> Result<(), InputError> {
    if dir.symlink_metadata().is_ok() {
        return Err(InputError::new(
            format!("--findings {}", dir.display()),
            "exists (a file, a directory or a symbolic link): give a new path (nothing is overwritten)",
        ));
    }
    Ok(())
}

/// Writes each finding as it comes: the directory is created at the first one (it must not
/// exist then either), `case-<n>.<ext>` and a line of `findings.txt` per finding.
struct FindingsDir {
    dir: PathBuf,
    list: Option<std::fs::File>,
    listed: String,
}

impl FindingsDir {
    fn write(&mut self, f: &Finding) -> Result<()> {
        use std::io::Write;
        let shown = || format!("--findings {}", self.dir.display());
        if self.list.is_none() {
            std::fs::create_dir(&self.dir).map_err(|e| {
                if e.kind() == std::io::ErrorKind::AlreadyExists {
                    anyhow::Error::new(InputError::new(
                        shown(),
                        "appeared while fuzzing: give a new path (nothing is overwritten)",
                    ))
                } else {
                    anyhow::Error::new(e).context(format!("creating {}", self.dir.display()))
                }
            })?;
            let list = std::fs::OpenOptions::new()
                .create_new(true)
                .append(true)
                .open(self.dir.join("findings.txt"))
                .with_context(|| format!("writing {}", self.dir.display()))?;
            self.list = Some(list);
        }
        let name = format!("case-{}.{}", f.case, f.target.ext());
        std::fs::write(self.dir.join(&name), &f.input)
            .with_context(|| format!("writing {}", self.dir.join(&name).display()))?;
        let line = format!("{name} ({:?}): {}\n", f.target, f.what);
        if let Some(list) = &mut self.list {
            list.write_all(line.as_bytes())?;
            list.flush()?;
        }
        if self.listed.lines().count() < LISTED_FINDINGS {
            self.listed.push_str(&line);
        }
        Ok(())
    }
}

/// Run the command: exit 1 when there are findings (their inputs written to `--findings`).
///
/// # Errors
/// [`InputError`] for an existing findings path (checked before any case runs); an error
/// naming the findings.
pub fn run(args: &Args) -> Result<()> {
    let root = crate::paths::workspace_root()?;
    let dir = findings_dir(args.findings.as_deref(), &root);
    check_findings_path(&dir)?;
    let mut out = FindingsDir {
        dir,
        list: None,
        listed: String::new(),
    };
    let t = Instant::now();
    let sum = fuzz(&root, args.cases, args.seed, args.repeat_kib, &mut |f| {
        out.write(&f)
    })?;
    let secs = t.elapsed().as_secs_f64();
    let mut text = format!(
        "fuzz: {} cases (seed {}) in {:.1} s: {} valid, {} rejected with a located error, {} findings; slowest case {:.3} s\n",
        sum.cases, args.seed, secs, sum.valid, sum.rejected, sum.findings, sum.slowest_s
    );
    if sum.findings > 0 {
        text.push_str(&out.listed);
        if sum.findings > LISTED_FINDINGS as u64 {
            text.push_str(&format!(
                "... and {} more in {}\n",
                sum.findings - LISTED_FINDINGS as u64,
                out.dir.join("findings.txt").display()
            ));
        }
        crate::out::print(&text)?;
        anyhow::bail!("{} findings; inputs in {}", sum.findings, out.dir.display());
    }
    crate::out::print(&text)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A panic inside a case is caught and reported as a finding with its message (the
    /// harness can see what it is looking for).
    #[test]
    fn a_panicking_case_is_a_finding() {
        let prev = std::panic::take_hook();
        std::panic::set_hook(Box::new(|_| {}));
        let o = guarded(|| panic!("boom"));
        std::panic::set_hook(prev);
        assert_eq!(o, Outcome::Finding("panic: boom".into()));
    }

    /// The default findings directory is the workspace's `target/fuzz-findings` (issue 19: it
    /// was relative to the current directory); a given path is kept as given.
    #[test]
    fn findings_go_under_the_workspace_target_unless_given() {
        let root = std::path::Path::new("/work/clone");
        assert_eq!(
            findings_dir(None, root),
            std::path::Path::new("/work/clone/target/fuzz-findings")
        );
        assert_eq!(
            findings_dir(Some(std::path::Path::new("here")), root),
            std::path::Path::new("here")
        );
    }

    /// A CSV read through short reads (a pipe, a FIFO) gives exactly what the file gives:
    /// the same rows, the same errors.
    #[test]
    fn short_reads_give_what_the_file_gives() {
        let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
        let (seeds, studies) = seeds(&root).unwrap();
        let s = seeds.iter().find(|s| s.target == Target::CsvPipe).unwrap();
        let mut bytes = s.bytes.clone();
        bytes.extend_from_slice(&s.bytes[s.bytes.iter().position(|b| *b == b'\n').unwrap() + 1..]);
        for input in [
            bytes.clone(),
            bytes[..bytes.len() - 5].to_vec(),
            b"x\n".to_vec(),
        ] {
            let study = &studies[s.study];
            let file = csv_outcome(
                std::io::Cursor::new(&input),
                "f",
                study,
                JointColumns::Required,
            );
            let pipe = csv_outcome(
                std::io::BufReader::with_capacity(7, ShortReads::new(&input)),
                "f",
                study,
                JointColumns::Required,
            );
            assert_eq!(file, pipe);
        }
        assert_eq!(
            run_case(Target::CsvPipe, &bytes, &studies[s.study]),
            Outcome::Valid
        );
    }

    /// Errors count as located only when they name the source and give a reason.
    #[test]
    fn unlocated_errors_are_findings() {
        assert!(located(
            &StudyError::new("fuzz-input: key `site`", "bad"),
            "fuzz-input"
        ));
        assert!(!located(&StudyError::new("somewhere", "bad"), "fuzz-input"));
        assert!(!located(&StudyError::new("fuzz-input", " "), "fuzz-input"));
    }

    /// A few thousand cases over the shipped inputs: both valid and rejected inputs occur (the
    /// mutations neither leave everything intact nor break everything), with no finding, and
    /// the run is the same for 1 and 2 threads.
    #[test]
    fn a_few_thousand_cases_run_clean_and_reproducibly() {
        let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
        let run = |threads| {
            let mut found = Vec::new();
            let sum = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap()
                .install(|| {
                    fuzz(&root, 3000, 11, REPEAT_KIB, &mut |f| {
                        found.push(f.what);
                        Ok(())
                    })
                    .unwrap()
                });
            assert_eq!(sum.findings, found.len() as u64);
            assert!(found.is_empty(), "{found:?}");
            sum
        };
        let (a, b) = (run(1), run(2));
        assert!(
            a.valid > 100 && a.rejected > 100,
            "{} valid, {} rejected",
            a.valid,
            a.rejected
        );
        assert_eq!((a.valid, a.rejected), (b.valid, b.rejected));
    }
}
