//! Segments of a recording: given in a small CSV file, or detected (static intervals by a
//! moving-variance test on blocks of samples, turning intervals by the rate) and matched to
//! the study's schedule in order, every mismatch reported.
//!
//! # Kinds
//! - [`SegmentKind::Static`]: the table at rest at a schedule position (its pose, or the
//!   logged angles' mean);
//! - [`SegmentKind::Rate`]: a rate step at its commanded rate over whole revolutions (the
//!   samples given must span them);
//! - [`SegmentKind::Rotation`]: a rotation of a known total angle (the rate step's whole
//!   revolutions, or the logged angles' change) at an unknown rate: the mean rate is the angle
//!   over the segment's duration, whatever the rate profile (a hand-turned rotation of a
//!   six-face and three-rotation recording).
//!
//! # Detection
//! Samples are taken in blocks of [`DetectSettings::block_s`]. A block is at rest when every
//! output with a study noise model varies by at most [`DetectSettings::variance_ratio`] times
//! the model's white sample variance, the rate the gyro outputs show (the outputs with a known
//! or estimated term linear in one rate input) stays under
//! [`DetectSettings::turning_rate_deg_per_s`], and the logged angles (when present) move by at
//! most [`DetectSettings::still_deg`]. A run of resting blocks is a static interval without
//! its first and last block (settling); everything between two static intervals is a turning
//! interval. Static intervals shorter than [`DetectSettings::min_static_s`] are dropped (and
//! reported). Memory: two blocks and one accumulator per interval found.
//!
//! # Matching
//! The schedule's static positions take the static intervals in order; after the last, each
//! turning interval that starts and ends at the same pose (same outputs within
//! [`POSE_Z`] standard deviations, or the logged turning joint advanced by its whole
//! revolutions) is a rotation, matched to the rate steps in order; other turning intervals are
//! moves. Missing intervals are an error; extra ones and dropped short ones are reported.

use crate::error::RunError;
use crate::recording::Row;
use allan::{Settings, StreamingAllan};
use std::io::Read;

/// Two static intervals are at the same pose when no output's means differ by more than this
/// many standard deviations of their difference (measured noise).
pub(crate) const POSE_Z: f64 = 10.0;

/// The most intervals a detection keeps (a recording with more is not a planned calibration).
pub(crate) const MAX_INTERVALS: usize = 100_000;

/// A logged rotation matches its rate step when the turned angle is within this of the
/// step's whole revolutions, deg.
pub(crate) const ROTATION_MATCH_DEG: f64 = 5.0;

/// What a segment is.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum SegmentKind {
    /// At rest at a schedule position.
    Static,
    /// A rate step at its commanded rate, whole revolutions.
    Rate,
    /// A rotation of known total angle at an unknown rate.
    Rotation,
}

impl SegmentKind {
    /// The name as a segments file writes it.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            SegmentKind::Static => "static",
            SegmentKind::Rate => "rate",
            SegmentKind::Rotation => "rotation",
        }
    }
}

/// One segment of a segments file: samples `start..end` (0-based data rows, end exclusive)
/// belong to schedule entry `entry` (0-based: the static positions, then the rate steps).
#[derive(Debug, Clone, PartialEq)]
pub struct SegmentSpec {
    /// First sample.
    pub start: u64,
    /// One past the last sample.
    pub end: u64,
    /// Schedule entry.
    pub entry: usize,
    /// Kind.
    pub kind: SegmentKind,
    /// Its line in the segments file.
    pub line: u64,
}

/// Detection settings (defaults in [`Default`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DetectSettings {
    /// Block length, s.
    pub block_s: f64,
    /// A block rests when its sample variance is at most this times the model's white sample
    /// variance (every output with a noise model).
    pub variance_ratio: f64,
    /// A block turns when the gyro outputs show a rate above this, deg/s.
    pub turning_rate_deg_per_s: f64,
    /// A block turns when a logged angle moves by more than this, deg.
    pub still_deg: f64,
    /// Static intervals shorter than this are dropped, s (default: half the shortest dwell of
    /// the study's timing, else 1 s).
    pub min_static_s: Option<f64>,
}

impl Default for DetectSettings {
    fn default() -> Self {
        DetectSettings {
            block_s: 0.5,
            variance_ratio: 4.0,
            turning_rate_deg_per_s: 0.5,
            still_deg: 0.01,
            min_static_s: None,
        }
    }
}

/// Parse a segments file: a header `start,end,entry` (and optionally `kind`), then one row
/// per segment. `n_static` and `n_rate` are the schedule's static positions and rate steps.
///
/// # Errors
/// [`RunError::Input`] naming the line and column: a cell that is not a whole number, an
/// unknown kind, an entry outside the schedule, a kind that does not fit its entry, `start`
/// not below `end`, overlapping segments (both lines named), an entry given twice, and every
/// schedule entry without a segment.
pub fn parse_segments<R: Read>(
    reader: R,
    source: &str,
    n_static: usize,
    n_rate: usize,
) -> Result<Vec<SegmentSpec>, RunError> {
    let mut csv = csv::ReaderBuilder::new()
        .trim(csv::Trim::All)
        .comment(Some(b'#'))
        .from_reader(reader);
    let headers: Vec<String> = csv
        .headers()
        .map_err(|e| RunError::input(source, Some(1), None, e.to_string()))?
        .iter()
        .map(|h| h.trim_start_matches('\u{feff}').to_string())
        .collect();
    let col = |name: &str| headers.iter().position(|h| h == name);
    let need = |name: &str| {
        col(name).ok_or_else(|| {
            RunError::input(
                source,
                Some(1),
                None,
                format!("no column `{name}` (header: start,end,entry[,kind])"),
            )
        })
    };
    let (cs, ce, cn, ck) = (need("start")?, need("end")?, need("entry")?, col("kind"));
    let n_entries = n_static + n_rate;
    let mut specs: Vec<SegmentSpec> = Vec::new();
    for rec in csv.records() {
        let rec = rec.map_err(|e| {
            RunError::input(
                source,
                e.position().map(csv::Position::line),
                None,
                e.to_string(),
            )
        })?;
        let line = rec.position().map_or(0, csv::Position::line);
        let whole = |c: usize| -> Result<u64, RunError> {
            rec[c].parse::<u64>().map_err(|_| {
                RunError::input(
                    source,
                    Some(line),
                    Some(&headers[c]),
                    format!("`{}` is not a whole number", &rec[c]),
                )
            })
        };
        let (start, end, entry) = (whole(cs)?, whole(ce)?, whole(cn)?);
        let at = |c: usize, reason: String| {
            RunError::input(source, Some(line), Some(&headers[c]), reason)
        };
        if start >= end {
            return Err(at(ce, format!("end {end} is not after start {start}")));
        }
        let entry = usize::try_from(entry).ok().filter(|&e| e < n_entries).ok_or_else(|| {
            at(cn, format!("entry {entry} is outside the schedule (0 to {}: {n_static} static positions, then {n_rate} rate steps)", n_entries.saturating_sub(1)))
        })?;
        let is_rate = entry >= n_static;
        let kind = match ck.map(|c| rec[c].to_string()) {
            None => {
                if is_rate {
                    SegmentKind::Rate
                } else {
                    SegmentKind::Static
                }
            }
            Some(k) => match k.as_str() {
                "static" => SegmentKind::Static,
                "rate" => SegmentKind::Rate,
                "rotation" => SegmentKind::Rotation,
                "" if is_rate => SegmentKind::Rate,
                "" => SegmentKind::Static,
                other => {
                    return Err(at(
                        ck.unwrap_or(0),
                        format!("kind `{other}` is none of static, rate, rotation"),
                    ));
                }
            },
        };
        if is_rate == (kind == SegmentKind::Static) {
            return Err(at(
                ck.unwrap_or(cn),
                format!(
                    "entry {entry} is a {} but the kind is {}",
                    if is_rate {
                        "rate step"
                    } else {
                        "static position"
                    },
                    kind.name()
                ),
            ));
        }
        if let Some(prev) = specs.iter().find(|s| s.entry == entry) {
            return Err(at(
                cn,
                format!("entry {entry} already has a segment (line {})", prev.line),
            ));
        }
        specs.push(SegmentSpec {
            start,
            end,
            entry,
            kind,
            line,
        });
        if specs.len() > MAX_INTERVALS {
            return Err(RunError::input(
                source,
                Some(line),
                None,
                format!("more than {MAX_INTERVALS} segments"),
            ));
        }
    }
    specs.sort_by_key(|s| s.start);
    for w in specs.windows(2) {
        if w[1].start < w[0].end {
            return Err(RunError::input(
                source,
                Some(w[1].line),
                Some("start"),
                format!(
                    "segment overlaps the segment of line {} (samples {}..{})",
                    w[0].line, w[0].start, w[0].end
                ),
            ));
        }
    }
    let missing: Vec<String> = (0..n_entries)
        .filter(|e| !specs.iter().any(|s| s.entry == *e))
        .map(|e| e.to_string())
        .collect();
    if !missing.is_empty() {
        return Err(RunError::input(
            source,
            None,
            None,
            format!(
                "fewer segments than the schedule needs: no segment for entries {}",
                missing.join(", ")
            ),
        ));
    }
    Ok(specs)
}

/// Streaming sums of a run of samples (Welford per output; the logged angles' mean and turned
/// angle).
#[derive(Debug, Clone, Default)]
pub(crate) struct Acc {
    pub n: u64,
    pub mean: Vec<f64>,
    pub m2: Vec<f64>,
    pub start_index: u64,
    pub first_line: u64,
    pub last_line: u64,
    pub t_first: f64,
    pub t_last: f64,
    pub angle_mean: Vec<f64>,
    pub angle_first: Vec<f64>,
    pub angle_last: Vec<f64>,
    pub turned: Vec<f64>,
    pub angle_min: Vec<f64>,
    pub angle_max: Vec<f64>,
    pub saturated: u64,
}

/// `d` wrapped to (-180, 180], deg.
fn wrap_deg(d: f64) -> f64 {
    let w = d.rem_euclid(360.0);
    if w > 180.0 { w - 360.0 } else { w }
}

impl Acc {
    pub(crate) fn push(&mut self, row: &Row<'_>) {
        if self.n == 0 {
            let k = row.values.len();
            self.mean = vec![0.0; k];
            self.m2 = vec![0.0; k];
            self.start_index = row.index;
            self.first_line = row.line;
            self.t_first = row.t_s;
            if let Some(a) = row.angles_deg {
                self.angle_mean = vec![0.0; a.len()];
                self.angle_first = a.to_vec();
                self.angle_last = a.to_vec();
                self.turned = vec![0.0; a.len()];
                self.angle_min = a.to_vec();
                self.angle_max = a.to_vec();
            }
        }
        self.n += 1;
        let n = self.n as f64;
        for (k, &v) in row.values.iter().enumerate() {
            let d = v - self.mean[k];
            self.mean[k] += d / n;
            self.m2[k] += d * (v - self.mean[k]);
        }
        if let Some(a) = row.angles_deg {
            for (j, &v) in a.iter().enumerate() {
                self.turned[j] += wrap_deg(v - self.angle_last[j]);
                self.angle_last[j] = v;
                let unwrapped = self.angle_first[j] + self.turned[j];
                self.angle_mean[j] += (unwrapped - self.angle_mean[j]) / n;
                self.angle_min[j] = self.angle_min[j].min(unwrapped);
                self.angle_max[j] = self.angle_max[j].max(unwrapped);
            }
        }
        self.last_line = row.line;
        self.t_last = row.t_s;
        self.saturated += u64::from(row.saturated);
    }

    /// Append `b` (the samples right after these).
    pub(crate) fn merge(&mut self, b: &Acc) {
        if b.n == 0 {
            return;
        }
        if self.n == 0 {
            *self = b.clone();
            return;
        }
        let (na, nb) = (self.n as f64, b.n as f64);
        let n = na + nb;
        for k in 0..self.mean.len() {
            let d = b.mean[k] - self.mean[k];
            self.mean[k] += d * nb / n;
            self.m2[k] += b.m2[k] + d * d * na * nb / n;
        }
        for j in 0..self.turned.len() {
            let step = wrap_deg(b.angle_first[j] - self.angle_last[j]);
            let offset = self.turned[j] + step - b.angle_first[j] + self.angle_first[j];
            // b's unwrapped angles in self's frame: b.first + offset + b's own turn
            let b_mean =
                b.angle_mean[j] - b.angle_first[j] + (self.angle_first[j] + self.turned[j] + step);
            self.angle_mean[j] = (self.angle_mean[j] * na + b_mean * nb) / n;
            self.angle_min[j] = self.angle_min[j].min(b.angle_min[j] + offset);
            self.angle_max[j] = self.angle_max[j].max(b.angle_max[j] + offset);
            self.turned[j] += step + b.turned[j];
            self.angle_last[j] = b.angle_last[j];
        }
        self.n += b.n;
        self.last_line = b.last_line;
        self.t_last = b.t_last;
        self.saturated += b.saturated;
    }

    pub(crate) fn variance(&self, k: usize) -> f64 {
        if self.n > 1 {
            self.m2[k] / (self.n - 1) as f64
        } else {
            0.0
        }
    }
}

/// A static interval's accumulator with its Allan estimators (one per output).
pub(crate) struct StaticAcc {
    pub acc: Acc,
    pub allan: Vec<StreamingAllan>,
}

impl StaticAcc {
    pub(crate) fn new(outputs: usize, rate_hz: f64) -> Result<Self, RunError> {
        let allan = (0..outputs)
            // only the white density and the floor are read (`estimate::pool`)
            .map(|_| StreamingAllan::new(Settings::new(rate_hz).without_gauss_markov()))
            .collect::<Result<Vec<_>, _>>()
            .map_err(|e| RunError::Internal(format!("Allan deviation: {e}")))?;
        Ok(Self {
            acc: Acc::default(),
            allan,
        })
    }

    pub(crate) fn push_values(&mut self, values: &[f64]) {
        for (a, &v) in self.allan.iter_mut().zip(values) {
            // finite by the reader's check
            let _ = a.push(v);
        }
    }

    /// Push a block given per output (`columns[k]`: output k's samples in order).
    pub(crate) fn extend_columns(&mut self, columns: &[Vec<f64>]) {
        for (a, c) in self.allan.iter_mut().zip(columns) {
            // finite by the reader's check
            let _ = a.extend(c);
        }
    }
}

/// How each block is judged at rest.
#[derive(Debug, Clone)]
pub(crate) struct BlockTest {
    /// Per output: the model's white sample variance (None: not used).
    pub white_var: Vec<Option<f64>>,
    pub variance_ratio: f64,
    /// (output, rate input 0..3, coefficient in output unit per deg/h)
    pub rate_channels: Vec<(usize, usize, f64)>,
    pub turning_rate_deg_per_h: f64,
    pub still_deg: f64,
}

impl BlockTest {
    fn rests(&self, b: &Acc) -> bool {
        for (k, w) in self.white_var.iter().enumerate() {
            if let Some(w) = w {
                if b.variance(k) > self.variance_ratio * w {
                    return false;
                }
            }
        }
        let mut w = [0.0f64; 3];
        let mut any = false;
        for &(k, q, c) in &self.rate_channels {
            w[q] = b.mean[k] / c;
            any = true;
        }
        if any && (w[0] * w[0] + w[1] * w[1] + w[2] * w[2]).sqrt() > self.turning_rate_deg_per_h {
            return false;
        }
        for j in 0..b.angle_min.len() {
            if b.angle_max[j] - b.angle_min[j] > self.still_deg {
                return false;
            }
        }
        true
    }
}

/// The detector's result: static intervals and the turning intervals around them
/// (`turns.len() == statics.len() + 1`: `turns[j]` comes before `statics[j]`).
pub(crate) struct Detected {
    pub statics: Vec<StaticAcc>,
    pub turns: Vec<Acc>,
    /// Dropped short static intervals: (first line, last line, duration s).
    pub dropped: Vec<(u64, u64, f64)>,
}

/// The streaming detector.
pub(crate) struct Detector {
    test: BlockTest,
    block_n: u64,
    min_static_s: f64,
    rate_hz: f64,
    outputs: usize,
    block: Acc,
    block_values: Vec<Vec<f64>>,
    held: Option<(Acc, Vec<Vec<f64>>)>,
    run_len: u64,
    seg: Option<StaticAcc>,
    turn: Acc,
    out: Detected,
}

impl Detector {
    pub(crate) fn new(
        test: BlockTest,
        block_s: f64,
        min_static_s: f64,
        rate_hz: f64,
        outputs: usize,
    ) -> Self {
        let block_n = ((block_s * rate_hz).round() as u64).max(3);
        Self {
            test,
            block_n,
            min_static_s,
            rate_hz,
            outputs,
            block: Acc::default(),
            block_values: vec![Vec::with_capacity(block_n as usize); outputs],
            held: None,
            run_len: 0,
            seg: None,
            turn: Acc::default(),
            out: Detected {
                statics: Vec::new(),
                turns: Vec::new(),
                dropped: Vec::new(),
            },
        }
    }

    pub(crate) fn push(&mut self, row: &Row<'_>) -> Result<(), RunError> {
        self.block.push(row);
        for (c, &v) in self.block_values.iter_mut().zip(row.values) {
            c.push(v);
        }
        if self.block.n == self.block_n {
            self.finish_block()?;
        }
        Ok(())
    }

    fn finish_block(&mut self) -> Result<(), RunError> {
        let block = std::mem::take(&mut self.block);
        let values = std::mem::replace(
            &mut self.block_values,
            vec![Vec::with_capacity(self.block_n as usize); self.outputs],
        );
        if block.n == self.block_n && self.test.rests(&block) {
            self.run_len += 1;
            if self.run_len == 1 {
                self.turn.merge(&block);
            } else {
                if let Some((h, hv)) = self.held.take() {
                    if self.seg.is_none() {
                        if self.out.statics.len() >= MAX_INTERVALS {
                            return Err(RunError::Segments {
                                reason: format!(
                                    "more than {MAX_INTERVALS} static intervals detected: not a planned calibration (give a segments file)"
                                ),
                            });
                        }
                        self.out.turns.push(std::mem::take(&mut self.turn));
                        self.seg = Some(StaticAcc::new(self.outputs, self.rate_hz)?);
                    }
                    let s = self.seg.as_mut().expect("opened above");
                    s.acc.merge(&h);
                    s.extend_columns(&hv);
                }
                self.held = Some((block, values));
            }
        } else {
            self.end_run();
            self.turn.merge(&block);
        }
        Ok(())
    }

    fn end_run(&mut self) {
        if self.run_len == 0 {
            return;
        }
        self.run_len = 0;
        let held = self.held.take();
        if let Some(seg) = self.seg.take() {
            let dur = seg.acc.n as f64 / self.rate_hz;
            if dur < self.min_static_s {
                self.out
                    .dropped
                    .push((seg.acc.first_line, seg.acc.last_line, dur));
                let mut prev = self.out.turns.pop().unwrap_or_default();
                prev.merge(&seg.acc);
                prev.merge(&self.turn);
                self.turn = prev;
            } else {
                self.out.statics.push(seg);
            }
        }
        if let Some((h, _)) = held {
            self.turn.merge(&h);
        }
    }

    pub(crate) fn finish(mut self) -> Result<Detected, RunError> {
        if self.block.n > 0 {
            // a partial block never rests
            let block = std::mem::take(&mut self.block);
            self.end_run();
            self.turn.merge(&block);
        } else {
            self.end_run();
        }
        self.out.turns.push(self.turn);
        Ok(self.out)
    }
}
