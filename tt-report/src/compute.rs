//! Everything a report prints, computed by the libraries (this module only calls them, in
//! parallel where they are independent, and keeps the results): the requirement and its
//! surfaces, the sensitivities, the two-step and equal-effects allocations with their
//! certificates, the Monte Carlo, the end-to-end answer, the vendor check, the designed
//! schedule's comparison and, for the paper, the claims.

use crate::{Error, Result};
use alloc_opt::{
    Allocation, AllocationProblem, Allocator, EqualEffects, ExactAxisCheck, SensitivityWeighted,
    exact_chain_check,
};
use calib_lsq::{CalibError, OrientationRequirement, Reading, RequirementProblem, Surface};
use e2e_verify::ToleranceSheet;
use e2e_verify::paper::registry::{self, ClaimEvaluation, PaperRun};
use e2e_verify::{BuyersAnswer, EndToEnd, TurntableCheck};
use mc_verify::{ErrorBox, McConfig, McResult, MonteCarlo};
use rayon::prelude::*;
use std::time::Instant;
use study::Study;
use tt_kinematics::LinearModel;
use tt_lab::InputError;
use tt_lab::loaded::{self as st, StudyRequirement};

/// Grid points per side of a rate-error surface.
pub(crate) const SURFACE_POINTS: usize = 41;
/// Rays of a line of intersection (the boundary $\Delta\omega = \omega_m$).
pub(crate) const BOUNDARY_RAYS: usize = 120;
/// Points of a one-angle cut.
pub(crate) const CUT_POINTS: usize = 81;

/// What to compute.
#[derive(Debug, Clone)]
pub(crate) struct Options {
    /// Monte Carlo seed.
    pub seed: u64,
    /// Monte Carlo turntables per box.
    pub samples: u64,
    /// The paper's extras: Table 4 and the claims.
    pub paper: bool,
    /// A vendor's tolerances to check.
    pub tolerances: Option<ToleranceSheet>,
    /// A second study with a designed schedule.
    pub designed: Option<Study>,
    /// A processed recording (its section).
    pub run: Option<crate::ProcessedRun>,
    /// The JCGM 101 Monte Carlo's options (`None`: not run).
    pub jcgm101: Option<tt_lab::budget_mc::Options>,
}

/// One output's orientation-error plane: the data of the surfaces, lines and cuts.
#[derive(Debug, Clone)]
pub(crate) struct OutputPlane {
    /// Output index.
    pub output: usize,
    /// The angles it is sensitive to (indices into psi, theta, gamma).
    pub sensitive: Vec<usize>,
    /// The plotted plane (two sensitive angles; the third angle zero).
    pub plane: Option<[usize; 2]>,
    /// The surface over the plane.
    pub surface: Option<Surface>,
    /// The line $\Delta\omega = \omega_m$ in the plane (or why there is none).
    pub boundary: Result<Vec<[f64; 2]>, String>,
    /// $\Delta\omega$ against each angle (the others zero): (angle, [(rad, value)]).
    pub cuts: Vec<(usize, Vec<(f64, f64)>)>,
}

/// The two-step allocation and what follows from it.
#[derive(Debug, Clone)]
pub(crate) struct TwoStep {
    /// The problem (first-order model, the study's requirement, lower bounds).
    pub problem: AllocationProblem,
    /// The sensitivity-weighted allocation (the paper's method solved to the optimum).
    pub ours: Allocation,
    /// Its check on the exact chain (a search for the second-order excess).
    pub exact: Vec<ExactAxisCheck>,
    /// The Monte Carlo of its box with the requirement.
    pub monte_carlo: MonteCarlo,
    /// Its result.
    pub result: McResult,
}

/// One schedule's facts for the side-by-side comparison.
#[derive(Debug, Clone)]
pub(crate) struct ScheduleFacts {
    /// The study path as given.
    pub path: String,
    /// Number of positions.
    pub positions: usize,
    /// The static positions (joint angles, deg).
    pub positions_deg: Vec<Vec<f64>>,
    /// $J$ of the direct allocation under the study's reading, arcmin$^{-2}$.
    pub direct_objective_arcmin: f64,
    /// Condition number per output.
    pub conditions: Vec<f64>,
    /// The computed requirement.
    pub requirement: std::result::Result<OrientationRequirement, CalibError>,
}

/// The paper's extras.
#[derive(Debug, Clone)]
pub(crate) struct PaperExtras {
    /// The Monte Carlo of Table 4's box with the requirement of eq 16.
    pub table4_monte_carlo: MonteCarlo,
    /// Its result.
    pub table4_result: McResult,
    /// Every claim of the registry, evaluated on this run.
    pub claims: Vec<ClaimEvaluation>,
}

/// The computed report.
#[derive(Debug, Clone)]
pub(crate) struct Computed {
    /// The study.
    pub study: Study,
    /// The options.
    pub options: Options,
    /// The requirement handed to the allocation and the computed one.
    pub requirement: StudyRequirement,
    /// The requirement under the readings shown side by side (the study's first).
    pub readings: Vec<(
        Reading,
        std::result::Result<OrientationRequirement, CalibError>,
    )>,
    /// Per output.
    pub planes: Vec<OutputPlane>,
    /// Average sensitivities per error: `[psi, theta, gamma]` (eq 28).
    pub sensitivity: Vec<[f64; 3]>,
    /// The two-step allocation (`None`: no requirement).
    pub two_step: Option<TwoStep>,
    /// The equal-effects allocation of the same problem.
    pub equal: Option<Allocation>,
    /// The end-to-end simulator (the study's reading).
    pub e2e: EndToEnd,
    /// Its answer (the study's reading, then the user's).
    pub answer: BuyersAnswer,
    /// The vendor check.
    pub vendor: Option<(ToleranceSheet, TurntableCheck)>,
    /// The study's schedule beside the designed one.
    pub designed: Option<[ScheduleFacts; 2]>,
    /// The answer for both error sources (the study's noise over its timing, 3 sigma), when
    /// the study gives noise and a timing.
    pub noise: Option<tt_lab::end_to_end::NoisyAnswer>,
    /// The vendor check with the noise part (study's reading), when both are given.
    pub vendor_noise: Option<tt_lab::vendor::NoisyCheck>,
    /// The vendor check over the angular box and the sheet's rate errors and translations
    /// together (study's reading; `check-turntable`'s `rate_steps`), for a study with rate
    /// steps.
    pub vendor_rate: Option<tt_lab::vendor::rate::RateCheck>,
    /// The direct allocation of the angles and the rate tolerances together (study's
    /// reading), for a study with rate steps.
    pub rate_alloc: Option<tt_lab::vendor::rate::RateAllocated>,
    /// The paper's extras.
    pub paper: Option<PaperExtras>,
    /// Which table errors the calibration estimates itself (joint least squares, user's
    /// reading), at the vendor's sheet when given.
    /// `None` for a study with rate steps (the joint estimation takes static positions only).
    pub estimable: Option<tt_lab::estimable::Estimable>,
    /// The allocations under the study's angle-dependent model and after compensation
    /// (`None` when the study declares neither).
    pub angle_alloc: Option<tt_lab::allocation::angle::AngleAllocations>,
    /// The vendor sheet's pairs (wobble, orthogonality) allocated with one tolerance each, as
    /// a disc and as a square, per reading ([`tt_lab::vendor::angle::sheet_allocations`]; empty when
    /// the sheet states no pair, `None` without a sheet or for a study with rate steps).
    pub disc_alloc: Option<Vec<(EndToEnd, tt_lab::vendor::angle::DiscAllocation)>>,
    /// The verdict against the study's `[[specifications]]` (a GUM budget each) over the
    /// direct allocation's box under the study's reading, as `end-to-end` states it, with the
    /// tolerances it was evaluated at (rad); `None` without specifications.
    pub decision: Option<(Vec<f64>, e2e_verify::budget::PlanVerdict)>,
    /// The JCGM 101 Monte Carlo of the same specifications over the same tolerances
    /// (`report --jcgm101`; `None` without it or without specifications).
    pub jcgm101: Option<tt_lab::budget_mc::Jcgm101>,
    /// The study's specifications no table can meet (the noise part alone fills the limit),
    /// left out of the direct and the yield-based allocations, as `end-to-end` says them
    /// ([`tt_lab::end_to_end::EndToEndAnswer::no_table_suffices`]; the study's names
    /// unescaped).
    pub no_table_suffices: Vec<tt_lab::allocation::spec::NoTableSuffices>,
    /// Wall-clock seconds of the computation.
    pub seconds: f64,
}

/// The end-to-end answer, the vendor check and (for the paper) Table 4's Monte Carlo.
type AnswerPart = (
    BuyersAnswer,
    Option<(ToleranceSheet, TurntableCheck)>,
    Option<(MonteCarlo, McResult)>,
    Option<tt_lab::end_to_end::NoisyAnswer>,
);

/// With `XTASK_TIMING` set, print how long a phase took (to standard error).
fn timing(what: &str, since: Instant) {
    if std::env::var_os("XTASK_TIMING").is_some() {
        eprintln!("timing: {what}: {:.2} s", since.elapsed().as_secs_f64());
    }
}

fn calib(s: &Study, e: CalibError) -> tt_lab::LabError {
    tt_lab::error::library(e, s)
}

/// The planes, cuts and surfaces of every output.
fn planes(
    s: &Study,
    problem: &RequirementProblem,
    req: Option<&OrientationRequirement>,
) -> Result<Vec<OutputPlane>> {
    let mut out = Vec::new();
    for k in 0..s.sensor.n_outputs() {
        let region = problem.region(k).map_err(|e| calib(s, e))?;
        let sensitive = region.sensitive_angles().to_vec();
        let name = region.output().to_string();
        let bx = req.and_then(|r| r.boxes().iter().find(|b| b.output() == name));
        let plane = match sensitive.len() {
            0 | 1 => None,
            2 => Some([sensitive[0], sensitive[1]]),
            _ => {
                // the two most constraining angles of the output's box
                let mut by: Vec<usize> = sensitive.clone();
                if let Some(b) = bx {
                    by.sort_by(|a, c| {
                        b.half_rad()[*a]
                            .unwrap_or(f64::INFINITY)
                            .total_cmp(&b.half_rad()[*c].unwrap_or(f64::INFINITY))
                    });
                }
                let mut two = [by[0], by[1]];
                two.sort_unstable();
                Some(two)
            }
        };
        let half_box = bx
            .map(|b| {
                b.half_rad()
                    .iter()
                    .flatten()
                    .fold(0.0_f64, |m, v| m.max(*v))
            })
            .filter(|h| *h > 0.0);
        let Some(half_box) = half_box else {
            out.push(OutputPlane {
                output: k,
                sensitive,
                plane,
                surface: None,
                boundary: Err("the output does not constrain a constant orientation error".into()),
                cuts: Vec::new(),
            });
            continue;
        };
        let half = 2.0 * half_box;
        let surface = match plane {
            Some(p) => Some(
                region
                    .surface(p, half, SURFACE_POINTS)
                    .map_err(|e| calib(s, e))?,
            ),
            None => None,
        };
        let boundary = match plane {
            Some(p) => region.boundary(p, BOUNDARY_RAYS).map_err(|e| e.to_string()),
            None => Err("the output depends on one angle only".into()),
        };
        let cuts = (0..3)
            .map(|angle| {
                Ok((
                    angle,
                    region
                        .cut(angle, half, CUT_POINTS)
                        .map_err(|e| calib(s, e))?,
                ))
            })
            .collect::<Result<Vec<_>>>()?;
        out.push(OutputPlane {
            output: k,
            sensitive,
            plane,
            surface,
            boundary,
            cuts,
        });
    }
    Ok(out)
}

/// The facts of one study's schedule (for the designed-schedule comparison).
fn schedule_facts(s: &Study) -> Result<ScheduleFacts> {
    let e2e = tt_lab::loaded::simulator(s)?;
    let linear = e2e.linearization();
    let direct = e2e
        .allocate_direct(&linear, &s.lower_bounds_rad)
        .map_err(|e| tt_lab::error::library(e, s))?;
    Ok(ScheduleFacts {
        path: s.path.clone(),
        positions: s.positions_deg.len(),
        positions_deg: s.positions_deg.clone(),
        direct_objective_arcmin: direct.objective_arcmin(),
        conditions: s.calibration.condition_numbers(),
        requirement: st::requirement_problem(s).requirement(),
    })
}

/// The first key of the study file at which the designed study `d` differs from `s` in what
/// must be the same (everything but the schedule), or `None`.
fn differing_key(s: &Study, d: &Study) -> Option<String> {
    let (a, b) = (&s.turntable, &d.turntable);
    if a != b {
        if let Some(i) = (0..a.factors().len().max(b.factors().len()))
            .find(|&i| a.factors().get(i) != b.factors().get(i))
        {
            return Some(format!("turntable.factors[{i}]"));
        }
        if a.rotation_error_names() != b.rotation_error_names()
            || a.translation_error_names() != b.translation_error_names()
        {
            return Some("turntable.error_order".into());
        }
        if let Some(j) = (0..a.n_joints()).find(|&j| {
            a.joint_ranges_rad()[j].map(f64::to_bits) != b.joint_ranges_rad()[j].map(f64::to_bits)
        }) {
            return Some(format!("turntable.joint_ranges_deg.{}", a.joint_names()[j]));
        }
        let names = a
            .joint_names()
            .into_iter()
            .chain(a.rotation_error_names())
            .chain(a.translation_error_names());
        for n in names {
            if a.description_of(n) != b.description_of(n) {
                return Some(format!("turntable.descriptions.{n}"));
            }
        }
        return Some("turntable".into());
    }
    let (oa, ob) = (s.sensor.outputs(), d.sensor.outputs());
    if oa.len() != ob.len() {
        return Some("sensor.outputs".into());
    }
    for (i, (x, y)) in oa.iter().zip(ob).enumerate() {
        for (key, same) in [
            ("name", x.name == y.name),
            ("unit", x.unit == y.unit),
            ("accuracy", x.accuracy.to_bits() == y.accuracy.to_bits()),
            ("terms", x.terms == y.terms),
        ] {
            if !same {
                return Some(format!("sensor.outputs[{i}].{key}"));
            }
        }
    }
    if s.site.latitude_rad().to_bits() != d.site.latitude_rad().to_bits() {
        return Some("site.latitude_deg".into());
    }
    if s.site != d.site {
        return Some("site.earth_rate_rad_per_s".into());
    }
    if s.reading != d.reading {
        return Some("calibration.reading".into());
    }
    if s.delta_r_kind != d.delta_r_kind {
        return Some("calibration.delta_r".into());
    }
    let names = s.turntable.rotation_error_names();
    if let Some(j) = (0..names.len())
        .find(|&j| s.lower_bounds_rad[j].to_bits() != d.lower_bounds_rad[j].to_bits())
    {
        return Some(format!("{}.{}", tt_lab::error::LOWER_BOUNDS_KEY, names[j]));
    }
    differing_model_key(s, d)
}

/// The first key at which the error models, the noise, the mounting, the requirement or the
/// Monte Carlo settings of `d` differ from `s`'s (the turntable, sensor, site and reading
/// being the same), or `None`.
fn differing_model_key(s: &Study, d: &Study) -> Option<String> {
    let names = s.turntable.rotation_error_names();
    if let Some(j) = (0..names.len()).find(|&j| s.variations[j] != d.variations[j]) {
        // the factor that declares the error's variation
        let i = s.turntable.factors().iter().position(
            |f| matches!(f, tt_kinematics::Factor::Rotation { error, .. } if *error == j),
        );
        // the factor's `varies`, `of` and `harmonics` keys
        return Some(i.map_or_else(
            || "turntable.factors".into(),
            |i| format!("turntable.factors[{i}]"),
        ));
    }
    if let Some(j) = (0..names.len()).find(|&j| s.measured[j] != d.measured[j]) {
        return Some(format!("compensation.measured ({})", names[j]));
    }
    if let Some(i) = (0..s.noise.len()).find(|&i| s.noise[i] != d.noise[i]) {
        return Some(format!("sensor.outputs[{i}].noise"));
    }
    if s.lever_arm_m.map(f64::to_bits) != d.lever_arm_m.map(f64::to_bits) {
        return Some("sensor.lever_arm_m".into());
    }
    let joints = s.turntable.joint_names();
    if let Some(j) = (0..joints.len()).find(|&j| {
        s.max_rate_deg_per_s[j].map(f64::to_bits) != d.max_rate_deg_per_s[j].map(f64::to_bits)
    }) {
        return Some(format!("turntable.max_rate_deg_per_s.{}", joints[j]));
    }
    if s.requirement != d.requirement {
        return Some("requirement".into());
    }
    (s.monte_carlo != d.monte_carlo).then(|| "monte_carlo".into())
}

/// The designed study must describe the same turntable (its error models included), sensor
/// (its noise included), site, reading, lower bounds, requirement and Monte Carlo: only the
/// schedule (positions, timing, rate steps), the name and the description may differ; the
/// error names the first key that differs.
fn check_designed(s: &Study, d: &Study) -> Result<(), InputError> {
    match differing_key(s, d) {
        None => Ok(()),
        Some(key) => Err(InputError::new(
            format!("--designed {}: key `{key}`", d.path),
            format!(
                "differs from the study {}: the designed study must describe the same turntable (its error models included), sensor (its noise included), site, reading, lower bounds, requirement and Monte Carlo (only the schedule may differ: positions, timing, rate steps)",
                s.path
            ),
        )),
    }
}

/// What every part of the report starts from: the study's requirement, the end-to-end
/// simulator and its inputs, the two-step allocation's problem (`None` without a static
/// requirement) and the Monte Carlo histogram's bins.
struct Setup {
    requirement: StudyRequirement,
    problem: RequirementProblem,
    e2e: EndToEnd,
    inputs: e2e_verify::EndToEndInputs,
    alloc_problem: Option<AllocationProblem>,
    bins: usize,
    /// The specifications no table can meet (left out of the allocations).
    no_table_suffices: Vec<tt_lab::allocation::spec::NoTableSuffices>,
}

/// The left branch's results: the two-step allocation, the end-to-end answer, the vendor
/// check, Table 4's Monte Carlo (the paper) and the noise part.
type Left = (
    Option<TwoStep>,
    BuyersAnswer,
    Option<(ToleranceSheet, TurntableCheck)>,
    Option<(MonteCarlo, McResult)>,
    Option<tt_lab::end_to_end::NoisyAnswer>,
);

/// The right branch's results: equal effects, the readings' requirements, the planes, the
/// average sensitivities and the designed schedule's facts.
type Right = (
    Option<Allocation>,
    Vec<(
        Reading,
        std::result::Result<OrientationRequirement, CalibError>,
    )>,
    Vec<OutputPlane>,
    Vec<[f64; 3]>,
    Option<[ScheduleFacts; 2]>,
);

/// The answers computed after both branches (each needs the end-to-end answer or none).
struct Later {
    vendor_noise: Option<tt_lab::vendor::NoisyCheck>,
    vendor_rate: Option<tt_lab::vendor::rate::RateCheck>,
    rate_alloc: Option<tt_lab::vendor::rate::RateAllocated>,
    estimable: Option<tt_lab::estimable::Estimable>,
    angle_alloc: Option<tt_lab::allocation::angle::AngleAllocations>,
    disc_alloc: Option<Vec<(EndToEnd, tt_lab::vendor::angle::DiscAllocation)>>,
    decision: Option<(Vec<f64>, e2e_verify::budget::PlanVerdict)>,
    jcgm101: Option<tt_lab::budget_mc::Jcgm101>,
}

/// Compute the report of `study`.
///
/// # Errors
/// [`InputError`]s for inputs the libraries reject (exit 2), other errors when a solver
/// fails.
pub(crate) fn compute(study: Study, options: Options) -> Result<Computed> {
    let started = Instant::now();
    let s = &study;
    let setup = setup(s, &options)?;
    // Two independent branches on the two cores: (two-step, its Monte Carlo, the end-to-end
    // answer that reuses it, the vendor check) and (equal effects, surfaces, readings,
    // sensitivities, the designed schedule).
    let (left, right): (Result<Left>, Result<Right>) = rayon::join(
        || left_branch(s, &options, &setup),
        || right_branch(s, &options, &setup),
    );
    let (two_step, answer, vendor, table4, noise) = left?;
    let (equal, readings, planes, sensitivity, designed) = right?;
    let paper = paper_extras(
        s,
        &setup,
        table4,
        two_step.as_ref(),
        equal.as_ref(),
        &answer,
    )?;
    let later = later(s, &options, &setup, &answer, vendor.as_ref(), started)?;
    let Setup {
        requirement,
        e2e,
        no_table_suffices,
        ..
    } = setup;
    Ok(Computed {
        no_table_suffices,
        jcgm101: later.jcgm101,
        decision: later.decision,
        disc_alloc: later.disc_alloc,
        estimable: later.estimable,
        angle_alloc: later.angle_alloc,
        noise,
        vendor_noise: later.vendor_noise,
        vendor_rate: later.vendor_rate,
        rate_alloc: later.rate_alloc,
        study,
        options,
        requirement,
        readings,
        planes,
        sensitivity,
        two_step,
        equal,
        e2e,
        answer,
        vendor,
        designed,
        paper,
        seconds: started.elapsed().as_secs_f64(),
    })
}

/// The designed study checked, the requirement, the simulator and its inputs, the two-step
/// allocation's problem.
fn setup(s: &Study, options: &Options) -> Result<Setup> {
    if let Some(d) = &options.designed {
        check_designed(s, d)?;
    }
    let requirement = st::requirement(s)?;
    let problem = st::requirement_problem(s);
    let e2e = tt_lab::loaded::simulator(s)?;
    // the requirement above is the one `inputs` would compute again (a box search per output)
    let mut inputs = tt_lab::end_to_end::inputs_with(
        s,
        &requirement,
        options.samples,
        options.seed,
        e2e_verify::DEFAULT_YIELD_FRACTION,
    );
    // the direct allocations hold the study's specifications, as `end-to-end`'s do
    let specified = tt_lab::allocation::spec::context(s, &e2e)?;
    inputs.specifications = specified.context;
    // `inputs` adds Table 4 for the paper's table; only the paper's reproduction shows it
    inputs
        .extra_boxes
        .retain(|(n, _)| options.paper && n == e2e_verify::paper::TABLE4_BOX);
    let paper_table = options.paper && s.turntable == tt_kinematics::paper::table3();
    if options.paper && !paper_table {
        return Err(InputError::new(
            &s.path,
            "the paper's reproduction needs the paper's turntable (Table 3)",
        )
        .into());
    }
    // a study with rate steps gets no two-step allocation (the orientation requirement is
    // static), as `allocate` and `end-to-end` answer it: one answer in the whole report
    let alloc_problem = match requirement.used.filter(|_| !s.has_rate_steps()) {
        Some(req) => Some(
            AllocationProblem::new(
                LinearModel::new(&s.turntable),
                req,
                s.lower_bounds_rad.clone(),
            )
            .map_err(|e| tt_lab::error::library(e, s))?,
        ),
        None => None,
    };
    let bins = ((options.samples as f64).sqrt().round() as usize)
        .clamp(10, mc_verify::DEFAULT_HISTOGRAM_BINS);
    Ok(Setup {
        requirement,
        problem,
        e2e,
        inputs,
        alloc_problem,
        bins,
        no_table_suffices: specified.no_table_suffices,
    })
}

/// The Monte Carlo of the box `ub` (rad; an unbounded error held at its lower bound) with the
/// study's requirement.
fn mc_config(s: &Study, options: &Options, setup: &Setup, ub: &[f64]) -> Result<MonteCarlo> {
    let lb = &s.lower_bounds_rad;
    let ub: Vec<f64> = ub
        .iter()
        .zip(lb)
        .map(|(u, l)| if u.is_finite() { *u } else { *l })
        .collect();
    let b =
        ErrorBox::new(&s.turntable, lb.clone(), ub).map_err(|e| tt_lab::error::library(e, s))?;
    let mut cfg = McConfig::new(
        options.samples,
        options.seed,
        setup
            .requirement
            .used
            .unwrap_or_else(tt_core::Requirement::none),
    );
    cfg.histogram_bins = setup.bins;
    MonteCarlo::new(&s.turntable, b, cfg)
        .map_err(|e| Error::from(tt_lab::error::library_at(e, s, "--samples")))
}

/// The two-step allocation, its Monte Carlo (and the exact-chain check) beside the end-to-end
/// answer that reuses it, the vendor check, Table 4 and the noise part.
fn left_branch(s: &Study, options: &Options, setup: &Setup) -> Result<Left> {
    let t0 = Instant::now();
    // the two-step allocation beside the end-to-end allocations that do not need it
    let (ours, allocations) = rayon::join(
        || -> Result<Option<Allocation>> {
            let ours = match &setup.alloc_problem {
                Some(p) => Some(
                    SensitivityWeighted::general()
                        .allocate(p)
                        .map_err(|e| tt_lab::error::library(e, s))?,
                ),
                None => None,
            };
            timing("two-step allocation", t0);
            Ok(ours)
        },
        || {
            let a = e2e_verify::answer_allocations(&setup.e2e, &setup.inputs)
                .map_err(|e| tt_lab::error::library(e, s));
            timing("end-to-end allocations", t0);
            a
        },
    );
    let ours = ours?;
    // after the allocation: its Monte Carlo (and the exact-chain check) beside the
    // end-to-end answer that reuses it
    let (mc, rest) = rayon::join(
        || -> Result<Option<(Vec<alloc_opt::ExactAxisCheck>, MonteCarlo, McResult)>> {
            match (&setup.alloc_problem, &ours) {
                (Some(p), Some(a)) => {
                    let exact =
                        exact_chain_check(p, a).map_err(|e| tt_lab::error::library(e, s))?;
                    let monte_carlo = mc_config(s, options, setup, a.upper_bounds_rad())?;
                    let result = monte_carlo.run();
                    timing("two-step Monte Carlo", t0);
                    Ok(Some((exact.to_vec(), monte_carlo, result)))
                }
                _ => Ok(None),
            }
        },
        || -> Result<AnswerPart> {
            let answer = allocations?
                .answer(ours.clone())
                .map_err(|e| tt_lab::error::library(e, s))?;
            timing("end-to-end answer", t0);
            answer_part(s, options, setup, answer, t0)
        },
    );
    let (answer, vendor, table4, noise) = rest?;
    let two_step = match (ours, &setup.alloc_problem, mc?) {
        (Some(ours), Some(p), Some((exact, monte_carlo, result))) => Some(TwoStep {
            problem: p.clone(),
            ours,
            exact,
            monte_carlo,
            result,
        }),
        _ => None,
    };
    Ok((two_step, answer, vendor, table4, noise))
}

/// After the end-to-end answer: the noise part (it needs the answer) beside the vendor check
/// and Table 4.
fn answer_part(
    s: &Study,
    options: &Options,
    setup: &Setup,
    answer: BuyersAnswer,
    t0: Instant,
) -> Result<AnswerPart> {
    let e2e = &setup.e2e;
    let (noise, rest) = rayon::join(
        || {
            let noise =
                tt_lab::end_to_end::noisy_answer(s, e2e, &answer, e2e_verify::DEFAULT_K_SIGMA)
                    .map_err(crate::Error::from);
            timing("noise and test time", t0);
            noise
        },
        || -> Result<_> {
            let vendor = match &options.tolerances {
                Some(tol) => {
                    let settings = e2e_verify::McSettings::new(options.samples, options.seed);
                    let c = e2e
                        .vendor()
                        .check_sheet(tol, &settings)
                        .map_err(|e| tt_lab::error::library(e, s))?;
                    Some((tol.clone(), c))
                }
                None => None,
            };
            let table4 = if options.paper {
                let mc = mc_config(s, options, setup, &alloc_opt::paper::table4_rad())?;
                let r = mc.run();
                Some((mc, r))
            } else {
                None
            };
            Ok((vendor, table4))
        },
    );
    let (vendor, table4) = rest?;
    Ok((answer, vendor, table4, noise?))
}

/// Equal effects, the readings' requirements, the planes, the average sensitivities and the
/// designed schedule's facts.
fn right_branch(s: &Study, options: &Options, setup: &Setup) -> Result<Right> {
    let t0 = Instant::now();
    // equal effects where its worst case is exact and cheap (at most one free joint;
    // a searched certificate takes seconds), and always for the paper
    let equal = match &setup.alloc_problem {
        Some(p) if options.paper || s.turntable.free_joints().len() <= 1 => Some(
            EqualEffects
                .allocate(p)
                .map_err(|e| tt_lab::error::library(e, s))?,
        ),
        _ => None,
    };
    timing("equal effects", t0);
    // the other readings' requirements are independent: computed in parallel, kept
    // in this order
    let mut readings = vec![(s.reading, setup.requirement.computed.clone())];
    let others: Vec<Reading> = [Reading::PAPER, Reading::USER, Reading::AS_PRINTED]
        .into_iter()
        .filter(|r| *r != s.reading)
        .collect();
    readings.par_extend(others.into_par_iter().map(|r| {
        (
            r,
            RequirementProblem {
                reading: r,
                ..setup.problem.clone()
            }
            .requirement(),
        )
    }));
    timing("readings", t0);
    let planes = planes(s, &setup.problem, setup.requirement.computed.as_ref().ok())?;
    timing("planes", t0);
    let avg = LinearModel::new(&s.turntable).average_abs_coefficients();
    let sensitivity = (0..avg.ncols())
        .map(|i| [avg[(0, i)], avg[(1, i)], avg[(2, i)]])
        .collect();
    let designed = match &options.designed {
        Some(d) => Some([schedule_facts(s)?, schedule_facts(d)?]),
        None => None,
    };
    Ok((equal, readings, planes, sensitivity, designed))
}

/// The paper's extras: Table 4's Monte Carlo and the claims evaluated on this run (`None`
/// without `table4`, that is outside the paper's reproduction).
fn paper_extras(
    s: &Study,
    setup: &Setup,
    table4: Option<(MonteCarlo, McResult)>,
    two_step: Option<&TwoStep>,
    equal: Option<&Allocation>,
    answer: &BuyersAnswer,
) -> Result<Option<PaperExtras>> {
    match (table4, two_step, equal, &setup.alloc_problem) {
        (Some((mc, result)), Some(t), Some(eq), Some(p)) => {
            let run = PaperRun {
                requirement: &setup.problem,
                turntable: &s.turntable,
                allocation_problem: p,
                proposed: &t.ours,
                equal_effects: eq,
                table4_monte_carlo: (&mc, &result),
                end_to_end: (&setup.e2e, answer),
            };
            let claims = registry::evaluate(&run)
                .map_err(|e| Error::Internal(format!("evaluating the paper's claims: {e}")))?;
            Ok(Some(PaperExtras {
                table4_monte_carlo: mc,
                table4_result: result,
                claims,
            }))
        }
        (Some(_), ..) => Err(InputError::new(
            &s.path,
            "the paper's reproduction needs the study's requirement (eq 16)",
        )
        .into()),
        _ => Ok(None),
    }
}

/// The vendor check with noise and with rate errors, the rate allocation, the estimable
/// errors, the angle-dependent and disc allocations and the specifications' verdict.
fn later(
    s: &Study,
    options: &Options,
    setup: &Setup,
    answer: &BuyersAnswer,
    vendor: Option<&(ToleranceSheet, TurntableCheck)>,
    started: Instant,
) -> Result<Later> {
    let e2e = &setup.e2e;
    let vendor_noise = match vendor {
        Some((tol, chk)) => tt_lab::vendor::noisy_checks(
            s,
            e2e,
            &[(e2e.clone(), chk.clone())],
            tol,
            &e2e_verify::McSettings::new(options.samples, options.seed),
            e2e_verify::DEFAULT_K_SIGMA,
        )
        .map_err(crate::Error::from)?
        .pop(),
        None => None,
    };
    let vendor_rate = match vendor {
        Some((tol, _)) if e2e.has_rate_steps() => Some(
            tt_lab::vendor::rate::check(
                s,
                e2e,
                tol,
                &e2e_verify::McSettings::new(options.samples, options.seed),
            )
            .map_err(crate::Error::from)?,
        ),
        _ => None,
    };
    timing("vendor check with rate errors", started);
    let rate_alloc = tt_lab::vendor::rate::allocation(
        s,
        e2e,
        &e2e_verify::McSettings::new(options.samples, options.seed),
    )
    .map_err(crate::Error::from)?;
    timing("allocation with rate tolerances", started);
    // the joint estimation is built on static positions (one orientation error each)
    let estimable = if e2e.has_rate_steps() {
        None
    } else {
        Some(
            tt_lab::estimable::compute(s, vendor.map(|(tol, _)| tol.upper_bounds_rad()))
                .map_err(crate::Error::from)?,
        )
    };
    timing("estimable", started);
    let angle_alloc = tt_lab::allocation::angle::compute(s, e2e).map_err(crate::Error::from)?;
    timing("angle-dependent allocation", started);
    let disc_alloc = match vendor {
        Some((tol, _)) if !e2e.has_rate_steps() => Some(
            tt_lab::vendor::angle::sheet_allocations(s, e2e, tol).map_err(crate::Error::from)?,
        ),
        _ => None,
    };
    timing("the sheet's discs allocated", started);
    let bounds = answer.readings()[0].direct().upper_bounds_rad().to_vec();
    let decision = tt_lab::vendor::spec::compute(s, e2e, &bounds)
        .map_err(crate::Error::from)?
        .map(|v| (bounds, v));
    timing("the specifications' budgets", started);
    let jcgm101 = crate::jcgm101::compute(
        s,
        e2e,
        decision.as_ref(),
        options.jcgm101.as_ref(),
        options.seed,
    )?;
    Ok(Later {
        jcgm101,
        vendor_noise,
        vendor_rate,
        rate_alloc,
        estimable,
        angle_alloc,
        disc_alloc,
        decision,
    })
}
