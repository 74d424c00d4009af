//! `cargo xtask reproduce-paper` on the paper's study: every output exists and parses, and
//! results.json equals what the library crates compute; bad study files exit 2 naming the
//! file and key, and leave no output behind.

use alloc_opt::{AllocationProblem, Allocator, SensitivityWeighted};
use approx::assert_relative_eq;
use calib_lsq::RequirementProblem;
use mc_verify::{ErrorBox, McConfig, MonteCarlo};
use serde_json::Value;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use tt_kinematics::ErrorComponent;

/// The report prints library values through serde_json (shortest round-trip), so equality
/// holds to the last bit; allow a few ulps for unit conversions done on either side.
const SAME_VALUE_REL: f64 = 1e-12;

fn study_path() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../studies/gyrowheel-2017.toml")
}

fn run(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_xtask"))
        .arg("reproduce-paper")
        .args(args)
        .output()
        .expect("run xtask")
}

const OUTPUTS: [&str; 10] = [
    "report.md",
    "report.html",
    "figure_4_rate_error.svg",
    "figure_5_requirement.svg",
    "figure_8_sensitivities.svg",
    "figure_9_orientation_error.svg",
    "figure_e2e_rate_error.svg",
    "table_1.csv",
    "table_4.csv",
    "results.json",
];

#[test]
fn reproduce_paper_writes_every_output_and_agrees_with_the_library() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("paper");
    let o = run(&[
        "--out",
        out.to_str().unwrap(),
        "--samples",
        "20000",
        "--seed",
        "7",
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    for f in OUTPUTS {
        let text = std::fs::read_to_string(out.join(f)).unwrap_or_else(|e| panic!("{f}: {e}"));
        assert!(!text.is_empty(), "{f} is empty");
        if f.ends_with(".svg") {
            assert!(
                text.contains("<svg") && text.trim_end().ends_with("</svg>"),
                "{f} is not SVG"
            );
        }
    }
    let html = std::fs::read_to_string(out.join("report.html")).unwrap();
    assert_eq!(
        html.matches("<figure><svg").count(),
        5,
        "figures inline in the HTML"
    );
    // No temporary directory left behind.
    let leftovers: Vec<_> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert_eq!(leftovers.len(), 1, "{leftovers:?}");

    let r: Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("results.json")).unwrap()).unwrap();
    assert_eq!(r["seed"], 7);
    assert!(
        r["study"]
            .as_str()
            .unwrap()
            .ends_with("gyrowheel-2017.toml")
    );

    // Eq 16: equals calib-lsq on the paper's inputs.
    let req = RequirementProblem::paper().requirement().unwrap().deg();
    for (k, name) in ["psi", "theta", "gamma"].iter().enumerate() {
        assert_relative_eq!(
            r["orientation_requirement_deg"][name].as_f64().unwrap(),
            req[k],
            max_relative = SAME_VALUE_REL
        );
    }
    // Table 4 (ours): equals alloc-opt on the paper's example.
    let a = SensitivityWeighted::paper()
        .allocate(&AllocationProblem::paper_example().unwrap())
        .unwrap();
    let ub = a.upper_bounds_arcmin();
    for c in ErrorComponent::ALL {
        assert_relative_eq!(
            r["allocation_arcmin"][c.name()].as_f64().unwrap(),
            ub[c.index()],
            max_relative = SAME_VALUE_REL
        );
    }
    // Figure 9: equals mc-verify with the same seed, samples and bounds.
    let mut config = McConfig::new(20_000, 7);
    config.requirement_rad = [0.027_f64.to_radians(); 3];
    let mc = MonteCarlo::new(
        ErrorBox::new([0.0; 8], alloc_opt::paper_table4_rad()).unwrap(),
        config,
    )
    .unwrap()
    .run();
    assert_eq!(r["monte_carlo"]["samples"], 20_000);
    let m = mc.max_abs_rad();
    for (k, name) in ["psi", "theta", "gamma"].iter().enumerate() {
        assert_relative_eq!(
            r["monte_carlo"]["max_abs_deg"][name].as_f64().unwrap(),
            m[k].to_degrees(),
            max_relative = SAME_VALUE_REL
        );
    }
    assert_relative_eq!(
        r["monte_carlo"]["within_requirement_fraction"]
            .as_f64()
            .unwrap(),
        mc.within_requirement_fraction(),
        max_relative = SAME_VALUE_REL
    );

    // Claims: the required rows are there, each with a test name; only Table 4 fails.
    let claims = r["claims"].as_array().unwrap();
    for id in [
        "fig4-1",
        "fig4-2",
        "fig4-3",
        "eq16",
        "eq25-deta",
        "eq26",
        "fig8",
        "lemma1",
        "table4",
        "fig9",
        "conclusion1",
        "conclusion2",
        "e2e",
    ] {
        let c = claims
            .iter()
            .find(|c| c["id"] == id)
            .unwrap_or_else(|| panic!("claim {id} missing"));
        assert!(
            c["test"].as_str().unwrap().contains("::"),
            "{id} names no test"
        );
        assert_eq!(c["holds"].as_bool().unwrap(), id != "table4", "claim {id}");
    }
    // End to end: equals e2e-verify with the same samples and seed.
    let e2e = e2e_verify::answer(&e2e_verify::EndToEndInputs {
        samples: 20_000,
        seed: 7,
        ..e2e_verify::EndToEndInputs::paper()
    })
    .unwrap();
    for (key, ans) in [
        ("study_reading", &e2e.readings[0]),
        ("user_reading", &e2e.readings[1]),
    ] {
        let got = &r["end_to_end"][key]["table4"];
        let [x, y] = ans.table4.worst_case.exact_deg_per_h();
        assert_relative_eq!(
            got["worst_case_deg_per_h"]["x"].as_f64().unwrap(),
            x,
            max_relative = SAME_VALUE_REL
        );
        assert_relative_eq!(
            got["worst_case_deg_per_h"]["y"].as_f64().unwrap(),
            y,
            max_relative = SAME_VALUE_REL
        );
        assert_relative_eq!(
            got["yield"].as_f64().unwrap(),
            ans.table4.distribution.yield_fraction(),
            max_relative = SAME_VALUE_REL
        );
    }
    // table_4.csv: the paper's values beside ours.
    let t4 = std::fs::read_to_string(out.join("table_4.csv")).unwrap();
    assert!(t4.starts_with("component,paper_table4_arcmin,ours_arcmin"));
    assert!(t4.contains("dalpha_x2,0.2825,"));
}

/// The study with another `positions_deg` array.
fn with_positions(study: &str, positions: &str) -> String {
    let start = study.find("positions_deg = [").expect("positions key");
    let end = start + study[start..].find("]\n").expect("end of array") + 2;
    format!(
        "{}positions_deg = [{positions}]\n{}",
        &study[..start],
        &study[end..]
    )
}

#[test]
fn bad_study_files_exit_2_naming_file_and_key_and_write_nothing() {
    let good = std::fs::read_to_string(study_path()).unwrap();
    let cases = [
        (
            good.replacen(
                "latitude_deg = 45.75",
                "latitude_deg = 45.75\nlongitude_deg = 126.6",
                1,
            ),
            "longitude_deg",
        ),
        (
            good.replacen("latitude_deg = 45.75", "latitude_rad = 0.798", 1),
            "latitude_rad",
        ),
        (good.replacen("seed = 2017", "", 1), "seed"),
        (
            good.replacen("latitude_deg = 45.75", "latitude_deg = \"45.75\"", 1),
            "latitude_deg",
        ),
        (
            good.replacen(
                "rate_accuracy_deg_per_h = 0.01",
                "rate_accuracy_deg_per_h = nan",
                1,
            ),
            "calibration.rate_accuracy_deg_per_h",
        ),
        (
            good.replacen(
                "d_x_deg_per_h_per_g = -43.2",
                "d_x_deg_per_h_per_g = inf",
                1,
            ),
            "sensor.x_axis.d_x_deg_per_h_per_g",
        ),
        (
            good.replacen("dalpha_x2 = 0.0", "dalpha_x2 = -0.1", 1),
            "allocation.lower_bounds_arcmin.dalpha_x2",
        ),
        (
            good.replacen("samples = 10000", "samples = 0", 1),
            "monte_carlo.samples",
        ),
        (
            good.replacen(
                "reading = \"intended/beta1/printed\"",
                "reading = \"sideways\"",
                1,
            ),
            "calibration.reading",
        ),
        (
            with_positions(
                &good,
                "[0, 0], [0, 90], [0, 180], [0, 270], [90, 0], [90, 90], [90, 180], [90, 270], [180, 0], [180, 90], [180, 180], [180, 270], [270, 0], [270, 90], [270, 180], [270, 270]",
            ),
            "D(x)_xy",
        ),
    ];
    let dir = tempfile::tempdir().unwrap();
    for (k, (text, key)) in cases.iter().enumerate() {
        assert_ne!(text, &good, "case {k} did not change the study");
        let path = dir.path().join(format!("study-{k}.toml"));
        std::fs::write(&path, text).unwrap();
        let out = dir.path().join(format!("out-{k}"));
        let o = run(&[
            "--study",
            path.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ]);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "case {k} ({key}): {err}");
        assert!(
            err.contains(&format!("study-{k}.toml")),
            "case {k}: {err} should name the file"
        );
        assert!(err.contains(key), "case {k}: {err} should name {key}");
        assert!(!out.exists(), "case {k} wrote output");
    }
    let o = run(&[
        "--samples",
        "0",
        "--out",
        dir.path().join("zero").to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2));
}
