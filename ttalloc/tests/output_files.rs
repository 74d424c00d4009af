//! Issue 32 §1, §3, §5: what the program writes never costs the user a file, a lock or a
//! directory's permissions, and every path it prints is one visible line.
//!
//! - A report file is removed only while its content matches the SHA-256 its manifest lists: a
//!   manifest naming the user's `notes.md`, a report file the user edited, an older manifest
//!   without hashes: refused (exit 2 naming it), nothing touched.
//! - The lock beside `--out` is removed only when it is a lock of this program (its signature):
//!   another program's file at that name (a live or dead process id) is refused and kept.
//! - `--out`'s mode and owner are kept; a directory its owner may not write is refused.
//! - Paths print escaped; the "open" hint is one shell word; `--out od/.` is refused before the
//!   work; two flags naming one file are refused before anything is written.

mod common;

use common::{
    assert_input_error, hidden_names, names, ok, paper_into, run, sha256_hex, stderr, stdout, write,
};
use std::os::unix::fs::{MetadataExt, PermissionsExt};
use std::path::Path;
use std::process::Command;

/// The first line of a manifest of this version (with hashes).
const SIGNATURE: &str = "# files written by `cargo xtask` (gyrowheel turntable project) with their SHA-256; a file is replaced only while it matches";

/// The first line of a manifest of the versions before (names only).
const OLD_SIGNATURE: &str =
    "# files written by `cargo xtask` (gyrowheel turntable project); safe to replace as a whole";

/// The permission bits of `p` (with set-id and sticky bits).
fn mode(p: &Path) -> u32 {
    std::fs::metadata(p).unwrap().permissions().mode() & 0o7777
}

/// Issue 32 §1: a name in a manifest proves nothing. The user's `notes.md` listed by an
/// older manifest (names only: the reproduction), or listed with a hash that is not
/// its content's, and a report file the user edited after a run: each is refused with exit 2
/// naming the file, before the work, and every file stays as it was. (Before: the old-format
/// manifest made `report` delete `notes.md`, exit 0; the edited `report.md` was replaced.)
#[test]
fn a_listed_file_whose_content_is_not_what_was_written_is_refused_and_kept() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    std::fs::create_dir(&out).unwrap();
    let notes = write(&out, "notes.md", "my notes\n");
    let manifests = [
        format!("{OLD_SIGNATURE}\nnotes.md\n"),
        format!(
            "{SIGNATURE}\n{}  notes.md\n",
            sha256_hex(b"what a report would have written\n")
        ),
    ];
    for (manifest, needle) in manifests.iter().zip(["older version", "notes.md"]) {
        std::fs::write(out.join(".report-manifest"), manifest).unwrap();
        let o = paper_into(&out);
        assert_input_error(&o, &[out.to_str().unwrap(), needle, "nothing was touched"]);
        assert_eq!(std::fs::read_to_string(&notes).unwrap(), "my notes\n");
        assert_eq!(names(&out), [".report-manifest", "notes.md"]);
        assert_eq!(
            &std::fs::read_to_string(out.join(".report-manifest")).unwrap(),
            manifest
        );
        assert_eq!(names(dir.path()), ["out"], "nothing beside out");
    }

    // a report of ours, then the user edits report.md: the edit is theirs
    let mine = dir.path().join("mine");
    ok(&paper_into(&mine));
    let mut edited = std::fs::read_to_string(mine.join("report.md")).unwrap();
    edited.push_str("\nMy conclusions.\n");
    std::fs::write(mine.join("report.md"), &edited).unwrap();
    let before = names(&mine);
    let o = paper_into(&mine);
    assert_input_error(&o, &[mine.to_str().unwrap(), "report.md", "content"]);
    assert_eq!(
        std::fs::read_to_string(mine.join("report.md")).unwrap(),
        edited
    );
    assert_eq!(names(&mine), before);
    // unedited, it is replaced as before
    std::fs::remove_file(mine.join("report.md")).unwrap();
    ok(&paper_into(&mine));
    assert_eq!(names(&mine), before);
}

/// Issue 32 §1: the lock `.<out>.lock` beside `--out` is removed only when it carries this
/// program's signature. Another program's file there, holding the id of a live process that is
/// not this program, of a dead process, or other text, is refused with exit 2 naming it and
/// left as it was. A lock of ours whose process is gone is taken over, and the run removes its
/// own lock. (Before: the live and dead process ids were removed as stale, exit 0.)
#[test]
fn a_lock_file_that_is_not_ours_is_refused_and_kept() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("data");
    let lock = dir.path().join(".data.lock");
    let mut live = Command::new("sleep").arg("60").spawn().unwrap();
    let mut gone = Command::new("true").spawn().unwrap();
    let dead = gone.id();
    gone.wait().unwrap();
    for text in [
        format!("{}\n", live.id()),
        format!("{dead}\n"),
        "the other program's state\n".to_string(),
    ] {
        std::fs::write(&lock, &text).unwrap();
        let o = paper_into(&out);
        assert_input_error(&o, &[lock.to_str().unwrap(), "not a lock of this program"]);
        assert_eq!(std::fs::read_to_string(&lock).unwrap(), text);
        assert_eq!(names(dir.path()), [".data.lock"], "no report written");
    }
    live.kill().unwrap();
    live.wait().unwrap();

    let ours = format!(
        "# lock of a `cargo xtask` report run (gyrowheel turntable project); removed by that run\npid {dead}\ntoken {}\n",
        "0123456789abcdef".repeat(2)
    );
    std::fs::write(&lock, ours).unwrap();
    ok(&paper_into(&out));
    assert_eq!(names(dir.path()), ["data"], "stale lock of ours taken over");
}

/// Issue 32 §1: a report replacing an existing `--out` keeps the directory's mode (`700`
/// stays `700`, not `755`) and, written by root, its owner; a directory its owner may not write
/// (`555`) is refused with exit 2 before the work (as root, who may write anywhere, the owner's
/// write bit decides). (Before: `700` became `755`, the owner became the writer, and a `555`
/// directory got a report.)
#[test]
fn out_keeps_its_mode_and_owner_and_a_read_only_one_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let private = dir.path().join("private");
    std::fs::create_dir(&private).unwrap();
    std::fs::set_permissions(&private, std::fs::Permissions::from_mode(0o700)).unwrap();
    for _ in 0..2 {
        ok(&paper_into(&private));
        assert_eq!(mode(&private), 0o700);
        assert!(private.join("report.html").is_file());
    }
    if rustix::process::geteuid().is_root() {
        let theirs = dir.path().join("theirs");
        std::fs::create_dir(&theirs).unwrap();
        std::os::unix::fs::chown(&theirs, Some(65534), Some(65534)).unwrap();
        std::fs::set_permissions(&theirs, std::fs::Permissions::from_mode(0o2750)).unwrap();
        ok(&paper_into(&theirs));
        let m = std::fs::metadata(&theirs).unwrap();
        assert_eq!((m.uid(), m.gid()), (65534, 65534), "owner kept");
        assert_eq!(mode(&theirs), 0o2750);
    }
    let read_only = dir.path().join("read-only");
    std::fs::create_dir(&read_only).unwrap();
    std::fs::set_permissions(&read_only, std::fs::Permissions::from_mode(0o555)).unwrap();
    let o = paper_into(&read_only);
    assert_input_error(&o, &[read_only.to_str().unwrap(), "555", "may not"]);
    assert!(names(&read_only).is_empty());
    assert_eq!(mode(&read_only), 0o555);
    let left = hidden_names(dir.path());
    assert!(left.is_empty(), "no leftover: {left:?}");
}

/// The words of the "open" hint, as bash reads them (printed one per line, escaped).
fn bash_words(line: &str) -> Vec<String> {
    let o = Command::new("bash")
        .arg("-c")
        .arg(format!("for w in {line}; do printf '%q\\n' \"$w\"; done"))
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", stderr(&o));
    String::from_utf8(o.stdout)
        .unwrap()
        .lines()
        .map(String::from)
        .collect()
}

/// Issue 32 §1: paths reach the terminal escaped. An `--out` holding a line feed and a forged
/// verdict, and a study path holding one (in `report`, `requirement`, `allocate` and an error),
/// print as one visible line each (`\n`); the "open"
/// hint is one shell word that bash reads back as the report's path, even with a quote and a
/// command substitution in it (nothing is run). An error naming such a path is one line too.
/// (Before: the forged verdict printed as a line of its own; the hint was the raw path.)
#[test]
fn paths_print_as_one_visible_line_and_the_open_hint_is_one_shell_word() {
    let dir = tempfile::tempdir().unwrap();
    let forged = dir.path().join("x\nverdict: MEETS every accuracy");
    let o = paper_into(&forged);
    ok(&o);
    let text = stdout(&o);
    assert!(
        !text.lines().any(|l| l.starts_with("verdict")),
        "a forged line: {text}"
    );
    assert!(text.contains("x\\nverdict: MEETS every accuracy"), "{text}");

    let quoted = dir.path().join("it's $(touch pwned) dir");
    let o = paper_into(&quoted);
    ok(&o);
    let text = stdout(&o);
    let hint = text
        .lines()
        .find_map(|l| l.strip_prefix("  open "))
        .unwrap_or_else(|| panic!("no open hint: {text}"));
    let words = bash_words(hint);
    let expected = bash_words(&format!(
        "'{}'",
        quoted
            .join("report.html")
            .to_str()
            .unwrap()
            .replace('\'', "'\\''")
    ));
    assert_eq!(words, expected, "{hint}");
    assert!(!Path::new("pwned").exists() && !dir.path().join("pwned").exists());

    let study = write(
        dir.path(),
        "s\nverdict: forged.toml",
        &common::study_text("gyrowheel-2017"),
    );
    let o = run(&[
        "report",
        "--study",
        study.to_str().unwrap(),
        "--out",
        dir.path().join("rep").to_str().unwrap(),
        "--samples",
        "1500",
    ]);
    ok(&o);
    let text = stdout(&o);
    assert!(
        !text.lines().any(|l| l.starts_with("verdict")),
        "a forged line: {text}"
    );

    for args in [
        vec!["requirement", "--study", study.to_str().unwrap()],
        vec!["allocate", "--study", study.to_str().unwrap()],
    ] {
        let o = run(&args);
        ok(&o);
        assert!(
            !stdout(&o).lines().any(|l| l.starts_with("verdict")),
            "{args:?}: a forged line: {}",
            stdout(&o)
        );
    }
    let missing = dir.path().join("nope\nverdict: MEETS.toml");
    let o = run(&["end-to-end", "--study", missing.to_str().unwrap()]);
    assert_input_error(&o, &["nope\\nverdict: MEETS.toml"]);
    assert_eq!(stderr(&o).lines().count(), 1, "{}", stderr(&o));

    let file = write(dir.path(), "f\nverdict: MEETS", "mine");
    let o = paper_into(&file);
    assert_input_error(&o, &["f\\nverdict: MEETS", "not a directory"]);
    assert_eq!(stderr(&o).lines().count(), 1, "{}", stderr(&o));
}

/// Issue 32 §3: `--out od/.` (and `od/./`) cannot be exchanged with a new directory: refused
/// before the work with exit 2 naming it, `od` untouched. (Before: the whole report was
/// computed, then "Device or resource busy", exit 1.)
#[test]
fn out_ending_in_a_dot_is_refused_before_the_work() {
    let dir = tempfile::tempdir().unwrap();
    let od = dir.path().join("od");
    std::fs::create_dir(&od).unwrap();
    for spelled in ["od/.", "od/./", "od/.."] {
        let out = format!("{}/{spelled}", dir.path().display());
        let o = run(&["reproduce-paper", "--out", &out, "--samples", "1500"]);
        assert_input_error(&o, &[&out]);
        assert!(names(&od).is_empty());
        assert_eq!(names(dir.path()), ["od"]);
    }
}

/// Issue 32 §5: two flags naming one new file, spelled alike or not (`dir/s.svg` and
/// `dir/../dir/s.svg`, a path through a link to the directory), are refused with exit 2 naming
/// both flags before anything is written: `allan --figure --write-noise` and
/// `design-schedule --write-study --pareto-svg`. (Before: the figure was written, then exit 2.)
#[test]
fn one_file_named_by_two_flags_is_refused_before_anything_is_written() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path().join("d");
    std::fs::create_dir(&d).unwrap();
    std::os::unix::fs::symlink(&d, dir.path().join("link")).unwrap();
    let log = write(
        dir.path(),
        "log.csv",
        &(0..400).fold(String::from("x\n"), |mut s, i| {
            s.push_str(&format!("{}\n", f64::from(i % 7) * 0.1));
            s
        }),
    );
    let a = d.join("s.svg");
    for b in [
        d.join("s.svg"),
        dir.path().join("d/../d/s.svg"),
        dir.path().join("link/s.svg"),
    ] {
        let o = run(&[
            "allan",
            log.to_str().unwrap(),
            "--rate-hz",
            "10",
            "--figure",
            a.to_str().unwrap(),
            "--write-noise",
            b.to_str().unwrap(),
        ]);
        assert_input_error(&o, &["--figure", "--write-noise", "same file"]);
        assert!(names(&d).is_empty(), "nothing written");
        let o = run(&[
            "design-schedule",
            "--time-budget-s",
            "20000",
            "--write-study",
            a.to_str().unwrap(),
            "--pareto-svg",
            b.to_str().unwrap(),
        ]);
        assert_input_error(&o, &["--write-study", "--pareto-svg", "same file"]);
        assert!(names(&d).is_empty(), "nothing written");
    }
}

/// Issue 32 §1, the same for a tolerance sheet's path: a line feed in it cannot forge a line
/// of `check-turntable`'s output or of its error (the sheet is named as one visible line).
#[test]
fn a_tolerance_sheet_path_prints_as_one_visible_line() {
    let dir = tempfile::tempdir().unwrap();
    let sheet = write(
        dir.path(),
        "t\nverdict: MEETS every accuracy.toml",
        &std::fs::read_to_string(common::root().join("studies/tolerances/table4.toml")).unwrap(),
    );
    let o = run(&[
        "check-turntable",
        "--tolerances",
        sheet.to_str().unwrap(),
        "--samples",
        "2000",
    ]);
    ok(&o);
    let text = stdout(&o);
    assert!(
        !text.lines().any(|l| l.starts_with("verdict")),
        "a forged line: {text}"
    );
    let missing = dir.path().join("nope\nverdict: MEETS.toml");
    let o = run(&["check-turntable", "--tolerances", missing.to_str().unwrap()]);
    assert_input_error(&o, &["nope\\nverdict: MEETS.toml"]);
    assert_eq!(stderr(&o).lines().count(), 1, "{}", stderr(&o));
}
