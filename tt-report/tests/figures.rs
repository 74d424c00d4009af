//! The SVG figures: each is well-formed XML with its title, one path per line series, its
//! axes' labels and a legend entry per label; a value that cannot be plotted is a typed error
//! naming the figure and panel, never a hang or a wrong picture.

use tt_report::Error;
use tt_report::figures::{
    self, HeatPanel, HistPanel, LIMIT, LinePanel, Mark, Series, colour, hbar_figure, heat_figure,
    histogram_figure, line_figure,
};

fn series(label: &str, i: usize, ys: &[f64]) -> Series {
    Series {
        label: label.into(),
        points: ys
            .iter()
            .enumerate()
            .map(|(k, y)| ((k + 1) as f64, *y))
            .collect(),
        mark: Mark::Line(colour(i), i == 1),
    }
}

fn panel(title: &str, ys: &[f64]) -> LinePanel {
    LinePanel {
        title: title.into(),
        x_label: "test position (count)".into(),
        y_label: "Δω (deg/h)".into(),
        series: vec![series("two-step", 0, ys), series("direct", 2, &[0.002; 4])],
        hlines: vec![("ω_m".into(), 0.01, Mark::Line(LIMIT, true))],
        x_integer: true,
        y_from_zero: true,
    }
}

/// A histogram panel: its (title, x label), bin edges, counts and limit marks.
fn hist(
    (title, x_label): (&str, &str),
    edges: &[f64],
    counts: &[u64],
    limits: Vec<(String, f64, Mark)>,
) -> HistPanel {
    HistPanel {
        title: title.into(),
        x_label: x_label.into(),
        edges: edges.to_vec(),
        counts: counts.to_vec(),
        limits,
    }
}

/// A heat-map panel without a level or a rectangle: its [title, x label, y label, z label],
/// grid (xs, ys) and values `z` (one row per y).
fn heat(
    [title, x_label, y_label, z_label]: [&str; 4],
    (xs, ys): (&[f64], &[f64]),
    z: Vec<Vec<f64>>,
) -> HeatPanel {
    HeatPanel {
        title: title.into(),
        x_label: x_label.into(),
        y_label: y_label.into(),
        xs: xs.to_vec(),
        ys: ys.to_vec(),
        z,
        z_label: z_label.into(),
        level: None,
        rectangle: None,
    }
}

/// Every `<text>` of a parsed SVG.
fn texts(svg: &str) -> Vec<String> {
    let doc = roxmltree::Document::parse(svg).expect("the figure is well-formed XML");
    assert_eq!(doc.root_element().tag_name().name(), "svg");
    doc.descendants()
        .filter(|n| n.has_tag_name("text"))
        .map(|n| n.text().unwrap_or("").trim().to_string())
        .collect()
}

/// Paths (polylines) stroked with `c`, as plotters writes them.
fn polylines_of(svg: &str, c: figures::RGBColor) -> usize {
    let stroke = format!("stroke=\"#{:02X}{:02X}{:02X}\"", c.0, c.1, c.2);
    let doc = roxmltree::Document::parse(svg).unwrap();
    doc.descendants()
        .filter(|n| n.has_tag_name("polyline"))
        .filter(|n| {
            n.attribute("stroke")
                .is_some_and(|s| stroke.contains(&format!("\"{s}\"")))
        })
        .count()
}

#[test]
fn a_line_figure_is_xml_with_its_title_axes_legend_and_one_polyline_per_series() {
    let svg = line_figure(
        "Worst case per position",
        &[
            panel("Δψ", &[0.001, 0.004, 0.003, 0.006]),
            panel("Δθ", &[0.002, 0.001, 0.005, 0.002]),
        ],
        2,
    )
    .unwrap();
    let t = texts(&svg);
    let count = |s: &str| t.iter().filter(|x| *x == s).count();
    assert_eq!(count("Worst case per position"), 1);
    // each panel: its title and both axis labels
    assert_eq!(count("Δψ"), 1);
    assert_eq!(count("Δθ"), 1);
    assert_eq!(count("test position (count)"), 2);
    assert_eq!(count("Δω (deg/h)"), 2);
    // the legend: each label once for both panels
    assert_eq!(count("two-step"), 1);
    assert_eq!(count("direct"), 1);
    assert_eq!(count("ω_m"), 1);
    // the solid series: one polyline per panel and its legend mark
    assert_eq!(polylines_of(&svg, colour(0)), 2 + 1);
    let doc = roxmltree::Document::parse(&svg).unwrap();
    let root = doc.root_element();
    assert_eq!(root.attribute("width"), Some(&*figures::WIDTH.to_string()));
}

#[test]
fn histogram_bar_and_heat_figures_are_xml_with_their_labels() {
    let h = histogram_figure(
        "Monte Carlo",
        &[hist(
            ("Δψ", "orientation error (deg)"),
            &[-0.02, -0.01, 0.0, 0.01, 0.02],
            &[3, 10, 12, 2],
            vec![("±I".into(), 0.027, Mark::Line(LIMIT, false))],
        )],
        "turntables",
    )
    .unwrap();
    let t = texts(&h);
    for label in [
        "Monte Carlo",
        "Δψ",
        "orientation error (deg)",
        "turntables (count)",
        "±I",
        "turntables",
    ] {
        assert!(t.iter().any(|x| x == label), "{label}: {t:?}");
    }
    let b = hbar_figure(
        "Sensitivities",
        &["δx".into(), "δy".into(), "δz".into()],
        &[
            ("Δψ".into(), vec![1.0, 0.5, 0.0]),
            ("Δθ".into(), vec![0.2, 0.9, 0.4]),
        ],
        "average sensitivity (1)",
    )
    .unwrap();
    let t = texts(&b);
    for label in [
        "Sensitivities",
        "δx",
        "δy",
        "δz",
        "Δψ",
        "Δθ",
        "average sensitivity (1)",
    ] {
        assert!(t.iter().any(|x| x == label), "{label}: {t:?}");
    }
    let g = vec![-1.0, 0.0, 1.0];
    let m = heat_figure(
        "Surfaces",
        &[HeatPanel {
            level: Some(0.5),
            rectangle: Some((0.3, 0.3)),
            ..heat(
                ["Δω_x", "Δψ (deg)", "Δθ (deg)", "Δω (deg/h)"],
                (&g, &g),
                g.iter()
                    .map(|y| g.iter().map(|x| x * x + y * y).collect())
                    .collect(),
            )
        }],
        &[(
            "Δω = ω_m".into(),
            Mark::Line(figures::CONTOUR_LEGEND, false),
        )],
    )
    .unwrap();
    let t = texts(&m);
    for label in [
        "Surfaces",
        "Δω_x",
        "Δψ (deg)",
        "Δθ (deg)",
        "Δω (deg/h)",
        "Δω = ω_m",
    ] {
        assert!(t.iter().any(|x| x == label), "{label}: {t:?}");
    }
}

#[test]
fn values_that_cannot_be_plotted_are_typed_errors_naming_the_figure_and_panel() {
    for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY, 1e300] {
        let e = line_figure("Worst case", &[panel("Δψ", &[0.001, bad])], 1).unwrap_err();
        assert!(
            matches!(&e, Error::NotPlottable { figure, value }
                if figure == "Worst case: Δψ" && (value.is_nan() == bad.is_nan())),
            "{e:?}"
        );
        assert!(
            e.to_string()
                .starts_with("Worst case: Δψ: cannot plot the value"),
            "{e}"
        );
    }
    let e = histogram_figure(
        "H",
        &[hist(("h", "deg"), &[0.0, 1.0], &[1, 2], vec![])],
        "n",
    )
    .unwrap_err();
    assert!(
        matches!(&e, Error::HistogramEdges { figure, edges: 2, bins: 2 } if figure == "H: h"),
        "{e}"
    );
    let e = hbar_figure(
        "B",
        &["a".into(), "b".into()],
        &[("s".into(), vec![1.0])],
        "x",
    )
    .unwrap_err();
    assert_eq!(e.to_string(), "B: series s has 1 values for 2 categories");
    let e = heat_figure(
        "M",
        &[heat(
            ["m", "x", "y", "z"],
            (&[0.0, 1.0, 2.0], &[0.0, 1.0]),
            vec![vec![0.0, 1.0], vec![1.0, 1.0]],
        )],
        &[],
    )
    .unwrap_err();
    assert_eq!(e.to_string(), "M: m: the grid is not 3 x 2");
}

/// A recording of one output: `first` (min, max) over a static span, `turning` over the
/// rotation after it, `last` over the static span after that; one bucket per second.
fn buckets(first: (f64, f64), turning: (f64, f64), last: (f64, f64)) -> Vec<(f64, f64, f64, f64)> {
    (0..30)
        .map(|k| {
            let t = f64::from(k);
            let (lo, hi) = match k {
                0..10 => first,
                10..20 => turning,
                _ => last,
            };
            (t, t + 0.98, lo, hi)
        })
        .collect()
}

#[test]
fn a_gyro_panel_fits_its_static_levels_and_marks_its_rotations_clipped_an_accelerometer_is_whole() {
    use figures::{Envelope, Span, recording_figure};
    let spans = vec![
        Span {
            t0_s: 0.0,
            t1_s: 10.0,
            label: "1".into(),
            is_static: true,
        },
        Span {
            t0_s: 10.0,
            t1_s: 20.0,
            label: "2".into(),
            is_static: false,
        },
        Span {
            t0_s: 20.0,
            t1_s: 30.0,
            label: "3".into(),
            is_static: true,
        },
    ];
    // the accelerometer's rotation stays within 1.1 times its static levels' range
    let accel = buckets((0.9, 1.1), (-1.2, 1.2), (-1.1, -0.9));
    let svg = recording_figure(
        "R",
        &[
            Envelope {
                title: "gx".into(),
                y_label: "gx (deg/h)".into(),
                unit: "deg/h".into(),
                buckets: buckets((9.0, 11.0), (9.0, 36_000.0), (-16.0, -14.0)),
            },
            Envelope {
                title: "ax".into(),
                y_label: "ax (g)".into(),
                unit: "g".into(),
                buckets: accel,
            },
        ],
        &spans,
    )
    .unwrap();
    let t = texts(&svg);
    // the gyro's axis spans its static levels (-16 to 11 deg/h) with a margin: no tick
    // label reaches the rotation (36,000 deg/h); the time axis reads 0-30 s
    let numbers: Vec<f64> = t.iter().filter_map(|s| s.parse::<f64>().ok()).collect();
    assert!(numbers.iter().all(|v| v.abs() <= 30.0), "{numbers:?}");
    assert!(numbers.iter().any(|v| *v <= -10.0), "{numbers:?}");
    // the gyro's title says what is clipped and how far it reaches; the accelerometer's
    // panel is whole (its title alone), and the legend names the mark
    assert!(
        t.iter()
            .any(|s| s
                == "gx: axis fits the static levels; turning parts clipped (up to 36000 deg/h)"),
        "{t:?}"
    );
    assert!(t.iter().any(|s| s == "ax"), "{t:?}");
    assert!(
        t.iter()
            .any(|s| s == "beyond the axis (clipped at its edge)"),
        "{t:?}"
    );
    // one clipped run (the rotation's ten buckets), marked once, besides the legend's swatch
    assert_eq!(polylines_of(&svg, LIMIT), 1 + 1);
    // nothing is drawn beyond the figure: every polyline point lies inside the canvas
    let doc = roxmltree::Document::parse(&svg).unwrap();
    let height: f64 = doc
        .root_element()
        .attribute("height")
        .unwrap()
        .parse()
        .unwrap();
    for n in doc.descendants().filter(|n| n.has_tag_name("polyline")) {
        for p in n.attribute("points").unwrap().split_whitespace() {
            let y: f64 = p.split(',').nth(1).unwrap().parse().unwrap();
            assert!((0.0..=height).contains(&y), "{p} outside 0..{height}");
        }
    }
}
