//! The end-to-end error linearised in the turntable errors, $\Delta\hat{\boldsymbol\omega}
//! \approx \mathbf M\chi$, and the worst case of a tolerance box.

use crate::error::{E2eError, finite};
use crate::simulate::EndToEnd;
use calib_lsq::{ErrorForm, Estimate, OutputsAt, ReadingTerms, ReadingWork};
use gw_model::InputValues;
use nalgebra::{DMatrix, DVector};
use tt_kinematics::ScheduleErrorModel;

/// The Jacobian $\mathbf M$ of the error vectors with respect to $\chi$ at $\chi = 0$: row
/// $(k, i)$ for output $k$ at position $i$ (output-major), one column per angular error; in
/// output unit per radian.
#[derive(Debug, Clone, PartialEq)]
pub struct Linearization {
    m: DMatrix<f64>,
    n: usize,
    outputs: usize,
    /// Per output and error: the rounding level of that output's entries of $\mathbf M$
    /// (output unit per rad), see [`rounding_level`]; zero when unknown.
    noise: DMatrix<f64>,
    /// The errors' and the outputs' names; empty when not given
    /// ([`Linearization::with_names`]).
    names: Names,
}

/// The names a [`Linearization`] reports through alloc-opt's [`alloc_opt::LinearErrorModel`].
#[derive(Debug, Clone, PartialEq, Default)]
struct Names {
    errors: Vec<String>,
    outputs: Vec<String>,
}

/// Rounding of the calibration's residual, in units of $\varepsilon\,\kappa$ (dimensionless):
/// a residual $(\mathbf I - \mathbf A\mathbf A^+)\mathbf d$ is computed to about
/// $\varepsilon\,\kappa(\mathbf A)\,\lVert\mathbf d\rVert$; 64 covers the sums over positions and
/// coefficients with a wide margin (an error the calibration absorbs exactly leaves
/// $\sim 10^{-17}$ of its raw effect on the paper's schedule, against a threshold of
/// $\sim 2\cdot10^{-14}$).
pub(crate) const ROUNDING_ULPS: f64 = 64.0;

/// The rounding level of an output's column of $\mathbf M$: `ROUNDING_ULPS`
/// $\cdot\,\varepsilon \cdot \max(1, \kappa) \cdot \max_i \max(|d_{e,i}|, |d_{g,i}|)$, with
/// $\mathbf d_e, \mathbf d_g$ the raw first-order effects of the error on the outputs and
/// regressors at each position (before the calibration absorbs them) and $\kappa$ the
/// output's condition number. An entry below it is rounding, not an effect.
pub fn rounding_level(de: &[f64], dg: &[f64], condition: f64) -> f64 {
    let raw = de.iter().chain(dg).fold(0.0_f64, |m, v| m.max(v.abs()));
    ROUNDING_ULPS * f64::EPSILON * condition.max(1.0) * raw
}

impl Linearization {
    /// A linearisation from its matrix (rows output-major, `n` positions per output) and the
    /// rounding level of each output's column (outputs x errors, see [`rounding_level`]).
    #[doc(hidden)]
    pub fn from_parts(m: DMatrix<f64>, n: usize, outputs: usize, noise: DMatrix<f64>) -> Self {
        Self {
            m,
            n,
            outputs,
            noise,
            names: Names::default(),
        }
    }

    /// The same linearisation naming its errors (one per column) and its outputs, as
    /// alloc-opt's [`alloc_opt::LinearErrorModel`] reports them (in a certificate, an error's
    /// field); without names they are `chi{j}` and `output{k}`.
    /// [`EndToEnd::linearization`] names them after the analysis.
    ///
    /// # Errors
    /// [`E2eError::Field`] (wrong length) naming `error_names` or `output_names`.
    pub fn with_names(
        mut self,
        error_names: Vec<String>,
        output_names: Vec<String>,
    ) -> Result<Self, E2eError> {
        tt_core::length("error_names", self.m.ncols(), error_names.len())?;
        tt_core::length("output_names", self.outputs, output_names.len())?;
        self.names = Names {
            errors: error_names,
            outputs: output_names,
        };
        Ok(self)
    }

    /// The name of error `j` (column `j`): its given name, else `chi{j}`.
    #[must_use]
    pub fn error_name(&self, j: usize) -> String {
        self.names
            .errors
            .get(j)
            .cloned()
            .unwrap_or_else(|| format!("chi{j}"))
    }

    /// The name of output `k`: its given name, else `output{k}`.
    #[must_use]
    pub(crate) fn output_name(&self, k: usize) -> String {
        self.names
            .outputs
            .get(k)
            .cloned()
            .unwrap_or_else(|| format!("output{k}"))
    }

    /// The rounding level of every output's column (outputs x errors, output unit per rad):
    /// entries of $\mathbf M$ at or below it are rounding of a calibration that absorbs the
    /// error, not an effect (zero for the numerical Jacobian, whose level is not tracked).
    #[must_use]
    pub fn rounding(&self) -> &DMatrix<f64> {
        &self.noise
    }

    /// The matrix (rows output-major: output $k$, position $i$ at row $kn + i$).
    #[must_use]
    pub fn matrix(&self) -> &DMatrix<f64> {
        &self.m
    }

    /// Positions per output $n$.
    #[must_use]
    pub fn positions(&self) -> usize {
        self.n
    }

    /// Number of outputs.
    #[must_use]
    pub fn outputs(&self) -> usize {
        self.outputs
    }

    /// Row index of (output, position).
    #[must_use]
    pub(crate) fn row_index(&self, output: usize, position: usize) -> usize {
        output * self.n + position
    }

    /// One row $\mathbf M_r$ (output unit per rad).
    #[must_use]
    pub fn row(&self, output: usize, position: usize) -> Vec<f64> {
        self.m
            .row(self.row_index(output, position))
            .iter()
            .copied()
            .collect()
    }

    /// The linearised worst case of every row over the box $|\chi_j| \le \mathrm{UB}_j$:
    /// $\sum_j |M_{rj}|\,\mathrm{UB}_j$ (output unit), in row order. An infinite bound marks an
    /// error without a bound, one no output depends on ([`Linearization::unconstrained`]): it
    /// counts 0 (callers check that only those errors are unbounded).
    #[must_use]
    pub fn row_worst_cases(&self, ub_rad: &[f64]) -> DVector<f64> {
        DVector::from_iterator(
            self.m.nrows(),
            self.m.row_iter().map(|r| {
                r.iter()
                    .zip(ub_rad)
                    .map(|(m, u)| if u.is_finite() { m.abs() * u } else { 0.0 })
                    .sum::<f64>()
            }),
        )
    }

    /// Errors that no row depends on: all $|M_{rj}| \le 10^{-12}\max|M|$, or every output's
    /// entries at or below their rounding level ([`Linearization::rounding`]: the
    /// calibration absorbs the error's first-order effect). They do not affect any output and
    /// get no bound; when every error is such, no bound is needed at all.
    #[must_use]
    pub fn unconstrained(&self) -> Vec<usize> {
        let top = self.m.amax();
        (0..self.m.ncols())
            .filter(|&j| {
                self.m.column(j).amax() <= 1e-12 * top
                    || (0..self.outputs).all(|k| {
                        self.m.view((k * self.n, j), (self.n, 1)).amax() <= self.noise[(k, j)]
                    })
            })
            .collect()
    }
}

/// The worst case of one output over a tolerance box, with the data `X` its question adds:
/// [`BoxDetail`] for the box of the angular errors ([`EndToEnd::worst_case`], the default),
/// [`crate::angle::AngleDetail`] under the angle-dependent model
/// ([`crate::angle::AngleOutputWorstCase`]), [`crate::rate::ExtraDetail`] with the extra
/// errors of a schedule with rate steps ([`crate::ExtraOutputWorstCase`]).
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
#[non_exhaustive]
pub struct OutputWorstCase<X = BoxDetail> {
    /// The output's index.
    pub(crate) output: usize,
    /// $\max_r \sum_j |M_{rj}|\,\mathrm{UB}_j$ over this output's rows (output unit; with
    /// the extra errors' or the angle-dependent columns where `X` says so): the exact worst
    /// case of the linearised model (a maximum of absolute linear forms peaks at a vertex).
    pub(crate) linear_bound: f64,
    /// The position (index in the schedule; an entry with rate steps) of the worst row.
    pub(crate) position: usize,
    /// $\Delta\omega$ of this output on the exact chain at $\pm$ the worst vertex (the
    /// larger): a point of the box, so a lower bound on the exact worst case.
    pub(crate) exact_at_vertex: f64,
    /// The data the question adds.
    #[cfg_attr(feature = "serde", serde(flatten))]
    pub(crate) detail: X,
}

/// Read access to the fields (crate-private, so the type can grow without breaking callers).
impl<X> OutputWorstCase<X> {
    /// The output's index.
    #[must_use]
    pub fn output(&self) -> usize {
        self.output
    }

    /// $\max_r \sum_j |M_{rj}|\,\mathrm{UB}_j$ over this output's rows (output unit; with
    /// the extra errors' or the angle-dependent columns where `X` says so): the exact worst
    /// case of the linearised model (a maximum of absolute linear forms peaks at a vertex).
    #[must_use]
    pub fn linear_bound(&self) -> f64 {
        self.linear_bound
    }

    /// The position (index in the schedule; an entry with rate steps) of the worst row.
    #[must_use]
    pub fn position(&self) -> usize {
        self.position
    }

    /// $\Delta\omega$ of this output on the exact chain at $\pm$ the worst vertex (the
    /// larger): a point of the box, so a lower bound on the exact worst case.
    #[must_use]
    pub fn exact_at_vertex(&self) -> f64 {
        self.exact_at_vertex
    }
}

/// What the worst case over the box of the angular errors adds ([`OutputWorstCase`]).
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
#[non_exhaustive]
pub struct BoxDetail {
    /// The worst vertex $\chi_j = \operatorname{sign}(M_{rj})\,\mathrm{UB}_j$ (rad).
    pub(crate) worst_chi_rad: Vec<f64>,
    /// The derived bound $\tau$ on $|\Delta\hat\omega_{exact} - \mathbf M\chi|$ over the box
    /// (output unit; see [`EndToEnd::second_order_bound`]); `None` for readings without one.
    /// The exact worst case lies in `exact_at_vertex ..= linear_bound + tau`.
    pub(crate) second_order_bound: Option<f64>,
    /// Linearised worst case of every position (output unit), the data of the per-position
    /// figure.
    pub(crate) per_position: Vec<f64>,
    /// The computation's precision for this output ([`EndToEnd::precisions`], output unit):
    /// `linear_bound`, `exact_at_vertex` and `per_position` values at or below it are
    /// reported as 0 ([`crate::resolved`]).
    pub(crate) precision: f64,
}

/// Read access to the box's data.
impl OutputWorstCase {
    /// The worst vertex $\chi_j = \operatorname{sign}(M_{rj})\,\mathrm{UB}_j$ (rad).
    #[must_use]
    pub fn worst_chi_rad(&self) -> &[f64] {
        &self.detail.worst_chi_rad
    }

    /// The derived bound $\tau$ on $|\Delta\hat\omega_{exact} - \mathbf M\chi|$ over the box
    /// (output unit; see [`EndToEnd::second_order_bound`]); `None` for readings without one.
    /// The exact worst case lies in `exact_at_vertex ..= linear_bound + tau`.
    #[must_use]
    pub fn second_order_bound(&self) -> Option<f64> {
        self.detail.second_order_bound
    }

    /// Linearised worst case of every position (output unit), the data of the per-position
    /// figure.
    #[must_use]
    pub fn per_position(&self) -> &[f64] {
        &self.detail.per_position
    }

    /// The computation's precision for this output ([`EndToEnd::precisions`], output unit):
    /// `linear_bound`, `exact_at_vertex` and `per_position` values at or below it are
    /// reported as 0 ([`crate::resolved`]).
    #[must_use]
    pub fn precision(&self) -> f64 {
        self.detail.precision
    }

    /// `linear_bound + tau`: a rigorous bound on the exact worst case, when derived.
    #[must_use]
    pub fn certified_bound(&self) -> Option<f64> {
        self.detail
            .second_order_bound
            .map(|t| self.linear_bound + t)
    }
}

/// The worst case of every output over a tolerance box.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
#[non_exhaustive]
pub struct WorstCase {
    /// The upper bounds of the box (rad, order of $\chi$).
    pub(crate) upper_bounds_rad: Vec<f64>,
    /// One per output.
    pub(crate) outputs: Vec<OutputWorstCase>,
}

/// Read access to the fields (crate-private, so the type can grow without breaking callers).
impl WorstCase {
    /// The upper bounds of the box (rad, order of $\chi$).
    #[must_use]
    pub fn upper_bounds_rad(&self) -> &[f64] {
        &self.upper_bounds_rad
    }

    /// One per output.
    #[must_use]
    pub fn outputs(&self) -> &[OutputWorstCase] {
        &self.outputs
    }
}

impl WorstCase {
    /// Confirmed worst cases on the exact chain, output unit, per output.
    #[must_use]
    pub fn exact(&self) -> Vec<f64> {
        self.outputs.iter().map(|o| o.exact_at_vertex).collect()
    }

    /// Linearised worst cases, output unit, per output.
    #[must_use]
    pub fn linear(&self) -> Vec<f64> {
        self.outputs.iter().map(|o| o.linear_bound).collect()
    }

    /// Whether the box's worst turntable meets every accuracy (`accuracies` by output index,
    /// output unit): on the exact chain at the worst vertex, or only to first order, or not
    /// at all. Every output that prints a box's worst case says it in the words of
    /// [`BoxMeets`]'s `Display`.
    #[must_use]
    pub fn meets(&self, accuracies: &[f64]) -> BoxMeets {
        let acc = |o: &OutputWorstCase| accuracies.get(o.output).copied().unwrap_or(f64::NAN);
        if self.outputs.iter().all(|o| o.exact_at_vertex <= acc(o)) {
            return BoxMeets::Yes;
        }
        let excess = self
            .outputs
            .iter()
            .map(|o| o.exact_at_vertex / acc(o) - 1.0)
            .fold(f64::NEG_INFINITY, f64::max);
        if self
            .outputs
            .iter()
            .all(|o| o.linear_bound <= acc(o) * (1.0 + LINEAR_MEETS_REL))
        {
            BoxMeets::FirstOrderOnly { excess }
        } else {
            BoxMeets::No { excess }
        }
    }
}

/// A linearised worst case counts as meeting its accuracy within this relative rounding
/// (dimensionless): the direct allocation puts the worst row's load exactly at 1, which the
/// solver reaches to about $10^{-13}$ and the sum of a row's terms rounds at $10^{-16}$.
pub(crate) const LINEAR_MEETS_REL: f64 = 1e-9;

/// Whether the worst turntable of a tolerance box meets every output's accuracy
/// ([`WorstCase::meets`]). `Display` gives the words every output uses: `yes`,
/// `to first order; no on the exact chain (+1.7%)`, `no (+1.7%)`, the percentage being the
/// largest excess of the exact chain at the worst vertex over an accuracy.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize),
    serde(rename_all = "snake_case")
)]
pub enum BoxMeets {
    /// The worst vertex meets every accuracy on the exact chain.
    Yes,
    /// The linearised worst case meets every accuracy, the exact chain at the worst vertex
    /// misses one by `excess` (relative, > 0).
    FirstOrderOnly {
        /// Largest relative excess over an accuracy.
        excess: f64,
    },
    /// The linearised worst case misses an accuracy; the exact chain at the worst vertex
    /// misses by `excess` (relative, > 0).
    No {
        /// Largest relative excess over an accuracy.
        excess: f64,
    },
}

impl BoxMeets {
    /// Whether every accuracy is met on the exact chain at the worst vertex.
    #[must_use]
    pub fn holds(self) -> bool {
        self == BoxMeets::Yes
    }

    /// `yes`, `first-order-only` or `no`: a key for JSON.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            BoxMeets::Yes => "yes",
            BoxMeets::FirstOrderOnly { .. } => "first-order-only",
            BoxMeets::No { .. } => "no",
        }
    }

    /// The largest relative excess over an accuracy; `None` when every accuracy is met.
    #[must_use]
    pub fn excess(self) -> Option<f64> {
        match self {
            BoxMeets::Yes => None,
            BoxMeets::FirstOrderOnly { excess } | BoxMeets::No { excess } => Some(excess),
        }
    }
}

/// `100 x` with two significant digits (at least one decimal): `1.7`, `0.0042`, `25.0`.
fn percent_2sig(x: f64) -> String {
    let p = 100.0 * x;
    let decimals = if p.is_finite() && p > 0.0 {
        (1 - p.log10().floor() as i32).clamp(1, 12) as usize
    } else {
        1
    };
    format!("{p:.decimals$}")
}

impl std::fmt::Display for BoxMeets {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match *self {
            BoxMeets::Yes => f.write_str("yes"),
            BoxMeets::FirstOrderOnly { excess } => write!(
                f,
                "to first order; no on the exact chain (+{}%)",
                percent_2sig(excess)
            ),
            BoxMeets::No { excess } => write!(f, "no (+{}%)", percent_2sig(excess)),
        }
    }
}

/// First variations of the building blocks of eq 13 for one output and one error direction:
/// the same dispatch ([`calib_lsq::Reading::error_vector`]) turns them into a column of
/// $\mathbf M$. Used by [`EndToEnd::linearization`] and by the schedule designer
/// (the `schedule-design` crate) with the regression of a candidate schedule.
pub struct DerivativeTerms<'a> {
    /// The nominal regression matrix $\mathbf A$ ($n \times k$).
    pub a: &'a DMatrix<f64>,
    /// Its pseudo-inverse $\mathbf A^+$ ($k \times n$).
    pub pinv: &'a DMatrix<f64>,
    /// $d\mathbf e$: first variation of the known part (e.g. the rate input).
    pub de: Vec<f64>,
    /// $d\mathbf g = (d\mathbf A')\boldsymbol\beta$: first variation of the estimated part.
    pub dg: Vec<f64>,
}

impl ReadingTerms for DerivativeTerms<'_> {
    fn positions(&self) -> usize {
        self.de.len()
    }
    fn coefficients(&self) -> usize {
        self.pinv.nrows()
    }
    fn outputs(&self, at: OutputsAt, out: &mut [f64]) {
        for (i, o) in out.iter_mut().enumerate() {
            *o = match at {
                OutputsAt::Actual => self.dg[i] + self.de[i],
                OutputsAt::Intended => 0.0,
            };
        }
    }
    fn known(&self, actual: bool, out: &mut [f64]) {
        for (i, o) in out.iter_mut().enumerate() {
            *o = if actual { self.de[i] } else { 0.0 };
        }
    }
    fn estimate(&self, which: Estimate, db1: &[f64], out: &mut [f64]) {
        // d beta1 = A+ db1; d beta2 = A+ (db1 - de - dg) (A' = A + dA, beta2 = beta + dbeta)
        let y: Vec<f64> = match which {
            Estimate::Beta1 => db1.to_vec(),
            Estimate::Beta2 => (0..db1.len())
                .map(|i| db1[i] - self.de[i] - self.dg[i])
                .collect(),
        };
        for (j, o) in out.iter_mut().enumerate() {
            *o = self.pinv.row(j).iter().zip(&y).map(|(p, v)| p * v).sum();
        }
    }
    fn predict(&self, actual: bool, dbeta: &[f64], out: &mut [f64]) {
        // d(A beta) = A dbeta; d(A' beta) = dA beta + A dbeta = dg + A dbeta
        for (i, o) in out.iter_mut().enumerate() {
            let v: f64 = self.a.row(i).iter().zip(dbeta).map(|(r, b)| r * b).sum();
            *o = if actual { v + self.dg[i] } else { v };
        }
    }
}

/// $\sum_t \beta_t \nabla r_t(\mathbf u)\cdot d\mathbf u$ over the known (`known = true`) or the
/// estimated terms of an output.
pub fn directional(o: &gw_model::Output, known: bool, u: &InputValues, du: &[f64; 6]) -> f64 {
    o.terms
        .iter()
        .filter(|t| t.known == known)
        .map(|t| {
            let g = t.regressor.gradient(u);
            t.value * g.iter().zip(du).map(|(a, b)| a * b).sum::<f64>()
        })
        .sum()
}

impl<S: ScheduleErrorModel> EndToEnd<S> {
    /// Check upper bounds: one per angular error, non-negative, finite except for the errors
    /// no output depends on ([`Linearization::unconstrained`]), which may be `+inf`.
    pub(crate) fn check_bounds(
        &self,
        linear: &Linearization,
        ub_rad: &[f64],
    ) -> Result<(), E2eError> {
        tt_core::length("upper bounds", self.n_errors(), ub_rad.len())
            .map_err(|e| E2eError::Kinematics(e.into()))?;
        let free = linear.unconstrained();
        for (j, (name, u)) in self.error_names().iter().zip(ub_rad).enumerate() {
            let field = format!("upper_bounds.{name}");
            if u.is_nan() || (u.is_infinite() && !free.contains(&j)) {
                return Err(tt_core::FieldError::NonFinite { field, value: *u }.into());
            }
            if *u < 0.0 {
                return Err(tt_core::FieldError::NotPositive { field, value: *u }.into());
            }
        }
        Ok(())
    }

    /// The Jacobian $\mathbf M$ analytically: the first-order model of the turntable per
    /// position chained with the derivative of the reading's error vector with respect to
    /// the orientation error.
    ///
    /// # Formula
    /// At position $i$ the rotation vector of $\Delta\mathbf R_i$ is, to first order,
    /// $\boldsymbol\delta_i = \sum_j \chi_j\mathbf v_{ij}$ ([`ScheduleErrorModel::rotation_vectors`]),
    /// and $\mathbf u' = \Delta\mathbf R^T\mathbf u \approx \mathbf u + \mathbf u \times
    /// \boldsymbol\delta$ for $\mathbf a$ and $\boldsymbol\omega$ (eq 8). With the first
    /// variations $d\mathbf e_i = \sum_{\text{known}}\beta_t\nabla r_t\cdot d\mathbf u_i$ and
    /// $d\mathbf g_i = \sum_{\text{estimated}}\beta_t\nabla r_t\cdot d\mathbf u_i$, the blocks
    /// of eq 13 vary as $d\mathbf b_1 = d\mathbf g + d\mathbf e$ (outputs at the actual
    /// orientation) or $0$, $d\mathbf b_2' = d\mathbf e$, $d\hat{\boldsymbol\beta}_1 =
    /// \mathbf A^+ d\mathbf b_1$, $d\hat{\boldsymbol\beta}_2 = \mathbf A^+(d\mathbf b_1 - d\mathbf e -
    /// d\mathbf g)$, $d(\mathbf A'\hat{\boldsymbol\beta}) = d\mathbf g + \mathbf A\,d\hat{\boldsymbol\beta}$,
    /// and [`calib_lsq::Reading::error_vector`] (the one evaluation of the readings) combines
    /// them into column $j$.
    ///
    /// # Reference
    /// Eq 8-13, eq 26 generalised.
    #[must_use]
    pub fn linearization(&self) -> Linearization {
        let mut linear = self.linearization_with(self.n_errors(), self.angular_input_variation());
        linear.names = Names {
            errors: self.error_names(),
            outputs: self.output_names(),
        };
        linear
    }

    /// The first variation of the actual inputs at position `i` for a unit change of angular
    /// error `j` at the nominal inputs `u` (g and deg/h per rad): $\mathbf u \times
    /// \mathbf v_{ij}$ at a static position (eq 8), central differences of the compiled rate
    /// step at a rate step (its inputs are not a rotation of the nominal ones).
    fn angular_input_variation(&self) -> impl Fn(usize, usize, &InputValues) -> [f64; 6] + '_ {
        let vectors = self.rotation_vectors();
        let rate_du: Vec<Vec<Option<[f64; 6]>>> = (0..self.len())
            .map(|i| {
                (0..self.n_errors())
                    .map(|j| self.rate_input_derivative(i, j, false))
                    .collect()
            })
            .collect();
        move |i, j, u| {
            rate_du[i][j].unwrap_or_else(|| {
                let delta = vectors[i][j];
                let da = u.specific_force_g().cross(&delta);
                let dw = u.rate_deg_per_h().cross(&delta);
                [da.x, da.y, da.z, dw.x, dw.y, dw.z]
            })
        }
    }

    /// The first variations $d\mathbf e$ (known part) and $d\mathbf g$ (estimated part) of
    /// output `cal`'s outputs at every position for error `j`.
    fn output_variations(
        cal: &calib_lsq::OutputCalibration,
        j: usize,
        du: &impl Fn(usize, usize, &InputValues) -> [f64; 6],
    ) -> (Vec<f64>, Vec<f64>) {
        let o = cal.output();
        cal.nominal_values()
            .iter()
            .enumerate()
            .map(|(i, u)| {
                let du = du(i, j, u);
                (directional(o, true, u, &du), directional(o, false, u, &du))
            })
            .unzip()
    }

    /// The Jacobian of the user's estimated coefficients with respect to $\chi$ at
    /// $\chi = 0$, one matrix per output (its estimated coefficients x the angular errors,
    /// coefficient unit per rad): outputs at the actual orientation, calibrated with the
    /// intended inputs (eq 6), $d\hat{oldsymboleta}_1 = \mathbf A^+(d\mathbf g +
    /// d\mathbf e)$, the first-order model of [`EndToEnd::coefficient_errors`] whatever the
    /// study's reading (the coefficients the calibrating engineer gets).
    #[must_use]
    pub fn coefficient_linearization(&self) -> Vec<DMatrix<f64>> {
        self.coefficient_linearization_with(self.n_errors(), self.angular_input_variation())
    }

    /// [`EndToEnd::coefficient_linearization`] with respect to `errors` errors whose first
    /// variation of the inputs at position `i` for error `j` is `du(i, j, nominal inputs)`.
    pub(crate) fn coefficient_linearization_with(
        &self,
        errors: usize,
        du: impl Fn(usize, usize, &InputValues) -> [f64; 6],
    ) -> Vec<DMatrix<f64>> {
        self.calibration()
            .outputs()
            .iter()
            .map(|cal| {
                let pinv = cal.regression().pinv();
                let mut jac = DMatrix::zeros(pinv.nrows(), errors);
                for j in 0..errors {
                    let (de, dg) = Self::output_variations(cal, j, &du);
                    let db1: Vec<f64> = de.iter().zip(&dg).map(|(e, g)| e + g).collect();
                    for t in 0..pinv.nrows() {
                        jac[(t, j)] = pinv.row(t).iter().zip(&db1).map(|(p, v)| p * v).sum();
                    }
                }
                jac
            })
            .collect()
    }

    /// The Jacobian of the error vectors with respect to `errors` errors whose first
    /// variation of the inputs at position `i` for error `j` is `du(i, j, nominal inputs)`
    /// (g, deg/h per unit of the error), through the reading (see
    /// [`EndToEnd::linearization`]).
    pub(crate) fn linearization_with(
        &self,
        errors: usize,
        du: impl Fn(usize, usize, &InputValues) -> [f64; 6],
    ) -> Linearization {
        let n = self.len();
        let outputs = self.n_outputs();
        let mut m = DMatrix::zeros(outputs * n, errors);
        let mut noise = DMatrix::zeros(outputs, errors);
        let mut work = ReadingWork::default();
        let mut col = vec![0.0; n];
        for (k, cal) in self.calibration().outputs().iter().enumerate() {
            for j in 0..errors {
                let (de, dg) = Self::output_variations(cal, j, &du);
                noise[(k, j)] = rounding_level(&de, &dg, cal.regression().condition_number());
                let terms = DerivativeTerms {
                    a: cal.regression().matrix(),
                    pinv: cal.regression().pinv(),
                    de,
                    dg,
                };
                self.reading().error_vector(&terms, &mut work, &mut col);
                for (i, v) in col.iter().enumerate() {
                    m[(k * n + i, j)] = *v;
                }
            }
        }
        Linearization {
            m,
            n,
            outputs,
            noise,
            names: Names::default(),
        }
    }

    /// The Jacobian $\mathbf M$ by central differences of the reference path
    /// ([`EndToEnd::run`], calib-lsq's analysis with the plain exact chain):
    /// $\mathbf M_{:j} \approx (\Delta\hat{\boldsymbol\omega}(h\mathbf e_j) -
    /// \Delta\hat{\boldsymbol\omega}(-h\mathbf e_j))/(2h)$, error $O(h^2)$.
    ///
    /// # Errors
    /// [`E2eError::Field`] (out of range) naming `step_rad` unless $0 < h \le 10^{-2}$;
    /// [`E2eError::Calib`] as [`EndToEnd::run`].
    pub fn linearization_numerical(&self, step_rad: f64) -> Result<Linearization, E2eError> {
        if !(step_rad > 0.0 && step_rad <= 1e-2) {
            return Err(E2eError::Field(tt_core::FieldError::OutOfRange {
                field: "step_rad".into(),
                value: step_rad,
                range: "(0, 1e-2] rad".into(),
            }));
        }
        let n = self.len();
        let outputs = self.n_outputs();
        let mut m = DMatrix::zeros(outputs * n, self.n_errors());
        for j in 0..self.n_errors() {
            let mut chi = vec![0.0; self.n_errors()];
            chi[j] = step_rad;
            let plus = self.run(&chi)?;
            chi[j] = -step_rad;
            let minus = self.run(&chi)?;
            for k in 0..outputs {
                let col = (plus.analyses[k].error_vector() - minus.analyses[k].error_vector())
                    / (2.0 * step_rad);
                m.view_mut((k * n, j), (n, 1)).copy_from(&col);
            }
        }
        Ok(Linearization {
            m,
            n,
            outputs,
            noise: DMatrix::zeros(outputs, self.n_errors()),
            names: Names::default(),
        })
    }

    /// A derived bound $\tau_k$ (output unit) on $\lVert\Delta\hat{\boldsymbol\omega}_k(\chi) -
    /// \mathbf M_k\chi\rVert_\infty$ for every $\chi$ whose $\Delta\mathbf R_i$ are products of
    /// rotations with angles summing to at most $s$ (for a turntable: $\lVert\chi\rVert_1 \le s$;
    /// for another model: its [`ScheduleErrorModel::angle_sum_bound`]), or `None`
    /// for a reading it is not derived for (those with $\hat{\boldsymbol\beta}_2$,
    /// $\mathbf A\Delta\boldsymbol\beta$, or actual regressors with outputs at the actual
    /// orientation) and for a schedule with rate steps (see
    /// [`crate::RateQuestions::second_order_bound_with_extra`]).
    ///
    /// # Formula
    /// $\Delta\mathbf R$ is a product of rotations whose angles sum to at most $s$, so
    /// $\lVert\Delta\mathbf R^T - \mathbf I - [\boldsymbol\delta]_\times^T\rVert_2 \le e^s - 1 - s
    /// \le \rho = \tfrac12 s^2 e^s$ and the input moves by $|d\mathbf u| \le s|\mathbf u|$, with
    /// $|\mathbf a| = 1$ g and $|\boldsymbol\omega| = \omega_e$. A term $\beta_t r_t$ then leaves
    /// a remainder of at most $|\beta_t| c_t$, $c_t$ = the second-order remainder of the
    /// monomial over that box ([`gw_model::Regressor::remainder_bound`]) plus its gradient
    /// bound times $\rho|\mathbf u|$ (for eq 1: 0 for a constant, $\rho$ for $a_j$,
    /// $2\rho + s^2$ for a quadratic, $\rho\,\omega_e$ for the rate). Summing over the known and
    /// the estimated terms gives $r_e$ and $r_g$, and the readings map them as
    /// - intended outputs: printed $-\mathbf e$: $\tau = r_e$; nominal rate: $0$;
    ///   actual regressors $-\mathbf g - \mathbf e$: $r_g + r_e$; actual regressors, nominal
    ///   rate $-\mathbf g$: $r_g$;
    /// - actual outputs, $\hat{\boldsymbol\beta}_1$: printed
    ///   $(\mathbf I-\mathbf P)\mathbf g - \mathbf P\mathbf e$:
    ///   $\tau = \lVert\mathbf I-\mathbf P\rVert_\infty r_g + \lVert\mathbf P\rVert_\infty r_e$;
    ///   nominal rate $(\mathbf I-\mathbf P)(\mathbf g+\mathbf e)$.
    ///
    /// # Errors
    /// [`E2eError::Field`] (not finite, not positive) naming `l1_norm_rad` if $s$ is not
    /// finite and non-negative; [`E2eError::Field`] (out of range) for a missing output.
    pub fn second_order_bound(
        &self,
        output: usize,
        l1_norm_rad: f64,
    ) -> Result<Option<f64>, E2eError> {
        let (s, cal) = self.bound_arguments(output, l1_norm_rad)?;
        let reading = self.reading();
        if reading.estimate != Estimate::Beta1
            || reading.form == ErrorForm::DeltaBeta
            || self.has_rate_steps()
        {
            // (a rate step's inputs are not a rotation of the nominal ones: its bound needs the
            // extra errors' box, crate::RateQuestions::second_order_bound_with_extra)
            return Ok(None);
        }
        let rho = 0.5 * s * s * s.exp();
        let we = tt_core::units::rad_per_s_to_deg_per_h(
            self.calibration().site().earth_rate_rad_per_s(),
        );
        let m = [1.0, 1.0, 1.0, we, we, we];
        let d = m.map(|v| s * v);
        // the gradient's part: rho |u| at each input (|u_j| <= M_j)
        let rho_u = m.map(|v| rho * v);
        let remainder = |known: bool| terms_remainder(cal.output(), known, &m, &d, &rho_u);
        let (r_e, r_g) = (remainder(true), remainder(false));
        // the infinity norms of P = A A^+ and I - P, row by row (never the n x n projector),
        // once per regression
        let norms = || cal.regression().projector_norms();
        Ok(match (reading.outputs, reading.form) {
            (OutputsAt::Intended, ErrorForm::Printed) => Some(r_e),
            (OutputsAt::Intended, ErrorForm::NominalRate) => Some(0.0),
            (OutputsAt::Intended, ErrorForm::ActualRegressors) => Some(r_g + r_e),
            (OutputsAt::Intended, ErrorForm::ActualRegressorsNominalRate) => Some(r_g),
            (OutputsAt::Actual, ErrorForm::Printed) => {
                let (p, ip) = norms();
                Some(ip * r_g + p * r_e)
            }
            (OutputsAt::Actual, ErrorForm::NominalRate) => Some(norms().1 * (r_g + r_e)),
            _ => None,
        })
    }

    /// The worst case over the box $|\chi_j| \le \mathrm{UB}_j$ (the lower bounds do not
    /// matter: the maximum is at $|\chi_j| = \mathrm{UB}_j$), per output: exact for the
    /// linearised model, confirmed on the exact chain at the worst vertex, with the
    /// second-order bound. Values at or below the output's precision
    /// ([`EndToEnd::precisions`]) are reported as 0.
    ///
    /// # Errors
    /// [`E2eError::Field`] (not finite, not positive) naming the error of a bad bound; as
    /// [`EndToEnd::delta_omega`].
    pub fn worst_case(
        &self,
        linear: &Linearization,
        ub_rad: &[f64],
    ) -> Result<WorstCase, E2eError> {
        self.check_bounds(linear, ub_rad)?;
        let rows = linear.row_worst_cases(ub_rad);
        let n = self.len();
        let s = self.angle_sum(ub_rad)?;
        let mut work = self.work();
        let mut outputs = Vec::with_capacity(self.n_outputs());
        for k in 0..self.n_outputs() {
            let precision = self.precisions()[k];
            let per: Vec<f64> = rows.rows(k * n, n).iter().copied().collect();
            let (position, bound) =
                per.iter()
                    .copied()
                    .enumerate()
                    .fold(
                        (0, f64::NEG_INFINITY),
                        |b, (i, v)| if v > b.1 { (i, v) } else { b },
                    );
            let row = linear.row(k, position);
            let chi: Vec<f64> = row
                .iter()
                .zip(ub_rad)
                .map(|(m, u)| match (u.is_finite(), *m < 0.0) {
                    (false, _) => 0.0,
                    (true, true) => -u,
                    (true, false) => *u,
                })
                .collect();
            self.delta_omega_into(&chi, &mut work)?;
            let plus = work.delta_omega[k];
            let neg: Vec<f64> = chi.iter().map(|v| -v).collect();
            self.delta_omega_into(&neg, &mut work)?;
            let minus = work.delta_omega[k];
            outputs.push(OutputWorstCase {
                output: k,
                linear_bound: crate::resolved(bound, precision),
                position,
                exact_at_vertex: crate::resolved(plus.max(minus), precision),
                detail: BoxDetail {
                    worst_chi_rad: if plus >= minus { chi } else { neg },
                    second_order_bound: match s {
                        Some(s) => self.second_order_bound(k, s)?,
                        None => None,
                    },
                    per_position: per.iter().map(|v| crate::resolved(*v, precision)).collect(),
                    precision,
                },
            });
        }
        Ok(WorstCase {
            upper_bounds_rad: ub_rad.to_vec(),
            outputs,
        })
    }
}

impl<S: ScheduleErrorModel> EndToEnd<S> {
    /// The model's angle-sum bound ([`ScheduleErrorModel::angle_sum_bound`]) of the box
    /// `ub_rad` with every unbounded error (`+inf`) held at 0, as the worst-case vertex holds
    /// it: the model's hook never sees an infinite bound.
    ///
    /// # Errors
    /// [`E2eError::Field`] naming `angle_sum_bound` (the model's hook) when the model answers a
    /// non-finite or negative sum.
    pub(crate) fn angle_sum(&self, ub_rad: &[f64]) -> Result<Option<f64>, E2eError> {
        let held: Vec<f64> = ub_rad
            .iter()
            .map(|u| if u.is_finite() { *u } else { 0.0 })
            .collect();
        match self.model().angle_sum_bound(&held) {
            Some(s) if !(s.is_finite() && s >= 0.0) => Err(tt_core::FieldError::OutOfRange {
                field: "angle_sum_bound".into(),
                value: s,
                range: "finite and non-negative (the table model's angle-sum bound)".into(),
            }
            .into()),
            s => Ok(s),
        }
    }

    /// The arguments of a second-order bound, checked: the angle sum $s$ (finite,
    /// non-negative, named `l1_norm_rad`) and output `output`'s calibration.
    pub(crate) fn bound_arguments(
        &self,
        output: usize,
        l1_norm_rad: f64,
    ) -> Result<(f64, &calib_lsq::OutputCalibration), E2eError> {
        let s = finite("l1_norm_rad", l1_norm_rad)?;
        if s < 0.0 {
            return Err(tt_core::FieldError::NotPositive {
                field: "l1_norm_rad".into(),
                value: s,
            }
            .into());
        }
        let cal = self
            .calibration()
            .outputs()
            .get(output)
            .ok_or(E2eError::Field(tt_core::FieldError::OutOfRange {
                field: "output".into(),
                value: output as f64,
                range: "an output of the sensor".into(),
            }))?;
        Ok((s, cal))
    }
}

/// The second-order remainder of one output's terms (known or estimated) at one entry:
/// $\sum_t |\beta_t|\big(\mathrm{rem}_t(\mathbf m, \mathbf d) + \sum_j |\partial_j r_t|(\mathbf m)
/// \,\rho_j\big)$ (the static bound [`crate::EndToEnd::second_order_bound`] and, at rate steps,
/// [`crate::RateQuestions::second_order_bound_with_extra`]).
pub(crate) fn terms_remainder(
    output: &gw_model::Output,
    known: bool,
    m: &[f64; 6],
    d: &[f64; 6],
    rho: &[f64; 6],
) -> f64 {
    output
        .terms
        .iter()
        .filter(|t| t.known == known)
        .map(|t| {
            let r = &t.regressor;
            let grad: f64 = gw_model::Input::ALL
                .iter()
                .enumerate()
                .map(|(j, &inp)| {
                    let p = r.power(inp);
                    if p == 0 {
                        return 0.0;
                    }
                    let mono: f64 = gw_model::Input::ALL
                        .iter()
                        .enumerate()
                        .map(|(q, &iq)| {
                            let e = if q == j { p - 1 } else { r.power(iq) };
                            m[q].powi(i32::from(e))
                        })
                        .product();
                    f64::from(p) * mono * rho[j]
                })
                .sum();
            t.value.abs() * (r.remainder_bound(m, d) + grad)
        })
        .sum()
}

#[cfg(test)]
mod box_meets_tests {
    use super::{BoxMeets, OutputWorstCase, WorstCase};

    /// Issue 19 §5: one classification and one wording of "does the box's worst turntable
    /// meet every accuracy" for every output (`end-to-end`'s text and JSON, the report): `yes`,
    /// `to first order; no on the exact chain (+x%)`, `no (+x%)`, with the largest excess.
    #[test]
    fn box_meets_has_one_classification_and_one_wording() {
        let w = |output: usize, linear: f64, exact: f64| OutputWorstCase {
            output,
            linear_bound: linear,
            position: 0,
            exact_at_vertex: exact,
            detail: super::BoxDetail {
                worst_chi_rad: vec![],
                second_order_bound: None,
                per_position: vec![],
                precision: 1e-12,
            },
        };
        let wc = |outputs| WorstCase {
            upper_bounds_rad: vec![],
            outputs,
        };
        let acc = [0.5, 0.1];
        let yes = wc(vec![w(0, 0.49, 0.5), w(1, 0.05, 0.05)]).meets(&acc);
        assert_eq!(yes, BoxMeets::Yes);
        assert!(yes.holds() && yes.excess().is_none());
        assert_eq!(yes.to_string(), "yes");
        // the IMU case: gx 0.508 against 0.5, linearised at the accuracy
        let first = wc(vec![w(0, 0.5, 0.5085), w(1, 0.05, 0.05)]).meets(&acc);
        assert!(matches!(first, BoxMeets::FirstOrderOnly { .. }) && !first.holds());
        assert_eq!(
            first.to_string(),
            "to first order; no on the exact chain (+1.7%)"
        );
        let no = wc(vec![w(0, 0.4, 0.4), w(1, 0.2, 0.2)]).meets(&acc);
        assert_eq!(no.to_string(), "no (+100.0%)");
        assert_eq!(no.name(), "no");
        let tiny = wc(vec![w(0, 0.5, 0.500_021), w(1, 0.0, 0.0)]).meets(&acc);
        assert_eq!(
            tiny.to_string(),
            "to first order; no on the exact chain (+0.0042%)"
        );
    }
}
