//! `cargo xtask fuzz [--cases N] [--seed S] [--findings DIR]`: mutation fuzzing of the two
//! parsers that take user files, the study schema (with tolerance sheets) and turntable CSV,
//! of the one-line texts of those files (names and labels), and of the report-directory
//! writer against crafted previous reports, on stable Rust.
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
//! - never more CPU time than [`CASE_TIME_LIMIT`] (reported; the case's own thread's CPU time,
//!   not the wall clock, so that a loaded machine does not make findings);
//! - either a valid value, whose numbers are finite and whose schedule identifies every
//!   coefficient, or a typed error that names the source and where in it (a key, a line, a
//!   column): an error without a location is a finding.
//!
//! Two targets build their inputs instead of mutating text:
//!
//! - **Names** ([`Target::Names`]): a shipped study with its `name`, one output's `unit` or one
//!   `turntable.descriptions.*` replaced, or a shipped tolerance sheet with its `name`
//!   replaced, by a value drawn from hostile pieces (`..`, `/`, `\`, absolute paths, NUL and
//!   other control characters, terminal escape sequences, bidirectional overrides, strings of
//!   up to 5,000 characters, Unicode, Markdown and HTML, shell metacharacters) mixed with
//!   valid slugs, written as any of TOML's string forms. The parse must refuse it with an
//!   error that names the key (and quotes no raw control character), or keep exactly the
//!   value given: for `name` a file-name-safe slug ([`study::is_name_slug`]) whose default
//!   report directory (derived by `report`'s own function) is one entry directly inside
//!   `target/report`; for a label, text without an unsafe character
//!   ([`tt_core::human::is_unsafe_char`]).
//! - **Manifests** ([`Target::Manifests`]): in a fresh directory per case (under one
//!   temporary directory per run, in [`SCRATCH_IN_MEMORY`] where it can), a victim file and a victim directory beside `out`, and
//!   `out` as a previous report of ours, empty, missing, or a symbolic link to a report
//!   directory; then up to four changes: crafted manifest lines (`../victim.txt`, absolute
//!   paths to the victims, control characters, very long names, names of report files and of
//!   the user's files), the signature altered or missing, duplicated or dropped lines, a
//!   listed file missing, the manifest replaced (a directory, a link, not UTF-8, empty), the
//!   user's files, directories and links in `out`, look-alike leftovers of a killed run
//!   beside it. `report`'s writer ([`ttalloc::fuzzing::Prepared`]) then writes a tiny report
//!   into `out`. Nothing may be removed or changed but a regular file that a manifest of ours
//!   (signature first, every line a report file name) lists and that is named like a report
//!   file, that manifest, and a directory beside `out` that held only such files; nothing may
//!   appear outside the report directory; the run either succeeds, only when `out` held
//!   nothing but a previous report of ours and then with exactly the new report in it, or is
//!   refused with an input error (exit code 2) with every file as it was.
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
//! A new input kind is a [`Target`] variant (with its name and findings extension) and its
//! seed inputs in `seeds`. A text target's check goes in `run_case` and shares the text
//! mutations; a target that builds its own inputs (as names and manifests do) gets a case
//! function called from `one_case`, which returns the input written for a finding and an
//! [`Outcome`]. The code under test is reached through [`Hooks`], so that a test can plant a
//! faulty version and see the property fail. The blocks, the counters (per target too) and
//! the findings are shared.

use anyhow::{Context, Result};
use clap::Parser;
use rand_chacha::ChaCha8Rng;
use rand_core::{Rng, SeedableRng};
use rayon::prelude::*;
use std::collections::BTreeMap;
use std::ffi::OsStr;
use std::panic::AssertUnwindSafe;
use std::path::{Component, Path, PathBuf};
use std::time::{Duration, Instant};
use study::csv::JointColumns;
use study::{Study, StudyError, Tolerances};
use tt_core::human::{is_unsafe_char, visible};
use tt_kinematics::Turntable;
use ttalloc::InputError;
use ttalloc::fuzzing::{
    MANIFEST, OLD_SIGNATURE, SIGNATURE, for_each_row_in, is_report_file, manifest_text, sha256_hex,
};

/// The most CPU time a single case may take (its own thread's user and system time, so a
/// loaded or shared machine does not turn slow scheduling into findings; a case runs on one
/// thread).
pub(crate) const CASE_TIME_LIMIT: Duration = Duration::from_secs(1);

/// The CPU time this thread has used so far (`CLOCK_THREAD_CPUTIME_ID`).
fn thread_cpu_time() -> Duration {
    let t = rustix::time::clock_gettime(rustix::time::ClockId::ThreadCPUTime);
    Duration::new(
        u64::try_from(t.tv_sec).unwrap_or(0),
        u32::try_from(t.tv_nsec).unwrap_or(0),
    )
}

/// Cases per block: run in parallel, folded into the counters, then dropped.
pub(crate) const BLOCK: u64 = 4096;

/// Default largest text a repeated line adds to a case, KiB (enough for a schedule beyond
/// [`study::limits::MAX_POSITIONS`]; small beside [`study::limits::MAX_FILE_BYTES`]). A line
/// is repeated only in an input shorter than this, so no case exceeds about twice it: the
/// memory of a case, and so of a run, is bounded whatever the number of cases (`--repeat-kib`).
pub(crate) const REPEAT_KIB: usize = 128;

/// Where the manifests cases work when it is a writable directory (a memory file system:
/// their small files never reach a disk, about 6 times faster than a disk's); else in the
/// system's temporary directory.
pub(crate) const SCRATCH_IN_MEMORY: &str = "/dev/shm";

/// Findings listed in the command's output (all of them are in `findings.txt`).
pub(crate) const LISTED_FINDINGS: usize = 20;

/// The default findings directory, relative to the workspace root.
pub(crate) const DEFAULT_FINDINGS: &str = "target/fuzz-findings";

/// Arguments of `fuzz`.
#[derive(Debug, Parser)]
pub(crate) struct Args {
    /// Number of cases (accepts `1e5`, `100000`, `100_000`; up to 1e12).
    #[arg(long, allow_negative_numbers = true, default_value = "10000", value_parser = cases)]
    pub cases: u64,
    /// Seed of the mutations.
    #[arg(long, allow_negative_numbers = true, default_value_t = 1, value_parser = ttalloc::fuzzing::seed)]
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

/// `--cases`: a count up to 10^12 (cases stream, memory does not grow with them).
fn cases(s: &str) -> std::result::Result<u64, String> {
    ttalloc::fuzzing::count(s, 1_000_000_000_000)
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
pub(crate) enum Target {
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
    /// A study's `name`, an output's `unit`, a `turntable.descriptions.*` or a tolerance
    /// sheet's `name` replaced by a hostile value (see the [module](self)).
    Names,
    /// `report`'s writer into a crafted previous report directory (see the [module](self)).
    Manifests,
}

impl Target {
    /// Every target, in the order of the summary.
    pub(crate) const ALL: [Target; 7] = [
        Target::Study,
        Target::Tolerances,
        Target::CsvPoses,
        Target::CsvErrors,
        Target::CsvPipe,
        Target::Names,
        Target::Manifests,
    ];

    /// The target's name in the summary.
    #[must_use]
    pub(crate) fn name(self) -> &'static str {
        match self {
            Target::Study => "study",
            Target::Tolerances => "tolerances",
            Target::CsvPoses => "csv-poses",
            Target::CsvErrors => "csv-errors",
            Target::CsvPipe => "csv-pipe",
            Target::Names => "names",
            Target::Manifests => "manifests",
        }
    }

    fn ext(self) -> &'static str {
        match self {
            Target::Study | Target::Tolerances | Target::Names => "toml",
            Target::CsvPoses | Target::CsvErrors | Target::CsvPipe => "csv",
            Target::Manifests => "txt",
        }
    }

    fn is_csv(self) -> bool {
        matches!(self, Target::CsvPoses | Target::CsvErrors | Target::CsvPipe)
    }
}

/// What a seed input is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Form {
    /// A study or CSV text.
    Text,
    /// A tolerance sheet's text.
    Sheet,
    /// How `out` starts in a manifests case (no text).
    Out(Start),
}

/// A seed input.
struct Seed {
    target: Target,
    /// Index of the study whose turntable a tolerance sheet or CSV belongs to.
    study: usize,
    bytes: Vec<u8>,
    form: Form,
}

/// The outcome of one case.
#[derive(Debug, Clone, PartialEq, Eq)]
pub(crate) enum Outcome {
    /// The input parsed into a valid value.
    Valid,
    /// A typed error naming where.
    Rejected,
    /// A contract violation: what happened.
    Finding(String),
}

/// One finding: the case, its target, what happened and the input.
#[derive(Debug, Clone, PartialEq, Eq)]
pub(crate) struct Finding {
    /// The case number (replay with the same seed).
    pub case: u64,
    /// The parser driven.
    pub target: Target,
    /// What went wrong.
    pub what: String,
    /// The mutated input.
    pub input: Vec<u8>,
}

/// The counters of one target.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub(crate) struct Counts {
    /// Cases run.
    pub cases: u64,
    /// Valid inputs (names: kept as given; manifests: the report written).
    pub valid: u64,
    /// Rejected with a located error (names: naming the key; manifests: an input error with
    /// nothing touched).
    pub rejected: u64,
    /// Findings.
    pub findings: u64,
}

/// The summary of a run: counters only (the findings went to the sink as found).
#[derive(Debug, Clone, Default)]
pub(crate) struct Summary {
    /// Cases run.
    pub cases: u64,
    /// Valid inputs.
    pub valid: u64,
    /// Rejected with a located error.
    pub rejected: u64,
    /// Findings (each handed to the sink).
    pub findings: u64,
    /// The slowest case, CPU seconds.
    pub slowest_s: f64,
    /// The counters of each target ([`Target::ALL`] order in a run).
    pub by_target: Vec<(Target, Counts)>,
}

impl Summary {
    fn count(&mut self, target: Target, outcome: &Outcome) {
        if !self.by_target.iter().any(|(t, _)| *t == target) {
            self.by_target.push((target, Counts::default()));
        }
        let Some((_, c)) = self.by_target.iter_mut().find(|(t, _)| *t == target) else {
            return;
        };
        c.cases += 1;
        match outcome {
            Outcome::Valid => {
                self.valid += 1;
                c.valid += 1;
            }
            Outcome::Rejected => {
                self.rejected += 1;
                c.rejected += 1;
            }
            Outcome::Finding(_) => {
                self.findings += 1;
                c.findings += 1;
            }
        }
    }

    /// The counters of `target` (zero when it did not run).
    #[must_use]
    pub(crate) fn of(&self, target: Target) -> Counts {
        self.by_target
            .iter()
            .find(|(t, _)| *t == target)
            .map(|(_, c)| *c)
            .unwrap_or_default()
    }
}

/// A report writer: the files (name, bytes) into the report directory `out`.
pub(crate) type WriteReport = fn(&Path, &[(String, Vec<u8>)]) -> Result<()>;

/// The code a run drives: [`Hooks::REAL`], or in the tests a planted faulty version that a
/// property must catch.
#[derive(Clone, Copy)]
pub(crate) struct Hooks {
    /// Parse a study ([`Study::parse`]).
    pub parse_study: fn(&str, &str) -> Result<Study, StudyError>,
    /// Parse a tolerance sheet for a turntable ([`Tolerances::parse`]).
    pub parse_sheet: fn(&str, &str, &Turntable) -> Result<Tolerances, StudyError>,
    /// Write a report's files (name, bytes) into the report directory `out`.
    pub write_report: WriteReport,
}

impl Hooks {
    /// The code the commands run.
    pub(crate) const REAL: Hooks = Hooks {
        parse_study: Study::parse,
        parse_sheet: Tolerances::parse,
        write_report,
    };
}

/// `report`'s writer: the output directory checked, locked and recovered
/// ([`ttalloc::fuzzing::Prepared::new`]), then the files written and swapped into place.
fn write_report(out: &Path, files: &[(String, Vec<u8>)]) -> Result<()> {
    ttalloc::fuzzing::Prepared::new(out)
        .and_then(|p| p.write(files))
        .map_err(ttalloc::fuzzing::lab)
}

/// What a run does besides its case count and seed.
#[derive(Clone, Copy)]
pub(crate) struct Config {
    /// Largest text one repeated line adds to a case, KiB (`--repeat-kib`).
    pub repeat_kib: usize,
    /// The code driven.
    pub hooks: Hooks,
    /// Only this target's seeds (`None`: every target).
    pub only: Option<Target>,
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

/// Run one case of a text target on `bytes`.
fn run_case(target: Target, bytes: &[u8], study: &Study, hooks: &Hooks) -> Outcome {
    let source = "fuzz-input";
    guarded(|| -> Outcome {
        match target {
            Target::Study => {
                let Ok(text) = std::str::from_utf8(bytes) else {
                    // the file reader refuses invalid UTF-8 with the file named; the parser takes &str
                    return Outcome::Rejected;
                };
                match (hooks.parse_study)(source, text) {
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
                match (hooks.parse_sheet)(source, text, t) {
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
            Target::Names | Target::Manifests => Outcome::Finding(format!(
                "{} cases are built by their own case function, not from one text",
                target.name()
            )),
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

// ---------------------------------------------------------------------------------------------
// Names: hostile values in the one-line texts of a study or a tolerance sheet.

/// Where a names case puts its value.
#[derive(Debug, Clone, PartialEq, Eq)]
enum Slot {
    /// The study's `name`.
    Name,
    /// Output `k`'s `unit`.
    Unit(usize),
    /// `turntable.descriptions.<key>`.
    Description(String),
    /// A tolerance sheet's `name`.
    SheetName,
}

impl Slot {
    /// The key of the value.
    fn key(&self) -> String {
        match self {
            Slot::Name | Slot::SheetName => "name".into(),
            Slot::Unit(k) => format!("sensor.outputs[{k}].unit"),
            Slot::Description(n) => format!("turntable.descriptions.{n}"),
        }
    }

    /// Whether an error's location names the key of the value (for a unit, any key of its
    /// output: a unit's family is checked where the output's noise is given in a datasheet
    /// unit).
    fn named_in(&self, location: &str) -> bool {
        match self {
            Slot::Unit(k) => location.contains(&format!("key `sensor.outputs[{k}].")),
            _ => location.contains(&format!("key `{}`", self.key())),
        }
    }
}

/// The lines of a study's (or, with `sheet`, a tolerance sheet's) text that hold a slot's
/// value: the top-level `name`, each output's `unit` (in order), each entry of
/// `[turntable.descriptions]`.
fn slots(text: &str, sheet: bool) -> Vec<(usize, Slot)> {
    let mut found = Vec::new();
    let mut table = String::new();
    let mut units = 0;
    for (i, line) in text.lines().enumerate() {
        let l = line.trim();
        if l.starts_with('[') {
            table = l.trim_matches(|c| c == '[' || c == ']').trim().to_string();
            continue;
        }
        if l.starts_with('#') {
            continue;
        }
        let Some((key, _)) = l.split_once('=') else {
            continue;
        };
        match (table.as_str(), key.trim()) {
            ("", "name") if sheet => found.push((i, Slot::SheetName)),
            ("", "name") => found.push((i, Slot::Name)),
            ("sensor.outputs", "unit") if !sheet => {
                found.push((i, Slot::Unit(units)));
                units += 1;
            }
            ("turntable.descriptions", k) if !sheet => {
                found.push((i, Slot::Description(k.to_string())));
            }
            _ => {}
        }
    }
    found
}

/// Valid names (file-name-safe slugs).
const SLUGS: [&str; 8] = [
    "gyrowheel-2017",
    "a",
    "Z9",
    "my_study.v2",
    "x-1_y.2",
    "0",
    "imu.triad-3",
    "A.B",
];

/// Hostile pieces of names and labels.
const HOSTILE: [&str; 105] = [
    // path pieces
    "..",
    ".",
    "/",
    "\\",
    "../",
    "..\\",
    "/etc/passwd",
    "C:\\Windows\\x",
    "~",
    "~/x",
    "./",
    "//",
    // NUL and other control characters
    "\0",
    "\u{1}",
    "\u{7}",
    "\u{8}",
    "\t",
    "\n",
    "\r",
    "\r\n",
    "\u{b}",
    "\u{c}",
    "\u{1f}",
    "\u{7f}",
    "\u{85}",
    "\u{9b}",
    // terminal escape sequences
    "\u{1b}",
    "\u{1b}[31m",
    "\u{1b}[2J\u{1b}[H",
    "\u{1b}]0;pwned\u{7}",
    "\u{1b}]8;;http://x\u{1b}\\",
    "\u{1b}[?1049h",
    "\u{9b}31m",
    // bidirectional and invisible formatting
    "\u{202e}",
    "\u{202d}",
    "\u{202a}",
    "\u{2066}",
    "\u{2067}",
    "\u{2069}",
    "\u{200e}",
    "\u{200f}",
    "\u{61c}",
    "\u{2028}",
    "\u{2029}",
    "\u{200b}",
    "\u{feff}",
    "\u{ad}",
    // Unicode
    "é",
    "e\u{301}",
    "日本語",
    "🙂",
    "\u{ff0f}",
    "\u{2215}",
    "\u{2024}\u{2024}",
    "Ω",
    "\u{fffd}",
    "\u{10ffff}",
    // Markdown and HTML
    "<script>alert(1)</script>",
    "<img src=x onerror=alert(1)>",
    "**bold**",
    "_em_",
    "[x](javascript:alert(1))",
    "# title",
    "|",
    "`",
    "```",
    "&amp;",
    "&lt;",
    "<!--",
    "-->",
    "\\*",
    "<",
    ">",
    "]]>",
    "---",
    // shell metacharacters
    "$(id)",
    "`id`",
    ";",
    "&&",
    "||",
    "'",
    "\"",
    "*",
    "?",
    "$HOME",
    "${IFS}",
    "-rf",
    "--help",
    " ",
    "!",
    "#",
    "%",
    "=",
    "(",
    ")",
    "{",
    "}",
    // names that look like files or devices
    ".hidden",
    "-",
    "_",
    "CON",
    "nul",
    "report.md",
    "...",
    ".report-manifest",
];

/// A long run of one character (at, below and above the name's limit, up to 5,000).
fn long_piece(rng: &mut ChaCha8Rng) -> String {
    let n = *pick(rng, &[63_usize, 64, 65, 100, 255, 256, 1000, 5000]);
    pick(
        rng,
        &[
            "a", "Z", "é", "🙂", ".", "/", "..", "-", "\u{1b}", "\u{202e}",
        ],
    )
    .repeat(n)
}

/// A value for a name or a label: a valid slug (a quarter of the cases), else one to four
/// pieces, hostile, valid or long.
fn hostile_value(rng: &mut ChaCha8Rng) -> String {
    if rng.next_u32() % 4 == 0 {
        return match rng.next_u32() % 4 {
            0 => "a".repeat(64),
            _ => (*pick(rng, &SLUGS)).to_string(),
        };
    }
    let mut s = String::new();
    for _ in 0..1 + below(rng, 4) {
        match rng.next_u32() % 10 {
            0..=4 => s.push_str(pick::<&str>(rng, &HOSTILE)),
            5..=7 => s.push_str(pick::<&str>(rng, &SLUGS)),
            _ => s.push_str(&long_piece(rng)),
        }
    }
    s
}

/// `s` escaped for a TOML basic string: `"` and `\` escaped, every control character as
/// `\uXXXX`; with `raw_newlines` (a multi-line string) a line feed kept as is, except first.
fn toml_escaped(s: &str, raw_newlines: bool) -> String {
    let mut out = String::with_capacity(s.len() + 8);
    for (i, c) in s.chars().enumerate() {
        match c {
            '"' => out.push_str("\\\""),
            '\\' => out.push_str("\\\\"),
            '\n' if raw_newlines && i > 0 => out.push('\n'),
            c if c.is_control() => out.push_str(&format!("\\u{:04X}", u32::from(c))),
            c => out.push(c),
        }
    }
    out
}

/// `s` as a TOML string that reads back as exactly `s`, in one of TOML's forms: a basic
/// string, a multi-line basic string, or (where it can hold `s`) a literal string.
fn toml_string(rng: &mut ChaCha8Rng, s: &str) -> String {
    let literal_ok = !s.contains('\'') && !s.chars().any(|c| c.is_control() && c != '\t');
    match rng.next_u32() % 3 {
        0 if literal_ok => format!("'{s}'"),
        1 => format!("\"\"\"{}\"\"\"", toml_escaped(s, true)),
        _ => format!("\"{}\"", toml_escaped(s, false)),
    }
}

/// Whether the directory `report` derives from a study named `name` (its own function,
/// [`ttalloc::fuzzing::default_report_dir`]) is one entry directly inside `<target>/report`,
/// named `name`, that the system can create (no NUL, at most 255 bytes).
fn report_dir_stays_inside(name: &str) -> bool {
    let target = Path::new("/workspace/target");
    let dir = ttalloc::fuzzing::default_report_dir(target, name);
    let Ok(rest) = dir.strip_prefix(target.join("report")) else {
        return false;
    };
    let mut parts = rest.components();
    matches!(
        (parts.next(), parts.next()),
        (Some(Component::Normal(n)), None) if n == OsStr::new(name)
    ) && !name.contains('\0')
        && name.len() <= 255
}

/// A names case from `seed` (a study's or, with `sheet`, a tolerance sheet's text): one slot's
/// value replaced by a hostile one. Returns the text and the outcome.
fn names_case(
    rng: &mut ChaCha8Rng,
    seed: &Seed,
    sheet: bool,
    study: &Study,
    hooks: &Hooks,
) -> (Vec<u8>, Outcome) {
    let text = String::from_utf8_lossy(&seed.bytes);
    let all = slots(&text, sheet);
    // a kind first (names, units, descriptions each get their share), then one of that kind
    let kinds: [fn(&Slot) -> bool; 3] = [
        |s| matches!(s, Slot::Name | Slot::SheetName),
        |s| matches!(s, Slot::Unit(_)),
        |s| matches!(s, Slot::Description(_)),
    ];
    let groups: Vec<Vec<&(usize, Slot)>> = kinds
        .iter()
        .map(|is| all.iter().filter(|(_, s)| is(s)).collect::<Vec<_>>())
        .filter(|g| !g.is_empty())
        .collect();
    if groups.is_empty() {
        return (
            seed.bytes.clone(),
            Outcome::Finding("the seed input has no name or label to replace".into()),
        );
    }
    let group = pick(rng, &groups);
    let (line, slot) = *pick(rng, group);
    let value = hostile_value(rng);
    let mut lines: Vec<String> = text.lines().map(String::from).collect();
    let key = lines[*line]
        .split_once('=')
        .map_or("", |(k, _)| k)
        .to_string();
    lines[*line] = format!("{key}= {}", toml_string(rng, &value));
    let mut input = lines.join("\n");
    input.push('\n');
    let outcome = guarded(|| check_names(slot, &value, &input, study, hooks));
    (input.into_bytes(), outcome)
}

/// The property of a names case: `text` (with `value` at `slot`) is refused with an error
/// naming the key, or accepted with the value kept exactly, safe for its use.
fn check_names(slot: &Slot, value: &str, text: &str, study: &Study, hooks: &Hooks) -> Outcome {
    let source = "fuzz-input";
    let key = slot.key();
    let parsed = match slot {
        Slot::SheetName => (hooks.parse_sheet)(source, text, &study.turntable).map(|t| t.name),
        _ => (hooks.parse_study)(source, text).map(|s| match slot {
            Slot::Name => Some(s.name),
            Slot::Unit(k) => s.sensor.outputs().get(*k).map(|o| o.unit.clone()),
            Slot::Description(n) => s.turntable.description_of(n).map(String::from),
            Slot::SheetName => None,
        }),
    };
    match parsed {
        Err(e) => {
            if !located(&e, source) || !slot.named_in(&e.location) {
                Outcome::Finding(format!(
                    "`{key}` = \"{}\" refused without naming the key: {}: {}",
                    visible(value),
                    visible(&e.location),
                    visible(&e.reason)
                ))
            } else if e
                .location
                .chars()
                .chain(e.reason.chars())
                .any(|c| is_unsafe_char(c) && c != '\n')
            {
                Outcome::Finding(format!(
                    "the error refusing `{key}` quotes a raw control character: {}: {}",
                    visible(&e.location),
                    visible(&e.reason)
                ))
            } else {
                Outcome::Rejected
            }
        }
        Ok(got) if got.as_deref() != Some(value) => Outcome::Finding(format!(
            "`{key}` = \"{}\" accepted, but the parsed value is {}",
            visible(value),
            got.map_or_else(|| "missing".into(), |g| format!("\"{}\"", visible(&g)))
        )),
        Ok(_) if value.chars().any(is_unsafe_char) => Outcome::Finding(format!(
            "`{key}` accepted with an unsafe character: \"{}\"",
            visible(value)
        )),
        Ok(_) if *slot == Slot::Name && !study::is_name_slug(value) => Outcome::Finding(format!(
            "`name` accepted but it is not a file-name-safe slug: \"{}\"",
            visible(value)
        )),
        Ok(_) if *slot == Slot::Name && !report_dir_stays_inside(value) => {
            Outcome::Finding(format!(
                "`name` = \"{}\" accepted, and its default report directory {} is not one entry inside target/report",
                visible(value),
                visible(
                    &ttalloc::fuzzing::default_report_dir(Path::new("target"), value)
                        .display()
                        .to_string()
                )
            ))
        }
        Ok(_) => Outcome::Valid,
    }
}

// ---------------------------------------------------------------------------------------------
// Manifests: `report`'s writer into crafted previous report directories.

/// How `out` starts in a manifests case, before its changes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Start {
    /// A previous report of ours (its manifest and one to four listed files).
    Report,
    /// An empty directory.
    Empty,
    /// No `out` at all.
    Missing,
    /// A symbolic link to `real`, a previous report of ours beside it.
    Linked,
}

impl Start {
    const ALL: [Start; 4] = [Start::Report, Start::Empty, Start::Missing, Start::Linked];
}

/// The tiny report every manifests case writes.
const TINY_REPORT: [(&str, &str); 3] = [
    ("report.md", "# tiny report\n"),
    ("report.html", "<p>tiny report</p>\n"),
    ("results.json", "{}\n"),
];

/// The files of the previous report a case starts from (a prefix of these).
const PREVIOUS: [&str; 4] = [
    "report.md",
    "results.json",
    "figure_1.svg",
    "end_to_end.csv",
];

/// One entry of a directory tree, as far as the property is concerned.
#[derive(Debug, Clone, PartialEq, Eq)]
enum Entry {
    Dir,
    File(Vec<u8>),
    Link(PathBuf),
    Other,
}

/// Every entry under a directory, by path relative to it (links not followed).
type Tree = BTreeMap<PathBuf, Entry>;

fn snapshot(base: &Path) -> std::io::Result<Tree> {
    let mut tree = Tree::new();
    let mut dirs = vec![PathBuf::new()];
    while let Some(rel) = dirs.pop() {
        for e in std::fs::read_dir(base.join(&rel))? {
            let e = e?;
            let path = rel.join(e.file_name());
            let t = e.file_type()?;
            let entry = if t.is_symlink() {
                Entry::Link(std::fs::read_link(e.path())?)
            } else if t.is_dir() {
                dirs.push(path.clone());
                Entry::Dir
            } else if t.is_file() {
                Entry::File(std::fs::read(e.path())?)
            } else {
                Entry::Other
            };
            tree.insert(path, entry);
        }
    }
    Ok(tree)
}

/// Whether nothing is at `p` (not even a dangling link).
fn vacant(p: &Path) -> bool {
    std::fs::symlink_metadata(p).is_err()
}

/// A previous report of ours in `dir`: its manifest and the first one to four of [`PREVIOUS`].
fn previous_report(rng: &mut ChaCha8Rng, dir: &Path) -> std::io::Result<()> {
    std::fs::create_dir(dir)?;
    let files: Vec<(&str, Vec<u8>)> = PREVIOUS[..1 + below(rng, PREVIOUS.len())]
        .iter()
        .map(|n| (*n, previous_content(n)))
        .collect();
    std::fs::write(
        dir.join(MANIFEST),
        manifest_text(files.iter().map(|(n, b)| (*n, b.as_slice()))),
    )?;
    for (n, b) in &files {
        std::fs::write(dir.join(n), b)?;
    }
    Ok(())
}

/// What a previous report of ours holds in its file `name`.
fn previous_content(name: &str) -> Vec<u8> {
    format!("previous {name}\n").into_bytes()
}

/// The name in a manifest line (`<sha256>  <name>`; the whole line when it has no hash).
fn line_name(line: &str) -> &str {
    line.split_once("  ").map_or(line, |(_, n)| n)
}

/// The manifest's lines (none when it is missing, not a file or not text).
fn manifest_lines(dir: &Path) -> Vec<String> {
    std::fs::read_to_string(dir.join(MANIFEST))
        .map(|t| t.lines().map(String::from).collect())
        .unwrap_or_default()
}

/// Write the manifest's lines (creating `dir`); left alone when the manifest is a directory or
/// a link (never written through).
fn write_manifest(dir: &Path, lines: &[String]) -> std::io::Result<()> {
    std::fs::create_dir_all(dir)?;
    let m = dir.join(MANIFEST);
    if std::fs::symlink_metadata(&m).is_ok_and(|t| !t.is_file()) {
        return Ok(());
    }
    let mut text = lines.join("\n");
    text.push('\n');
    std::fs::write(m, text)
}

/// A crafted manifest line.
fn crafted_line(rng: &mut ChaCha8Rng, base: &Path, dir: &Path) -> String {
    let abs = |p: &str| base.join(p).display().to_string();
    let dir_name = dir
        .file_name()
        .map_or_else(String::new, |n| n.to_string_lossy().into_owned());
    match below(rng, 12) {
        0 => "../victim.txt".into(),
        1 => abs("victim.txt"),
        2 => "../victim_dir/report.md".into(),
        3 => (*pick(
            rng,
            &[
                "../victim_dir",
                "..",
                ".",
                "",
                "/",
                "../",
                "..\\victim.txt",
                "./../victim.txt",
            ],
        ))
        .into(),
        4 => abs(pick::<&str>(
            rng,
            &["victim_dir/keep.md", "victim_dir/report.md", "victim_dir"],
        )),
        5 => (*pick(
            rng,
            &[
                "report\u{1b}[2J.md",
                "a\tb.md",
                "x\r.md",
                "r\u{7}.md",
                "\u{202e}dm.troper",
                "report.md\u{85}",
                "re\u{8}port.md",
                "report.md\0",
                "report.md\u{b}",
            ],
        ))
        .into(),
        6 => match below(rng, 3) {
            0 => format!("{}.md", "a".repeat(100)),
            1 => format!("{}.md", "a".repeat(101)),
            _ => "b".repeat(4000),
        },
        7 => (*pick(
            rng,
            &[
                "report.md",
                "report.html",
                "results.json",
                "figure_1.svg",
                "end_to_end.csv",
                "unlisted.svg",
            ],
        ))
        .into(),
        8 => (*pick(
            rng,
            &[
                "notes.txt",
                "my_notes.md",
                "victim.txt",
                "README",
                ".report-manifest",
                ".DS_Store",
                "figs",
            ],
        ))
        .into(),
        9 => (*pick(
            rng,
            &[
                "report.md/",
                "./report.md",
                "sub/report.md",
                "Report.md",
                " report.md",
                "report.md ",
                "report.md\r",
            ],
        ))
        .into(),
        10 => format!("../{dir_name}/report.md"),
        _ => format!("../{dir_name}/../victim.txt"),
    }
}

/// The report files the manifest in `dir` lists (by name).
fn listed_report_files(dir: &Path) -> Vec<String> {
    manifest_lines(dir)
        .iter()
        .skip(1)
        .map(|l| line_name(l).to_string())
        .filter(|n| is_report_file(n))
        .collect()
}

/// An entry of the user's in `dir`: a file, a directory, a link (to a victim, dangling), a
/// hidden file, a name that is not UTF-8; some where a listed file was.
fn user_entry(rng: &mut ChaCha8Rng, dir: &Path) -> std::io::Result<String> {
    use std::os::unix::ffi::OsStrExt;
    std::fs::create_dir_all(dir)?;
    let listed: Vec<String> = listed_report_files(dir);
    let listed = if listed.is_empty() {
        "report.md".to_string()
    } else {
        pick(rng, &listed).clone()
    };
    let link = |target: &Path, at: &Path| -> std::io::Result<()> {
        if vacant(at) {
            std::os::unix::fs::symlink(target, at)?;
        }
        Ok(())
    };
    Ok(match below(rng, 10) {
        0 => {
            std::fs::write(dir.join("notes.txt"), "the user's notes\n")?;
            "the user's notes.txt".into()
        }
        1 => {
            std::fs::write(dir.join("summary.md"), "the user's summary\n")?;
            "the user's summary.md (named like a report file, not listed)".into()
        }
        2 => {
            let p = dir.join(&listed);
            if std::fs::symlink_metadata(&p).is_ok_and(|m| m.is_file()) {
                std::fs::remove_file(&p)?;
            }
            if vacant(&p) {
                std::fs::create_dir(&p)?;
                std::fs::write(p.join("inner.txt"), "the user's file in a directory\n")?;
            }
            format!("a directory of the user's where {listed} was")
        }
        3 => {
            let p = dir.join("figs");
            if vacant(&p) {
                std::fs::create_dir(&p)?;
                std::fs::write(p.join("a.svg"), "<svg/>\n")?;
            }
            "the user's directory figs".into()
        }
        4 => {
            link(Path::new("../victim.txt"), &dir.join("link.md"))?;
            "a link link.md to ../victim.txt".into()
        }
        5 => {
            let p = dir.join(&listed);
            if std::fs::symlink_metadata(&p).is_ok_and(|m| m.is_file()) {
                std::fs::remove_file(&p)?;
            }
            link(Path::new("../victim.txt"), &p)?;
            format!("a link {listed} to ../victim.txt where the file was")
        }
        6 => {
            let victim_dir = dir.parent().unwrap_or(dir).join("victim_dir");
            link(&victim_dir, &dir.join("results_dir"))?;
            "a link to the victim directory".into()
        }
        7 => {
            link(Path::new("nowhere"), &dir.join("dangling.svg"))?;
            "a dangling link dangling.svg".into()
        }
        8 => {
            std::fs::write(dir.join(".DS_Store"), "hidden\n")?;
            "a hidden file of the user's".into()
        }
        _ => {
            std::fs::write(
                dir.join(OsStr::from_bytes(b"r\xffport.md")),
                "a name that is not UTF-8\n",
            )?;
            "a file whose name is not UTF-8".into()
        }
    })
}

/// A look-alike of a killed run's leftover beside `dir`: the user's, ours, empty, a file.
fn leftover(rng: &mut ChaCha8Rng, base: &Path, dir: &Path) -> std::io::Result<String> {
    let tag = dir
        .file_name()
        .map_or_else(String::new, |n| n.to_string_lossy().into_owned());
    let n = below(rng, 5);
    let kind = if n % 2 == 0 { "tmp" } else { "old" };
    let p = base.join(format!(".{tag}.{kind}-{}-0", 70 + n));
    if !vacant(&p) {
        return Ok(format!("{} exists already", p.display()));
    }
    let what = match n {
        0 => {
            std::fs::create_dir(&p)?;
            std::fs::write(p.join("keep.txt"), "the user's file\n")?;
            "a directory of the user's"
        }
        1 => {
            previous_report(rng, &p)?;
            "a previous report of ours"
        }
        2 => {
            std::fs::create_dir(&p)?;
            "an empty directory"
        }
        3 => {
            std::fs::write(&p, "the user's file\n")?;
            "a file of the user's"
        }
        _ => {
            previous_report(rng, &p)?;
            std::fs::write(p.join("extra.txt"), "the user's file\n")?;
            "a previous report of ours with a file of the user's"
        }
    };
    Ok(format!(
        "{what} named like a leftover: {}",
        p.file_name().unwrap_or_default().to_string_lossy()
    ))
}

/// The manifest's lines in `dir`, with the signature line when there are none.
fn with_signature(dir: &Path) -> Vec<String> {
    let mut lines = manifest_lines(dir);
    if lines.is_empty() {
        lines.push(SIGNATURE.to_string());
    }
    lines
}

/// One random change to the manifest's signature line; what it did.
fn change_signature(rng: &mut ChaCha8Rng, dir: &Path) -> std::io::Result<String> {
    let mut lines = with_signature(dir);
    let what = match below(rng, 7) {
        0 => {
            lines.remove(0);
            "removed"
        }
        6 => {
            lines[0] = OLD_SIGNATURE.to_string();
            "of the older format (names without hashes)"
        }
        1 => {
            lines[0] = SIGNATURE.replacen("files", "fi1es", 1);
            "one letter changed"
        }
        2 => {
            lines[0] = format!("{SIGNATURE} ");
            "with a trailing space"
        }
        3 => {
            lines[0] = format!("\u{feff}{SIGNATURE}");
            "after a byte-order mark"
        }
        4 => {
            lines[0] = SIGNATURE.to_uppercase();
            "in upper case"
        }
        _ => {
            lines[0] = SIGNATURE[..SIGNATURE.len() / 2].to_string();
            "cut short"
        }
    };
    write_manifest(dir, &lines)?;
    Ok(format!("manifest signature {what}"))
}

/// The manifest replaced by a directory, a link, a file that is not UTF-8, an empty file or
/// one holding only the signature; what it did.
fn replace_manifest(rng: &mut ChaCha8Rng, base: &Path, dir: &Path) -> std::io::Result<String> {
    std::fs::create_dir_all(dir)?;
    let m = dir.join(MANIFEST);
    if !std::fs::symlink_metadata(&m).is_ok_and(|t| t.is_file()) && !vacant(&m) {
        return Ok("manifest already replaced".into());
    }
    Ok(match below(rng, 5) {
        0 => {
            let _ = std::fs::remove_file(&m);
            std::fs::create_dir(&m)?;
            "manifest replaced by a directory".into()
        }
        1 => {
            let _ = std::fs::remove_file(&m);
            let copy = base.join("manifest_copy.txt");
            std::fs::write(
                &copy,
                manifest_text([("report.md", previous_content("report.md").as_slice())]),
            )?;
            std::os::unix::fs::symlink(&copy, &m)?;
            "manifest replaced by a link to a valid manifest outside out".into()
        }
        2 => {
            let mut bytes = format!("{SIGNATURE}\n").into_bytes();
            bytes.extend_from_slice(b"r\xffport.md\n");
            std::fs::write(&m, bytes)?;
            "manifest not UTF-8".into()
        }
        3 => {
            std::fs::write(&m, "")?;
            "manifest empty".into()
        }
        _ => {
            std::fs::write(&m, manifest_text(std::iter::empty()))?;
            "manifest holding only the signature".into()
        }
    })
}

/// One random change to `dir` (the report directory `out` names) or beside it; what it did.
fn change_out(rng: &mut ChaCha8Rng, base: &Path, dir: &Path) -> std::io::Result<String> {
    Ok(match below(rng, 10) {
        0 | 1 => {
            let name = crafted_line(rng, base, dir);
            // the hash of what a previous report holds there, of a user's file, or none
            let line = match below(rng, 4) {
                0 => name,
                1 => format!("{}  {name}", sha256_hex(&previous_content(&name))),
                2 => format!("{}  {name}", sha256_hex(b"the user's notes\n")),
                _ => format!("{}  {name}", "0".repeat(64)),
            };
            let mut lines = with_signature(dir);
            let at = 1 + below(rng, lines.len());
            lines.insert(at, line.clone());
            write_manifest(dir, &lines)?;
            format!("manifest line \"{}\"", visible(&line))
        }
        2 => change_signature(rng, dir)?,
        3 => {
            let mut lines = with_signature(dir);
            let i = below(rng, lines.len());
            let l = lines[i].clone();
            lines.insert(below(rng, lines.len() + 1), l.clone());
            write_manifest(dir, &lines)?;
            format!("manifest line \"{}\" duplicated", visible(&l))
        }
        4 => {
            let mut lines = manifest_lines(dir);
            if lines.len() < 2 {
                return Ok("no listed line to drop".into());
            }
            let l = lines.remove(1 + below(rng, lines.len() - 1));
            write_manifest(dir, &lines)?;
            format!("manifest line \"{}\" dropped (its file stays)", visible(&l))
        }
        5 => {
            let listed: Vec<String> = listed_report_files(dir);
            if listed.is_empty() {
                return Ok("no listed file to remove".into());
            }
            let n = pick(rng, &listed).clone();
            if std::fs::symlink_metadata(dir.join(&n)).is_ok_and(|m| m.is_file()) {
                std::fs::remove_file(dir.join(&n))?;
            }
            format!("listed file {n} missing")
        }
        6 => user_entry(rng, dir)?,
        7 => replace_manifest(rng, base, dir)?,
        8 => leftover(rng, base, dir)?,
        _ => {
            let (name, text) = *pick(
                rng,
                &[
                    (
                        "my_notes.md",
                        "the user's notes, named like a report file\n",
                    ),
                    ("notes.txt", "the user's notes\n"),
                    ("Notes.md", "the user's notes\n"),
                    ("data.csv", "the user's data\n"),
                ],
            );
            let mut lines = with_signature(dir);
            // listed by name, with the hash of a previous report's file there (not this
            // content), or with the hash of this very content (a manifest crafted so)
            let hash = if below(rng, 4) == 0 {
                sha256_hex(text.as_bytes())
            } else {
                sha256_hex(&previous_content(name))
            };
            lines.push(format!("{hash}  {name}"));
            write_manifest(dir, &lines)?;
            if vacant(&dir.join(name)) {
                std::fs::write(dir.join(name), text)?;
            }
            format!("the manifest lists the user's file {name}")
        }
    })
}

/// Build a manifests case in `base` (which must not exist): the victims, `out` as `start`
/// says, then zero to four changes. Returns what was done, and the report directory (`out`,
/// or `real` when `out` is a link to it) relative to `base`.
fn lay_out(
    rng: &mut ChaCha8Rng,
    base: &Path,
    start: Start,
) -> std::io::Result<(Vec<String>, PathBuf)> {
    std::fs::create_dir(base)?;
    std::fs::write(base.join("victim.txt"), "the user's file beside out\n")?;
    std::fs::create_dir(base.join("victim_dir"))?;
    std::fs::write(base.join("victim_dir/keep.md"), "the user's notes\n")?;
    std::fs::write(base.join("victim_dir/report.md"), "the user's report\n")?;
    let real = PathBuf::from(if start == Start::Linked {
        "real"
    } else {
        "out"
    });
    let dir = base.join(&real);
    match start {
        Start::Report => previous_report(rng, &dir)?,
        Start::Empty => std::fs::create_dir(&dir)?,
        Start::Missing => {}
        Start::Linked => {
            previous_report(rng, &dir)?;
            std::os::unix::fs::symlink("real", base.join("out"))?;
        }
    }
    let mut log = vec![format!("start: {start:?}")];
    for _ in 0..below(rng, 5) {
        log.push(change_out(rng, base, &dir)?);
    }
    Ok((log, real))
}

/// The (name, SHA-256) a manifest of ours in `dir` lists: its first line the signature, every
/// other line 64 lowercase hex digits, two spaces and the name of a report file
/// ([`is_report_file`]), each name once; `None` for anything else.
fn valid_manifest(tree: &Tree, dir: &Path) -> Option<Vec<(String, String)>> {
    let Some(Entry::File(bytes)) = tree.get(&dir.join(MANIFEST)) else {
        return None;
    };
    let text = std::str::from_utf8(bytes).ok()?;
    let mut lines = text.lines();
    if lines.next() != Some(SIGNATURE) {
        return None;
    }
    let listed: Vec<(String, String)> = lines
        .map(|l| {
            let (h, n) = l.split_once("  ")?;
            let hex = h.len() == 64 && h.bytes().all(|b| matches!(b, b'0'..=b'9' | b'a'..=b'f'));
            (hex && is_report_file(n)).then(|| (n.to_string(), h.to_string()))
        })
        .collect::<Option<_>>()?;
    // the program lists each file once: a name listed twice is no manifest of ours
    let unique = listed
        .iter()
        .enumerate()
        .all(|(i, (n, _))| listed[..i].iter().all(|(m, _)| m != n));
    unique.then_some(listed)
}

/// Whether a valid manifest's `listed` (name, SHA-256) has `name` with the hash of `bytes`:
/// a file provably written by the program.
fn listed_as(listed: &[(String, String)], name: &str, bytes: &[u8]) -> bool {
    let hash = sha256_hex(bytes);
    listed.iter().any(|(n, h)| n == name && *h == hash)
}

/// The entries directly inside `dir`.
fn children<'t>(tree: &'t Tree, dir: &'t Path) -> impl Iterator<Item = (&'t PathBuf, &'t Entry)> {
    tree.iter().filter(move |(p, _)| p.parent() == Some(dir))
}

/// Whether the entry at `p` may be removed or changed: a regular file named like a report file
/// and listed by a valid manifest of ours in its directory with the SHA-256 of its content,
/// that manifest, or a directory directly beside `out` all of whose entries may be removed.
fn may_change(before: &Tree, p: &Path) -> bool {
    let Some(dir) = p.parent() else {
        return false;
    };
    match before.get(p) {
        Some(Entry::File(bytes)) => {
            let Some(listed) = valid_manifest(before, dir) else {
                return false;
            };
            let name = p.file_name().and_then(OsStr::to_str).unwrap_or_default();
            name == MANIFEST || (is_report_file(name) && listed_as(&listed, name, bytes))
        }
        Some(Entry::Dir) => {
            dir.as_os_str().is_empty()
                && before
                    .keys()
                    .filter(|q| q.starts_with(p) && q.as_path() != p)
                    .all(|q| may_change(before, q))
        }
        _ => false,
    }
}

/// Whether the report directory `real` held nothing but a previous report of ours: missing,
/// empty, or regular files only, each the manifest or a name a valid manifest lists with the
/// SHA-256 of its content.
fn held_only_ours(before: &Tree, real: &Path) -> bool {
    match before.get(real) {
        None => true,
        Some(Entry::Dir) => {
            let mut kids = children(before, real).peekable();
            if kids.peek().is_none() {
                return true;
            }
            let Some(listed) = valid_manifest(before, real) else {
                return false;
            };
            kids.all(|(p, e)| {
                let name = p.file_name().and_then(OsStr::to_str);
                match e {
                    Entry::File(b) => {
                        name.is_some_and(|n| n == MANIFEST || listed_as(&listed, n, b))
                    }
                    _ => false,
                }
            })
        }
        _ => false,
    }
}

fn shown(p: &Path) -> String {
    visible(&p.display().to_string()).into_owned()
}

/// The property of a manifests case, from the trees before and after the writer ran.
fn judge(
    before: &Tree,
    after: &Tree,
    real: &Path,
    result: &Result<()>,
    files: &[(String, Vec<u8>)],
) -> Outcome {
    let mut wrong = Vec::new();
    for (p, e) in before {
        match after.get(p) {
            Some(a) if a == e => {}
            _ if may_change(before, p) => {}
            None => wrong.push(format!("{} was removed", shown(p))),
            Some(_) => wrong.push(format!("{} was changed", shown(p))),
        }
    }
    for (p, e) in after {
        let inside = p == real || p.parent() == Some(real);
        if before.get(p) != Some(e) && !inside {
            wrong.push(format!(
                "{} appeared outside the report directory",
                shown(p)
            ));
        }
    }
    let ours = held_only_ours(before, real);
    match result {
        Ok(()) => {
            if !ours {
                wrong.push(
                    "the report was written although out held more than a previous report of ours"
                        .into(),
                );
            }
            let mut expected: Tree = files
                .iter()
                .map(|(n, b)| (real.join(n), Entry::File(b.clone())))
                .collect();
            expected.insert(
                real.join(MANIFEST),
                Entry::File(
                    manifest_text(files.iter().map(|(n, b)| (n.as_str(), b.as_slice())))
                        .into_bytes(),
                ),
            );
            let got: Tree = after
                .iter()
                .filter(|(p, _)| p.starts_with(real) && p.as_path() != real)
                .map(|(p, e)| (p.clone(), e.clone()))
                .collect();
            if got != expected {
                wrong.push(format!(
                    "after success, out does not hold exactly the new report: {}",
                    got.keys().map(|p| shown(p)).collect::<Vec<_>>().join(", ")
                ));
            }
        }
        Err(e) => {
            if e.downcast_ref::<InputError>().is_none() {
                wrong.push(format!(
                    "failed with an error that is not an input error (exit 1): {}",
                    visible(&format!("{e:#}"))
                ));
            }
            if before != after {
                wrong.push("refused, but files changed".into());
            }
            if ours {
                wrong.push(format!(
                    "refused a previous report of ours: {}",
                    visible(&format!("{e:#}"))
                ));
            }
        }
    }
    if !wrong.is_empty() {
        wrong.truncate(4);
        return Outcome::Finding(wrong.join("; "));
    }
    if result.is_ok() {
        Outcome::Valid
    } else {
        Outcome::Rejected
    }
}

/// The text written for a manifests finding: what was done and every entry before the writer
/// ran (paths relative to the case's directory, contents escaped on one line).
fn describe(log: &[String], before: &Tree) -> String {
    let mut t = String::from(
        "# manifests case: what was laid out, and every entry before the report was written into `out`\n",
    );
    for l in log {
        t.push_str(&format!("# {l}\n"));
    }
    for (p, e) in before {
        let what = match e {
            Entry::Dir => "directory".to_string(),
            Entry::File(b) => format!("file \"{}\"", visible(&String::from_utf8_lossy(b))),
            Entry::Link(to) => format!("link to {}", shown(to)),
            Entry::Other => "other".into(),
        };
        t.push_str(&format!("{}: {what}\n", shown(p)));
    }
    t
}

/// A manifests case in `base` (a new directory): laid out, `hooks.write_report` run into
/// `base/out` with a tiny report, judged. Returns the description and the outcome.
fn manifest_case(
    rng: &mut ChaCha8Rng,
    start: Start,
    base: &Path,
    hooks: &Hooks,
) -> (Vec<u8>, Outcome) {
    let setup = |rng: &mut ChaCha8Rng| -> std::io::Result<(Vec<String>, PathBuf, Tree)> {
        let (log, real) = lay_out(rng, base, start)?;
        let before = snapshot(base)?;
        Ok((log, real, before))
    };
    let (log, real, before) = match setup(rng) {
        Ok(s) => s,
        Err(e) => {
            return (
                Vec::new(),
                Outcome::Finding(format!("laying out the case failed: {e}")),
            );
        }
    };
    let files: Vec<(String, Vec<u8>)> = TINY_REPORT
        .iter()
        .map(|(n, t)| ((*n).to_string(), t.as_bytes().to_vec()))
        .collect();
    let outcome = guarded(|| {
        let result = (hooks.write_report)(&base.join("out"), &files);
        match snapshot(base) {
            Ok(after) => judge(&before, &after, &real, &result, &files),
            Err(e) => Outcome::Finding(format!("reading the case after the writer failed: {e}")),
        }
    });
    (describe(&log, &before).into_bytes(), outcome)
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
            target: Target::Names,
            study: i,
            bytes: text.clone(),
            form: Form::Text,
        });
        seeds.push(Seed {
            target: Target::Study,
            study: i,
            bytes: text,
            form: Form::Text,
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
            form: Form::Text,
        });
        seeds.push(Seed {
            target: Target::CsvPoses,
            study: i,
            bytes: poses,
            form: Form::Text,
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
            form: Form::Text,
        });
        studies.push(s);
    }
    for (file, study) in [("table4.toml", 0), ("three-axis-navigation-grade.toml", 1)] {
        let bytes = std::fs::read(root.join("studies/tolerances").join(file))?;
        for target in [Target::Tolerances, Target::Names] {
            seeds.push(Seed {
                target,
                study,
                bytes: bytes.clone(),
                form: Form::Sheet,
            });
        }
    }
    for start in Start::ALL {
        seeds.push(Seed {
            target: Target::Manifests,
            study: 0,
            bytes: Vec::new(),
            form: Form::Out(start),
        });
    }
    Ok((seeds, studies))
}

/// Run case `case` of the run seeded `seed`: its target, outcome, duration (s) and input.
/// Manifests cases work in `scratch/case-<case>`, removed afterwards.
fn one_case(
    seeds: &[Seed],
    studies: &[Study],
    seed: u64,
    case: u64,
    config: &Config,
    scratch: &Path,
) -> (Target, Outcome, f64, Vec<u8>) {
    let mut rng = ChaCha8Rng::seed_from_u64(seed ^ case.wrapping_mul(0x9E37_79B9_7F4A_7C15));
    let s = &seeds[below(&mut rng, seeds.len())];
    let study = &studies[s.study];
    let t = thread_cpu_time();
    let (bytes, outcome) = match (s.target, s.form) {
        (Target::Manifests, Form::Out(start)) => {
            let base = scratch.join(format!("case-{case}"));
            let r = manifest_case(&mut rng, start, &base, &config.hooks);
            let _ = std::fs::remove_dir_all(&base);
            r
        }
        (Target::Names, form) => names_case(&mut rng, s, form == Form::Sheet, study, &config.hooks),
        (target, _) => {
            let mut bytes = s.bytes.clone();
            for _ in 0..1 + below(&mut rng, 4) {
                bytes = mutate(&mut rng, &bytes, target.is_csv(), config.repeat_kib << 10);
            }
            let t = thread_cpu_time();
            let outcome = run_case(target, &bytes, study, &config.hooks);
            return timed(target, outcome, thread_cpu_time().saturating_sub(t), bytes);
        }
    };
    timed(
        s.target,
        outcome,
        thread_cpu_time().saturating_sub(t),
        bytes,
    )
}

/// A case's result, a case over [`CASE_TIME_LIMIT`] made a finding.
fn timed(
    target: Target,
    mut outcome: Outcome,
    dt: Duration,
    bytes: Vec<u8>,
) -> (Target, Outcome, f64, Vec<u8>) {
    if dt > CASE_TIME_LIMIT && !matches!(outcome, Outcome::Finding(_)) {
        outcome = Outcome::Finding(format!("took {:.2} s of CPU time", dt.as_secs_f64()));
    }
    (target, outcome, dt.as_secs_f64(), bytes)
}

/// Run `cases` cases from `seed` on the shipped inputs under `root`, in blocks of [`BLOCK`]:
/// each block's outcomes are folded into the counters and dropped, its findings handed to
/// `sink` in case order. Memory does not grow with `cases`.
///
/// # Errors
/// When a seed input cannot be read (a broken checkout); the sink's first error.
pub(crate) fn fuzz(
    root: &std::path::Path,
    cases: u64,
    seed: u64,
    repeat_kib: usize,
    sink: &mut dyn FnMut(Finding) -> Result<()>,
) -> Result<Summary> {
    let config = Config {
        repeat_kib,
        hooks: Hooks::REAL,
        only: None,
    };
    fuzz_with(root, cases, seed, &config, sink)
}

/// [`fuzz`] with the code driven and the targets chosen by `config`.
///
/// # Errors
/// As [`fuzz`]; the temporary directory of the manifests cases cannot be created.
pub(crate) fn fuzz_with(
    root: &std::path::Path,
    cases: u64,
    seed: u64,
    config: &Config,
    sink: &mut dyn FnMut(Finding) -> Result<()>,
) -> Result<Summary> {
    let (mut seeds, studies) = seeds(root)?;
    if let Some(only) = config.only {
        seeds.retain(|s| s.target == only);
    }
    // one temporary directory per run for the manifests cases (a directory per case inside):
    // in memory where the system has it, so that their small files never reach a disk
    let scratch = tempfile::Builder::new()
        .prefix("xtask-fuzz-")
        .tempdir_in(SCRATCH_IN_MEMORY)
        .or_else(|_| tempfile::Builder::new().prefix("xtask-fuzz-").tempdir())
        .context("creating a temporary directory for the manifests cases")?;
    let scratch_dir = scratch.path().canonicalize()?;
    let mut sum = Summary {
        cases,
        by_target: Target::ALL.map(|t| (t, Counts::default())).to_vec(),
        ..Summary::default()
    };
    let mut first = 0;
    while first < cases {
        let last = first.saturating_add(BLOCK).min(cases);
        let block: Vec<(u64, Target, Outcome, f64, Vec<u8>)> = (first..last)
            .into_par_iter()
            .map(|case| {
                let (target, outcome, dt, bytes) =
                    one_case(&seeds, &studies, seed, case, config, &scratch_dir);
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
            sum.count(target, &outcome);
            if let Outcome::Finding(what) = outcome {
                sink(Finding {
                    case,
                    target,
                    what,
                    input,
                })?;
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
pub(crate) fn run(args: &Args) -> Result<()> {
    // the shipped studies and sheets are the seeds: a clone of the project is needed
    let root = ttalloc::fuzzing::workspace_root().map_err(|_| {
        InputError::new(
            "fuzz",
            "runs inside a clone of the project (its studies/ are the seeds); none found above the current directory or the program",
        )
    })?;
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
        "fuzz: {} cases (seed {}) in {:.1} s: {} valid, {} rejected with a located error, {} findings; slowest case {:.3} CPU s\n",
        sum.cases, args.seed, secs, sum.valid, sum.rejected, sum.findings, sum.slowest_s
    );
    for (target, c) in Target::ALL.map(|t| (t, sum.of(t))) {
        if c.cases == 0 {
            continue;
        }
        text.push_str(&format!(
            "  {:<10} {} cases: {} valid, {} rejected, {} findings\n",
            target.name(),
            c.cases,
            c.valid,
            c.rejected,
            c.findings
        ));
    }
    if sum.findings > 0 {
        text.push_str(&out.listed);
        if sum.findings > LISTED_FINDINGS as u64 {
            text.push_str(&format!(
                "... and {} more in {}\n",
                sum.findings - LISTED_FINDINGS as u64,
                out.dir.join("findings.txt").display()
            ));
        }
        ttalloc::fuzzing::print(&text)?;
        anyhow::bail!("{} findings; inputs in {}", sum.findings, out.dir.display());
    }
    ttalloc::fuzzing::print(&text)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A case is timed by its own thread's CPU time: waiting (what a loaded machine does to a
    /// case) does not count, work does, and a case over [`CASE_TIME_LIMIT`] is a finding
    /// (a wall-clock limit once reported parsing a study on a busy machine as a 1.26 s case).
    #[test]
    fn cases_are_timed_by_their_cpu_time_not_the_wall_clock() {
        let t = thread_cpu_time();
        std::thread::sleep(CASE_TIME_LIMIT + Duration::from_millis(200));
        let waited = thread_cpu_time().saturating_sub(t);
        assert!(
            waited < CASE_TIME_LIMIT / 4,
            "sleeping used {waited:?} of CPU time"
        );
        let t = thread_cpu_time();
        let mut x = 0u64;
        while thread_cpu_time().saturating_sub(t) < Duration::from_millis(30) {
            x = std::hint::black_box(x.wrapping_add(1));
        }
        assert!(thread_cpu_time().saturating_sub(t) >= Duration::from_millis(30));
        let slow = timed(
            Target::Study,
            Outcome::Valid,
            CASE_TIME_LIMIT * 2,
            Vec::new(),
        );
        assert!(matches!(slow.1, Outcome::Finding(ref m) if m.contains("CPU time")));
        let fast = timed(
            Target::Study,
            Outcome::Valid,
            CASE_TIME_LIMIT / 2,
            Vec::new(),
        );
        assert!(matches!(fast.1, Outcome::Valid));
    }

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
            run_case(Target::CsvPipe, &bytes, &studies[s.study], &Hooks::REAL),
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

    /// A few thousand cases over the shipped inputs: both valid and rejected inputs occur in
    /// every target (the mutations neither leave everything intact nor break everything; names
    /// are both accepted and refused; reports are both written and refused), with no finding,
    /// and the run is the same for 1 and 2 threads.
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
        for t in Target::ALL {
            let c = a.of(t);
            assert!(c.valid > 20 && c.rejected > 20, "{}: {c:?}", t.name());
            assert_eq!(c, b.of(t), "{}", t.name());
        }
        assert_eq!(
            Target::ALL.iter().map(|t| a.of(*t).cases).sum::<u64>(),
            a.cases
        );
    }

    /// Run `cases` cases of `target` only, with `hooks`; the findings' texts.
    fn findings_of(target: Target, cases: u64, hooks: Hooks) -> Vec<String> {
        let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
        let config = Config {
            repeat_kib: REPEAT_KIB,
            hooks,
            only: Some(target),
        };
        let mut found = Vec::new();
        let sum = fuzz_with(&root, cases, 5, &config, &mut |f| {
            assert_eq!(f.target, target);
            found.push(f.what);
            Ok(())
        })
        .unwrap();
        assert_eq!(sum.of(target).cases, cases);
        found
    }

    /// The real hooks with a planted study parser.
    fn parsing_studies_with(parse: fn(&str, &str) -> Result<Study, StudyError>) -> Hooks {
        Hooks {
            parse_study: parse,
            ..Hooks::REAL
        }
    }

    /// The real hooks with a planted tolerance sheet parser.
    fn parsing_sheets_with(
        parse: fn(&str, &str, &Turntable) -> Result<Tolerances, StudyError>,
    ) -> Hooks {
        Hooks {
            parse_sheet: parse,
            ..Hooks::REAL
        }
    }

    /// The real hooks with a planted report writer.
    fn writing_with(write: WriteReport) -> Hooks {
        Hooks {
            write_report: write,
            ..Hooks::REAL
        }
    }

    /// Asserts that one of the findings' texts contains `needle`.
    fn assert_found(found: &[String], needle: &str) {
        assert_found_where(found, needle, |f| f.contains(needle));
    }

    /// Asserts that one of the findings' texts is `what` (by the predicate `is`).
    fn assert_found_where(found: &[String], what: &str, is: impl Fn(&str) -> bool) {
        assert!(
            found.iter().any(|f| is(f)),
            "no finding is {what:?}: {found:?}"
        );
    }

    /// The names target finds every name and label of the shipped studies and sheets: the
    /// study's `name`, one `unit` per output, the turntable's descriptions, a sheet's `name`.
    #[test]
    fn the_names_target_reaches_every_name_and_label_of_the_shipped_inputs() {
        let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
        let (seeds, studies) = seeds(&root).unwrap();
        let names: Vec<&Seed> = seeds.iter().filter(|s| s.target == Target::Names).collect();
        assert_eq!(names.len(), 5);
        for s in names {
            let text = std::str::from_utf8(&s.bytes).unwrap();
            let found = slots(text, s.form == Form::Sheet);
            if s.form == Form::Sheet {
                assert_eq!(
                    found.iter().map(|(_, s)| s).collect::<Vec<_>>(),
                    [&Slot::SheetName]
                );
                continue;
            }
            let study = &studies[s.study];
            let count = |is: fn(&Slot) -> bool| found.iter().filter(|(_, s)| is(s)).count();
            assert_eq!(count(|s| *s == Slot::Name), 1);
            assert_eq!(
                count(|s| matches!(s, Slot::Unit(_))),
                study.sensor.outputs().len()
            );
            assert!(
                count(|s| matches!(s, Slot::Description(_))) >= study.turntable.n_rotation_errors()
            );
        }
    }

    /// Every hostile piece, written in each TOML string form, reads back as exactly itself: the
    /// names cases reach the study's own checks, not TOML's syntax errors.
    #[test]
    fn hostile_values_read_back_exactly_from_every_toml_string_form() {
        let mut rng = ChaCha8Rng::seed_from_u64(3);
        let long = "\u{1b}".repeat(300);
        for v in HOSTILE
            .iter()
            .chain(&SLUGS)
            .map(|s| (*s).to_string())
            .chain([long])
        {
            let mut forms = std::collections::BTreeSet::new();
            for _ in 0..40 {
                let encoded = toml_string(&mut rng, &v);
                forms.insert(encoded.chars().take(3).collect::<String>());
                let t: toml::Table = toml::from_str(&format!("name = {encoded}\n"))
                    .unwrap_or_else(|e| panic!("{v:?} as {encoded}: {e}"));
                assert_eq!(t["name"].as_str(), Some(v.as_str()), "{encoded}");
            }
            assert!(forms.len() >= 2, "{v:?}: {forms:?}");
        }
    }

    /// The property's path check, on `report`'s own derivation of the default directory:
    /// names that would leave `target/report` (or name it, or cannot be created) fail it.
    #[test]
    fn report_directories_of_escaping_names_fail_the_path_check() {
        for ok in ["gyrowheel-2017", "a", "x.y_z-1"] {
            assert!(report_dir_stays_inside(ok), "{ok}");
        }
        for bad in [
            "",
            ".",
            "..",
            "../x",
            "../../../escaped",
            "/abs",
            "a/b",
            "a/..",
            "x\0y",
        ] {
            assert!(!report_dir_stays_inside(bad), "{bad:?}");
        }
        assert!(!report_dir_stays_inside(&"a".repeat(256)));
    }

    /// The value a TOML text gives `name` at the top level (for the planted parsers).
    fn given_name(source: &str, text: &str) -> Result<String, StudyError> {
        let t: toml::Table =
            toml::from_str(text).map_err(|e| StudyError::new(source, e.to_string()))?;
        Ok(t.get("name")
            .and_then(|v| v.as_str())
            .unwrap_or_default()
            .to_string())
    }

    /// `text` with its top-level `name` line set to a harmless value.
    fn with_harmless_name(text: &str, sheet: bool) -> String {
        let mut lines: Vec<String> = text.lines().map(String::from).collect();
        for (i, slot) in slots(text, sheet) {
            if matches!(slot, Slot::Name | Slot::SheetName) {
                lines[i] = "name = \"harmless\"".into();
            }
        }
        lines.join("\n")
    }

    /// A planted bug: a study parser whose `name` check skips the slug rule.
    fn parse_study_skipping_the_slug_rule(source: &str, text: &str) -> Result<Study, StudyError> {
        let name = given_name(source, text)?;
        let mut s = Study::parse(source, &with_harmless_name(text, false))?;
        s.name = name;
        Ok(s)
    }

    /// A planted bug: a tolerance sheet parser that does not check its `name`.
    fn parse_sheet_without_the_label_check(
        source: &str,
        text: &str,
        turntable: &Turntable,
    ) -> Result<Tolerances, StudyError> {
        let name = given_name(source, text)?;
        let mut t = Tolerances::parse(source, &with_harmless_name(text, true), turntable)?;
        t.name = Some(name);
        Ok(t)
    }

    /// The names property catches a study parser that skips the slug rule for `name`: the
    /// hostile names it lets through are findings (path pieces that leave `target/report`
    /// among them), so the target cannot pass silently.
    #[test]
    fn a_name_check_that_skips_the_slug_rule_is_caught() {
        let hooks = parsing_studies_with(parse_study_skipping_the_slug_rule);
        let found = findings_of(Target::Names, 600, hooks);
        assert_found_where(&found, "a slug finding on `name`", |f| {
            f.contains("`name`") && f.contains("not a file-name-safe slug")
        });
        assert_found(&found, "`name` accepted with an unsafe character");
        assert!(found.iter().all(|f| f.contains("`name`")), "{found:?}");
    }

    /// The names property catches a sheet parser that lets control characters into its `name`
    /// label.
    #[test]
    fn a_label_check_that_lets_control_characters_through_is_caught() {
        let hooks = parsing_sheets_with(parse_sheet_without_the_label_check);
        let found = findings_of(Target::Names, 600, hooks);
        assert_found_where(&found, "an unsafe `name` label finding", |f| {
            f.starts_with("`name` accepted with an unsafe character")
        });
    }

    /// The names property catches a parser that accepts a name but changes it (here: the
    /// study parser's own name kept in place of the one given).
    #[test]
    fn a_parser_that_alters_an_accepted_name_is_caught() {
        fn parse_keeping_a_fixed_name(source: &str, text: &str) -> Result<Study, StudyError> {
            Study::parse(source, &with_harmless_name(text, false))
        }
        let hooks = parsing_studies_with(parse_keeping_a_fixed_name);
        let found = findings_of(Target::Names, 300, hooks);
        assert_found(&found, "accepted, but the parsed value is \"harmless\"");
    }

    /// A planted bug: a report writer that trusts the manifest, removing every line it lists
    /// relative to `out` (`../victim.txt` and absolute paths too), then writes the files
    /// (through whatever is at their names).
    fn write_trusting_the_manifest(out: &Path, files: &[(String, Vec<u8>)]) -> Result<()> {
        if let Ok(t) = std::fs::read_to_string(out.join(MANIFEST)) {
            for line in t.lines().skip(1).filter(|l| !l.is_empty()) {
                let _ = std::fs::remove_file(out.join(line_name(line)));
            }
        }
        write_with_manifest(out, files)
    }

    /// Writes `files` into `out` (created if needed) and a manifest listing them: what the
    /// planted writers do after their (wrong) clean-up.
    fn write_with_manifest(out: &Path, files: &[(String, Vec<u8>)]) -> Result<()> {
        std::fs::create_dir_all(out)?;
        for (n, b) in files {
            std::fs::write(out.join(n), b)?;
        }
        std::fs::write(
            out.join(MANIFEST),
            manifest_text(files.iter().map(|(n, b)| (n.as_str(), b.as_slice()))),
        )?;
        Ok(())
    }

    /// A planted bug (issue 32): the real writer's checks, but a listed report file counts as
    /// ours by its name alone: the previous report's files whose hashes are not checked are
    /// removed, then the report written.
    fn write_trusting_the_names(out: &Path, files: &[(String, Vec<u8>)]) -> Result<()> {
        if let Ok(t) = std::fs::read_to_string(out.join(MANIFEST)) {
            if t.lines().next() == Some(SIGNATURE) {
                for line in t.lines().skip(1) {
                    if is_report_file(line_name(line)) {
                        let _ = std::fs::remove_file(out.join(line_name(line)));
                    }
                }
            }
        }
        write_report(out, files)
    }

    /// The manifests property catches a writer that removes a listed file whose content is not
    /// what the manifest's hash says (the user's `my_notes.md` listed by name).
    #[test]
    fn a_writer_that_trusts_the_listed_names_is_caught() {
        let hooks = writing_with(write_trusting_the_names);
        let found = findings_of(Target::Manifests, 400, hooks);
        assert_found(&found, "out/my_notes.md was removed");
    }

    /// A planted bug: a report writer that replaces `out` whatever it holds.
    fn write_over_anything(out: &Path, files: &[(String, Vec<u8>)]) -> Result<()> {
        let dir = std::fs::canonicalize(out).unwrap_or_else(|_| out.to_path_buf());
        let _ = std::fs::remove_dir_all(&dir);
        write_with_manifest(&dir, files)
    }

    /// The manifests property catches a writer that follows `../victim.txt` or an absolute
    /// path in a manifest: the victims beside `out` are findings.
    #[test]
    fn a_writer_that_trusts_the_manifest_is_caught() {
        let hooks = writing_with(write_trusting_the_manifest);
        let found = findings_of(Target::Manifests, 400, hooks);
        for victim in ["victim.txt was removed", "victim_dir/report.md was removed"] {
            assert_found(&found, victim);
        }
        assert_found(&found, "victim.txt was changed");
    }

    /// The manifests property catches a writer that replaces `out` whatever it holds: the
    /// user's files in `out` removed, a report written over a directory that was not ours.
    #[test]
    fn a_writer_that_replaces_out_whatever_it_holds_is_caught() {
        let found = findings_of(Target::Manifests, 400, writing_with(write_over_anything));
        assert_found(&found, "out/notes.txt was removed");
        assert_found(
            &found,
            "written although out held more than a previous report",
        );
    }

    /// The manifests property catches a writer that refuses a previous report of ours, or
    /// refuses with an error that is not an input error.
    #[test]
    fn a_writer_that_refuses_everything_with_exit_1_is_caught() {
        fn refuse(_: &Path, _: &[(String, Vec<u8>)]) -> Result<()> {
            anyhow::bail!("disk on fire")
        }
        let found = findings_of(Target::Manifests, 100, writing_with(refuse));
        assert!(
            found.iter().all(|f| f.contains("not an input error")),
            "{found:?}"
        );
        assert_found(&found, "refused a previous report of ours");
    }
}
