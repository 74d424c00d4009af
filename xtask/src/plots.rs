//! SVG figures (plotters, SVG backend, no system fonts needed). Each function takes plain
//! data and returns a self-contained SVG document as a string.

use anyhow::{Result, anyhow};
use plotters::coord::Shift;
use plotters::prelude::*;

const W: u32 = 900;
const H: u32 = 520;
const PALETTE: [RGBColor; 6] = [
    RGBColor(31, 119, 180),
    RGBColor(255, 127, 14),
    RGBColor(44, 160, 44),
    RGBColor(214, 39, 40),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
];

fn err<E: std::fmt::Debug>(e: E) -> anyhow::Error {
    anyhow!("drawing failed: {e:?}")
}

/// The colour of series `i`.
pub fn colour(i: usize) -> RGBColor {
    PALETTE[i % PALETTE.len()]
}

fn span(values: impl Iterator<Item = f64>) -> (f64, f64) {
    let (lo, hi) = values
        .filter(|v| v.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
            (a.min(v), b.max(v))
        });
    if !lo.is_finite() {
        return (0.0, 1.0);
    }
    if hi - lo < 1e-300 {
        (lo - 0.5, hi + 0.5)
    } else {
        (lo, hi)
    }
}

/// A grouped bar chart: one group per category, one bar per series (Figure 8).
pub fn grouped_bars(
    title: &str,
    y_label: &str,
    categories: &[String],
    series: &[(String, Vec<f64>)],
) -> Result<String> {
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (W, H)).into_drawing_area();
        root.fill(&WHITE).map_err(err)?;
        let y_max = series
            .iter()
            .flat_map(|(_, v)| v.iter().copied())
            .fold(0.0_f64, f64::max)
            * 1.35;
        let n = categories.len();
        let mut chart = ChartBuilder::on(&root)
            .caption(title, ("sans-serif", 20))
            .margin(12)
            .x_label_area_size(40)
            .y_label_area_size(60)
            .build_cartesian_2d(0.0..n as f64, 0.0..y_max.max(1e-12))
            .map_err(err)?;
        let cats = categories.to_vec();
        chart
            .configure_mesh()
            .disable_x_mesh()
            .x_labels(n * 2 + 1)
            .x_label_formatter(&|x| {
                let k = x.floor() as usize;
                if (x - x.floor() - 0.5).abs() < 1e-6 && k < cats.len() {
                    cats[k].clone()
                } else {
                    String::new()
                }
            })
            .y_desc(y_label)
            .draw()
            .map_err(err)?;
        let m = series.len().max(1) as f64;
        let width = 0.8 / m;
        for (s, (name, values)) in series.iter().enumerate() {
            let c = colour(s);
            chart
                .draw_series(values.iter().enumerate().map(|(k, v)| {
                    let x0 = k as f64 + 0.1 + s as f64 * width;
                    Rectangle::new([(x0, 0.0), (x0 + width * 0.95, *v)], c.filled())
                }))
                .map_err(err)?
                .label(name.as_str())
                .legend(move |(x, y)| Rectangle::new([(x, y - 5), (x + 12, y + 5)], c.filled()));
        }
        chart
            .configure_series_labels()
            .position(SeriesLabelPosition::UpperMiddle)
            .border_style(BLACK)
            .background_style(WHITE.mix(0.9))
            .draw()
            .map_err(err)?;
        root.present().map_err(err)?;
    }
    Ok(svg)
}

/// One line series.
pub struct Line {
    /// Legend label.
    pub label: String,
    /// Points (x, y).
    pub points: Vec<(f64, f64)>,
    /// Dashed (drawn as points) rather than solid.
    pub dashed: bool,
}

/// Line plots side by side (one panel per entry): Figure 4 cuts and the end-to-end figure.
/// `hline` draws a horizontal reference line (for example $\omega_m$) in every panel.
pub fn line_panels(
    title: &str,
    panels: &[(String, String, String, Vec<Line>)],
    hline: Option<(&str, f64)>,
) -> Result<String> {
    let mut svg = String::new();
    {
        // Two columns for four panels (a 2 x 2 grid), otherwise up to three per row.
        let cols = if panels.len() == 4 {
            2
        } else {
            panels.len().clamp(1, 3)
        };
        let rows = panels.len().div_ceil(cols).max(1);
        let root = SVGBackend::with_string(&mut svg, (W, (H / 2 + 40) * rows as u32 + 40))
            .into_drawing_area();
        root.fill(&WHITE).map_err(err)?;
        let root = root.titled(title, ("sans-serif", 20)).map_err(err)?;
        let areas = root.split_evenly((rows, cols));
        for ((panel_title, x_label, y_label, lines), area) in panels.iter().zip(areas.iter()) {
            draw_lines(area, panel_title, x_label, y_label, lines, hline)?;
        }
        root.present().map_err(err)?;
    }
    Ok(svg)
}

fn draw_lines(
    area: &DrawingArea<SVGBackend<'_>, Shift>,
    title: &str,
    x_label: &str,
    y_label: &str,
    lines: &[Line],
    hline: Option<(&str, f64)>,
) -> Result<()> {
    let (x0, x1) = span(lines.iter().flat_map(|l| l.points.iter().map(|p| p.0)));
    let (mut y0, mut y1) = span(
        lines
            .iter()
            .flat_map(|l| l.points.iter().map(|p| p.1))
            .chain(hline.map(|h| h.1)),
    );
    y0 = y0.min(0.0);
    y1 += 0.08 * (y1 - y0);
    let mut chart = ChartBuilder::on(area)
        .caption(title, ("sans-serif", 15))
        .margin(8)
        .x_label_area_size(35)
        .y_label_area_size(60)
        .build_cartesian_2d(x0..x1, y0..y1)
        .map_err(err)?;
    chart
        .configure_mesh()
        .x_desc(x_label)
        .y_desc(y_label)
        .draw()
        .map_err(err)?;
    for (i, l) in lines.iter().enumerate() {
        let c = colour(i);
        let style = c.stroke_width(2);
        if l.dashed {
            chart
                .draw_series(l.points.iter().map(|p| Circle::new(*p, 2, c.filled())))
                .map_err(err)?
                .label(l.label.as_str())
                .legend(move |(x, y)| Circle::new((x + 6, y), 3, c.filled()));
        } else {
            chart
                .draw_series(LineSeries::new(l.points.clone(), style))
                .map_err(err)?
                .label(l.label.as_str())
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 14, y)], style));
        }
    }
    if let Some((label, y)) = hline {
        chart
            .draw_series(LineSeries::new(
                vec![(x0, y), (x1, y)],
                BLACK.stroke_width(1),
            ))
            .map_err(err)?
            .label(label)
            .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 14, y)], BLACK));
    }
    chart
        .configure_series_labels()
        .border_style(BLACK)
        .background_style(WHITE.mix(0.9))
        .draw()
        .map_err(err)?;
    Ok(())
}

/// A scalar field on a rectangular grid: `z[i][j]` at `(xs[i], ys[j])`.
pub struct Grid {
    /// Abscissae, increasing.
    pub xs: Vec<f64>,
    /// Ordinates, increasing.
    pub ys: Vec<f64>,
    /// Values, `z[i][j]` at `(xs[i], ys[j])`.
    pub z: Vec<Vec<f64>>,
}

fn heat(t: f64) -> RGBColor {
    // A perceptually ordered blue-green-yellow ramp (viridis anchors).
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

/// Segments of the level set `z = level` by marching squares.
pub fn contour_segments(grid: &Grid, level: f64) -> Vec<[(f64, f64); 2]> {
    let mut out = Vec::new();
    for i in 0..grid.xs.len().saturating_sub(1) {
        for j in 0..grid.ys.len().saturating_sub(1) {
            let corners = [
                (grid.xs[i], grid.ys[j], grid.z[i][j]),
                (grid.xs[i + 1], grid.ys[j], grid.z[i + 1][j]),
                (grid.xs[i + 1], grid.ys[j + 1], grid.z[i + 1][j + 1]),
                (grid.xs[i], grid.ys[j + 1], grid.z[i][j + 1]),
            ];
            let mut cross = Vec::new();
            for k in 0..4 {
                let (xa, ya, za) = corners[k];
                let (xb, yb, zb) = corners[(k + 1) % 4];
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

/// One heat-map panel with the level set `level` and centred rectangles (half-widths).
pub struct HeatPanel {
    /// Panel title.
    pub title: String,
    /// Axis labels.
    pub x_label: String,
    /// Axis labels.
    pub y_label: String,
    /// The field.
    pub grid: Grid,
    /// Level drawn as a contour line (for example $\omega_m$).
    pub level: Option<f64>,
    /// Centred rectangles to outline: (half-width in x, half-height in y, label).
    pub rectangles: Vec<(f64, f64, String)>,
}

/// Heat maps side by side (Figure 4 surfaces, Figure 5 lines of intersection).
pub fn heat_panels(title: &str, z_label: &str, panels: &[HeatPanel]) -> Result<String> {
    let mut svg = String::new();
    {
        let cols = panels.len().clamp(1, 3);
        let rows = panels.len().div_ceil(cols).max(1);
        let root =
            SVGBackend::with_string(&mut svg, (W, 460 * rows as u32 + 40)).into_drawing_area();
        root.fill(&WHITE).map_err(err)?;
        let root = root.titled(title, ("sans-serif", 20)).map_err(err)?;
        for (p, area) in panels.iter().zip(root.split_evenly((rows, cols)).iter()) {
            let g = &p.grid;
            let (x0, x1) = span(g.xs.iter().copied());
            let (y0, y1) = span(g.ys.iter().copied());
            let (z0, z1) = span(g.z.iter().flatten().copied());
            let mut chart = ChartBuilder::on(area)
                .caption(
                    format!("{} ({z_label}: {z0:.3e}..{z1:.3e})", p.title),
                    ("sans-serif", 13),
                )
                .margin(8)
                .x_label_area_size(35)
                .y_label_area_size(55)
                .build_cartesian_2d(x0..x1, y0..y1)
                .map_err(err)?;
            chart
                .configure_mesh()
                .disable_mesh()
                .x_desc(p.x_label.as_str())
                .y_desc(p.y_label.as_str())
                .draw()
                .map_err(err)?;
            let n = g.xs.len();
            let m = g.ys.len();
            let half = |v: &[f64], k: usize, len: usize| {
                let lo = if k == 0 {
                    v[0]
                } else {
                    0.5 * (v[k - 1] + v[k])
                };
                let hi = if k + 1 == len {
                    v[k]
                } else {
                    0.5 * (v[k] + v[k + 1])
                };
                (lo, hi)
            };
            chart
                .draw_series((0..n).flat_map(|i| {
                    (0..m).map(move |j| {
                        let (xa, xb) = half(&g.xs, i, n);
                        let (ya, yb) = half(&g.ys, j, m);
                        let t = (g.z[i][j] - z0) / (z1 - z0);
                        Rectangle::new([(xa, ya), (xb, yb)], heat(t).filled())
                    })
                }))
                .map_err(err)?;
            if let Some(level) = p.level {
                chart
                    .draw_series(
                        contour_segments(g, level)
                            .into_iter()
                            .map(|s| PathElement::new(s.to_vec(), WHITE.stroke_width(2))),
                    )
                    .map_err(err)?;
            }
            for (k, (hx, hy, label)) in p.rectangles.iter().enumerate() {
                let c = if k == 0 { BLACK } else { colour(3 + k) };
                chart
                    .draw_series(std::iter::once(Rectangle::new(
                        [(-hx, -hy), (*hx, *hy)],
                        c.stroke_width(2),
                    )))
                    .map_err(err)?
                    .label(label.as_str())
                    .legend(move |(x, y)| {
                        Rectangle::new([(x, y - 5), (x + 12, y + 5)], c.stroke_width(2))
                    });
            }
            if !p.rectangles.is_empty() {
                chart
                    .configure_series_labels()
                    .border_style(BLACK)
                    .background_style(WHITE.mix(0.9))
                    .draw()
                    .map_err(err)?;
            }
        }
        root.present().map_err(err)?;
    }
    Ok(svg)
}

/// One histogram panel: bin edges, counts, and symmetric limits drawn as vertical lines.
pub struct HistPanel {
    /// Panel title.
    pub title: String,
    /// Axis label of the variable.
    pub x_label: String,
    /// Bin edges (`counts.len() + 1` increasing values).
    pub edges: Vec<f64>,
    /// Counts per bin.
    pub counts: Vec<u64>,
    /// Limit drawn at `-limit` and `+limit` (for example the requirement I).
    pub limit: Option<f64>,
}

/// Histograms side by side (Figure 9).
pub fn histogram_panels(title: &str, panels: &[HistPanel]) -> Result<String> {
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (W, H)).into_drawing_area();
        root.fill(&WHITE).map_err(err)?;
        let root = root.titled(title, ("sans-serif", 20)).map_err(err)?;
        let areas = root.split_evenly((1, panels.len().max(1)));
        for (p, area) in panels.iter().zip(areas.iter()) {
            let (mut x0, mut x1) = span(p.edges.iter().copied());
            if let Some(l) = p.limit {
                x0 = x0.min(-1.1 * l);
                x1 = x1.max(1.1 * l);
            }
            let y1 = p.counts.iter().copied().max().unwrap_or(1).max(1) as f64 * 1.1;
            let mut chart = ChartBuilder::on(area)
                .caption(p.title.as_str(), ("sans-serif", 14))
                .margin(8)
                .x_label_area_size(35)
                .y_label_area_size(55)
                .build_cartesian_2d(x0..x1, 0.0..y1)
                .map_err(err)?;
            chart
                .configure_mesh()
                .x_labels(5)
                .x_desc(p.x_label.as_str())
                .y_desc("count")
                .draw()
                .map_err(err)?;
            chart
                .draw_series(p.counts.iter().enumerate().map(|(k, c)| {
                    Rectangle::new(
                        [(p.edges[k], 0.0), (p.edges[k + 1], *c as f64)],
                        colour(0).filled(),
                    )
                }))
                .map_err(err)?;
            if let Some(l) = p.limit {
                for x in [-l, l] {
                    chart
                        .draw_series(LineSeries::new(
                            vec![(x, 0.0), (x, y1)],
                            colour(3).stroke_width(2),
                        ))
                        .map_err(err)?;
                }
            }
        }
        root.present().map_err(err)?;
    }
    Ok(svg)
}
