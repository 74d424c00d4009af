//! SVG figures of the report (plotters, SVG backend; text is rendered by the browser, so
//! Unicode symbols such as Δψ and ω_m appear as written).
//!
//! Every function takes plain data and returns one SVG document. Every plotted value is
//! checked first ([`finite`]): a NaN, an infinity or an absurd magnitude is an error naming
//! the figure, never a hang in plotters' tick search (which loops on an infinite span) or a
//! silently wrong picture. Legends are drawn in a strip of their own under the title, never
//! over the data; heat maps carry a colour bar; axes that count things get integer ticks;
//! every axis names its unit.

use crate::{Error, Result};
use plotters::coord::{CoordTranslate, Shift};

mod run;
use plotters::prelude::*;
pub use run::{
    CLIP_FACTOR, Envelope, Residuals, STATIC_SHADE, Span, TURNING_SHADE, recording_figure,
    residual_figure,
};

pub use plotters::style::RGBColor;
/// Black (the requirement's rectangle, reference marks).
pub(crate) const BLACK: RGBColor = RGBColor(0, 0, 0);

/// Figure width, px (the page column is 1180 px; figures scale down with it).
pub const WIDTH: u32 = 1120;

/// Largest magnitude a plotted value may have: far beyond any angle, rate or count of a
/// study, far below where spans overflow.
pub(crate) const MAX_PLOT_ABS: f64 = 1e100;

const TITLE_PX: u32 = 34;
/// The figures' font: the families `cargo xtask test` installs first (as the page's CSS).
const FONT: &str = "DejaVu Sans, Liberation Sans, sans-serif";
const PALETTE: [RGBColor; 7] = [
    RGBColor(31, 119, 180),
    RGBColor(255, 127, 14),
    RGBColor(44, 160, 44),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
    RGBColor(227, 119, 194),
    RGBColor(23, 190, 207),
];
/// The legend's stand-in for the white contour line of the heat maps (white is invisible on
/// the legend's white background).
pub const CONTOUR_LEGEND: RGBColor = RGBColor(170, 170, 170);
/// Grid lines: light grey, one per tick (no minor lines).
const GRID: RGBColor = RGBColor(225, 225, 225);
/// Colour of limits (a requirement, an accuracy).
pub const LIMIT: RGBColor = RGBColor(200, 30, 30);

fn err<E: std::fmt::Debug>(e: E) -> Error {
    Error::Drawing(format!("{e:?}"))
}

/// The colour of series `i`.
#[must_use]
pub fn colour(i: usize) -> RGBColor {
    PALETTE[i % PALETTE.len()]
}

/// How a legend entry (and its series) is drawn.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Mark {
    /// A line; dashed or solid.
    Line(RGBColor, bool),
    /// A filled box (bars, histograms).
    Fill(RGBColor),
    /// Dots (a series the paper says is flat).
    Dots(RGBColor),
}

/// Check that every value is finite and at most [`MAX_PLOT_ABS`] in magnitude.
///
/// # Errors
/// Names the figure and the offending value.
pub fn finite(what: &str, values: impl IntoIterator<Item = f64>) -> Result<()> {
    for v in values {
        if !v.is_finite() || v.abs() > MAX_PLOT_ABS {
            return Err(Error::NotPlottable {
                figure: what.to_string(),
                value: v,
            });
        }
    }
    Ok(())
}

/// The range of the values (checked), padded when degenerate.
fn span(what: &str, values: impl IntoIterator<Item = f64> + Clone) -> Result<(f64, f64)> {
    finite(what, values.clone())?;
    let (lo, hi) = values
        .into_iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
            (a.min(v), b.max(v))
        });
    if lo > hi {
        return Ok((0.0, 1.0));
    }
    if hi - lo <= 1e-12 * hi.abs().max(lo.abs()).max(1e-300) {
        let pad = if hi == 0.0 { 1.0 } else { 0.5 * hi.abs() };
        return Ok((lo - pad, hi + pad));
    }
    Ok((lo, hi))
}

/// Tick labels with as many decimals as the axis span needs (no `0.30000000000000004`).
fn tick(span: f64) -> impl Fn(&f64) -> String {
    let step = span / 8.0;
    let decimals = if step > 0.0 {
        (-step.log10().floor()).clamp(0.0, 12.0) as usize
    } else {
        0
    };
    let sci = span > 0.0 && span < 1e-4;
    move |v: &f64| {
        if sci {
            tt_core::human::sig(*v, 3)
        } else {
            let s = format!("{v:.decimals$}");
            if s.trim_start_matches('-')
                .chars()
                .all(|c| c == '0' || c == '.')
            {
                "0".into()
            } else {
                s
            }
        }
    }
}

/// Text width estimate (px) for the legend layout.
fn text_px(s: &str, size: f64) -> u32 {
    (s.chars().count() as f64 * size * 0.56).ceil() as u32
}

/// Rows of a legend of `entries` across `width` px.
fn legend_rows(entries: &[(String, Mark)], width: u32) -> Vec<Vec<usize>> {
    let mut rows: Vec<Vec<usize>> = vec![Vec::new()];
    let mut x = 0;
    for (i, (label, _)) in entries.iter().enumerate() {
        let w = 34 + text_px(label, 14.0) + 26;
        if x + w > width.saturating_sub(40) && !rows.last().is_some_and(Vec::is_empty) {
            rows.push(Vec::new());
            x = 0;
        }
        x += w;
        if let Some(r) = rows.last_mut() {
            r.push(i);
        }
    }
    rows
}

/// Height of the legend strip, px.
fn legend_height(entries: &[(String, Mark)], width: u32) -> u32 {
    if entries.is_empty() {
        0
    } else {
        24 * legend_rows(entries, width).len() as u32 + 8
    }
}

/// Draw a legend strip (entries centred in rows).
fn draw_legend(
    area: &DrawingArea<SVGBackend<'_>, Shift>,
    entries: &[(String, Mark)],
) -> Result<()> {
    let (width, _) = area.dim_in_pixel();
    let style = TextStyle::from((FONT, 14).into_font()).color(&BLACK);
    for (r, row) in legend_rows(entries, width).iter().enumerate() {
        let total: u32 = row
            .iter()
            .map(|&i| 34 + text_px(&entries[i].0, 14.0) + 26)
            .sum();
        let mut x = (width.saturating_sub(total) / 2) as i32;
        let y = 14 + 24 * r as i32;
        for &i in row {
            let (label, mark) = &entries[i];
            match *mark {
                Mark::Line(c, dashed) => {
                    if dashed {
                        for k in 0..3 {
                            area.draw(&PathElement::new(
                                vec![(x + 10 * k, y), (x + 10 * k + 6, y)],
                                c.stroke_width(2),
                            ))
                            .map_err(err)?;
                        }
                    } else {
                        area.draw(&PathElement::new(
                            vec![(x, y), (x + 28, y)],
                            c.stroke_width(2),
                        ))
                        .map_err(err)?;
                    }
                }
                Mark::Fill(c) => {
                    area.draw(&Rectangle::new(
                        [(x + 4, y - 6), (x + 24, y + 6)],
                        c.filled(),
                    ))
                    .map_err(err)?;
                }
                Mark::Dots(c) => {
                    for k in 0..3 {
                        area.draw(&Circle::new((x + 4 + 10 * k, y), 2, c.filled()))
                            .map_err(err)?;
                    }
                }
            }
            area.draw(&Text::new(label.clone(), (x + 34, y - 8), style.clone()))
                .map_err(err)?;
            x += (34 + text_px(label, 14.0) + 26) as i32;
        }
    }
    Ok(())
}

/// The figure canvas: a title, a legend strip, and the panel grid below.
fn canvas(
    svg: &mut String,
    title: &str,
    legend: &[(String, Mark)],
    panels: usize,
    cols: usize,
    panel_height: u32,
    body: impl FnOnce(Vec<DrawingArea<SVGBackend<'_>, Shift>>) -> Result<()>,
) -> Result<()> {
    let cols = cols.max(1);
    let rows = panels.div_ceil(cols).max(1);
    let lh = legend_height(legend, WIDTH);
    let height = TITLE_PX + lh + panel_height * rows as u32;
    let root = SVGBackend::with_string(svg, (WIDTH, height)).into_drawing_area();
    root.fill(&WHITE).map_err(err)?;
    let (top, rest) = root.split_vertically(TITLE_PX);
    top.draw(&Text::new(
        title.to_string(),
        (WIDTH as i32 / 2, 8),
        TextStyle::from((FONT, 19).into_font()).pos(plotters::style::text_anchor::Pos::new(
            plotters::style::text_anchor::HPos::Center,
            plotters::style::text_anchor::VPos::Top,
        )),
    ))
    .map_err(err)?;
    let (leg, grid) = rest.split_vertically(lh);
    if lh > 0 {
        draw_legend(&leg, legend)?;
    }
    let areas = grid.split_evenly((rows, cols));
    body(areas.into_iter().take(panels).collect())?;
    root.present().map_err(err)?;
    Ok(())
}

/// Draw `points` as one line in `mark`'s colour, dashed when the mark is a dashed line (a fill
/// or dots mark draws a solid line: reference lines and limits).
fn draw_line<CT>(
    chart: &mut ChartContext<'_, SVGBackend<'_>, CT>,
    points: Vec<CT::From>,
    mark: Mark,
) -> Result<()>
where
    CT: CoordTranslate,
    CT::From: Clone + 'static,
{
    let (c, dashed) = match mark {
        Mark::Line(c, d) => (c, d),
        Mark::Fill(c) | Mark::Dots(c) => (c, false),
    };
    if dashed {
        chart
            .draw_series(DashedLineSeries::new(points, 6, 4, c.stroke_width(2)))
            .map_err(err)?;
    } else {
        chart
            .draw_series(LineSeries::new(points, c.stroke_width(2)))
            .map_err(err)?;
    }
    Ok(())
}

/// One panel of a [`panel_figure`].
trait Panel {
    /// The panel's title.
    fn title(&self) -> &str;

    /// Draw the panel in `area`, `what` naming it in errors (`figure title: panel title`).
    fn draw(&self, area: &DrawingArea<SVGBackend<'_>, Shift>, what: String) -> Result<()>;
}

/// A figure of `panels`, `cols` to a row and `panel_height` px tall, under `title` and
/// `legend` ([`canvas`]): each panel drawn in its area ([`Panel::draw`]).
fn panel_figure<P: Panel>(
    title: &str,
    legend: &[(String, Mark)],
    panels: &[P],
    cols: usize,
    panel_height: u32,
) -> Result<String> {
    let mut svg = String::new();
    canvas(
        &mut svg,
        title,
        legend,
        panels.len(),
        cols,
        panel_height,
        |areas| {
            for (p, area) in panels.iter().zip(&areas) {
                p.draw(area, format!("{title}: {}", p.title()))?;
            }
            Ok(())
        },
    )?;
    Ok(svg)
}

/// One line series.
#[derive(Debug, Clone)]
pub struct Series {
    /// Legend label.
    pub label: String,
    /// Points (x, y).
    pub points: Vec<(f64, f64)>,
    /// How it is drawn.
    pub mark: Mark,
}

/// One panel of line series.
#[derive(Debug, Clone)]
pub struct LinePanel {
    /// Panel title.
    pub title: String,
    /// x-axis label with unit.
    pub x_label: String,
    /// y-axis label with unit.
    pub y_label: String,
    /// The series.
    pub series: Vec<Series>,
    /// Horizontal reference lines (label for the legend, y, mark).
    pub hlines: Vec<(String, f64, Mark)>,
    /// The x axis counts things (test positions): integer ticks.
    pub x_integer: bool,
    /// The y axis starts at zero.
    pub y_from_zero: bool,
}

/// The legend of a set of panels: every series and reference line, once per label.
fn legend_of(panels: &[LinePanel]) -> Vec<(String, Mark)> {
    let mut out: Vec<(String, Mark)> = Vec::new();
    for p in panels {
        for (l, m) in p
            .series
            .iter()
            .map(|s| (&s.label, s.mark))
            .chain(p.hlines.iter().map(|h| (&h.0, h.2)))
        {
            if !out.iter().any(|(k, _)| k == l) {
                out.push((l.clone(), m));
            }
        }
    }
    out
}

/// Line panels in a grid of `cols` columns, one shared legend (every series and reference
/// line, once per label).
///
/// # Errors
/// A non-finite or absurd value ([`finite`]), or a drawing failure.
pub fn line_figure(title: &str, panels: &[LinePanel], cols: usize) -> Result<String> {
    line_figure_with_legend(title, panels, cols, &legend_of(panels))
}

/// [`line_figure`] with a given legend.
///
/// # Errors
/// As [`line_figure`].
pub(crate) fn line_figure_with_legend(
    title: &str,
    panels: &[LinePanel],
    cols: usize,
    legend: &[(String, Mark)],
) -> Result<String> {
    let panel_height = if cols >= 3 { 300 } else { 340 };
    panel_figure(title, legend, panels, cols, panel_height)
}

impl Panel for LinePanel {
    fn title(&self) -> &str {
        &self.title
    }

    fn draw(&self, area: &DrawingArea<SVGBackend<'_>, Shift>, what: String) -> Result<()> {
        let (x0, x1) = span(
            &what,
            self.series
                .iter()
                .flat_map(|s| s.points.iter().map(|q| q.0)),
        )?;
        let (mut y0, mut y1) = span(
            &what,
            self.series
                .iter()
                .flat_map(|s| s.points.iter().map(|q| q.1))
                .chain(self.hlines.iter().map(|h| h.1)),
        )?;
        if self.y_from_zero {
            y0 = y0.min(0.0);
        }
        // room around the data: nothing drawn on the frame
        let pad = 0.05 * (y1 - y0);
        if !self.y_from_zero || y0 < 0.0 {
            y0 -= pad;
        }
        y1 += pad;
        let (x0, x1) = if self.x_integer {
            (x0 - 0.5, x1 + 0.5)
        } else if self.y_from_zero {
            (x0, x1)
        } else {
            (x0 - 0.05 * (x1 - x0), x1 + 0.05 * (x1 - x0))
        };
        let mut chart = ChartBuilder::on(area)
            .caption(self.title.as_str(), (FONT, 17))
            .margin(10)
            .x_label_area_size(42)
            .y_label_area_size(78)
            .build_cartesian_2d(x0..x1, y0..y1)
            .map_err(err)?;
        let xs = x1 - x0;
        let x_fmt = tick(xs);
        let int_fmt = |v: &f64| {
            if (v - v.round()).abs() < 1e-9 {
                format!("{}", v.round() as i64)
            } else {
                String::new()
            }
        };
        let y_fmt = tick(y1 - y0);
        let mut mesh = chart.configure_mesh();
        mesh.light_line_style(TRANSPARENT)
            .bold_line_style(GRID)
            .x_desc(self.x_label.as_str())
            .y_desc(self.y_label.as_str())
            .y_label_formatter(&y_fmt)
            .label_style((FONT, 14))
            .axis_desc_style((FONT, 15));
        if self.x_integer {
            mesh.x_labels((xs.floor() as usize).clamp(2, 12))
                .x_label_formatter(&int_fmt);
        } else {
            mesh.x_labels(7).x_label_formatter(&x_fmt);
        }
        mesh.draw().map_err(err)?;
        for (_, y, mark) in &self.hlines {
            draw_line(&mut chart, vec![(x0, *y), (x1, *y)], *mark)?;
        }
        for s in &self.series {
            match s.mark {
                Mark::Line(..) => draw_line(&mut chart, s.points.clone(), s.mark)?,
                Mark::Dots(c) | Mark::Fill(c) => {
                    chart
                        .draw_series(s.points.iter().map(|q| Circle::new(*q, 2, c.filled())))
                        .map_err(err)?;
                }
            }
        }
        Ok(())
    }
}

/// A scalar field on a grid: `z[j][i]` at `(xs[i], ys[j])`.
#[derive(Debug, Clone)]
pub struct HeatPanel {
    /// Panel title.
    pub title: String,
    /// x-axis label with unit.
    pub x_label: String,
    /// y-axis label with unit.
    pub y_label: String,
    /// Abscissae, increasing.
    pub xs: Vec<f64>,
    /// Ordinates, increasing.
    pub ys: Vec<f64>,
    /// Values, `z[j][i]`.
    pub z: Vec<Vec<f64>>,
    /// The colour bar's label with unit.
    pub z_label: String,
    /// A level drawn as a white contour line (the accuracy).
    pub level: Option<f64>,
    /// A centred rectangle (half-widths in x and y) drawn dashed black (the requirement).
    pub rectangle: Option<(f64, f64)>,
}

/// A perceptually ordered blue-green-yellow ramp (viridis anchors), `t` in [0, 1].
fn viridis(t: f64) -> RGBColor {
    const A: [(f64, (f64, f64, f64)); 5] = [
        (0.0, (68.0, 1.0, 84.0)),
        (0.25, (59.0, 82.0, 139.0)),
        (0.5, (33.0, 145.0, 140.0)),
        (0.75, (94.0, 201.0, 98.0)),
        (1.0, (253.0, 231.0, 37.0)),
    ];
    let t = if t.is_finite() {
        t.clamp(0.0, 1.0)
    } else {
        1.0
    };
    let k = A
        .iter()
        .rposition(|a| a.0 <= t)
        .unwrap_or(0)
        .min(A.len() - 2);
    let (t0, c0) = A[k];
    let (t1, c1) = A[k + 1];
    let u = (t - t0) / (t1 - t0);
    let mix = |a: f64, b: f64| (a + u * (b - a)).round() as u8;
    RGBColor(mix(c0.0, c1.0), mix(c0.1, c1.1), mix(c0.2, c1.2))
}

/// Segments of the level set `z = level` (marching squares; `z[j][i]`).
#[must_use]
pub(crate) fn contour_segments(
    xs: &[f64],
    ys: &[f64],
    z: &[Vec<f64>],
    level: f64,
) -> Vec<[(f64, f64); 2]> {
    let mut out = Vec::new();
    for j in 0..ys.len().saturating_sub(1) {
        for i in 0..xs.len().saturating_sub(1) {
            let c = [
                (xs[i], ys[j], z[j][i]),
                (xs[i + 1], ys[j], z[j][i + 1]),
                (xs[i + 1], ys[j + 1], z[j + 1][i + 1]),
                (xs[i], ys[j + 1], z[j + 1][i]),
            ];
            let mut cross = Vec::new();
            for k in 0..4 {
                let (xa, ya, za) = c[k];
                let (xb, yb, zb) = c[(k + 1) % 4];
                if (za - level) * (zb - level) < 0.0 {
                    let t = (level - za) / (zb - za);
                    cross.push((xa + t * (xb - xa), ya + t * (yb - ya)));
                }
            }
            for pair in cross.chunks_exact(2) {
                out.push([pair[0], pair[1]]);
            }
        }
    }
    out
}

/// Heat maps, up to three per row, each with its colour bar.
///
/// # Errors
/// A non-finite or absurd value, a ragged grid, or a drawing failure.
pub fn heat_figure(title: &str, panels: &[HeatPanel], legend: &[(String, Mark)]) -> Result<String> {
    // at most two per row: each map keeps a readable size beside its colour bar
    let cols = panels.len().clamp(1, 2);
    panel_figure(title, legend, panels, cols, 420)
}

impl Panel for HeatPanel {
    fn title(&self) -> &str {
        &self.title
    }

    fn draw(&self, area: &DrawingArea<SVGBackend<'_>, Shift>, what: String) -> Result<()> {
        if self.z.len() != self.ys.len()
            || self.z.iter().any(|r| r.len() != self.xs.len())
            || self.xs.len() < 2
            || self.ys.len() < 2
        {
            return Err(Error::Grid {
                figure: what,
                nx: self.xs.len(),
                ny: self.ys.len(),
            });
        }
        let (x0, x1) = span(&what, self.xs.iter().copied())?;
        let (y0, y1) = span(&what, self.ys.iter().copied())?;
        let (z0, z1) = span(&what, self.z.iter().flatten().copied())?;
        if let Some(l) = self.level {
            finite(&what, [l])?;
        }
        if let Some((a, b)) = self.rectangle {
            finite(&what, [a, b])?;
        }
        let (w, _) = area.dim_in_pixel();
        let (plot, bar) = area.split_horizontally(w.saturating_sub(92));
        let mut chart = ChartBuilder::on(&plot)
            .caption(self.title.as_str(), (FONT, 17))
            .margin(8)
            .x_label_area_size(42)
            .y_label_area_size(70)
            .build_cartesian_2d(x0..x1, y0..y1)
            .map_err(err)?;
        let xf = tick(x1 - x0);
        let yf = tick(y1 - y0);
        chart
            .configure_mesh()
            .disable_mesh()
            .x_labels(5)
            .y_labels(5)
            .x_label_formatter(&xf)
            .y_label_formatter(&yf)
            .x_desc(self.x_label.as_str())
            .y_desc(self.y_label.as_str())
            .label_style((FONT, 14))
            .axis_desc_style((FONT, 15))
            .draw()
            .map_err(err)?;
        let half = |v: &[f64], k: usize| {
            let lo = if k == 0 {
                v[0]
            } else {
                0.5 * (v[k - 1] + v[k])
            };
            let hi = if k + 1 == v.len() {
                v[k]
            } else {
                0.5 * (v[k] + v[k + 1])
            };
            (lo, hi)
        };
        chart
            .draw_series((0..self.ys.len()).flat_map(|j| {
                (0..self.xs.len()).map(move |i| {
                    let (xa, xb) = half(&self.xs, i);
                    let (ya, yb) = half(&self.ys, j);
                    Rectangle::new(
                        [(xa, ya), (xb, yb)],
                        viridis((self.z[j][i] - z0) / (z1 - z0)).filled(),
                    )
                })
            }))
            .map_err(err)?;
        if let Some(level) = self.level {
            chart
                .draw_series(
                    contour_segments(&self.xs, &self.ys, &self.z, level)
                        .into_iter()
                        .map(|s| PathElement::new(s.to_vec(), WHITE.stroke_width(2))),
                )
                .map_err(err)?;
        }
        if let Some((a, b)) = self.rectangle {
            let pts = vec![(-a, -b), (a, -b), (a, b), (-a, b), (-a, -b)];
            chart
                .draw_series(DashedLineSeries::new(pts, 6, 4, BLACK.stroke_width(2)))
                .map_err(err)?;
        }
        // the colour bar
        let mut cb = ChartBuilder::on(&bar)
            .margin_top(34)
            .margin_bottom(50)
            .margin_right(4)
            .y_label_area_size(56)
            .build_cartesian_2d(0.0..1.0, z0..z1)
            .map_err(err)?;
        let zf = tick(z1 - z0);
        cb.configure_mesh()
            .disable_mesh()
            .disable_x_axis()
            .y_labels(6)
            .y_label_formatter(&zf)
            .y_desc(self.z_label.as_str())
            .label_style((FONT, 11))
            .axis_desc_style((FONT, 12))
            .draw()
            .map_err(err)?;
        const STEPS: usize = 64;
        cb.draw_series((0..STEPS).map(|k| {
            let a = z0 + (z1 - z0) * k as f64 / STEPS as f64;
            let b = z0 + (z1 - z0) * (k + 1) as f64 / STEPS as f64;
            Rectangle::new(
                [(0.0, a), (1.0, b)],
                viridis((k as f64 + 0.5) / STEPS as f64).filled(),
            )
        }))
        .map_err(err)?;
        if let Some(level) = self.level.filter(|l| *l >= z0 && *l <= z1) {
            cb.draw_series(std::iter::once(PathElement::new(
                vec![(0.0, level), (1.0, level)],
                WHITE.stroke_width(2),
            )))
            .map_err(err)?;
        }
        Ok(())
    }
}

/// One histogram panel.
#[derive(Debug, Clone)]
pub struct HistPanel {
    /// Panel title.
    pub title: String,
    /// x-axis label with unit.
    pub x_label: String,
    /// Bin edges (`counts.len() + 1` increasing values).
    pub edges: Vec<f64>,
    /// Counts per bin.
    pub counts: Vec<u64>,
    /// Symmetric limits drawn at ±x (legend label, x, mark).
    pub limits: Vec<(String, f64, Mark)>,
}

/// Histograms side by side (integer count axis), one shared legend.
///
/// # Errors
/// A non-finite or absurd value, inconsistent edges, or a drawing failure.
pub fn histogram_figure(title: &str, panels: &[HistPanel], fill_label: &str) -> Result<String> {
    let mut legend = vec![(fill_label.to_string(), Mark::Fill(colour(0)))];
    for p in panels {
        for (l, _, m) in &p.limits {
            if !legend.iter().any(|(k, _)| k == l) {
                legend.push((l.clone(), *m));
            }
        }
    }
    panel_figure(title, &legend, panels, panels.len().clamp(1, 3), 360)
}

impl Panel for HistPanel {
    fn title(&self) -> &str {
        &self.title
    }

    fn draw(&self, area: &DrawingArea<SVGBackend<'_>, Shift>, what: String) -> Result<()> {
        if self.edges.len() != self.counts.len() + 1 {
            return Err(Error::HistogramEdges {
                figure: what,
                edges: self.edges.len(),
                bins: self.counts.len(),
            });
        }
        let (mut x0, mut x1) = span(&what, self.edges.iter().copied())?;
        finite(&what, self.limits.iter().map(|l| l.1))?;
        for (_, l, _) in &self.limits {
            x0 = x0.min(-1.08 * l.abs());
            x1 = x1.max(1.08 * l.abs());
        }
        let ymax = self.counts.iter().copied().max().unwrap_or(1).max(1);
        let y1 = ymax + ymax / 10 + 1;
        let mut chart = ChartBuilder::on(area)
            .caption(self.title.as_str(), (FONT, 17))
            .margin(10)
            .x_label_area_size(42)
            .y_label_area_size(64)
            .build_cartesian_2d(x0..x1, 0u64..y1)
            .map_err(err)?;
        let xf = tick(x1 - x0);
        chart
            .configure_mesh()
            .light_line_style(TRANSPARENT)
            .bold_line_style(GRID)
            .x_labels(5)
            .y_labels(6)
            .x_label_formatter(&xf)
            .x_desc(self.x_label.as_str())
            .y_desc("turntables (count)")
            .label_style((FONT, 14))
            .axis_desc_style((FONT, 15))
            .draw()
            .map_err(err)?;
        chart
            .draw_series(
                self.counts
                    .iter()
                    .enumerate()
                    .filter(|(_, c)| **c > 0)
                    .map(|(k, c)| {
                        Rectangle::new(
                            [(self.edges[k], 0), (self.edges[k + 1], *c)],
                            colour(0).filled(),
                        )
                    }),
            )
            .map_err(err)?;
        for (_, l, mark) in &self.limits {
            for x in [-l.abs(), l.abs()] {
                draw_line(&mut chart, vec![(x, 0), (x, y1)], *mark)?;
            }
        }
        Ok(())
    }
}

/// Height of one category row of [`hbar_figure`] in its integer coordinate: plotters' integer
/// key points (steps 1, 2, 5, 10, 20, 50, ...) land on the row centres.
const ROW: i32 = 20;

/// Horizontal grouped bars: one row per category (error), one bar per series (angle).
///
/// # Errors
/// A non-finite or absurd value, ragged series, or a drawing failure.
pub fn hbar_figure(
    title: &str,
    categories: &[String],
    series: &[(String, Vec<f64>)],
    x_label: &str,
) -> Result<String> {
    hbar_figure_with_limit(title, categories, series, x_label, None)
}

/// [`hbar_figure`] with a vertical line across every row at `limit` (its legend label and
/// value; the axis reaches it).
///
/// # Errors
/// As [`hbar_figure`].
pub(crate) fn hbar_figure_with_limit(
    title: &str,
    categories: &[String],
    series: &[(String, Vec<f64>)],
    x_label: &str,
    limit: Option<(&str, f64)>,
) -> Result<String> {
    let mut svg = String::new();
    let mut legend: Vec<(String, Mark)> = series
        .iter()
        .enumerate()
        .map(|(i, (l, _))| (l.clone(), Mark::Fill(colour(i))))
        .collect();
    if let Some((label, v)) = limit {
        finite(title, [v])?;
        legend.push((label.to_string(), Mark::Line(LIMIT, false)));
    }
    let n = categories.len().max(1);
    let height = (26 * n as u32 + 110).max(260);
    canvas(&mut svg, title, &legend, 1, 1, height, |areas| {
        let Some(area) = areas.first() else {
            return Ok(());
        };
        for (l, v) in series {
            if v.len() != categories.len() {
                return Err(Error::RaggedSeries {
                    figure: title.to_string(),
                    series: l.clone(),
                    values: v.len(),
                    categories: categories.len(),
                });
            }
            finite(title, v.iter().copied())?;
        }
        let xmax = series
            .iter()
            .flat_map(|(_, v)| v.iter().copied())
            .fold(0.0_f64, f64::max)
            .max(limit.map_or(1e-12, |(_, v)| v))
            * 1.08;
        let label_px = categories
            .iter()
            .map(|c| text_px(c, 13.0))
            .max()
            .unwrap_or(40)
            + 16;
        // categories at multiples of ROW (integer key points land on them); row k spans
        // [ROW k - ROW/2, ROW k + ROW/2), three quarters of it filled by the bars
        let mut chart = ChartBuilder::on(area)
            .margin(10)
            .x_label_area_size(44)
            .y_label_area_size(label_px)
            .build_cartesian_2d(0.0..xmax, -(ROW / 2)..(ROW * n as i32 - ROW / 2))
            .map_err(err)?;
        // the first category at the top: row k drawn at position n - 1 - k
        let cats = categories.to_vec();
        let last = n as i32 - 1;
        let yf = move |v: &i32| {
            if v.rem_euclid(ROW) == 0 {
                cats.get((last - *v / ROW) as usize)
                    .cloned()
                    .unwrap_or_default()
            } else {
                String::new()
            }
        };
        let xf = tick(xmax);
        chart
            .configure_mesh()
            .disable_y_mesh()
            .light_line_style(TRANSPARENT)
            .bold_line_style(GRID)
            .y_labels(n + 1)
            .y_label_formatter(&yf)
            .x_label_formatter(&xf)
            .x_desc(x_label)
            .label_style((FONT, 13))
            .axis_desc_style((FONT, 15))
            .draw()
            .map_err(err)?;
        let m = series.len().max(1) as i32;
        let thick = (3 * ROW / 4 / m).max(1);
        for (s, (_, values)) in series.iter().enumerate() {
            let c = colour(s);
            let off = -(thick * m) / 2 + thick * s as i32;
            chart
                .draw_series(
                    values
                        .iter()
                        .enumerate()
                        .filter(|(_, v)| **v > 0.0)
                        .map(|(k, v)| {
                            let y = ROW * (last - k as i32) - off - thick;
                            Rectangle::new([(0.0, y), (*v, y + thick)], c.filled())
                        }),
                )
                .map_err(err)?;
        }
        if let Some((_, v)) = limit {
            let span = [-(ROW / 2), ROW * n as i32 - ROW / 2];
            chart
                .draw_series(LineSeries::new(span.map(|y| (v, y)), LIMIT.stroke_width(2)))
                .map_err(err)?;
        }
        Ok(())
    })?;
    Ok(svg)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn panel(y: Vec<f64>) -> LinePanel {
        LinePanel {
            title: "p".into(),
            x_label: "position".into(),
            y_label: "Δω (deg/h)".into(),
            series: vec![Series {
                label: "a".into(),
                points: y
                    .iter()
                    .enumerate()
                    .map(|(i, v)| ((i + 1) as f64, *v))
                    .collect(),
                mark: Mark::Line(colour(0), false),
            }],
            hlines: vec![("ω_m".into(), 0.01, Mark::Line(LIMIT, true))],
            x_integer: true,
            y_from_zero: true,
        }
    }

    #[test]
    fn non_finite_or_absurd_values_are_errors_naming_the_figure_never_a_hang() {
        for bad in [f64::NAN, f64::INFINITY, 1e308, -1e200] {
            let e = line_figure("F", &[panel(vec![0.001, bad])], 1)
                .unwrap_err()
                .to_string();
            assert!(e.contains("F: p") && e.contains("cannot plot"), "{e}");
        }
        let e = histogram_figure(
            "H",
            &[HistPanel {
                title: "h".into(),
                x_label: "deg".into(),
                edges: vec![0.0, 1.0],
                counts: vec![3],
                limits: vec![("I".into(), 1e308, Mark::Line(LIMIT, false))],
            }],
            "n",
        )
        .unwrap_err();
        assert!(e.to_string().contains("H: h"), "{e}");
        let e = hbar_figure("B", &["a".into()], &[("s".into(), vec![f64::NAN])], "x").unwrap_err();
        assert!(e.to_string().contains("B"), "{e}");
        let e = heat_figure(
            "M",
            &[HeatPanel {
                title: "m".into(),
                x_label: "x".into(),
                y_label: "y".into(),
                xs: vec![0.0, 1.0],
                ys: vec![0.0, 1.0],
                z: vec![vec![0.0, 1.0], vec![f64::NAN, 1.0]],
                z_label: "z".into(),
                level: None,
                rectangle: None,
            }],
            &[],
        )
        .unwrap_err();
        assert!(e.to_string().contains("M: m"), "{e}");
    }

    /// The text of every `<text>` element of an SVG document, and its y coordinate.
    fn texts(svg: &str) -> Vec<(String, f64)> {
        svg.split("<text")
            .skip(1)
            .map(|t| {
                let y = t
                    .split("y=\"")
                    .nth(1)
                    .and_then(|r| r.split('"').next())
                    .and_then(|v| v.parse().ok())
                    .unwrap_or(f64::NAN);
                let body = t
                    .split_once('>')
                    .map_or("", |x| x.1)
                    .split("</text>")
                    .next()
                    .unwrap_or("")
                    .trim()
                    .to_string();
                (body, y)
            })
            .collect()
    }

    #[test]
    fn integer_axes_have_integer_ticks_and_the_legend_sits_above_the_panels() {
        let svg = line_figure(
            "F",
            &[panel((0..32).map(|k| 0.001 * f64::from(k)).collect())],
            1,
        )
        .unwrap();
        let t = texts(&svg);
        let legend_y = t
            .iter()
            .find(|(s, _)| s == "ω_m")
            .map(|x| x.1)
            .expect("the legend names ω_m");
        let ticks: Vec<&(String, f64)> =
            t.iter().filter(|(s, _)| s.parse::<f64>().is_ok()).collect();
        assert!(ticks.len() > 8, "{t:?}");
        // the panel (its ticks, its title) is below the legend strip
        let title_y = t.iter().find(|(s, _)| s == "p").map(|x| x.1).unwrap();
        assert!(
            legend_y < title_y && ticks.iter().all(|(_, y)| *y > legend_y),
            "{t:?}"
        );
        // x ticks (positions 1..32) are whole numbers printed without decimals
        let x_ticks: Vec<&str> = t
            .iter()
            .filter(|(s, _)| !s.contains('.'))
            .filter_map(|(s, _)| s.parse::<i64>().ok().map(|_| s.as_str()))
            .collect();
        assert!(x_ticks.len() >= 5 && x_ticks.contains(&"10"), "{x_ticks:?}");
        assert!(
            !t.iter()
                .any(|(s, _)| s.ends_with(".0") || s == "2.5" || s == "7.5"),
            "{t:?}"
        );
        let h = histogram_figure(
            "H",
            &[HistPanel {
                title: "h".into(),
                x_label: "deg".into(),
                edges: vec![-1.0, 0.0, 1.0],
                counts: vec![7, 3],
                limits: vec![],
            }],
            "draws",
        )
        .unwrap();
        let t = texts(&h);
        // counts: integer ticks only
        assert!(
            t.iter().any(|(s, _)| s == "7" || s == "6" || s == "8"),
            "{t:?}"
        );
        assert!(
            !t.iter()
                .any(|(s, _)| s == "7.5" || s == "2.5" || s == "3.5"),
            "{t:?}"
        );
    }

    #[test]
    fn contour_of_a_cone_is_a_closed_ring() {
        let g: Vec<f64> = (0..21).map(|k| -1.0 + 0.1 * f64::from(k)).collect();
        let z: Vec<Vec<f64>> = g
            .iter()
            .map(|y| g.iter().map(|x| (x * x + y * y).sqrt()).collect())
            .collect();
        let segs = contour_segments(&g, &g, &z, 0.5);
        assert!(segs.len() > 20);
        for s in segs {
            for (x, y) in s {
                assert!(((x * x + y * y).sqrt() - 0.5).abs() < 0.05);
            }
        }
    }
}
