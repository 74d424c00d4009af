//! `cargo xtask fuzz`, the mutation fuzzer (automation, not a command of the user's binary):
//! its flags and findings directory are checked before any case runs, and memory does not grow
//! with the case count. The fuzzer's own properties (a planted faulty writer is caught) are
//! unit tests of `xtask/src/fuzz.rs`.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::time::Duration;

/// A command that must refuse its input at once takes at most this (s): far above the
/// milliseconds it takes, far below the minutes (or the abort) of the old behaviour.
const PROMPT_S: u64 = 60;

/// `cargo xtask <args>` (the built binary) from the workspace root.
fn xtask(args: &[&str]) -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_xtask"));
    c.args(args)
        .current_dir(Path::new(env!("CARGO_MANIFEST_DIR")).join(".."));
    c
}

/// Run `cargo xtask <args>`, killed (and the test failed) when it does not end within
/// [`PROMPT_S`].
fn run_promptly(args: &[&str]) -> Output {
    testkit::output_within(
        xtask(args),
        Duration::from_secs(PROMPT_S),
        &format!("{args:?}"),
    )
}

/// Exit code 2, nothing on standard output, and a message with every needle, no panic.
fn refused(o: &Output, needles: &[&str]) {
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(
        o.stdout.is_empty(),
        "{}",
        String::from_utf8_lossy(&o.stdout)
    );
    for n in needles {
        assert!(err.contains(n), "stderr lacks `{n}`: {err}");
    }
    assert!(!err.contains("panicked"), "{err}");
}

/// A fresh scratch directory under the target's (never the source tree).
fn scratch(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("fuzz-{name}"));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// `--cases` takes a negative number as its value, so the range check names the flag
/// (before: "unexpected argument '-3'").
#[test]
fn a_negative_case_count_is_range_checked_by_name() {
    let o = run_promptly(&["fuzz", "--cases", "-3"]);
    refused(&o, &["--cases", "from 1 to 1e12"]);
    assert!(
        !String::from_utf8_lossy(&o.stderr).contains("unexpected argument"),
        "{o:?}"
    );
}

/// `fuzz --findings` refuses an existing path before any case runs (before: after all of
/// them; `--cases 1e12` aborted on a 72 TB allocation first) and a dangling symbolic link
/// with exit 2 naming it (before: exit 1 without a path). Nothing is created or changed.
#[test]
fn fuzz_findings_paths_are_checked_before_any_case() {
    let dir = scratch("findings");
    let existing = dir.join("mine");
    std::fs::create_dir(&existing).unwrap();
    std::fs::write(existing.join("notes.txt"), "mine").unwrap();
    let dangling = dir.join("dangling");
    std::os::unix::fs::symlink(dir.join("nowhere"), &dangling).unwrap();
    for p in [&existing, &dangling] {
        let o = run_promptly(&["fuzz", "--cases", "1e12", "--findings", p.to_str().unwrap()]);
        refused(&o, &[&format!("--findings {}", p.display()), "exists"]);
    }
    assert_eq!(
        std::fs::read_to_string(existing.join("notes.txt")).unwrap(),
        "mine"
    );
    assert!(!dir.join("nowhere").exists());
    // a clean run creates nothing
    let fresh = dir.join("fresh");
    let o = run_promptly(&[
        "fuzz",
        "--cases",
        "200",
        "--findings",
        fresh.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(!fresh.exists());
}

/// The fuzz harness streams its cases (issue 19: `--cases 1e12` aborted on a 72 TB
/// allocation; 10^5 cases kept 14 MB of results): 16 times more cases take no more memory.
/// One worker thread, so that the peak is the same case's whatever the scheduling (before:
/// +3.8 MB from 5,000 to 60,000 cases on one thread). The largest single case grows the peak
/// too (a line repeated up to `--repeat-kib`: a schedule of thousands of positions costs some
/// MB to parse), and more cases meet larger ones; with repeats held to 8 KiB every case is
/// small, and what is left is what a run keeps per case.
#[test]
fn fuzz_memory_does_not_grow_with_the_case_count() {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("memory-fuzz-findings");
    let _ = std::fs::remove_dir_all(&dir);
    let findings = dir.to_str().unwrap();
    let run = |cases: &str| {
        let args = [
            "fuzz",
            "--cases",
            cases,
            "--repeat-kib",
            "8",
            "--findings",
            findings,
        ];
        let mut c = xtask(&args);
        c.env("RAYON_NUM_THREADS", "1");
        testkit::peak_kib(c, &format!("{args:?}"))
    };
    let small = run("5000");
    let large = run("80000");
    assert!(
        large < small + 2 * 1024,
        "5,000 cases: {small} KiB, 80,000 cases: {large} KiB"
    );
    assert!(!dir.exists(), "no finding, no directory");
}
