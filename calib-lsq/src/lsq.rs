//! Least squares by QR decomposition (eq 6 and 11 without forming $A^TA$).

use crate::error::{CalibError, finite};
use gw_model::{N_COEFFICIENTS, SensingAxis};
use nalgebra::{DMatrix, DVector};

/// Relative threshold for the numerical rank: a diagonal entry of the column-pivoted $\mathbf R$
/// below `RANK_RTOL` $\cdot |R_{11}|$ counts as zero. Dimensionless. A coefficient identified
/// only with an error amplification above $10^{10}$ is unidentifiable for any practical
/// purpose, and exact deficiencies of trigonometric schedules show up near $10^{-16}$.
pub const RANK_RTOL: f64 = 1e-10;

/// Share of a coefficient in the null space above which it is named unidentifiable.
/// Dimensionless (component of a unit null vector); exact deficiencies give components of
/// order 1, numerical noise of order $10^{-15}$.
pub const NULL_COMPONENT_TOL: f64 = 1e-6;

/// A least-squares solution with its quality: residuals, rank, condition number.
#[derive(Debug, Clone, PartialEq)]
pub struct LsqSolution {
    /// The estimate $\hat{\boldsymbol\beta}$ (rad/s, rad/s/g, rad/s/g², eq 1 order).
    pub beta: DVector<f64>,
    /// Residuals $\mathbf y - \mathbf A\hat{\boldsymbol\beta}$ (rad/s), one per position.
    pub residuals: DVector<f64>,
    /// Numerical rank of $\mathbf A$ (threshold [`RANK_RTOL`]).
    pub rank: usize,
    /// 2-norm condition number $\sigma_{max}/\sigma_{min}$ of $\mathbf A$ (infinite if rank
    /// deficient).
    pub condition_number: f64,
    /// Singular values of $\mathbf A$, descending.
    pub singular_values: DVector<f64>,
}

impl LsqSolution {
    /// Root mean square of the residuals, rad/s.
    #[must_use]
    pub fn rms_residual(&self) -> f64 {
        if self.residuals.is_empty() {
            0.0
        } else {
            self.residuals.norm() / (self.residuals.len() as f64).sqrt()
        }
    }
}

/// A factored regression matrix $\mathbf A$ (n x 7) of one axis, reusable for many right-hand
/// sides.
///
/// Solves by Householder QR ($\mathbf A = \mathbf Q\mathbf R$, then
/// $\mathbf R\hat{\boldsymbol\beta} = \mathbf Q^T\mathbf y$); the rank and the unidentifiable
/// coefficients come from a column-pivoted QR; the singular values (for the condition number)
/// from the symmetric eigenproblem of the $7\times7$ $\mathbf R^T\mathbf R$.
///
/// nalgebra 0.35's SVD is not used: for some row orders of the default schedule it returns
/// factors that do not recompose $\mathbf A$ (error 0.09 on entries of order 1; nalgebra issue
/// #1172), which broke the permutation-invariance test of the estimate.
#[derive(Debug, Clone)]
pub struct Regression {
    axis: SensingAxis,
    a: DMatrix<f64>,
    q: DMatrix<f64>,
    r: DMatrix<f64>,
    rank: usize,
    condition_number: f64,
    singular_values: DVector<f64>,
}

impl Regression {
    /// Factor $\mathbf A$ and check that every coefficient is identifiable.
    ///
    /// # Errors
    /// [`CalibError::Unidentifiable`] naming every coefficient with a component in the null
    /// space of $\mathbf A$; [`CalibError::NonFinite`] for a non-finite entry;
    /// [`CalibError::LengthMismatch`] unless $\mathbf A$ has 7 columns.
    pub fn new(axis: SensingAxis, a: DMatrix<f64>) -> Result<Self, CalibError> {
        for (k, v) in a.iter().enumerate() {
            finite(format!("A[{}][{}]", k % a.nrows(), k / a.nrows()), *v)?;
        }
        let n = a.nrows();
        if a.ncols() != N_COEFFICIENTS {
            return Err(CalibError::LengthMismatch {
                what: "regression matrix columns",
                expected: N_COEFFICIENTS,
                found: a.ncols(),
            });
        }
        // With fewer than 7 rows pad with zero rows: the missing directions become null.
        let padded = if n < N_COEFFICIENTS {
            let mut p = DMatrix::zeros(N_COEFFICIENTS, N_COEFFICIENTS);
            p.view_mut((0, 0), (n, N_COEFFICIENTS)).copy_from(&a);
            p
        } else {
            a.clone()
        };
        let names = axis.coefficient_names();
        let (rank, null_rows) = pivoted_rank_and_null_space(&padded);
        if rank < N_COEFFICIENTS {
            let coefficients = names
                .iter()
                .zip(null_rows)
                .filter(|(_, share)| *share > NULL_COMPONENT_TOL)
                .map(|(name, _)| *name)
                .collect();
            return Err(CalibError::Unidentifiable {
                axis,
                coefficients,
                rank,
                positions: n,
            });
        }
        let qr = padded.qr();
        let (q, r) = (qr.q(), qr.r());
        let eig = (r.transpose() * &r).symmetric_eigenvalues();
        let mut sv: Vec<f64> = eig.iter().map(|l| l.max(0.0).sqrt()).collect();
        sv.sort_by(|x, y| y.total_cmp(x));
        let singular_values = DVector::from_vec(sv);
        let condition_number = singular_values.max() / singular_values.min();
        Ok(Self {
            axis,
            a,
            q,
            r,
            rank,
            condition_number,
            singular_values,
        })
    }

    /// The axis.
    #[must_use]
    pub fn axis(&self) -> SensingAxis {
        self.axis
    }

    /// The regression matrix $\mathbf A$.
    #[must_use]
    pub fn matrix(&self) -> &DMatrix<f64> {
        &self.a
    }

    /// Numerical rank (always 7 for a constructed `Regression`).
    #[must_use]
    pub fn rank(&self) -> usize {
        self.rank
    }

    /// Condition number $\sigma_{max}/\sigma_{min}$.
    #[must_use]
    pub fn condition_number(&self) -> f64 {
        self.condition_number
    }

    /// The least-squares estimate $\hat{\boldsymbol\beta} = \mathbf A^+ \mathbf y$ only.
    ///
    /// # Errors
    /// [`CalibError::LengthMismatch`] if `y` does not have one entry per row of $\mathbf A$.
    pub fn estimate(&self, y: &DVector<f64>) -> Result<DVector<f64>, CalibError> {
        let n = self.a.nrows();
        if y.len() != n {
            return Err(CalibError::LengthMismatch {
                what: "right-hand side",
                expected: n,
                found: y.len(),
            });
        }
        let rhs = if n < N_COEFFICIENTS {
            let mut p = DVector::zeros(N_COEFFICIENTS);
            p.rows_mut(0, n).copy_from(y);
            p
        } else {
            y.clone()
        };
        // Full rank was checked in `new`, so R is invertible.
        let qty = self.q.transpose() * rhs;
        self.r
            .solve_upper_triangular(&qty)
            .ok_or(CalibError::Unidentifiable {
                axis: self.axis,
                coefficients: Vec::new(),
                rank: self.rank,
                positions: n,
            })
    }

    /// Solve $\min \lVert \mathbf A\boldsymbol\beta - \mathbf y \rVert_2$ with residuals, rank and
    /// condition number.
    ///
    /// # Formula
    /// $\hat{\boldsymbol\beta} = \mathbf R^{-1} \mathbf Q^T \mathbf y$, equal to
    /// $(\mathbf A^T\mathbf A)^{-1}\mathbf A^T \mathbf y$ of eq 6/11 without forming
    /// $\mathbf A^T\mathbf A$ (which would square the condition number).
    ///
    /// # Reference
    /// Eq 6 and 11.
    ///
    /// # Errors
    /// As [`estimate`](Self::estimate).
    pub fn solve(&self, y: &DVector<f64>) -> Result<LsqSolution, CalibError> {
        let beta = self.estimate(y)?;
        let residuals = y - &self.a * &beta;
        Ok(LsqSolution {
            beta,
            residuals,
            rank: self.rank,
            condition_number: self.condition_number,
            singular_values: self.singular_values.clone(),
        })
    }
}

/// Least squares for one axis in one call: factor `a` and solve for `y`.
///
/// # Errors
/// As [`Regression::new`] and [`Regression::solve`].
pub fn solve_least_squares(
    axis: SensingAxis,
    a: DMatrix<f64>,
    y: &DVector<f64>,
) -> Result<LsqSolution, CalibError> {
    Regression::new(axis, a)?.solve(y)
}

/// Numerical rank of `a` (square or tall) by column-pivoted QR, and for each column the norm
/// of its row in a normalised null-space basis (zero for identifiable coefficients).
fn pivoted_rank_and_null_space(a: &DMatrix<f64>) -> (usize, Vec<f64>) {
    let m = a.ncols();
    let cp = a.clone().col_piv_qr();
    let r = cp.r();
    let d0 = r[(0, 0)].abs();
    let rank = (0..m)
        .take_while(|&k| r[(k, k)].abs() > RANK_RTOL * d0 && d0 > 0.0)
        .count();
    let mut shares = vec![0.0; m];
    if rank == m {
        return (rank, shares);
    }
    // A P = Q R with R = [R11 R12; 0 ~0]: null vectors in pivoted order are
    // [-R11^{-1} R12 e_k; e_k].
    let r11 = r.view((0, 0), (rank, rank)).clone_owned();
    let r12 = r.view((0, rank), (rank, m - rank)).clone_owned();
    let x = if rank > 0 {
        r11.solve_upper_triangular(&r12)
            .unwrap_or_else(|| DMatrix::zeros(rank, m - rank))
    } else {
        DMatrix::zeros(0, m - rank)
    };
    let mut null = DMatrix::zeros(m, m - rank);
    null.view_mut((0, 0), (rank, m - rank)).copy_from(&(-x));
    null.view_mut((rank, 0), (m - rank, m - rank))
        .fill_with_identity();
    // Back to the original column order; try both directions of the permutation and keep the
    // one that annihilates A (robust to the permutation convention).
    let mut fwd = null.clone();
    cp.p().permute_rows(&mut fwd);
    let mut inv = null;
    cp.p().inv_permute_rows(&mut inv);
    let basis = if (a * &fwd).amax() <= (a * &inv).amax() {
        fwd
    } else {
        inv
    };
    // Orthonormalise so that shares are comparable between columns.
    let q = basis.qr().q();
    for (j, s) in shares.iter_mut().enumerate() {
        *s = q.row(j).norm();
    }
    (rank, shares)
}

/// Plain Householder-QR least squares for a matrix known to be a small perturbation of a
/// full-rank one (eq 11's $\mathbf A'$): no rank analysis. `None` if $\mathbf R$ is singular.
pub(crate) fn qr_estimate(a: DMatrix<f64>, y: &DVector<f64>) -> Option<DVector<f64>> {
    if a.nrows() < a.ncols() || y.len() != a.nrows() {
        return None;
    }
    let qr = a.qr();
    let qty = qr.q().transpose() * y;
    qr.r().solve_upper_triangular(&qty)
}
