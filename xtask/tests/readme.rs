//! The README is the newcomer's contract: its two commands (the commands table that lists
//! every subcommand with every flag it takes is on docs/commands.md, tested in docs_pages.rs).

mod common;

fn readme() -> String {
    page("README.md")
}

/// A documentation page (`docs/...`) or the README, by its path from the repository root.
fn page(path: &str) -> String {
    std::fs::read_to_string(common::root().join(path)).expect(path)
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
    let ci = std::fs::read_to_string(common::root().join(".ci/run")).unwrap();
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

/// `design-schedule --time-budget-s BUDGET --json` on the noise-assumed paper study.
fn budget_design(budget: &str) -> serde_json::Value {
    common::json(&[
        "design-schedule",
        "--study",
        "studies/gyrowheel-2017-noise-assumed.toml",
        "--time-budget-s",
        budget,
        "--json",
    ])
}

/// `v` with `,` between thousands, as the README prints a whole number.
fn thousands(v: f64) -> String {
    let digits = format!("{v:.0}");
    let mut out = String::new();
    for (i, c) in digits.chars().enumerate() {
        if i > 0 && (digits.len() - i) % 3 == 0 {
            out.push(',');
        }
        out.push(c);
    }
    out
}

/// The noise-budget paragraph of docs/findings.md (issue 32: it said 21,120 s buys J = 365.0 where the
/// binary finds 21 positions x 945.7 s at J = 201.09): the study's own test time
/// (32 x (600 + 60) s), its choice, its certified J, the designed schedule at the study's
/// dwell, the front's shortest test, its 14.7 h point and its last, as the binary prints them.
#[test]
fn readme_noise_budget_figures_are_the_binarys() {
    let text = page("docs/findings.md");
    let v = budget_design("21120");
    let c = &v["time_budget"]["chosen"];
    let n = |x: &serde_json::Value| x.as_f64().expect("a number");
    let chosen = format!(
        "buys J = {:.1} with {} positions\nx {:.1} s (linearised, noise part kept free; certified {:.1}), against {:.1} for the 32",
        n(&c["objective_arcmin"]),
        c["n_positions"],
        n(&c["dwell_s"]),
        n(&c["certified_objective_arcmin"]),
        n(&v["combined"]["designed_objective_arcmin"])
    );
    assert!(text.contains(&chosen), "docs/findings.md lacks `{chosen}`");
    let front = v["pareto"].as_array().expect("a front");
    let (first, last) = (&front[0], &front[front.len() - 1]);
    let shortest = format!(
        "the shortest test takes {:.1} h ({} x {:.0} s, J = {})",
        n(&first["total_s"]) / 3600.0,
        first["n_positions"],
        n(&first["dwell_s"]),
        thousands(n(&first["objective_arcmin"]))
    );
    assert!(
        text.contains(&shortest),
        "docs/findings.md lacks `{shortest}`"
    );
    let p = front
        .iter()
        .find(|p| p["n_positions"] == 32 && format!("{:.1}", n(&p["total_s"]) / 3600.0) == "14.7")
        .expect("a 32-position point of 14.7 h");
    let mid = format!(
        "14.7 h buys J = {:.1}\n(32 x {} s,",
        n(&p["objective_arcmin"]),
        thousands(n(&p["dwell_s"]))
    );
    assert!(text.contains(&mid), "docs/findings.md lacks `{mid}`");
    assert_eq!(
        n(&last["dwell_s"]).to_bits(),
        86_400.0_f64.to_bits(),
        "the front ends at a day"
    );
    let end = format!(
        "and {} positions at a day each\nJ = {:.1};",
        last["n_positions"],
        n(&last["objective_arcmin"])
    );
    assert!(text.contains(&end), "docs/findings.md lacks `{end}`");
    // twice the study's time: the counts refined and the choice
    let v = budget_design("42240");
    let tb = &v["time_budget"];
    let refined: Vec<String> = tb["counts_refined"]
        .as_array()
        .unwrap()
        .iter()
        .map(ToString::to_string)
        .collect();
    let (last_two, rest) = refined.split_last().unwrap();
    let twice = format!(
        "then the count refined by bisection: {} and {last_two}) {} x {} s wins\nwith J = {:.1} (certified {:.1};",
        rest.join(", "),
        tb["chosen"]["n_positions"],
        thousands(n(&tb["chosen"]["dwell_s"])),
        n(&tb["chosen"]["objective_arcmin"]),
        n(&tb["chosen"]["certified_objective_arcmin"])
    );
    assert!(text.contains(&twice), "docs/findings.md lacks `{twice}`");
}
