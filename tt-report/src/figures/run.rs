//! The figures of a processed run: the recording with its segments, and the standardized
//! residuals per segment.

use super::{
    BLACK, FONT, LIMIT, LinePanel, Mark, Series, canvas, colour, err, finite, line_figure, span,
    tick,
};
use crate::Result;
use plotters::prelude::*;

/// Shade of a static segment's span.
pub const STATIC_SHADE: RGBColor = RGBColor(205, 222, 240);
/// Shade of a turning segment's span (a rate step, a rotation).
pub const TURNING_SHADE: RGBColor = RGBColor(250, 222, 190);

/// A segment's span on the recording.
#[derive(Debug, Clone)]
pub struct Span {
    /// Start, s.
    pub t0_s: f64,
    /// End, s.
    pub t1_s: f64,
    /// Its label (the schedule entry).
    pub label: String,
    /// Static (else turning).
    pub is_static: bool,
}

/// One channel of a recording, decimated: per bucket the first and last sample's time and
/// the channel's minimum and maximum.
#[derive(Debug, Clone)]
pub struct Envelope {
    /// Panel title (the channel).
    pub title: String,
    /// y-axis label with unit.
    pub y_label: String,
    /// `(t_first_s, t_last_s, min, max)` per bucket, in time order.
    pub buckets: Vec<(f64, f64, f64, f64)>,
}

/// The recording: one panel per channel (its min/max envelope over time), every segment's
/// span shaded ([`STATIC_SHADE`], [`TURNING_SHADE`]: one `<rect>` per segment per panel)
/// and labelled.
///
/// # Errors
/// A non-finite or absurd value ([`finite`]), or a drawing failure.
pub fn recording_figure(title: &str, channels: &[Envelope], spans: &[Span]) -> Result<String> {
    let legend = vec![
        ("static segment".to_string(), Mark::Fill(STATIC_SHADE)),
        ("turning segment".to_string(), Mark::Fill(TURNING_SHADE)),
        (
            "recording (min and max)".to_string(),
            Mark::Line(colour(0), false),
        ),
    ];
    let mut svg = String::new();
    canvas(&mut svg, title, &legend, channels.len(), 1, 260, |areas| {
        for (ch, area) in channels.iter().zip(&areas) {
            let what = format!("{title}: {}", ch.title);
            finite(&what, spans.iter().flat_map(|s| [s.t0_s, s.t1_s]))?;
            let (x0, x1) = span(
                &what,
                ch.buckets
                    .iter()
                    .flat_map(|b| [b.0, b.1])
                    .chain(spans.iter().flat_map(|s| [s.t0_s, s.t1_s])),
            )?;
            let (mut y0, mut y1) = span(&what, ch.buckets.iter().flat_map(|b| [b.2, b.3]))?;
            let pad = 0.08 * (y1 - y0);
            y0 -= pad;
            y1 += 2.0 * pad;
            let mut chart = ChartBuilder::on(area)
                .caption(ch.title.as_str(), (FONT, 16))
                .margin(10)
                .x_label_area_size(40)
                .y_label_area_size(78)
                .build_cartesian_2d(x0..x1, y0..y1)
                .map_err(err)?;
            let x_fmt = tick(x1 - x0);
            let y_fmt = tick(y1 - y0);
            chart
                .configure_mesh()
                .light_line_style(TRANSPARENT)
                .bold_line_style(super::GRID)
                .x_desc("time (s)")
                .y_desc(ch.y_label.as_str())
                .x_labels(8)
                .x_label_formatter(&x_fmt)
                .y_label_formatter(&y_fmt)
                .label_style((FONT, 13))
                .axis_desc_style((FONT, 14))
                .draw()
                .map_err(err)?;
            chart
                .draw_series(spans.iter().map(|s| {
                    let shade = if s.is_static {
                        STATIC_SHADE
                    } else {
                        TURNING_SHADE
                    };
                    Rectangle::new([(s.t0_s, y0), (s.t1_s, y1)], shade.filled())
                }))
                .map_err(err)?;
            let label_style = TextStyle::from((FONT, 11).into_font()).color(&BLACK);
            chart
                .draw_series(spans.iter().map(|s| {
                    Text::new(
                        s.label.clone(),
                        (0.5 * (s.t0_s + s.t1_s), y1 - 0.4 * pad),
                        label_style.clone(),
                    )
                }))
                .map_err(err)?;
            let c = colour(0);
            chart
                .draw_series(ch.buckets.iter().map(|b| {
                    let t = 0.5 * (b.0 + b.1);
                    PathElement::new(vec![(t, b.2), (t, b.3)], c.stroke_width(1))
                }))
                .map_err(err)?;
            for line in [
                ch.buckets
                    .iter()
                    .map(|b| (0.5 * (b.0 + b.1), b.2))
                    .collect::<Vec<_>>(),
                ch.buckets
                    .iter()
                    .map(|b| (0.5 * (b.0 + b.1), b.3))
                    .collect(),
            ] {
                chart
                    .draw_series(LineSeries::new(line, c.stroke_width(1)))
                    .map_err(err)?;
            }
        }
        Ok(())
    })?;
    Ok(svg)
}

/// One output's standardized residuals: `(segment number, z, outlier)`.
#[derive(Debug, Clone)]
pub struct Residuals {
    /// The output (legend label).
    pub label: String,
    /// Per segment.
    pub points: Vec<(f64, f64, bool)>,
}

/// The standardized residual per segment of every output (dots), the outlier band at
/// `±band` (dashed), the outliers marked again in the limit's colour.
///
/// # Errors
/// As [`line_figure`].
pub fn residual_figure(title: &str, outputs: &[Residuals], band: f64) -> Result<String> {
    let mut series: Vec<Series> = outputs
        .iter()
        .enumerate()
        .map(|(i, o)| Series {
            label: o.label.clone(),
            points: o.points.iter().map(|p| (p.0, p.1)).collect(),
            mark: Mark::Dots(colour(i)),
        })
        .collect();
    let outliers: Vec<(f64, f64)> = outputs
        .iter()
        .flat_map(|o| o.points.iter().filter(|p| p.2).map(|p| (p.0, p.1)))
        .collect();
    if !outliers.is_empty() {
        series.push(Series {
            label: format!("outlier (|z| > {band})"),
            points: outliers,
            mark: Mark::Dots(LIMIT),
        });
    }
    let panel = LinePanel {
        title: "standardized residual per segment".into(),
        x_label: "segment (count)".into(),
        y_label: "residual / its standard deviation".into(),
        series,
        hlines: vec![
            (
                format!("outlier band ±{band}"),
                band,
                Mark::Line(LIMIT, true),
            ),
            (
                format!("outlier band ±{band}"),
                -band,
                Mark::Line(LIMIT, true),
            ),
        ],
        x_integer: true,
        y_from_zero: false,
    };
    line_figure(title, &[panel], 1)
}
