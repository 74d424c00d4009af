//! The command line as a lab installs it (`cargo install --path ttalloc`): a `ttalloc` binary
//! that runs outside any clone of the project. Without `--study` it answers for the paper's
//! study compiled into it, exactly as inside the repository; user paths resolve against the
//! current directory; its reports go where the user says.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// The workspace root (this crate's parent).
fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("ttalloc sits in the workspace")
        .to_path_buf()
}

/// A copy of the built binary in a directory outside the repository, as `cargo install`
/// leaves one on a lab's PATH (run in place, the binary would find the workspace above
/// `target/`).
fn installed() -> (tempfile::TempDir, PathBuf) {
    let dir = tempfile::tempdir().expect("temporary directory");
    let bin = dir.path().join("bin");
    std::fs::create_dir(&bin).expect("bin directory");
    let exe = bin.join("ttalloc");
    std::fs::copy(env!("CARGO_BIN_EXE_ttalloc"), &exe).expect("copy of the binary");
    (dir, exe)
}

/// Runs the copied binary. A freshly written executable can be "busy" (ETXTBSY) for a moment:
/// while this test wrote it, another test thread may have forked a child that still held the
/// write descriptor until its own exec. That is the test harness's race, not the program's,
/// so the start is retried a few times.
fn run(exe: &Path, cwd: &Path, args: &[&str]) -> Output {
    let mut tries = 0;
    loop {
        match Command::new(exe).args(args).current_dir(cwd).output() {
            Err(e) if e.kind() == std::io::ErrorKind::ExecutableFileBusy && tries < 50 => {
                tries += 1;
                std::thread::sleep(std::time::Duration::from_millis(20));
            }
            r => return r.expect("ttalloc runs"),
        }
    }
}

fn stdout(o: &Output) -> String {
    assert!(
        o.status.success(),
        "exit {:?}: {}",
        o.status.code(),
        String::from_utf8_lossy(&o.stderr)
    );
    String::from_utf8(o.stdout.clone()).expect("UTF-8 output")
}

#[test]
fn outside_a_clone_the_built_in_paper_study_answers_exactly_as_the_repository_file() {
    let (dir, exe) = installed();
    assert!(
        !dir.path()
            .ancestors()
            .any(|d| d.join("Cargo.toml").is_file()),
        "the test directory must lie outside any workspace"
    );
    let outside = stdout(&run(&exe, dir.path(), &["requirement", "--json"]));
    let inside = stdout(&run(
        Path::new(env!("CARGO_BIN_EXE_ttalloc")),
        &root(),
        &["requirement", "--json"],
    ));
    assert_eq!(outside, inside);
    assert!(outside.contains("gyrowheel-2017"), "{outside}");
}

#[test]
fn an_installed_binary_reads_the_users_study_relative_to_the_current_directory() {
    let (dir, exe) = installed();
    std::fs::copy(
        root().join("studies/three-axis-example.toml"),
        dir.path().join("mine.toml"),
    )
    .expect("copy of a study");
    let text = stdout(&run(
        &exe,
        dir.path(),
        &["requirement", "--study", "mine.toml", "--json"],
    ));
    let inside = stdout(&run(
        Path::new(env!("CARGO_BIN_EXE_ttalloc")),
        &root(),
        &[
            "requirement",
            "--study",
            "studies/three-axis-example.toml",
            "--json",
        ],
    ));
    // the same answer; only the study's path is shown as the user gave it
    assert!(text.contains("\"study\": \"mine.toml\""), "{text}");
    assert_eq!(
        text.replace("\"mine.toml\"", "\"studies/three-axis-example.toml\""),
        inside
    );
    // a missing file is the user's input error: exit 2, the path as given
    let o = run(&exe, dir.path(), &["requirement", "--study", "absent.toml"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("absent.toml"));
}

#[test]
fn an_installed_binary_writes_the_papers_report_where_the_user_says() {
    let (dir, exe) = installed();
    let o = run(
        &exe,
        dir.path(),
        &[
            "reproduce-paper",
            "--out",
            "paper-report",
            "--samples",
            "2000",
        ],
    );
    stdout(&o);
    let md = std::fs::read_to_string(dir.path().join("paper-report/report.md"))
        .expect("report.md written under the current directory");
    assert!(md.contains("Table 4"), "the paper's report names Table 4");
    assert!(dir.path().join("paper-report/report.html").is_file());
}

#[test]
fn the_help_names_the_program_as_installed() {
    let (dir, exe) = installed();
    let text = stdout(&run(&exe, dir.path(), &["--help"]));
    assert!(text.contains("Usage: ttalloc"), "{text}");
    assert!(!text.contains("cargo xtask"), "{text}");
}

/// The fuzzer is automation (`cargo xtask fuzz`), not a command of the user's binary.
#[test]
fn the_installed_program_has_no_fuzz_command() {
    let (dir, exe) = installed();
    let o = run(&exe, dir.path(), &["fuzz", "--cases", "10"]);
    assert_eq!(o.status.code(), Some(2));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("unrecognized subcommand 'fuzz'"), "{err}");
    assert!(o.stdout.is_empty());
    let help = stdout(&run(&exe, dir.path(), &["--help"]));
    assert!(!help.contains("fuzz"), "{help}");
}
