//! The noise keys of a study (`[sensor.outputs.noise]`, `[calibration.timing]`): the IMU
//! example's cited values, a study without them parsing as before, and every bad input a
//! typed error naming the file, the key and the reason.

use approx::assert_relative_eq;
use study::Study;

const PAPER: &str = include_str!("../../studies/gyrowheel-2017.toml");
const IMU: &str = include_str!("../../studies/imu-triad-example.toml");
const THREE_AXIS: &str = include_str!("../../studies/three-axis-example.toml");

/// Unit conversions and closed forms in a few operations: a few ulps, relative.
const CONVERSION_REL: f64 = 1e-14;
/// Covariance through QR and products on 24 positions: relative, a few hundred ulps.
const PRODUCT_REL: f64 = 1e-12;

/// The noise model of the paper's second output with `lines` as its noise table.
fn noise_of(lines: &str) -> gw_model::noise::NoiseModel {
    Study::parse("s.toml", &paper_with(lines, ""))
        .unwrap()
        .noise[1]
        .clone()
        .unwrap()
}

fn err(text: &str) -> String {
    Study::parse("s.toml", text).unwrap_err().to_string()
}

/// The paper's study with `noise` (TOML lines) as the noise table of its second output
/// (`y`, deg/h) and `timing` (lines) as `[calibration.timing]`.
fn paper_with(noise: &str, timing: &str) -> String {
    let mut text = PAPER.replace(
        "\n# Multiposition calibration (eq 2-14).\n[calibration]\n",
        &format!("\n[sensor.outputs.noise]\n{noise}\n\n[calibration]\n"),
    );
    if noise.is_empty() {
        text = PAPER.to_string();
    }
    if !timing.is_empty() {
        text.push_str(&format!("\n[calibration.timing]\n{timing}\n"));
    }
    text
}

/// A study without noise and timing parses exactly as before: no noise model, no timing; and
/// adding them changes nothing else.
#[test]
fn study_without_noise_or_timing_parses_as_before() {
    for text in [PAPER, THREE_AXIS] {
        let s = Study::parse("s.toml", text).unwrap();
        assert_eq!(s.noise, vec![None; s.sensor.n_outputs()]);
        assert_eq!(s.timing, None);
    }
    let plain = Study::parse("s.toml", PAPER).unwrap();
    let noisy = Study::parse(
        "s.toml",
        &paper_with(
            "white_deg_per_sqrt_h = 0.15",
            "dwell_s = 60\nsample_rate_hz = 1000",
        ),
    )
    .unwrap();
    assert!(noisy.noise[0].is_none() && noisy.noise[1].is_some());
    assert!(noisy.timing.is_some());
    assert_eq!(noisy.turntable, plain.turntable);
    assert_eq!(noisy.sensor, plain.sensor);
    assert_eq!(noisy.site, plain.site);
    assert_eq!(noisy.reading, plain.reading);
    assert_eq!(noisy.delta_r_kind, plain.delta_r_kind);
    assert_eq!(noisy.positions_deg, plain.positions_deg);
    assert_eq!(noisy.schedule(), plain.schedule());
    assert_eq!(noisy.requirement, plain.requirement);
    assert_eq!(noisy.lower_bounds_rad, plain.lower_bounds_rad);
    assert_eq!(noisy.monte_carlo, plain.monte_carlo);
}

/// The IMU example carries the STIM300's datasheet noise (gyro ARW 0.15 deg/sqrt(h) = 9
/// (deg/h)/sqrt(Hz), bias instability 0.5 deg/h; accelerometer VRW 0.07 (m/s)/sqrt(h) =
/// 0.07/(60 * 9.80665e-3) mg/sqrt(Hz), bias instability 0.05 mg; correlation 1 h) and a 24 x
/// 60 s timing at 1000 Hz with 10 s moves. Through calib-lsq the gyro biases get the issue's
/// white-noise figure 9/sqrt(24 * 60) deg/h.
#[test]
fn imu_example_has_the_stim300_noise_and_a_timing() {
    let s = Study::parse("imu-triad-example.toml", IMU).unwrap();
    let t = s.timing.as_ref().unwrap();
    assert_eq!(t.dwell_s(), [60.0; 24]);
    assert_eq!((t.sample_rate_hz(), t.move_s()), (1000.0, 10.0));
    for (o, n) in s.sensor.outputs().iter().zip(&s.noise) {
        let n = n.as_ref().unwrap();
        let gm = n.bias().unwrap();
        assert_eq!(gm.correlation_s().to_bits(), 3600f64.to_bits());
        let (white, b) = if o.unit == "deg_per_h" {
            (9.0, 0.5)
        } else {
            assert_eq!(o.unit, "mg");
            (0.07 / 60.0 / 9.806_65e-3, 0.05)
        };
        assert_relative_eq!(n.white_per_sqrt_hz(), white, max_relative = CONVERSION_REL);
        assert_relative_eq!(gm.bias_instability(), b, max_relative = CONVERSION_REL);
        assert_eq!(n.quantization().to_bits(), 0);
    }
    let cov = s.calibration.noise_covariances(&s.noise, t).unwrap();
    for (o, c) in s.sensor.outputs().iter().zip(&cov).take(3) {
        let c = c.as_ref().unwrap();
        assert_eq!(c.coefficients().names()[0], o.estimated_names()[0]);
        assert_relative_eq!(
            c.coefficients().white_sigma()[0],
            9.0 / (24.0_f64 * 60.0).sqrt(),
            max_relative = PRODUCT_REL
        );
    }
}

/// Each white key converts from its datasheet unit; `white_per_sqrt_hz` takes the output's
/// unit as it is.
#[test]
fn each_white_key_converts_to_the_output_unit() {
    for (line, expected) in [
        ("white_deg_per_sqrt_h = 0.15", 9.0),
        ("white_per_sqrt_hz = 2.5", 2.5),
    ] {
        assert_relative_eq!(
            noise_of(line).white_per_sqrt_hz(),
            expected,
            max_relative = CONVERSION_REL
        );
    }
    // the IMU's accelerometers (mg) take both accelerometer units
    let acc = IMU.replace(
        "white_m_per_s_per_sqrt_h = 0.07 #",
        "white_ug_per_sqrt_hz = 30 #",
    );
    let s = Study::parse("s.toml", &acc).unwrap();
    assert_relative_eq!(
        s.noise[3].as_ref().unwrap().white_per_sqrt_hz(),
        0.03,
        max_relative = CONVERSION_REL
    );
    // bias alone, quantization alone
    let n = noise_of("bias_instability = 0.002\nbias_correlation_s = 100");
    assert_eq!(n.white_per_sqrt_hz().to_bits(), 0);
    assert_relative_eq!(
        n.bias().unwrap().bias_instability(),
        0.002,
        max_relative = CONVERSION_REL
    );
    assert_eq!(
        noise_of("quantization = 0.001").quantization().to_bits(),
        0.001f64.to_bits()
    );
}

/// Bad noise values: negative, non-finite, above the limit, pairs incomplete, two white keys,
/// an empty table, an unknown key: each names the file and the key.
#[test]
fn bad_noise_is_an_error_naming_the_key() {
    let key = |k: &str| format!("s.toml: key `sensor.outputs[1].noise{k}`");
    let cases: &[(&str, &str, &str)] = &[
        (
            "white_deg_per_sqrt_h = -0.15",
            ".white_deg_per_sqrt_h",
            "must lie in [0, ",
        ),
        (
            "white_deg_per_sqrt_h = nan",
            ".white_deg_per_sqrt_h",
            "found NaN",
        ),
        (
            "white_per_sqrt_hz = inf",
            ".white_per_sqrt_hz",
            "must lie in",
        ),
        (
            "white_per_sqrt_hz = 1e7",
            ".white_per_sqrt_hz",
            "must lie in",
        ),
        ("quantization = -1", ".quantization", "must lie in [0, "),
        (
            "bias_instability = -0.5\nbias_correlation_s = 10",
            ".bias_instability",
            "must lie in",
        ),
        (
            "bias_instability = 0.5\nbias_correlation_s = 0",
            ".bias_correlation_s",
            "must lie in (0, ",
        ),
        (
            "bias_instability = 0.5\nbias_correlation_s = -inf",
            ".bias_correlation_s",
            "must lie in",
        ),
        (
            "rate_random_walk = -0.005",
            ".rate_random_walk",
            "must lie in [0, ",
        ),
        ("rate_random_walk = nan", ".rate_random_walk", "found NaN"),
        ("rate_random_walk = 1e7", ".rate_random_walk", "must lie in"),
        ("rate_ramp = -inf", ".rate_ramp", "must lie in"),
        ("rate_ramp = 2e6", ".rate_ramp", "must lie in"),
        (
            "flicker_bias_instability = -0.5",
            ".flicker_bias_instability",
            "must lie in [0, ",
        ),
        (
            "flicker_bias_instability = nan",
            ".flicker_bias_instability",
            "found NaN",
        ),
        (
            "angle_quantization = inf",
            ".angle_quantization",
            "must lie in",
        ),
        (
            "angle_quantization = -1",
            ".angle_quantization",
            "must lie in",
        ),
        ("bias_instability = 0.5", ".bias_correlation_s", "missing"),
        ("bias_correlation_s = 10", ".bias_instability", "missing"),
        (
            "white_deg_per_sqrt_h = 0.15\nwhite_per_sqrt_hz = 9",
            "",
            "white_deg_per_sqrt_h, white_per_sqrt_hz",
        ),
        ("", "", "an empty noise table"),
    ];
    for &(lines, k, reason) in cases {
        let text = if lines.is_empty() {
            PAPER.replace(
                "\n# Multiposition calibration (eq 2-14).\n[calibration]\n",
                "\n[sensor.outputs.noise]\n\n[calibration]\n",
            )
        } else {
            paper_with(lines, "")
        };
        let e = err(&text);
        assert!(
            e.starts_with(&key(k)) && e.contains(reason),
            "{lines:?}: {e}"
        );
    }
    // an unknown key: the TOML error locates it
    let e = err(&paper_with("white_noise = 1", ""));
    assert!(e.starts_with("s.toml:") && e.contains("white_noise"), "{e}");
}

/// A density of one family for an output of the other exits with an error naming the key and
/// the output's unit (both ways); a datasheet unit for an output whose unit we cannot convert
/// to names both too, while `white_per_sqrt_hz` takes any unit.
#[test]
fn density_of_the_wrong_family_names_the_key_and_the_unit() {
    let e = err(&paper_with("white_ug_per_sqrt_hz = 30", ""));
    assert!(
        e.starts_with("s.toml: key `sensor.outputs[1].noise.white_ug_per_sqrt_hz`")
            && e.contains("\"deg_per_h\"")
            && e.contains("a specific force")
            && e.contains("an angular rate"),
        "{e}"
    );
    let gyro_on_acc = IMU.replace(
        "white_m_per_s_per_sqrt_h = 0.07 #",
        "white_deg_per_sqrt_h = 0.15 #",
    );
    let e = err(&gyro_on_acc);
    assert!(
        e.starts_with("s.toml: key `sensor.outputs[3].noise.white_deg_per_sqrt_h`")
            && e.contains("\"mg\""),
        "{e}"
    );
    let counts = paper_with("white_deg_per_sqrt_h = 0.15", "").replacen(
        "unit = \"deg_per_h\"\naccuracy = 0.01   # omega_m (§2.3, §4.3)",
        "unit = \"counts\"\naccuracy = 0.01",
        1,
    );
    assert!(counts.contains("\"counts\""));
    let e = err(&counts);
    assert!(
        e.starts_with("s.toml: key `sensor.outputs[1].noise.white_deg_per_sqrt_h`")
            && e.contains("\"counts\"")
            && e.contains("white_per_sqrt_hz"),
        "{e}"
    );
    let counts_ok = counts.replace("white_deg_per_sqrt_h = 0.15", "white_per_sqrt_hz = 3");
    assert!(Study::parse("s.toml", &counts_ok).is_ok());
}

/// Timing: one dwell or one per position; bad values, lengths, types and a dwell shorter than
/// a sample are errors naming the key.
#[test]
fn bad_timing_is_an_error_naming_the_key() {
    let list: Vec<String> = (0..32).map(|i| format!("{}", 30 + i)).collect();
    let s = Study::parse(
        "s.toml",
        &paper_with(
            "",
            &format!(
                "dwell_s = [{}]\nsample_rate_hz = 100\nmove_s = 5",
                list.join(", ")
            ),
        ),
    )
    .unwrap();
    let t = s.timing.unwrap();
    assert_eq!(t.dwell_s()[31].to_bits(), 61f64.to_bits());
    assert_eq!(t.move_s().to_bits(), 5f64.to_bits());
    let s = Study::parse(
        "s.toml",
        &paper_with("", "dwell_s = 60\nsample_rate_hz = 100"),
    )
    .unwrap();
    assert_eq!(s.timing.unwrap().move_s().to_bits(), 0); // move_s defaults to 0

    let key = |k: &str| format!("s.toml: key `calibration.timing.{k}`");
    let mut bad_list = list.clone();
    bad_list[3] = "-1".into();
    let cases: Vec<(String, String, &str)> = vec![
        (
            "dwell_s = -60\nsample_rate_hz = 100".into(),
            key("dwell_s"),
            "must lie in (0, ",
        ),
        (
            "dwell_s = 0\nsample_rate_hz = 100".into(),
            key("dwell_s"),
            "must lie in (0, ",
        ),
        (
            "dwell_s = nan\nsample_rate_hz = 100".into(),
            key("dwell_s"),
            "found NaN",
        ),
        (
            "dwell_s = 1e6\nsample_rate_hz = 100".into(),
            key("dwell_s"),
            "must lie in",
        ),
        (
            "dwell_s = \"60\"\nsample_rate_hz = 100".into(),
            key("dwell_s"),
            "found a string",
        ),
        (
            "dwell_s = [60, 60]\nsample_rate_hz = 100".into(),
            key("dwell_s"),
            "32 positions, found 2 values",
        ),
        (
            format!("dwell_s = [{}]\nsample_rate_hz = 100", bad_list.join(", ")),
            key("dwell_s[3]"),
            "must lie in",
        ),
        (
            "dwell_s = 60\nsample_rate_hz = 0".into(),
            key("sample_rate_hz"),
            "must lie in (0, ",
        ),
        (
            "dwell_s = 60\nsample_rate_hz = -inf".into(),
            key("sample_rate_hz"),
            "must lie in",
        ),
        (
            "dwell_s = 60\nsample_rate_hz = 1e7".into(),
            key("sample_rate_hz"),
            "must lie in",
        ),
        (
            "dwell_s = 60\nsample_rate_hz = 100\nmove_s = -1".into(),
            key("move_s"),
            "must lie in [0, ",
        ),
        (
            "dwell_s = 60\nsample_rate_hz = 100\nmove_s = nan".into(),
            key("move_s"),
            "found NaN",
        ),
        (
            "dwell_s = 0.5\nsample_rate_hz = 1".into(),
            key("dwell_s"),
            "less than one sample",
        ),
    ];
    for (lines, k, reason) in cases {
        let e = err(&paper_with("", &lines));
        assert!(e.starts_with(&k) && e.contains(reason), "{lines:?}: {e}");
    }
    let e = err(&paper_with("", "dwell_s = 60"));
    assert!(
        e.starts_with("s.toml:") && e.contains("sample_rate_hz"),
        "{e}"
    );
    let e = err(&paper_with(
        "",
        "dwell_s = 60\nsample_rate_hz = 100\nsettle_s = 1",
    ));
    assert!(e.starts_with("s.toml:") && e.contains("settle_s"), "{e}");
}

/// Other positions: one dwell for all carries over to any count; a per-position list only to
/// as many positions, and a study written with other positions refuses a list that no longer
/// fits (naming the key) rather than writing a file that would not parse.
#[test]
fn per_position_dwell_does_not_carry_over_to_another_count() {
    let fewer: Vec<Vec<f64>> = Study::parse("s.toml", PAPER).unwrap().positions_deg[..24].to_vec();
    let uniform = Study::parse(
        "s.toml",
        &paper_with("", "dwell_s = 60\nsample_rate_hz = 100"),
    )
    .unwrap();
    let moved = uniform.with_positions_deg(fewer.clone()).unwrap();
    assert_eq!(moved.timing.unwrap().dwell_s(), [60.0; 24]);
    assert!(uniform.text_with_positions(&fewer, "designed").is_ok());

    let list: Vec<String> = (0..32).map(|_| "60".to_string()).collect();
    let listed = Study::parse(
        "s.toml",
        &paper_with(
            "",
            &format!("dwell_s = [{}]\nsample_rate_hz = 100", list.join(", ")),
        ),
    )
    .unwrap();
    // equal values carry over; other values do not
    assert!(listed.with_positions_deg(fewer.clone()).is_ok());
    let e = listed
        .text_with_positions(&fewer, "designed")
        .unwrap_err()
        .to_string();
    assert!(
        e.starts_with("s.toml: key `calibration.timing.dwell_s`"),
        "{e}"
    );
    let varied: Vec<String> = (0..32).map(|i| format!("{}", 30 + i)).collect();
    let varied = Study::parse(
        "s.toml",
        &paper_with(
            "",
            &format!("dwell_s = [{}]\nsample_rate_hz = 100", varied.join(", ")),
        ),
    )
    .unwrap();
    let e = varied.with_positions_deg(fewer).unwrap_err().to_string();
    assert!(
        e.starts_with("s.toml: key `calibration.timing.dwell_s`"),
        "{e}"
    );
}

/// A study written with other positions and a chosen dwell (`text_with_dwell`, as
/// `design-schedule --time-budget-s --write-study` writes it) parses back to exactly those
/// positions and that dwell at every position (one number replaces a per-position list of
/// any length), keeps the comment beside the dwell and every other timing value, and a dwell
/// outside its range or a study without timing is refused naming the key.
#[test]
fn text_with_dwell_parses_back_to_the_same_positions_and_dwell() {
    let fewer: Vec<Vec<f64>> = Study::parse("s.toml", PAPER).unwrap().positions_deg[..24]
        .iter()
        .rev()
        .cloned()
        .collect();
    // a dwell that is not a round number: it must come back bit for bit
    let dwell = 1_234.567_890_123_4_f64;
    let list: Vec<String> = (0..32).map(|i| format!("{}", 30 + i)).collect();
    for timing in [
        "dwell_s = 600 # ten minutes\nsample_rate_hz = 100\nmove_s = 60".to_string(),
        format!(
            "dwell_s = [{}] # per position\nsample_rate_hz = 100\nmove_s = 60",
            list.join(", ")
        ),
    ] {
        let s = Study::parse("s.toml", &paper_with("", &timing)).unwrap();
        let text = s.text_with_dwell(&fewer, dwell, "chosen by test").unwrap();
        assert!(text.contains("# chosen by test\npositions_deg"), "{text}");
        assert!(text.contains("# Table 1, D(x)_xy"));
        let back = Study::parse("s.toml", &text).unwrap();
        assert_eq!(back.positions_deg, fewer);
        let t = back.timing.expect("the timing is kept");
        assert_eq!(t.dwell_s(), vec![dwell; fewer.len()].as_slice());
        assert_eq!(t.sample_rate_hz().to_bits(), 100.0_f64.to_bits());
        assert_eq!(t.move_s().to_bits(), 60.0_f64.to_bits());
        assert_eq!(back.sensor, s.sensor);
    }
    let s = Study::parse(
        "s.toml",
        &paper_with("", "dwell_s = 600 # ten minutes\nsample_rate_hz = 100"),
    )
    .unwrap();
    let text = s.text_with_dwell(&fewer, dwell, "chosen").unwrap();
    assert!(
        text.contains("dwell_s = 1234.5678901234 # ten minutes"),
        "{text}"
    );
    for bad in [0.0, -1.0, f64::NAN, f64::INFINITY, 1e6] {
        let e = s.text_with_dwell(&fewer, bad, "c").unwrap_err().to_string();
        assert!(
            e.starts_with("s.toml: key `calibration.timing.dwell_s`"),
            "{bad}: {e}"
        );
    }
    let plain = Study::parse("s.toml", PAPER).unwrap();
    let e = plain
        .text_with_dwell(&fewer, dwell, "c")
        .unwrap_err()
        .to_string();
    assert!(e.starts_with("s.toml: key `calibration.timing`"), "{e}");
}

/// `rate_random_walk` (output unit per sqrt(s)) and `rate_ramp` (output unit per s) reach the
/// noise model unconverted, alone (a table with only a drift is not empty) or beside the
/// other terms, and absent they are zero.
#[test]
fn rate_random_walk_and_ramp_keys_reach_the_noise_model() {
    let n = noise_of("white_deg_per_sqrt_h = 0.15\nrate_random_walk = 0.005\nrate_ramp = 1e-4");
    assert_relative_eq!(n.white_per_sqrt_hz(), 9.0, max_relative = CONVERSION_REL);
    assert_eq!(n.rate_random_walk().to_bits(), 0.005f64.to_bits());
    assert_eq!(n.rate_ramp().to_bits(), 1e-4f64.to_bits());
    let alone = noise_of("rate_random_walk = 0.005");
    assert_eq!(alone.white_per_sqrt_hz().to_bits(), 0);
    assert_eq!(alone.rate_random_walk().to_bits(), 0.005f64.to_bits());
    let none = noise_of("white_deg_per_sqrt_h = 0.15");
    assert_eq!(
        (
            none.rate_random_walk().to_bits(),
            none.rate_ramp().to_bits()
        ),
        (0, 0)
    );
}

/// `flicker_bias_instability` (output unit) and `angle_quantization` (output unit times s)
/// reach the noise model unconverted, alone (a table with only one of them is not empty) or
/// beside the other terms, and absent they are zero.
#[test]
fn flicker_and_angle_quantization_keys_reach_the_noise_model() {
    let n = noise_of(
        "white_deg_per_sqrt_h = 0.15\nflicker_bias_instability = 0.5\nangle_quantization = 0.01",
    );
    assert_relative_eq!(n.white_per_sqrt_hz(), 9.0, max_relative = CONVERSION_REL);
    assert_eq!(n.flicker().to_bits(), 0.5f64.to_bits());
    assert_eq!(n.angle_quantization().to_bits(), 0.01f64.to_bits());
    assert_eq!(
        noise_of("flicker_bias_instability = 0.5")
            .flicker()
            .to_bits(),
        0.5f64.to_bits()
    );
    assert_eq!(
        noise_of("angle_quantization = 0.01")
            .angle_quantization()
            .to_bits(),
        0.01f64.to_bits()
    );
    let none = noise_of("white_deg_per_sqrt_h = 0.15");
    assert_eq!(
        (
            none.flicker().to_bits(),
            none.angle_quantization().to_bits()
        ),
        (0, 0)
    );
}

/// `[sensor.outputs.noise.uncertainty]`: each standard uncertainty under its term's key and
/// unit, converted as the term (0.01 deg/sqrt(h) is 0.6 (deg/h)/sqrt(Hz); a bias
/// instability's is the Gauss-Markov sigma's times 1.0760); an uncertainty of a term the
/// table does not give, or a negative one, is an error naming the key.
#[test]
fn noise_uncertainties_reach_the_model_converted_as_their_terms() {
    use gw_model::noise::{
        FLICKER_FLOOR_PER_BIAS_INSTABILITY, GM_ADEV_PEAK_PER_SIGMA, NoiseParameter as P,
    };
    let n = noise_of(
        "white_deg_per_sqrt_h = 0.15\nbias_instability = 0.5\nbias_correlation_s = 60\nflicker_bias_instability = 0.2\n[sensor.outputs.noise.uncertainty]\nwhite_deg_per_sqrt_h = 0.01\nbias_instability = 0.1\nbias_correlation_s = 20\nflicker_bias_instability = 0.05",
    );
    assert_relative_eq!(n.uncertainty(P::White), 0.6, max_relative = CONVERSION_REL);
    assert_relative_eq!(
        n.uncertainty(P::BiasSigma),
        0.1 * FLICKER_FLOOR_PER_BIAS_INSTABILITY / GM_ADEV_PEAK_PER_SIGMA,
        max_relative = CONVERSION_REL
    );
    assert_eq!(n.uncertainty(P::BiasCorrelation).to_bits(), 20f64.to_bits());
    assert_eq!(n.uncertainty(P::Flicker).to_bits(), 0.05f64.to_bits());
    assert_eq!(n.uncertainty(P::RateRamp).to_bits(), 0);
    for (lines, k, reason) in [
        (
            "white_deg_per_sqrt_h = 0.15\n[sensor.outputs.noise.uncertainty]\nrate_ramp = 1e-4",
            ".uncertainty.rate_ramp",
            "does not give",
        ),
        (
            "white_deg_per_sqrt_h = 0.15\n[sensor.outputs.noise.uncertainty]\nwhite_deg_per_sqrt_h = -0.01",
            ".uncertainty.white_deg_per_sqrt_h",
            "must lie in [0, ",
        ),
    ] {
        let e = err(&paper_with(lines, ""));
        assert!(
            e.contains(&format!("noise{k}")) && e.contains(reason),
            "{lines:?}: {e}"
        );
    }
}
