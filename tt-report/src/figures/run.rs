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
    /// The channel's unit (written after a clipped extreme in the panel's title).
    pub unit: String,
    /// `(t_first_s, t_last_s, min, max)` per bucket, in time order.
    pub buckets: Vec<(f64, f64, f64, f64)>,
}

/// A panel's y axis fits its static segments' levels when the whole recording spans more
/// than this many times their span: a gyro's rotations (1e4-1e6 deg/h) would otherwise
/// flatten its static levels (earth rate and bias, tens of deg/h) into lines. Below it (an
/// accelerometer, whose turning parts stay within its static +-1 g) nothing is clipped.
pub const CLIP_FACTOR: f64 = 4.0;

/// A clipping panel's axis reaches this fraction of the static levels' span beyond them.
const CLIP_MARGIN: f64 = 0.25;

/// A recording panel's y axis: the data range drawn and what lies beyond it.
struct PanelAxis {
    lo: f64,
    hi: f64,
    /// The recording's minimum when below `lo` (clipped), else `None`.
    below: Option<f64>,
    /// The recording's maximum when above `hi` (clipped), else `None`.
    above: Option<f64>,
}

/// The y axis of one channel: the whole recording's range, or the static segments' levels
/// (the buckets wholly inside a static span) with [`CLIP_MARGIN`] when the whole range is
/// more than [`CLIP_FACTOR`] times theirs.
fn panel_axis(what: &str, ch: &Envelope, spans: &[Span]) -> Result<PanelAxis> {
    let (lo, hi) = span(what, ch.buckets.iter().flat_map(|b| [b.2, b.3]))?;
    let whole = PanelAxis {
        lo,
        hi,
        below: None,
        above: None,
    };
    let inside_static = |b: &&(f64, f64, f64, f64)| {
        spans
            .iter()
            .any(|s| s.is_static && b.0 >= s.t0_s && b.1 <= s.t1_s)
    };
    let statics: Vec<f64> = ch
        .buckets
        .iter()
        .filter(inside_static)
        .flat_map(|b| [b.2, b.3])
        .collect();
    if statics.is_empty() {
        return Ok(whole);
    }
    let (s_lo, s_hi) = span(what, statics.iter().copied())?;
    let w = s_hi - s_lo;
    if hi - lo <= CLIP_FACTOR * w {
        return Ok(whole);
    }
    let (a_lo, a_hi) = (s_lo - CLIP_MARGIN * w, s_hi + CLIP_MARGIN * w);
    Ok(PanelAxis {
        lo: a_lo,
        hi: a_hi,
        below: (lo < a_lo).then_some(lo),
        above: (hi > a_hi).then_some(hi),
    })
}

/// The time runs `(t_start_s, t_end_s)` of consecutive buckets for which `beyond` holds.
fn clipped_runs(
    buckets: &[(f64, f64, f64, f64)],
    beyond: impl Fn(&(f64, f64, f64, f64)) -> bool,
) -> Vec<(f64, f64)> {
    let mut runs: Vec<(f64, f64)> = Vec::new();
    let mut open = false;
    for b in buckets {
        if beyond(b) {
            if let (true, Some(r)) = (open, runs.last_mut()) {
                r.1 = b.1;
            } else {
                runs.push((b.0, b.1));
            }
            open = true;
        } else {
            open = false;
        }
    }
    runs
}

/// The recording: one panel per channel (its min/max envelope over time), every segment's
/// span shaded ([`STATIC_SHADE`], [`TURNING_SHADE`]: one `<rect>` per segment per panel)
/// and labelled. A panel whose recording spans more than [`CLIP_FACTOR`] times its static
/// levels has its axis fitted to those levels: what lies beyond is drawn at the axis edge,
/// marked by a thick line in [`LIMIT`]'s colour over its time (one `<polyline>` per run of
/// clipped buckets), and the panel's title states the recording's extreme beyond each edge.
///
/// # Errors
/// A non-finite or absurd value ([`finite`]), or a drawing failure.
pub fn recording_figure(title: &str, channels: &[Envelope], spans: &[Span]) -> Result<String> {
    let axes = channels
        .iter()
        .map(|ch| panel_axis(&format!("{title}: {}", ch.title), ch, spans))
        .collect::<Result<Vec<_>>>()?;
    let mut legend = vec![
        ("static segment".to_string(), Mark::Fill(STATIC_SHADE)),
        ("turning segment".to_string(), Mark::Fill(TURNING_SHADE)),
        (
            "recording (min and max)".to_string(),
            Mark::Line(colour(0), false),
        ),
    ];
    if axes.iter().any(|a| a.below.is_some() || a.above.is_some()) {
        legend.push((
            "beyond the axis (clipped at its edge)".to_string(),
            Mark::Line(LIMIT, false),
        ));
    }
    let mut svg = String::new();
    canvas(&mut svg, title, &legend, channels.len(), 1, 260, |areas| {
        for ((ch, axis), area) in channels.iter().zip(&axes).zip(&areas) {
            let what = format!("{title}: {}", ch.title);
            finite(&what, spans.iter().flat_map(|s| [s.t0_s, s.t1_s]))?;
            let (x0, x1) = span(
                &what,
                ch.buckets
                    .iter()
                    .flat_map(|b| [b.0, b.1])
                    .chain(spans.iter().flat_map(|s| [s.t0_s, s.t1_s])),
            )?;
            let (lo, hi) = (axis.lo, axis.hi);
            let pad = 0.08 * (hi - lo);
            let (y0, y1) = (lo - pad, hi + 2.0 * pad);
            let caption = match (axis.below, axis.above) {
                (None, None) => ch.title.clone(),
                (below, above) => {
                    let side = |v: Option<f64>, dir: &str| {
                        v.map(|v| format!("{dir} {} {}", tt_core::human::sig(v, 3), ch.unit))
                    };
                    let beyond: Vec<String> = [side(below, "down to"), side(above, "up to")]
                        .into_iter()
                        .flatten()
                        .collect();
                    format!(
                        "{}: axis fits the static levels; turning parts clipped ({})",
                        ch.title,
                        beyond.join(", ")
                    )
                }
            };
            let mut chart = ChartBuilder::on(area)
                .caption(caption.as_str(), (FONT, 16))
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
            let clip = |v: f64| v.clamp(lo, hi);
            chart
                .draw_series(ch.buckets.iter().map(|b| {
                    let t = 0.5 * (b.0 + b.1);
                    PathElement::new(vec![(t, clip(b.2)), (t, clip(b.3))], c.stroke_width(1))
                }))
                .map_err(err)?;
            for line in [
                ch.buckets
                    .iter()
                    .map(|b| (0.5 * (b.0 + b.1), clip(b.2)))
                    .collect::<Vec<_>>(),
                ch.buckets
                    .iter()
                    .map(|b| (0.5 * (b.0 + b.1), clip(b.3)))
                    .collect(),
            ] {
                chart
                    .draw_series(LineSeries::new(line, c.stroke_width(1)))
                    .map_err(err)?;
            }
            let mut marks = Vec::new();
            if axis.below.is_some() {
                marks.extend(
                    clipped_runs(&ch.buckets, |b| b.2 < lo)
                        .into_iter()
                        .map(|r| (r, lo)),
                );
            }
            if axis.above.is_some() {
                marks.extend(
                    clipped_runs(&ch.buckets, |b| b.3 > hi)
                        .into_iter()
                        .map(|r| (r, hi)),
                );
            }
            chart
                .draw_series(marks.into_iter().map(|((ta, tb), y)| {
                    PathElement::new(vec![(ta, y), (tb, y)], LIMIT.stroke_width(4))
                }))
                .map_err(err)?;
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
