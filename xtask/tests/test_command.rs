//! `cargo xtask test`, the README's test command: the README and `.ci/run` show it, and it
//! never skips its browser test silently. (The README's other checks are the command line's,
//! in `ttalloc/tests/readme.rs`.)

use std::path::{Path, PathBuf};

/// The workspace root.
fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

fn readme() -> String {
    std::fs::read_to_string(root().join("README.md")).expect("README.md")
}

/// The README's quick start shows the two commands a newcomer needs: the main job and the
/// test command that does its own set-up on a fresh machine (`cargo xtask test`), which
/// `.ci/run` runs too (issue 19 §1: `cargo test --workspace` alone failed on a fresh machine).
#[test]
fn readme_shows_the_main_job_and_the_test_command() {
    let r = readme();
    let start = r.find("## Quick start").unwrap();
    let quick = &r[start..start + 3 + r[start + 3..].find("\n## ").unwrap()];
    assert!(quick.contains("cargo xtask reproduce-paper"));
    assert!(quick.contains("cargo xtask test"));
    assert!(quick.contains("fonts-dejavu-core fonts-liberation"));
    let ci = std::fs::read_to_string(root().join(".ci/run")).unwrap();
    assert!(
        ci.lines().any(|l| l.trim() == "cargo xtask test"),
        ".ci/run must run the README's test command"
    );
}

/// Issue 19 §1: the README's test command never skips its browser test silently: when the
/// browser it is told to use is missing (`$CHROMIUM` naming nothing) it stops at once, before
/// running cargo, with exit 1 and the instruction (what to install, or to unset `CHROMIUM`).
#[test]
fn test_command_stops_at_once_with_the_instruction_when_the_browser_is_missing() {
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_xtask"))
        .arg("test")
        .env("CHROMIUM", "/nonexistent/chromium")
        .current_dir(root())
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(err.contains("/nonexistent/chromium"), "{err}");
    assert!(err.contains("unset CHROMIUM"), "{err}");
    assert!(
        err.contains("apt-get install -y --no-install-recommends chromium chromium-driver fonts-dejavu-core fonts-liberation"),
        "{err}"
    );
    assert!(
        !err.contains("cargo xtask test: Chromium"),
        "cargo was not run: {err}"
    );
}

/// Issue 37: the README's test command also builds the Python package's wheel, installs it in
/// a fresh virtual environment and runs pytest; without a usable Python it stops at once,
/// before running cargo, with exit 1 naming the interpreter and what to install.
#[test]
fn test_command_includes_the_python_package_and_says_what_is_missing_without_python() {
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_xtask"))
        .arg("test")
        .env("PYTHON", "/nonexistent/python3")
        .current_dir(root())
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(err.contains("/nonexistent/python3"), "{err}");
    assert!(
        err.contains("apt-get install -y python3 python3-venv"),
        "{err}"
    );
    assert!(
        !err.contains("cargo xtask test: Chromium"),
        "cargo was not run: {err}"
    );
    let help = std::process::Command::new(env!("CARGO_BIN_EXE_xtask"))
        .arg("--help")
        .current_dir(root())
        .output()
        .unwrap();
    assert!(
        String::from_utf8_lossy(&help.stdout).contains("Python package"),
        "the help line of `test` names the Python step"
    );
}
