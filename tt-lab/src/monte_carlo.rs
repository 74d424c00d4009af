//! The Monte Carlo check of a tolerance box (paper §4.3, Figure 9) for a study's turntable:
//! `N` random turntables (|chi_i| uniform in [LB_i, UB_i], fair random signs, poses uniform
//! over the joint ranges; see `mc_verify::sampler`) through the exact chain with the eq-24
//! read-out: the extremes (with their worst samples), mean, standard deviation, histograms
//! and the fraction inside the study's orientation requirement. The box is the study's
//! two-step allocation, the paper's Table 4 (`paper` feature, the paper's table only) or a
//! vendor's tolerance sheet. The result does not depend on the thread count (the caller's
//! rayon pool) nor on the SIMD level.

use crate::error::{InputError, Result};
use crate::json::PerAngle;
use crate::loaded;
use alloc_opt::{AllocationProblem, Allocator, SensitivityWeighted};
use mc_verify::{ErrorBox, McConfig, McResult, MonteCarlo, SimdLevel};
use std::collections::BTreeMap;
use std::path::PathBuf;
use std::time::Instant;
use study::Study;
use tt_core::units::{rad_to_arcmin, rad_to_deg};
use tt_kinematics::LinearModel;

/// Which tolerance box to verify.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
#[non_exhaustive]
pub enum Bounds {
    /// The study's two-step allocation (the paper's method solved to the optimum).
    #[default]
    TwoStep,
    /// The paper's Table 4 (the paper's table only).
    #[cfg(feature = "paper")]
    Table4,
    /// A vendor's tolerance file.
    Tolerances(PathBuf),
}

/// The run's settings.
#[derive(Debug, Clone, PartialEq, Eq)]
#[non_exhaustive]
pub struct Options {
    /// Random turntables drawn (`None`: the study's `monte_carlo.samples`).
    pub samples: Option<u64>,
    /// Seed of the random streams (`None`: the study's `monte_carlo.seed`).
    pub seed: Option<u64>,
    /// The box verified.
    pub bounds: Bounds,
    /// Samples per random stream (part of the reproducibility contract).
    pub chunk_size: u32,
    /// Histogram bins per angle.
    pub bins: usize,
}

impl Default for Options {
    fn default() -> Self {
        Self {
            samples: None,
            seed: None,
            bounds: Bounds::TwoStep,
            chunk_size: mc_verify::DEFAULT_CHUNK_SIZE,
            bins: mc_verify::DEFAULT_HISTOGRAM_BINS,
        }
    }
}

/// The box and its name for the options.
///
/// # Errors
/// An [`InputError`] naming the flag or key.
fn bounds(o: &Options, s: &Study) -> Result<(String, ErrorBox)> {
    let lb = s.lower_bounds_rad.clone();
    let boxed = |ub: Vec<f64>, what: &str| -> Result<ErrorBox> {
        ErrorBox::new(&s.turntable, lb.clone(), ub)
            .map_err(|e| crate::error::library_at(e, s, what))
    };
    match &o.bounds {
        Bounds::Tolerances(path) => {
            let sheet = s.load_sheet(path).map_err(InputError::from)?;
            Ok((
                format!("tolerances {}", sheet.source()),
                boxed(sheet.upper_bounds_rad().to_vec(), sheet.source())?,
            ))
        }
        #[cfg(feature = "paper")]
        Bounds::Table4 => {
            if s.turntable != tt_kinematics::paper::table3() {
                return Err(InputError::new(
                    "--bounds",
                    "table4 is the paper's Table 4: it applies only to the paper's turntable",
                )
                .into());
            }
            Ok((
                "table4".into(),
                boxed(alloc_opt::paper::table4_rad(), "Table 4 (--bounds table4)")?,
            ))
        }
        Bounds::TwoStep => {
            let req = loaded::requirement(s)?;
            let r = req.used.ok_or_else(|| {
                InputError::new(
                    "--bounds two-step",
                    "the study has no orientation requirement (no output constrains a constant orientation error): give --tolerances, or use end-to-end",
                )
            })?;
            let a = SensitivityWeighted::general()
                .allocate(
                    &AllocationProblem::new(LinearModel::new(&s.turntable), r, lb.clone())
                        .map_err(|e| crate::error::library(e, s))?,
                )
                .map_err(|e| crate::error::library(e, s))?;
            let ub: Vec<f64> = a
                .upper_bounds_rad()
                .iter()
                .zip(&lb)
                .map(|(u, l)| if u.is_finite() { *u } else { *l })
                .collect();
            Ok(("two-step".into(), boxed(ub, "the two-step allocation")?))
        }
    }
}

/// The configured run of a study: its box (named), its settings and the requirement's note.
#[derive(Debug)]
#[non_exhaustive]
pub struct McPlan {
    name: String,
    mc: MonteCarlo,
    note: Option<String>,
}

impl McPlan {
    /// The box's name (`two-step`, `table4`, `tolerances <sheet>`).
    #[must_use]
    pub fn name(&self) -> &str {
        &self.name
    }

    /// The run (its box and configuration).
    #[must_use]
    pub fn monte_carlo(&self) -> &MonteCarlo {
        &self.mc
    }

    /// Why the requirement is not the study's (or the rate steps' note), else `None`.
    #[must_use]
    pub fn requirement_note(&self) -> Option<&str> {
        self.note.as_deref()
    }

    /// Run it on the current rayon pool, `progress` told the samples done.
    #[must_use]
    pub fn run(self, progress: &(dyn Fn(u64) + Sync)) -> McAnswer {
        let t = Instant::now();
        let result = self.mc.run_with_progress(progress);
        let seconds = t.elapsed().as_secs_f64();
        McAnswer {
            plan: self,
            result,
            seconds,
        }
    }
}

/// The run of a study's Monte Carlo configured from the options (box, samples, seed).
///
/// # Errors
/// An [`InputError`] naming the flag or key for a bad box or configuration.
pub fn plan(s: &Study, o: &Options) -> Result<McPlan> {
    let req = loaded::requirement(s)?;
    let requirement = req.used.unwrap_or_else(tt_core::Requirement::none);
    let mut cfg = McConfig::new(
        o.samples.unwrap_or(s.monte_carlo.samples),
        o.seed.unwrap_or(s.monte_carlo.seed),
        requirement,
    );
    cfg.chunk_size = o.chunk_size;
    cfg.histogram_bins = o.bins;
    let (name, b) = bounds(o, s)?;
    let mc =
        MonteCarlo::new(&s.turntable, b, cfg).map_err(|e| crate::error::library_at(e, s, "mc"))?;
    Ok(McPlan {
        name,
        mc,
        note: req.disagreement,
    })
}

/// The Monte Carlo check of the options' box for the study, on the current rayon pool,
/// `progress` told the samples done.
///
/// # Errors
/// As [`plan`].
pub fn monte_carlo(s: &Study, o: &Options, progress: &(dyn Fn(u64) + Sync)) -> Result<McAnswer> {
    Ok(plan(s, o)?.run(progress))
}

/// A finished run.
#[derive(Debug)]
#[non_exhaustive]
pub struct McAnswer {
    plan: McPlan,
    result: McResult,
    seconds: f64,
}

impl McAnswer {
    /// The run as configured.
    #[must_use]
    pub fn plan(&self) -> &McPlan {
        &self.plan
    }

    /// Its result.
    #[must_use]
    pub fn result(&self) -> &McResult {
        &self.result
    }

    /// The run's wall time, s.
    #[must_use]
    pub fn seconds(&self) -> f64 {
        self.seconds
    }

    /// The JSON view (`mc --json`), `threads` the pool's size.
    #[must_use]
    pub fn view<'a>(&'a self, s: &'a Study, threads: usize) -> McJson<'a> {
        let mut v = McJson::new(
            s,
            &self.plan.name,
            &self.plan.mc,
            &self.result,
            threads,
            self.seconds,
        );
        v.requirement_note = self.plan.note.as_deref();
        v
    }
}

/// Per error, keyed `<error>_arcmin`: a box's bound in arcminutes.
fn errors_arcmin(names: &[&str], rad: &[f64]) -> BTreeMap<String, f64> {
    names
        .iter()
        .zip(rad)
        .map(|(n, v)| (format!("{n}_arcmin"), rad_to_arcmin(*v)))
        .collect()
}

/// The worst sample of one angle.
#[derive(Debug)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
#[cfg_attr(not(feature = "serde"), allow(dead_code))]
struct WorstJson {
    /// The sample's index in the run.
    index: u64,
    /// Its angle error, degrees.
    value_deg: f64,
    /// Its pose, keyed `<joint>_deg`, degrees.
    pose_deg: BTreeMap<String, f64>,
    /// Its errors, keyed `<error>_arcmin`, arcminutes.
    chi: BTreeMap<String, f64>,
}

/// The histogram of one angle's error.
#[derive(Debug)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
#[cfg_attr(not(feature = "serde"), allow(dead_code))]
struct HistogramJson<'a> {
    /// Half the histogram's range, degrees.
    half_range_deg: f64,
    /// Counts per bin.
    counts: &'a [u64],
    /// Samples below the range.
    underflow: u64,
    /// Samples above the range.
    overflow: u64,
}

/// `mc --json`: the run's summary.
#[derive(Debug)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
#[cfg_attr(not(feature = "serde"), allow(dead_code))]
pub struct McJson<'a> {
    /// The study's path.
    study: &'a str,
    /// Turntables drawn.
    samples: u64,
    /// Seed of the random streams.
    seed: u64,
    /// Threads of the run.
    threads: usize,
    /// Time of the run, s.
    seconds: f64,
    /// Turntables per second.
    samples_per_sec: f64,
    /// The box's name (`two-step`, `table4`, the sheet's path).
    bounds: &'a str,
    /// Samples per chunk of the parallel run.
    chunk_size: u32,
    /// The evaluator, in words.
    evaluator: &'static str,
    /// The SIMD level chosen at run time.
    simd_level: &'static str,
    /// The box's lower bounds, keyed `<error>_arcmin`, arcminutes.
    lb_arcmin: BTreeMap<String, f64>,
    /// The box's upper bounds, keyed `<error>_arcmin`, arcminutes.
    ub_arcmin: BTreeMap<String, f64>,
    /// The study's orientation requirement per angle, degrees (`null`: none).
    requirement_deg: PerAngle<Option<f64>>,
    /// The largest |error| drawn per angle, degrees.
    max_abs_deg: PerAngle<f64>,
    /// The certified linearised worst case per angle, degrees (`null` when not certified).
    linear_worst_case_deg: PerAngle<Option<f64>>,
    /// The mean error per angle, degrees.
    mean_deg: PerAngle<f64>,
    /// The standard deviation per angle, degrees.
    std_deg: PerAngle<f64>,
    /// Fraction of samples inside the requirement on all three angles, in [0, 1].
    within_requirement_fraction: f64,
    /// The same per angle.
    within_requirement_fraction_per_axis: PerAngle<f64>,
    /// The worst sample per angle.
    worst: PerAngle<WorstJson>,
    /// The histogram per angle.
    histogram_deg: PerAngle<HistogramJson<'a>>,
    /// Why the requirement is not the study's, else `null`.
    requirement_note: Option<&'a str>,
}

impl<'a> McJson<'a> {
    /// The view of the run `r` of `mc` (box `name`) for study `s`.
    #[must_use]
    fn new(
        s: &'a Study,
        name: &'a str,
        mc: &MonteCarlo,
        r: &'a McResult,
        threads: usize,
        seconds: f64,
    ) -> Self {
        let std = r.std_rad();
        let names = s.turntable.rotation_error_names();
        let joints = s.turntable.joint_names();
        let linear = LinearModel::new(&s.turntable);
        Self {
            study: &s.path,
            samples: r.count().samples(),
            seed: r.count().seed(),
            threads,
            seconds,
            samples_per_sec: r.count().samples() as f64 / seconds,
            bounds: name,
            chunk_size: r.chunk_size(),
            evaluator: "exact chain, eq-24 read-out (fast quaternion plan)",
            simd_level: SimdLevel::detected().name(),
            lb_arcmin: errors_arcmin(&names, mc.bounds().lb_rad()),
            ub_arcmin: errors_arcmin(&names, mc.bounds().ub_rad()),
            requirement_deg: PerAngle::new(|a| r.requirement().get(a).map(rad_to_deg)),
            max_abs_deg: PerAngle::new(|a| rad_to_deg(r.axis(a).max_abs_rad())),
            linear_worst_case_deg: PerAngle::new(|a| {
                linear
                    .worst_pose_certified(a, mc.bounds().ub_rad(), true, None)
                    .ok()
                    .map(|w| rad_to_deg(w.upper_bound()))
            }),
            mean_deg: PerAngle::new(|a| rad_to_deg(r.axis(a).mean_rad())),
            std_deg: PerAngle::new(|a| rad_to_deg(std[a.index()])),
            within_requirement_fraction: r.count().fraction(),
            within_requirement_fraction_per_axis: PerAngle::new(|a| {
                r.count().meeting_per_output()[a.index()] as f64 / r.count().samples() as f64
            }),
            worst: PerAngle::new(|a| {
                let w = r.axis(a).worst();
                WorstJson {
                    index: w.index(),
                    value_deg: rad_to_deg(w.value()),
                    pose_deg: joints
                        .iter()
                        .zip(w.pose().angles_rad())
                        .map(|(j, v)| (format!("{j}_deg"), rad_to_deg(*v)))
                        .collect(),
                    chi: errors_arcmin(&names, w.chi_rad()),
                }
            }),
            histogram_deg: PerAngle::new(|a| {
                let h = &r.axis(a).histogram();
                HistogramJson {
                    half_range_deg: rad_to_deg(h.hi()),
                    counts: h.counts(),
                    underflow: h.underflow(),
                    overflow: h.overflow(),
                }
            }),
            requirement_note: None,
        }
    }
}
