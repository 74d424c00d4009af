//! Position schedules, the regression of eq 2/4/5, simulation of outputs and calibration (eq 6).

use crate::error::{CalibError, finite};
use crate::lsq::{LsqSolution, Regression};
use gw_model::{
    AxisCoefficients, DriftCoefficients, Inputs, N_COEFFICIENTS, Position, SensingAxis, Site,
    regressors,
};
use nalgebra::{DMatrix, DVector, Matrix3};

/// Outer-axis angles of the default schedule, degrees.
pub const DEFAULT_PHI_1_DEG: [f64; 4] = [0.0, 90.0, 180.0, 270.0];
/// Inner-axis angles of the default schedule, degrees.
pub const DEFAULT_PHI_2_DEG: [f64; 8] = [0.0, 45.0, 90.0, 135.0, 180.0, 225.0, 270.0, 315.0];

/// A list of turntable positions $(\phi_{1i}, \phi_{2i})$ that identifies all seven coefficients
/// of both axes.
#[derive(Debug, Clone, PartialEq)]
pub struct Schedule {
    positions: Vec<Position>,
}

impl Schedule {
    /// A schedule from positions, checked for identifiability of both axes.
    ///
    /// # Errors
    /// [`CalibError::Unidentifiable`] naming the coefficients the positions cannot separate (for
    /// example `D(x)_xy` when every $\phi_2$ is a multiple of 90°, which makes $a_x a_y = 0$).
    pub fn new(positions: Vec<Position>) -> Result<Self, CalibError> {
        let s = Self { positions };
        for axis in SensingAxis::ALL {
            Regression::new(axis, s.regression_matrix(axis))?;
        }
        Ok(s)
    }

    /// A schedule from $(\phi_1, \phi_2)$ pairs in degrees.
    ///
    /// # Errors
    /// [`CalibError::Model`] for a non-finite angle; otherwise as [`Schedule::new`].
    pub fn from_deg(pairs: &[(f64, f64)]) -> Result<Self, CalibError> {
        let positions = pairs
            .iter()
            .map(|&(a, b)| Position::from_deg(a, b))
            .collect::<Result<Vec<_>, _>>()?;
        Self::new(positions)
    }

    /// The default schedule: the 32 positions $\phi_1 \in \{0, 90, 180, 270\}°$ times
    /// $\phi_2 \in \{0, 45, \dots, 315\}°$.
    ///
    /// The paper does not list its positions (it cites a schedule optimised in its reference
    /// \[10\]; NOTES item 10). This grid is the usual choice for a two-axis multiposition test:
    /// - gravity: $\phi_1 = 0, 180°$ put $z$ up and down; $\phi_1 = 90, 270°$ sweep $x$, $y$
    ///   around the horizontal in 45° steps, so $a_x^2$, $a_x a_y$ ($\pm 1/2$ at odd multiples
    ///   of 45°) and $a_z^2$ are separated: all seven coefficients of both axes are identifiable
    ///   (condition number about 4.6);
    /// - earth rate: the set is symmetric under $\phi_2 \to -\phi_2$ and
    ///   $\phi_2 \to 180° - \phi_2$, which makes the rate-sensing errors even (claim 2 of §2.2).
    #[must_use]
    pub fn paper_default() -> Self {
        let positions = DEFAULT_PHI_1_DEG
            .iter()
            .flat_map(|&p1| {
                DEFAULT_PHI_2_DEG.iter().map(move |&p2| {
                    Position::new(p1.to_radians(), p2.to_radians())
                        .unwrap_or_else(|_| unreachable!("finite constants"))
                })
            })
            .collect();
        Self { positions }
    }

    /// A product grid $\phi_1 \in \{k\,\Delta_1\}$, $\phi_2 \in \{k\,\Delta_2\}$ over full turns,
    /// steps in degrees (must divide 360).
    ///
    /// # Errors
    /// [`CalibError::NonPositive`] for a non-positive step; otherwise as [`Schedule::new`].
    pub fn grid_deg(step_1_deg: f64, step_2_deg: f64) -> Result<Self, CalibError> {
        for (field, s) in [("phi1 step", step_1_deg), ("phi2 step", step_2_deg)] {
            finite(field, s)?;
            if s <= 0.0 {
                return Err(CalibError::NonPositive { field, value: s });
            }
        }
        let n1 = (360.0 / step_1_deg).round().max(1.0) as usize;
        let n2 = (360.0 / step_2_deg).round().max(1.0) as usize;
        let mut pairs = Vec::with_capacity(n1 * n2);
        for i in 0..n1 {
            for j in 0..n2 {
                pairs.push((i as f64 * step_1_deg, j as f64 * step_2_deg));
            }
        }
        Self::from_deg(&pairs)
    }

    /// The positions.
    #[must_use]
    pub fn positions(&self) -> &[Position] {
        &self.positions
    }

    /// Number of positions $n$.
    #[must_use]
    pub fn len(&self) -> usize {
        self.positions.len()
    }

    /// Whether there are no positions (never true for a constructed schedule).
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.positions.is_empty()
    }

    /// The same schedule with the positions in another order; `order[i]` is the index of the
    /// position placed at `i`.
    ///
    /// # Errors
    /// [`CalibError::LengthMismatch`] unless `order` is a permutation of `0..n`.
    pub fn permuted(&self, order: &[usize]) -> Result<Self, CalibError> {
        let n = self.len();
        let mut seen = vec![false; n];
        for &k in order {
            if k >= n || seen[k] {
                return Err(CalibError::LengthMismatch {
                    what: "permutation",
                    expected: n,
                    found: order.len(),
                });
            }
            seen[k] = true;
        }
        if order.len() != n {
            return Err(CalibError::LengthMismatch {
                what: "permutation",
                expected: n,
                found: order.len(),
            });
        }
        Ok(Self {
            positions: order.iter().map(|&k| self.positions[k]).collect(),
        })
    }

    /// The nominal inputs at every position (eq 3).
    #[must_use]
    pub fn inputs(&self, site: &Site) -> Vec<Inputs> {
        self.positions.iter().map(|p| site.inputs(p)).collect()
    }

    /// The regression matrix $\mathbf A$ of one axis with the intended orientations (eq 2/4).
    /// It depends on gravity only, not on the site.
    #[must_use]
    pub fn regression_matrix(&self, axis: SensingAxis) -> DMatrix<f64> {
        let site = Site::paper_default();
        regression_matrix(axis, &self.inputs(&site))
    }
}

/// The regression matrix (n x 7) of one axis for given inputs: row $i$ is
/// [`regressors`]`(axis, a_i)` (eq 2/4 with $\mathbf a$; eq 10 with $\mathbf a'$).
#[must_use]
pub fn regression_matrix(axis: SensingAxis, inputs: &[Inputs]) -> DMatrix<f64> {
    let mut a = DMatrix::zeros(inputs.len(), N_COEFFICIENTS);
    for (i, inp) in inputs.iter().enumerate() {
        for (j, r) in regressors(axis, &inp.specific_force_g).iter().enumerate() {
            a[(i, j)] = *r;
        }
    }
    a
}

/// The rate vector of one axis ($\mathbf b_2$ of eq 4 with nominal inputs, $\mathbf b_2'$ of eq
/// 10 with actual ones), rad/s.
#[must_use]
pub fn rate_vector(axis: SensingAxis, inputs: &[Inputs]) -> DVector<f64> {
    DVector::from_iterator(
        inputs.len(),
        inputs
            .iter()
            .map(|i| axis.rate_component(&i.rate_rad_per_s)),
    )
}

/// Simulated outputs $\mathbf b_1 = [k\,i]$ (rad/s) of one axis when position $i$ is realised
/// with the orientation error `delta_r[i]` ($\Delta\mathbf R = \mathbf R_d^T\mathbf R_t$, eq 23;
/// pass identities for the intended orientation).
///
/// # Formula
/// $b_{1,i} = \omega'_i + \sum_j D_j\, r_j(\mathbf a'_i)$ with the actual inputs of eq 8, i.e.
/// $\mathbf b_1 = \mathbf A'\boldsymbol\beta + \mathbf b_2'$ (eq 9).
///
/// # Reference
/// Eq 1, 8, 9.
///
/// # Errors
/// [`CalibError::LengthMismatch`] unless there is one matrix per position.
pub fn simulate_outputs(
    coefficients: &AxisCoefficients,
    schedule: &Schedule,
    site: &Site,
    delta_r: &[Matrix3<f64>],
) -> Result<DVector<f64>, CalibError> {
    let inputs = actual_inputs(schedule, site, delta_r)?;
    Ok(DVector::from_iterator(
        inputs.len(),
        inputs.iter().map(|i| coefficients.output_rad_per_s(i)),
    ))
}

/// The actual inputs (eq 8) at every position for per-position $\Delta\mathbf R$.
///
/// # Errors
/// [`CalibError::LengthMismatch`] unless there is one matrix per position.
pub fn actual_inputs(
    schedule: &Schedule,
    site: &Site,
    delta_r: &[Matrix3<f64>],
) -> Result<Vec<Inputs>, CalibError> {
    if delta_r.len() != schedule.len() {
        return Err(CalibError::LengthMismatch {
            what: "delta_r",
            expected: schedule.len(),
            found: delta_r.len(),
        });
    }
    Ok(schedule
        .positions()
        .iter()
        .zip(delta_r)
        .map(|(p, d)| site.inputs_with_error(p, d))
        .collect())
}

/// A calibration result: the estimated coefficients of one axis and the fit's quality.
#[derive(Debug, Clone, PartialEq)]
pub struct Calibration {
    /// The estimated coefficients $\hat{\boldsymbol\beta}_1$.
    pub coefficients: AxisCoefficients,
    /// The least-squares solution (residuals, rank, condition number).
    pub solution: LsqSolution,
}

/// Calibrate one axis from measured outputs $\mathbf b_1$ (rad/s, one per position), using the
/// nominal inputs of the schedule.
///
/// # Formula
/// $\hat{\boldsymbol\beta}_1 = \arg\min \lVert \mathbf A\boldsymbol\beta - (\mathbf b_1 -
/// \mathbf b_2)\rVert_2$, solved by SVD.
///
/// # Reference
/// Eq 5-6.
///
/// # Errors
/// [`CalibError::LengthMismatch`], [`CalibError::NonFinite`] naming the output, or
/// [`CalibError::Unidentifiable`].
pub fn calibrate(
    axis: SensingAxis,
    schedule: &Schedule,
    site: &Site,
    outputs_rad_per_s: &[f64],
) -> Result<Calibration, CalibError> {
    if outputs_rad_per_s.len() != schedule.len() {
        return Err(CalibError::LengthMismatch {
            what: "outputs",
            expected: schedule.len(),
            found: outputs_rad_per_s.len(),
        });
    }
    for (i, v) in outputs_rad_per_s.iter().enumerate() {
        finite(format!("outputs[{i}]"), *v)?;
    }
    let inputs = schedule.inputs(site);
    let b1 = DVector::from_column_slice(outputs_rad_per_s);
    let y = b1 - rate_vector(axis, &inputs);
    let solution = Regression::new(axis, regression_matrix(axis, &inputs))?.solve(&y)?;
    let mut values = [0.0; N_COEFFICIENTS];
    values.copy_from_slice(solution.beta.as_slice());
    let coefficients = AxisCoefficients::from_rad_per_s(axis, values)?;
    Ok(Calibration {
        coefficients,
        solution,
    })
}

/// Calibrate both axes from simulated outputs with per-position orientation errors: the
/// end-to-end path (outputs at the actual orientation, estimate from the nominal inputs).
///
/// # Errors
/// As [`simulate_outputs`] and [`calibrate`].
pub fn calibrate_simulated(
    truth: &DriftCoefficients,
    schedule: &Schedule,
    site: &Site,
    delta_r: &[Matrix3<f64>],
) -> Result<[Calibration; 2], CalibError> {
    let mut out = Vec::with_capacity(2);
    for axis in SensingAxis::ALL {
        let b1 = simulate_outputs(truth.axis(axis), schedule, site, delta_r)?;
        out.push(calibrate(axis, schedule, site, b1.as_slice())?);
    }
    let y = out.pop().unwrap_or_else(|| unreachable!("two axes pushed"));
    let x = out.pop().unwrap_or_else(|| unreachable!("two axes pushed"));
    Ok([x, y])
}
