//! The README is the newcomer's contract: its two commands, and a commands table that lists
//! every subcommand of the CLI with every flag it takes (checked against `--help`).

mod common;

use common::{run, stdout};

fn readme() -> String {
    std::fs::read_to_string(common::root().join("README.md")).expect("README.md")
}

/// The subcommands `cargo xtask --help` lists.
fn subcommands() -> Vec<String> {
    let help = stdout(&run(&["--help"]));
    help.lines()
        .skip_while(|l| !l.starts_with("Commands:"))
        .skip(1)
        .take_while(|l| l.starts_with("  "))
        .filter_map(|l| l.split_whitespace().next().map(String::from))
        .filter(|c| c != "help")
        .collect()
}

/// The README's quick start shows the two commands a newcomer needs: the main job and the
/// test command that does its own set-up on a fresh machine (`cargo xtask test`), which
/// `.ci/run` runs too (issue 19 §1: `cargo test --workspace` alone failed on a fresh machine).
#[test]
fn readme_shows_the_main_job_and_the_test_command() {
    let r = readme();
    let quick = &r[r.find("## Quick start").unwrap()..r.find("## What we find").unwrap()];
    assert!(quick.contains("cargo xtask reproduce-paper"));
    assert!(quick.contains("cargo xtask test"));
    assert!(quick.contains("fonts-dejavu-core fonts-liberation"));
    let ci = std::fs::read_to_string(common::root().join(".ci/run")).unwrap();
    assert!(
        ci.lines().any(|l| l.trim() == "cargo xtask test"),
        ".ci/run must run the README's test command"
    );
}

/// Every subcommand has a row in the README's commands table naming every long flag of its
/// `--help`.
#[test]
fn readme_commands_table_lists_every_command_and_flag() {
    let r = readme();
    let commands = subcommands();
    assert!(commands.len() >= 10, "{commands:?}");
    for c in commands {
        let row = r
            .lines()
            .find(|l| l.starts_with(&format!("| `cargo xtask {c}")))
            .unwrap_or_else(|| panic!("README has no commands-table row for `{c}`"));
        let help = stdout(&run(&[&c, "--help"]));
        for flag in help
            .split_whitespace()
            .filter(|w| w.starts_with("--") && w.len() > 2)
            .map(|w| {
                w.trim_end_matches([',', '.', ')', '`', ';'])
                    .split(['=', '<'])
                    .next()
                    .unwrap_or("")
                    .to_string()
            })
            .filter(|f| f != "--help" && f.len() > 2)
        {
            assert!(
                row.contains(&flag),
                "README row for `{c}` lacks `{flag}`: {row}"
            );
        }
    }
}

/// Issue 19 §1: the README's test command never skips its browser test silently: when the
/// browser it is told to use is missing (`$CHROMIUM` naming nothing) it stops at once, before
/// running cargo, with exit 1 and the instruction (what to install, or to unset `CHROMIUM`).
#[test]
fn test_command_stops_at_once_with_the_instruction_when_the_browser_is_missing() {
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_xtask"))
        .arg("test")
        .env("CHROMIUM", "/nonexistent/chromium")
        .current_dir(common::root())
        .output()
        .unwrap();
    let err = common::stderr(&o);
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
