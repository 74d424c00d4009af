//! A sensor on a schedule at a site: the regressions of eq 2/4/5 per output, simulation of the
//! outputs (eq 8-9) and the calibration (eq 6).

use crate::error::{CalibError, finite};
use crate::lsq::{LsqSolution, Regression};
use crate::schedule::Schedule;
use gw_model::{InputValues, Inputs, Output, SensorModel, Site};
use nalgebra::{DMatrix, DVector, Matrix3};

/// A monomial compiled for fast evaluation: the input indices of its factors (a power
/// repeats its index).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Mono {
    idx: [u8; gw_model::MAX_REGRESSOR_DEGREE as usize],
    len: u8,
}

impl Mono {
    fn new(r: &gw_model::Regressor) -> Self {
        let mut idx = [0u8; gw_model::MAX_REGRESSOR_DEGREE as usize];
        let mut len = 0;
        for (j, u) in gw_model::Input::ALL.iter().enumerate() {
            for _ in 0..r.power(*u) {
                idx[len] = j as u8;
                len += 1;
            }
        }
        Self {
            idx,
            len: len as u8,
        }
    }

    #[inline(always)]
    pub(crate) fn eval(&self, v: &[f64; 6]) -> f64 {
        let mut out = 1.0;
        for &i in &self.idx[..usize::from(self.len)] {
            out *= v[usize::from(i)];
        }
        out
    }

    /// The input indices of the factors, in input order (a power repeats its index).
    #[inline(always)]
    pub(crate) fn factors(&self) -> &[u8] {
        self.idx.get(..usize::from(self.len)).unwrap_or_default()
    }

    /// Mark the inputs (indices into the six input values) the monomial multiplies.
    pub(crate) fn mark_inputs(&self, used: &mut [bool; 6]) {
        for &i in &self.idx[..usize::from(self.len)] {
            if let Some(u) = used.get_mut(usize::from(i)) {
                *u = true;
            }
        }
    }

    /// The monomial as a product of two entries of $(1, \mathbf v)$ (indices into
    /// $(1, \mathbf v)$, index 0 the 1), when its degree is at most 2: evaluates to the same bits as
    /// [`Mono::eval`] ($1\cdot x = x$ exactly).
    fn pair(&self) -> Option<[u8; 2]> {
        let i = |q: usize| self.idx[q] + 1;
        match self.len {
            0 => Some([0, 0]),
            1 => Some([i(0), 0]),
            2 => Some([i(0), i(1)]),
            _ => None,
        }
    }
}

/// An output whose every monomial has degree at most 2, compiled for the branch-free fast
/// path of the readings with outputs at the actual orientation and $\hat{\boldsymbol\beta}_1$
/// (the user's reading): each monomial a product of two entries of $(1, \mathbf v)$ (index 0 the 1).
#[derive(Debug, Clone)]
pub(crate) struct QuadraticTerms {
    /// The estimated terms' monomials, in column order.
    pub estimated: Vec<[u8; 2]>,
    /// The known terms: value and monomial.
    pub known: Vec<(f64, [u8; 2])>,
    /// $\mathbf A^+$ position-major ($n \times k$: entry $(i, j)$ at $ik + j$).
    pub pinv_cols: Vec<f64>,
    /// $\mathbf A^+$ position-major with rows padded by zeros to
    /// [`crate::columns::COEFFICIENT_LANES`] entries ($n \times 8$), empty when $k$ exceeds
    /// it.
    pub pinv_lanes: Vec<f64>,
    /// $\mathbf A$ in blocks of [`crate::columns::POSITION_LANES`] positions ($L$), the
    /// positions of a block contiguous: entry $(bL + l, j)$ at $bLk + jL + l$, whole blocks
    /// only (the remaining rows are read from [`FastOutput::a_rows`]).
    pub a_lanes: Vec<f64>,
}

/// Row-major copies and compiled terms of an output for the fast path (no lookups, contiguous
/// rows).
#[derive(Debug, Clone)]
pub(crate) struct FastOutput {
    /// $\mathbf A$ row-major ($n \times k$).
    pub a_rows: Vec<f64>,
    /// $\mathbf A^+$ row-major ($k \times n$).
    pub pinv_rows: Vec<f64>,
    /// Estimated terms' monomials (the columns of $\mathbf A$).
    pub estimated: Vec<Mono>,
    /// Known terms: value and monomial.
    pub known: Vec<(f64, Mono)>,
    /// $\mathbf A\boldsymbol\beta + \mathbf b_2$: the outputs at the intended orientation.
    pub b1_intended: Vec<f64>,
    /// The compiled terms when every monomial has degree at most 2.
    pub quadratic: Option<QuadraticTerms>,
    /// $\mathbf b_1 - \mathbf A\hat{\boldsymbol\beta}_1$ with the outputs at the intended
    /// orientation ($\mathbf b_1 = \mathbf A\boldsymbol\beta + \mathbf b_2$,
    /// $\hat{\boldsymbol\beta}_1 = \mathbf A^+(\mathbf b_1 - \mathbf b_2)$): the part of
    /// [`crate::Reading::PAPER`]'s error vector that does not depend on the actual inputs,
    /// computed once with the fast path's operations ([`crate::analysis`]).
    pub intended_residual: Vec<f64>,
}

/// One output of a prepared calibration: its nominal regression and the true quantities.
#[derive(Debug, Clone)]
pub struct OutputCalibration {
    output: Output,
    regression: Regression,
    b2: DVector<f64>,
    a_beta: DVector<f64>,
    beta: DVector<f64>,
    nominal: Vec<InputValues>,
    pub(crate) fast: FastOutput,
}

impl OutputCalibration {
    /// The nominal input values of every position (regressor units: g and deg/h).
    #[must_use]
    pub fn nominal_values(&self) -> &[InputValues] {
        &self.nominal
    }

    /// The output's description.
    #[must_use]
    pub fn output(&self) -> &Output {
        &self.output
    }

    /// The nominal regression ($\mathbf A$ factored, rank, condition number).
    #[must_use]
    pub fn regression(&self) -> &Regression {
        &self.regression
    }

    /// $\mathbf b_2$: the known part of the outputs at the intended orientations.
    #[must_use]
    pub fn b2(&self) -> &DVector<f64> {
        &self.b2
    }

    /// $\mathbf A\boldsymbol\beta$ with the true coefficients.
    #[must_use]
    pub fn a_beta(&self) -> &DVector<f64> {
        &self.a_beta
    }

    /// The true estimated coefficients $\boldsymbol\beta$ (study order).
    #[must_use]
    pub fn beta(&self) -> &DVector<f64> {
        &self.beta
    }
}

/// The result of calibrating one output: its estimated coefficients and the fit's quality.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct CalibrationResult {
    /// The output's name.
    pub(crate) output: String,
    /// The estimated coefficients' names (study order).
    pub(crate) names: Vec<String>,
    /// The least-squares solution (estimate $\hat{\boldsymbol\beta}_1$, residuals, rank,
    /// condition number).
    pub(crate) solution: LsqSolution,
}

/// Read access to the fields (crate-private, so the type can grow without breaking callers).
impl CalibrationResult {
    /// The output's name.
    #[must_use]
    pub fn output(&self) -> &str {
        &self.output
    }

    /// The estimated coefficients' names (study order).
    #[must_use]
    pub fn names(&self) -> &[String] {
        &self.names
    }

    /// The least-squares solution (estimate $\hat{\boldsymbol\beta}_1$, residuals, rank,
    /// condition number).
    #[must_use]
    pub fn solution(&self) -> &LsqSolution {
        &self.solution
    }
}

/// A sensor, a site and a schedule, checked to identify every output's coefficients; the
/// nominal regressions are factored once.
#[derive(Debug, Clone)]
pub struct Calibration {
    sensor: SensorModel,
    site: Site,
    schedule: Schedule,
    nominal: Vec<Inputs>,
    outputs: Vec<OutputCalibration>,
}

/// The regression matrix (n x k) of an output at the given inputs: row $i$ holds the
/// estimated terms' regressors at input $i$ (eq 2/4 at nominal inputs, eq 10 at actual ones).
#[must_use]
pub fn design_matrix(output: &Output, inputs: &[Inputs]) -> DMatrix<f64> {
    let k = output.n_estimated();
    let mut a = DMatrix::zeros(inputs.len(), k);
    for (i, inp) in inputs.iter().enumerate() {
        let v = InputValues::from_inputs(inp);
        for (j, r) in output.regressor_row(&v).enumerate() {
            a[(i, j)] = r;
        }
    }
    a
}

/// The known part of an output at the given inputs ($\mathbf b_2$ of eq 4 at nominal inputs,
/// $\mathbf b_2'$ of eq 10 at actual ones), in the output's unit.
#[must_use]
pub fn known_vector(output: &Output, inputs: &[Inputs]) -> DVector<f64> {
    DVector::from_iterator(
        inputs.len(),
        inputs
            .iter()
            .map(|i| output.known_part(&InputValues::from_inputs(i))),
    )
}

/// The outputs $\mathbf b_1$ the sensor produces at the given (actual) inputs: eq 1 solved
/// for the output, $\mathbf b_1 = \mathbf A'\boldsymbol\beta + \mathbf b_2'$ (eq 9).
#[must_use]
pub fn simulate_outputs(output: &Output, inputs: &[Inputs]) -> DVector<f64> {
    DVector::from_iterator(
        inputs.len(),
        inputs
            .iter()
            .map(|i| output.value(&InputValues::from_inputs(i))),
    )
}

impl Calibration {
    /// Prepare the calibration of `sensor` on `schedule` at `site`.
    ///
    /// # Errors
    /// [`CalibError::Unidentifiable`] naming the first output the schedule cannot identify and
    /// its unidentifiable coefficients.
    pub fn new(sensor: &SensorModel, site: &Site, schedule: &Schedule) -> Result<Self, CalibError> {
        let nominal = schedule.inputs(site);
        let outputs = sensor
            .outputs()
            .iter()
            .map(|o| {
                let a = design_matrix(o, &nominal);
                let names = o.estimated_names().into_iter().map(String::from).collect();
                let regression = Regression::new(&o.name, names, a)?;
                let beta = DVector::from_vec(o.estimated_values());
                let a_beta = regression.matrix() * &beta;
                let b2 = known_vector(o, &nominal);
                let (n, k) = regression.matrix().shape();
                let estimated: Vec<Mono> = o.estimated().map(|t| Mono::new(&t.regressor)).collect();
                let known: Vec<(f64, Mono)> = o
                    .known_terms()
                    .map(|t| (t.value, Mono::new(&t.regressor)))
                    .collect();
                let quadratic = (|| {
                    Some(QuadraticTerms {
                        estimated: estimated.iter().map(Mono::pair).collect::<Option<_>>()?,
                        known: known
                            .iter()
                            .map(|(c, m)| Some((*c, m.pair()?)))
                            .collect::<Option<_>>()?,
                        pinv_cols: (0..n)
                            .flat_map(|i| (0..k).map(move |j| (j, i)))
                            .map(|(j, i)| regression.pinv()[(j, i)])
                            .collect(),
                        pinv_lanes: if k <= crate::columns::COEFFICIENT_LANES {
                            (0..n)
                                .flat_map(|i| {
                                    (0..crate::columns::COEFFICIENT_LANES).map(move |j| (j, i))
                                })
                                .map(|(j, i)| {
                                    if j < k {
                                        regression.pinv()[(j, i)]
                                    } else {
                                        0.0
                                    }
                                })
                                .collect()
                        } else {
                            Vec::new()
                        },
                        a_lanes: {
                            let lanes = crate::columns::POSITION_LANES;
                            (0..n / lanes)
                                .flat_map(|b| {
                                    (0..k).flat_map(move |j| {
                                        (0..lanes).map(move |l| (b * lanes + l, j))
                                    })
                                })
                                .map(|(i, j)| regression.matrix()[(i, j)])
                                .collect()
                        },
                    })
                })();
                let mut fast = FastOutput {
                    a_rows: (0..n)
                        .flat_map(|i| (0..k).map(move |j| (i, j)))
                        .map(|(i, j)| regression.matrix()[(i, j)])
                        .collect(),
                    pinv_rows: (0..k)
                        .flat_map(|j| (0..n).map(move |i| (j, i)))
                        .map(|(j, i)| regression.pinv()[(j, i)])
                        .collect(),
                    estimated,
                    known,
                    b1_intended: (&a_beta + &b2).iter().copied().collect(),
                    quadratic,
                    intended_residual: Vec::new(),
                };
                fast.intended_residual =
                    crate::analysis::intended_residual(&fast, b2.as_slice(), k);
                Ok(OutputCalibration {
                    nominal: nominal.iter().map(InputValues::from_inputs).collect(),
                    a_beta,
                    b2,
                    beta,
                    regression,
                    output: o.clone(),
                    fast,
                })
            })
            .collect::<Result<Vec<_>, CalibError>>()?;
        Ok(Self {
            sensor: sensor.clone(),
            site: *site,
            schedule: schedule.clone(),
            nominal,
            outputs,
        })
    }

    /// The sensor.
    #[must_use]
    pub fn sensor(&self) -> &SensorModel {
        &self.sensor
    }

    /// The site.
    #[must_use]
    pub fn site(&self) -> &Site {
        &self.site
    }

    /// The schedule.
    #[must_use]
    pub fn schedule(&self) -> &Schedule {
        &self.schedule
    }

    /// The nominal inputs of every position (eq 3).
    #[must_use]
    pub fn nominal_inputs(&self) -> &[Inputs] {
        &self.nominal
    }

    /// Every output, in study order.
    #[must_use]
    pub fn outputs(&self) -> &[OutputCalibration] {
        &self.outputs
    }

    /// The condition number of every output's regression, study order.
    #[must_use]
    pub fn condition_numbers(&self) -> Vec<f64> {
        self.outputs
            .iter()
            .map(|o| o.regression.condition_number())
            .collect()
    }

    /// Calibrate output `k` from measured outputs $\mathbf b_1$ (one per position, in the
    /// output's unit), with the nominal inputs of the schedule.
    ///
    /// # Formula
    /// $\hat{\boldsymbol\beta}_1 = \arg\min \lVert \mathbf A\boldsymbol\beta - (\mathbf b_1 -
    /// \mathbf b_2)\rVert_2$, by QR.
    ///
    /// # Reference
    /// Eq 5-6.
    ///
    /// # Errors
    /// [`CalibError::Field`] ([`tt_core::FieldError::Length`]) for a wrong count; [`CalibError::Field`] (not finite) naming the
    /// output entry.
    pub fn calibrate(&self, k: usize, outputs: &[f64]) -> Result<CalibrationResult, CalibError> {
        let o = self
            .outputs
            .get(k)
            .ok_or(CalibError::Field(tt_core::FieldError::Length {
                field: "output index".into(),
                expected: self.outputs.len(),
                found: k,
            }))?;
        if outputs.len() != self.schedule.len() {
            return Err(CalibError::Field(tt_core::FieldError::Length {
                field: "outputs".into(),
                expected: self.schedule.len(),
                found: outputs.len(),
            }));
        }
        for (i, v) in outputs.iter().enumerate() {
            finite(format!("outputs[{i}]"), *v)?;
        }
        let y = DVector::from_column_slice(outputs) - &o.b2;
        Ok(CalibrationResult {
            output: o.output.name.clone(),
            names: o.regression.names().to_vec(),
            solution: o.regression.solve(&y)?,
        })
    }

    /// The end-to-end path: every output simulated at the actual orientations (eq 8-9,
    /// `delta_r[i]` the orientation error of position $i$) and calibrated at the intended ones
    /// (eq 6), as a calibrating engineer gets it.
    ///
    /// # Errors
    /// As [`Schedule::actual_inputs`] and [`Calibration::calibrate`].
    pub fn calibrate_simulated(
        &self,
        delta_r: &[Matrix3<f64>],
    ) -> Result<Vec<CalibrationResult>, CalibError> {
        let actual = self.schedule.actual_inputs(&self.site, delta_r)?;
        (0..self.outputs.len())
            .map(|k| {
                let b1 = simulate_outputs(&self.outputs[k].output, &actual);
                self.calibrate(k, b1.as_slice())
            })
            .collect()
    }
}
