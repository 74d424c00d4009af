//! Least squares by QR decomposition (eq 6 and 11 without forming $A^TA$), with rank,
//! identifiability and singular values, and the covariance of the estimate under sensor
//! noise (submodule `covariance`: [`Regression::coefficient_covariance`]).

use crate::error::{CalibError, finite};
use nalgebra::{DMatrix, DVector};

mod covariance;
pub use covariance::{CoefficientCovariance, NoiseCovariance, RateErrorCovariance};

/// Relative threshold for the numerical rank: a diagonal entry of the column-pivoted $\mathbf R$
/// below `RANK_RTOL` $\cdot |R_{11}|$ counts as zero. Dimensionless. A coefficient identified
/// only with an error amplification above $10^{10}$ is unidentifiable for any practical
/// purpose, and exact deficiencies of trigonometric schedules show up near $10^{-16}$.
pub const RANK_RTOL: f64 = 1e-10;

/// Share of a coefficient in the null space above which it is named unidentifiable.
/// Dimensionless (component of a unit null vector); exact deficiencies give components of
/// order 1, numerical noise of order $10^{-15}$.
pub const NULL_COMPONENT_TOL: f64 = 1e-6;

/// Sweeps of the one-sided Jacobi SVD before it gives up (it converges quadratically; a
/// 20 x 20 triangle needs about 8).
pub(crate) const JACOBI_MAX_SWEEPS: usize = 60;

/// The conditioning of a regression matrix $\mathbf A$: its numerical rank, condition number
/// and singular values, computed once by [`Regression::new`] and carried by every
/// [`LsqSolution`] it solves.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct Conditioning {
    /// Numerical rank of $\mathbf A$ (threshold [`RANK_RTOL`]; the column count for a
    /// constructed [`Regression`]).
    pub(crate) rank: usize,
    /// 2-norm condition number $\sigma_{max}/\sigma_{min}$ of $\mathbf A$.
    pub(crate) condition_number: f64,
    /// Singular values of $\mathbf A$, descending.
    pub(crate) singular_values: DVector<f64>,
}

/// Read access to the fields (crate-private, so the type can grow without breaking callers).
impl Conditioning {
    /// Numerical rank of $\mathbf A$ (threshold [`RANK_RTOL`]; the column count for a
    /// constructed [`Regression`]).
    #[must_use]
    pub fn rank(&self) -> usize {
        self.rank
    }

    /// 2-norm condition number $\sigma_{max}/\sigma_{min}$ of $\mathbf A$.
    #[must_use]
    pub fn condition_number(&self) -> f64 {
        self.condition_number
    }

    /// Singular values of $\mathbf A$, descending.
    #[must_use]
    pub fn singular_values(&self) -> &DVector<f64> {
        &self.singular_values
    }
}

/// A least-squares solution with its quality: residuals and the regression's conditioning
/// (rank, condition number).
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct LsqSolution {
    /// The estimate $\hat{\boldsymbol\beta}$ (one value per estimated coefficient).
    pub(crate) beta: DVector<f64>,
    /// Residuals $\mathbf y - \mathbf A\hat{\boldsymbol\beta}$, one per position.
    pub(crate) residuals: DVector<f64>,
    /// The regression's rank, condition number and singular values.
    pub(crate) conditioning: Conditioning,
}

/// Read access to the fields (crate-private, so the type can grow without breaking callers).
impl LsqSolution {
    /// The estimate $\hat{\boldsymbol\beta}$ (one value per estimated coefficient).
    #[must_use]
    pub fn beta(&self) -> &DVector<f64> {
        &self.beta
    }

    /// Residuals $\mathbf y - \mathbf A\hat{\boldsymbol\beta}$, one per position.
    #[must_use]
    pub fn residuals(&self) -> &DVector<f64> {
        &self.residuals
    }

    /// The regression's rank, condition number and singular values
    /// ([`Regression::conditioning`]).
    #[must_use]
    pub fn conditioning(&self) -> &Conditioning {
        &self.conditioning
    }
}

impl LsqSolution {
    /// Root mean square of the residuals.
    #[must_use]
    pub fn rms_residual(&self) -> f64 {
        if self.residuals.is_empty() {
            0.0
        } else {
            self.residuals.norm() / (self.residuals.len() as f64).sqrt()
        }
    }
}

/// A factored regression matrix $\mathbf A$ ($n \times k$) of one output, reusable for many
/// right-hand sides.
///
/// Solves by Householder QR ($\mathbf A = \mathbf Q\mathbf R$, then
/// $\mathbf R\hat{\boldsymbol\beta} = \mathbf Q^T\mathbf y$); the rank and the unidentifiable
/// coefficients come from a column-pivoted QR; the singular values (for the condition number)
/// from a one-sided Jacobi SVD of the $k \times k$ triangle $\mathbf R$ (the singular values of
/// $\mathbf A$, to high relative accuracy; forming $\mathbf R^T\mathbf R$ would square the
/// condition number).
///
/// nalgebra 0.35's SVD is not used: for some row orders of a 32-position schedule it returns
/// factors that do not recompose $\mathbf A$ (nalgebra issue #1172).
#[derive(Debug, Clone)]
pub struct Regression {
    output: String,
    names: Vec<String>,
    a: DMatrix<f64>,
    q: DMatrix<f64>,
    r: DMatrix<f64>,
    pinv: DMatrix<f64>,
    conditioning: Conditioning,
    /// $\lVert\mathbf P\rVert_\infty$ and $\lVert\mathbf I - \mathbf P\rVert_\infty$, computed
    /// at the first use ([`Regression::projector_norms`]).
    projector_norms: std::sync::OnceLock<(f64, f64)>,
}

impl Regression {
    /// Factor $\mathbf A$ (one column per coefficient named in `names`) and check that every
    /// coefficient is identifiable.
    ///
    /// # Errors
    /// [`CalibError::Unidentifiable`] naming `output` and every coefficient with a component in
    /// the null space of $\mathbf A$; [`CalibError::Field`] (not finite) for a non-finite entry;
    /// [`CalibError::Field`] ([`tt_core::FieldError::Length`]) unless there is one name per column.
    pub fn new(output: &str, names: Vec<String>, a: DMatrix<f64>) -> Result<Self, CalibError> {
        let rank = check_identifiable(output, &names, &a)?;
        let qr = a.clone().qr();
        let (q, r) = (qr.q(), qr.r());
        let sv = jacobi_singular_values(&r);
        let singular_values = DVector::from_vec(sv);
        let condition_number = singular_values.max() / singular_values.min();
        let pinv = r
            .solve_upper_triangular(&q.transpose())
            .unwrap_or_else(|| unreachable!("full rank was checked"));
        Ok(Self {
            output: output.to_string(),
            names,
            a,
            q,
            r,
            pinv,
            conditioning: Conditioning {
                rank,
                condition_number,
                singular_values,
            },
            projector_norms: std::sync::OnceLock::new(),
        })
    }

    /// $\lVert\mathbf P\rVert_\infty$ and $\lVert\mathbf I - \mathbf P\rVert_\infty$ of the
    /// projector $\mathbf P = \mathbf A\mathbf A^+$ ([`Regression::projector_row_sums`] with
    /// unit weights, their largest entries): $O(n^2 k)$ once per regression, then a look-up.
    #[must_use]
    pub fn projector_norms(&self) -> (f64, f64) {
        *self.projector_norms.get_or_init(|| {
            let ones = vec![1.0; self.a.nrows()];
            let (p, ip) = self.projector_row_sums(&ones, &ones);
            let max = |x: Vec<f64>| x.into_iter().fold(0.0, f64::max);
            (max(p), max(ip))
        })
    }

    /// The output's name.
    #[must_use]
    pub fn output(&self) -> &str {
        &self.output
    }

    /// The coefficient names (columns).
    #[must_use]
    pub fn names(&self) -> &[String] {
        &self.names
    }

    /// The regression matrix $\mathbf A$.
    #[must_use]
    pub fn matrix(&self) -> &DMatrix<f64> {
        &self.a
    }

    /// The pseudo-inverse $\mathbf A^+ = \mathbf R^{-1}\mathbf Q^T$ ($k \times n$), computed once:
    /// $\hat{\boldsymbol\beta} = \mathbf A^+\mathbf y$ for every right-hand side.
    #[must_use]
    pub fn pinv(&self) -> &DMatrix<f64> {
        &self.pinv
    }

    /// The weighted absolute row sums of the projector $\mathbf P = \mathbf A\mathbf A^+$ and
    /// of $\mathbf I - \mathbf P$: for every row $i$, $\sum_j \lvert P_{ij}\rvert\,w_j$ and
    /// $\sum_j \lvert\delta_{ij} - P_{ij}\rvert\,v_j$ (`w`, `v` one weight per row of
    /// $\mathbf A$). Row by row, $P_{ij} = \mathbf a_i\cdot\mathbf A^+_{:,j}$: memory linear
    /// in the positions (the $n \times n$ projector is never formed), time $O(n^2 k)$.
    ///
    /// # Panics
    /// Debug assertion on the weights' lengths.
    #[must_use]
    pub fn projector_row_sums(&self, w: &[f64], v: &[f64]) -> (Vec<f64>, Vec<f64>) {
        let (n, k) = self.a.shape();
        debug_assert!(w.len() == n && v.len() == n);
        let mut row = vec![0.0; k];
        let (mut p_sums, mut ip_sums) = (Vec::with_capacity(n), Vec::with_capacity(n));
        for i in 0..n {
            for (c, r) in row.iter_mut().enumerate() {
                *r = self.a[(i, c)];
            }
            let (mut sp, mut sip) = (0.0, 0.0);
            for (j, col) in self.pinv.column_iter().enumerate() {
                let p: f64 = row.iter().zip(col.iter()).map(|(x, y)| x * y).sum();
                sp += p.abs() * w[j];
                let delta = if i == j { 1.0 } else { 0.0 };
                sip += (delta - p).abs() * v[j];
            }
            p_sums.push(sp);
            ip_sums.push(sip);
        }
        (p_sums, ip_sums)
    }

    /// The rank, condition number and singular values of $\mathbf A$.
    #[must_use]
    pub fn conditioning(&self) -> &Conditioning {
        &self.conditioning
    }

    /// Numerical rank (always the column count for a constructed `Regression`).
    #[must_use]
    pub fn rank(&self) -> usize {
        self.conditioning.rank
    }

    /// Condition number $\sigma_{max}/\sigma_{min}$.
    #[must_use]
    pub fn condition_number(&self) -> f64 {
        self.conditioning.condition_number
    }

    /// Singular values of $\mathbf A$, descending.
    #[must_use]
    pub fn singular_values(&self) -> &DVector<f64> {
        &self.conditioning.singular_values
    }

    /// The least-squares estimate $\hat{\boldsymbol\beta} = \mathbf A^+ \mathbf y$ only.
    ///
    /// # Errors
    /// [`CalibError::Field`] ([`tt_core::FieldError::Length`]) if `y` does not have one entry per row of $\mathbf A$.
    pub fn estimate(&self, y: &DVector<f64>) -> Result<DVector<f64>, CalibError> {
        let n = self.a.nrows();
        if y.len() != n {
            return Err(CalibError::Field(tt_core::FieldError::Length {
                field: "right-hand side".into(),
                expected: n,
                found: y.len(),
            }));
        }
        let qty = self.q.transpose() * y;
        Ok(self
            .r
            .solve_upper_triangular(&qty)
            .unwrap_or_else(|| unreachable!("full rank was checked")))
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
            conditioning: self.conditioning.clone(),
        })
    }
}

/// Singular values (descending) of a square or tall matrix by the one-sided Jacobi method
/// (Hestenes): rotate column pairs until all are orthogonal; the column norms are then the
/// singular values, to high relative accuracy.
#[must_use]
pub fn jacobi_singular_values(m: &DMatrix<f64>) -> Vec<f64> {
    crate::joint::jacobi_svd(m).0
}

/// The checks of [`Regression::new`]: every entry finite (the first non-finite one named),
/// one name per column, full rank (else the unidentifiable coefficients named). Returns the
/// rank. Nothing is formatted unless a check fails (this runs once per evaluation of a
/// reading with $\hat{\boldsymbol\beta}_2$).
fn check_identifiable(
    output: &str,
    names: &[String],
    a: &DMatrix<f64>,
) -> Result<usize, CalibError> {
    if let Some((k, v)) = a.iter().enumerate().find(|(_, v)| !v.is_finite()) {
        finite(format!("A[{}][{}]", k % a.nrows(), k / a.nrows()), *v)?;
    }
    let (n, k) = a.shape();
    if names.len() != k || k == 0 {
        return Err(CalibError::Field(tt_core::FieldError::Length {
            field: "coefficient names".into(),
            expected: k,
            found: names.len(),
        }));
    }
    // With fewer rows than columns pad with zero rows: the missing directions become null.
    let (rank, null_rows) = if n < k {
        let mut p = DMatrix::zeros(k, k);
        p.view_mut((0, 0), (n, k)).copy_from(a);
        pivoted_rank_and_null_space(&p)
    } else {
        pivoted_rank_and_null_space(a)
    };
    if rank < k {
        let coefficients = names
            .iter()
            .zip(null_rows)
            .filter(|(_, share)| *share > NULL_COMPONENT_TOL)
            .map(|(name, _)| name.clone())
            .collect();
        return Err(CalibError::Unidentifiable {
            output: output.to_string(),
            coefficients,
            rank,
            columns: k,
            positions: n,
        });
    }
    Ok(rank)
}

/// The least-squares solve of a [`Regression`] without what only a report needs (names,
/// condition number, singular values, pseudo-inverse): the factorisation of $\mathbf A'$ that
/// readings with $\hat{\boldsymbol\beta}_2$ make at every evaluation. Same checks and the same
/// arithmetic as [`Regression::new`] and [`Regression::estimate`], so the same estimate to the
/// bit.
#[derive(Debug, Clone)]
pub(crate) struct QrSolve {
    q: DMatrix<f64>,
    r: DMatrix<f64>,
}

impl QrSolve {
    /// Check and factor `a` as [`Regression::new`] does.
    pub(crate) fn new(output: &str, names: &[String], a: DMatrix<f64>) -> Result<Self, CalibError> {
        check_identifiable(output, names, &a)?;
        let qr = a.qr();
        Ok(Self {
            q: qr.q(),
            r: qr.r(),
        })
    }

    /// $\hat{\boldsymbol\beta} = \mathbf R^{-1}\mathbf Q^T\mathbf y$ (`y` one value per row).
    pub(crate) fn estimate(&self, y: &DVector<f64>) -> DVector<f64> {
        let qty = self.q.transpose() * y;
        self.r
            .solve_upper_triangular(&qty)
            .unwrap_or_else(|| unreachable!("full rank was checked"))
    }
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

#[cfg(test)]
mod tests {
    use super::*;

    fn bits(v: &DVector<f64>) -> Vec<u64> {
        v.iter().map(|x| x.to_bits()).collect()
    }

    /// The factorisation a reading with beta-hat-2 makes per evaluation (`QrSolve`) gives
    /// `Regression`'s estimate to the bit, and the same errors: the first non-finite entry
    /// named, a dependent column named unidentifiable, a name missing.
    #[test]
    fn qr_solve_is_the_regression_estimate_to_the_bit_with_the_same_errors() {
        let a = DMatrix::from_fn(7, 3, |i, j| {
            ((i * 3 + j) as f64 * 0.7).sin() + if i == j { 1.0 } else { 0.0 }
        });
        let names: Vec<String> = ["b", "k", "m"].map(String::from).to_vec();
        let y = DVector::from_fn(7, |i, _| (i as f64 * 0.37).cos());
        let r = Regression::new("out", names.clone(), a.clone()).unwrap();
        let q = QrSolve::new("out", &names, a.clone()).unwrap();
        assert_eq!(bits(&q.estimate(&y)), bits(&r.estimate(&y).unwrap()));

        let mut bad = a.clone();
        bad[(2, 1)] = f64::NAN;
        bad[(5, 2)] = f64::INFINITY;
        let e = QrSolve::new("out", &names, bad.clone()).unwrap_err();
        assert!(e.to_string().contains("A[2][1]"), "{e}");
        assert_eq!(
            e.to_string(),
            Regression::new("out", names.clone(), bad)
                .unwrap_err()
                .to_string()
        );

        let mut dependent = a.clone();
        dependent.set_column(2, &(a.column(0) * 2.0));
        let e = QrSolve::new("out", &names, dependent.clone()).unwrap_err();
        assert!(
            matches!(&e, CalibError::Unidentifiable { coefficients, rank: 2, .. } if coefficients.contains(&"m".to_string())),
            "{e}"
        );
        assert_eq!(
            e,
            Regression::new("out", names.clone(), dependent).unwrap_err()
        );

        let e = QrSolve::new("out", &names[..2], a.clone()).unwrap_err();
        assert_eq!(
            e,
            Regression::new("out", names[..2].to_vec(), a).unwrap_err()
        );
    }
}
