//! The study parser: the paper's study reproduces the paper's inputs, and every bad input is
//! a typed error naming the file, the key and the reason.

use study::{RequirementSource, Study, Tolerances};

const PAPER: &str = include_str!("../../studies/gyrowheel-2017.toml");

fn err(text: &str) -> String {
    Study::parse("s.toml", text).unwrap_err().to_string()
}

/// The three-axis example study describes the reference three-axis table of tt-kinematics'
/// conformance suite (the table every crate's three-axis tests, benchmarks and examples use):
/// the same factors in the same order.
#[test]
fn three_axis_study_is_the_conformance_suites_three_axis_table() {
    let s = Study::load(std::path::Path::new(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../studies/three-axis-example.toml"
    )))
    .unwrap();
    assert_eq!(
        s.turntable.factors(),
        tt_kinematics::conformance::three_axis().factors()
    );
}

/// The paper's study file holds exactly the library's paper instances: Table 3, Table 1,
/// Harbin, the 32-position schedule, eq 16 as given, LB = 0, 10,000 samples.
#[test]
fn paper_study_holds_the_papers_inputs() {
    let s = Study::parse("studies/gyrowheel-2017.toml", PAPER).unwrap();
    assert_eq!(s.turntable, tt_kinematics::paper::table3());
    assert_eq!(s.sensor, gw_model::paper::gyrowheel());
    assert_eq!(s.site, gw_model::paper::site());
    assert_eq!(s.positions_deg.len(), 32);
    assert_eq!(s.reading, calib_lsq::Reading::PAPER);
    assert_eq!(s.delta_r_kind, tt_core::DeltaRKind::SmallAngle);
    match s.requirement {
        RequirementSource::Given { rad } => {
            for r in rad {
                assert!((r.to_degrees() - 0.027).abs() < 1e-15);
            }
        }
        RequirementSource::Computed => panic!("the paper's study gives eq 16"),
    }
    assert_eq!(s.lower_bounds_rad, vec![0.0; 8]);
    assert_eq!((s.monte_carlo.samples, s.monte_carlo.seed), (10_000, 2017));
    let paper_schedule = calib_lsq::paper::schedule();
    for (a, b) in s
        .schedule()
        .positions()
        .iter()
        .zip(paper_schedule.positions())
    {
        assert!((a.base_from_sensor() - b.base_from_sensor()).amax() < 1e-15);
    }
    assert_eq!(s.path, "studies/gyrowheel-2017.toml");
}

fn replace(from: &str, to: &str) -> String {
    assert!(PAPER.contains(from), "{from}");
    PAPER.replacen(from, to, 1)
}

/// Each of `cases` (a malformed study, where its error must point and the reason it must
/// give) is refused with an error naming both (a failure points at the calling test).
#[track_caller]
fn assert_each_names_the_location_and_the_reason(cases: &[(String, &str, &str)]) {
    for (text, location, reason) in cases {
        let e = err(text);
        assert!(
            e.contains(location),
            "{e}\n  expected location `{location}`"
        );
        assert!(e.contains(reason), "{e}\n  expected reason `{reason}`");
    }
}

/// An unknown key, at the top or inside a factor, and a value TOML cannot read are refused
/// naming the file and line.
#[test]
fn unknown_keys_and_invalid_toml_name_the_file() {
    assert_each_names_the_location_and_the_reason(&[
        (
            replace("name = \"gyrowheel-2017\"", "name = \"x\"\ncolour = 3"),
            "s.toml:",
            "unknown field `colour`",
        ),
        (
            replace(
                "{ joint = \"phi1\", about = \"y\" }",
                "{ joint = \"phi1\", wobble = 2, about = \"y\" }",
            ),
            "s.toml:",
            "unknown field `wobble`",
        ),
        (
            replace("[90, 45], [90, 90]", "[90, 45], [90, 1e999]"),
            "s.toml:",
            "invalid TOML",
        ),
    ]);
}

/// A bad factor (an unknown axis, a name already taken, both a joint and an error) names
/// the factor's key with its list index.
#[test]
fn bad_turntable_factors_name_the_factor_and_the_reason() {
    assert_each_names_the_location_and_the_reason(&[
        (
            replace(
                "{ joint = \"phi1\", about = \"y\" }",
                "{ joint = \"phi1\", about = \"w\" }",
            ),
            "key `turntable.factors[0].about`",
            "unknown axis `w`",
        ),
        (
            replace(
                "{ error = \"dalpha_z1\", about = \"z\" }",
                "{ error = \"dphi_y1\", about = \"z\" }",
            ),
            "key `turntable.factors[2].error`",
            "already the name of factors[1]",
        ),
        (
            replace(
                "{ joint = \"phi1\", about = \"y\" }",
                "{ joint = \"phi1\", error = \"e\", about = \"y\" }",
            ),
            "key `turntable.factors[0]`",
            "exactly one of",
        ),
    ]);
}

/// A joint range that is empty or of no joint names the joint's key.
#[test]
fn bad_joint_ranges_name_the_joint() {
    assert_each_names_the_location_and_the_reason(&[
        (
            replace(
                "[turntable.descriptions]",
                "[turntable.joint_ranges_deg]\nphi2 = [90, 90]\n\n[turntable.descriptions]",
            ),
            "key `turntable.joint_ranges_deg.phi2`",
            "min must be below max",
        ),
        (
            replace(
                "[turntable.descriptions]",
                "[turntable.joint_ranges_deg]\nphi3 = [0, 90]\n\n[turntable.descriptions]",
            ),
            "key `turntable.joint_ranges_deg.phi3`",
            "not a joint",
        ),
    ]);
}

/// A position with too many or too few angles names the position's index and both counts.
#[test]
fn positions_of_the_wrong_length_name_the_position() {
    assert_each_names_the_location_and_the_reason(&[
        (
            replace("[0, 0], [0, 45]", "[0, 0], [0, 45, 999]"),
            "key `calibration.positions_deg[1]`",
            "one angle per joint (2: phi1, phi2), found 3",
        ),
        (
            replace("[0, 0], [0, 45]", "[0, 0], [0]"),
            "key `calibration.positions_deg[1]`",
            "found 1",
        ),
    ]);
}

/// A bad term (an unknown input symbol, a coefficient already estimated elsewhere, a value
/// out of range) or accuracy names the output and the term by their indices.
#[test]
fn bad_sensor_outputs_name_the_output_and_the_term() {
    assert_each_names_the_location_and_the_reason(&[
        (
            replace(
                "regressor = \"a_x*a_y\", value = 17.4",
                "regressor = \"a_x*a_q\", value = 17.4",
            ),
            "key `sensor.outputs[0].terms[7].regressor`",
            "unknown input symbol `a_q`",
        ),
        (
            replace("coefficient = \"dy_f\"", "coefficient = \"dx_f\""),
            "key `sensor.outputs[1].terms[1].coefficient`",
            "already the coefficient of outputs[0].terms[1]",
        ),
        (
            replace(
                "accuracy = 0.01   # omega_m, the",
                "accuracy = -0.01   # omega_m, the",
            ),
            "key `sensor.outputs[0].accuracy`",
            "must lie in",
        ),
        (
            replace(
                "accuracy = 0.01   # omega_m, the",
                "accuracy = 1e300   # omega_m, the",
            ),
            "key `sensor.outputs[0].accuracy`",
            "must lie in",
        ),
        (
            replace("value = -43.2", "value = 1e300"),
            "key `sensor.outputs[0].terms[2].value`",
            "must lie in",
        ),
    ]);
}

/// An Earth rate or latitude out of range names the site's key and the accepted range.
#[test]
fn out_of_range_site_values_name_the_key_and_the_range() {
    assert_each_names_the_location_and_the_reason(&[
        (
            replace(
                "earth_rate_rad_per_s = 7.2921159e-5",
                "earth_rate_rad_per_s = 1e300",
            ),
            "key `site.earth_rate_rad_per_s`",
            "must lie in [1e-6, 0.001] rad/s, found 1e300",
        ),
        (
            replace("latitude_deg = 45.75", "latitude_deg = 91"),
            "key `site.latitude_deg`",
            "must lie in [-90, 90] deg",
        ),
    ]);
}

/// A given requirement out of range or missing, or values given to a computed one, name the
/// requirement's key.
#[test]
fn bad_requirements_name_the_key() {
    assert_each_names_the_location_and_the_reason(&[
        (
            replace("gamma_deg = 0.027", "gamma_deg = 1e308"),
            "key `requirement.gamma_deg`",
            "must lie in [1e-9, 10] deg",
        ),
        (
            replace("gamma_deg = 0.027 # eq 16", ""),
            "key `requirement.gamma_deg`",
            "missing",
        ),
        (
            replace("source = \"given\"", "source = \"computed\""),
            "key `requirement.source`",
            "takes no values",
        ),
    ]);
}

/// A negative lower bound, or one of a translation error, names the error's key.
#[test]
fn bad_lower_bounds_name_the_error() {
    assert_each_names_the_location_and_the_reason(&[
        (
            replace("dalpha_x2 = 0.0", "dalpha_x2 = -1.0"),
            "key `allocation.lower_bounds_arcmin.dalpha_x2`",
            "must lie in [0, 600] arcmin",
        ),
        (
            replace("deps_y = 0.0\n", "deps_y = 0.0\ndeta = 1.0\n"),
            "key `allocation.lower_bounds_arcmin.deta`",
            "is a translation",
        ),
    ]);
}

/// A Monte Carlo sample count of zero or above the maximum names the key.
#[test]
fn sample_counts_out_of_range_name_the_key() {
    assert_each_names_the_location_and_the_reason(&[
        (
            replace("samples = 10000", "samples = 0"),
            "key `monte_carlo.samples`",
            "at least 1",
        ),
        (
            replace("samples = 10000", "samples = 100000000000000000"),
            "key `monte_carlo.samples`",
            "at most",
        ),
    ]);
}

/// An unknown reading or orientation-error kind names the calibration's key (and the words
/// accepted).
#[test]
fn unknown_calibration_words_name_the_key() {
    assert_each_names_the_location_and_the_reason(&[
        (
            replace(
                "reading = \"intended/beta1/printed\"",
                "reading = \"intended/beta3/printed\"",
            ),
            "key `calibration.reading`",
            "unknown reading",
        ),
        (
            replace("delta_r = \"small-angle\"", "delta_r = \"tiny\""),
            "key `calibration.delta_r`",
            "\"small-angle\" or \"exact\"",
        ),
    ]);
}

/// The paper's schedule without its sixteen positions with phi2 at 45, 135, 225 or 315 deg
/// cannot identify a coefficient: the error names the positions' key and the coefficient.
#[test]
fn a_schedule_that_cannot_identify_a_coefficient_names_it() {
    let text = PAPER
        .replace(", [0, 45]", "")
        .replace(", [0, 135]", "")
        .replace(", [0, 225]", "")
        .replace(", [0, 315]", "")
        .replace(", [90, 45]", "")
        .replace(", [90, 135]", "")
        .replace(", [90, 225]", "")
        .replace(", [90, 315]", "")
        .replace(", [180, 45]", "")
        .replace(", [180, 135]", "")
        .replace(", [180, 225]", "")
        .replace(", [180, 315]", "")
        .replace(", [270, 45]", "")
        .replace(", [270, 135]", "")
        .replace(", [270, 225]", "")
        .replace(", [270, 315]", "");
    assert_each_names_the_location_and_the_reason(&[(
        text,
        "key `calibration.positions_deg`",
        "cannot identify dx_xy of output `x`",
    )]);
}

/// A missing required key is named.
#[test]
fn missing_keys_are_named() {
    let e = err(&PAPER.replace("latitude_deg = 45.75", ""));
    assert!(e.contains("missing field `latitude_deg`"), "{e}");
    let e = err(&PAPER.replace("[monte_carlo]", "[monte_carlox]"));
    assert!(e.contains("monte_carlo"), "{e}");
}

/// Defaults of a new study: computed requirement, the user's reading, the exact matrix.
#[test]
fn omitted_optional_sections_take_their_documented_defaults() {
    let start = PAPER.find("[requirement]").unwrap();
    let end = PAPER.find("# Tolerance allocation").unwrap();
    let text = format!("{}{}", &PAPER[..start], &PAPER[end..])
        .replace("reading = \"intended/beta1/printed\"", "")
        .replace("delta_r = \"small-angle\"", "");
    let s = Study::parse("s.toml", &text).unwrap();
    assert_eq!(s.requirement, RequirementSource::Computed);
    assert_eq!(s.reading, calib_lsq::Reading::USER);
    assert_eq!(s.delta_r_kind, tt_core::DeltaRKind::Exact);
    // a byte-order mark is accepted
    assert!(Study::parse("s.toml", &format!("\u{feff}{PAPER}")).is_ok());
}

/// A study rewritten with other positions keeps every comment and value, and parses back to
/// the same study with the new positions.
#[test]
fn text_with_positions_keeps_comments_and_round_trips() {
    let s = Study::parse("s.toml", PAPER).unwrap();
    let positions: Vec<Vec<f64>> = s.positions_deg.iter().rev().cloned().collect();
    let text = s
        .text_with_positions(&positions, "designed by test\nsecond line")
        .unwrap();
    assert!(
        text.contains("# designed by test\n# second line\npositions_deg"),
        "{text}"
    );
    assert!(text.contains("# Table 1, D(x)_xy"));
    // the comment that described the old positions stays, above the new lines
    assert!(
        text.contains("# both axes.\n# designed by test\n"),
        "{text}"
    );
    let back = Study::parse("s.toml", &text).unwrap();
    assert_eq!(back.positions_deg, positions);
    assert_eq!(back.sensor, s.sensor);
}

#[test]
fn tolerance_files_are_strict() {
    let t = tt_kinematics::paper::table3();
    let good = "[tolerances_arcmin]\ndphi_y1 = 0.4\ndphi_z2 = 0.8\ndalpha_x1 = 0.4\ndalpha_z1 = 0.8\ndalpha_x2 = 0.3\ndalpha_y2 = 0.3\ndeps_x = 0.4\ndeps_y = 0.4\n[tolerances_mm]\ndeta = 0.1\n";
    let tol = Tolerances::parse("t.toml", good, &t).unwrap();
    assert!((tol.ub_rad[4] - 0.3_f64.to_radians() / 60.0).abs() < 1e-18);
    assert_eq!(tol.translations_m, vec![Some(1e-4)]);
    let e = Tolerances::parse("t.toml", &good.replace("deps_y = 0.4\n", ""), &t)
        .unwrap_err()
        .to_string();
    assert!(e.contains("missing: deps_y"), "{e}");
    let e = Tolerances::parse(
        "t.toml",
        &good.replace("deps_y = 0.4", "deps_y = 1e300"),
        &t,
    )
    .unwrap_err()
    .to_string();
    assert!(
        e.contains("key `tolerances_arcmin.deps_y`") && e.contains("must lie in"),
        "{e}"
    );
    let e = Tolerances::parse(
        "t.toml",
        &good.replace("deps_y = 0.4", "deps_y = 0.4\ndeta = 2"),
        &t,
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("is a translation"), "{e}");
}

#[test]
fn csv_columns_follow_the_study_turntable_in_any_order() {
    use study::csv::{TurntableColumns, expected_header};
    let t = tt_kinematics::paper::table3();
    assert_eq!(
        expected_header(&t),
        "phi1_deg,phi2_deg,dphi_y1_arcmin,dphi_z2_arcmin,dalpha_x1_arcmin,dalpha_z1_arcmin,dalpha_x2_arcmin,dalpha_y2_arcmin,deps_x_arcmin,deps_y_arcmin,deta_mm"
    );
    let header = "deta_mm, phi2_deg,phi1_deg,dphi_y1_arcmin,dphi_z2_arcmin,dalpha_x1_arcmin,dalpha_z1_arcmin,dalpha_x2_arcmin,dalpha_y2_arcmin,deps_x_arcmin,deps_y_arcmin";
    let cols = TurntableColumns::from_header("c.csv", 1, &format!("\u{feff}{header}"), &t).unwrap();
    let row = cols
        .parse_row("c.csv", 2, "0.1, 90, 30, 1,0,0,0,0,0,0,0")
        .unwrap();
    assert!((row.pose_rad[0] - 30f64.to_radians()).abs() < 1e-15);
    assert!((row.pose_rad[1] - 90f64.to_radians()).abs() < 1e-15);
    assert!((row.translations_m[0] - 1e-4).abs() < 1e-18);
    for (line, want) in [
        (
            "0.1,90,30,1,0,0,0,0,0,0",
            "c.csv:2: expected 11 columns, found 10",
        ),
        (
            "0.1,90,30,x,0,0,0,0,0,0,0",
            "c.csv:2 column 4: `dphi_y1_arcmin`: `x` is not a number",
        ),
        (
            "0.1,90,30,1e300,0,0,0,0,0,0,0",
            "c.csv:2 column 4: `dphi_y1_arcmin` must lie in",
        ),
        ("0.1,NaN,30,1,0,0,0,0,0,0,0", "column 2"),
    ] {
        let e = cols.parse_row("c.csv", 2, line).unwrap_err().to_string();
        assert!(e.contains(want), "{e}");
    }
    let e = TurntableColumns::from_header("c.csv", 1, "phi1_deg,phi2_deg,extra_arcmin", &t)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("column 3") && e.contains("unknown column `extra_arcmin`"),
        "{e}"
    );
    let e = TurntableColumns::from_header("c.csv", 1, "phi1_deg,phi2_deg", &t)
        .unwrap_err()
        .to_string();
    assert!(e.contains("missing columns: dphi_y1_arcmin"), "{e}");
    let e = TurntableColumns::from_header("c.csv", 1, "phi1_deg,phi1_deg", &t)
        .unwrap_err()
        .to_string();
    assert!(e.contains("appears twice"), "{e}");
    assert!(
        study::csv::decode_line("c.csv", 3, b"1,\xff,2")
            .unwrap_err()
            .to_string()
            .starts_with("c.csv:3")
    );
}

#[test]
fn files_that_are_not_regular_or_too_large_are_refused() {
    let e = Study::load(std::path::Path::new("/dev/null"))
        .unwrap_err()
        .to_string();
    assert!(e.contains("not a regular file"), "{e}");
    let e = Study::load(std::path::Path::new("/nonexistent/study.toml"))
        .unwrap_err()
        .to_string();
    assert!(
        e.starts_with("/nonexistent/study.toml: cannot read study file"),
        "{e}"
    );
}

/// A schedule longer than `study::limits::MAX_POSITIONS` is refused when read, naming
/// `calibration.positions_deg` and the count (issue 19: 150,000 positions, a 1.4 MB file under
/// the size limit, made `requirement` run past 100 s at 533 MB); the limit itself is accepted.
#[test]
fn schedules_beyond_the_position_limit_are_refused_with_the_count() {
    let with = |n: usize| {
        let positions: Vec<String> = (0..n)
            .map(|k| format!("[{}, {}]", (k * 7) % 360, (k * 13) % 360))
            .collect();
        let start = PAPER.find("positions_deg = [").unwrap();
        let end = start + PAPER[start..].find("\n]\n").unwrap() + 3;
        format!(
            "{}positions_deg = [{}]\n{}",
            &PAPER[..start],
            positions.join(", "),
            &PAPER[end..]
        )
    };
    let max = study::limits::MAX_POSITIONS;
    let e = err(&with(150_000));
    assert!(
        e.contains("key `calibration.positions_deg`")
            && e.contains("150000")
            && e.contains(&max.to_string()),
        "{e}"
    );
    assert!(err(&with(max + 1)).contains(&(max + 1).to_string()));
    assert_eq!(
        Study::parse("s.toml", &with(max))
            .unwrap()
            .positions_deg
            .len(),
        max
    );
}

/// A coefficient named `<output>_rate` would print the column `<output>_rate_error` of
/// `calibration-error` twice (issue 19): refused when read, naming both keys.
#[test]
fn colliding_calibration_error_columns_are_refused_naming_both_keys() {
    let e = err(&replace(
        "{ coefficient = \"dx_zz\", regressor = \"a_z^2\"",
        "{ coefficient = \"x_rate\", regressor = \"a_z^2\"",
    ));
    assert!(
        e.contains("key `sensor.outputs[0].name`")
            && e.contains("sensor.outputs[0].terms[6].coefficient")
            && e.contains("`x_rate_error`"),
        "{e}"
    );
    // the columns of a valid study are all distinct
    let s = Study::parse("s.toml", PAPER).unwrap();
    let cols = study::csv::calibration_error_columns(&s.sensor);
    let mut names: Vec<&str> = cols.iter().map(|(c, _)| c.as_str()).collect();
    names.sort_unstable();
    names.dedup();
    assert_eq!(names.len(), cols.len());
}

/// An out-of-range value is shown as given, not rounded back into range (issue 19:
/// 600.0000001 arcmin read "found 600"), and a given requirement below the documented lower
/// limit (1e-300 deg made the objective overflow) is refused naming the key.
#[test]
fn out_of_range_values_are_shown_exactly_and_tiny_requirements_refused() {
    let e = err(&replace("dphi_y1 = 0.0", "dphi_y1 = 600.0000001"));
    assert!(
        e.contains("key `allocation.lower_bounds_arcmin.dphi_y1`")
            && e.contains("found 600.0000001"),
        "{e}"
    );
    let e = err(&replace("psi_deg = 0.027", "psi_deg = 1e-300"));
    assert!(
        e.contains("key `requirement.psi_deg`")
            && e.contains("must lie in [1e-9, 10] deg")
            && e.contains("found 1e-300"),
        "{e}"
    );
    let lo = study::limits::REQUIREMENT_DEG.0;
    assert!(
        Study::parse(
            "s.toml",
            &replace("psi_deg = 0.027", &format!("psi_deg = {lo:e}"))
        )
        .is_ok()
    );
}

#[test]
#[ignore = "prints sample messages for a human to read: cargo test -p study -- --ignored --nocapture"]
fn print_sample_messages() {
    for (from, to) in [
        ("name = \"gyrowheel-2017\"", "name = \"x\"\ncolour = 3"),
        ("[90, 45], [90, 90]", "[90, 45], [90, 1e999]"),
        ("latitude_deg = 45.75", ""),
        ("gamma_deg = 0.027", "gamma_deg = 1e308"),
    ] {
        println!("{}", err(&replace(from, to)));
    }
}

/// Issue 19 §6: an output with a known input term and an estimated scale-factor error on the
/// same regressor (the most common gyro and accelerometer model) parses, as in the shipped IMU
/// example's `ax`; two estimated coefficients of one regressor are still refused, naming the
/// key.
#[test]
fn a_known_input_and_an_estimated_scale_factor_error_may_share_a_regressor() {
    let imu = Study::load(std::path::Path::new(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../studies/imu-triad-example.toml"
    )))
    .unwrap();
    let ax = imu.sensor.output("ax").unwrap();
    let on_ax: Vec<(&str, bool)> = ax
        .terms
        .iter()
        .filter(|t| t.regressor.to_string() == "a_x")
        .map(|t| (t.coefficient.as_str(), t.known))
        .collect();
    assert_eq!(on_ax, [("in_x", true), ("sf_x", false)]);
    // the paper's x output with a known unit input on the bias regressor beside D(x)_F
    let text = replace(
        "{ coefficient = \"dx_f\", regressor = \"1\", value = -93.3 },",
        "{ coefficient = \"dx_in\", regressor = \"1\", value = 1.0, known = true },\n  { coefficient = \"dx_f\", regressor = \"1\", value = -93.3 },",
    );
    let s = Study::parse("s.toml", &text).unwrap();
    assert_eq!(s.sensor.outputs()[0].n_estimated(), 7);
    let e = err(&replace(
        "regressor = \"a_x*a_y\", value = 17.4",
        "regressor = \"a_x\", value = 17.4",
    ));
    assert!(
        e.contains("key `sensor.outputs[0].terms[7].regressor`")
            && e.contains("two estimated coefficients of one regressor"),
        "{e}"
    );
}

/// Issue 19 §2: the study's `name` names the report directory (`target/report/<name>`), so it
/// is a file-name-safe slug checked at parse time. A path (`../../../escaped`), `.`, `..`, a NUL
/// or an escape character, a space, a leading `-` or `.`, and 300 characters are refused naming
/// the key `name`, the offending value shown escaped and shortened (never raw).
#[test]
fn study_name_is_a_file_name_safe_slug_checked_at_parse_time() {
    let long = "a".repeat(300);
    let bad = [
        "../../../escaped",
        "..",
        ".",
        "a/b",
        "a\\\\b",
        "nul\\u0000byte",
        "esc\\u001b[31mred",
        "bell\\u0007",
        "cr\\r",
        "my study",
        "-rf",
        ".hidden",
        "",
        long.as_str(),
        "ünïcode",
    ];
    for b in bad {
        let text = replace("name = \"gyrowheel-2017\"", &format!("name = \"{b}\""));
        let e = err(&text);
        assert!(e.contains("s.toml: key `name`"), "{b}: {e}");
        assert!(e.contains("file-name-safe"), "{b}: {e}");
        assert!(
            !e.chars().any(tt_core::human::is_unsafe_char),
            "{b}: the message carries a raw control character: {e:?}"
        );
        assert!(e.len() < 400, "{b}: the value is shortened: {e}");
    }
    let e = err(&replace(
        "name = \"gyrowheel-2017\"",
        "name = \"esc\\u001b[31mred\"",
    ));
    assert!(e.contains("esc\\u{1b}[31mred"), "shown escaped: {e}");
    assert!(
        err(&replace(
            "name = \"gyrowheel-2017\"",
            &format!("name = \"{long}\"")
        ))
        .contains("(300 characters)")
    );
    for good in ["gyrowheel-2017", "Lab_3.v2", "x", &"a".repeat(64)] {
        let s = Study::parse(
            "s.toml",
            &replace("name = \"gyrowheel-2017\"", &format!("name = \"{good}\"")),
        )
        .unwrap_or_else(|e| panic!("{good}: {e}"));
        assert_eq!(s.name, good);
    }
}

/// Issue 19 §2: the one-line labels printed as they are by every command (an output's `unit`,
/// a turntable part's description, a tolerance sheet's `name`) refuse control characters
/// (ESC, BEL, CR, a line break, a bidirectional override), naming the key and showing the value
/// escaped; printable text, markup included, is accepted (the outputs escape it).
#[test]
fn one_line_labels_refuse_control_characters_naming_the_key() {
    let cases = [
        (
            "unit = \"deg_per_h\"",
            "unit = \"deg/h\\u001b[31m\"",
            "sensor.outputs[0].unit",
            "deg/h\\u{1b}[31m",
        ),
        (
            "unit = \"deg_per_h\"",
            "unit = \"deg/h\\nverdict: meets\"",
            "sensor.outputs[0].unit",
            "deg/h\\nverdict: meets",
        ),
        (
            "phi1 = \"outer axis\"",
            "phi1 = \"outer\\u202eaxis\"",
            "turntable.descriptions.phi1",
            "outer\\u{202e}axis",
        ),
    ];
    for (from, to, key, shown) in cases {
        let e = err(&replace(from, to));
        assert!(e.contains(&format!("s.toml: key `{key}`")), "{e}");
        assert!(e.contains(shown), "{e}");
        assert!(!e.chars().any(tt_core::human::is_unsafe_char), "{e:?}");
    }
    let s = Study::parse(
        "s.toml",
        &replace("unit = \"deg_per_h\"", "unit = \"deg/h<img src=x>\""),
    )
    .unwrap();
    assert_eq!(s.sensor.outputs()[0].unit, "deg/h<img src=x>");

    let turntable = Study::parse("s.toml", PAPER).unwrap().turntable;
    let sheet = "[tolerances_arcmin]\ndphi_y1 = 0.4\ndphi_z2 = 0.78\ndalpha_x1 = 0.4\ndalpha_z1 = 0.78\ndalpha_x2 = 0.28\ndalpha_y2 = 0.28\ndeps_x = 0.42\ndeps_y = 0.42\n";
    let e = Tolerances::parse(
        "t.toml",
        &format!("name = \"v\\u0007\\r\"\n{sheet}"),
        &turntable,
    )
    .unwrap_err()
    .to_string();
    assert!(
        e.contains("t.toml: key `name`") && e.contains("v\\u{7}\\r"),
        "{e}"
    );
    let t = Tolerances::parse(
        "t.toml",
        &format!("name = \"<script>\"\n{sheet}"),
        &turntable,
    )
    .unwrap();
    assert_eq!(t.name.as_deref(), Some("<script>"));
}

/// Angle-dependent errors (issue 22): `varies`, `of` and `harmonics` on an error factor give
/// each error its model in the order of chi; bad input names the key.
#[test]
fn angle_dependent_errors_are_read_and_bad_ones_name_the_key() {
    let wobble = r#"{ error = "dalpha_y2", about = "y" }"#;
    let with = |to: &str| PAPER.replacen(wobble, to, 1);
    let s = Study::parse(
        "s.toml",
        &with(r#"{ error = "dalpha_y2", about = "y", harmonics = [1, 2], of = "phi2" }"#),
    )
    .unwrap();
    let i = s.turntable.rotation_error_index("dalpha_y2").unwrap();
    assert_eq!(
        s.variations[i],
        tt_kinematics::ErrorVariation::Harmonics {
            joint: "phi2".into(),
            orders: vec![1, 2]
        }
    );
    assert!(s.has_angle_dependent_errors());
    assert_eq!(s.expansion().unwrap().n_coefficients(), 8 + 4);
    let s = Study::parse(
        "s.toml",
        &with(r#"{ error = "dalpha_y2", about = "y", varies = "any", of = "phi2" }"#),
    )
    .unwrap();
    // phi2 takes 8 distinct angles in the paper's schedule
    assert_eq!(s.expansion().unwrap().n_coefficients(), 7 + 8);
    let paper = Study::parse("s.toml", PAPER).unwrap();
    assert!(!paper.has_angle_dependent_errors());
    for (to, key) in [
        (
            r#"{ error = "dalpha_y2", about = "y", harmonics = [1.5], of = "phi2" }"#,
            "turntable.factors[8].harmonics[0]",
        ),
        (
            r#"{ error = "dalpha_y2", about = "y", harmonics = [0], of = "phi2" }"#,
            "turntable.factors[8].harmonics[0]",
        ),
        (
            r#"{ error = "dalpha_y2", about = "y", harmonics = [1, -2], of = "phi2" }"#,
            "turntable.factors[8].harmonics[1]",
        ),
        (
            r#"{ error = "dalpha_y2", about = "y", harmonics = [1], of = "phi9" }"#,
            "turntable.factors[8].of",
        ),
        (
            r#"{ error = "dalpha_y2", about = "y", harmonics = [1] }"#,
            "turntable.factors[8].of",
        ),
        (
            r#"{ error = "dalpha_y2", about = "y", varies = "sometimes", of = "phi2" }"#,
            "turntable.factors[8].varies",
        ),
        (
            r#"{ error = "dalpha_y2", about = "y", varies = "any", of = "phi2", harmonics = [1] }"#,
            "turntable.factors[8].harmonics",
        ),
    ] {
        let e = err(&with(to));
        assert!(e.contains(&format!("key `{key}`")), "{to}: {e}");
    }
    // an error before the joint does not follow it
    let e = err(&PAPER.replacen(
        r#"{ error = "dphi_y1", about = "y" }"#,
        r#"{ error = "dphi_y1", about = "y", varies = "any", of = "phi2" }"#,
        1,
    ));
    assert!(e.contains("turntable.factors[1].of"), "{e}");
}

/// A sheet in the vendor's terms (issue 22): per axis a wobble and a perpendicularity bound a
/// disc on the two errors they name (the square around it in `ub_rad`), a positioning accuracy
/// one error; the convention scales the values; a quantity of an axis the table lacks, or
/// errors that do not ride on the axis, name the key.
#[test]
fn vendor_sheets_map_axis_quantities_onto_the_description_and_refuse_what_does_not_map() {
    let three = Study::load(std::path::Path::new(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../studies/three-axis-example.toml"
    )))
    .unwrap();
    let t = &three.turntable;
    let sheet = include_str!("../../studies/tolerances/three-axis-vendor-sheet.toml");
    let tol = Tolerances::parse("v.toml", sheet, t).unwrap();
    assert_eq!(tol.discs.len(), 5);
    let arcsec = |v: f64| v / 3600.0 * std::f64::consts::PI / 180.0;
    let i = t.rotation_error_index("dalpha_ix").unwrap();
    approx::assert_relative_eq!(tol.ub_rad[i], arcsec(3.0), max_relative = 1e-15);
    assert_eq!(
        tol.implied[i],
        Some(tt_kinematics::ErrorVariation::Any {
            joint: "phi_i".into()
        })
    );
    // the axes' intersection bounds the translation between the previous joint and this one
    let mm = |v: f64| v * 1e-3;
    for name in ["deta_om", "deta_mi"] {
        let k = t
            .translation_error_names()
            .iter()
            .position(|n| *n == name)
            .unwrap();
        approx::assert_relative_eq!(
            tol.translations_m[k].unwrap(),
            mm(0.1),
            max_relative = 1e-15
        );
    }
    let o = t.rotation_error_index("deps_mi_x").unwrap();
    assert_eq!(
        tol.implied[o],
        Some(tt_kinematics::ErrorVariation::Constant)
    );
    // peak-to-peak halves every value, one-sigma triples one
    let p2p = Tolerances::parse(
        "v.toml",
        &sheet.replace("convention = \"bound\"", "convention = \"peak-to-peak\"\n[conventions]\n\"axes.phi_i.wobble_arcsec\" = \"one-sigma\""),
        t,
    )
    .unwrap();
    let p = t.rotation_error_index("dphi_i").unwrap();
    approx::assert_relative_eq!(p2p.ub_rad[p], arcsec(2.5), max_relative = 1e-15);
    approx::assert_relative_eq!(p2p.ub_rad[i], arcsec(9.0), max_relative = 1e-15);
    let bad = |from: &str, to: &str| {
        Tolerances::parse("v.toml", &sheet.replacen(from, to, 1), t)
            .unwrap_err()
            .to_string()
    };
    for (from, to, key) in [
        ("[axes.phi_i]", "[axes.phi_x]", "axes.phi_x"),
        (
            "wobble = [\"dalpha_ix\", \"dalpha_iz\"]",
            "wobble = [\"dalpha_ox\", \"dalpha_iz\"]",
            "axes.phi_i.wobble[0]",
        ),
        (
            "wobble = [\"dalpha_ix\", \"dalpha_iz\"]",
            "wobble = [\"dalpha_ix\"]",
            "axes.phi_i.wobble",
        ),
        (
            "positioning = \"dphi_i\"",
            "positioning = \"dalpha_ix\"",
            "axes.phi_i.positioning",
        ),
        (
            "convention = \"bound\"",
            "convention = \"2-sigma\"",
            "convention",
        ),
        (
            "intersection = [\"deta_mi\"]",
            "intersection = [\"dphi_i\"]",
            "axes.phi_i.intersection",
        ),
        (
            "intersection = [\"deta_mi\"]",
            "intersection = [\"deta_om\"]",
            "axes.phi_i.intersection",
        ),
        (
            "intersection_mm = 0.1\nintersection = [\"deta_mi\"]",
            "intersection_mm = -0.1\nintersection = [\"deta_mi\"]",
            "axes.phi_i.intersection_mm",
        ),
        (
            "intersection_mm = 0.1\nintersection = [\"deta_mi\"]",
            "intersection = [\"deta_mi\"]",
            "axes.phi_i.intersection",
        ),
        (
            "intersection = [\"deta_mi\"]",
            "intersection = [\"deta_mi\"]\n[tolerances_mm]\ndeta_mi = 0.2",
            "axes.phi_i.intersection",
        ),
        (
            "wobble_arcsec = 3.0\nwobble = [\"dalpha_ix\", \"dalpha_iz\"]",
            "wobble_arcsec = -3.0\nwobble = [\"dalpha_ix\", \"dalpha_iz\"]",
            "axes.phi_i.wobble_arcsec",
        ),
    ] {
        let e = bad(from, to);
        assert!(e.contains(&format!("key `{key}`")), "{to}: {e}");
    }
}

/// Measured errors (issue 22): `[[compensation.measured]]` gives a constant's value or a
/// harmonic error's coefficients with an uncertainty; a negative uncertainty, a value outside
/// the physical range, the wrong number of coefficients or an unknown error name the key.
#[test]
fn measured_errors_are_read_and_bad_ones_name_the_key() {
    let text = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../studies/gyrowheel-2017-harmonic-errors.toml"
    ))
    .unwrap();
    let s = Study::parse("h.toml", &text).unwrap();
    let i = s.turntable.rotation_error_index("dalpha_x1").unwrap();
    let m = s.measured[i].as_ref().unwrap();
    assert_eq!(m.coefficients_rad.len(), 5);
    approx::assert_relative_eq!(
        m.uncertainty_rad,
        0.05 * std::f64::consts::PI / 10800.0,
        max_relative = 1e-15
    );
    assert_eq!(s.measured.iter().filter(|m| m.is_some()).count(), 4);
    for (from, to, key) in [
        (
            "value_arcmin = 0.20\nuncertainty_arcmin = 0.05",
            "value_arcmin = 0.20\nuncertainty_arcmin = -0.05",
            "compensation.measured[0].uncertainty_arcmin",
        ),
        (
            "value_arcmin = 0.20",
            "value_arcmin = 700.0",
            "compensation.measured[0].value_arcmin",
        ),
        (
            "coefficients_arcmin = [0.05, 0.20, -0.10, 0.03, 0.02]",
            "coefficients_arcmin = [0.05, 0.20]",
            "compensation.measured[2].coefficients_arcmin",
        ),
        (
            "error = \"deps_y\"\nvalue",
            "error = \"deps_q\"\nvalue",
            "compensation.measured[1].error",
        ),
        (
            "error = \"deps_y\"\nvalue",
            "error = \"deps_x\"\nvalue",
            "compensation.measured[1].error",
        ),
        (
            "error = \"deps_y\"\nvalue_arcmin = -0.15",
            "error = \"dalpha_x2\"\nvalue_arcmin = -0.15",
            "compensation.measured[1].value_arcmin",
        ),
    ] {
        assert!(text.contains(from), "{from}");
        let e = err(&text.replacen(from, to, 1));
        assert!(e.contains(&format!("key `{key}`")), "{to}: {e}");
    }
}

/// Issue 32 item 4: a convention could lift a bound past the documented maximum (a one-sigma
/// 36,000" became a 30 degree bound, the limit being 10 degrees). The bound after the
/// convention is checked against the same limit, naming the value's key and the convention's.
/// Failed before the fix (the sheet was accepted).
#[test]
fn a_convention_cannot_lift_a_sheet_bound_past_the_documented_maximum() {
    let three = Study::load(std::path::Path::new(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../studies/three-axis-example.toml"
    )))
    .unwrap();
    let sheet = include_str!("../../studies/tolerances/three-axis-vendor-sheet.toml");
    let lifted = sheet.replacen("wobble_arcsec = 3.0", "wobble_arcsec = 36000", 1);
    // as a bound, 36,000" (600') is the largest accepted
    assert!(Tolerances::parse("v.toml", &lifted, &three.turntable).is_ok());
    let one_sigma = lifted.replace(
        "convention = \"bound\"",
        "convention = \"bound\"\n[conventions]\n\"axes.phi_o.wobble_arcsec\" = \"one-sigma\"",
    );
    let err = Tolerances::parse("v.toml", &one_sigma, &three.turntable)
        .unwrap_err()
        .to_string();
    for needle in [
        "axes.phi_o.wobble_arcsec",
        "36000 arcsec read as `conventions.axes.phi_o.wobble_arcsec` = \"one-sigma\" bounds the error by 108000 arcsec",
        "36000 arcsec)",
    ] {
        assert!(err.contains(needle), "`{needle}` not in: {err}");
    }
}
