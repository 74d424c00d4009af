//! The Allan deviation figure of a noise log (`ttalloc allan --figure`): the curve with its
//! confidence band, the other deviations where they can be drawn on a log scale, the fitted
//! white-noise line ($N/\sqrt{\tau}$) and the flicker floor ($0.664\,B$).

use crate::figures::{LIMIT, WIDTH, colour, finite};
use crate::{Error, Result};
use allan::{AllanPoint, FLICKER_FLOOR_FACTOR};
use plotters::coord::Shift;
use plotters::coord::combinators::{LogCoord, WithKeyPoints};
use plotters::prelude::*;
use tt_core::human::sig;
use tt_lab::InputError;
use tt_lab::noise_log::{NoiseLog, numbers};

/// The figure's name in messages.
const WHAT: &str = "Allan deviation figure";

/// A deviation of a point (modified, Hadamard, total).
type Dev = fn(&AllanPoint) -> f64;

/// The chart: log-log, cluster time against deviation.
type LogChart<'a, 'b> = ChartContext<
    'a,
    SVGBackend<'b>,
    Cartesian2d<WithKeyPoints<LogCoord<f64>>, WithKeyPoints<LogCoord<f64>>>,
>;

/// A drawing error, naming the figure.
fn drawing<E: std::fmt::Debug>(e: E) -> Error {
    Error::Drawing(format!("{WHAT}: {e:?}"))
}

/// The log-log figure of the log's analysis (deviations in `unit`): the curve with its band,
/// the fitted -1/2 line and the floor, as SVG text.
///
/// # Errors
/// A non-finite number in the analysis; an input error naming `--figure` when the deviation
/// or its band is zero somewhere (nothing to draw on a log scale); a drawing failure.
pub fn allan_figure_svg(log: &NoiseLog, unit: &str) -> Result<String> {
    let a = log.analysis();
    finite(WHAT, numbers(a))?;
    if let Some(p) = a.points().iter().find(|p| p.lower() <= 0.0) {
        return Err(Error::Lab(
            InputError::new(
                "--figure",
                format!(
                    "the Allan deviation (or its band) is zero at tau = {} s: nothing to draw on a log scale",
                    sig(p.tau_s(), 4)
                ),
            )
            .into(),
        ));
    }
    let others = other_deviations(a.points());
    let (xs, ys) = ranges(log, &others);
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (WIDTH, 640)).into_drawing_area();
        root.fill(&WHITE).map_err(drawing)?;
        let mut chart = chart(&root, log, unit, xs, ys)?;
        draw_curves(&mut chart, log, &others)?;
        draw_fits(&mut chart, log, unit, xs, ys)?;
        chart
            .configure_series_labels()
            .position(SeriesLabelPosition::LowerLeft)
            .background_style(WHITE.mix(0.9))
            .border_style(BLACK.mix(0.3))
            .label_font(("sans-serif", 14))
            .draw()
            .map_err(drawing)?;
        root.present().map_err(drawing)?;
    }
    Ok(svg)
}

/// The other deviations, drawn where every point is positive (a log scale).
fn other_deviations(points: &[AllanPoint]) -> Vec<(&'static str, Dev)> {
    [
        ("modified Allan deviation", AllanPoint::mdev as Dev),
        ("overlapping Hadamard deviation", AllanPoint::hdev as Dev),
        ("total deviation", AllanPoint::totdev as Dev),
    ]
    .into_iter()
    .filter(|(_, d)| points.iter().all(|p| d(p) > 0.0))
    .collect()
}

/// The axes' ranges `(x0, x1)`, `(y0, y1)`: every point, band, other deviation and the floor
/// inside, with a margin.
fn ranges(log: &NoiseLog, others: &[(&str, Dev)]) -> ((f64, f64), (f64, f64)) {
    let a = log.analysis();
    let x0 = a.points()[0].tau_s();
    let x1 = a.points()[a.points().len() - 1].tau_s();
    let mut y0 = a
        .points()
        .iter()
        .map(AllanPoint::lower)
        .fold(f64::INFINITY, f64::min);
    for (_, d) in others {
        y0 = a.points().iter().map(d).fold(y0, f64::min);
    }
    let y1 = others.iter().fold(
        a.points().iter().map(AllanPoint::upper).fold(0.0, f64::max),
        |m, (_, d)| a.points().iter().map(d).fold(m, f64::max),
    );
    let floor = a.fit().bias_instability() * FLICKER_FLOOR_FACTOR;
    if floor > 0.0 {
        y0 = y0.min(floor);
    }
    ((x0 / 1.5, x1 * 1.5), (y0 / 2.0, y1 * 2.0))
}

/// The chart with its title, axes and mesh.
fn chart<'a, 'b>(
    root: &'a DrawingArea<SVGBackend<'b>, Shift>,
    log: &NoiseLog,
    unit: &str,
    (x0, x1): (f64, f64),
    (y0, y1): (f64, f64),
) -> Result<LogChart<'a, 'b>> {
    let a = log.analysis();
    let title = format!(
        "Allan deviation of {}, column {} ({} samples at {} Hz)",
        log.name().escape_debug(),
        log.column().escape_debug(),
        a.samples(),
        sig(a.rate_hz(), 6)
    );
    let mut chart = ChartBuilder::on(root)
        .caption(title, ("sans-serif", 19))
        .margin(16)
        .x_label_area_size(48)
        .y_label_area_size(90)
        .build_cartesian_2d(
            (x0..x1).log_scale().with_key_points(log_ticks(x0, x1)),
            (y0..y1).log_scale().with_key_points(log_ticks(y0, y1)),
        )
        .map_err(drawing)?;
    chart
        .configure_mesh()
        .x_desc("cluster time tau (s)")
        .y_desc(format!("Allan deviation ({unit})"))
        .x_label_formatter(&|v| sig(*v, 3))
        .y_label_formatter(&|v| sig(*v, 3))
        .light_line_style(TRANSPARENT)
        .bold_line_style(RGBColor(225, 225, 225))
        .draw()
        .map_err(drawing)?;
    Ok(chart)
}

/// The band, the overlapping Allan deviation with its points, and the other deviations.
fn draw_curves(chart: &mut LogChart<'_, '_>, log: &NoiseLog, others: &[(&str, Dev)]) -> Result<()> {
    let a = log.analysis();
    let band: Vec<(f64, f64)> = a
        .points()
        .iter()
        .map(|p| (p.tau_s(), p.upper()))
        .chain(a.points().iter().rev().map(|p| (p.tau_s(), p.lower())))
        .collect();
    let c = colour(0);
    chart
        .draw_series(std::iter::once(Polygon::new(band, c.mix(0.18).filled())))
        .map_err(drawing)?
        .label(format!("{} % band", sig(100.0 * a.confidence(), 3)))
        .legend(move |(x, y)| Rectangle::new([(x, y - 6), (x + 20, y + 6)], c.mix(0.18).filled()));
    chart
        .draw_series(LineSeries::new(
            a.points().iter().map(|p| (p.tau_s(), p.adev())),
            c.stroke_width(2),
        ))
        .map_err(drawing)?
        .label("overlapping Allan deviation")
        .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], c.stroke_width(2)));
    chart
        .draw_series(
            a.points()
                .iter()
                .map(|p| Circle::new((p.tau_s(), p.adev()), 3, c.filled())),
        )
        .map_err(drawing)?;
    for (k, (name, d)) in others.iter().enumerate() {
        let oc = colour(2 + k);
        chart
            .draw_series(LineSeries::new(
                a.points().iter().map(|p| (p.tau_s(), d(p))),
                oc.stroke_width(1),
            ))
            .map_err(drawing)?
            .label(*name)
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], oc.stroke_width(1)));
    }
    Ok(())
}

/// The fitted white-noise line (where it lies inside the plot) and the flicker floor.
fn draw_fits(
    chart: &mut LogChart<'_, '_>,
    log: &NoiseLog,
    unit: &str,
    (x0, x1): (f64, f64),
    (y0, y1): (f64, f64),
) -> Result<()> {
    let f = log.analysis().fit();
    if f.white_noise() > 0.0 {
        let w = colour(1);
        let white = |t: f64| f.white_noise() / t.sqrt();
        // the -1/2 line where it lies inside the plot
        let pts: Vec<(f64, f64)> = (0..=64)
            .map(|i| x0 * (x1 / x0).powf(f64::from(i) / 64.0))
            .map(|t| (t, white(t)))
            .filter(|(_, v)| *v >= y0 && *v <= y1)
            .collect();
        chart
            .draw_series(LineSeries::new(pts, w.stroke_width(2)))
            .map_err(drawing)?
            .label(format!(
                "white noise N / sqrt(tau), N = {} {unit}/sqrt(Hz)",
                sig(f.white_noise(), 3)
            ))
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], w.stroke_width(2)));
    }
    let floor = f.bias_instability() * FLICKER_FLOOR_FACTOR;
    if floor > 0.0 {
        chart
            .draw_series(LineSeries::new(
                [(x0, floor), (x1, floor)],
                LIMIT.stroke_width(2),
            ))
            .map_err(drawing)?
            .label(format!(
                "floor 0.664 B, B = {} {unit} (at tau = {} s)",
                sig(f.bias_instability(), 3),
                sig(f.floor_tau_s(), 3)
            ))
            .legend(move |(x, y)| {
                PathElement::new(vec![(x, y), (x + 20, y)], LIMIT.stroke_width(2))
            });
    }
    Ok(())
}

/// Tick values of a log axis over `[lo, hi]`: 1, 2, 5 times the powers of ten, or the powers
/// of ten alone over more than four decades.
fn log_ticks(lo: f64, hi: f64) -> Vec<f64> {
    let first = lo.log10().floor() as i32;
    let last = hi.log10().ceil() as i32;
    let steps: &[f64] = if last - first > 4 {
        &[1.0]
    } else {
        &[1.0, 2.0, 5.0]
    };
    (first..=last)
        .flat_map(|e| steps.iter().map(move |s| s * 10f64.powi(e)))
        .filter(|v| *v >= lo && *v <= hi)
        .collect()
}
