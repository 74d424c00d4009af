//! `[[calibration.rate_steps]]`, `turntable.max_rate_deg_per_s` and `sensor.lever_arm_m`:
//! accepted when valid, refused naming the key otherwise (issue 23).

use std::path::Path;
use study::Study;

fn example() -> String {
    std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../studies/tactical-rate-table-example.toml"),
    )
    .expect("the example study")
}

/// The example with the first rate step's `key = value` line replaced.
fn with_first_step(key: &str, value: &str) -> String {
    let text = example();
    let start = text
        .find("[[calibration.rate_steps]]")
        .expect("a rate step");
    let line_start = start + text[start..].find(&format!("\n{key} = ")).expect("the key") + 1;
    let line_end = line_start + text[line_start..].find('\n').expect("a line");
    format!(
        "{}{key} = {value}{}",
        &text[..line_start],
        &text[line_end..]
    )
}

fn refused(text: &str) -> String {
    match Study::parse("s.toml", text) {
        Ok(_) => panic!("accepted"),
        Err(e) => e.to_string(),
    }
}

#[test]
fn example_with_rate_steps_is_read() {
    let s = Study::parse("s.toml", &example()).expect("valid");
    assert_eq!(s.rate_steps.len(), 6);
    assert_eq!(s.schedule().len(), 24 + 6);
    assert!(s.schedule().has_rate_steps());
    // read as written: the same decimal literal parses to the same double
    for (got, want) in s.lever_arm_m.iter().zip([0.02, -0.01, 0.05]) {
        approx::assert_relative_eq!(*got, want, max_relative = f64::EPSILON);
    }
}

#[test]
fn zero_rate_is_refused_naming_the_key() {
    let msg = refused(&with_first_step("rate_deg_per_s", "0.0"));
    assert!(
        msg.contains("calibration.rate_steps[0].rate_deg_per_s"),
        "{msg}"
    );
}

#[test]
fn rate_above_the_joints_limit_is_refused_naming_the_key() {
    let msg = refused(&with_first_step("rate_deg_per_s", "-300.5"));
    assert!(
        msg.contains("calibration.rate_steps[0].rate_deg_per_s"),
        "{msg}"
    );
    assert!(msg.contains("300"), "{msg}");
}

#[test]
fn rate_step_on_a_joint_that_does_not_exist_is_refused_naming_the_key() {
    let msg = refused(&with_first_step("joint", "\"phi_x\""));
    assert!(msg.contains("calibration.rate_steps[0].joint"), "{msg}");
}

/// With a `[calibration.timing]` a rate step may leave out `revolutions`: it turns the fewest
/// whole revolutions lasting at least the longest static dwell, and that turning time is its
/// averaging window after the static positions (the shipped STIM300 rate-table example: 84
/// revolutions at 100 deg/s for a 300 s dwell, 302.4 s).
#[test]
fn rate_steps_without_revolutions_turn_at_least_the_static_dwell() {
    let text = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../studies/stim300-rate-table-example.toml"),
    )
    .expect("the example study");
    let s = Study::parse("s.toml", &text).expect("valid");
    let t = s.timing.as_ref().expect("a timing");
    assert_eq!((t.positions(), t.len()), (24, 30));
    for (step, &w) in s.rate_steps.iter().zip(t.rate_step_s()) {
        assert_eq!(step.revolutions, 84);
        assert_eq!(w.to_bits(), step.duration_s().to_bits());
        assert!((w - 302.4).abs() < 1e-9, "{w}");
    }
    // a dwell of exactly whole turns is those turns; never below one
    assert_eq!(study::default_revolutions(100.0, 36.0), 10);
    assert_eq!(study::default_revolutions(-100.0, 36.1), 11);
    assert_eq!(study::default_revolutions(600.0, 0.01), 1);
}

/// Without a timing the revolutions are required (nothing sets them); a rate step shorter than
/// one sample is refused naming its revolutions.
#[test]
fn missing_revolutions_without_timing_and_a_step_shorter_than_a_sample_are_refused() {
    let text = example();
    let line = "\nrevolutions = 10\n";
    let start = text.find(line).expect("revolutions");
    let without = format!("{}\n{}", &text[..start], &text[start + line.len()..]);
    let msg = refused(&without);
    assert!(
        msg.contains("calibration.rate_steps[0].revolutions"),
        "{msg}"
    );
    assert!(msg.contains("missing"), "{msg}");
    // one revolution at 60 deg/s is 6 s: at 0.1 Hz no sample
    let one_rev = with_first_step("revolutions", "1");
    let timed = format!(
        "{}\n[calibration.timing]\ndwell_s = 20\nsample_rate_hz = 0.1\n",
        &one_rev[..one_rev.find("[monte_carlo]").expect("monte_carlo")]
    ) + &one_rev[one_rev.find("[monte_carlo]").expect("monte_carlo")..];
    let msg = refused(&timed);
    assert!(
        msg.contains("calibration.rate_steps[0].revolutions"),
        "{msg}"
    );
    assert!(msg.contains("less than one sample"), "{msg}");
}

#[test]
fn non_whole_revolutions_are_refused_naming_the_key() {
    for bad in ["2.5", "0", "-1"] {
        let msg = refused(&with_first_step("revolutions", bad));
        assert!(
            msg.contains("calibration.rate_steps[0].revolutions"),
            "{bad}: {msg}"
        );
    }
}

#[test]
fn rate_step_without_a_rate_limit_and_a_bad_lever_arm_are_refused() {
    let text = example().replace(
        "max_rate_deg_per_s = { phi_o = 300.0, phi_m = 300.0, phi_i = 600.0 }",
        "max_rate_deg_per_s = { phi_m = 300.0, phi_i = 600.0 }",
    );
    let msg = refused(&text);
    assert!(msg.contains("calibration.rate_steps[0].joint"), "{msg}");
    assert!(msg.contains("turntable.max_rate_deg_per_s.phi_o"), "{msg}");
    let text = example().replace(
        "lever_arm_m = [0.02, -0.01, 0.05]",
        "lever_arm_m = [0.02, 11.0, 0.05]",
    );
    let msg = refused(&text);
    assert!(msg.contains("sensor.lever_arm_m[1]"), "{msg}");
    let text = example().replace("phi_o = 300.0, phi_m", "phi_o = -1.0, phi_m");
    let msg = refused(&text);
    assert!(msg.contains("turntable.max_rate_deg_per_s.phi_o"), "{msg}");
}
