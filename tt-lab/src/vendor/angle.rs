//! Errors that vary with the shaft angle (issue 22) in the vendor check and the allocations: a tolerance box checked
//! under the angle-dependent model beside the constant one.
//!
//! The model: the study's (`turntable.factors[i].varies`) when it declares one; otherwise
//! every error an arbitrary bounded function of the angle of the shaft it rides on (`any`,
//! [`tt_kinematics::on_shafts`]): what a sheet supports that bounds each error over the whole
//! revolution ("wobble <= 3 arcsec") and says nothing more. The constant model (the paper's)
//! is supported only by a table whose errors are known not to vary with the angle.

use crate::Result;
use crate::json::{ArcminBounds, arcmin_bounds};
use e2e_verify::angle::{AngleOutputWorstCase, AngleYield};
use e2e_verify::disc::{Pair, PairModel, PairShape};
use e2e_verify::noise::weakest;
use e2e_verify::{DirectAllocation, EndToEnd, ToleranceSheet, TurntableCheck, Verdict};
use study::Study;
use tt_core::human::num;
use tt_kinematics::{ErrorVariation, Expansion};

/// The angle-dependent check of one reading.
#[derive(Debug, Clone)]
pub struct ReadingAngle {
    /// Per output.
    pub outputs: Vec<AngleOutputWorstCase>,
    /// The Monte Carlo yield under the model.
    pub yield_: AngleYield,
    /// The weakest of the outputs' verdicts, every modelled source counted (with the
    /// study's noise: the table's part and the noise's, [`NoisePart`]).
    pub verdict: Verdict,
    /// Every output's verdict, every modelled source counted (as `verdict`).
    pub output_verdicts: Vec<Verdict>,
    /// With the study's noise: the weakest verdict of the table's part alone.
    pub table_verdict: Option<Verdict>,
    /// With the sheet's magnitude bounds (discs): the linearised worst case per output.
    pub disc: Option<DiscWorst>,
}

/// The study's noise part of every output (calib-lsq's covariance over the study's timing):
/// what each verdict adds to the table's part, `k_sigma` times `sigma`.
#[derive(Debug, Clone)]
pub struct NoisePart {
    /// The noise's standard deviation of every output's rate error (output's unit).
    pub sigma: Vec<f64>,
    /// The confidence multiplier (`--k-sigma`).
    pub k_sigma: f64,
}

impl NoisePart {
    /// The noise part of output `k` (output's unit): `k_sigma` times its sigma.
    #[must_use]
    pub fn margin(&self, k: usize) -> f64 {
        self.k_sigma * self.sigma[k]
    }

    /// The rule of a verdict that counts it, in words.
    #[must_use]
    pub fn rule(&self) -> String {
        format!(
            "table and noise counted: the table's worst case plus {} sigma of the noise against the accuracy",
            num(self.k_sigma)
        )
    }
}

/// The verdict of an angle-dependent worst case with the noise part `margin` added (output's
/// unit, 0 without noise), as [`e2e_verify::CombinedOutput::of`] gives the constant model's:
/// fails when the exact chain at the worst errors found plus the noise misses the accuracy,
/// guaranteed when the linear bound plus the second-order bound plus the noise meets it,
/// likely otherwise.
#[must_use]
pub(crate) fn counted_verdict(o: &AngleOutputWorstCase, accuracy: f64, margin: f64) -> Verdict {
    if o.exact_at_vertex() + margin > accuracy {
        Verdict::Fails
    } else {
        match o.second_order_bound() {
            Some(t) if o.linear_bound() + t + margin <= accuracy => Verdict::Guaranteed,
            _ => Verdict::Likely,
        }
    }
}

/// The answers when the sheet's magnitudes bound a disc, not the square of the two
/// components ([`e2e_verify::disc`]).
#[derive(Debug, Clone)]
pub struct DiscWorst {
    /// The linearised worst case per output (output unit), constant errors.
    pub constant: Vec<f64>,
    /// The same, angle-dependent errors (rigorous: exact for constant and `any` pairs, an
    /// upper bound for harmonic pairs).
    pub angle: Vec<f64>,
    /// A value the angle-dependent worst case certainly reaches per output (certified lower
    /// dual norms; equal to `angle` unless a pair is harmonic).
    pub angle_lower: Vec<f64>,
    /// The Monte Carlo yield under the angle-dependent model with every pair drawn in its
    /// disc (same samples and seed as the square's).
    pub yield_: AngleYield,
    /// The same with every error constant (the constant check's Monte Carlo draws the
    /// square).
    pub constant_yield: AngleYield,
    /// The allocations with one tolerance per pair of the sheet; `None` for the compensated
    /// check.
    pub allocation: Option<DiscAllocation>,
}

/// The direct allocation with one tolerance per pair of the sheet (a wobble, a
/// perpendicularity), the pair read as a disc or as the square around it, under both models.
#[derive(Debug, Clone)]
pub struct DiscAllocation {
    /// Constant errors, discs.
    pub constant_disc: DirectAllocation,
    /// Constant errors, squares.
    pub constant_square: DirectAllocation,
    /// Angle-dependent errors, discs.
    pub angle_disc: DirectAllocation,
    /// Angle-dependent errors, squares.
    pub angle_square: DirectAllocation,
    /// Angle-dependent errors, discs, certified on the exact chain (or why not).
    pub angle_disc_certified: std::result::Result<DirectAllocation, String>,
    /// Angle-dependent errors, squares, certified (or why not).
    pub angle_square_certified: std::result::Result<DirectAllocation, String>,
}

fn paired_allocations(
    s: &Study,
    e2e: &EndToEnd,
    constant: &PairModel,
    angle: &PairModel,
    discs: &[Pair],
) -> Result<DiscAllocation> {
    let lib = |e: e2e_verify::E2eError| crate::error::library(e, s);
    let lb = &s.lower_bounds_rad;
    let square: Vec<Pair> = discs
        .iter()
        .map(|p| Pair {
            errors: p.errors,
            shape: PairShape::Square,
        })
        .collect();
    let direct = |m: &PairModel, p: &[Pair]| {
        e2e.angle()
            .allocate_direct_paired(&m.merged(p), lb, p, None)
            .map_err(lib)
    };
    let certified =
        |m: &PairModel, p: &[Pair]| -> Result<std::result::Result<DirectAllocation, String>> {
            let params = e2e_verify::CertifyParams::default();
            match e2e
                .angle()
                .allocate_direct_paired(&m.merged(p), lb, p, Some(&params))
            {
                Ok(d) => Ok(Ok(d)),
                Err(
                    e @ (e2e_verify::E2eError::NoSecondOrderBound { .. }
                    | e2e_verify::E2eError::NoConvergence { .. }
                    | e2e_verify::E2eError::MarginExceedsAccuracy { .. }),
                ) => Ok(Err(e.to_string())),
                Err(e) => Err(lib(e)),
            }
        };
    Ok(DiscAllocation {
        constant_disc: direct(constant, discs)?,
        constant_square: direct(constant, &square)?,
        angle_disc: direct(angle, discs)?,
        angle_square: direct(angle, &square)?,
        angle_disc_certified: certified(angle, discs)?,
        angle_square_certified: certified(angle, &square)?,
    })
}

/// The angle-dependent check of every reading (same order as the constant checks).
#[derive(Debug, Clone)]
pub struct AngleCheck {
    /// Whether the model is the study's (else `any` on every shaft).
    pub study_model: bool,
    /// Each error's model (order of chi).
    pub variations: Vec<ErrorVariation>,
    /// Per reading.
    pub readings: Vec<ReadingAngle>,
    /// The study's noise part, counted by every verdict; `None` without noise.
    pub noise: Option<NoisePart>,
}

/// The expansion of `variations` on `sim`'s schedule, refused (exit 2, naming
/// `calibration.positions_deg`, the count and the limit) when its first-order model would
/// exceed [`e2e_verify::angle::MAX_EXPANDED_VALUES`]: an `any` error has one coefficient per
/// distinct angle of its shaft, so the model grows as positions times distinct angles.
///
/// # Errors
/// The refusal; a library error located in the study.
pub(crate) fn expansion(
    s: &Study,
    sim: &EndToEnd,
    variations: &[ErrorVariation],
) -> Result<Expansion> {
    let coefficients = Expansion::count_coefficients(sim.turntable(), variations, sim.poses())
        .map_err(|e| crate::error::library(e, s))?;
    let values = sim
        .n_outputs()
        .saturating_mul(sim.len())
        .saturating_mul(coefficients);
    let max = e2e_verify::angle::MAX_EXPANDED_VALUES;
    if values > max {
        return Err(crate::InputError::new(
            format!("{}: key `calibration.positions_deg`", s.path),
            format!(
                "{} test positions give the angle-dependent model {} coefficients (one per distinct angle of each shaft for an `any` error): {} outputs x {} x {} = {values} values, at most {max} are accepted; repeat the shafts' angles (a grid) or use fewer positions",
                sim.len(),
                coefficients,
                sim.n_outputs(),
                sim.len(),
                coefficients,
            ),
        )
        .into());
    }
    Expansion::new(sim.turntable(), variations, sim.poses())
        .map_err(|e| crate::error::library(e, s))
}

/// The model used: the study's, or `any` on every shaft with the models the sheet's vendor
/// quantities imply (an orthogonality is a constant).
#[must_use]
pub(crate) fn model_of(s: &Study, sheet: &ToleranceSheet) -> (bool, Vec<ErrorVariation>) {
    if s.has_angle_dependent_errors() {
        (true, s.variations.clone())
    } else {
        (false, sheet.supported_model(&s.turntable))
    }
}

/// Check the sheet's bounds under the angle-dependent model for every simulator of
/// `checks`, with `samples` Monte Carlo turntables from `seed`; with the sheet's discs, their
/// worst case, yield and (with `allocate`) the allocations with one tolerance per pair.
///
/// # Errors
/// A library error located in the study.
pub fn check(
    s: &Study,
    checks: &[(EndToEnd, TurntableCheck)],
    sheet: &ToleranceSheet,
    samples: u64,
    seed: u64,
    allocate: bool,
    noise: Option<&NoisePart>,
) -> Result<AngleCheck> {
    let ub_rad = sheet.upper_bounds_rad();
    let (study_model, variations) = model_of(s, sheet);
    let discs = sheet.disc_bounds();
    let mut readings = Vec::with_capacity(checks.len());
    for (e2e, _) in checks {
        let ex = expansion(s, e2e, &variations)?;
        let lin = e2e.linearization();
        let al = e2e
            .angle()
            .angle_linearization(&ex)
            .map_err(|e| crate::error::library(e, s))?;
        let outputs = e2e
            .angle()
            .angle_worst_case(&ex, &al, &lin, ub_rad)
            .map_err(|e| crate::error::library(e, s))?;
        let yield_ = e2e
            .angle()
            .angle_yield(&ex, ub_rad, samples, seed)
            .map_err(|e| crate::error::library(e, s))?;
        let acc = e2e.accuracies();
        let output_verdicts: Vec<Verdict> = outputs
            .iter()
            .map(|o| {
                let margin = noise.map_or(0.0, |n| n.margin(o.output()));
                counted_verdict(o, acc[o.output()], margin)
            })
            .collect();
        let verdict = weakest(output_verdicts.iter().copied());
        let table_verdict = noise.map(|_| weakest(outputs.iter().map(|o| o.verdict())));
        let disc = if discs.is_empty() {
            None
        } else {
            let lib = |e: e2e_verify::E2eError| crate::error::library(e, s);
            let constant = Expansion::new(
                e2e.turntable(),
                &vec![ErrorVariation::Constant; e2e.n_errors()],
                e2e.poses(),
            )
            .map_err(|e| crate::error::library(e, s))?;
            let constant_model = e2e.angle().pair_model(&constant).map_err(lib)?;
            let angle_model = e2e.angle().pair_model(&ex).map_err(lib)?;
            let pairs: Vec<Pair> = discs
                .iter()
                .map(|(errors, _)| Pair {
                    errors: *errors,
                    shape: PairShape::Disc,
                })
                .collect();
            let with_w: Vec<(Pair, f64)> = pairs
                .iter()
                .zip(&discs)
                .map(|(p, (_, w))| (*p, *w))
                .collect();
            let (constant_wc, _) = constant_model.worst_case(ub_rad, &with_w);
            let (angle_wc, angle_lower) = angle_model.worst_case(ub_rad, &with_w);
            let yield_ = e2e
                .angle()
                .angle_yield_with_discs(&ex, ub_rad, &discs, samples, seed)
                .map_err(lib)?;
            let constant_yield = e2e
                .angle()
                .angle_yield_with_discs(&constant, ub_rad, &discs, samples, seed)
                .map_err(lib)?;
            let allocation = if allocate {
                Some(paired_allocations(
                    s,
                    e2e,
                    &constant_model,
                    &angle_model,
                    &pairs,
                )?)
            } else {
                None
            };
            Some(DiscWorst {
                constant: constant_wc,
                angle: angle_wc,
                angle_lower,
                yield_,
                constant_yield,
                allocation,
            })
        };
        readings.push(ReadingAngle {
            outputs,
            yield_,
            verdict,
            output_verdicts,
            table_verdict,
            disc,
        });
    }
    Ok(AngleCheck {
        study_model,
        variations,
        readings,
        noise: noise.cloned(),
    })
}

/// The allocations with one tolerance per pair of the sheet (its `[axes.<joint>]`
/// wobbles and orthogonalities; the values are not used, only which errors pair up), for the
/// study's reading and the user's when different; the angle-dependent model is
/// [`model_of`]'s. Empty when the sheet states no pair.
///
/// # Errors
/// A library error located in the study.
pub fn sheet_allocations(
    s: &Study,
    e2e: &EndToEnd,
    sheet: &ToleranceSheet,
) -> Result<Vec<(EndToEnd, DiscAllocation)>> {
    if sheet.discs().is_empty() {
        return Ok(Vec::new());
    }
    let lib = |e: e2e_verify::E2eError| crate::error::library(e, s);
    let (_, variations) = model_of(s, sheet);
    let pairs: Vec<Pair> = sheet
        .discs()
        .iter()
        .map(|d| Pair {
            errors: d.errors,
            shape: PairShape::Disc,
        })
        .collect();
    let mut sims = vec![e2e.clone()];
    if e2e.reading() != calib_lsq::Reading::USER {
        sims.push(e2e.with_reading(calib_lsq::Reading::USER).map_err(lib)?);
    }
    sims.into_iter()
        .map(|sim| {
            let kin = |e: tt_kinematics::KinematicsError| crate::error::library(e, s);
            let constant = Expansion::new(
                sim.turntable(),
                &vec![ErrorVariation::Constant; sim.n_errors()],
                sim.poses(),
            )
            .map_err(kin)?;
            let ex = expansion(s, &sim, &variations)?;
            let cm = sim.angle().pair_model(&constant).map_err(lib)?;
            let am = sim.angle().pair_model(&ex).map_err(lib)?;
            let al = paired_allocations(s, &sim, &cm, &am, &pairs)?;
            Ok((sim, al))
        })
        .collect()
}

/// The check of the compensated table: the measured errors are known inputs of the chain, so
/// their bound is what the measurement leaves ([`ToleranceSheet::compensated`]; the rest of
/// the sheet unchanged).
#[derive(Debug, Clone)]
pub struct Compensated {
    /// The compensated sheet: the box that matters.
    pub sheet: ToleranceSheet,
    /// The constant-model check of every reading.
    pub checks: Vec<TurntableCheck>,
    /// The angle-dependent check.
    pub angle: AngleCheck,
    /// One sentence per measured error whose uncertainty exceeds the sheet's bound.
    pub notes: Vec<String>,
}

/// The compensated check when the study measures errors (`[[compensation.measured]]`), else
/// `None`.
///
/// # Errors
/// A library error located in the study.
pub fn compensated(
    s: &Study,
    checks: &[(EndToEnd, TurntableCheck)],
    sheet: &ToleranceSheet,
    settings: &e2e_verify::McSettings,
    noise: Option<&NoisePart>,
) -> Result<Option<Compensated>> {
    use tt_core::units::rad_to_arcmin;
    let Some((compensated, above)) = sheet.compensated() else {
        return Ok(None);
    };
    let names = s.turntable.rotation_error_names();
    let notes = above
        .iter()
        .map(|a| {
            let j = a.error();
            let uncertainty = s.measured[j]
                .as_ref()
                .map_or(0.0, |m| m.uncertainty_arcmin);
            format!(
                "the measurement uncertainty of `{}` ({} arcmin) exceeds the sheet's {}: compensation cannot bound it better than the sheet and the measured value do, {} arcmin (the sheet's bound plus the measured error's largest magnitude {} arcmin), the bound used after compensation",
                names[j],
                tt_core::human::exact(uncertainty),
                study::sheet_bound_words(s, sheet, j),
                tt_core::human::num(rad_to_arcmin(a.residual_rad())),
                tt_core::human::num(rad_to_arcmin(a.largest_measured_rad())),
            )
        })
        .collect();
    let mut out = Vec::with_capacity(checks.len());
    for (e2e, _) in checks {
        out.push(
            e2e.vendor()
                .check_sheet(&compensated, settings)
                .map_err(|e| crate::error::library(e, s))?,
        );
    }
    let angle = check(
        s,
        checks,
        &compensated,
        settings.samples,
        settings.seed,
        false,
        noise,
    )?;
    Ok(Some(Compensated {
        sheet: compensated,
        checks: out,
        angle,
        notes,
    }))
}

/// The verdict of a constant-model check with the noise part counted (as
/// [`e2e_verify::CombinedOutput::of`]); the table's verdict without noise.
#[must_use]
pub fn constant_counted(check: &TurntableCheck, noise: Option<&NoisePart>) -> Verdict {
    match noise {
        Some(n) => weakest(check.outputs().iter().map(|o| {
            e2e_verify::CombinedOutput::of(
                o.worst_case(),
                o.accuracy(),
                n.sigma[o.output()],
                n.k_sigma,
            )
            .verdict()
        })),
        None => check.verdict(),
    }
}

/// An allocation with one tolerance per pair (or per error), or under the shaft-angle model.
#[derive(Debug)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub(crate) struct AllocationJson {
    /// J, arcmin^-2; `null` when no error needs a bound.
    pub objective_arcmin: Option<f64>,
    /// Its bounds, arcmin.
    pub upper_bounds_arcmin: ArcminBounds,
}

impl AllocationJson {
    /// The view of `d` (errors named `names`).
    pub(crate) fn new(names: &[&str], d: &DirectAllocation) -> Self {
        Self {
            objective_arcmin: crate::allocation::angle::objective(d),
            upper_bounds_arcmin: arcmin_bounds(names, d.upper_bounds_rad()),
        }
    }
}

/// A certified allocation, or why there is none.
#[derive(Debug)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
#[cfg_attr(feature = "serde", serde(untagged))]
pub(crate) enum CertifiedJson<'a> {
    /// The certified allocation.
    Certified(AllocationJson),
    /// None.
    NotCertified {
        /// Why, in words.
        not_certified: &'a str,
    },
}

impl<'a> CertifiedJson<'a> {
    fn new(names: &[&str], d: &'a std::result::Result<DirectAllocation, String>) -> Self {
        match d {
            Ok(d) => Self::Certified(AllocationJson::new(names, d)),
            Err(why) => Self::NotCertified { not_certified: why },
        }
    }
}

/// The constant model's allocations as discs and as squares.
#[derive(Debug)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub(crate) struct ConstantPairsJson {
    /// One tolerance per pair, a disc.
    pub disc: AllocationJson,
    /// One tolerance per error, a square.
    pub square: AllocationJson,
}

/// The angle-dependent model's allocations as discs and squares, with their certified ones.
#[derive(Debug)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub(crate) struct AnglePairsJson<'a> {
    /// One tolerance per pair, a disc.
    pub disc: AllocationJson,
    /// One tolerance per error, a square.
    pub square: AllocationJson,
    /// The disc's certified allocation, or `{"not_certified": why}`.
    pub disc_certified: CertifiedJson<'a>,
    /// The square's certified allocation, or `{"not_certified": why}`.
    pub square_certified: CertifiedJson<'a>,
}

/// The allocations with one tolerance per pair (`constant` / `angle_dependent`, each `disc` /
/// `square`; the angle-dependent model's certified ones as `disc_certified` /
/// `square_certified`, or `{"not_certified": why}`).
#[derive(Debug)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub(crate) struct DiscAllocationJson<'a> {
    /// Under the constant model.
    pub constant: ConstantPairsJson,
    /// Under the angle-dependent model.
    pub angle_dependent: AnglePairsJson<'a>,
}

impl<'a> DiscAllocationJson<'a> {
    /// The view of `al` for the table of `e2e`.
    #[must_use]
    pub(crate) fn new(e2e: &EndToEnd, al: &'a DiscAllocation) -> Self {
        let names = e2e.turntable().rotation_error_names();
        Self {
            constant: ConstantPairsJson {
                disc: AllocationJson::new(&names, &al.constant_disc),
                square: AllocationJson::new(&names, &al.constant_square),
            },
            angle_dependent: AnglePairsJson {
                disc: AllocationJson::new(&names, &al.angle_disc),
                square: AllocationJson::new(&names, &al.angle_square),
                disc_certified: CertifiedJson::new(&names, &al.angle_disc_certified),
                square_certified: CertifiedJson::new(&names, &al.angle_square_certified),
            },
        }
    }
}

/// One reading of the sheet allocations.
#[derive(Debug)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub(crate) struct SheetReadingJson<'a> {
    /// The reading of eq 13.
    pub reading: String,
    /// Its allocations.
    #[cfg_attr(feature = "serde", serde(flatten))]
    pub allocation: DiscAllocationJson<'a>,
}

/// The sheet allocations (`disc_allocation`): the sheet's path and one entry per reading.
#[derive(Debug)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct SheetAllocationsJson<'a> {
    /// The sheet's path.
    pub tolerances: &'a str,
    /// Per reading.
    pub(crate) readings: Vec<SheetReadingJson<'a>>,
}

impl<'a> SheetAllocationsJson<'a> {
    /// The view of the allocations `a` with the sheet at `path`.
    #[must_use]
    pub fn new(path: &'a str, a: &'a [(EndToEnd, DiscAllocation)]) -> Self {
        Self {
            tolerances: path,
            readings: a
                .iter()
                .map(|(e2e, al)| SheetReadingJson {
                    reading: e2e.reading().to_string(),
                    allocation: DiscAllocationJson::new(e2e, al),
                })
                .collect(),
        }
    }
}

/// Worst cases over the discs, per output, output's unit.
#[derive(Debug)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub(crate) struct DiscWorstCaseJson<'a> {
    /// Under the constant model.
    pub constant: &'a [f64],
    /// Under the angle-dependent model.
    pub angle_dependent: &'a [f64],
}

/// The check with the sheet's pairs as discs.
#[derive(Debug)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub(crate) struct DiscsJson<'a> {
    /// A lower bound of the angle-dependent worst case per output, output's unit.
    pub worst_case_linear_lower: &'a [f64],
    /// Yield under the angle-dependent model, in [0, 1].
    #[cfg_attr(feature = "serde", serde(rename = "yield"))]
    pub yield_fraction: f64,
    /// Its 95% interval.
    pub yield_interval_95: (f64, f64),
    /// Turntables drawn.
    pub samples: u64,
    /// Yield under the constant model, in [0, 1].
    pub constant_yield: f64,
    /// Its 95% interval.
    pub constant_yield_interval_95: (f64, f64),
    /// The allocations with one tolerance per pair, `null` when not computed.
    pub allocation: Option<DiscAllocationJson<'a>>,
}

/// One output's worst case under the angle-dependent model, output's unit.
#[derive(Debug)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub(crate) struct AngleOutputJson<'a> {
    /// The output's name.
    pub name: &'a str,
    /// The linearised worst case, output's unit.
    pub worst_case_linear: f64,
    /// The same under the constant model, output's unit.
    pub worst_case_linear_constant_model: f64,
    /// The exact chain at the worst errors, output's unit.
    pub worst_case_exact_at_worst: f64,
    /// The certified second-order bound (`null` when not computed), output's unit.
    pub second_order_bound: Option<f64>,
    /// The worst test position (index into the schedule).
    pub worst_position: usize,
    /// The output's verdict, every modelled source counted.
    pub verdict: &'static str,
    /// With the study's noise: the table's part alone; absent otherwise.
    #[cfg_attr(feature = "serde", serde(skip_serializing_if = "Option::is_none"))]
    pub table_verdict: Option<&'static str>,
}

/// The angle-dependent check of one reading.
#[derive(Debug)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub(crate) struct ReadingAngleJson<'a> {
    /// The weakest output's verdict, every modelled source counted (with the study's noise:
    /// the table's part plus the noise's).
    pub verdict: &'static str,
    /// With the study's noise: the table's part alone; absent otherwise.
    #[cfg_attr(feature = "serde", serde(skip_serializing_if = "Option::is_none"))]
    pub table_verdict: Option<&'static str>,
    /// Yield, in [0, 1].
    #[cfg_attr(feature = "serde", serde(rename = "yield"))]
    pub yield_fraction: f64,
    /// Its 95% interval.
    pub yield_interval_95: (f64, f64),
    /// Turntables drawn.
    pub samples: u64,
    /// With the sheet's pairs: the worst cases over the discs, else `null`.
    pub disc_worst_case_linear: Option<DiscWorstCaseJson<'a>>,
    /// With the sheet's pairs: the check with discs, else `null`.
    pub discs: Option<DiscsJson<'a>>,
    /// Every output's worst case.
    pub outputs: Vec<AngleOutputJson<'a>>,
}

impl<'a> ReadingAngleJson<'a> {
    /// The view of the reading `a` of `e2e`.
    #[must_use]
    pub(crate) fn new(e2e: &'a EndToEnd, a: &'a ReadingAngle) -> Self {
        Self {
            verdict: a.verdict.name(),
            table_verdict: a.table_verdict.map(Verdict::name),
            yield_fraction: a.yield_.count().fraction(),
            yield_interval_95: a.yield_.count().interval_95(),
            samples: a.yield_.count().samples(),
            disc_worst_case_linear: a.disc.as_ref().map(|d| DiscWorstCaseJson {
                constant: &d.constant,
                angle_dependent: &d.angle,
            }),
            discs: a.disc.as_ref().map(|d| DiscsJson {
                worst_case_linear_lower: &d.angle_lower,
                yield_fraction: d.yield_.count().fraction(),
                yield_interval_95: d.yield_.count().interval_95(),
                samples: d.yield_.count().samples(),
                constant_yield: d.constant_yield.count().fraction(),
                constant_yield_interval_95: d.constant_yield.count().interval_95(),
                allocation: d
                    .allocation
                    .as_ref()
                    .map(|al| DiscAllocationJson::new(e2e, al)),
            }),
            outputs: a
                .outputs
                .iter()
                .zip(&a.output_verdicts)
                .map(|(o, counted)| AngleOutputJson {
                    name: &e2e.calibration().outputs()[o.output()].output().name,
                    worst_case_linear: o.linear_bound(),
                    worst_case_linear_constant_model: o.constant_linear_bound(),
                    worst_case_exact_at_worst: o.exact_at_vertex(),
                    second_order_bound: o.second_order_bound(),
                    worst_position: o.position(),
                    verdict: counted.name(),
                    table_verdict: a.table_verdict.map(|_| o.verdict().name()),
                })
                .collect(),
        }
    }
}

/// One error's shaft-angle model.
#[derive(Debug)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub(crate) struct ErrorModelJson<'a> {
    /// The error's name.
    pub error: &'a str,
    /// `constant`, `harmonics` or `any` ([`ErrorVariation::name`]).
    pub varies: &'static str,
    /// The joint whose angle it varies with, `null` when constant.
    pub of: Option<&'a str>,
    /// The harmonics' orders, `null` unless `harmonics`.
    pub harmonics: Option<&'a [u32]>,
}

/// The `angle_dependent` key of `check-turntable`: the model and one object per reading (the
/// study's, then the user's when different).
#[derive(Debug)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub(crate) struct AngleCheckJson<'a> {
    /// `study` (the study's model) or `any-on-shafts`.
    pub model: &'static str,
    /// What the sheet supports: `study` or `angle-dependent`.
    pub sheet_supports: &'static str,
    /// Every error's model.
    pub errors: Vec<ErrorModelJson<'a>>,
    /// Per reading.
    pub readings: Vec<ReadingAngleJson<'a>>,
}

impl<'a> AngleCheckJson<'a> {
    /// The view of `a` for `checks`.
    #[must_use]
    pub(crate) fn new(checks: &'a [(EndToEnd, TurntableCheck)], a: &'a AngleCheck) -> Self {
        let names = checks[0].0.turntable().rotation_error_names();
        Self {
            model: if a.study_model {
                "study"
            } else {
                "any-on-shafts"
            },
            sheet_supports: if a.study_model {
                "study"
            } else {
                "angle-dependent"
            },
            errors: names
                .iter()
                .zip(&a.variations)
                .map(|(n, v)| {
                    let (joint, orders) = match v {
                        ErrorVariation::Harmonics { joint, orders } => {
                            (Some(joint.as_str()), Some(orders.as_slice()))
                        }
                        ErrorVariation::Any { joint } => (Some(joint.as_str()), None),
                        ErrorVariation::Constant => (None, None),
                    };
                    ErrorModelJson {
                        error: n,
                        varies: v.name(),
                        of: joint,
                        harmonics: orders,
                    }
                })
                .collect(),
            readings: checks
                .iter()
                .zip(&a.readings)
                .map(|((e, _), r)| ReadingAngleJson::new(e, r))
                .collect(),
        }
    }
}

/// One reading of the compensated check.
#[derive(Debug)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub(crate) struct CompensatedReadingJson<'a> {
    /// The reading of eq 13.
    pub reading: String,
    /// The weakest output's verdict (constant errors), every modelled source counted.
    pub verdict: &'static str,
    /// With the study's noise: the table's part alone; absent otherwise.
    #[cfg_attr(feature = "serde", serde(skip_serializing_if = "Option::is_none"))]
    pub table_verdict: Option<&'static str>,
    /// Every output's linearised worst case, output's unit.
    pub worst_case_linear: Vec<f64>,
    /// The angle-dependent check.
    pub angle_dependent: ReadingAngleJson<'a>,
}

/// The `compensated` key of `check-turntable`.
#[derive(Debug)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub(crate) struct CompensatedJson<'a> {
    /// The box that matters (measured errors at their uncertainty, or at the sheet's bound
    /// plus the measured value's largest magnitude when smaller), arcmin.
    pub tolerances_arcmin: ArcminBounds,
    /// One sentence per measured error whose uncertainty exceeds the sheet's bound.
    pub notes: &'a [String],
    /// Per reading.
    pub(crate) readings: Vec<CompensatedReadingJson<'a>>,
}

impl<'a> CompensatedJson<'a> {
    /// The view of `c` for `checks`.
    #[must_use]
    pub(crate) fn new(checks: &'a [(EndToEnd, TurntableCheck)], c: &'a Compensated) -> Self {
        let names = checks[0].0.turntable().rotation_error_names();
        Self {
            tolerances_arcmin: arcmin_bounds(&names, c.sheet.upper_bounds_rad()),
            notes: &c.notes,
            readings: checks
                .iter()
                .zip(&c.checks)
                .zip(&c.angle.readings)
                .map(|(((e2e, _), k), a)| CompensatedReadingJson {
                    reading: e2e.reading().to_string(),
                    verdict: constant_counted(k, c.angle.noise.as_ref()).name(),
                    table_verdict: c.angle.noise.as_ref().map(|_| k.verdict().name()),
                    worst_case_linear: k
                        .outputs()
                        .iter()
                        .map(|o| o.worst_case().linear_bound())
                        .collect(),
                    angle_dependent: ReadingAngleJson::new(e2e, a),
                })
                .collect(),
        }
    }
}
