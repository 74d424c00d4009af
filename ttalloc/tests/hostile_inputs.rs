//! Hostile inputs of issue 19 through the built binary: inputs that cannot be read twice,
//! grids and schedules too large to build, and messages that name the flag or key with the
//! value as given. Each test failed before the fix it names.

mod common;

use common::{assert_input_error, run, run_with_stdin, stderr, stdout, study_text};
use std::io::Write;
use std::path::PathBuf;
use std::process::Command;
use std::time::Duration;

/// A command that must refuse its input at once takes at most this (s): far above the
/// milliseconds it takes, far below the minutes (or the abort) of the old behaviour.
const PROMPT_S: u64 = 60;

/// The paper's turntable CSV header (orientation-error).
const HEADER: &str = "phi1_deg,phi2_deg,dphi_y1_arcmin,dphi_z2_arcmin,dalpha_x1_arcmin,dalpha_z1_arcmin,dalpha_x2_arcmin,dalpha_y2_arcmin,deps_x_arcmin,deps_y_arcmin,deta_mm";

fn scratch(name: &str) -> PathBuf {
    common::scratch("hostile", name)
}

fn csv() -> String {
    format!(
        "{HEADER}\n10,20,0.4,0.78,0.42,0.78,0.28,0.28,0.42,0.42,0.1\n0,0,1e-300,0,0,0,0,0,0,0,0\n"
    )
}

/// Run `cargo xtask <args>` from the workspace root, killed (and the test failed) when it
/// does not end within `limit_s`.
fn run_within(args: &[&str], limit_s: u64) -> std::process::Output {
    let mut c = Command::new(env!("CARGO_BIN_EXE_ttalloc"));
    c.args(args).current_dir(common::root());
    testkit::output_within(c, Duration::from_secs(limit_s), &format!("{args:?}"))
}

/// The expected output of [`csv`]: the same whether read from a file, a FIFO or a pipe.
fn expected_output() -> String {
    let dir = scratch("file");
    let path = dir.join("c.csv");
    std::fs::write(&path, csv()).unwrap();
    let o = run(&["orientation-error", path.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    stdout(&o)
}

/// A CSV argument that is a FIFO is read once and answered (before: a hang, the file being
/// opened a second time with no writer left).
#[test]
fn a_fifo_csv_argument_is_read_once_and_answered() {
    let want = expected_output();
    let dir = scratch("fifo");
    let fifo = dir.join("c.fifo");
    let made = Command::new("mkfifo").arg(&fifo).status().unwrap();
    assert!(made.success(), "mkfifo");
    let writer = {
        let fifo = fifo.clone();
        std::thread::spawn(move || {
            let mut f = std::fs::OpenOptions::new().write(true).open(fifo).unwrap();
            f.write_all(csv().as_bytes()).unwrap();
        })
    };
    let o = run_within(&["orientation-error", fifo.to_str().unwrap()], PROMPT_S);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(stdout(&o), want);
    // it read the FIFO, so the writer is done
    writer.join().unwrap();
}

/// `/dev/stdin` on a pipe (as `<(cat c.csv)` gives `/dev/fd/63`) is read once: the whole
/// answer, not the header followed by "empty input".
#[test]
fn a_pipe_named_as_a_file_is_read_once_and_answered() {
    let want = expected_output();
    for cmd in ["orientation-error", "calibration-error"] {
        let input = if cmd == "orientation-error" {
            csv()
        } else {
            format!(
                "{}\n0.4,0.78,0.42,0.78,0.28,0.28,0.42,0.42,0.1\n",
                HEADER.split_once(",phi2_deg,").unwrap().1
            )
        };
        let o = run_with_stdin(&[cmd, "/dev/stdin"], input.as_bytes());
        assert!(o.status.success(), "{cmd}: {}", stderr(&o));
        assert!(!stderr(&o).contains("empty input"), "{}", stderr(&o));
        let lines = stdout(&o).lines().count();
        assert_eq!(lines, input.lines().count(), "{cmd}: {}", stdout(&o));
        if cmd == "orientation-error" {
            assert_eq!(stdout(&o), want);
        }
    }
}

/// CSV output keeps full precision in a short field: 1e-300 is `1e-300`, not a
/// 300-character fixed-point field, and every field reads back as a finite number.
#[test]
fn csv_output_of_tiny_values_is_short_and_exact() {
    let out = expected_output();
    let last = out.lines().last().unwrap();
    let fields: Vec<&str> = last.split(',').collect();
    assert!(fields.iter().all(|f| f.len() <= 24), "{last}");
    let v: f64 = fields[0].parse().unwrap();
    // 1e-300 arcmin in, the same angle out (the exact chain at zero elsewhere)
    approx::assert_relative_eq!(v, 1e-300, max_relative = 1e-12);
    assert_eq!(tt_core::human::exact(v), fields[0], "shortest round trip");
}

/// `design-schedule --step-deg 1e-308` (24 GB, killed) and `1e-6` (a 4 GB allocation
/// aborted) are refused at once with exit 2, naming the flag and the candidate count.
#[test]
fn tiny_grid_steps_are_refused_at_once_with_the_count() {
    for (step, count) in [
        ("1e-308", "about 1.3e621 candidate positions"),
        (
            "1e-6",
            "candidate positions (360000000 x 360000000 per joint)",
        ),
    ] {
        let o = run_within(&["design-schedule", "--step-deg", step], PROMPT_S);
        assert_input_error(
            &o,
            &[&format!("--step-deg {step}"), count, "more than 50000"],
        );
    }
}

/// A 150,000-position study (1.4 MB, under the size limit) is refused at once naming
/// `calibration.positions_deg` and the count (before: `requirement` ran past 100 s at 533 MB).
#[test]
fn an_oversized_schedule_is_refused_at_once() {
    let text = study_text("gyrowheel-2017");
    let start = text.find("positions_deg = [").unwrap();
    let end = start + text[start..].find("\n]\n").unwrap() + 3;
    let positions: Vec<String> = (0..150_000)
        .map(|k| format!("[{}, {}]", (k * 7) % 360, (k * 13) % 360))
        .collect();
    let big = format!(
        "{}positions_deg = [{}]\n{}",
        &text[..start],
        positions.join(","),
        &text[end..]
    );
    assert!(big.len() < 4 << 20);
    let dir = scratch("positions");
    let path = dir.join("big.toml");
    std::fs::write(&path, big).unwrap();
    let o = run_within(
        &["requirement", "--study", path.to_str().unwrap()],
        PROMPT_S,
    );
    assert_input_error(
        &o,
        &[
            "key `calibration.positions_deg`",
            "150000 test positions",
            "at most 10000",
        ],
    );
    // design-schedule asks for no more than a study may hold
    let o = run(&["design-schedule", "--positions", "10001"]);
    assert_input_error(&o, &["--positions", "from 1 to 1e4"]);
}

/// Numeric flags take negative numbers as values, so the range check names the flag (before:
/// "unexpected argument '-5'"); counts are parsed by one parser (before: `--chunk-size 1e12`
/// said "invalid digit"); `--max-condition nan` says what the help says.
#[test]
fn numeric_flags_are_range_checked_by_name() {
    for (args, needles) in [
        (
            vec!["design-schedule", "--positions", "-5"],
            vec!["--positions", "`-5`: must be a whole number from 1 to 1e4"],
        ),
        (
            vec!["design-schedule", "--step-deg", "-15"],
            vec!["--step-deg", "`-15`: must lie in (0, 360]"],
        ),
        (
            vec!["design-schedule", "--max-condition", "nan"],
            vec![
                "--max-condition",
                "a condition number must lie in [1, 1e12]",
            ],
        ),
        (
            vec!["mc", "--chunk-size", "1e12"],
            vec![
                "--chunk-size",
                "must be a whole number from 1 to 4294967295",
            ],
        ),
        (
            vec!["mc", "--threads", "-2"],
            vec!["--threads", "from 1 to 1024"],
        ),
        (
            vec!["mc", "--samples", "-1"],
            vec!["--samples", "from 1 to 1e10"],
        ),
        (
            vec!["end-to-end", "--yield-fraction", "-0.5"],
            vec!["--yield-fraction", "must lie in (0, 1)"],
        ),
    ] {
        let o = run(&args);
        let n: Vec<&str> = needles.clone();
        assert_input_error(&o, &n);
        assert!(!stderr(&o).contains("unexpected argument"), "{args:?}");
    }
    // the --help of the condition bound states the same range
    let help = stdout(&run(&["design-schedule", "--help"]));
    assert!(help.contains("[1, 1e12]"), "{help}");
}

/// A `--max-condition` below what any schedule reaches quotes the smallest value the search
/// reached, and that value is accepted (before: "the best one reached inf").
#[test]
fn an_unreachable_condition_bound_quotes_a_reachable_value() {
    let o = run(&[
        "design-schedule",
        "--step-deg",
        "60",
        "--max-condition",
        "1.0001",
    ]);
    assert_input_error(
        &o,
        &["--max-condition", "the smallest the search reached is"],
    );
    let err = stderr(&o);
    assert!(!err.contains("inf"), "{err}");
    let quoted = err
        .split("the smallest the search reached is ")
        .nth(1)
        .and_then(|t| t.split_whitespace().next())
        .unwrap();
    let v: f64 = quoted.parse().unwrap();
    assert!(v > 1.0001 && v.is_finite(), "{err}");
    let o = run(&[
        "design-schedule",
        "--step-deg",
        "60",
        "--max-condition",
        quoted,
        "--json",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
}

/// A lower bound above the paper's Table 4, which `end-to-end` evaluates beside its own
/// allocations, is refused naming the box (before: "of the box").
#[test]
fn a_lower_bound_above_table_4_names_table_4() {
    let dir = scratch("lb");
    let path = dir.join("lb.toml");
    std::fs::write(
        &path,
        study_text("gyrowheel-2017").replacen("dphi_y1 = 0.0", "dphi_y1 = 0.5", 1),
    )
    .unwrap();
    let o = run(&[
        "end-to-end",
        "--study",
        path.to_str().unwrap(),
        "--samples",
        "1500",
    ]);
    assert_input_error(
        &o,
        &[
            "key `allocation.lower_bounds_arcmin.dphi_y1`",
            "exceeds the upper bound 0.4235 arcmin of Table 4",
        ],
    );
}

/// `requirement --all-readings --reading X` is refused (before: `--reading` was ignored).
#[test]
fn all_readings_with_one_reading_is_refused() {
    let o = run(&[
        "requirement",
        "--all-readings",
        "--reading",
        "actual/beta1/printed",
    ]);
    assert_input_error(&o, &["--all-readings", "--reading"]);
}

/// A coefficient named `x_rate` beside the output `x` is refused when the study is read
/// (before: `calibration-error` printed the column `x_rate_error` twice).
#[test]
fn colliding_calibration_error_columns_are_refused() {
    let dir = scratch("xrate");
    let path = dir.join("xrate.toml");
    std::fs::write(
        &path,
        study_text("gyrowheel-2017").replacen(
            "{ coefficient = \"dx_zz\", regressor = \"a_z^2\"",
            "{ coefficient = \"x_rate\", regressor = \"a_z^2\"",
            1,
        ),
    )
    .unwrap();
    let o = run(&["calibration-error", "--study", path.to_str().unwrap()]);
    assert_input_error(
        &o,
        &[
            "key `sensor.outputs[0].name`",
            "sensor.outputs[0].terms[6].coefficient",
            "x_rate_error",
        ],
    );
}

/// The longest number a message may show (characters): `1.7976931348623157e308` and a sign.
const LONGEST_NUMBER_CHARS: usize = 24;

/// Whether `text` holds a run of digits longer than any number written in shortest form.
fn has_a_long_number(text: &str) -> bool {
    text.split(|c: char| !(c.is_ascii_digit() || c == '.'))
        .any(|w| w.len() > LONGEST_NUMBER_CHARS)
}

/// `text` with the first line starting with `key =` replaced by `key = value`.
fn with_key(text: &str, key: &str, value: &str) -> String {
    let mut done = false;
    let out: Vec<String> = text
        .lines()
        .map(|l| {
            if !done && l.trim_start().starts_with(&format!("{key} =")) {
                done = true;
                format!("{key} = {value}")
            } else {
                l.to_string()
            }
        })
        .collect();
    assert!(done, "{key} not found");
    out.join("\n") + "\n"
}

/// Issue 32 item 4, timing: `dwell_s = 1e-300` printed a 300-digit number, and
/// `sample_rate_hz = 1e-300` blamed `dwell_s` with two 300-digit numbers. Now the values are
/// quoted as written, and a sample rate at which no accepted dwell holds a sample is blamed
/// on `sample_rate_hz`. Failed before the fix.
#[test]
fn timing_messages_quote_the_values_as_written_and_blame_the_right_key() {
    let dir = scratch("timing-messages");
    let text = study_text("gyrowheel-2017-noise-assumed");
    let dwell = common::write(&dir, "dwell.toml", &with_key(&text, "dwell_s", "1e-300"));
    let o = run(&["end-to-end", "--study", dwell.to_str().unwrap()]);
    assert_input_error(
        &o,
        &[
            "calibration.timing.dwell_s",
            "1e-300 s",
            "sample_rate_hz = 100 Hz",
        ],
    );
    assert!(!has_a_long_number(&stderr(&o)), "{}", stderr(&o));
    let rate = common::write(
        &dir,
        "rate.toml",
        &with_key(&text, "sample_rate_hz", "1e-300"),
    );
    let o = run(&["end-to-end", "--study", rate.to_str().unwrap()]);
    assert_input_error(&o, &["calibration.timing.sample_rate_hz", "1e-300 Hz"]);
    assert!(!stderr(&o).contains("dwell_s`"), "{}", stderr(&o));
    assert!(!has_a_long_number(&stderr(&o)), "{}", stderr(&o));
}

/// Issue 32 item 4, rate steps: `rate_deg_per_s = 5e-324` named `angles_deg` and said
/// "rate_rad_per_s = 0 is outside non-zero"; a rate above the limit quoted the limit rounded
/// (`300.00000000000006 deg/s is above the rate limit (300 deg/s)` where the limit was
/// written otherwise); `estimable` on a rate study said "calibration.rate_steps = 6 is outside
/// no rate step". Each now names the key with the value as written in a sentence. Failed
/// before the fix.
#[test]
fn rate_step_messages_name_the_rate_as_written_in_clear_sentences() {
    let dir = scratch("rate-messages");
    let text = study_text("tactical-rate-table-example");
    let tiny = common::write(
        &dir,
        "tiny.toml",
        &with_key(&text, "rate_deg_per_s", "5e-324"),
    );
    let o = run(&["end-to-end", "--study", tiny.to_str().unwrap()]);
    assert_input_error(
        &o,
        &["calibration.rate_steps[0].rate_deg_per_s", "found 5e-324"],
    );
    assert!(!stderr(&o).contains("angles_deg"), "{}", stderr(&o));
    let limit = text.replace("phi_o = 300.0,", "phi_o = 299.9999999999999,");
    assert_ne!(limit, text);
    let o = run(&[
        "design-schedule",
        "--study",
        common::write(&dir, "limit.toml", &limit).to_str().unwrap(),
        "--rates-deg-per-s",
        "299.99999999999994",
    ]);
    assert_input_error(
        &o,
        &["299.99999999999994 deg/s", "(299.9999999999999 deg/s"],
    );
    let o = run(&[
        "estimable",
        "--study",
        "studies/tactical-rate-table-example.toml",
    ]);
    assert_input_error(
        &o,
        &[
            "calibration.rate_steps",
            "the study has 6 rate steps",
            "static positions only",
        ],
    );
    assert!(!stderr(&o).contains("is outside"), "{}", stderr(&o));
}

/// Issue 32 item 4, sheets: `convention = "one-sigma"` made 36,000" a 30 degree bound, beyond
/// the documented 10 degrees. The bound after the convention is checked, naming the key and
/// the convention. Failed before the fix (exit 0).
#[test]
fn a_sheet_convention_cannot_lift_a_bound_past_the_documented_maximum() {
    let dir = scratch("convention");
    let sheet = common::write(
        &dir,
        "s.toml",
        "convention = \"one-sigma\"\n[tolerances_arcmin]\ndphi_y1 = 600\ndphi_z2 = 0.78\ndalpha_x1 = 0.4234\ndalpha_z1 = 0.78\ndalpha_x2 = 0.2825\ndalpha_y2 = 0.2824\ndeps_x = 0.4234\ndeps_y = 0.4233\n",
    );
    let o = run(&["check-turntable", "--tolerances", sheet.to_str().unwrap()]);
    assert_input_error(
        &o,
        &[
            "tolerances_arcmin.dphi_y1",
            "600 arcmin read as `convention` = \"one-sigma\" bounds the error by 1800 arcmin",
            "600 arcmin",
        ],
    );
}

/// Issue 32 item 4, numbers: `allocate --safety-margin 0.9999999999999999` printed `0.0000`
/// for bounds of 1e-16 arcmin; bounds are printed with significant digits. Failed before the
/// fix.
#[test]
fn allocate_prints_tiny_bounds_with_significant_digits() {
    let o = run(&["allocate", "--safety-margin", "0.9999999999999999"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let t = stdout(&o);
    let row = t
        .lines()
        .find(|l| l.starts_with("dphi_y1 "))
        .expect("the bounds' table");
    assert!(!row.contains("0.0000"), "{row}");
    assert!(row.contains("e-"), "{row}");
}

/// One sample limit for every command that takes a count (issue 32: `report` on a study with
/// `monte_carlo.samples = 1e12` ran past 120 s where `end-to-end` refused naming `--samples`,
/// a flag the user did not give): the study's count is refused when the study is read, naming
/// the key in the file; the flag's by the flag.
#[test]
fn a_sample_count_above_the_limit_is_refused_at_once_by_the_key_written() {
    let text =
        study_text("gyrowheel-2017").replace("samples = 10000 #", "samples = 1000000000000 #");
    let dir = scratch("samples");
    let path = common::write(&dir, "many.toml", &text);
    let p = path.to_str().unwrap();
    let out = dir.join("report");
    let tol = "studies/tolerances/table4.toml";
    for args in [
        vec!["report", "--study", p, "--out", out.to_str().unwrap()],
        vec!["end-to-end", "--study", p],
        vec!["check-turntable", "--study", p, "--tolerances", tol],
        vec!["mc", "--study", p],
    ] {
        let o = run_within(&args, PROMPT_S);
        assert_input_error(&o, &["key `monte_carlo.samples`", "at most 10000000000"]);
        assert!(
            !stderr(&o).contains("--samples"),
            "{args:?}: {}",
            stderr(&o)
        );
    }
    assert!(!out.exists(), "a refused report wrote its directory");
    let study = common::study("gyrowheel-2017");
    for cmd in ["report", "end-to-end", "mc"] {
        let o = run_within(&[cmd, "--study", &study, "--samples", "2e10"], PROMPT_S);
        assert_input_error(&o, &["--samples", "from 1 to 1e10"]);
    }
}

/// An angle-dependent model too large for its limit is refused at once, naming the positions
/// key, the count and the limit (issue 32: `check-turntable` with 400 positions at distinct
/// angles ran past 120 s; its `any` model holds a coefficient per distinct shaft angle, so it
/// grows as positions times distinct angles).
#[test]
fn a_schedule_at_too_many_distinct_angles_is_refused_by_check_turntable() {
    let positions: Vec<String> = (0..2000)
        .map(|k| {
            format!(
                "[{}, {}]",
                0.18 * f64::from(k),
                (137.5 * f64::from(k)) % 360.0
            )
        })
        .collect();
    let study = common::paper_study_with_positions(&positions);
    let dir = scratch("distinct");
    let path = common::write(&dir, "distinct.toml", &study);
    let o = run_within(
        &[
            "check-turntable",
            "--study",
            path.to_str().unwrap(),
            "--tolerances",
            "studies/tolerances/table4.toml",
            "--samples",
            "1500",
        ],
        PROMPT_S,
    );
    assert_input_error(
        &o,
        &[
            "key `calibration.positions_deg`",
            "2000 test positions",
            "at most 25000000",
        ],
    );
}
