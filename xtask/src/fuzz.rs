//! `cargo xtask fuzz [--cases N] [--seed S] [--findings DIR]`: mutation fuzzing of the two
//! parsers that take user files, the study schema (with tolerance sheets) and turntable CSV,
//! on stable Rust.
//!
//! Each case takes a seed input (a shipped study, a shipped tolerance sheet, a valid CSV for a
//! shipped study's turntable) and applies one to four random mutations: a line deleted,
//! duplicated or swapped; a value replaced by an extreme or ill-typed one (`1e308`, `-0`,
//! `nan`, `inf`, `1e-320`, a 30-digit integer, `""`, `true`, `[1, 2]`, `{a = 1}`); a key
//! renamed or its value retyped; the text truncated at a random byte; random bytes inserted
//! (including invalid UTF-8 and NUL); a CSV cell replaced or a separator dropped. The case then
//! asserts the contract of the input layer:
//!
//! - never a panic (caught and reported with the input);
//! - never longer than [`CASE_TIME_LIMIT`] (reported);
//! - either a valid value, whose numbers are finite and whose schedule identifies every
//!   coefficient, or a typed error that names the source and where in it (a key, a line, a
//!   column): an error without a location is a finding.
//!
//! Cases are independent and seeded by (seed, case number), so a run is reproducible for any
//! thread count and a finding can be replayed alone. Findings are written (only when there are
//! some) as `case-<n>.<ext>` files with a `findings.txt` summary to `--findings DIR`, a new
//! directory (an existing one is refused rather than overwritten).

use crate::InputError;
use crate::csvio::for_each_row_in;
use anyhow::Result;
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

/// Arguments of `fuzz`.
#[derive(Debug, Parser)]
pub struct Args {
    /// Number of cases (accepts `1e5`, `100000`, `100_000`).
    #[arg(long, allow_negative_numbers = true, default_value = "10000", value_parser = crate::args::samples)]
    pub cases: u64,
    /// Seed of the mutations.
    #[arg(long, allow_negative_numbers = true, default_value_t = 1, value_parser = crate::args::seed)]
    pub seed: u64,
    /// Directory for the inputs of findings (created; must not exist).
    #[arg(long, default_value = "target/fuzz-findings")]
    pub findings: PathBuf,
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
}

impl Target {
    fn ext(self) -> &'static str {
        match self {
            Target::Study | Target::Tolerances => "toml",
            Target::CsvPoses | Target::CsvErrors => "csv",
        }
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

/// The summary of a run.
#[derive(Debug, Clone, Default)]
pub struct Summary {
    /// Cases run.
    pub cases: u64,
    /// Valid inputs.
    pub valid: u64,
    /// Rejected with a located error.
    pub rejected: u64,
    /// (case, target, what, input) of each finding.
    pub findings: Vec<(u64, Target, String, Vec<u8>)>,
    /// The slowest case, seconds.
    pub slowest_s: f64,
}

const EXTREMES: [&str; 16] = [
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
fn mutate(rng: &mut ChaCha8Rng, bytes: &[u8], csv: bool) -> Vec<u8> {
    let text = String::from_utf8_lossy(bytes).into_owned();
    let mut lines: Vec<String> = text.lines().map(String::from).collect();
    let n = lines.len();
    match rng.next_u32() % 10 {
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
fn run_case(target: Target, bytes: &[u8], studies: &[Study]) -> Outcome {
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
                let t = &studies[0].turntable;
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
                let mut bad = None;
                let r = for_each_row_in(
                    std::io::Cursor::new(bytes),
                    source,
                    &studies[0].turntable,
                    joints,
                    |_, row| {
                        if row
                            .chi_rad
                            .iter()
                            .chain(&row.pose_rad)
                            .chain(&row.translations_m)
                            .any(|v| !v.is_finite())
                        {
                            bad = Some("a valid row holds a non-finite number".to_string());
                        }
                        Ok(())
                    },
                );
                match (r, bad) {
                    (_, Some(f)) => Outcome::Finding(f),
                    (Ok(()), None) => Outcome::Valid,
                    (Err(InputError { location, reason }), None) => {
                        if location.contains(source) && !reason.is_empty() {
                            Outcome::Rejected
                        } else {
                            Outcome::Finding(format!(
                                "error without a location: {location}: {reason}"
                            ))
                        }
                    }
                }
            }
        }
    })
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
        seeds.push(Seed {
            target: Target::CsvPoses,
            study: i,
            bytes: format!("{header}\n{}\n{}\n", row.join(","), row.join(",")).into_bytes(),
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

/// Run `cases` cases from `seed` on the shipped inputs under `root`.
///
/// # Errors
/// When a seed input cannot be read (a broken checkout).
pub fn fuzz(root: &std::path::Path, cases: u64, seed: u64) -> Result<Summary> {
    let (seeds, studies) = seeds(root)?;
    let results: Vec<(u64, Target, Outcome, f64, Vec<u8>)> = (0..cases)
        .into_par_iter()
        .map(|case| {
            let mut rng =
                ChaCha8Rng::seed_from_u64(seed ^ case.wrapping_mul(0x9E37_79B9_7F4A_7C15));
            let s = &seeds[below(&mut rng, seeds.len())];
            let csv = matches!(s.target, Target::CsvPoses | Target::CsvErrors);
            let mut bytes = s.bytes.clone();
            for _ in 0..1 + below(&mut rng, 4) {
                bytes = mutate(&mut rng, &bytes, csv);
            }
            let own: Vec<Study> = vec![studies[s.study].clone()];
            let t = Instant::now();
            let mut outcome = run_case(s.target, &bytes, &own);
            let dt = t.elapsed();
            if dt > CASE_TIME_LIMIT && !matches!(outcome, Outcome::Finding(_)) {
                outcome = Outcome::Finding(format!("took {:.2} s", dt.as_secs_f64()));
            }
            let keep = if matches!(outcome, Outcome::Finding(_)) {
                bytes
            } else {
                Vec::new()
            };
            (case, s.target, outcome, dt.as_secs_f64(), keep)
        })
        .collect();
    let mut sum = Summary {
        cases,
        ..Summary::default()
    };
    for (case, target, outcome, dt, bytes) in results {
        sum.slowest_s = sum.slowest_s.max(dt);
        match outcome {
            Outcome::Valid => sum.valid += 1,
            Outcome::Rejected => sum.rejected += 1,
            Outcome::Finding(what) => sum.findings.push((case, target, what, bytes)),
        }
    }
    Ok(sum)
}

/// Run the command: exit 1 when there are findings (their inputs written to `--findings`).
///
/// # Errors
/// [`InputError`] for an existing findings directory; an error naming the findings.
pub fn run(args: &Args) -> Result<()> {
    let root = crate::paths::workspace_root()?;
    let t = Instant::now();
    let sum = fuzz(&root, args.cases, args.seed)?;
    let secs = t.elapsed().as_secs_f64();
    let mut text = format!(
        "fuzz: {} cases (seed {}) in {:.1} s: {} valid, {} rejected with a located error, {} findings; slowest case {:.3} s\n",
        sum.cases,
        args.seed,
        secs,
        sum.valid,
        sum.rejected,
        sum.findings.len(),
        sum.slowest_s
    );
    if !sum.findings.is_empty() {
        let dir = &args.findings;
        if dir.exists() {
            return Err(InputError::new(
                format!("--findings {}", dir.display()),
                "exists: give a new directory (nothing is overwritten)",
            )
            .into());
        }
        std::fs::create_dir_all(dir)?;
        let mut list = String::new();
        for (case, target, what, bytes) in &sum.findings {
            let name = format!("case-{case}.{}", target.ext());
            std::fs::write(dir.join(&name), bytes)?;
            list.push_str(&format!("{name} ({target:?}): {what}\n"));
        }
        std::fs::write(dir.join("findings.txt"), &list)?;
        text.push_str(&list);
        crate::out::print(&text)?;
        anyhow::bail!(
            "{} findings; inputs in {}",
            sum.findings.len(),
            dir.display()
        );
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
            rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap()
                .install(|| fuzz(&root, 3000, 11).unwrap())
        };
        let (a, b) = (run(1), run(2));
        assert!(
            a.findings.is_empty(),
            "{:?}",
            a.findings.iter().map(|f| &f.2).collect::<Vec<_>>()
        );
        assert!(
            a.valid > 100 && a.rejected > 100,
            "{} valid, {} rejected",
            a.valid,
            a.rejected
        );
        assert_eq!((a.valid, a.rejected), (b.valid, b.rejected));
    }
}
