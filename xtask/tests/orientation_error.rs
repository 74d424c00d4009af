//! `cargo xtask orientation-error`: output equals the library, bad rows exit 2 with nothing
//! on standard output and a message naming the line and column.

use approx::assert_relative_eq;
use std::io::Write;
use std::process::{Command, Output, Stdio};
use tt_kinematics::units::rad_to_arcmin;
use tt_kinematics::{
    ClosedForm, ExactChain, OrientationErrorModel, Pose, SmallAngleChain, TurntableErrors,
};

const HEADER: &str = "phi1_deg,phi2_deg,dphi_y1_arcmin,dphi_z2_arcmin,dalpha_x1_arcmin,dalpha_z1_arcmin,dalpha_x2_arcmin,dalpha_y2_arcmin,deps_x_arcmin,deps_y_arcmin,deta_mm";

/// The command prints shortest round-trip decimals, so values equal the library's bit for bit
/// after parsing; allow one ulp for the arcmin conversion.
const ROUND_TRIP_REL: f64 = 4.0 * f64::EPSILON;

fn run(args: &[&str], stdin: &str) -> Output {
    let mut child = Command::new(env!("CARGO_BIN_EXE_xtask"))
        .arg("orientation-error")
        .args(args)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("spawn xtask");
    child
        .stdin
        .take()
        .unwrap()
        .write_all(stdin.as_bytes())
        .unwrap();
    child.wait_with_output().unwrap()
}

#[test]
fn orientation_error_command_matches_library_for_each_model() {
    let rows = [
        [
            30.0, 45.0, 0.4235, 0.78, 0.4234, 0.78, 0.2825, 0.2824, 0.4234, 0.4233, 0.1,
        ],
        [
            200.0, 310.0, -7.0, 3.0, 9.5, -4.0, 6.0, -10.0, 2.5, -8.0, -2.0,
        ],
    ];
    let mut input = format!("{HEADER}\n");
    for r in &rows {
        let line: Vec<String> = r.iter().map(f64::to_string).collect();
        input.push_str(&line.join(","));
        input.push('\n');
    }
    let models: [(&str, &dyn OrientationErrorModel); 4] = [
        ("", &ExactChain::default()),
        ("exact", &ExactChain::default()),
        ("small-angle", &SmallAngleChain),
        ("closed-form", &ClosedForm),
    ];
    for (flag, model) in models {
        let args: Vec<&str> = if flag.is_empty() {
            vec![]
        } else {
            vec!["--model", flag]
        };
        let out = run(&args, &input);
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let text = String::from_utf8(out.stdout).unwrap();
        let mut lines = text.lines();
        assert_eq!(
            lines.next(),
            Some("dpsi_arcmin,dtheta_arcmin,dgamma_arcmin")
        );
        for r in &rows {
            let got: Vec<f64> = lines
                .next()
                .expect("one output row per input row")
                .split(',')
                .map(|v| v.parse().unwrap())
                .collect();
            let mut chi = [0.0; 8];
            chi.copy_from_slice(&r[2..10]);
            let e = model.orientation_error(
                &Pose::from_deg(r[0], r[1]).unwrap(),
                &TurntableErrors::from_arcmin(chi, r[10] * 1e-3).unwrap(),
            );
            let want = e.to_array().map(rad_to_arcmin);
            for (g, w) in got.iter().zip(want) {
                assert_relative_eq!(*g, w, max_relative = ROUND_TRIP_REL);
            }
        }
        assert_eq!(lines.next(), None);
    }
}

#[test]
fn malformed_rows_exit_2_naming_line_and_column_with_no_partial_output() {
    let good = "0,0,1,0,0,0,0,0,0,0,0";
    let cases = [
        (
            format!("{HEADER}\n{good}\n0,0,1,0\n"),
            "<stdin>:3",
            "expected 11 columns",
        ),
        (
            format!("{HEADER}\n{good}\n0,0,x,0,0,0,0,0,0,0,0\n"),
            "<stdin>:3 column 3",
            "dphi_y1_arcmin",
        ),
        (
            format!("{HEADER}\n{good}\n0,0,1,0,0,0,0,NaN,0,0,0\n"),
            "<stdin>:3 column 8",
            "finite",
        ),
        (
            format!("{HEADER}\n0,inf,1,0,0,0,0,0,0,0,0\n"),
            "<stdin>:2 column 2",
            "finite",
        ),
        ("phi1_deg,phi2_deg\n".to_string(), "<stdin>:1", "header"),
        (String::new(), "<stdin>", "empty input"),
    ];
    for (input, location, reason) in cases {
        let out = run(&[], &input);
        assert_eq!(out.status.code(), Some(2), "input {input:?}");
        assert!(out.stdout.is_empty(), "partial output for {input:?}");
        let err = String::from_utf8(out.stderr).unwrap();
        assert!(err.contains(location), "{err} should name {location}");
        assert!(err.contains(reason), "{err} should say {reason}");
    }
}

#[test]
fn missing_file_exits_2() {
    let out = run(&["/nonexistent/turntables.csv"], "");
    assert_eq!(out.status.code(), Some(2));
    assert!(out.stdout.is_empty());
}
