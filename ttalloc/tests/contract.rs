//! The input and output contract of every command (README, "Input contract"): bad input exits
//! 2 with nothing on standard output and a message naming the file and key (or flag, or line
//! and column) in the user's units; no value outside its physical range reaches a
//! computation; a closed pipe ends quietly; defaults resolve at run time.

mod common;

use common::{assert_input_error, run, run_with_stdin, stderr, stdout, study, study_text, write};
use std::io::{BufRead, BufReader, Write};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// The paper's study with one line replaced (the line must exist).
fn paper_with(old: &str, new: &str) -> String {
    let text = study_text("gyrowheel-2017");
    assert!(text.contains(old), "the paper's study has no `{old}`");
    text.replacen(old, new, 1)
}

/// Every command that reads a study, with arguments that make it quick.
fn study_commands(path: &str) -> Vec<Vec<String>> {
    let v = |a: &[&str]| a.iter().map(|s| (*s).to_string()).collect::<Vec<_>>();
    vec![
        v(&["requirement", "--study", path]),
        v(&["allocate", "--study", path]),
        v(&["mc", "--study", path, "--samples", "1000"]),
        v(&["end-to-end", "--study", path, "--samples", "1500"]),
        v(&[
            "check-turntable",
            "--study",
            path,
            "--tolerances",
            "studies/tolerances/table4.toml",
            "--samples",
            "500",
        ]),
        v(&["calibration-error", "--study", path]),
        v(&["orientation-error", "--study", path]),
        v(&["estimable", "--study", path]),
    ]
}

fn run_owned(args: &[String]) -> std::process::Output {
    let a: Vec<&str> = args.iter().map(String::as_str).collect();
    run(&a)
}

/// Issue 15 defects 2, 4 and 5: values outside their physical range are refused at the input
/// by every command, exit 2, naming the file and the key (before: a hang in the plot's key
/// search for `gamma_deg = 1e308`, `I = 0.000000000` for an earth rate of 1e300, a dropped
/// third joint angle, exit 1 for an accuracy of 1e300).
#[test]
fn out_of_range_study_values_exit_2_naming_the_key_in_every_command() {
    let dir = tempfile::tempdir().unwrap();
    let cases = [
        (
            "gamma_deg = 0.027 # eq 16",
            "gamma_deg = 1e308",
            "requirement.gamma_deg",
        ),
        (
            "earth_rate_rad_per_s = 7.2921159e-5",
            "earth_rate_rad_per_s = 1e300",
            "site.earth_rate_rad_per_s",
        ),
        ("value = -93.3 }", "value = 1e300 }", "value"),
        (
            "accuracy = 0.01   # omega_m, the required",
            "accuracy = 1e300   # omega_m, the required",
            "accuracy",
        ),
        (
            "[0, 0], [0, 45],",
            "[270, 315, 999], [0, 45],",
            "positions_deg",
        ),
        ("dalpha_x2 = 0.0", "dalpha_x2 = 1e300", "dalpha_x2"),
        (
            "samples = 10000",
            "samples = 100000000000000000",
            "monte_carlo.samples",
        ),
        (
            "latitude_deg = 45.75",
            "latitude_deg = 91",
            "site.latitude_deg",
        ),
    ];
    for (i, (old, new, key)) in cases.iter().enumerate() {
        let path = write(dir.path(), &format!("bad{i}.toml"), &paper_with(old, new));
        let p = path.to_str().unwrap();
        for cmd in study_commands(p) {
            let start = Instant::now();
            let o = run_owned(&cmd);
            assert_input_error(&o, &[p, key]);
            assert!(
                start.elapsed() < Duration::from_secs(20),
                "{cmd:?} took {:?}",
                start.elapsed()
            );
        }
    }
}

/// Issue 15 defect 3: a huge sample count is a typed error (exit 2 naming the flag and the
/// maximum), never an allocation failure; every count flag accepts the same forms.
#[test]
fn huge_and_malformed_counts_exit_2_naming_the_flag() {
    for cmd in [
        &["end-to-end"][..],
        &["mc"],
        &[
            "check-turntable",
            "--tolerances",
            "studies/tolerances/table4.toml",
        ],
    ] {
        for bad in ["100000000000000000", "0", "1.5", "-3", "lots"] {
            let mut args = cmd.to_vec();
            let flag = format!("--samples={bad}");
            args.push(&flag);
            let o = run(&args);
            assert_input_error(&o, &["--samples", bad]);
        }
    }
    let o = run(&["end-to-end", "--samples", "2e10"]);
    assert_input_error(&o, &["--samples"]);
    let o = run(&[
        "end-to-end",
        "--samples",
        "2e3",
        "--seed",
        "1_000",
        "--json",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(v["samples"], 2000);
    assert_eq!(v["seed"], 1000);
}

/// Issue 15 defect 5: a lower bound above a tolerance is exit 2 naming the key and the values
/// in arcmin; `mc --bounds table4` works with the study's lower bounds when they fit.
#[test]
fn lower_bounds_are_checked_in_arcmin_against_every_box() {
    let dir = tempfile::tempdir().unwrap();
    let big = write(
        dir.path(),
        "lb.toml",
        &paper_with("dalpha_x2 = 0.0", "dalpha_x2 = 5"),
    );
    let p = big.to_str().unwrap();
    for cmd in [
        vec!["allocate", "--study", p],
        vec!["mc", "--study", p, "--samples", "1000"],
        vec!["end-to-end", "--study", p, "--samples", "1500"],
    ] {
        let o = run(&cmd);
        assert_input_error(&o, &[p, "dalpha_x2", "arcmin"]);
        assert!(!stderr(&o).contains(" rad"), "{}", stderr(&o));
    }
    let small = write(
        dir.path(),
        "lb_small.toml",
        &paper_with("dalpha_x2 = 0.0", "dalpha_x2 = 0.1"),
    );
    let o = run(&[
        "mc",
        "--study",
        small.to_str().unwrap(),
        "--bounds",
        "table4",
        "--samples",
        "1000",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let too_big = write(
        dir.path(),
        "lb_big.toml",
        &paper_with("dalpha_x2 = 0.0", "dalpha_x2 = 0.3"),
    );
    let o = run(&[
        "mc",
        "--study",
        too_big.to_str().unwrap(),
        "--bounds",
        "table4",
        "--samples",
        "1000",
    ]);
    assert_input_error(&o, &["dalpha_x2", "0.3", "0.2825"]);
}

/// Issue 15 defects 5 and 6: CSV input errors name the line and column; invalid UTF-8 and an
/// out-of-range cell (1e300 arcmin) are exit 2 with nothing written; a row with too many
/// cells is refused, never truncated.
#[test]
fn csv_errors_exit_2_naming_line_and_column_with_nothing_written() {
    let header = "phi1_deg,phi2_deg,dphi_y1_arcmin,dphi_z2_arcmin,dalpha_x1_arcmin,dalpha_z1_arcmin,dalpha_x2_arcmin,dalpha_y2_arcmin,deps_x_arcmin,deps_y_arcmin,deta_mm";
    let good = "30,45,0.4,0.78,0.42,0.78,0.28,0.28,0.42,0.42,0.1";
    let cases: Vec<(Vec<u8>, Vec<&str>)> = vec![
        (
            format!("{header}\n{good}\n30,45,1e300,0,0,0,0,0,0,0,0\n").into_bytes(),
            vec!["<stdin>:3", "column 3", "dphi_y1_arcmin"],
        ),
        (
            format!("{header}\n{good}\n30,45,0.4,0.78,0.42,0.78,0.28,0.28,0.42,0.42,0.1,7\n")
                .into_bytes(),
            vec!["<stdin>:3", "12"],
        ),
        (
            format!("{header}\n{good}\n30,45,x,0,0,0,0,0,0,0,0\n").into_bytes(),
            vec!["<stdin>:3", "column 3", "not a number"],
        ),
        (
            [
                format!("{header}\n{good}\n").as_bytes(),
                b"30,45,\xff\xfe,0\n",
            ]
            .concat(),
            vec!["<stdin>:3", "UTF-8"],
        ),
        (
            b"phi1_deg,phi2_deg\n".to_vec(),
            vec!["<stdin>:1", "missing columns"],
        ),
    ];
    for (input, needles) in cases {
        let o = run_with_stdin(&["orientation-error"], &input);
        assert_input_error(&o, &needles);
    }
    let o = run_with_stdin(&["calibration-error"], format!("{header}\n").as_bytes());
    assert_input_error(&o, &["phi1_deg", "no joint angles"]);
}

/// Issue 15 defect 6: a study that is not a regular file (`/dev/urandom`, a directory) or is
/// too large is refused at once, exit 2, instead of being read forever.
#[test]
fn non_regular_and_oversized_study_files_are_refused_at_once() {
    let dir = tempfile::tempdir().unwrap();
    let huge = dir.path().join("huge.toml");
    let f = std::fs::File::create(&huge).unwrap();
    f.set_len(64 << 20).unwrap();
    for path in [
        "/dev/urandom",
        dir.path().to_str().unwrap(),
        huge.to_str().unwrap(),
    ] {
        let start = Instant::now();
        let o = run(&["requirement", "--study", path]);
        assert_input_error(&o, &[path]);
        assert!(start.elapsed() < Duration::from_secs(5));
    }
    let o = run(&["requirement", "--study", "no/such/study.toml"]);
    assert_input_error(&o, &["no/such/study.toml", "cannot read"]);
    // a tolerance sheet is a user file too (before: exit 1)
    for path in ["/dev/null", "no/such/sheet.toml"] {
        let o = run(&["check-turntable", "--tolerances", path]);
        assert_input_error(&o, &[path, "tolerance file"]);
    }
}

/// Issue 15 defect 6: `orientation-error big.csv | head -2` ends quietly (exit 0, nothing on
/// standard error) as Unix tools do.
#[test]
fn closed_standard_output_ends_quietly() {
    let header = "phi1_deg,phi2_deg,dphi_y1_arcmin,dphi_z2_arcmin,dalpha_x1_arcmin,dalpha_z1_arcmin,dalpha_x2_arcmin,dalpha_y2_arcmin,deps_x_arcmin,deps_y_arcmin,deta_mm";
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("big.csv");
    let mut f = std::io::BufWriter::new(std::fs::File::create(&path).unwrap());
    writeln!(f, "{header}").unwrap();
    for i in 0..200_000 {
        writeln!(
            f,
            "{},45,0.4,0.78,0.42,0.78,0.28,0.28,0.42,0.42,0.1",
            i % 360
        )
        .unwrap();
    }
    drop(f);
    let mut child = Command::new(env!("CARGO_BIN_EXE_ttalloc"))
        .args(["orientation-error", path.to_str().unwrap()])
        .current_dir(common::root())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut out = BufReader::new(child.stdout.take().unwrap());
    let mut line = String::new();
    for _ in 0..2 {
        line.clear();
        out.read_line(&mut line).unwrap();
    }
    drop(out);
    let o = child.wait_with_output().unwrap();
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    assert!(o.stderr.is_empty(), "{}", stderr(&o));
}

/// Issue 15 item 7: the default study resolves at run time from the current directory (any
/// subdirectory of the workspace), not from a path fixed at compile time; outside a workspace
/// it is the paper's study compiled into the program (issue 20), and a user's path resolves
/// against the current directory.
#[test]
fn default_study_resolves_from_the_current_directory() {
    let o = Command::new(env!("CARGO_BIN_EXE_ttalloc"))
        .args(["requirement", "--json"])
        .current_dir(common::root().join("xtask/src"))
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", stderr(&o));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(v["study"], "studies/gyrowheel-2017.toml");
    let inside = stdout(&o);
    // Outside any workspace, with the binary copied out of the clone too: the paper's study
    // compiled into the program answers exactly as the repository's file (issue 20: the CLI
    // runs outside the repository).
    let dir = tempfile::tempdir().unwrap();
    let exe = dir.path().join("xtask-copy");
    std::fs::copy(env!("CARGO_BIN_EXE_ttalloc"), &exe).unwrap();
    let o = common::output_of_fresh_copy(
        Command::new(&exe)
            .args(["requirement", "--json"])
            .current_dir(dir.path()),
    );
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(stdout(&o), inside);
    let copy = write(dir.path(), "mine.toml", &study_text("gyrowheel-2017"));
    let o = common::output_of_fresh_copy(
        Command::new(&exe)
            .args(["requirement", "--study", "mine.toml"])
            .current_dir(dir.path()),
    );
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(stdout(&o).contains("mine.toml"));
    assert!(copy.exists());
}

/// Issue 15 item 8: a study whose given requirement disagrees with the one computed from its
/// own inputs says so in one line in every command that uses it; a computed one (the default
/// for a new study) follows the latitude and the accuracy.
#[test]
fn given_requirement_that_disagrees_is_flagged_everywhere() {
    let dir = tempfile::tempdir().unwrap();
    let text = paper_with("latitude_deg = 45.75", "latitude_deg = 30")
        .replace("accuracy = 0.01 ", "accuracy = 0.005 ");
    let given = write(dir.path(), "given.toml", &text);
    let p = given.to_str().unwrap();
    for cmd in [
        vec!["requirement", "--study", p],
        vec!["allocate", "--study", p],
        vec!["mc", "--study", p, "--samples", "1000"],
    ] {
        let o = run(&cmd);
        assert!(o.status.success(), "{cmd:?}: {}", stderr(&o));
        let all = format!("{}{}", stdout(&o), stderr(&o));
        assert_eq!(
            all.matches("differs from the one computed").count(),
            1,
            "{cmd:?}: {all}"
        );
        assert!(all.contains("0.027 deg given"), "{all}");
    }
    let computed_text = text
        .replace("source = \"given\"", "source = \"computed\"")
        .lines()
        .filter(|l| {
            !(l.starts_with("psi_deg") || l.starts_with("theta_deg") || l.starts_with("gamma_deg"))
        })
        .collect::<Vec<_>>()
        .join("\n");
    let computed = write(dir.path(), "computed.toml", &computed_text);
    let v = common::json(&[
        "requirement",
        "--study",
        computed.to_str().unwrap(),
        "--json",
    ]);
    let psi = common::num(&v["orientation_requirement_deg"]["psi"]);
    assert!(psi < 0.02 && psi > 0.01, "{psi}");
    assert!(v["disagreement"].is_null());
}

/// Issue 15 item 9: human-readable output uses sensible significant digits (no
/// `29.999999999999996`, no 17-digit floats, no 300-digit numbers), and no NaN reaches any
/// output; help texts carry neither issue numbers nor "the paper's inputs".
#[test]
fn human_output_has_sensible_digits_and_no_nan() {
    let dir = tempfile::tempdir().unwrap();
    let odd = write(
        dir.path(),
        "odd.toml",
        &paper_with("latitude_deg = 45.75", "latitude_deg = 29.999999999999996"),
    );
    let p = odd.to_str().unwrap();
    let long_float = |t: &str| {
        t.split(|c: char| !(c.is_ascii_digit() || c == '.'))
            .any(|w| w.contains('.') && w.chars().filter(char::is_ascii_digit).count() > 10)
    };
    for cmd in [
        vec!["requirement", "--study", p],
        vec!["allocate", "--study", p],
        vec!["mc", "--study", p, "--samples", "1000"],
        vec!["end-to-end", "--study", p, "--samples", "1500"],
        vec![
            "check-turntable",
            "--study",
            p,
            "--tolerances",
            "studies/tolerances/table4.toml",
            "--samples",
            "500",
        ],
    ] {
        let o = run(&cmd);
        assert!(o.status.success(), "{cmd:?}: {}", stderr(&o));
        let t = stdout(&o);
        assert!(!long_float(&t), "{cmd:?} prints a long float:\n{t}");
        assert!(!t.contains("NaN") && !t.contains("inf"), "{cmd:?}:\n{t}");
        assert!(!t.contains("29.999"), "{cmd:?}");
    }
    for cmd in [
        "requirement",
        "allocate",
        "mc",
        "end-to-end",
        "check-turntable",
        "orientation-error",
        "calibration-error",
    ] {
        let h = stdout(&run(&[cmd, "--help"]));
        assert!(
            !h.contains("issue") && !h.contains("paper's inputs"),
            "{cmd}: {h}"
        );
    }
}

/// Every command runs on every shipped study (exit 0): the turntable and the sensor are data.
#[test]
fn every_command_runs_on_every_shipped_study() {
    for name in ["three-axis-example", "imu-triad-example"] {
        let p = study(name);
        let s = study::Study::load(&common::root().join(&p)).unwrap();
        let header = study::csv::expected_header(&s.turntable);
        let zeros = vec!["0"; header.split(',').count()].join(",");
        let errors_only =
            study::csv::expected_header_for(&s.turntable, study::csv::JointColumns::Absent);
        let zeros_e = vec!["0.1"; errors_only.split(',').count()].join(",");
        for cmd in study_commands(&p) {
            let input = match cmd[0].as_str() {
                "orientation-error" => format!("{header}\n{zeros}\n"),
                "calibration-error" => format!("{errors_only}\n{zeros_e}\n"),
                _ => String::new(),
            };
            let mut cmd = cmd.clone();
            if cmd[0] == "check-turntable" {
                cmd[4] = "studies/tolerances/three-axis-navigation-grade.toml".into();
            }
            let a: Vec<&str> = cmd.iter().map(String::as_str).collect();
            let o = run_with_stdin(&a, input.as_bytes());
            assert!(o.status.success(), "{name} {cmd:?}: {}", stderr(&o));
            assert!(!o.stdout.is_empty());
        }
    }
}
