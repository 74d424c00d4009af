//! `design-schedule --time-budget-s` through the built binary (issue 21 item 4): bad values
//! exit 2 naming the flag with nothing on standard output, a study without noise keeps its
//! answer and says why, and with noise the Pareto front (JSON `pareto`) is monotone, the
//! chosen point fits the budget and `--pareto-svg` writes a new figure, never over a file;
//! `--write-study` writes the chosen positions and dwell, which `end-to-end` answers.

mod common;

use approx::assert_relative_eq;
use common::{
    assert_flags_refused, assert_input_error, assert_input_error_of, end_to_end_json, json_of, ok,
    root, run as xtask, scratch, stderr, stdout,
};
use serde_json::Value;
use std::process::Output;

const NOISY: &str = "studies/gyrowheel-2017-noise-assumed.toml";

/// A budget that is not a finite positive number, and `--pareto-svg` without a budget, exit 2
/// naming the flag, with nothing on standard output.
#[test]
fn bad_time_budgets_exit_2_naming_the_flag() {
    assert_flags_refused(
        &["design-schedule", "--study", NOISY],
        &[
            ["--time-budget-s", "0"],
            ["--time-budget-s", "-60"],
            ["--time-budget-s", "nan"],
            ["--time-budget-s", "inf"],
            ["--time-budget-s", "an hour"],
            ["--pareto-svg", "front.svg"],
        ],
    );
}

/// A budget too short for the fewest positions that identify every output (the paper's
/// noisy copy: 60 s to move to each, so its 7 positions need 420 s) exits 2 before the search,
/// naming the flag and the library's `time_budget_s`, with nothing on standard output.
#[test]
fn a_budget_too_short_for_the_fewest_positions_exits_2_naming_it() {
    let r = noisy_with_budget("100", &["--json"]);
    assert_input_error(
        &r,
        &["--time-budget-s", "time_budget_s = 100 s is too short"],
    );
}

/// Without noise the budget only changes the dwell: the answer is the one without a budget
/// (the same designed positions and J), with a note saying so and no front.
#[test]
fn without_noise_the_budget_changes_nothing_but_says_why() {
    let plain = json_of(&xtask(&["design-schedule", "--step-deg", "45", "--json"]));
    let with = json_of(&xtask(&[
        "design-schedule",
        "--step-deg",
        "45",
        "--time-budget-s",
        "3600",
        "--json",
    ]));
    assert_eq!(plain["designed"], with["designed"]);
    assert_eq!(plain["study"], with["study"]);
    let note = with["time_budget"]["note"].as_str().expect("a note");
    assert!(note.contains("only changes the dwell"), "{note}");
    assert!(with.get("pareto").is_none());
}

/// With noise: the front is ordered by total time with J strictly falling, each total is
/// n_positions x (dwell + move), the chosen point is on it within the budget, and the figure
/// is written once (an existing file is refused with exit 2 and left as it was).
#[test]
fn with_noise_the_front_is_monotone_the_choice_fits_and_the_figure_is_new() {
    let dir = scratch("design-budget", "front");
    let svg = dir.join("front.svg");
    let svg_arg = svg.to_str().unwrap();
    let budget = 25_000.0;
    let v = noisy_budget_json(&["--pareto-svg", svg_arg]);
    let front = v["pareto"].as_array().expect("a front");
    assert!(front.len() >= 3, "{front:?}");
    let f = |p: &Value, k: &str| p[k].as_f64().unwrap();
    for w in front.windows(2) {
        assert!(f(&w[1], "total_s") > f(&w[0], "total_s"), "{w:?}");
        assert!(
            f(&w[1], "objective_arcmin") < f(&w[0], "objective_arcmin"),
            "{w:?}"
        );
    }
    // the study's 60 s move between positions
    for p in front {
        let n = p["n_positions"].as_u64().unwrap() as f64;
        let total = n * (f(p, "dwell_s") + 60.0);
        assert!((f(p, "total_s") - total).abs() <= 1e-9 * total, "{p}");
    }
    // every point's tolerance box: one bound per rotation error of the paper's table (its
    // eight, named as in the study), in arcmin, each positive (or null: no bound needed), and
    // the chosen point's is the front's
    let names = [
        "dphi_y1",
        "dalpha_z1",
        "dalpha_x1",
        "deps_y",
        "deps_x",
        "dalpha_y2",
        "dphi_z2",
        "dalpha_x2",
    ];
    for p in front {
        let bounds = p["bounds_arcmin"].as_object().expect("a tolerance box");
        let mut keys: Vec<&str> = bounds.keys().map(String::as_str).collect();
        let mut want = names.to_vec();
        keys.sort_unstable();
        want.sort_unstable();
        assert_eq!(keys, want, "{p}");
        for (k, u) in bounds {
            assert!(
                u.is_null() || u.as_f64().is_some_and(|u| u > 0.0),
                "{k}: {u}"
            );
        }
    }
    let chosen = &v["time_budget"]["chosen"];
    assert!(
        front
            .iter()
            .any(|p| p["bounds_arcmin"] == chosen["bounds_arcmin"])
    );
    assert!(f(chosen, "total_s") <= budget, "{chosen}");
    // the number of positions is searched: the chosen count is one of the counts designed for,
    // and its test fits the budget
    let counts: Vec<u64> = v["time_budget"]["counts"]
        .as_array()
        .expect("counts")
        .iter()
        .map(|c| c.as_u64().unwrap())
        .collect();
    assert!(counts.len() > 1, "{counts:?}");
    let n = chosen["n_positions"].as_u64().unwrap();
    assert!(counts.contains(&n), "{n} not in {counts:?}");
    assert!(n as f64 * (f(chosen, "dwell_s") + 60.0) <= budget * (1.0 + 1e-12));
    assert!(front.iter().any(|p| p["total_s"] == chosen["total_s"]
        && p["objective_arcmin"] == chosen["objective_arcmin"]));
    let text = std::fs::read_to_string(&svg).expect("the figure is written");
    assert!(text.contains("<svg"), "{}", &text[..text.len().min(200)]);
    let again = noisy_budget(&["--pareto-svg", svg_arg]);
    assert_input_error(&again, &[]);
    assert_eq!(std::fs::read_to_string(&svg).unwrap(), text);
}

/// The same certified allocation computed by two commands on the same positions and dwell
/// (the written dwell is the chosen one bit for bit): JSON at full precision, one conversion
/// to arcmin^-2 each, so only rounding may differ (dimensionless, relative).
const SAME_ALLOCATION_REL: f64 = 1e-9;

/// The budget's J is the linearised direct allocation, `end-to-end`'s `direct_with_noise` the
/// one certified on the exact chain: on the paper's study they differ by a few percent (the
/// noiseless designed schedule: 12.144 against 12.45, 2.5%); this bounds that gap
/// (dimensionless, relative).
const LINEARISATION_GAP_REL: f64 = 0.05;

/// With a budget and noise, `--write-study` writes the chosen point: its positions and its one
/// dwell (`calibration.timing.dwell_s`), the study's move time and sample rate kept; and
/// `end-to-end` on the written file answers that point: its certified direct allocation with
/// the noise kept free is the chosen point's `certified_objective_arcmin`, within the
/// linearisation's gap of the chosen (linearised) J, and the table it allocates meets every
/// output's accuracy with the noise counted.
#[test]
fn written_study_holds_the_chosen_point_and_end_to_end_answers_its_j() {
    let dir = scratch("design-budget", "write-study");
    let out = dir.join("chosen.toml");
    let out_arg = out.to_str().unwrap();
    let v = noisy_budget_json(&["--write-study", out_arg]);
    let chosen = &v["time_budget"]["chosen"];
    let dwell = chosen["dwell_s"].as_f64().expect("a chosen point");
    let positions: Vec<Vec<f64>> = serde_json::from_value(chosen["positions_deg"].clone()).unwrap();
    let text = std::fs::read_to_string(&out).expect("the study is written");
    let written = study::Study::parse(out_arg, &text).expect("the written study parses");
    assert_eq!(written.positions_deg, positions);
    let timing = written.timing.as_ref().expect("the timing is kept");
    assert!(
        timing
            .dwell_s()
            .iter()
            .all(|t| t.to_bits() == dwell.to_bits()),
        "{:?} against {dwell}",
        timing.dwell_s()
    );
    assert_eq!(timing.move_s().to_bits(), 60.0_f64.to_bits());
    assert_eq!(timing.sample_rate_hz().to_bits(), 100.0_f64.to_bits());
    assert!(text.contains("With --time-budget-s 25000"), "{text}");
    let e2e = end_to_end_json(out_arg, "2000", &[]);
    let direct = &e2e["readings"][0]["noise"]["direct_with_noise"];
    assert_eq!(direct["no_table_suffices"], false, "{direct}");
    let e2e_j = direct["objective"].as_f64().unwrap();
    let certified = chosen["certified_objective_arcmin"].as_f64().unwrap();
    assert_relative_eq!(e2e_j, certified, max_relative = SAME_ALLOCATION_REL);
    let linearised = chosen["objective_arcmin"].as_f64().unwrap();
    assert_relative_eq!(e2e_j, linearised, max_relative = LINEARISATION_GAP_REL);
    // the combined answer of the allocated table: every output meets its accuracy
    for o in direct["box"]["outputs"].as_array().expect("outputs") {
        assert_eq!(o["combined_meets"], true, "{o}");
    }
}

/// `design-schedule` on the noisy paper study at the 45 deg grid under a budget of
/// `budget_s` seconds, with `extra` arguments.
fn noisy_with_budget(budget_s: &str, extra: &[&str]) -> Output {
    let mut args = vec![
        "design-schedule",
        "--study",
        NOISY,
        "--step-deg",
        "45",
        "--time-budget-s",
        budget_s,
    ];
    args.extend_from_slice(extra);
    xtask(&args)
}

/// [`noisy_with_budget`] under 25,000 s.
fn noisy_budget(extra: &[&str]) -> Output {
    noisy_with_budget("25000", extra)
}

/// [`noisy_budget`] with `--json`, its output parsed.
fn noisy_budget_json(extra: &[&str]) -> Value {
    let mut args = extra.to_vec();
    args.push("--json");
    json_of(&noisy_budget(&args))
}

/// An empty front is an answer (issue 32): the IMU example's bias instability fills an
/// accuracy at every dwell, so no table suffices within any budget; with `--pareto-svg` the
/// command still answers with exit 0, says that no table suffices and that no figure was
/// written (text and JSON `pareto_svg_note`), and leaves nothing in the directory.
#[test]
fn an_empty_front_answers_with_exit_0_and_writes_no_figure() {
    let dir = scratch("design-budget", "empty-front");
    let svg = dir.join("p.svg");
    let svg_arg = svg.to_str().unwrap();
    let args = [
        "design-schedule",
        "--study",
        "studies/imu-triad-example.toml",
        "--step-deg",
        "90",
        "--time-budget-s",
        "5000",
        "--pareto-svg",
        svg_arg,
    ];
    let r = xtask(&args);
    ok(&r);
    let text = stdout(&r);
    assert!(text.contains("no table suffices at any dwell"), "{text}");
    assert!(
        text.contains(&format!("--pareto-svg {svg_arg}: not written")),
        "{text}"
    );
    let mut with_json = args.to_vec();
    with_json.push("--json");
    let v = json_of(&xtask(&with_json));
    assert_eq!(v["pareto"].as_array().map(Vec::len), Some(0), "{v}");
    assert!(v["time_budget"]["chosen"].is_null());
    let note = v["pareto_svg_note"].as_str().expect("a note");
    assert!(note.contains("the Pareto front is empty"), "{note}");
    let left: Vec<_> = std::fs::read_dir(&dir).unwrap().collect();
    assert!(left.is_empty(), "{left:?}");
}

/// The budget's refusals come before the search (issue 32) and quote the value as given:
/// `--max-condition 1` makes the search itself fail (no schedule is that well conditioned),
/// so an error naming `--time-budget-s` proves the budget was refused first. A study with
/// noise but no `[calibration.timing]`, and a budget of 1e-300 s (quoted as `1e-300`, not as
/// a 300-digit decimal).
#[test]
fn budget_refusals_come_before_the_search_and_quote_the_value_as_given() {
    let dir = scratch("design-budget", "early");
    let text = std::fs::read_to_string(root().join(NOISY)).unwrap();
    let no_timing = text.replace(
        "[calibration.timing]\ndwell_s = 600\nsample_rate_hz = 100\nmove_s = 60\n",
        "",
    );
    assert_ne!(no_timing, text, "the timing block was removed");
    let no_timing_path = dir.join("no-timing.toml");
    std::fs::write(&no_timing_path, no_timing).unwrap();
    for (study, budget, needle) in [
        (NOISY, "1e-300", "time_budget_s = 1e-300 s is too short"),
        (
            no_timing_path.to_str().unwrap(),
            "3600",
            "no [calibration.timing]",
        ),
    ] {
        let r = xtask(&[
            "design-schedule",
            "--study",
            study,
            "--step-deg",
            "90",
            "--max-condition",
            "1",
            "--time-budget-s",
            budget,
        ]);
        assert_input_error_of(budget, &r, &["--time-budget-s", needle]);
        let err = stderr(&r);
        assert!(!err.contains("0000000000"), "{err}");
    }
}
