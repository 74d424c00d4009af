//! Figures the documentation quotes are the binary's (the README's two commands are checked
//! with xtask's own `test` command in xtask/tests/test_command.rs; the commands table that
//! lists every subcommand with every flag is on docs/commands.md, tested in docs_pages.rs).

mod common;

/// A documentation page (`docs/...`) or the README, by its path from the repository root.
fn page(path: &str) -> String {
    std::fs::read_to_string(common::root().join(path)).expect(path)
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
/// dwell, the front's shortest test, its first point below the noiseless study schedule's J
/// and its last, as the binary prints them.
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
    // one point per schedule and dwell: a dwell end-to-end lists that equals a grid dwell up
    // to round-off (a day as 86,399.99999999993 s) is not a second point
    for (i, p) in front.iter().enumerate() {
        for q in &front[..i] {
            let same_dwell = (n(&p["dwell_s"]) - n(&q["dwell_s"])).abs() <= 1e-9 * n(&q["dwell_s"]);
            assert!(
                !(same_dwell && p["n_positions"] == q["n_positions"] && p["origin"] == q["origin"]),
                "two front points of one schedule at dwell {}",
                p["dwell_s"]
            );
        }
    }
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
    // J of the noiseless study's own schedule (arcmin^-2, as the page quotes it)
    const NOISELESS_STUDY_J: f64 = 54.65;
    let p = front
        .iter()
        .find(|p| n(&p["objective_arcmin"]) < NOISELESS_STUDY_J)
        .expect("a point below the noiseless study schedule's J");
    let mid = format!(
        "{:.1} h buys J = {:.1}\n({} x {} s, the first point below the noiseless study schedule's 54.65)",
        n(&p["total_s"]) / 3600.0,
        n(&p["objective_arcmin"]),
        p["n_positions"],
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
