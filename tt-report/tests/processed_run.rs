//! The report's section for a processed run (issue 36 item 5): computed from tt-lab's answer
//! for a simulated recording, it states the recording, every coefficient's estimate with its
//! expanded uncertainty and the plan's predicted standard uncertainty beside the observed ones,
//! each verdict with its rule, the segments; its figures show one shaded span per segment per
//! output and the residuals with the outlier band; `results.json` carries the same numbers.

use approx::assert_relative_eq;
use std::path::Path;
use tt_core::human::sig;
use tt_report::figures::{STATIC_SHADE, TURNING_SHADE};
use tt_report::{ProcessedRun, Report, ReportOptions};

/// The JSON number of a value the report states: the same `f64` (serialized exactly).
const SAME_F64: f64 = 1e-15;

fn six_face() -> study::Study {
    study::Study::load(
        &Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../calib-run/studies/imu-six-face-three-rotation.toml"),
    )
    .unwrap()
}

/// The study's run: a recording simulated with its own coefficients (50 Hz, 10 s dwells).
fn processed(s: &study::Study) -> (ProcessedRun, Vec<u8>) {
    let settings = calib_run::simulate::SimSettings::for_study(s, 50.0, 10.0, 4);
    let mut rec = Vec::new();
    calib_run::simulate::simulate_recording(s, &s.sensor, &settings, &mut rec).unwrap();
    let mut o = tt_lab::calibrate::Options::default();
    o.specs = vec![calib_run::Spec {
        coefficient: "bg_x".into(),
        limit: 100.0,
        unit: None,
    }];
    o.overview_buckets = Some(64);
    let answer = tt_lab::calibrate::calibrate(s, rec.as_slice(), "run <1>.csv", &o).unwrap();
    (
        ProcessedRun::new(answer, vec!["--recording".into(), "run <1>.csv".into()]),
        rec,
    )
}

fn report(s: &study::Study, run: ProcessedRun) -> Report {
    let mut options = ReportOptions::default();
    options.samples = Some(2_000);
    options.run = Some(run);
    Report::compute(s.clone(), options).unwrap()
}

/// `<rect>`s filled with `c`, as plotters writes them.
fn rects_filled(svg: &str, c: tt_report::figures::RGBColor) -> usize {
    let fill = format!("#{:02X}{:02X}{:02X}", c.0, c.1, c.2);
    roxmltree::Document::parse(svg)
        .expect("the figure is well-formed XML")
        .descendants()
        .filter(|n| n.has_tag_name("rect") && n.attribute("fill") == Some(fill.as_str()))
        .count()
}

#[test]
fn the_processed_run_section_states_the_runs_numbers_and_verdicts_with_their_rule() {
    let s = six_face();
    let (run, rec) = processed(&s);
    let answer = run.answer().clone();
    let r = report(&s, run);
    let md = r.markdown().unwrap();
    let section = &md[md.find("## Processed run").expect("the section")..];
    let section = &section[..section[3..].find("\n## ").map_or(section.len(), |i| i + 3)];
    // the recording: its name escaped, its hash and sample count
    assert!(section.contains("`run <1>.csv`"), "{section}");
    assert!(
        section.contains(&calib_run::recording::sha256_hex(&rec)),
        "{section}"
    );
    assert!(
        section.contains(&format!("{} samples", answer.run().recording().samples)),
        "{section}"
    );
    // every coefficient with its estimate, U (k) and the predicted beside the observed u
    let mut coefficients = 0;
    for o in answer.run().outputs() {
        for c in o.coefficients() {
            let (u, k) = c.expanded();
            let row = section
                .lines()
                .find(|l| l.starts_with(&format!("| `{}` | `{}` |", o.name(), c.name())))
                .unwrap_or_else(|| panic!("{}: no row", c.name()));
            assert!(row.contains(&sig(c.value(), 6)), "{row}");
            assert!(
                row.contains(&format!("{} (k = {})", sig(u, 3), sig(k, 3))),
                "{row}"
            );
            assert!(row.contains(&sig(c.u_measured_noise(), 3)), "{row}");
            coefficients += 1;
        }
    }
    assert_eq!(coefficients, 24, "the six-face model's 24 coefficients");
    // each verdict on one line, naming its rule
    assert!(!answer.verdicts().is_empty());
    for v in answer.verdicts() {
        let wanted = format!("- {}", tt_report::doc::text(&v.statement));
        let line = section
            .lines()
            .find(|l| *l == wanted)
            .unwrap_or_else(|| panic!("no line {wanted}"));
        assert!(line.contains("ILAC-G8"), "{line}");
    }
    // the segment table: one row per segment
    let n = answer.run().segments().len();
    assert_eq!(n, 9, "six faces and three rotations");
    assert!(
        section.contains(&format!("| {n} | 8 | rotation |")),
        "{section}"
    );
    // results.json: the same numbers
    let json = r.results().unwrap();
    let pr = &json["processed_run"]["run"];
    assert_eq!(pr["segments"].as_array().unwrap().len(), n);
    let (_, c) = answer.run().coefficient("bg_x").unwrap();
    let o = pr["outputs"]
        .as_array()
        .unwrap()
        .iter()
        .find(|o| {
            o["coefficients"]
                .as_array()
                .unwrap()
                .iter()
                .any(|c| c["name"] == "bg_x")
        })
        .expect("the output of bg_x");
    let cj = o["coefficients"]
        .as_array()
        .unwrap()
        .iter()
        .find(|c| c["name"] == "bg_x")
        .unwrap();
    assert_relative_eq!(
        cj["value"].as_f64().unwrap(),
        c.value(),
        max_relative = SAME_F64
    );
    assert_relative_eq!(
        cj["expanded"].as_f64().unwrap(),
        c.expanded().0,
        max_relative = SAME_F64
    );
    assert_eq!(json["processed_run"]["verdicts"][0]["meets"], true);
    // the reproducing command carries the recording, quoted
    assert!(md.contains("--recording 'run <1>.csv'"), "{md}");
}

#[test]
fn the_segments_figure_shades_one_span_per_segment_per_output_and_the_residuals_show_the_band() {
    let s = six_face();
    let (run, _) = processed(&s);
    let segments = run.answer().run().segments().to_vec();
    let overview = run.answer().overview().expect("overview").clone();
    assert!(overview.buckets().len() <= 64);
    let r = report(&s, run);
    let files = r.files().unwrap();
    let svg = |name: &str| {
        String::from_utf8(
            files
                .iter()
                .find(|f| f.name == name)
                .unwrap_or_else(|| panic!("no {name}"))
                .bytes
                .clone(),
        )
        .unwrap()
    };
    let seg = svg("fig_run_segments.svg");
    let outputs = s.sensor.outputs().len();
    let statics = segments
        .iter()
        .filter(|x| x.kind() == calib_run::segments::SegmentKind::Static)
        .count();
    // the legend's two swatches besides one span per segment per output panel
    assert_eq!(rects_filled(&seg, STATIC_SHADE), statics * outputs + 1);
    assert_eq!(
        rects_filled(&seg, TURNING_SHADE),
        (segments.len() - statics) * outputs + 1
    );
    // each span labelled with its schedule entry
    let doc = roxmltree::Document::parse(&seg).unwrap();
    let labels: Vec<&str> = doc
        .descendants()
        .filter(|n| n.has_tag_name("text"))
        .filter_map(|n| n.text())
        .collect();
    for x in &segments {
        let e = x.entry().to_string();
        // once per panel at least (a tick label may read the same number)
        assert!(
            labels.iter().filter(|l| l.trim() == e).count() >= outputs,
            "entry {e}: {labels:?}"
        );
    }
    // each gyro panel's axis fits its static levels (earth rate, bias and noise: hundreds of
    // deg/h) and clips the rotations (tens of thousands); each accelerometer panel, whose
    // rotations stay within its six faces' +-1 g, is whole
    for o in s.sensor.outputs() {
        let clipped = format!(
            "{}: axis fits the static levels; turning parts clipped",
            o.name
        );
        assert_eq!(
            labels.iter().any(|l| l.trim().starts_with(&clipped)),
            o.unit == "deg_per_h",
            "{}: {labels:?}",
            o.name
        );
    }
    let res = svg("fig_run_residuals.svg");
    let doc = roxmltree::Document::parse(&res).unwrap();
    let texts: String = doc
        .descendants()
        .filter(|n| n.has_tag_name("text"))
        .filter_map(|n| n.text())
        .collect::<Vec<_>>()
        .join("|");
    assert!(texts.contains("outlier band ±3"), "{texts}");
    assert!(texts.contains("segment (count)"), "{texts}");
}

#[test]
fn a_report_without_a_recording_has_no_processed_run() {
    let s = six_face();
    let mut options = ReportOptions::default();
    options.samples = Some(2_000);
    let r = Report::compute(s, options).unwrap();
    assert!(!r.markdown().unwrap().contains("Processed run"));
    assert!(r.results().unwrap().get("processed_run").is_none());
    assert!(
        !r.files()
            .unwrap()
            .iter()
            .any(|f| f.name.starts_with("fig_run_"))
    );
}

/// The recording with `offset` added to column `column` in data rows `rows` (0-based).
fn bumped(rec: &[u8], column: &str, rows: std::ops::Range<usize>, offset: f64) -> Vec<u8> {
    let text = String::from_utf8(rec.to_vec()).unwrap();
    let mut lines = text.lines();
    let header = lines.next().unwrap();
    let col = header.split(',').position(|h| h == column).unwrap();
    let mut out = format!("{header}\n");
    for (i, l) in lines.enumerate() {
        let mut cells: Vec<String> = l.split(',').map(str::to_string).collect();
        if rows.contains(&i) {
            cells[col] = (cells[col].parse::<f64>().unwrap() + offset).to_string();
        }
        out.push_str(&cells.join(","));
        out.push('\n');
    }
    out.into_bytes()
}

/// A static segment bumped by 5 mg in `ax` (about 100 times its noise): the segment table names
/// the outlier with its z, the residual figure marks it, and with `--robust` the table gains
/// what the robust fit moved and the notes name the down-weighted entry.
#[test]
fn an_outlier_segment_is_named_in_the_table_and_marked_and_the_robust_fit_says_what_it_changed() {
    let s = six_face();
    let settings = calib_run::simulate::SimSettings::for_study(&s, 50.0, 10.0, 4);
    let mut rec = Vec::new();
    calib_run::simulate::simulate_recording(&s, &s.sensor, &settings, &mut rec).unwrap();
    // the second static segment spans data rows 625..1075 (see the segment table above)
    let rec = bumped(&rec, "ax", 700..1000, 5.0);
    let mut o = tt_lab::calibrate::Options::default();
    o.robust = true;
    o.overview_buckets = Some(64);
    let answer = tt_lab::calibrate::calibrate(&s, rec.as_slice(), "bumped.csv", &o).unwrap();
    let (out_ax, _) = answer.run().coefficient("ba_x").unwrap();
    let flagged: Vec<_> = out_ax.residuals().iter().filter(|r| r.outlier).collect();
    assert!(!flagged.is_empty(), "the bump is an outlier");
    let (_, ba_x) = answer.run().coefficient("ba_x").unwrap();
    let moved = ba_x.robust_change().expect("robust");
    let r = report(&s, ProcessedRun::new(answer.clone(), vec![]));
    let md = r.markdown().unwrap();
    let section = &md[md.find("## Processed run").unwrap()..];
    assert!(section.contains("| robust fit moved it by |"), "{section}");
    let row = section
        .lines()
        .find(|l| l.starts_with("| `ax` | `ba_x` |"))
        .unwrap();
    assert!(row.ends_with(&format!("| {} |", sig(moved, 3))), "{row}");
    for z in &flagged {
        let seg = z.segment + 1;
        let line = section
            .lines()
            .find(|l| l.starts_with(&format!("| {seg} | ")))
            .unwrap();
        assert!(
            line.contains(&format!("`ax` z = {}", sig(z.standardized, 3))),
            "{line}"
        );
    }
    assert!(section.contains("robust fit: entry"), "{section}");
    let files = r.files().unwrap();
    let res = files
        .iter()
        .find(|f| f.name == "fig_run_residuals.svg")
        .unwrap();
    let res = String::from_utf8(res.bytes.clone()).unwrap();
    assert!(res.contains("outlier (|z| &gt; 3)") || res.contains("outlier (|z| > 3)"));
}
