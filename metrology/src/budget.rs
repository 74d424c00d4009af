//! The GUM uncertainty budget of one or several output quantities that depend linearly (to
//! first order) on the input quantities (JCGM 100 5.1, 5.2, G.4, G.6).
//!
//! With the input components $x_1, \dots, x_n$ (a disc counts two), their standard
//! uncertainties $u_i$, correlation matrix $\mathbf R$ (identity unless given) and
//! $\mathbf V = \mathbf D \mathbf R \mathbf D$, $\mathbf D = \operatorname{diag}(u_i)$, and the
//! sensitivity coefficients $c_{ji} = \partial y_j / \partial x_i$ of the outputs $y_j$:
//!
//! - contribution $u_{ji}(y) = |c_{ji}| u_i$ (JCGM 100 5.1.3);
//! - combined standard uncertainty $u_c(y_j) = \sqrt{\mathbf c_j^{\mathsf T} \mathbf V
//!   \mathbf c_j}$ (5.2.2), and the covariance of the outputs
//!   $\mathbf U_y = \mathbf C \mathbf V \mathbf C^{\mathsf T}$ (JCGM 102 6.2.1.3);
//! - effective degrees of freedom (Welch-Satterthwaite, G.4.1)
//!   $$\nu_{\mathrm{eff}} = \frac{u_c^4(y)}{\sum_i u_i^4(y)/\nu_i},$$
//!   infinite when every $\nu_i$ is; with a correlation matrix the same formula is used over
//!   the contributions (the GUM gives none for correlated inputs; give the inputs as a linear
//!   map of independent sources, [`Budget::evaluate_mapped`], to have it exact);
//! - coverage factor $k_p = t_{(1+p)/2}(\nu)$, Student's $t$ quantile with $\nu =
//!   \lfloor\nu_{\mathrm{eff}}\rfloor$ (G.4.1 note 1; [`BudgetSettings::truncate_dof`]) at the
//!   coverage probability $p$ (default 0.95), and the expanded uncertainty
//!   $U_p = k_p u_c(y)$ (G.6.4).
//!
//! Correlations carried exactly: when the inputs $\mathbf x = \mathbf A \mathbf s$ are a linear
//! map of independent sources $\mathbf s$ (table errors and noise through a least squares, a
//! shared reference), the budget over the sources with sensitivities $\mathbf C \mathbf A$
//! ([`Budget::evaluate_mapped`]) carries every correlation of $\mathbf x$ without a
//! correlation matrix.
//!
//! # Reference
//! JCGM 100:2008, *Evaluation of measurement data - Guide to the expression of uncertainty in
//! measurement* (GUM), 5.1-5.2, G.4, G.6, example H.1; JCGM 102:2011 6.2 (several outputs).

use crate::error::{MetrologyError, check_matrix, probability};
use crate::input::Input;
use crate::special::student_t_quantile;
use nalgebra::DMatrix;
use std::collections::HashSet;

/// The settings of a budget.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct BudgetSettings {
    /// The coverage probability $p$ of the expanded uncertainty, in (0, 1). Default 0.95.
    pub coverage: f64,
    /// Truncate $\nu_{\mathrm{eff}}$ to the next lower integer before the $t$ quantile (JCGM
    /// 100 G.4.1 note 1). Default true; false takes the $t$ quantile at the real
    /// $\nu_{\mathrm{eff}}$.
    pub truncate_dof: bool,
}

impl Default for BudgetSettings {
    fn default() -> Self {
        BudgetSettings {
            coverage: 0.95,
            truncate_dof: true,
        }
    }
}

/// The input side of a budget: the input quantities and their correlation, checked once.
#[derive(Debug, Clone, PartialEq)]
pub struct Budget {
    inputs: Vec<Input>,
    correlation: Option<DMatrix<f64>>,
    settings: BudgetSettings,
    /// Standard uncertainty per component.
    u: Vec<f64>,
    /// Degrees of freedom per component.
    dof: Vec<f64>,
}

/// The coverage factor $t_{(1+p)/2}(\nu)$ for degrees of freedom `dof` (infinite: the normal
/// quantile) at coverage probability `coverage`, $0 < p < 1$.
///
/// ```
/// use approx::assert_relative_eq;
/// // JCGM 100 table G.2: t_95(16) = 2.12, t_99(16) = 2.92
/// assert_relative_eq!(metrology::coverage_factor(16.0, 0.95)?, 2.12, epsilon = 0.005);
/// assert_relative_eq!(metrology::coverage_factor(16.0, 0.99)?, 2.92, epsilon = 0.005);
/// assert_relative_eq!(metrology::coverage_factor(f64::INFINITY, 0.95)?, 1.959_964, epsilon = 5e-7);
/// # Ok::<(), metrology::MetrologyError>(())
/// ```
///
/// # Errors
/// `coverage` outside (0, 1); `dof` NaN or not positive.
pub fn coverage_factor(dof: f64, coverage: f64) -> Result<f64, MetrologyError> {
    probability("coverage", coverage)?;
    if !(dof.is_infinite() && dof > 0.0) {
        tt_core::positive("dof", dof)?;
    }
    Ok(student_t_quantile(0.5 * (1.0 + coverage), dof))
}

impl Budget {
    /// A budget over `inputs` (at least one, names distinct), independent unless
    /// [`Budget::with_correlation`] is given.
    ///
    /// # Errors
    /// No inputs (`inputs`), a repeated name, `coverage` outside (0, 1).
    pub fn new(inputs: Vec<Input>, settings: BudgetSettings) -> Result<Self, MetrologyError> {
        probability("coverage", settings.coverage)?;
        if inputs.is_empty() {
            return Err(tt_core::FieldError::Length {
                field: "inputs".into(),
                expected: 1,
                found: 0,
            }
            .into());
        }
        let mut seen = HashSet::new();
        let (mut u, mut dof) = (Vec::new(), Vec::new());
        for input in &inputs {
            if !seen.insert(input.name.as_str()) {
                return Err(MetrologyError::DuplicateName {
                    name: input.name.clone(),
                });
            }
            for _ in 0..input.components() {
                u.push(input.standard_uncertainty());
                dof.push(input.dof);
            }
        }
        Ok(Budget {
            inputs,
            correlation: None,
            settings,
            u,
            dof,
        })
    }

    /// The same budget with the correlation matrix `r` of the input components (symmetric,
    /// unit diagonal, entries in [-1, 1], positive semi-definite; the two components of a
    /// disc are uncorrelated).
    ///
    /// # Errors
    /// [`MetrologyError::Shape`] or [`MetrologyError::NonFiniteEntry`] (`correlation`),
    /// [`MetrologyError::InvalidCorrelation`] naming the entry, or the whole matrix when it
    /// is not positive semi-definite.
    pub fn with_correlation(mut self, r: DMatrix<f64>) -> Result<Self, MetrologyError> {
        let n = self.components();
        check_matrix("correlation", &r, n, n, || {
            format!("{n} x {n} (input components)")
        })?;
        let bad = |i: usize, j: usize, reason: &str| MetrologyError::InvalidCorrelation {
            field: format!("correlation[{i}, {j}]"),
            reason: format!("{} ({})", reason, r[(i, j)]),
        };
        for i in 0..n {
            if (r[(i, i)] - 1.0).abs() > 1e-12 {
                return Err(bad(i, i, "a diagonal entry must be 1"));
            }
            for j in 0..i {
                if (r[(i, j)] - r[(j, i)]).abs() > 1e-12 {
                    return Err(bad(i, j, "the matrix must be symmetric"));
                }
                if r[(i, j)].abs() > 1.0 {
                    return Err(bad(i, j, "a correlation must lie in [-1, 1]"));
                }
            }
        }
        // positive semi-definite up to rounding: Cholesky of R + 1e-12 I
        let shifted = &r + DMatrix::identity(n, n) * 1e-12;
        if nalgebra::Cholesky::new(shifted).is_none() {
            return Err(MetrologyError::InvalidCorrelation {
                field: "correlation".into(),
                reason: "the matrix is not positive semi-definite (no joint distribution has it)"
                    .into(),
            });
        }
        self.correlation = Some(r);
        Ok(self)
    }

    /// The input quantities.
    #[must_use]
    pub fn inputs(&self) -> &[Input] {
        &self.inputs
    }

    /// The number of input components (columns of the sensitivity matrix).
    #[must_use]
    pub(crate) fn components(&self) -> usize {
        self.u.len()
    }

    /// The settings.
    #[must_use]
    pub fn settings(&self) -> BudgetSettings {
        self.settings
    }

    /// The budget of the outputs named `output_names` with sensitivities `c` (outputs x input
    /// components, in the order of the inputs; a disc's $x$ then $y$).
    ///
    /// ```
    /// use approx::assert_relative_eq;
    /// use metrology::{Budget, BudgetSettings, Input};
    /// use nalgebra::DMatrix;
    /// // y = x1 + 2 x2: x1 normal u = 0.3 with 9 degrees of freedom, x2 rectangular a = 0.1
    /// let budget = Budget::new(
    ///     vec![
    ///         Input::normal("x1", 1.0, 0.3)?.with_dof(9.0)?,
    ///         Input::rectangular("x2", 0.0, 0.1)?,
    ///     ],
    ///     BudgetSettings::default(),
    /// )?;
    /// let result = budget.evaluate(&["y"], &DMatrix::from_row_slice(1, 2, &[1.0, 2.0]))?;
    /// let y = &result.outputs()[0];
    /// let u2 = 2.0 * 0.1 / 3.0_f64.sqrt();
    /// assert_relative_eq!(y.contributions()[1], u2, max_relative = 1e-15);
    /// assert_relative_eq!(y.combined(), (0.09 + u2 * u2).sqrt(), max_relative = 1e-15);
    /// assert_relative_eq!(y.dof_eff(), y.combined().powi(4) / (0.3_f64.powi(4) / 9.0), max_relative = 1e-12);
    /// assert_relative_eq!(y.expanded(), y.coverage_factor() * y.combined(), max_relative = 1e-15);
    /// # Ok::<(), metrology::MetrologyError>(())
    /// ```
    ///
    /// # Errors
    /// `output_names` not one per row; `sensitivities` of the wrong size or with a
    /// non-finite entry; a covariance that overflows (reported as entry (row, col) of the
    /// outputs' covariance, `sensitivities[j, l]`: rescale the units).
    pub fn evaluate<S: AsRef<str>>(
        &self,
        output_names: &[S],
        c: &DMatrix<f64>,
    ) -> Result<BudgetResult, MetrologyError> {
        let (m, n) = (output_names.len(), self.components());
        check_matrix("sensitivities", c, m, n, || {
            format!("{m} x {n} (outputs x input components)")
        })?;
        // C D: each column scaled by its standard uncertainty
        let mut cd = c.clone();
        for (i, &u) in self.u.iter().enumerate() {
            cd.column_mut(i).scale_mut(u);
        }
        let covariance = match &self.correlation {
            Some(r) => &cd * r * cd.transpose(),
            None => &cd * cd.transpose(),
        };
        // finite sensitivities and uncertainties can still overflow a double
        if let Some((k, v)) = covariance.iter().enumerate().find(|(_, v)| !v.is_finite()) {
            return Err(MetrologyError::NonFiniteEntry {
                field: "sensitivities",
                row: k % m,
                col: k / m,
                value: *v,
            });
        }
        let mut outputs = Vec::with_capacity(m);
        // coverage factors by degrees of freedom: truncated dof repeat across outputs
        let mut factors: Vec<(u64, f64)> = Vec::new();
        for (j, name) in output_names.iter().enumerate() {
            let contributions: Vec<f64> = cd.row(j).iter().map(|v| v.abs()).collect();
            let combined = covariance[(j, j)].max(0.0).sqrt();
            let denominator: f64 = contributions
                .iter()
                .zip(&self.dof)
                .map(|(ui, nu)| ui.powi(4) / nu)
                .sum();
            let dof_eff = if denominator > 0.0 {
                combined.powi(4) / denominator
            } else {
                f64::INFINITY
            };
            let dof_used = if self.settings.truncate_dof && dof_eff.is_finite() && dof_eff >= 1.0 {
                dof_eff.floor()
            } else {
                dof_eff
            };
            let k = match factors.iter().find(|(bits, _)| *bits == dof_used.to_bits()) {
                Some(&(_, k)) => k,
                None => {
                    let k = coverage_factor(dof_used, self.settings.coverage)?;
                    factors.push((dof_used.to_bits(), k));
                    k
                }
            };
            outputs.push(OutputUncertainty {
                name: name.as_ref().to_string(),
                sensitivities: c.row(j).iter().copied().collect(),
                contributions,
                combined,
                dof_eff,
                dof_used,
                coverage_factor: k,
                expanded: k * combined,
            });
        }
        let mut rows = Vec::with_capacity(n);
        for input in &self.inputs {
            for comp in 0..input.components() {
                rows.push(BudgetRow {
                    name: input.component_name(comp),
                    distribution: input.distribution.name(),
                    standard_uncertainty: input.standard_uncertainty(),
                    dof: input.dof,
                });
            }
        }
        Ok(BudgetResult {
            rows,
            outputs,
            covariance,
            coverage: self.settings.coverage,
        })
    }

    /// The budget when the model's inputs are a linear map $\mathbf x = \mathbf A \mathbf s$
    /// of this budget's (independent) components $\mathbf s$: `c` is outputs x
    /// derived inputs, `map` derived inputs x components; the rows are the sources and the
    /// sensitivities $\mathbf C \mathbf A$, so every correlation of $\mathbf x$ is carried
    /// exactly and Welch-Satterthwaite applies over independent sources.
    ///
    /// # Errors
    /// As [`Budget::evaluate`]; `map` of the wrong size or with a non-finite entry.
    pub fn evaluate_mapped<S: AsRef<str>>(
        &self,
        output_names: &[S],
        c: &DMatrix<f64>,
        map: &DMatrix<f64>,
    ) -> Result<BudgetResult, MetrologyError> {
        let n = self.components();
        let d = c.ncols();
        check_matrix("map", map, d, n, || {
            format!("{d} x {n} (derived inputs, the columns of the sensitivities, x components)")
        })?;
        check_matrix("sensitivities", c, output_names.len(), d, || {
            format!("{} x {d} (outputs x derived inputs)", output_names.len())
        })?;
        self.evaluate(output_names, &(c * map))
    }
}

/// One row of a budget: an input component.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct BudgetRow {
    pub(crate) name: String,
    pub(crate) distribution: &'static str,
    pub(crate) standard_uncertainty: f64,
    pub(crate) dof: f64,
}

/// Read access to the fields (crate-private, so the type can grow without breaking callers).
impl BudgetRow {
    /// The input's name (`NAME[x]`, `NAME[y]` for a disc's components).
    #[must_use]
    pub fn name(&self) -> &str {
        &self.name
    }

    /// The distribution's name (`normal`, `rectangular`, ...).
    #[must_use]
    pub fn distribution(&self) -> &'static str {
        self.distribution
    }

    /// The standard uncertainty $u(x_i)$, in the input's unit.
    #[must_use]
    pub fn standard_uncertainty(&self) -> f64 {
        self.standard_uncertainty
    }

    /// The degrees of freedom $\nu_i$ (infinite for a value known exactly).
    #[must_use]
    pub fn dof(&self) -> f64 {
        self.dof
    }
}

/// The uncertainty of one output quantity.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct OutputUncertainty {
    pub(crate) name: String,
    pub(crate) sensitivities: Vec<f64>,
    pub(crate) contributions: Vec<f64>,
    pub(crate) combined: f64,
    pub(crate) dof_eff: f64,
    pub(crate) dof_used: f64,
    pub(crate) coverage_factor: f64,
    pub(crate) expanded: f64,
}

/// Read access to the fields (crate-private, so the type can grow without breaking callers).
impl OutputUncertainty {
    /// The output's name.
    #[must_use]
    pub fn name(&self) -> &str {
        &self.name
    }

    /// The sensitivity coefficients $c_i$, one per budget row.
    #[must_use]
    pub fn sensitivities(&self) -> &[f64] {
        &self.sensitivities
    }

    /// The contributions $u_i(y) = |c_i| u(x_i)$, one per budget row, output unit.
    #[must_use]
    pub fn contributions(&self) -> &[f64] {
        &self.contributions
    }

    /// The combined standard uncertainty $u_c(y)$, output unit.
    #[must_use]
    pub fn combined(&self) -> f64 {
        self.combined
    }

    /// The effective degrees of freedom $\nu_{\mathrm{eff}}$ (Welch-Satterthwaite; infinite when
    /// every input's are).
    #[must_use]
    pub fn dof_eff(&self) -> f64 {
        self.dof_eff
    }

    /// The degrees of freedom of the coverage factor ($\lfloor\nu_{\mathrm{eff}}\rfloor$ when
    /// truncating).
    #[must_use]
    pub fn dof_used(&self) -> f64 {
        self.dof_used
    }

    /// The coverage factor $k_p$.
    #[must_use]
    pub fn coverage_factor(&self) -> f64 {
        self.coverage_factor
    }

    /// The expanded uncertainty $U_p = k_p u_c(y)$, output unit.
    #[must_use]
    pub fn expanded(&self) -> f64 {
        self.expanded
    }

    /// The index of the largest contribution (the dominant input), `None` if all are zero.
    #[must_use]
    pub fn dominant(&self) -> Option<usize> {
        let (i, v) = self
            .contributions
            .iter()
            .enumerate()
            .max_by(|a, b| a.1.total_cmp(b.1))?;
        (*v > 0.0).then_some(i)
    }
}

/// A budget: its rows, the uncertainty of each output and the outputs' covariance.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct BudgetResult {
    pub(crate) rows: Vec<BudgetRow>,
    pub(crate) outputs: Vec<OutputUncertainty>,
    pub(crate) covariance: DMatrix<f64>,
    pub(crate) coverage: f64,
}

/// Read access to the fields (crate-private, so the type can grow without breaking callers).
impl BudgetResult {
    /// The rows: one per input component.
    #[must_use]
    pub fn rows(&self) -> &[BudgetRow] {
        &self.rows
    }

    /// The outputs, in the order of the sensitivity matrix.
    #[must_use]
    pub fn outputs(&self) -> &[OutputUncertainty] {
        &self.outputs
    }

    /// The covariance $\mathbf C \mathbf V \mathbf C^{\mathsf T}$ of the outputs (output units
    /// squared).
    #[must_use]
    pub fn covariance(&self) -> &DMatrix<f64> {
        &self.covariance
    }

    /// The coverage probability $p$ of the expanded uncertainties.
    #[must_use]
    pub fn coverage(&self) -> f64 {
        self.coverage
    }
}
