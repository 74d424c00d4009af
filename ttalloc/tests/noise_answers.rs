//! Both error sources in the commands' answers (issue 21): the table's part, the noise's and
//! their combination per output, the verdict counting both, and a study without noise
//! answered exactly as before.

mod common;

use approx::assert_relative_eq;
use common::{
    assert_input_error, check_turntable, end_to_end_json, json, num, report_args, run, scratch,
    stdout, write,
};
use serde_json::Value;

/// JSON keeps full precision; the sum is one rounding (relative).
const SUM_REL: f64 = 1e-12;

const TOL: &str = "studies/tolerances/three-axis-navigation-grade.toml";

/// The IMU example without its noise blocks.
fn imu_without_noise() -> String {
    let t = common::study_text("imu-triad-example");
    let mut out = Vec::new();
    let mut skipping = false;
    for line in t.lines() {
        if line.trim() == "[sensor.outputs.noise]" {
            skipping = true;
            continue;
        }
        if skipping && line.trim_start().starts_with('[') {
            skipping = false;
        }
        if !skipping {
            out.push(line);
        }
    }
    out.join("\n") + "\n"
}

/// The keys the noise adds, removed; `table_verdict` put back as `verdict`.
fn strip_noise(v: &mut Value) {
    if let Value::Object(m) = v {
        if let Some(t) = m.remove("table_verdict") {
            m.insert("verdict".into(), t);
        }
        for k in [
            "k_sigma",
            "combined_yield",
            "table_part",
            "table_certified",
            "noise_sigma",
            "combined",
            "combined_meets",
            "dominant",
        ] {
            m.remove(k);
        }
        for (_, x) in m.iter_mut() {
            strip_noise(x);
        }
    } else if let Value::Array(a) = v {
        a.iter_mut().for_each(strip_noise);
    }
}

#[test]
fn check_turntable_splits_every_output_into_table_and_noise() {
    let v = json(&check_turntable(
        "studies/imu-triad-example.toml",
        TOL,
        "2000",
        &["--json"],
    ));
    for o in v["outputs"].as_array().unwrap() {
        let (t, s, c) = (
            num(&o["table_part"]),
            num(&o["noise_sigma"]),
            num(&o["combined"]),
        );
        assert_relative_eq!(c, t + 3.0 * s, max_relative = SUM_REL);
        assert!(s > 0.0);
        assert_eq!(o["combined_meets"], c <= num(&o["accuracy"]));
    }
    // the gyros' noise alone at 60 s exceeds 0.1 deg/h: the table is proven, the calibration not
    assert_eq!(v["table_verdict"], "guaranteed");
    assert_eq!(v["verdict"], "fails");
    assert!(num(&v["combined_yield"]["yield"]) < 0.01);
    let t = stdout(&run(&check_turntable(
        "studies/imu-triad-example.toml",
        TOL,
        "2000",
        &[],
    )));
    assert!(t.contains("with noise: table "), "{t}");
    assert!(t.contains(" at 3 sigma"), "{t}");
    assert!(
        t.contains("does NOT meet every accuracy once the noise is counted"),
        "{t}"
    );
}

#[test]
fn a_study_without_noise_answers_exactly_as_before() {
    // the same study without its noise: the JSON is the noisy one's minus the noise's keys,
    // with the table's verdict as the verdict
    let dir = scratch("noise", "without");
    let quiet = write(&dir, "imu-quiet.toml", &imu_without_noise());
    let quiet = quiet.to_str().unwrap();
    let args = |study: &'static str| -> Vec<String> {
        [
            "check-turntable",
            "--tolerances",
            TOL,
            "--samples",
            "2000",
            "--json",
            "--study",
            study,
        ]
        .iter()
        .map(|s| s.to_string())
        .collect()
    };
    let mut a = args("studies/imu-triad-example.toml");
    let mut noisy = {
        let r: Vec<&str> = a.iter().map(String::as_str).collect();
        json(&r)
    };
    a.pop();
    a.push(quiet.to_string());
    let plain = {
        let r: Vec<&str> = a.iter().map(String::as_str).collect();
        json(&r)
    };
    for key in ["table_part", "noise_sigma", "combined", "table_verdict"] {
        assert!(
            !plain.to_string().contains(&format!("\"{key}\"")),
            "no `{key}` without noise"
        );
    }
    strip_noise(&mut noisy);
    // the study's specifications are answered by budgets that count the noise where it is
    // modelled (xtask/tests/specifications.rs): compared apart from this
    let mut plain = plain;
    for v in [&mut noisy, &mut plain] {
        v.as_object_mut().unwrap().remove("decision");
    }
    assert_eq!(noisy, plain);
}

#[test]
fn k_sigma_out_of_range_exits_2_naming_the_flag() {
    for bad in ["0", "-1", "nan", "inf", "11", "x"] {
        let o = run(&[
            "check-turntable",
            "--study",
            "studies/imu-triad-example.toml",
            "--tolerances",
            TOL,
            "--k-sigma",
            bad,
        ]);
        assert_input_error(&o, &["--k-sigma"]);
    }
}

#[test]
fn a_larger_k_sigma_gives_a_larger_noise_part() {
    let get = |k: &str| {
        json(&[
            "check-turntable",
            "--study",
            "studies/imu-triad-example.toml",
            "--tolerances",
            TOL,
            "--samples",
            "500",
            "--k-sigma",
            k,
            "--json",
        ])
    };
    let (one, three) = (get("1"), get("3"));
    for (a, b) in one["outputs"]
        .as_array()
        .unwrap()
        .iter()
        .zip(three["outputs"].as_array().unwrap())
    {
        assert_relative_eq!(num(&a["noise_sigma"]), num(&b["noise_sigma"]));
        assert_relative_eq!(
            num(&b["combined"]) - num(&a["combined"]),
            2.0 * num(&a["noise_sigma"]),
            max_relative = 1e-9
        );
    }
}

/// The IMU example with white noise only (its bias-instability lines removed).
fn imu_white_only() -> String {
    common::study_text("imu-triad-example")
        .lines()
        .filter(|l| {
            let t = l.trim_start();
            !t.starts_with("bias_instability") && !t.starts_with("bias_correlation_s")
        })
        .collect::<Vec<_>>()
        .join("\n")
        + "\n"
}

#[test]
fn end_to_end_states_the_shortest_dwell_and_the_tradeoff() {
    // white noise only: sigma scales as 1/sqrt(T), so the shortest dwell is the closed form
    // T0 (3 sigma(T0) / accuracy)^2 of the output that needs the longest (no lower bounds)
    let dir = scratch("noise", "white");
    let p = write(&dir, "imu-white.toml", &imu_white_only());
    let v = end_to_end_json(p.to_str().unwrap(), "2000", &["--yield-fraction", "0.9"]);
    let noise = &v["readings"][0]["noise"];
    let sigma: Vec<f64> = noise["noise_sigma"]
        .as_array()
        .unwrap()
        .iter()
        .map(num)
        .collect();
    let acc: Vec<f64> = v["outputs"]
        .as_array()
        .unwrap()
        .iter()
        .map(|o| num(&o["accuracy"]))
        .collect();
    let expected = sigma
        .iter()
        .zip(&acc)
        .map(|(s, a)| 60.0 * (3.0 * s / a).powi(2))
        .fold(0.0, f64::max);
    // bisection to 2^-48 of the log width; JSON full precision
    assert_relative_eq!(num(&v["min_dwell_s"]), expected, max_relative = 1e-9);
    let curve = v["tradeoff"].as_array().unwrap();
    assert!(curve.len() >= 10);
    let js: Vec<f64> = curve.iter().map(|p| num(&p["objective_arcmin"])).collect();
    assert!(js.windows(2).all(|w| w[1] < w[0]), "{js:?}");
    assert!(num(&curve[0]["dwell_s"]) > num(&v["min_dwell_s"]));
    // at 60 s the gyros' noise alone exceeds 0.1 deg/h: an answer, exit 0
    assert_eq!(noise["direct_with_noise"]["no_table_suffices"], true);
    // the paper's study has no noise: none of the new keys
    let paper = json(&["end-to-end", "--samples", "2000", "--json"]);
    for key in ["min_dwell_s", "tradeoff", "k_sigma"] {
        assert!(paper.get(key).is_none(), "{key}");
    }
    assert!(paper["readings"][0].get("noise").is_none());
}

#[test]
fn end_to_end_with_bias_instability_says_no_dwell_within_a_day_suffices() {
    let v = end_to_end_json(
        "studies/imu-triad-example.toml",
        "2000",
        &["--yield-fraction", "0.9"],
    );
    assert!(v["min_dwell_s"].is_null());
    assert_eq!(v["tradeoff"], serde_json::json!([]));
    assert_eq!(
        v["readings"][0]["noise"]["direct_with_noise"]["no_table_suffices"],
        true
    );
}

#[test]
fn report_shows_the_split_and_the_tradeoff_figure_only_with_noise() {
    let dir = scratch("noise", "report");
    let out = dir.join("imu");
    let o = run(&report_args(
        "studies/imu-triad-example.toml",
        &out,
        "2000",
        &[],
    ));
    assert!(o.status.success(), "{}", common::stderr(&o));
    let md = std::fs::read_to_string(out.join("report.md")).unwrap();
    assert!(md.contains("## Noise and test time"), "noise section");
    assert!(md.contains("| box | output | table part | noise part | combined |"));
    assert!(md.contains("No table suffices at this dwell"));
    assert!(md.contains("No dwell up to 86400 s per position"));
    let svg = std::fs::read_to_string(out.join("tradeoff.svg")).unwrap();
    assert!(svg.starts_with("<svg") && svg.contains("noise part against the dwell"));
    let results: Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("results.json")).unwrap()).unwrap();
    assert!(results["noise"]["min_dwell_s"].is_null());
    assert_eq!(results["noise"]["noise_sigma"].as_array().unwrap().len(), 6);
    // the three-axis example has no noise: no section, no figure
    let plain = dir.join("three-axis");
    let o = run(&report_args(
        "studies/three-axis-example.toml",
        &plain,
        "2000",
        &[],
    ));
    assert!(o.status.success(), "{}", common::stderr(&o));
    let md = std::fs::read_to_string(plain.join("report.md")).unwrap();
    assert!(!md.contains("Noise and test time"));
    assert!(!plain.join("tradeoff.svg").exists());
}

/// The paper's study with an assumed navigation-grade white noise
/// (`studies/gyrowheel-2017-noise-assumed.toml`: 0.002 deg/sqrt(h) = 0.12 (deg/h)/sqrt(Hz) per
/// axis, 32 positions x 600 s): the noise sigma at the worst position is the closed form
/// sqrt(0.12^2 / 600 * 5/16) deg/h (5/16 the leverage x^T (A^T A)^-1 x of the worst position
/// of the 32-position schedule), the shortest dwell at which some table meets 0.01 deg/h is the
/// 405 s per position of docs/findings.md, and the paper's noiseless answers (J = 54.65 direct) stay the
/// study's noiseless J.
#[test]
fn paper_study_with_assumed_noise_needs_405_s_per_position() {
    /// JSON keeps full precision; the covariance is a few hundred roundings (relative).
    const SIGMA_REL: f64 = 1e-9;
    /// docs/findings.md states the dwell to 3 significant digits (relative).
    const README_REL: f64 = 5e-3;
    let v = end_to_end_json("studies/gyrowheel-2017-noise-assumed.toml", "2000", &[]);
    let sigma: Vec<f64> = v["readings"][0]["noise"]["noise_sigma"]
        .as_array()
        .unwrap()
        .iter()
        .map(num)
        .collect();
    let closed_form = (0.12f64.powi(2) / 600.0 * 5.0 / 16.0).sqrt();
    for s in &sigma {
        assert_relative_eq!(*s, closed_form, max_relative = SIGMA_REL);
    }
    assert_relative_eq!(num(&v["min_dwell_s"]), 405.0, max_relative = README_REL);
    assert_relative_eq!(
        num(&v["noiseless_objective_arcmin"]),
        54.65,
        max_relative = README_REL
    );
    // at the study's 600 s the noise leaves the table a sliver: a much tighter table than
    // the noiseless one, but one exists
    let d = &v["readings"][0]["noise"]["direct_with_noise"];
    assert_eq!(d["no_table_suffices"], false);
    assert!(num(&d["objective"]) > 10.0 * num(&v["noiseless_objective_arcmin"]));
    // the box it recommends is certified with the noise part kept free: it meets its own
    // combined verdict (the first-order allocation missed it by 5e-5 relative)
    for o in d["box"]["outputs"].as_array().unwrap() {
        assert_eq!(o["combined_meets"], true, "{o}");
        assert!(num(&o["combined"]) <= num(&o["accuracy"]), "{o}");
    }
}

/// A per-position dwell list is scanned as the list scaled alike (issue 32): with 31
/// positions at 600 s and one at 0.01 s no scale up to a mean of 86,400 s lets a table meet
/// (the short position reaches only 1.49 s), while one dwell of 405 s at every position does.
/// `end-to-end` says what it scanned (the factor range and each end's dwell range) in text and
/// JSON (`dwell_scan`), never "no dwell up to 86400 s", and the report says the same.
#[test]
fn a_dwell_list_is_scanned_scaled_alike_and_the_output_says_so() {
    // the scan's ends are computed from the same sums: rounding only
    const SAME_SUM_REL: f64 = 1e-9;
    let dir = scratch("noise-answers", "dwell-list");
    let text = common::study_text("gyrowheel-2017-noise-assumed");
    let mut list = vec!["600"; 31];
    list.push("0.01");
    let listed = text.replacen(
        "dwell_s = 600\n",
        &format!("dwell_s = [{}]\n", list.join(", ")),
        1,
    );
    assert_ne!(listed, text);
    let p = write(&dir, "list.toml", &listed);
    let p = p.to_str().unwrap();
    let out = stdout(&run(&["end-to-end", "--study", p, "--samples", "2000"]));
    assert!(!out.contains("no dwell up to"), "{out}");
    assert!(
        out.contains("scanned: the study's per-position dwells scaled alike by x"),
        "{out}"
    );
    let v = json(&["end-to-end", "--study", p, "--samples", "2000", "--json"]);
    let scan = &v["dwell_scan"];
    assert_eq!(scan["per_position_list"], true, "{scan}");
    let mean = (31.0 * 600.0 + 0.01) / 32.0;
    let hi = 86_400.0 / mean;
    assert_relative_eq!(
        num(&scan["scale_range"][1]),
        hi,
        max_relative = SAME_SUM_REL
    );
    assert_relative_eq!(
        num(&scan["mean_dwell_range_s"][1]),
        86_400.0,
        max_relative = SAME_SUM_REL
    );
    // the short position's range: one sample at 100 Hz to 0.01 s x 86400 / mean
    assert_relative_eq!(
        num(&scan["shortest_dwell_range_s"][0]),
        0.01,
        max_relative = 1e-6
    );
    assert_relative_eq!(
        num(&scan["shortest_dwell_range_s"][1]),
        0.01 * hi,
        max_relative = SAME_SUM_REL
    );
    assert_relative_eq!(
        num(&scan["longest_dwell_range_s"][1]),
        600.0 * hi,
        max_relative = SAME_SUM_REL
    );
    assert!(v["min_dwell_s"].is_null());
    // one dwell at every position: the dwell itself is scanned
    let uniform = end_to_end_json("studies/gyrowheel-2017-noise-assumed.toml", "2000", &[]);
    assert_eq!(uniform["dwell_scan"]["per_position_list"], false);
    let report = dir.join("report");
    let r = run(&report_args(p, &report, "2000", &[]));
    assert_eq!(r.status.code(), Some(0), "{}", common::stderr(&r));
    let md = std::fs::read_to_string(report.join("report.md")).unwrap();
    assert!(!md.contains("No dwell up to"), "the report's trade-off");
    assert!(md.contains("Scanned: the study's per-position dwells scaled alike by x"));
    let results: Value =
        serde_json::from_str(&std::fs::read_to_string(report.join("results.json")).unwrap())
            .unwrap();
    assert_eq!(results["noise"]["dwell_scan"]["per_position_list"], true);
}

/// The first number of `text` after `label`.
fn number_after(text: &str, label: &str) -> f64 {
    let at = text
        .find(label)
        .unwrap_or_else(|| panic!("no `{label}` in {text}"));
    text[at + label.len()..]
        .split(|c: char| !(c.is_ascii_digit() || c == '.' || c == 'e' || c == '-'))
        .find(|s| !s.is_empty())
        .and_then(|s| s.parse().ok())
        .unwrap_or_else(|| panic!("no number after `{label}`"))
}

/// Issue 35 item 2: the uncertainty of the noise parameters carried into the answers. The
/// gyros' white noise 0.15 +- 0.015 deg/sqrt(h) (`[sensor.outputs.noise.uncertainty]`, 10%):
/// with white noise alone sigma scales as N and the shortest dwell as N^2, so end-to-end
/// prints each gyro's noise sigma at 0.9 N and 1.1 N and the shortest dwell at the
/// optimistic and pessimistic corners 0.81 and 1.21 times the nominal one, and names white
/// noise as what the gyros depend on most (before: the uncertainty had no key).
#[test]
fn end_to_end_gives_the_answers_at_the_noise_parameters_plus_minus_one_uncertainty() {
    /// `num` prints 6 significant digits: relative.
    const PRINTED_REL: f64 = 1e-5;
    let text: String = imu_white_only()
        .lines()
        .flat_map(|l| {
            let mut v = vec![l.to_string()];
            if l.trim_start().starts_with("white_deg_per_sqrt_h") {
                v.push("[sensor.outputs.noise.uncertainty]".into());
                v.push("white_deg_per_sqrt_h = 0.015".into());
            }
            v
        })
        .collect::<Vec<_>>()
        .join("\n")
        + "\n";
    let dir = scratch("noise", "uncertainty");
    let p = write(&dir, "imu-white-u.toml", &text);
    let o = run(&[
        "end-to-end",
        "--study",
        p.to_str().unwrap(),
        "--samples",
        "2000",
        "--yield-fraction",
        "0.9",
    ]);
    assert!(o.status.success(), "{}", common::stderr(&o));
    let out = stdout(&o);
    let line = out
        .lines()
        .find(|l| {
            l.trim_start()
                .starts_with("gx white = 9 +- 0.9: noise sigma ")
        })
        .unwrap_or_else(|| panic!("no gx white line: {out}"));
    let (lo, hi) = {
        let rest = line.split("noise sigma ").nth(1).unwrap();
        let mut w = rest.split_whitespace();
        let lo: f64 = w.next().unwrap().parse().unwrap();
        assert_eq!(w.next(), Some(".."), "{line}");
        (lo, w.next().unwrap().parse::<f64>().unwrap())
    };
    assert_relative_eq!(hi / lo, 1.1 / 0.9, max_relative = PRINTED_REL);
    assert!(
        out.contains("output gx: noise sigma") && out.contains("it depends most on white"),
        "{out}"
    );
    let d = number_after(&out, "shortest dwell at which some table suffices: ");
    let opt = number_after(&out, "s at the parameters' values, ");
    let pes = number_after(&out, "s at the optimistic corner, ");
    assert_relative_eq!(opt / d, 0.81, max_relative = PRINTED_REL);
    assert_relative_eq!(pes / d, 1.21, max_relative = PRINTED_REL);
}

/// An allocation that leaves an error unbounded (the STIM300-class study's direct box gives
/// the combination dphi_o + deps_om_z, which the reading cannot see, 6.6e17 arcmin) has an
/// infinite second-order bound: the table's part with noise is then the exact chain at the
/// worst vertex, said to be not certified, never "table inf ... combined inf" (as it printed).
#[test]
fn an_unbounded_allocation_gives_a_finite_uncertified_table_part_never_inf() {
    let o = run(&[
        "end-to-end",
        "--study",
        "studies/stim300-class-example.toml",
        "--samples",
        "2000",
    ]);
    assert!(o.status.success(), "{}", common::stderr(&o));
    let out = stdout(&o);
    assert!(
        !out.split_whitespace()
            .any(|w| w.trim_matches(|c: char| !c.is_alphanumeric()) == "inf"),
        "no infinite figure reaches the text:\n{out}"
    );
    let direct = out
        .lines()
        .skip_while(|l| !l.trim_start().starts_with("direct         verdict"))
        .nth(1)
        .expect("the direct box's first output with noise");
    assert!(
        direct.contains("(not certified)") && direct.contains("(noise dominates)"),
        "{direct}"
    );
}
