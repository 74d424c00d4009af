//! The report's end-to-end section lists the yield-based box's re-measured turntables against
//! each limit its yield counts (issue 34): the same figures as `end-to-end --json` for the same
//! study, samples and seed, the study's labels escaped for Markdown.

use std::path::Path;
use tt_report::{Report, ReportOptions};

fn imu_example() -> study::Study {
    study::Study::load(
        &Path::new(env!("CARGO_MANIFEST_DIR")).join("../studies/imu-triad-example.toml"),
    )
    .unwrap()
}

/// The items of the Markdown list that opens `block` (after blank lines), without `- `.
fn list_items(block: &str) -> Vec<&str> {
    block
        .trim_start()
        .lines()
        .take_while(|l| l.starts_with("- "))
        .map(|l| &l[2..])
        .collect()
}

/// The IMU example, its report.md and `end-to-end`'s answer for the same 2,000 turntables
/// (seed 7).
fn report_and_answer() -> (study::Study, String, tt_lab::end_to_end::EndToEndAnswer) {
    let s = imu_example();
    let mut options = ReportOptions::default();
    options.samples = Some(2_000);
    options.seed = Some(7);
    let md = Report::compute(s.clone(), options)
        .unwrap()
        .markdown()
        .unwrap();
    let o = tt_lab::end_to_end::Options {
        samples: Some(2_000),
        seed: Some(7),
        ..Default::default()
    };
    let r = tt_lab::end_to_end::end_to_end(&s, &o).unwrap();
    (s, md, r)
}

/// On the IMU example (2,000 turntables, seed 7) each reading's list in report.md has one item
/// per limit: every output's accuracy with `remeasured.meeting`, then each specification the
/// yield counts (its label with `_` escaped, as Markdown must show it) with its
/// `remeasured_per_specification` count, each with the fraction and the Wilson 95% interval;
/// the fewest marked as limiting the yield.
#[test]
fn the_report_lists_the_yields_count_per_specification_as_end_to_end_json_has_them() {
    let (s, md, r) = report_and_answer();
    let v = serde_json::to_value(tt_lab::end_to_end::EndToEndJson::of(&s, &r)).unwrap();
    let readings = v["readings"].as_array().unwrap();
    let intro = "The yield-based box's re-measured turntables against each limit its yield counts:";
    assert_eq!(md.matches(intro).count(), readings.len(), "{md}");
    for (reading, block) in readings.iter().zip(md.split(intro).skip(1)) {
        let y = &reading["yield_based"];
        let samples = y["remeasured"]["samples"].as_u64().unwrap();
        let mut limits = vec![(
            "every output's accuracy (eq 14)".to_string(),
            y["remeasured"]["meeting"].as_u64().unwrap(),
        )];
        for p in y["specifications"]["remeasured_per_specification"]
            .as_array()
            .unwrap()
        {
            limits.push((
                p["specification"].as_str().unwrap().replace('_', "\\_"),
                p["meeting"].as_u64().unwrap(),
            ));
        }
        assert_eq!(limits.len(), 4, "the accuracies and three specifications");
        assert_eq!(limits[1].0, "ax ba\\_x (bias) in ug");
        let fewest = limits.iter().map(|l| l.1).min().unwrap();
        let items = list_items(block);
        assert_eq!(items.len(), limits.len(), "{block}");
        for ((label, meeting), item) in limits.iter().zip(items) {
            let (lo, hi) = e2e_verify::wilson_interval_95(*meeting, samples);
            let shown = format!(
                "{label}: {meeting} of {samples} ({:.2}%, 95% interval {:.2}-{:.2}%)",
                100.0 * *meeting as f64 / samples as f64,
                100.0 * lo,
                100.0 * hi
            );
            if *meeting == fewest && fewest < samples {
                assert_eq!(
                    item,
                    format!("{shown}; the fewest: it limits the yield most")
                );
            } else {
                assert_eq!(item, shown);
            }
        }
    }
}

/// The IMU example's two gyro specifications (bias and g-sensitivity at 0.1) cannot be met by
/// any table (the noise part alone fills each limit): the report lists them, escaped, as left
/// out of the allocations, each as `end-to-end` answers them, and the yield-based box's cell
/// says it counts every specification *a table can meet*, naming the two left out, instead of
/// "every specification".
#[test]
fn the_report_says_which_specifications_its_yield_leaves_out_because_no_table_can_meet_them() {
    let (_, md, r) = report_and_answer();
    assert_eq!(
        r.no_table_suffices().len(),
        2,
        "{:?}",
        r.no_table_suffices()
    );
    let intro = "Left out of the direct and the yield-based allocations (no table can meet them):";
    let block = md.split(intro).nth(1).expect(intro);
    let items = list_items(block);
    let expected: Vec<String> = r
        .no_table_suffices()
        .iter()
        // Markdown shows `_` and `>` only escaped
        .map(|n| n.to_string().replace('_', "\\_").replace('>', "\\>"))
        .collect();
    assert_eq!(items, expected);
    assert!(
        items[0].starts_with("no table suffices for gx bg\\_x (bias)"),
        "{items:?}"
    );
    assert!(
        md.contains("of draws meeting every accuracy and every specification a table can meet (2 specifications no table can meet not counted: the noise alone fills the limit):"),
        "{md}"
    );
    assert!(
        !md.contains("every accuracy and every specification:"),
        "{md}"
    );
}
