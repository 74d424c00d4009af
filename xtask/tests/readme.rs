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

/// The README shows the two commands a newcomer needs: the main job and the tests.
#[test]
fn readme_shows_the_main_job_and_the_test_command() {
    let r = readme();
    assert!(r.contains("cargo xtask reproduce-paper"));
    assert!(r.contains("cargo test --workspace"));
    let ci = std::fs::read_to_string(common::root().join(".ci/run")).unwrap();
    assert!(
        ci.contains("cargo test --workspace"),
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
