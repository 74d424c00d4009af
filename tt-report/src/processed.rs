//! The report's section for a processed run (`report --recording`): the recording, every
//! coefficient's estimate with its expanded uncertainty, the plan's predicted standard
//! uncertainty beside the run's observed ones, the verdicts under their named rule, the
//! segments, and two figures (the recording with its segments; the residuals).

use crate::Result;
use crate::doc;
use crate::figures::{self, Envelope, Residuals, Span};
use crate::render::Sections;
use tt_core::human::sig;
use tt_lab::calibrate::CalibrationAnswer;

/// A recording processed for the report: tt-lab's answer (with an overview of the recording,
/// [`tt_lab::calibrate::Options::overview_buckets`]) and the flags that reproduce it.
#[derive(Debug, Clone)]
pub struct ProcessedRun {
    pub(crate) answer: CalibrationAnswer,
    pub(crate) flags: Vec<String>,
}

impl ProcessedRun {
    /// `answer` from [`tt_lab::calibrate::calibrate`]; `flags`: the command line's recording
    /// flags as given (`--recording LOG.csv --robust ...`), for the report's "Reproduce"
    /// line (each is shell-quoted there).
    #[must_use]
    pub fn new(answer: CalibrationAnswer, flags: Vec<String>) -> Self {
        Self { answer, flags }
    }

    /// The answer.
    #[must_use]
    pub fn answer(&self) -> &CalibrationAnswer {
        &self.answer
    }

    /// The flags as given.
    #[must_use]
    pub(crate) fn flags(&self) -> &[String] {
        &self.flags
    }
}

/// `-` for a missing number.
fn opt(v: Option<f64>) -> String {
    v.map_or("-".into(), |v| sig(v, 3))
}

impl Sections<'_> {
    /// The processed run's section (nothing without one).
    ///
    /// # Errors
    /// When a figure cannot be drawn.
    pub(crate) fn processed_run(&mut self) -> Result<()> {
        let c = self.c;
        let Some(pr) = &c.options.run else {
            return Ok(());
        };
        let a = &pr.answer;
        let run = a.run();
        let r = run.recording();
        let robust = run
            .outputs()
            .iter()
            .any(|o| o.coefficients().iter().any(|k| k.robust_change().is_some()));
        self.doc.h(2, "Processed run");
        self.doc.p(format!(
            "The recording {} (SHA-256 {}): {} samples, {} s at {} Hz{}; {} segments matched to the schedule. Each output's coefficients by weighted least squares on the segment averages (the `calib-run` crate, as {}); the expanded uncertainty is a GUM budget at coverage {} (the noise as measured, the table's part from a tolerance sheet when one is given).",
            doc::code(&r.source),
            doc::code(&r.sha256),
            r.samples,
            sig(r.duration_s, 6),
            sig(1.0 / r.dt_s, 6),
            if r.angles_logged {
                ", the table's angles logged"
            } else {
                ""
            },
            run.segments().len(),
            doc::code("ttalloc calibrate"),
            sig(run.coverage(), 3)
        ));
        if !run.warnings().is_empty() {
            self.doc.callout_list(
                "Warnings (mismatches with the schedule, saturation, dropped intervals):",
                run.warnings().iter().map(|w| doc::text(w)).collect(),
            );
        }
        let mut rows = Vec::new();
        for o in run.outputs() {
            for k in o.coefficients() {
                let (u, kf) = k.expanded();
                let mut row = vec![
                    doc::code(o.name()),
                    doc::code(k.name()),
                    format!("{} {}", sig(k.value(), 6), doc::text(k.unit())),
                    format!("{} (k = {})", sig(u, 3), sig(kf, 3)),
                    opt(k.predicted_u()),
                    sig(k.u_measured_noise(), 3),
                    opt(k.u_residuals()),
                    sig(k.u_table(), 3),
                    sig(k.u_combined(), 3),
                ];
                if robust {
                    row.push(opt(k.robust_change()));
                }
                rows.push(row);
            }
        }
        self.doc.p("Predicted against observed: the plan's standard uncertainty (the study's noise over its timing; `-` without a timing) beside the run's, from its measured noise and from its residuals (the Birge ratio times the first; `-` with no degrees of freedom), with the table's part and the combination.");
        let mut header = vec![
            "output",
            "coefficient",
            "estimate",
            "expanded uncertainty U",
            "predicted u (plan)",
            "observed u (measured noise)",
            "observed u (residuals)",
            "u (table)",
            "combined u",
        ];
        if robust {
            header.push("robust fit moved it by");
        }
        self.doc.table(&header, rows);
        let notes: Vec<String> = run
            .outputs()
            .iter()
            .flat_map(|o| {
                o.notes()
                    .iter()
                    .map(move |n| format!("{}: {}", doc::code(o.name()), doc::text(n)))
            })
            .collect();
        if !notes.is_empty() {
            self.doc.p(if robust {
                "What the robust (Huber) fit changed, and other notes of the estimate:"
            } else {
                "Notes of the estimate:"
            });
            self.doc.list(notes);
        }
        if a.verdicts().is_empty() {
            self.doc
                .p("No specification judged on this run (none in the study, no `--spec`).");
        } else {
            self.doc.p(format!(
                "Specifications, each under the decision rule it names ({} verdicts):",
                a.verdicts().len()
            ));
            self.doc.list(
                a.verdicts()
                    .iter()
                    .map(|v| doc::text(&v.statement))
                    .collect(),
            );
        }
        if !a.specification_notes().is_empty() {
            self.doc
                .p("Specifications of the study not judged on one run:");
            self.doc.list(
                a.specification_notes()
                    .iter()
                    .map(|n| doc::text(n))
                    .collect(),
            );
        }
        self.segment_table();
        self.run_figures()
    }

    fn segment_table(&mut self) {
        let run = self.c.options.run.as_ref().map(|p| p.answer.run());
        let Some(run) = run else { return };
        let rows = run
            .segments()
            .iter()
            .enumerate()
            .map(|(i, s)| {
                let (start, n) = s.range();
                let (t0, dur) = s.time_s();
                let flagged: Vec<String> = run
                    .outputs()
                    .iter()
                    .filter_map(|o| {
                        o.residuals()
                            .iter()
                            .find(|x| x.segment == i && x.outlier)
                            .map(|x| {
                                format!("{} z = {}", doc::code(o.name()), sig(x.standardized, 3))
                            })
                    })
                    .collect();
                vec![
                    (i + 1).to_string(),
                    s.entry().to_string(),
                    s.kind().name().to_string(),
                    format!("{start}..{}", start + n),
                    sig(t0, 6),
                    sig(dur, 4),
                    if flagged.is_empty() {
                        "-".into()
                    } else {
                        flagged.join(", ")
                    },
                ]
            })
            .collect();
        self.doc.p(format!(
            "The segments (schedule entry: the static positions in the study's order, then the rate steps; samples are 0-based data rows, the end exclusive; an outlier is a standardized residual beyond {}):",
            calib_run::OUTLIER_Z
        ));
        self.doc.table(
            &[
                "segment",
                "entry",
                "kind",
                "samples",
                "start (s)",
                "duration (s)",
                "outliers",
            ],
            rows,
        );
    }

    fn run_figures(&mut self) -> Result<()> {
        let c = self.c;
        let Some(pr) = &c.options.run else {
            return Ok(());
        };
        let run = pr.answer.run();
        let spans: Vec<Span> = run
            .segments()
            .iter()
            .map(|s| {
                let (t0, dur) = s.time_s();
                Span {
                    t0_s: t0,
                    t1_s: t0 + dur,
                    label: s.entry().to_string(),
                    is_static: s.kind() == calib_run::segments::SegmentKind::Static,
                }
            })
            .collect();
        if let Some(ov) = pr.answer.overview() {
            let channels: Vec<Envelope> = c
                .study
                .sensor
                .outputs()
                .iter()
                .enumerate()
                .map(|(k, o)| Envelope {
                    title: o.name.clone(),
                    y_label: format!("{} ({})", o.name, o.unit),
                    unit: o.unit.clone(),
                    buckets: ov
                        .buckets()
                        .iter()
                        .map(|b| (b.t_first_s, b.t_last_s, b.min[k], b.max[k]))
                        .collect(),
                })
                .collect();
            let svg =
                figures::recording_figure("The recording and its segments", &channels, &spans)?;
            self.doc.figure(
                "fig_run_segments.svg",
                format!(
                    "Every output over the recording (its minimum and maximum in {} buckets of {} samples, kept while the recording streamed), each segment's span shaded (blue static, orange turning) and labelled with its schedule entry. Where an output's recording spans more than {} times its static levels' range (a gyro's rotations), its axis fits the static levels: the turning parts are clipped at the axis edge, marked red, and the panel's title states how far they reach.",
                    ov.buckets().len(),
                    ov.samples_per_bucket(),
                    figures::CLIP_FACTOR
                ),
                svg,
            );
        }
        let outputs: Vec<Residuals> = run
            .outputs()
            .iter()
            .map(|o| Residuals {
                label: o.name().to_string(),
                points: o
                    .residuals()
                    .iter()
                    .map(|x| ((x.segment + 1) as f64, x.standardized, x.outlier))
                    .collect(),
            })
            .filter(|r| !r.points.is_empty())
            .collect();
        if !outputs.is_empty() {
            let svg = figures::residual_figure(
                "Standardized residuals per segment",
                &outputs,
                calib_run::OUTLIER_Z,
            )?;
            self.doc.figure(
                "fig_run_residuals.svg",
                format!(
                    "Each output's residual per segment divided by its standard deviation (the measured noise and the leverage); beyond ±{} (dashed) a segment is an outlier, marked in red.",
                    calib_run::OUTLIER_Z
                ),
                svg,
            );
        }
        Ok(())
    }
}
