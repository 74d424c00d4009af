//! The report's sections for any study: formatting of what [`crate::compute`] computed
//! (no science here: every number comes from a library result).

use crate::Result;
use crate::compute::{Computed, OutputPlane, TwoStep};
use crate::doc::{self, Doc};
use crate::figures::{self, HeatPanel, HistPanel, LIMIT, LinePanel, Mark, Series, colour};
use calib_lsq::{CalibError, OrientationRequirement, Reading};
use e2e_verify::{BoxAnswer, BoxMeets, ReadingAnswer, Verdict, YieldVerdict};
use std::fmt::Write as _;
use tt_core::human::{exact, num, sig};
use tt_core::units::objective_to_arcmin;
use tt_core::units::{rad_to_arcmin, rad_to_deg};
use tt_kinematics::{Factor, OrientationAxis};

/// Greek letter of angle `k` (ψ, θ, γ).
#[must_use]
pub(crate) fn greek(k: usize) -> &'static str {
    ["ψ", "θ", "γ"][k.min(2)]
}

/// `Δψ`, `Δθ`, `Δγ`.
#[must_use]
pub(crate) fn d(k: usize) -> String {
    format!("Δ{}", greek(k))
}

/// A unit label for people: `deg_per_h` → `deg/h`.
#[must_use]
pub(crate) fn unit(u: &str) -> String {
    u.replace("_per_", "/")
        .replace("/(g)", "/g")
        .replace("^2", "²")
        .replace("^3", "³")
}

/// A short name of a reading for headers: `intended`/`actual` for the paper's and the user's.
#[must_use]
pub(crate) fn short_reading(r: Reading) -> String {
    if r == Reading::PAPER {
        "intended".into()
    } else if r == Reading::USER {
        "actual".into()
    } else {
        r.to_string()
    }
}

/// A `note: ...` line as a sentence.
fn sentence(note: &str) -> String {
    let t = note.trim_start_matches("note: ");
    let mut c = t.chars();
    match c.next() {
        Some(f) => format!(
            "Note: {}{}.",
            f.to_uppercase(),
            c.as_str().trim_end_matches('.')
        ),
        None => String::new(),
    }
}

/// A joint's name for people: a leading `phi` becomes φ and trailing digits subscripts
/// (`phi1` → `φ₁`, `phi_o` → `φ_o`); other names as written.
#[must_use]
pub(crate) fn joint(name: &str) -> String {
    match name.strip_prefix("phi") {
        Some(rest) if rest.chars().all(|c| c.is_ascii_digit()) => {
            let sub: String = rest
                .chars()
                .map(|c| char::from_u32(0x2080 + c.to_digit(10).unwrap_or(0)).unwrap_or(c))
                .collect();
            format!("φ{sub}")
        }
        Some(rest) if rest.starts_with('_') => format!("φ{rest}"),
        _ => name.to_string(),
    }
}

/// `yes`, or `**no**` (coloured in HTML).
fn verdict_md(v: Verdict) -> String {
    match v {
        Verdict::Guaranteed => "**meets** (proven)".into(),
        Verdict::Likely => "likely meets".into(),
        Verdict::Fails => "does **not** meet".into(),
    }
}

fn yes_no(b: bool) -> String {
    if b { "**yes**".into() } else { "**no**".into() }
}

fn pct(v: f64) -> String {
    format!("{:.1}%", 100.0 * v)
}

/// The requirement as `I_ψ = … deg, …` (`none` for an unconstrained angle).
pub(crate) fn requirement_text(r: &[Option<f64>; 3]) -> String {
    (0..3)
        .map(|k| {
            format!(
                "I_{} = {}",
                greek(k),
                r[k].map_or("none".into(), |v| format!("{} deg", num(rad_to_deg(v))))
            )
        })
        .collect::<Vec<_>>()
        .join(", ")
}

fn reading_words(r: Reading) -> &'static str {
    if r.needs_actual_outputs() {
        "outputs simulated at the actual orientation, what a calibrating lab measures"
    } else {
        "outputs simulated at the intended orientation"
    }
}

/// Whether a box's worst turntable meets every accuracy: [`e2e_verify::BoxMeets`]'s words
/// (the same as `end-to-end`'s), with the verdict word in bold.
fn meets_md(m: BoxMeets) -> String {
    let words = m.to_string();
    match m {
        BoxMeets::Yes => format!("**{words}**"),
        BoxMeets::FirstOrderOnly { .. } | BoxMeets::No { .. } => words.replacen("no", "**no**", 1),
    }
}

/// The groups of errors that act only together, one line each ([`tt_lab::groups::sentence`]),
/// with the bound of their combination under each labelled box; nothing when there is none.
fn group_list(doc: &mut Doc, t: &tt_kinematics::Turntable, bounds: &[(&str, &[f64])]) {
    let lines = tt_lab::groups::lines(t, bounds);
    if !lines.is_empty() {
        doc.list(lines);
    }
}

/// The verdict on a vendor's sheet with its Monte Carlo yield: one wording for the answer at
/// the top and the vendor section.
fn sheet_verdict(chk: &e2e_verify::TurntableCheck) -> String {
    let (lo, hi) = chk.distribution().count().interval_95();
    let verdict = match chk.verdict() {
        Verdict::Guaranteed => {
            "these tolerances **meet** every accuracy: proven for every turntable within them"
        }
        Verdict::Likely => {
            "these tolerances likely meet every accuracy: the worst turntable does, but no bound proves it for the whole box"
        }
        Verdict::Fails => {
            "these tolerances do **not** meet every accuracy: a turntable within them (the worst vertex) misses"
        }
    };
    format!(
        "{verdict}; {:.2}% of {} random turntables meet every accuracy (95% interval {:.2}%-{:.2}%)",
        100.0 * chk.distribution().count().fraction(),
        chk.distribution().count().samples(),
        100.0 * lo,
        100.0 * hi
    )
}

/// `text` with its first letter in upper case.
fn upper_first(text: &str) -> String {
    let mut c = text.chars();
    c.next()
        .map_or(String::new(), |f| f.to_uppercase().chain(c).collect())
}

/// `text` with its first letter in lower case.
fn lower_first(text: &str) -> String {
    let mut c = text.chars();
    c.next()
        .map_or(String::new(), |f| f.to_lowercase().chain(c).collect())
}

/// The paper's Table 4 beside the allocation: bounds (arcmin), J (arcmin⁻²), shares of the
/// requirement.
pub(crate) type PaperColumn = (Vec<f64>, f64, [Option<f64>; 3]);

/// Context shared by the sections.
pub(crate) struct Sections<'a> {
    /// The computed report.
    pub c: &'a Computed,
    /// The document.
    pub doc: Doc,
    /// CSV files.
    pub csv: Vec<(String, String)>,
    /// Anchors of the figures by key (for links from the paper's claims table).
    pub figure_ids: Vec<(&'static str, String)>,
}

impl<'a> Sections<'a> {
    /// A new renderer of `c`.
    #[must_use]
    pub(crate) fn new(c: &'a Computed) -> Self {
        Self {
            c,
            doc: Doc::default(),
            csv: Vec::new(),
            figure_ids: Vec::new(),
        }
    }

    fn outputs(&self) -> Vec<(String, String, f64)> {
        self.c
            .study
            .sensor
            .outputs()
            .iter()
            .map(|o| (o.name.clone(), doc::text(&unit(&o.unit)), o.accuracy))
            .collect()
    }

    /// The anchor of a figure by key.
    #[must_use]
    pub(crate) fn figure(&self, key: &str) -> Option<&str> {
        self.figure_ids
            .iter()
            .find(|(k, _)| *k == key)
            .map(|(_, id)| id.as_str())
    }

    /// The answer in a few sentences (the top of the report): one bullet per reading.
    pub(crate) fn answer_callout(&mut self) {
        let c = self.c;
        let acc = c.e2e.accuracies();
        let outs = self.outputs();
        // a study with rate steps: the two-step allocation is not made (the requirement is a
        // static concept), so the answer never states its verdict
        let rate_steps = c.study.has_rate_steps();
        let two = c
            .two_step
            .as_ref()
            .filter(|_| !rate_steps)
            .map(|t| t.ours.objective_arcmin());
        let mut items = Vec::new();
        for (i, r) in c.answer.readings().iter().enumerate() {
            let mut s = format!(
                "Reading `{}`{} ({}): ",
                r.reading(),
                if i == 0 { ", the study's" } else { "" },
                reading_words(r.reading())
            );
            if let Some(b) = r
                .boxes()
                .iter()
                .find(|b| b.name() == "two-step" && !rate_steps)
            {
                let ok = b.worst_case().meets(&acc).holds();
                let worst = tt_lab::end_to_end::worst_turntable_words(b, |k, v| {
                    format!("{} {} {}", outs[k].0, sig(v, 4), outs[k].1)
                });
                let _ = write!(
                    s,
                    "the two-step allocation (J = {:.2} arcmin⁻²) {} every output's accuracy (worst turntable {}; {} of random turntables meet them); ",
                    objective_to_arcmin(b.objective()),
                    if ok { "**meets**" } else { "**does not meet**" },
                    worst,
                    pct(b.distribution().count().fraction())
                );
            }
            let j = r.direct().objective_arcmin();
            if r.direct().no_bound_needed() {
                s.push_str(e2e_verify::NO_BOUND_NEEDED);
            } else {
                let _ = write!(
                    s,
                    "the direct allocation against every accuracy needs J = {j:.2} arcmin⁻²"
                );
            }
            if let (Some(t), false) = (two, r.direct().no_bound_needed()) {
                let ratio = t / j;
                if ratio >= 1.0 {
                    let _ = write!(
                        s,
                        ", {}× looser than the two-step allocation",
                        sig(ratio, 3)
                    );
                } else {
                    let _ = write!(
                        s,
                        ", {}× tighter than the two-step allocation",
                        sig(1.0 / ratio, 3)
                    );
                }
            }
            s.push('.');
            items.push(s);
        }
        if let Some(ra) = &c.rate_alloc {
            items.push(format!(
                "With the rate steps' own errors (reading `{}`): the direct allocation with the rate tolerances (the angles, the rate accuracy, the rate ripple and the translations together) needs J = {:.2} arcmin⁻² over both.",
                c.e2e.reading(),
                ra.allocation.combined().objective_arcmin()
            ));
        }
        if c.vendor.is_some() {
            // the allocations answer another question than the sheet's: a comparison
            for i in &mut items {
                *i = format!("For comparison, {}", lower_first(i));
            }
        }
        // (with rate steps the two-step allocation is not made: the question above says so)
        if c.two_step.is_none() && !rate_steps {
            items.push(if c.vendor.is_some() {
                "No output constrains a constant orientation error, so there is no two-step allocation.".into()
            } else {
                "No output constrains a constant orientation error, so there is no two-step allocation: the direct allocation is the answer.".into()
            });
        }
        if let Some(n) = &c.requirement.disagreement {
            items.push(sentence(n));
        }
        let allocation_question = "Does a turntable allocated by the two-step method (an orientation requirement first, then the turntable against it) deliver every output's accuracy, and what does the direct allocation against those accuracies ask of the table (J: lower is a looser, cheaper table)?";
        let lead = match &c.vendor {
            // the user's question comes first: the verdict on their sheet
            Some((tol, chk)) => {
                items.insert(0, self.sheet_outputs(chk));
                format!(
                    "**Answer.** Do the tolerances of {}{} deliver every output's accuracy? {}.{}",
                    doc::code(tol.source()),
                    tol.name()
                        .map_or(String::new(), |n| format!(" ({})", doc::text(n))),
                    upper_first(&sheet_verdict(chk)),
                    c.vendor_rate.as_ref().map_or(String::new(), |r| {
                        format!(
                            " The study has rate steps, and with the sheet's rate errors and translations: {}.",
                            verdict_sentence(&c.e2e, r)
                        )
                    })
                )
            }
            None if rate_steps => "**Answer.** What does the direct allocation against every output's accuracy ask of the table (J: lower is a looser, cheaper table)? The study has rate steps, so the two-step allocation (an orientation requirement first) is not made.".into(),
            None => format!("**Answer.** {allocation_question}"),
        };
        self.doc.callout_list(lead, items);
    }

    /// Inputs: site, reading, sensor, turntable, schedule.
    pub(crate) fn inputs(&mut self) {
        let c = self.c;
        let s = &c.study;
        self.doc.h(2, "Inputs");
        let lb_nonzero: Vec<String> = s
            .turntable
            .rotation_error_names()
            .iter()
            .zip(&s.lower_bounds_rad)
            .filter(|(_, l)| **l > 0.0)
            .map(|(n, l)| format!("`{n}` {} arcmin", num(rad_to_arcmin(*l))))
            .collect();
        let req = match (&c.requirement.given, c.requirement.used) {
            (true, Some(r)) => format!("given in the study: {}", requirement_text(&r.to_array())),
            (false, Some(r)) => format!(
                "computed from the calibration inputs: {}",
                requirement_text(&r.to_array())
            ),
            (_, None) => "none (no output constrains a constant orientation error)".into(),
        };
        self.doc.table(
            &["input", "value"],
            vec![
                vec![
                    "study".into(),
                    format!("{} ({})", doc::code(&s.name), doc::code(&s.path)),
                ],
                vec![
                    "description".into(),
                    s.description
                        .as_deref()
                        .map_or_else(|| "-".into(), doc::text),
                ],
                vec![
                    "site".into(),
                    format!(
                        "latitude {} deg, earth rate {} rad/s",
                        num(s.site.latitude_deg()),
                        sig(s.site.earth_rate_rad_per_s(), 8)
                    ),
                ],
                vec![
                    "reading of eq 13".into(),
                    format!(
                        "`{}`: {}, error vector `{}`",
                        s.reading,
                        reading_words(s.reading),
                        s.reading.formula()
                    ),
                ],
                vec!["ΔR of eq 7".into(), s.delta_r_kind.name().into()],
                vec![
                    "calibration positions".into(),
                    s.positions_deg.len().to_string(),
                ],
                vec!["requirement handed to the two-step allocation".into(), req],
                vec![
                    "lower bounds LB_i".into(),
                    if lb_nonzero.is_empty() {
                        "0 for every error".into()
                    } else {
                        format!("{} (0 for the others)", lb_nonzero.join(", "))
                    },
                ],
                vec![
                    "Monte Carlo".into(),
                    format!(
                        "{} turntables per box, seed {}",
                        c.options.samples, c.options.seed
                    ),
                ],
            ],
        );
        if let Some(n) = &c.requirement.disagreement {
            self.doc.callout(sentence(n));
        }
        self.inputs_sensor();
        self.inputs_turntable();
        self.inputs_schedule();
    }

    /// Inputs: the sensor's terms (and `sensor_terms.csv`).
    fn inputs_sensor(&mut self) {
        let s = &self.c.study;
        self.doc.h(3, "Sensor");
        let mut rows = Vec::new();
        let mut csv = String::from(
            "output,coefficient,regressor,value,unit,estimated,accuracy,output_unit\n",
        );
        for o in s.sensor.outputs() {
            for t in &o.terms {
                rows.push(vec![
                    format!("`{}`", o.name),
                    format!("`{}`", t.coefficient),
                    format!("`{}`", t.regressor),
                    num(t.value),
                    doc::text(&unit(&o.coefficient_unit(t))),
                    if t.known {
                        "known".into()
                    } else {
                        "estimated".into()
                    },
                ]);
                let _ = writeln!(
                    csv,
                    "{},{},{},{},{},{},{},{}",
                    o.name,
                    t.coefficient,
                    t.regressor,
                    exact(t.value),
                    csv_field(&o.coefficient_unit(t)),
                    !t.known,
                    exact(o.accuracy),
                    csv_field(&o.unit)
                );
            }
        }
        let acc: Vec<String> = s
            .sensor
            .outputs()
            .iter()
            .map(|o| {
                format!(
                    "`{}` {} {}",
                    o.name,
                    num(o.accuracy),
                    doc::text(&unit(&o.unit))
                )
            })
            .collect();
        self.doc.p(format!(
            "{} outputs, each linear in its coefficients; the calibration must reach the accuracy ω_m of every output: {}. Written to `sensor_terms.csv`.",
            s.sensor.n_outputs(),
            acc.join(", ")
        ));
        self.doc.table(
            &[
                "output",
                "coefficient",
                "regressor",
                "nominal value",
                "unit",
                "role",
            ],
            rows,
        );
        self.csv.push(("sensor_terms.csv".into(), csv));
    }

    /// Inputs: the turntable's factors and its groups of errors that act only together.
    fn inputs_turntable(&mut self) {
        let s = &self.c.study;
        self.doc.h(3, "Turntable");
        let mut rows = Vec::new();
        let joints = s.turntable.joints();
        for (i, f) in s.turntable.factors().iter().enumerate() {
            let (name, kind, axis) = match f {
                Factor::Joint { joint, about } => (
                    joints[*joint].name.clone(),
                    "joint",
                    format!("about {about}"),
                ),
                Factor::Rotation { error, about } => (
                    s.turntable.rotation_errors()[*error].name.clone(),
                    "angular error",
                    format!("about {about}"),
                ),
                Factor::Translation { error, along } => (
                    s.turntable.translation_errors()[*error].name.clone(),
                    "translation error",
                    format!("along {along}"),
                ),
                Factor::Fixed { angle_rad, about } => (
                    format!("{} deg", num(rad_to_deg(*angle_rad))),
                    "fixed rotation",
                    format!("about {about}"),
                ),
            };
            let desc = s
                .turntable
                .description_of(&name)
                .map_or_else(|| "-".into(), doc::text);
            rows.push(vec![
                (i + 1).to_string(),
                format!("`{name}`"),
                kind.into(),
                axis,
                desc,
            ]);
        }
        self.doc.p(format!(
            "Factors from the base to the platform, each about (or along) an axis of the current frame: {} joints, {} angular errors (the vector χ), {} translation errors.",
            s.turntable.n_joints(),
            s.turntable.n_rotation_errors(),
            s.turntable.n_translation_errors()
        ));
        self.doc
            .table(&["#", "factor", "kind", "axis", "description"], rows);
        if !s.turntable.proportional_groups().is_empty() {
            self.doc.p("Errors that act only together: rotations about one axis with nothing but other errors between them (or a joint about that axis, as a wobble about the next joint's axis and that joint's position error) are one rotation to first order at every pose, so no calibration can tell them apart and the shares, allocations and verdicts below treat each such group as one:");
            group_list(&mut self.doc, &s.turntable, &[]);
        }
    }

    /// Inputs: the schedule's positions (and `schedule.csv`).
    fn inputs_schedule(&mut self) {
        let s = &self.c.study;
        self.doc.h(3, "Schedule");
        let jn = s.turntable.joint_names();
        let mut csv = format!(
            "position,{}\n",
            jn.iter()
                .map(|j| format!("{j}_deg"))
                .collect::<Vec<_>>()
                .join(",")
        );
        let mut items = Vec::new();
        for (i, p) in s.positions_deg.iter().enumerate() {
            let _ = writeln!(
                csv,
                "{},{}",
                i + 1,
                p.iter().map(|v| exact(*v)).collect::<Vec<_>>().join(",")
            );
            items.push(format!(
                "{}: ({})",
                i + 1,
                p.iter().map(|v| num(*v)).collect::<Vec<_>>().join(", ")
            ));
        }
        self.doc.p(format!(
            "{} test positions, joint angles ({}) in deg; written to `schedule.csv`: {}.",
            s.positions_deg.len(),
            jn.iter().map(|j| joint(j)).collect::<Vec<_>>().join(", "),
            items.join("; ")
        ));
        self.csv.push(("schedule.csv".into(), csv));
    }

    /// Identifiability and condition numbers.
    pub(crate) fn calibration(&mut self) {
        let c = self.c;
        self.doc
            .h(2, "Calibration: identifiability and conditioning");
        let mut rows = Vec::new();
        for o in c.study.calibration.outputs() {
            let r = o.regression();
            let sv = r.singular_values();
            let (lo, hi) = (
                sv.iter().copied().fold(f64::INFINITY, f64::min),
                sv.iter().copied().fold(0.0_f64, f64::max),
            );
            rows.push(vec![
                format!("`{}`", o.output().name),
                r.names().len().to_string(),
                r.rank().to_string(),
                sig(r.condition_number(), 4),
                format!("{} / {}", sig(lo, 4), sig(hi, 4)),
            ]);
        }
        self.doc.p(format!(
            "Least squares over the {} positions (eq 5-6): every output's estimated coefficients are identifiable (full column rank; the study is rejected otherwise). The condition number of the regression matrix A (ratio of its largest to smallest singular value, by an SVD of R) says how much the schedule amplifies errors into the coefficients.",
            c.study.positions_deg.len()
        ));
        self.doc.table(
            &[
                "output",
                "estimated coefficients",
                "rank",
                "condition number",
                "smallest / largest singular value",
            ],
            rows,
        );
    }

    /// The orientation requirement and its figures.
    pub(crate) fn requirement(&mut self) -> Result<()> {
        let c = self.c;
        let outs = self.outputs();
        self.doc.h(2, "Orientation requirement (eq 15-16)");
        self.doc.p(format!(
            "Under one constant orientation error (Δψ, Δθ, Δγ) at every test position, the calibration's rate error Δω of each output depends on the angles; the requirement is the largest box |Δψ| ≤ I_ψ, |Δθ| ≤ I_θ, |Δγ| ≤ I_γ inside which every output meets its accuracy (the largest-area rectangle of each output's region, the smallest half-side per angle). Reading of eq 13: `{}` ({}).",
            c.study.reading,
            reading_words(c.study.reading)
        ));
        let mut rows = Vec::new();
        let boxes = c.requirement.computed.as_ref().ok().map(|r| r.boxes());
        for (k, (name, u, acc)) in outs.iter().enumerate() {
            let p = &c.planes[k];
            let b = boxes.and_then(|b| b.iter().find(|b| b.output() == name));
            let sides = match b {
                Some(b) => (0..3).map(|j| b.half_rad()[j].map_or("-".into(), |h| num(rad_to_deg(h)))).collect::<Vec<_>>().join(" / "),
                None => "no requirement: it meets its accuracy under every constant orientation error (only the end-to-end allocation bounds the turntable for it)".into(),
            };
            rows.push(vec![
                format!("`{name}`"),
                format!("{} {u}", num(*acc)),
                p.sensitive
                    .iter()
                    .map(|&j| d(j))
                    .collect::<Vec<_>>()
                    .join(", "),
                sides,
            ]);
        }
        self.doc.table(
            &[
                "output",
                "accuracy ω_m",
                "sensitive to",
                "largest box: half-sides Δψ / Δθ / Δγ (deg)",
            ],
            rows,
        );
        match &c.requirement.computed {
            Ok(r) => self.doc.p(format!(
                "Requirement computed from the study: {}.",
                requirement_text(&r.requirement().to_array())
            )),
            Err(e) => self.doc.p(format!("No requirement can be computed: {e}.")),
        }
        self.doc.h(3, "Readings of eq 13");
        self.doc.p("Eq 13 can be read in several ways (`cargo xtask requirement --all-readings` lists all 18). Side by side, the requirement under the study's reading and under the main alternatives:");
        let rows = c
            .readings
            .iter()
            .map(|(r, req)| {
                let cell = match req {
                    Ok(q) => (0..3)
                        .map(|k| {
                            q.requirement().to_array()[k]
                                .map_or("none".into(), |v| num(rad_to_deg(v)))
                        })
                        .collect::<Vec<_>>()
                        .join(" / "),
                    Err(e) => format!("none ({e})"),
                };
                vec![
                    format!(
                        "`{r}`{}",
                        if *r == c.study.reading {
                            " (study)"
                        } else {
                            ""
                        }
                    ),
                    reading_words(*r).to_string(),
                    format!("`{}`", r.formula()),
                    cell,
                ]
            })
            .collect();
        self.doc.table(
            &[
                "reading",
                "outputs",
                "error vector",
                "I_ψ / I_θ / I_γ (deg)",
            ],
            rows,
        );
        self.requirement_figures()
    }

    /// The requirement's figures: the surfaces, the one-angle cuts, the lines of intersection.
    fn requirement_figures(&mut self) -> Result<()> {
        let c = self.c;
        let outs = self.outputs();
        let req = c.requirement.computed.as_ref().ok();
        let plotted: Vec<&OutputPlane> = c.planes.iter().filter(|p| p.surface.is_some()).collect();
        if plotted.is_empty() {
            self.doc
                .p("No output constrains two angles: no surface to draw.");
            return Ok(());
        }
        // surfaces
        let mut panels = Vec::new();
        for p in &plotted {
            let (Some(s), Some([a, b])) = (&p.surface, p.plane) else {
                continue;
            };
            let (name, u, acc) = &outs[p.output];
            panels.push(HeatPanel {
                title: format!("Δω_{name} over ({}, {})", d(a), d(b)),
                x_label: format!("{} (deg)", d(a)),
                y_label: format!("{} (deg)", d(b)),
                xs: s.u_rad().iter().map(|v| rad_to_deg(*v)).collect(),
                ys: s.v_rad().iter().map(|v| rad_to_deg(*v)).collect(),
                z: s.delta_omega().to_vec(),
                z_label: format!("Δω_{name} ({})", doc::plain(u)),
                level: Some(*acc),
                rectangle: req
                    .map(|r| {
                        (
                            r.requirement().to_array()[a].map_or(0.0, rad_to_deg),
                            r.requirement().to_array()[b].map_or(0.0, rad_to_deg),
                        )
                    })
                    .filter(|(x, y)| *x > 0.0 && *y > 0.0),
            });
        }
        let third = |p: &OutputPlane| {
            p.plane.map_or(String::new(), |[a, b]| {
                (0..3)
                    .find(|k| *k != a && *k != b)
                    .map_or(String::new(), |k| format!(", {} = 0", d(k)))
            })
        };
        let legend = vec![
            (
                "Δω = ω_m (white line)".to_string(),
                Mark::Line(figures::CONTOUR_LEGEND, false),
            ),
            (
                "requirement box ±I (dashed)".to_string(),
                Mark::Line(figures::BLACK, true),
            ),
        ];
        let svg = figures::heat_figure(
            "Rate-sensing error against the orientation error",
            &panels,
            &legend,
        )?;
        self.doc.h(3, "Rate-sensing error surfaces");
        let id = self.doc.figure(
            "rate_error_surfaces.svg",
            format!(
                "The calibration's rate error of each output over its two most constraining angles{} (colour; white line: Δω = ω_m; dashed: the requirement box). The paper's Figure 4 (a, b) for this study.",
                plotted.first().map_or(String::new(), |p| third(p))
            ),
            svg,
        );
        self.figure_ids.push(("surfaces", id));
        self.requirement_cuts(&plotted)?;
        self.requirement_lines(&plotted)
    }

    /// One-angle cuts of the `plotted` outputs' surfaces (the other two angles zero).
    fn requirement_cuts(&mut self, plotted: &[&OutputPlane]) -> Result<()> {
        let outs = self.outputs();
        let mut panels = Vec::new();
        for p in plotted {
            let (name, u, acc) = &outs[p.output];
            let series = p
                .cuts
                .iter()
                .map(|(angle, pts)| {
                    let sensitive = p.sensitive.contains(angle);
                    // the second sensitive angle dashed: equal cuts stay visible
                    let dashed = p.sensitive.first().is_some_and(|f| f != angle);
                    Series {
                        label: d(*angle),
                        points: pts.iter().map(|(a, v)| (rad_to_deg(*a), *v)).collect(),
                        mark: if sensitive {
                            Mark::Line(colour(*angle), dashed)
                        } else {
                            Mark::Dots(colour(*angle))
                        },
                    }
                })
                .collect();
            panels.push(LinePanel {
                title: format!("Δω_{name} against one angle, the others 0"),
                x_label: "orientation error (deg)".into(),
                y_label: format!("Δω_{name} ({})", doc::plain(u)),
                series,
                hlines: vec![("accuracy ω_m".into(), *acc, Mark::Line(LIMIT, true))],
                x_integer: false,
                y_from_zero: true,
            });
        }
        let cols = if panels.len() >= 3 { 3 } else { 2 };
        let mut legend: Vec<(String, Mark)> = (0..3)
            .map(|k| (format!("against {}", d(k)), Mark::Line(colour(k), false)))
            .collect();
        legend.push((
            "dotted: an angle the output ignores".into(),
            Mark::Dots(figures::BLACK),
        ));
        legend.push(("accuracy ω_m".into(), Mark::Line(LIMIT, true)));
        let svg = figures::line_figure_with_legend(
            "Rate-sensing error against each angle",
            &panels,
            cols,
            &legend,
        )?;
        let id = self.doc.figure("rate_error_cuts.svg", "One-angle cuts of the surfaces (the other two angles zero); a second sensitive angle is dashed so that equal cuts stay visible, dots mark an angle the output does not depend on. The paper's Figure 4 (c-f) for this study.", svg);
        self.figure_ids.push(("cuts", id));
        Ok(())
    }

    /// Lines of intersection of the `plotted` outputs, their largest boxes and the
    /// requirement.
    fn requirement_lines(&mut self, plotted: &[&OutputPlane]) -> Result<()> {
        let outs = self.outputs();
        let req = self.c.requirement.computed.as_ref().ok();
        let mut panels = Vec::new();
        let mut notes = Vec::new();
        for p in plotted {
            let (name, _, _) = &outs[p.output];
            let Some([a, b]) = p.plane else { continue };
            let bx = req.and_then(|r| r.boxes().iter().find(|x| x.output() == name));
            let mut series = Vec::new();
            match &p.boundary {
                Ok(pts) => {
                    let mut v: Vec<(f64, f64)> = pts
                        .iter()
                        .map(|q| (rad_to_deg(q[0]), rad_to_deg(q[1])))
                        .collect();
                    if let Some(f) = v.first().copied() {
                        v.push(f);
                    }
                    series.push(Series {
                        label: "Δω = ω_m".into(),
                        points: v,
                        mark: Mark::Line(colour(0), false),
                    });
                }
                Err(e) => notes.push(format!("`{name}`: no closed line ({e})")),
            }
            if let Some(bx) = bx {
                if let (Some(ha), Some(hb)) = (bx.half_rad()[a], bx.half_rad()[b]) {
                    let (x, y) = (rad_to_deg(ha), rad_to_deg(hb));
                    series.push(Series {
                        label: "largest box of the output".into(),
                        points: vec![(-x, -y), (x, -y), (x, y), (-x, y), (-x, -y)],
                        mark: Mark::Line(colour(1), false),
                    });
                }
            }
            if let Some(r) = req {
                if let (Some(ia), Some(ib)) =
                    (r.requirement().to_array()[a], r.requirement().to_array()[b])
                {
                    let (x, y) = (rad_to_deg(ia), rad_to_deg(ib));
                    series.push(Series {
                        label: "requirement (all outputs)".into(),
                        points: vec![(-x, -y), (x, -y), (x, y), (-x, y), (-x, -y)],
                        mark: Mark::Line(colour(2), true),
                    });
                }
            }
            if series.is_empty() {
                continue;
            }
            panels.push(LinePanel {
                title: format!("Δω_{name} = ω_m in the ({}, {}) plane", d(a), d(b)),
                x_label: format!("{} (deg)", d(a)),
                y_label: format!("{} (deg)", d(b)),
                series,
                hlines: Vec::new(),
                x_integer: false,
                y_from_zero: false,
            });
        }
        if !panels.is_empty() {
            let cols = if panels.len() >= 3 { 3 } else { 2 };
            let svg =
                figures::line_figure("Lines of intersection and the requirement", &panels, cols)?;
            self.doc.h(3, "Lines of intersection and the requirement");
            let id = self.doc.figure(
                "requirement_lines.svg",
                "Where each output's rate error reaches its accuracy (the surface cut at Δω = ω_m), the largest box inside it, and the requirement common to all outputs (eq 15-16). The paper's Figure 5 for this study.",
                svg,
            );
            self.figure_ids.push(("lines", id));
        }
        if !notes.is_empty() {
            self.doc.p(notes.join("; "));
        }
        Ok(())
    }

    /// Average sensitivities (Figure 8 for any table).
    pub(crate) fn sensitivities(&mut self) -> Result<()> {
        let c = self.c;
        let t = &c.study.turntable;
        let names: Vec<String> = t
            .rotation_error_names()
            .iter()
            .map(|s| (*s).to_string())
            .collect();
        self.doc.h(2, "Turntable error model and sensitivities");
        self.doc.p(format!(
            "The orientation error of the platform is ΔR = R_dᵀ R_t (eq 23), read out as (Δψ, Δθ, Δγ) (eq 24); to first order each angle is a sum of the {} angular errors with pose-dependent coefficients (eq 26 for the paper's table). The average sensitivity of an angle to an error (eq 28) is the mean of the coefficient's magnitude over the poses: it sets the error's weight in the allocation. Written to `sensitivities.csv`.",
            names.len()
        ));
        let series: Vec<(String, Vec<f64>)> = OrientationAxis::ALL
            .iter()
            .map(|a| {
                (
                    d(a.index()),
                    (0..names.len())
                        .map(|i| c.sensitivity[i][a.index()])
                        .collect(),
                )
            })
            .collect();
        let svg = figures::hbar_figure(
            "Average sensitivity of the orientation error to each turntable error",
            &names,
            &series,
            "average |∂f/∂χ_i| over the poses (rad/rad)",
        )?;
        let id = self.doc.figure("sensitivities.svg", "Average sensitivities (eq 28) of Δψ, Δθ, Δγ to every angular error, from the turntable's first-order model. The paper's Figure 8 for this table.", svg);
        self.figure_ids.push(("sensitivities", id));
        let mut rows = Vec::new();
        let mut csv = String::from("error,psi,theta,gamma\n");
        for (i, n) in names.iter().enumerate() {
            let v: Vec<f64> = (0..3).map(|k| c.sensitivity[i][k]).collect();
            rows.push(vec![
                format!("`{n}`"),
                t.description_of(n).map_or_else(|| "-".into(), doc::text),
                format!("{:.4}", v[0]),
                format!("{:.4}", v[1]),
                format!("{:.4}", v[2]),
            ]);
            let _ = writeln!(csv, "{n},{},{},{}", exact(v[0]), exact(v[1]), exact(v[2]));
        }
        self.doc
            .table(&["error", "description", "Δψ", "Δθ", "Δγ"], rows);
        self.csv.push(("sensitivities.csv".into(), csv));
        Ok(())
    }

    /// The two-step allocation with its certificate; `table4`: the paper's column.
    pub(crate) fn allocation(&mut self, table4: Option<&PaperColumn>) {
        let c = self.c;
        self.doc.h(2, "Two-step allocation");
        let Some(t) = &c.two_step else {
            if c.study.has_rate_steps() {
                self.doc.p("The study has rate steps: the orientation requirement (eq 15-16) is a static concept (one orientation error at every test position), so the paper's two-step method (requirement, then allocation against it) is not made; see the end-to-end section for the direct allocation with the rate tolerances.");
                return;
            }
            self.doc.p("The study has no orientation requirement (no output constrains a constant orientation error), so the paper's two-step method (requirement, then allocation against it) does not apply; see the end-to-end section for the direct allocation against every output's accuracy.");
            return;
        };
        let names = c.study.turntable.rotation_error_names();
        let req = t.problem.requirement();
        self.doc.p(format!(
            "Upper bounds UB_i on the angular errors such that, for every pose and every χ with LB_i ≤ |χ_i| ≤ UB_i, the first-order orientation error stays within the requirement ({}) (Lemma 1), minimising J = Σ_k Σ_i W_ki²/UB_i² with the weights W = 1/average sensitivity (problems 31-34, solved to the optimum with the constraint over every pose; errors combined by rule 34). {} Written to `allocation.csv`.",
            requirement_text(&req.to_array()),
            if c.equal.is_some() {
                "Beside it the equal-effects allocation (every error contributes equally to the worst case, same guarantee)."
            } else {
                "(The equal-effects comparison is shown for tables with at most one free joint, where its worst case is exact; `cargo xtask allocate` computes it for any table.)"
            }
        ));
        let ours = t.ours.upper_bounds_arcmin();
        let equal = c.equal.as_ref().map(|e| e.upper_bounds_arcmin());
        let cell = |v: f64| {
            if v.is_finite() {
                format!("{v:.4}")
            } else {
                "none".into()
            }
        };
        let mut header = vec!["error", "description", "two-step (arcmin)"];
        if equal.is_some() {
            header.push("equal effects (arcmin)");
        }
        if table4.is_some() {
            header.push("Table 4 (arcmin)");
        }
        let mut rows = Vec::new();
        let mut csv = String::from("error,two_step_arcmin");
        if equal.is_some() {
            csv.push_str(",equal_effects_arcmin");
        }
        if table4.is_some() {
            csv.push_str(",paper_table4_arcmin");
        }
        csv.push('\n');
        for (i, n) in names.iter().enumerate() {
            let mut row = vec![
                format!("`{n}`"),
                c.study
                    .turntable
                    .description_of(n)
                    .map_or_else(|| "-".into(), doc::text),
                cell(ours[i]),
            ];
            if let Some(e) = &equal {
                row.push(cell(e[i]));
            }
            let _ = write!(csv, "{n},{}", exact(ours[i]));
            if let Some(e) = &equal {
                let _ = write!(csv, ",{}", exact(e[i]));
            }
            if let Some((t4, _, _)) = &table4 {
                row.push(cell(t4[i]));
                let _ = write!(csv, ",{}", exact(t4[i]));
            }
            csv.push('\n');
            rows.push(row);
        }
        let mut jrow = vec![
            "**J**".to_string(),
            "objective (arcmin⁻²)".into(),
            format!("{:.3}", t.ours.objective_arcmin()),
        ];
        if let Some(e) = &c.equal {
            jrow.push(format!("{:.3}", e.objective_arcmin()));
        }
        let _ = write!(
            csv,
            "objective_J_arcmin^-2,{}",
            exact(t.ours.objective_arcmin())
        );
        if let Some(e) = &c.equal {
            let _ = write!(csv, ",{}", exact(e.objective_arcmin()));
        }
        if let Some((_, j, _)) = &table4 {
            jrow.push(format!("{j:.3}"));
            let _ = write!(csv, ",{}", exact(*j));
        }
        csv.push('\n');
        rows.push(jrow);
        self.doc.table(&header, rows);
        self.csv.push(("allocation.csv".into(), csv));
        let mut group_bounds: Vec<(&str, &[f64])> = vec![("two-step", t.ours.upper_bounds_rad())];
        if let Some(e) = &c.equal {
            group_bounds.push(("equal effects", e.upper_bounds_rad()));
        }
        let t4_rad = table4.map(|(t4, _, _)| {
            t4.iter()
                .map(|v| tt_core::units::arcmin_to_rad(*v))
                .collect::<Vec<f64>>()
        });
        if let Some(t4) = &t4_rad {
            group_bounds.push(("Table 4", t4));
        }
        group_list(&mut self.doc, &c.study.turntable, &group_bounds);
        if !t.ours.unconstrained().is_empty() {
            self.doc.p(format!(
                "No angle with a requirement depends on {}: no bound (held at the lower bound in the Monte Carlo).",
                t.ours.unconstrained_names().iter().map(|n| format!("`{n}`")).collect::<Vec<_>>().join(", ")
            ));
        }
        self.allocation_certificate(t, table4);
    }

    /// The two-step allocation `t`'s Lemma 1 certificate, and the shares of the requirement
    /// used beside equal effects' and `table4`'s.
    fn allocation_certificate(&mut self, t: &TwoStep, table4: Option<&PaperColumn>) {
        let c = self.c;
        let jn = c.study.turntable.joint_names();
        let mut rows = Vec::new();
        let shares = |s: &[Option<f64>]| {
            (0..3)
                .map(|k| s[k].map_or("-".into(), pct))
                .collect::<Vec<_>>()
                .join(" / ")
        };
        for a in t.ours.certificate().axes() {
            let k = a.quantity();
            rows.push(vec![
                d(k),
                a.requirement_rad()
                    .map_or("none".into(), |v| num(rad_to_deg(v))),
                num(rad_to_deg(a.worst_case_rad())),
                num(rad_to_deg(a.upper_bound_rad())),
                a.share().map_or("-".into(), pct),
                format!(
                    "({})",
                    jn.iter()
                        .zip(a.worst_pose_rad())
                        .map(|(j, v)| format!("{j} {}", num(rad_to_deg(*v))))
                        .collect::<Vec<_>>()
                        .join(", ")
                ),
                yes_no(a.satisfied()),
                t.exact.get(k).map_or("-".into(), |e| {
                    e.excess_rad().map_or("-".into(), |x| {
                        format!("{} arcmin", sig(rad_to_arcmin(x), 3))
                    })
                }),
            ]);
        }
        self.doc.p(format!(
            "Lemma 1 certificate of the two-step allocation: the worst case of each angle over every pose and every admissible χ ({}), a rigorous upper bound on it, the share of the requirement used, and the exact chain's excess over the requirement at the worst vertices found (second order; negative: within).",
            if t.ours.certificate().exact() { "exact: at most one free joint" } else { "searched over the free joints, bounded by branch and bound" }
        ));
        self.doc.table(
            &[
                "angle",
                "requirement (deg)",
                "worst case (deg)",
                "proven bound (deg)",
                "share used",
                "worst pose (deg)",
                "Lemma 1",
                "exact chain over I",
            ],
            rows,
        );
        if let Some((_, _, s)) = &table4 {
            self.doc.p(format!(
                "Shares of the requirement used: two-step {}, equal effects {}, Table 4 {}.",
                shares(&t.ours.shares()),
                c.equal.as_ref().map_or("-".into(), |e| shares(&e.shares())),
                shares(s)
            ));
        }
    }

    /// The Monte Carlo of the two-step box (and the paper's Table 4 box).
    pub(crate) fn monte_carlo(
        &mut self,
        table4: Option<(&mc_verify::MonteCarlo, &mc_verify::McResult)>,
    ) -> Result<()> {
        let c = self.c;
        let Some(t) = &c.two_step else { return Ok(()) };
        self.doc.h(2, "Monte Carlo of the allocation");
        self.doc.p(format!(
            "{} random turntables per box, seed {}: each |χ_i| uniform in [LB_i, UB_i] with a fair random sign, the pose uniform over the joint ranges, evaluated on the exact chain (eq 25, read-out of eq 24); the same for any number of threads. The largest drawn |Δ| is compared with the proven worst case over the whole box (the certificate's first-order worst case plus the exact chain's remainder): the draws rarely reach the box's corners, so \"every draw inside\" alone proves little. An allocation that uses 100% of I to first order exceeds it on the exact chain by the second-order remainder (the certificate's last column).",
            c.options.samples, c.options.seed
        ));
        let mut runs: Vec<(&str, &mc_verify::MonteCarlo, &mc_verify::McResult)> =
            vec![("two-step", &t.monte_carlo, &t.result)];
        if let Some((mc, r)) = table4 {
            runs.push(("Table 4", mc, r));
        }
        let mut rows = Vec::new();
        for (name, mc, r) in &runs {
            let bound = mc.half_range_rad();
            let sd = r.std_rad();
            for a in OrientationAxis::ALL {
                let k = a.index();
                rows.push(vec![
                    (*name).to_string(),
                    d(k),
                    sig(rad_to_deg(r.axes()[k].max_abs_rad()), 5),
                    sig(rad_to_deg(bound[k]), 5),
                    r.requirement().to_array()[k].map_or("none".into(), |i| sig(rad_to_deg(i), 5)),
                    sig(rad_to_deg(sd[k]), 4),
                    pct(r.count().meeting_per_output()[k] as f64 / r.count().samples() as f64),
                ]);
            }
        }
        self.doc.table(
            &[
                "box",
                "angle",
                "largest drawn |Δ| (deg)",
                "proven bound (deg)",
                "requirement (deg)",
                "std (deg)",
                "draws inside",
            ],
            rows,
        );
        let (name, _mc, r) =
            runs.last()
                .copied()
                .unwrap_or(("two-step", &t.monte_carlo, &t.result));
        let panels: Vec<HistPanel> = OrientationAxis::ALL
            .iter()
            .map(|a| {
                let k = a.index();
                let h = &r.axes()[k].histogram();
                let mut limits = Vec::new();
                if let Some(i) = r.requirement().to_array()[k] {
                    limits.push((
                        "±I (requirement)".to_string(),
                        rad_to_deg(i),
                        Mark::Line(LIMIT, false),
                    ));
                }
                let mc = runs.last().map_or(&t.monte_carlo, |x| x.1);
                limits.push((
                    "± proven worst case".to_string(),
                    rad_to_deg(mc.half_range_rad()[k]),
                    Mark::Line(figures::BLACK, true),
                ));
                HistPanel {
                    title: format!("{} ({name})", d(k)),
                    x_label: format!("{} (deg)", d(k)),
                    edges: h.edges().iter().map(|v| rad_to_deg(*v)).collect(),
                    counts: h.counts().to_vec(),
                    limits,
                }
            })
            .collect();
        let svg = figures::histogram_figure(
            &format!(
                "Orientation error of {} random turntables of the {name} box",
                r.count().samples()
            ),
            &panels,
            "draws per bin",
        )?;
        let caption = if name == "Table 4" {
            "Distribution of the orientation error of random Table 4 turntables on the exact chain (red: ±I of eq 16; dashed: the proven worst case). The paper's Figure 9."
        } else {
            "Distribution of the orientation error of random turntables of the two-step box on the exact chain (red: ±I, the requirement; dashed: the proven worst case). The paper's Figure 9 for this study."
        };
        let id = self.doc.figure("monte_carlo.svg", caption, svg);
        self.figure_ids.push(("monte_carlo", id));
        Ok(())
    }

    fn reading_table(&mut self, r: &ReadingAnswer) {
        let c = self.c;
        let acc = c.e2e.accuracies();
        let outs = self.outputs();
        let mut rows = Vec::new();
        let mut boxes: Vec<(&str, &BoxAnswer)> = r.boxes().iter().map(|b| (b.name(), b)).collect();
        boxes.push(("direct", r.direct_box()));
        boxes.push(("yield-based", r.yield_box()));
        for (name, b) in boxes {
            let worst = tt_lab::end_to_end::worst_turntable_words(b, |k, v| {
                format!("{} {}", outs[k].0, sig(v, 5))
            });
            // the yield-based box's yield is what its allocation counts (with specifications:
            // every accuracy and every specification)
            let count = if name == "yield-based" {
                r.yield_count()
            } else {
                b.distribution().count()
            };
            let (lo, hi) = count.interval_95();
            let label = match name {
                "two-step" => "two-step (requirement, then turntable)".to_string(),
                "direct" => "direct (against every accuracy)".to_string(),
                "yield-based" => format!(
                    "yield-based ({}% of turntables)",
                    num(100.0 * r.yield_based().target())
                ),
                other => other.to_string(),
            };
            let mut yield_cell = format!(
                "{:.2}% [{:.2}, {:.2}]",
                100.0 * count.fraction(),
                100.0 * lo,
                100.0 * hi
            );
            if name == "yield-based" {
                // re-measured on independent draws, against the allocation's target
                let _ = write!(
                    yield_cell,
                    " of {}: {} its target",
                    tt_lab::end_to_end::yield_counts_words(r, c.no_table_suffices.len()),
                    match r.yield_verdict() {
                        YieldVerdict::Meets => "**meets**",
                        YieldVerdict::DoesNotMeet => "does **not** meet",
                        YieldVerdict::CannotTell => "cannot tell whether it meets",
                    }
                );
            }
            rows.push(vec![
                label,
                format!("{:.2}", objective_to_arcmin(b.objective())),
                worst,
                meets_md(b.worst_case().meets(&acc)),
                yield_cell,
            ]);
        }
        if let Some((dc, wc)) = &r.direct_certified() {
            let proven: Vec<String> = wc
                .outputs()
                .iter()
                .map(|w| {
                    format!(
                        "{} ≤ {}",
                        outs[w.output()].0,
                        w.certified_bound().map_or("-".into(), |v| sig(v, 6))
                    )
                })
                .collect();
            let ok = wc
                .outputs()
                .iter()
                .all(|w| w.certified_bound().is_some_and(|v| v <= acc[w.output()]));
            rows.push(vec![
                "direct, certified on the exact chain".into(),
                format!("{:.2}", dc.objective_arcmin()),
                proven.join(", "),
                yes_no(ok),
                "-".into(),
            ]);
        }
        self.doc.table(
            &[
                "box",
                "J (arcmin⁻²)",
                "worst turntable: Δω per output",
                "meets every ω_m",
                "yield [95% interval]",
            ],
            rows,
        );
        let limits = tt_lab::end_to_end::yield_limit_lines(r, &doc::text);
        if !limits.is_empty() {
            self.doc.p(
                "The yield-based box's re-measured turntables against each limit its yield counts:",
            );
            self.doc.list(limits);
        }
        if !c.no_table_suffices.is_empty() {
            self.doc.p(
                "Left out of the direct and the yield-based allocations (no table can meet them):",
            );
            self.doc.list(
                c.no_table_suffices
                    .iter()
                    .map(|n| doc::text(&n.to_string()))
                    .collect(),
            );
        }
        if let Some(n) = &r.direct_certified_note() {
            self.doc.p(format!(
                "The direct allocation could not be certified on the exact chain here: {n}."
            ));
        }
        let mut zeroed: Vec<usize> = Vec::new();
        for b in r.boxes().iter().chain([r.direct_box(), r.yield_box()]) {
            for w in b.worst_case().outputs() {
                if w.exact_at_vertex() == 0.0 && !zeroed.contains(&w.output()) {
                    zeroed.push(w.output());
                }
            }
        }
        self.precision_note(&zeroed);
    }

    /// One sentence for worst cases shown as 0 because they are at or below the computation's
    /// precision (`outputs`: their indices), with the precision of each.
    fn precision_note(&mut self, outputs: &[usize]) {
        let outs = self.outputs();
        let p = self.c.e2e.precisions();
        let zeroed: Vec<(&str, &str, f64)> = outputs
            .iter()
            .map(|&k| (outs[k].0.as_str(), outs[k].1.as_str(), p[k]))
            .collect();
        if let Some(n) = tt_lab::end_to_end::precision_note(&zeroed) {
            self.doc.p(format!("Worst cases: {n}."));
        }
    }

    /// End to end: both readings, the direct allocation.
    pub(crate) fn end_to_end(&mut self) -> Result<()> {
        let c = self.c;
        let outs = self.outputs();
        self.doc.h(
            2,
            "End to end: does the turntable deliver every output's accuracy?",
        );
        self.doc.p(format!(
            "A real turntable has fixed errors χ whose orientation error changes from position to position. Each turntable is calibrated end to end: at every one of the {} positions the exact chain gives ΔR, the outputs follow, the least-squares calibration is run, and Δω of every output (eq 14) is compared with its accuracy. Worst cases are the vertex of the linearised problem, confirmed on the exact chain; yields come from {} random turntables per box (seed {}). Accuracies: {}.",
            c.study.positions_deg.len(),
            c.options.samples,
            c.options.seed,
            outs.iter().map(|(n, u, a)| format!("`{n}` {} {u}", num(*a))).collect::<Vec<_>>().join(", ")
        ));
        let readings = c.answer.readings().to_vec();
        for (i, r) in readings.iter().enumerate() {
            self.doc.h(
                3,
                format!(
                    "Reading `{}`{}",
                    r.reading(),
                    if i == 0 { " (the study's)" } else { "" }
                ),
            );
            self.doc.p(format!(
                "{}; error vector `{}`.",
                reading_words(r.reading()),
                r.reading().formula()
            ));
            self.reading_table(r);
        }
        self.direct_allocation(&readings);
        self.end_to_end_figure(&readings)
    }

    /// The direct allocation's bounds under each of the `readings` (and `end_to_end.csv`).
    fn direct_allocation(&mut self, readings: &[ReadingAnswer]) {
        let c = self.c;
        self.doc.h(3, "Direct allocation");
        let names = c.study.turntable.rotation_error_names();
        let mut header: Vec<String> = Vec::new();
        header.push("error".into());
        let mut cols: Vec<(String, Vec<f64>)> = Vec::new();
        for r in readings {
            cols.push((
                format!("direct, {} (arcmin)", short_reading(r.reading())),
                r.direct().upper_bounds_arcmin(),
            ));
            if let Some((dc, _)) = &r.direct_certified() {
                cols.push((
                    format!("certified, {}", short_reading(r.reading())),
                    dc.upper_bounds_arcmin(),
                ));
            }
        }
        if let Some(t) = &c.two_step {
            cols.push(("two-step (arcmin)".into(), t.ours.upper_bounds_arcmin()));
        }
        header.extend(cols.iter().map(|(h, _)| h.clone()));
        let mut rows = Vec::new();
        let mut csv = format!(
            "error,{}\n",
            cols.iter()
                .map(|(h, _)| h
                    .replace(['`', ','], "")
                    .replace(" (arcmin)", "")
                    .replace(' ', "_"))
                .collect::<Vec<_>>()
                .join(",")
        );
        for (i, n) in names.iter().enumerate() {
            let mut row = vec![format!("`{n}`")];
            let mut line = n.to_string();
            for (_, v) in &cols {
                row.push(if v[i].is_finite() {
                    format!("{:.4}", v[i])
                } else {
                    "none".into()
                });
                let _ = write!(
                    line,
                    ",{}",
                    if v[i].is_finite() {
                        exact(v[i])
                    } else {
                        String::new()
                    }
                );
            }
            rows.push(row);
            let _ = writeln!(csv, "{line}");
        }
        let h: Vec<&str> = header.iter().map(String::as_str).collect();
        self.doc.p(format!(
            "The direct allocation bounds the turntable against every output's accuracy at every position (no square requirement in between): one linear constraint per output and position on the linearised errors, the same objective J; \"certified\" keeps room for the exact chain's second-order terms. Its bounds{} (none: no output depends on the error). Readings: {}. Written to `end_to_end.csv`.",
            if c.two_step.is_some() { " beside the two-step allocation's" } else { "" },
            readings.iter().map(|r| format!("{} = `{}`", short_reading(r.reading()), r.reading())).collect::<Vec<_>>().join(", ")
        ));
        self.doc.table(&h, rows);
        self.csv.push(("end_to_end.csv".into(), csv));
        let labels: Vec<String> = readings
            .iter()
            .map(|r| format!("direct, {}", short_reading(r.reading())))
            .collect();
        let group_bounds: Vec<(&str, &[f64])> = labels
            .iter()
            .zip(readings)
            .map(|(l, r)| (l.as_str(), r.direct().upper_bounds_rad()))
            .collect();
        group_list(&mut self.doc, &c.study.turntable, &group_bounds);
    }

    /// The figure of the worst case per position, per reading and output.
    fn end_to_end_figure(&mut self, readings: &[ReadingAnswer]) -> Result<()> {
        let c = self.c;
        let outs = self.outputs();
        let mut panels = Vec::new();
        for r in readings {
            for (k, (name, u, acc)) in outs.iter().enumerate() {
                let mut series = Vec::new();
                let mut boxes: Vec<(&str, &BoxAnswer)> =
                    r.boxes().iter().map(|b| (b.name(), b)).collect();
                boxes.push(("direct", r.direct_box()));
                for (j, (bn, b)) in boxes.iter().enumerate() {
                    let Some(w) = b.worst_case().outputs().iter().find(|w| w.output() == k) else {
                        continue;
                    };
                    series.push(Series {
                        label: (*bn).to_string(),
                        points: w
                            .per_position()
                            .iter()
                            .enumerate()
                            .map(|(i, v)| ((i + 1) as f64, *v))
                            .collect(),
                        mark: Mark::Line(colour(j), false),
                    });
                }
                panels.push(LinePanel {
                    title: format!("Δω_{name}, `{}`", r.reading()).replace('`', ""),
                    x_label: "test position".into(),
                    y_label: format!("worst Δω_{name} ({})", doc::plain(u)),
                    series,
                    hlines: vec![("accuracy ω_m".into(), *acc, Mark::Line(LIMIT, true))],
                    x_integer: true,
                    y_from_zero: true,
                });
            }
        }
        let cols = if panels.len() == 4 || panels.len() <= 2 {
            2
        } else {
            3
        };
        let svg = figures::line_figure(
            "Worst-case calibration error at each test position",
            &panels,
            cols,
        )?;
        let id = self.doc.figure(
            "end_to_end.svg",
            if c.two_step.is_some() {
                "The linearised worst-case rate error of each output at each test position, for the two-step allocation's box and the direct allocation's (dashed red: the output's accuracy), under each reading."
            } else {
                "The linearised worst-case rate error of each output at each test position, for the direct allocation's box (dashed red: the output's accuracy), under each reading."
            },
            svg,
        );
        self.figure_ids.push(("end_to_end", id));
        Ok(())
    }

    /// Noise and test time (issue 21): every box's answer split into the table's part and
    /// the noise's, the direct allocation that gives the table what the noise leaves, and the
    /// time/table trade-off with its figure. Nothing when the study gives no noise.
    pub(crate) fn noise(&mut self) -> Result<()> {
        let c = self.c;
        let Some(n) = &c.noise else {
            return Ok(());
        };
        let outs = self.outputs();
        let tr = &n.tradeoff;
        let k = tr.k_sigma();
        let nr = &n.readings[0];
        let timing = c.study.timing.as_ref();
        self.doc
            .h(2, "Noise and test time: both error sources in one answer");
        self.doc.p(format!(
            "The sensor's noise, averaged over the dwell at each position, adds a random part to every output's calibration error: its standard deviation σ at the worst test position comes from the covariance of the least-squares calibration (white noise and the Gauss-Markov bias instability, positions in the schedule's order{}). The answer per output is the table's part (the certified worst case over the box where a second-order bound is derived) plus {} σ; it meets the accuracy only when the sum does. Noise σ: {}.",
            timing.map_or(String::new(), |t| format!(
                "; {} positions, mean dwell {} s{}, {} Hz, move {} s, total {} s",
                t.positions(),
                num(t.dwell_s().iter().sum::<f64>() / t.positions() as f64),
                match t.rate_step_s() {
                    [] => String::new(),
                    r => format!(
                        ", then {} rate steps each averaged over its whole revolutions ({} s in all)",
                        r.len(),
                        num(r.iter().sum::<f64>())
                    ),
                },
                num(t.sample_rate_hz()),
                num(t.move_s()),
                num(t.total_s())
            )),
            num(k),
            outs.iter()
                .zip(nr.sigma())
                .map(|((name, u, _), s)| format!("{} {} {u}", doc::code(name), sig(*s, 4)))
                .collect::<Vec<_>>()
                .join(", ")
        ));
        let reading = c.answer.readings()[0].reading();
        let mut rows = Vec::new();
        for b in nr.boxes() {
            for o in b.outputs() {
                let (name, u, acc) = &outs[o.output()];
                rows.push(vec![
                    doc::text(b.name()),
                    doc::code(name),
                    format!(
                        "{}{}",
                        sig(o.table_part(), 4),
                        if o.table_certified() {
                            ""
                        } else {
                            " (not certified)"
                        }
                    ),
                    format!(
                        "{} ({} σ)",
                        sig(o.k_sigma() * o.noise_sigma(), 4),
                        num(o.k_sigma())
                    ),
                    format!("{} {u}", sig(o.combined(), 4)),
                    format!("{} {u}", sig(*acc, 4)),
                    o.dominant().name().to_string(),
                    verdict_md(o.verdict()),
                ]);
            }
        }
        self.doc.p(format!(
            "Every box of the end-to-end answer under the study's reading `{reading}`, split per output (the yields count calibrations over random turntables in the box and random noise, {} draws, seed {}):",
            c.options.samples, c.options.seed
        ));
        self.doc.table(
            &[
                "box",
                "output",
                "table part",
                "noise part",
                "combined",
                "accuracy ω_m",
                "dominates",
                "verdict",
            ],
            rows,
        );
        let yields: Vec<String> = nr
            .boxes()
            .iter()
            .map(|b| {
                let (lo, hi) = b.combined_yield().interval_95();
                format!(
                    "{} {:.2}% [{:.2}, {:.2}]",
                    doc::text(b.name()),
                    100.0 * b.combined_yield().fraction(),
                    100.0 * lo,
                    100.0 * hi
                )
            })
            .collect();
        self.doc.p(format!(
            "Yield over turntables and noise [95% interval]: {}.",
            yields.join("; ")
        ));
        self.noise_direct(n);
        self.noise_tradeoff(n);
        self.noise_figure(n)
    }

    /// The direct allocation with the noise part kept free (or why no table suffices), and
    /// the vendor's sheet with the noise counted.
    fn noise_direct(&mut self, n: &tt_lab::end_to_end::NoisyAnswer) {
        let c = self.c;
        let outs = self.outputs();
        let k = n.tradeoff.k_sigma();
        let nr = &n.readings[0];
        match &nr.direct() {
            e2e_verify::NoisyDirect::Allocated { allocation, answer } => {
                self.doc.p(format!(
                    "The direct allocation with the noise part kept free (each output's rows held to ω_m − {} σ: the table gets what the noise leaves) needs J = {} arcmin⁻² against {} without noise; its verdict with the noise: {}.",
                    num(k),
                    sig(allocation.objective_arcmin(), 5),
                    sig(c.answer.readings()[0].direct().objective_arcmin(), 5),
                    verdict_md(answer.verdict())
                ));
            }
            e2e_verify::NoisyDirect::NoTableSuffices { outputs } => {
                let what: Vec<String> = outputs
                    .iter()
                    .map(|b| {
                        let (name, u, acc) = &outs[b.output()];
                        format!(
                            "{}: noise part {} of {} {u}",
                            doc::code(name),
                            sig(b.noise_part(), 4),
                            sig(*acc, 4)
                        )
                    })
                    .collect();
                self.doc.callout(format!(
                    "**No table suffices at this dwell**: the noise alone takes the whole accuracy of {}. A longer dwell (or a quieter sensor) is needed before any turntable can help.",
                    what.join(", ")
                ));
            }
        }
        if let Some(nc) = &c.vendor_noise {
            let parts: Vec<String> = nc
                .outputs
                .iter()
                .map(|o| {
                    let (name, u, _) = &outs[o.output()];
                    format!(
                        "{} table {}, noise {} at {} σ, combined {} {u}",
                        doc::code(name),
                        sig(o.table_part(), 3),
                        sig(o.k_sigma() * o.noise_sigma(), 3),
                        num(o.k_sigma()),
                        sig(o.combined(), 3)
                    )
                })
                .collect();
            let (lo, hi) = nc.combined_yield.interval_95();
            self.doc.p(format!(
                "The vendor's sheet with the noise counted: {}; verdict {}; yield over turntables and noise {:.2}% [{:.2}, {:.2}].",
                parts.join("; "),
                verdict_md(nc.verdict),
                100.0 * nc.combined_yield.fraction(),
                100.0 * lo,
                100.0 * hi
            ));
        }
    }

    /// How long to dwell: the shortest dwell, the knee, the trade-off table (and
    /// `tradeoff.csv`).
    fn noise_tradeoff(&mut self, n: &tt_lab::end_to_end::NoisyAnswer) {
        let outs = self.outputs();
        let tr = &n.tradeoff;
        let k = tr.k_sigma();
        self.doc
            .h(3, "How long to dwell, and how good the table must be");
        let list = n.scanned.list_words();
        if let Some(w) = &list {
            self.doc.p(format!(
                "Scanned: {w}; a dwell below is the mean dwell per position."
            ));
        }
        match tr.min_dwell_s() {
            Some(d) => self.doc.p(format!(
                "The shortest {}dwell at which some table meets every accuracy (noise part plus the lower bounds' table part within ω_m, found by bisection): **{} s per position**{}. Above it the table's J falls towards its noiseless value {} arcmin⁻²; the knee (where a longer dwell stops paying: d ln J / d ln T = −1) {}. Written to `tradeoff.csv`.",
                if list.is_some() { "mean " } else { "" },
                sig(d, 4),
                if tr.min_dwell_at_range_start() { " (one sample per position already suffices)" } else { "" },
                sig(objective_to_arcmin(tr.noiseless_objective()), 5),
                tr.knee_dwell_s().map_or("is not on the curve".into(), |v| format!("lies at {} s", sig(v, 3)))
            )),
            None => {
                let last: Vec<String> = tr
                    .noise_curve()
                    .last()
                    .map(|(_, m)| {
                        outs.iter()
                            .zip(m)
                            .map(|((name, u, _), v)| format!("{} {} {u}", doc::code(name), sig(*v, 3)))
                            .collect()
                    })
                    .unwrap_or_default();
                self.doc.p(if list.is_some() {
                    format!(
                        "**At no scale of the study's dwells** does any table meet every accuracy: the noise part alone exceeds one even at the longest ({} σ there: {}). Written to `tradeoff.csv`.",
                        num(k),
                        last.join(", ")
                    )
                } else {
                    format!(
                        "**No dwell up to {} s per position** lets any table meet every accuracy: the noise part alone exceeds one even then ({} σ at that dwell: {}). Written to `tradeoff.csv`.",
                        num(tr.range_s().1),
                        num(k),
                        last.join(", ")
                    )
                });
            }
        }
        let mut csv = String::from("dwell_s,total_s,objective_arcmin\n");
        let mut rows = Vec::new();
        for p in tr.points() {
            let j = p.objective().map(objective_to_arcmin);
            let _ = writeln!(
                csv,
                "{},{},{}",
                exact(p.dwell_s()),
                exact(p.total_s()),
                j.map_or(String::new(), exact)
            );
            rows.push(vec![
                sig(p.dwell_s(), 4),
                sig(p.total_s(), 4),
                j.map_or("none".into(), |v| sig(v, 5)),
            ]);
        }
        if !rows.is_empty() {
            self.doc.table(
                &[
                    "dwell per position (s)",
                    "total test time (s)",
                    "J (arcmin⁻²)",
                ],
                rows,
            );
        }
        self.csv.push(("tradeoff.csv".into(), csv));
    }

    /// The figure of the noise part against the dwell (every study with noise), and J against
    /// the dwell (when some table suffices); log10 of the dwell on x.
    fn noise_figure(&mut self, n: &tt_lab::end_to_end::NoisyAnswer) -> Result<()> {
        let outs = self.outputs();
        let tr = &n.tradeoff;
        let k = tr.k_sigma();
        let mut panels = Vec::new();
        // outputs without noise have no curve (their noise part is 0 at every dwell)
        let series: Vec<Series> = outs
            .iter()
            .enumerate()
            .filter(|(o, _)| tr.noise_curve().iter().all(|(_, m)| m[*o] > 0.0))
            .map(|(o, (name, _, acc))| Series {
                label: format!("{name}: {} σ / ω_m", num(k)),
                points: tr
                    .noise_curve()
                    .iter()
                    .map(|(t, m)| (t.log10(), (m[o] / acc).log10()))
                    .collect(),
                mark: Mark::Line(colour(o), false),
            })
            .collect();
        panels.push(LinePanel {
            title: "noise part against the dwell".into(),
            x_label: "dwell per position, log10 (s)".into(),
            y_label: "log10 (noise part / accuracy)".into(),
            series,
            hlines: vec![("the whole accuracy".into(), 0.0, Mark::Line(LIMIT, true))],
            x_integer: false,
            y_from_zero: false,
        });
        let curve: Vec<(f64, f64)> = tr
            .points()
            .iter()
            .filter_map(|p| {
                p.objective()
                    .map(|j| (p.dwell_s().log10(), objective_to_arcmin(j)))
            })
            .collect();
        if !curve.is_empty() {
            panels.push(LinePanel {
                title: "the table's J against the dwell".into(),
                x_label: "dwell per position, log10 (s)".into(),
                y_label: "J (arcmin⁻²)".into(),
                series: vec![Series {
                    label: "direct allocation, noise part kept free".into(),
                    points: curve,
                    mark: Mark::Line(colour(0), false),
                }],
                hlines: vec![(
                    "J without noise".into(),
                    objective_to_arcmin(tr.noiseless_objective()),
                    Mark::Line(LIMIT, true),
                )],
                x_integer: false,
                y_from_zero: true,
            });
        }
        let cols = panels.len();
        let svg = figures::line_figure("Noise and test time", &panels, cols)?;
        let id = self.doc.figure(
            "tradeoff.svg",
            format!(
                "Left: each output's noise part ({} σ) over its accuracy against the dwell per position (dashed red: the whole accuracy; where the noise crosses it lies the shortest dwell). Right, when some table suffices: the J the table needs against the dwell (dashed red: J without noise).",
                num(k)
            ),
            svg,
        );
        self.figure_ids.push(("tradeoff", id));
        Ok(())
    }

    /// The verdict against the study's `[[specifications]]` (absent without): per
    /// specification its verdict line with the rule (as `end-to-end` prints it) and its GUM
    /// budget table, then one figure of every input's share of u_c² per specification. Every
    /// figure is the library's ([`e2e_verify::BudgetQuestions::plan_verdict`] through
    /// [`tt_lab::vendor::spec`]), in the specification's unit.
    pub(crate) fn specifications(&mut self) -> Result<()> {
        let c = self.c;
        let Some((_, v)) = &c.decision else {
            return Ok(());
        };
        let s = &c.study;
        let j = tt_lab::vendor::spec::SpecVerdictJson::new(s, Some(v));
        self.doc.h(
            2,
            "Specifications: uncertainty budgets and the decision rule",
        );
        self.doc.p(format!(
            "Every specification of the study is answered by a GUM uncertainty budget (JCGM 100) over the direct allocation's box under the study's reading `{}` (as `ttalloc end-to-end` states it): one row per input quantity (each turntable error, {} on its tolerance; each noise term of the output where the study models it), with its standard uncertainty u(x) in its own unit (rad for a table error, the output's unit for a noise term), its sensitivity coefficient c in the specification's unit per the input's unit, its contribution |c| u(x) and its degrees of freedom; then the combined standard uncertainty u_c, the effective degrees of freedom ν_eff (Welch-Satterthwaite; ∞ when every input's are), the coverage factor k, the expanded uncertainty U = k u_c, the limit and U / limit. Decision rule: {}.",
            c.answer.readings()[0].reading(),
            j.tolerance_distribution,
            doc::text(j.rule),
        ));
        let dof = |d: Option<f64>| d.map_or_else(|| "∞".to_string(), |d| sig(d, 3));
        let mut categories: Vec<String> = Vec::new();
        for sp in &j.specifications {
            for r in &sp.budget {
                if !categories.contains(&r.name) {
                    categories.push(r.name.clone());
                }
            }
        }
        let mut series = Vec::new();
        for (i, sp) in j.specifications.iter().enumerate() {
            self.doc.h(3, doc::text(&sp.quantity));
            self.doc
                .p(doc::text(&tt_lab::vendor::spec::spec_line(s, v, i)));
            let u = doc::text(&sp.unit);
            let mut rows: Vec<Vec<String>> = sp
                .budget
                .iter()
                .map(|r| {
                    vec![
                        doc::code(&r.name),
                        r.distribution.to_string(),
                        sig(r.standard_uncertainty, 4),
                        sig(r.shown_sensitivity, 4),
                        format!("{} {u}", sig(r.shown_contribution, 4)),
                        dof(r.dof),
                    ]
                })
                .collect();
            let blank = || "".to_string();
            for (what, value) in [
                (
                    "u_c",
                    format!("{} {u}", sig(sp.combined_standard_uncertainty, 4)),
                ),
                ("ν_eff", dof(sp.dof_eff)),
                ("k", num(sp.coverage_factor)),
                (
                    "U",
                    format!(
                        "{} {u} (p = {}%)",
                        sig(sp.expanded, 4),
                        num(100.0 * sp.coverage)
                    ),
                ),
                ("limit", format!("{} {u}", num(sp.limit))),
                ("U / limit", sig(sp.ratio, 4)),
            ] {
                rows.push(vec![
                    format!("**{what}**"),
                    blank(),
                    blank(),
                    blank(),
                    value,
                    blank(),
                ]);
            }
            self.doc.table(
                &[
                    "input",
                    "distribution",
                    "u(x)",
                    "c",
                    "contribution |c| u(x)",
                    "dof",
                ],
                rows,
            );
            // each input's share of u_c² (the library's contributions, squared over u_c²)
            let share: Vec<f64> = categories
                .iter()
                .map(|n| {
                    sp.budget
                        .iter()
                        .find(|r| &r.name == n)
                        .filter(|_| sp.combined_standard_uncertainty > 0.0)
                        .map_or(0.0, |r| {
                            100.0 * (r.contribution / sp.combined_standard_uncertainty).powi(2)
                        })
                })
                .collect();
            series.push((sp.quantity.clone(), share));
        }
        self.doc.p(doc::text(&tt_lab::vendor::spec::headline(s, v)));
        let svg = figures::hbar_figure(
            "Contributions to the combined variance u_c² per specification",
            &categories,
            &series,
            "share of u_c² (%)",
        )?;
        let id = self.doc.figure(
            "specification_contributions.svg",
            "Each input's contribution to the combined variance of every specification's budget, (|c| u(x))² / u_c² in percent: the inputs that dominate each verdict.",
            svg,
        );
        self.figure_ids.push(("specifications", id));
        Ok(())
    }

    /// The vendor's tolerances.
    pub(crate) fn vendor(&mut self) {
        let c = self.c;
        let Some((tol, chk)) = &c.vendor else { return };
        let outs = self.outputs();
        self.doc.h(2, "Vendor tolerances");
        self.doc.p(format!(
            "The tolerances of {}{} checked end to end under the study's reading: for every output the worst turntable within them (linearised, confirmed on the exact chain, with the derived second-order bound where the reading has one), the Monte Carlo yield, and each error's share of the worst case and of the variance (one share per group of errors that act only together).",
            doc::code(tol.source()),
            tol.name()
                .map_or(String::new(), |n| format!(" ({})", doc::text(n)))
        ));
        let mut rows = Vec::new();
        for o in chk.outputs() {
            let (n, u, _) = &outs[o.output()];
            let dominant: Vec<String> = o
                .dominant(3)
                .iter()
                .map(|k| {
                    format!(
                        "`{}` {}",
                        tt_lab::groups::contribution_name(&c.study.turntable, k.group()),
                        pct(k.worst_share())
                    )
                })
                .collect();
            rows.push(vec![
                format!("`{n}`"),
                format!("{} {u}", num(o.accuracy())),
                format!("{} {u}", sig(o.worst_case().exact_at_vertex(), 5)),
                o.worst_case()
                    .certified_bound()
                    .map_or("-".into(), |v| sig(v, 5)),
                pct(
                    chk.distribution().count().meeting_per_output()[o.output()] as f64
                        / chk.distribution().count().samples() as f64,
                ),
                match o.verdict() {
                    Verdict::Guaranteed => "**yes** (proven)".into(),
                    Verdict::Likely => "likely (not proven)".into(),
                    Verdict::Fails => "**no**".into(),
                },
                dominant.join(", "),
            ]);
        }
        self.doc.table(
            &[
                "output",
                "accuracy",
                "worst turntable",
                "proven bound",
                "random turntables meeting it",
                "meets",
                "dominant errors (share of the worst case)",
            ],
            rows,
        );
        let zeroed: Vec<usize> = chk
            .outputs()
            .iter()
            .filter(|o| o.worst_case().exact_at_vertex() == 0.0)
            .map(|o| o.output())
            .collect();
        self.precision_note(&zeroed);
        self.doc
            .callout(format!("Verdict: {}.", sheet_verdict(chk)));
        self.disc_allocation();
        self.vendor_rate();
    }

    /// The sheet's pairs (wobble, orthogonality) allocated with one tolerance each, as a disc
    /// and as a square ([`tt_lab::vendor::angle::sheet_allocations`]).
    fn disc_allocation(&mut self) {
        let Some(al) = &self.c.disc_alloc else { return };
        if al.is_empty() {
            return;
        }
        self.doc.p("The sheet states magnitudes (a wobble, a perpendicularity: sqrt(a_x^2 + a_y^2) <= w on two errors). Allocated with one tolerance per pair, read as the disc the vendor means and as the square around it (each value copied into both components); the angle-dependent model is every error any function of its shaft's angle unless the study declares its own. J in arcmin^-2 (direct allocation; certified on the exact chain where the reading has the second-order bound).");
        let j = |d: &e2e_verify::DirectAllocation| {
            if d.no_bound_needed() {
                "no bound needed".to_string()
            } else {
                sig(d.objective_arcmin(), 5)
            }
        };
        let cert = |d: &std::result::Result<e2e_verify::DirectAllocation, String>| match d {
            Ok(d) => j(d),
            Err(_) => "-".into(),
        };
        let mut rows = Vec::new();
        for (e2e, a) in al {
            rows.push(vec![
                format!("`{}`", e2e.reading()),
                j(&a.constant_disc),
                j(&a.constant_square),
                format!(
                    "{} (certified {})",
                    j(&a.angle_disc),
                    cert(&a.angle_disc_certified)
                ),
                format!(
                    "{} (certified {})",
                    j(&a.angle_square),
                    cert(&a.angle_square_certified)
                ),
            ]);
        }
        self.doc.table(
            &[
                "reading",
                "constant errors, discs",
                "constant errors, squares",
                "angle-dependent, discs",
                "angle-dependent, squares",
            ],
            rows,
        );
    }

    /// The direct allocation of a study with rate steps: the angles and the rate tolerances
    /// (rate accuracy, ripple, translations) allocated together (`tt_lab::vendor::rate::allocation`).
    pub(crate) fn rate_allocation(&mut self) {
        let c = self.c;
        let Some(ra) = &c.rate_alloc else { return };
        let a = &ra.allocation;
        let e2e = &c.e2e;
        let outs = self.outputs();
        self.doc.h(2, "Direct allocation with the rate tolerances");
        self.doc.p(format!(
            "The study has rate steps, where the table's rate accuracy, its rate ripple and its translations (the axes' non-intersection) act besides the angles. The direct allocation gives them tolerances together with the angles (reading {}): every output's worst case over both boxes within its accuracy to first order, then checked on the exact chain at each output's worst vertex. A tolerance costs in J what an angle of the same end-to-end influence costs (the weights' choice is documented at `RateQuestions::rate_tolerance_weights`). J = {} arcmin⁻² over both.",
            doc::code(&e2e.reading().to_string()),
            sig(a.combined().objective_arcmin(), 5)
        ));
        let names = e2e.turntable().rotation_error_names();
        let mut rows: Vec<Vec<String>> = names
            .iter()
            .zip(a.angles_rad())
            .map(|(n, u)| {
                vec![
                    doc::code(n),
                    if u.is_finite() {
                        format!("{} arcmin", sig(rad_to_arcmin(*u), 4))
                    } else {
                        "no bound needed".into()
                    },
                ]
            })
            .collect();
        rows.extend(
            e2e.rates()
                .rate_tolerance_names()
                .iter()
                .zip(a.tolerances())
                .zip(a.tolerance_bounds())
                .map(|((n, t), b)| {
                    vec![
                        doc::code(n),
                        if b.is_finite() {
                            let (v, unit) = tt_lab::vendor::rate::tolerance_in_sheet_units(t, *b);
                            format!("{} {unit}", sig(v, 4))
                        } else {
                            "no bound needed".into()
                        },
                    ]
                }),
        );
        self.doc.table(&["error", "allocated bound"], rows);
        let acc = e2e.accuracies();
        let rows = a
            .worst_cases()
            .iter()
            .map(|w| {
                let (n, u, _) = &outs[w.output()];
                vec![
                    format!("`{n}`"),
                    format!("{} {u}", num(acc[w.output()])),
                    format!("{} {u}", sig(w.linear_bound(), 5)),
                    format!("{} {u}", sig(w.exact_at_vertex(), 5)),
                    format!("{} {u}", sig(acc[w.output()] - w.exact_at_vertex(), 3)),
                ]
            })
            .collect();
        self.doc.table(
            &[
                "output",
                "accuracy",
                "worst case, both boxes (first order)",
                "exact chain at the worst vertex",
                "margin there",
            ],
            rows,
        );
        let (lo, hi) = ra.count.interval_95();
        self.doc.p(format!(
            "{:.2}% of {} random turntables within both allocated boxes meet every accuracy on the exact chain (95% interval {:.2}%-{:.2}%). Note: {}.",
            100.0 * ra.count.meeting() as f64 / ra.count.samples() as f64,
            ra.count.samples(),
            100.0 * lo,
            100.0 * hi,
            doc::text(e2e_verify::rate::NOT_CERTIFIED_AT_RATE_STEPS)
        ));
        match &ra.certified {
            Ok(c) => self.doc.p(format!(
                "Certified allocation with the rate tolerances (first-order worst case over both boxes plus the derived second-order bound of the revolution averages within every accuracy): J = {} arcmin^-2 against the direct allocation's {}; largest certified bound / accuracy {}.",
                sig(c.combined().objective_arcmin(), 5),
                sig(a.combined().objective_arcmin(), 5),
                sig(
                    (0..acc.len())
                        .filter_map(|k| c.certificate().map(|x| x.certified_bound(k) / acc[k]))
                        .fold(0.0, f64::max),
                    4
                )
            )),
            Err(why) => self
                .doc
                .p(format!("No certified allocation with the rate tolerances: {}.", doc::text(why))),
        }
    }

    /// The vendor check of a study with rate steps over the angular box and the sheet's rate
    /// errors and translations together (`check-turntable`'s `rate_steps`, computed once).
    fn vendor_rate(&mut self) {
        let c = self.c;
        let Some(r) = &c.vendor_rate else { return };
        let outs = self.outputs();
        let e2e = &c.e2e;
        self.doc
            .h(3, "Rate errors and translations at the rate steps");
        self.doc.p(format!(
            "At a rate step the table's rate accuracy, its rate ripple (first harmonic, cosine and sine parts, each within the sheet's ripple) and its translations (the axes' non-intersection) act besides the angles; the table above holds them at zero. Here the sheet bounds them: the worst case over the angular box and their box together (reading {}, linearised, confirmed on the exact chain at the worst vertex), each one's part of it at the entry where it is reached, and the Monte Carlo yield over both boxes ({}).",
            doc::code(&e2e.reading().to_string()),
            doc::code("check-turntable --json: rate_steps")
        ));
        let names = e2e.extra_names();
        let mut header: Vec<String> = vec!["error".into(), "bound".into()];
        header.extend(
            r.outputs
                .iter()
                .map(|o| format!("part for `{}` ({})", outs[o.output()].0, outs[o.output()].1)),
        );
        let rows = e2e
            .extra_errors()
            .iter()
            .enumerate()
            .map(|(i, x)| {
                let (b, unit) = tt_lab::vendor::rate::in_sheet_units(x, r.bounds[i]);
                let mut row = vec![doc::code(&names[i]), format!("{} {unit}", num(b))];
                row.extend(r.outputs.iter().map(|o| sig(o.extra_parts()[i], 4)));
                row
            })
            .collect();
        let h: Vec<&str> = header.iter().map(String::as_str).collect();
        self.doc.table(&h, rows);
        let acc = e2e.accuracies();
        let rows = r
            .outputs
            .iter()
            .map(|o| {
                let (n, u, _) = &outs[o.output()];
                let meets =
                    o.linear_bound() <= acc[o.output()] && o.exact_at_vertex() <= acc[o.output()];
                vec![
                    format!("`{n}`"),
                    format!("{} {u}", num(acc[o.output()])),
                    format!("{} {u}", sig(o.linear_bound(), 5)),
                    sig(o.angular_part(), 4),
                    sig(o.extra_part(), 4),
                    o.position().to_string(),
                    format!("{} {u}", sig(o.exact_at_vertex(), 5)),
                    format!("{} {u}", sig(r.max_drawn[o.output()], 5)),
                    yes_no(meets),
                ]
            })
            .collect();
        self.doc.table(
            &[
                "output",
                "accuracy",
                "worst case, both boxes",
                "angles' part",
                "rate errors' and translations' part",
                "entry",
                "exact chain at the worst vertex",
                "largest error drawn",
                "meets",
            ],
            rows,
        );
        self.doc.callout(format!(
            "Verdict with the rate errors and translations: {}.",
            verdict_sentence(e2e, r)
        ));
    }

    /// The allocation when the study's errors vary with the shaft angle, and after its measured
    /// errors are compensated (`tt_lab::allocation::angle`).
    pub(crate) fn angle_allocation(&mut self) {
        let Some(a) = &self.c.angle_alloc else { return };
        let names = self.c.study.turntable.rotation_error_names();
        self.doc
            .h(2, "Errors that vary with the shaft angle, and compensation");
        if a.varies {
            let models: Vec<String> = names
                .iter()
                .zip(&a.variations)
                .map(|(n, v)| {
                    format!(
                        "{} {}",
                        doc::code(n),
                        doc::text(&tt_lab::allocation::angle::model_name(v))
                    )
                })
                .collect();
            self.doc.p(format!(
                "The study's errors vary with the shaft angle ({}); every bound holds over the whole revolution. The direct allocation under that model (each error's dual norm in place of its coefficient), certified on the exact chain where the reading has a second-order bound, beside the constant model's.",
                models.join(", ")
            ));
        } else {
            self.doc.p("The study gives measured errors: the allocation with them compensated beside the allocation without.");
        }
        let j = |d: &e2e_verify::DirectAllocation| {
            if d.no_bound_needed() {
                "no bound needed".to_string()
            } else {
                sig(d.objective_arcmin(), 5)
            }
        };
        let rows = a
            .readings
            .iter()
            .map(|r| {
                vec![
                    doc::code(&r.reading.to_string()),
                    j(&r.constant_direct),
                    j(&r.direct),
                    r.certified.as_ref().map_or("-".into(), &j),
                    match &r.compensated {
                        Some(Ok(d)) => format!(
                            "{} (before: {})",
                            j(d),
                            r.unmeasured_before_arcmin.map_or("-".into(), |v| sig(v, 5))
                        ),
                        Some(Err(why)) => doc::text(why),
                        None => "-".into(),
                    },
                ]
            })
            .collect();
        self.doc.table(
            &[
                "reading",
                "J, constant model",
                "J, the study's model",
                "J certified",
                "J of the unmeasured errors, compensated",
            ],
            rows,
        );
    }

    /// Which table errors the calibration estimates itself: the joint least squares of the
    /// sensor coefficients and the table errors (`cargo xtask estimable`).
    pub(crate) fn estimable(&mut self) {
        let c = self.c;
        self.doc
            .h(2, "Table errors the calibration estimates itself");
        let Some(a) = &c.estimable else {
            self.doc.p(format!(
                "Joint estimation {}.",
                crate::report::ESTIMABLE_STATIC_ONLY
            ));
            return;
        };
        let est = &a.est;
        let names = est.names();
        if let Some(m) = tt_lab::estimable::model_words(a) {
            self.doc.p(format!(
                "Error model: {}; every answer below is of this model.",
                doc::text(&m)
            ));
        }
        self.doc.p(format!(
            "A joint least squares of the sensor coefficients and the table errors from the same data (outputs simulated at the actual orientation, the user's reading): the joint Jacobian at zero table error has rank {} of {} ({} coefficients and {} table parameters; singular values of the table part counted above {} of the largest raw effect, rows weighted by 1/accuracy). {} combinations of the errors are estimable with the coefficients; {} are not: their effect lies in the sensor's columns, the calibration absorbs it.",
            est.rank(),
            est.columns(),
            est.coefficients(),
            names.len(),
            sig(calib_lsq::joint::JOINT_RANK_RTOL, 1),
            est.table_rank(),
            names.len() - est.table_rank(),
        ));
        let reference = est.reference();
        let sv: Vec<String> = est
            .singular_values()
            .iter()
            .map(|v| sig(if reference > 0.0 { v / reference } else { 0.0 }, 3))
            .collect();
        self.doc.p(format!(
            "Singular values of the table part relative to the largest raw effect: {} (the smallest counted one says how weakly the least estimable combination shows in the data).",
            sv.join(", ")
        ));
        let mut rows: Vec<Vec<String>> = est
            .estimable_combinations()
            .iter()
            .map(|comb| vec!["estimable".into(), doc::code(&comb.to_string())])
            .collect();
        rows.extend(
            est.invisible_combinations()
                .iter()
                .map(|comb| vec!["not estimable".into(), doc::code(&comb.to_string())]),
        );
        self.doc.table(&["", "combination"], rows);
        let alloc = |d: &e2e_verify::DirectAllocation| {
            if d.no_bound_needed() {
                "no bound needed for any error".to_string()
            } else {
                format!("J = {} arcmin^-2", sig(d.objective_arcmin(), 5))
            }
        };
        self.doc.p(format!(
            "Direct allocation (user's reading, first order): {} with the ordinary calibration; {} when the estimable combinations are estimated (the rest keep their first-order effect).",
            alloc(&a.ordinary),
            alloc(&a.joint),
        ));
        let what = if a.at_box.source == "tolerances" {
            "the vendor's sheet"
        } else {
            "the ordinary direct allocation's box"
        };
        let outs = self.outputs();
        let rows = a
            .at_box
            .rates
            .iter()
            .enumerate()
            .map(|(k, (p, j))| {
                let (n, u, acc) = &outs[k];
                vec![
                    format!("`{n}`"),
                    format!("{} {u}", num(*acc)),
                    format!("{} {u}", sig(*p, 4)),
                    format!("{} {u}", sig(*j, 3)),
                ]
            })
            .collect();
        self.doc.p(format!(
            "At the worst turntable of {what} (exact chain, noiseless sensor; the joint estimator by Gauss-Newton from zero):"
        ));
        self.doc.table(
            &[
                "output",
                "accuracy",
                "ordinary calibration",
                "joint estimator",
            ],
            rows,
        );
    }

    /// Every output's worst turntable within the sheet against its accuracy, with the
    /// dominant error (or group), for the answer at the top.
    fn sheet_outputs(&self, chk: &e2e_verify::TurntableCheck) -> String {
        let outs = self.outputs();
        let t = &self.c.study.turntable;
        let per: Vec<String> = chk
            .outputs()
            .iter()
            .map(|o| {
                let (n, u, _) = &outs[o.output()];
                let top = o
                    .contributions()
                    .iter()
                    .filter(|k| k.worst_share() > 0.0)
                    .max_by(|a, b| a.worst_share().total_cmp(&b.worst_share()));
                format!(
                    "`{n}` {} {u} against {} {u} ({}{})",
                    sig(o.worst_case().exact_at_vertex(), 4),
                    num(o.accuracy()),
                    match o.verdict() {
                        Verdict::Guaranteed => "**yes**, proven",
                        Verdict::Likely => "likely, not proven",
                        Verdict::Fails => "**no**",
                    },
                    top.map_or(String::new(), |k| format!(
                        "; dominant `{}` {}",
                        tt_lab::groups::contribution_name(t, k.group()),
                        pct(k.worst_share())
                    ))
                )
            })
            .collect();
        format!(
            "The worst turntable within the sheet under the study's reading `{}` ([vendor tolerances](#vendor-tolerances)): {}.",
            self.c.study.reading,
            per.join(", ")
        )
    }

    /// The study's schedule beside the designed one.
    pub(crate) fn designed(&mut self) {
        let c = self.c;
        let Some([a, b]) = &c.designed else { return };
        let outs = self.outputs();
        self.doc.h(2, "Designed schedule");
        self.doc.p(format!(
            "The study's schedule beside the designed one of {} (same sensor, site, turntable and reading): J of the direct allocation under the study's reading (the cost of the turntable that meets every output's accuracy; lower is a cheaper table), the condition number of every output's regression, and the orientation requirement.",
            doc::code(&b.path)
        ));
        let req = |r: &Result<OrientationRequirement, CalibError>| match r {
            Ok(q) => (0..3)
                .map(|k| {
                    q.requirement().to_array()[k].map_or("none".into(), |v| num(rad_to_deg(v)))
                })
                .collect::<Vec<_>>()
                .join(" / "),
            Err(e) => format!("none ({e})"),
        };
        let conds = |f: &crate::compute::ScheduleFacts| {
            f.conditions
                .iter()
                .zip(&outs)
                .map(|(v, o)| format!("{} {}", o.0, sig(*v, 4)))
                .collect::<Vec<_>>()
                .join(", ")
        };
        let rows = [("study's", a), ("designed", b)]
            .iter()
            .map(|(name, f)| {
                vec![
                    format!("{name} ({})", doc::code(&f.path)),
                    f.positions.to_string(),
                    format!("{:.3}", f.direct_objective_arcmin),
                    conds(f),
                    req(&f.requirement),
                ]
            })
            .collect();
        self.doc.table(
            &[
                "schedule",
                "positions",
                "J direct (arcmin⁻²)",
                "condition numbers",
                "I_ψ / I_θ / I_γ (deg)",
            ],
            rows,
        );
        let ratio = a.direct_objective_arcmin / b.direct_objective_arcmin;
        let (jb, ja) = (
            format!("{:.3}", b.direct_objective_arcmin),
            format!("{:.3}", a.direct_objective_arcmin),
        );
        self.doc.p(if a.positions_deg == b.positions_deg {
            format!(
                "The designed file has the study's own positions: the same turntable, J {ja} for both."
            )
        } else if ja == jb {
            format!(
                "The designed schedule's turntable is as demanding as the study's: J {ja} for both (to the digits shown)."
            )
        } else {
            format!(
                "The designed schedule's turntable is {} demanding: J {jb} vs {ja} ({}×).",
                if ratio >= 1.0 { "less" } else { "more" },
                sig(if ratio >= 1.0 { ratio } else { 1.0 / ratio }, 3)
            )
        });
    }
}

/// A CSV field (RFC 4180) from a file's text (a unit): control characters shown escaped
/// ([`tt_core::human::visible`]), in double quotes when it holds a comma or a quote.
#[must_use]
fn csv_field(s: &str) -> String {
    let v = tt_core::human::visible(s);
    if v.contains([',', '"']) {
        format!("\"{}\"", v.replace('"', "\"\""))
    } else {
        v.into_owned()
    }
}

/// The verdict over both boxes as a sentence (Markdown): whether every output's worst case
/// (linear and at the worst vertex on the exact chain) is within its accuracy, and the yield.
#[must_use]
fn verdict_sentence(e2e: &e2e_verify::EndToEnd, c: &tt_lab::vendor::rate::RateCheck) -> String {
    let (lo, hi) = c.count.interval_95();
    let verdict = if c.meets_every_accuracy(e2e) {
        "these tolerances **meet** every accuracy with the rate errors and translations at their bounds (the worst turntable of both boxes, linearised and on the exact chain at its vertex)"
    } else {
        "these tolerances do **not** meet every accuracy with the rate errors and translations at their bounds (a turntable within both boxes misses)"
    };
    let (rule, alone) = if c.noise.is_some() {
        (format!(" (rule: {})", c.rule()), ", the table alone")
    } else {
        (String::new(), "")
    };
    format!(
        "{verdict}{rule}; {:.2}% of {} random turntables over both boxes meet every accuracy (95% interval {:.2}%-{:.2}%{alone})",
        100.0 * c.count.meeting() as f64 / c.count.samples() as f64,
        c.count.samples(),
        100.0 * lo,
        100.0 * hi
    )
}
