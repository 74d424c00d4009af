//! The buyer's question for one set of inputs: worst case and yield of the paper's Table 4 and
//! of the two-step optimum, and the direct and yield-based allocations, for the chosen reading
//! and for the user's reading.

use crate::allocate::{DEFAULT_YIELD_FRACTION, DirectAllocation, YieldAllocation, paper_objective};
use crate::error::{E2eError, fraction, positive};
use crate::linear::WorstCase;
use crate::montecarlo::{McSettings, RateDistribution};
use crate::simulate::EndToEnd;
use alloc_opt::{
    AllocationProblem, Allocator, PAPER_REQUIREMENT_DEG, Requirement, SensitivityWeighted,
    paper_table4_rad,
};
use calib_lsq::{PAPER_OMEGA_M_DEG_PER_H, Reading, Schedule};
use gw_model::units::deg_per_h_to_rad_per_s;
use gw_model::{DriftCoefficients, Site};
use mc_verify::ErrorBox;
use tt_kinematics::units::{RAD_PER_ARCMIN, deg_to_rad};
use tt_kinematics::{CHI_LEN, LinearModel};

/// Default number of Monte Carlo turntables per box.
pub const DEFAULT_SAMPLES: u64 = 20_000;

/// Default seed.
pub const DEFAULT_SEED: u64 = 2017;

/// Everything the end-to-end answer depends on (radians and rad/s inside; a study file fills
/// it at the edge).
#[derive(Debug, Clone, PartialEq)]
pub struct EndToEndInputs {
    /// The true drift coefficients (default Table 1).
    pub coefficients: DriftCoefficients,
    /// Latitude and earth rate (default Harbin, WGS-84).
    pub site: Site,
    /// The calibration positions (default [`Schedule::paper_default`]).
    pub schedule: Schedule,
    /// The reading of eq 13 (default [`Reading::PAPER`]); the user's reading
    /// [`Reading::USER`] is always evaluated as well.
    pub reading: Reading,
    /// Required calibration accuracy $\omega_m$, rad/s (default 0.01 deg/h).
    pub omega_m_rad_per_s: f64,
    /// Lower bounds $\mathrm{LB}$, rad (default 0: the paper gives none).
    pub lower_bounds_rad: [f64; CHI_LEN],
    /// The orientation requirement $(I_\psi, I_\theta, I_\gamma)$ handed to the two-step
    /// allocation, rad (default 0.027 deg each, eq 16 as printed).
    pub two_step_requirement_rad: [f64; 3],
    /// Monte Carlo turntables per box.
    pub samples: u64,
    /// Seed (the yield-allocation design uses `seed + 1`).
    pub seed: u64,
    /// Target yield of the yield-based allocation (default 0.9973).
    pub yield_fraction: f64,
}

impl EndToEndInputs {
    /// The paper's inputs with this project's documented defaults.
    #[must_use]
    pub fn paper() -> Self {
        Self {
            coefficients: DriftCoefficients::table_1(),
            site: Site::paper_default(),
            schedule: Schedule::paper_default(),
            reading: Reading::PAPER,
            omega_m_rad_per_s: deg_per_h_to_rad_per_s(PAPER_OMEGA_M_DEG_PER_H),
            lower_bounds_rad: [0.0; CHI_LEN],
            two_step_requirement_rad: [deg_to_rad(PAPER_REQUIREMENT_DEG); 3],
            samples: DEFAULT_SAMPLES,
            seed: DEFAULT_SEED,
            yield_fraction: DEFAULT_YIELD_FRACTION,
        }
    }

    /// Check every field.
    ///
    /// # Errors
    /// Typed errors naming the field: `omega_m`, `two_step_requirement`, `samples`,
    /// `yield_fraction`, or the component and bound of a bad lower bound.
    pub fn validate(&self) -> Result<(), E2eError> {
        positive("omega_m", self.omega_m_rad_per_s)?;
        for (name, v) in ["psi", "theta", "gamma"]
            .iter()
            .zip(self.two_step_requirement_rad)
        {
            positive(&format!("two_step_requirement.{name}"), v)?;
        }
        if self.samples == 0 {
            return Err(E2eError::ZeroSamples { field: "samples" });
        }
        fraction("yield_fraction", self.yield_fraction)?;
        ErrorBox::new(
            self.lower_bounds_rad,
            self.lower_bounds_rad.map(|v| v.max(0.0)),
        )?;
        Ok(())
    }
}

/// Worst case and Monte Carlo distribution of one tolerance box.
#[derive(Debug, Clone, PartialEq)]
pub struct BoxAnswer {
    /// The upper bounds (rad).
    pub upper_bounds_rad: [f64; CHI_LEN],
    /// $J$ of these bounds (rad$^{-2}$).
    pub objective: f64,
    /// Worst case (linearised vertex, exact confirmation, second-order bound).
    pub worst_case: WorstCase,
    /// Distribution and yield over turntables drawn from the box.
    pub distribution: RateDistribution,
}

/// The answer under one reading.
#[derive(Debug, Clone, PartialEq)]
pub struct ReadingAnswer {
    /// The reading.
    pub reading: Reading,
    /// The paper's Table 4.
    pub table4: BoxAnswer,
    /// The two-step optimum (alloc-opt, sensitivity-weighted, against $I$).
    pub ours: BoxAnswer,
    /// The direct allocation against $\omega_m$ and its check.
    pub direct: DirectAllocation,
    /// The direct allocation's box (worst case and yield).
    pub direct_box: BoxAnswer,
    /// The direct allocation certified on the exact chain
    /// ([`EndToEnd::allocate_direct_certified`]); `None` for a reading without a derived
    /// second-order bound.
    pub direct_certified: Option<(DirectAllocation, WorstCase)>,
    /// The yield-based allocation (shape of the direct one).
    pub yield_based: YieldAllocation,
    /// The yield-based box re-measured with an independent seed (`seed + 2`).
    pub yield_box: BoxAnswer,
}

/// The full answer.
#[derive(Debug, Clone, PartialEq)]
pub struct BuyersAnswer {
    /// The inputs.
    pub inputs: EndToEndInputs,
    /// $J$ of the two-step optimum (rad$^{-2}$).
    pub two_step_objective: f64,
    /// $J$ of Table 4 (rad$^{-2}$).
    pub table4_objective: f64,
    /// One answer per reading: `inputs.reading` first, then [`Reading::USER`] (if different).
    pub readings: Vec<ReadingAnswer>,
}

/// $J$ in arcmin$^{-2}$ from rad$^{-2}$.
#[must_use]
pub fn objective_to_arcmin(objective_rad: f64) -> f64 {
    objective_rad * RAD_PER_ARCMIN * RAD_PER_ARCMIN
}

/// Answer the buyer's question for `inputs`.
///
/// # Errors
/// As [`EndToEndInputs::validate`], [`EndToEnd::new`], the allocations and the Monte Carlo.
pub fn answer(inputs: &EndToEndInputs) -> Result<BuyersAnswer, E2eError> {
    inputs.validate()?;
    let table4 = paper_table4_rad();
    let two_step = SensitivityWeighted::paper().allocate(&AllocationProblem::new(
        LinearModel::paper_eq26(),
        Requirement::new(
            inputs.two_step_requirement_rad[0],
            inputs.two_step_requirement_rad[1],
            inputs.two_step_requirement_rad[2],
        )?,
        inputs.lower_bounds_rad,
    )?)?;
    let ours = two_step.upper_bounds_rad;
    // Both boxes must contain their lower bounds (named error before any heavy work).
    ErrorBox::new(inputs.lower_bounds_rad, table4)?;
    ErrorBox::new(inputs.lower_bounds_rad, ours)?;
    let mut readings = vec![inputs.reading];
    if inputs.reading != Reading::USER {
        readings.push(Reading::USER);
    }
    let settings = McSettings::new(inputs.samples, inputs.seed);
    let lb = inputs.lower_bounds_rad;
    let omega_m = inputs.omega_m_rad_per_s;
    let mut out = Vec::new();
    for reading in readings {
        let e2e = EndToEnd::new(
            &inputs.coefficients,
            &inputs.site,
            &inputs.schedule,
            reading,
        )?;
        let linear = e2e.linearization();
        let box_answer = |ub: [f64; CHI_LEN], s: &McSettings| -> Result<BoxAnswer, E2eError> {
            Ok(BoxAnswer {
                upper_bounds_rad: ub,
                objective: paper_objective(&ub),
                worst_case: e2e.worst_case(&linear, &ub)?,
                distribution: e2e.rate_distribution(&ErrorBox::new(lb, ub)?, omega_m, s)?,
            })
        };
        let direct = e2e.allocate_direct(&linear, omega_m, &lb)?;
        let direct_certified = match e2e.allocate_direct_certified(&linear, omega_m, &lb) {
            Ok(d) => {
                let wc = e2e.worst_case(&linear, &d.upper_bounds_rad)?;
                Some((d, wc))
            }
            Err(E2eError::OutOfRange {
                field: "reading", ..
            }) => None,
            Err(e) => return Err(e),
        };
        let design = McSettings::new(inputs.samples, inputs.seed.wrapping_add(1));
        let yield_based = e2e.allocate_yield(
            &direct.upper_bounds_rad,
            &lb,
            omega_m,
            inputs.yield_fraction,
            &design,
        )?;
        let recheck = McSettings::new(inputs.samples, inputs.seed.wrapping_add(2));
        out.push(ReadingAnswer {
            reading,
            table4: box_answer(table4, &settings)?,
            ours: box_answer(ours, &settings)?,
            direct_box: box_answer(direct.upper_bounds_rad, &settings)?,
            yield_box: box_answer(yield_based.upper_bounds_rad, &recheck)?,
            direct,
            direct_certified,
            yield_based,
        });
    }
    Ok(BuyersAnswer {
        inputs: inputs.clone(),
        two_step_objective: paper_objective(&ours),
        table4_objective: paper_objective(&table4),
        readings: out,
    })
}
