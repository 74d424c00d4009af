//! Joint least squares of the sensor coefficients and further parameters of the data (for
//! example the turntable's errors): which parameters, or combinations of them, the same
//! calibration data identify together with the coefficients.
//!
//! # Model
//! Output $k$ at the test positions, to first order in the extra parameters $\mathbf x$
//! (shared by every output),
//! $$\mathbf b_{1,k} - \mathbf b_{2,k} = \mathbf A_k\boldsymbol\beta_k + \mathbf D_k\mathbf x,$$
//! with $\mathbf A_k$ the output's regression ($n \times p_k$, full column rank) and
//! $\mathbf D_k$ the first-order effect of each parameter on its outputs ($n \times m$). The
//! joint Jacobian is $\mathbf J = [\operatorname{blockdiag}(\mathbf A_k) \mid \mathbf D]$. With
//! $\mathbf P_k = \mathbf A_k\mathbf A_k^+$, its rank is $\sum_k p_k + \operatorname{rank}
//! \tilde{\mathbf D}$, $\tilde{\mathbf D} = [w_k(\mathbf I - \mathbf P_k)\mathbf D_k]_k$ (the
//! effects with what the coefficients absorb removed; $w_k$ a weight per output, e.g. the
//! inverse of its accuracy, which makes outputs of different units comparable: it changes
//! neither the rank nor the subspaces below, only which singular values the tolerance
//! compares).
//!
//! - The **estimable** combinations $\mathbf v^T\mathbf x$ are those in the row space of
//!   $\tilde{\mathbf D}$: right singular vectors with $\sigma_i > $ [`JOINT_RANK_RTOL`]
//!   $\cdot\,\sigma_{\mathrm{ref}}$, $\sigma_{\mathrm{ref}}$ the largest singular value of the
//!   weighted raw effects $[w_k\mathbf D_k]_k$ (so an effect the coefficients absorb down to
//!   rounding counts as absorbed, however small the raw effect).
//! - The **invisible** combinations span the null space of $\tilde{\mathbf D}$: their effect
//!   $\mathbf D_k\mathbf v$ lies in the span of the sensor's columns $\mathbf A_k$ for every
//!   output (a calibration absorbs it into $\boldsymbol\beta$), so no estimator can see them.
//!
//! Noiseless data fit exactly to first order: $\mathbf D\,\Pi_N\mathbf x = \mathbf A\mathbf w$,
//! so the joint estimate gives the estimable part $\Pi_E\mathbf x$ exactly and the coefficients
//! the error $\mathbf w = \mathbf A^+\mathbf D\,\Pi_N\mathbf x$: what remains of the
//! parameters' effect is that of $\Pi_N\mathbf x$ ([`JointEstimability::invisible_projector`]).
//!
//! Singular values and vectors by the one-sided Jacobi method ([`jacobi_svd`]), accurate
//! where forming $\tilde{\mathbf D}^T\tilde{\mathbf D}$ would square the condition.

use crate::error::CalibError;
use crate::lsq::Regression;
use nalgebra::{DMatrix, DVector};
use std::fmt;

/// Singular values of the projected effects at or below this fraction of the reference
/// $\sigma_{\mathrm{ref}}$ count as zero (dimensionless). A combination seen only at $10^{-8}$
/// of the strongest raw effect would need a table error $10^8$ times larger to show as much:
/// not estimable in practice; combinations absorbed exactly (errors acting together, a
/// rotation the coefficients take up) show at $10^{-15}$ and below.
pub const JOINT_RANK_RTOL: f64 = 1e-8;

/// A parameter's share (norm of its row in an orthonormal basis) at or below this counts as
/// zero when sorting parameters into estimable alone / only in combinations / invisible, and a
/// combination's coefficient at or below it is dropped (dimensionless; unit vectors).
pub const SHARE_TOL: f64 = 1e-6;

/// One output of a joint least squares: its regression $\mathbf A_k$ (nominal), the
/// first-order effect of the extra parameters on its outputs $\mathbf D_k$ ($n \times m$,
/// output unit per parameter unit) and the weight of its rows (e.g. $1/\omega_{m,k}$).
#[derive(Debug, Clone, Copy)]
pub struct JointBlock<'a> {
    /// The output's nominal regression.
    pub regression: &'a Regression,
    /// $\mathbf D_k$: one row per position, one column per extra parameter.
    pub effects: &'a DMatrix<f64>,
    /// Weight of the output's rows (positive, finite).
    pub weight: f64,
}

/// What a parameter is to the joint estimator.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Identifiability {
    /// Estimable on its own (its unit vector lies in the estimable subspace).
    Alone,
    /// Only in combinations with others (components in both subspaces).
    Combined,
    /// Invisible: its effect lies in the sensor's columns (the estimable subspace holds none
    /// of it).
    Invisible,
}

impl Identifiability {
    /// `alone`, `combined` or `invisible` (a JSON key).
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Identifiability::Alone => "alone",
            Identifiability::Combined => "combined",
            Identifiability::Invisible => "invisible",
        }
    }
}

/// A linear combination of named parameters, unit Euclidean norm, its first term positive.
#[derive(Debug, Clone, PartialEq)]
pub struct Combination {
    /// (parameter name, coefficient), in parameter order, zero coefficients left out.
    pub terms: Vec<(String, f64)>,
}

impl fmt::Display for Combination {
    /// `0.71 dphi_y1 - 0.71 deps_y` (two decimals).
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        for (i, (name, c)) in self.terms.iter().enumerate() {
            let sign = if *c < 0.0 { "-" } else { "+" };
            if i == 0 {
                if *c < 0.0 {
                    f.write_str("-")?;
                }
            } else {
                write!(f, " {sign} ")?;
            }
            write!(f, "{:.2} {name}", c.abs())?;
        }
        Ok(())
    }
}

/// The estimability of extra parameters together with the sensor coefficients (see the
/// [module](self)).
#[derive(Debug, Clone, PartialEq)]
pub struct JointEstimability {
    names: Vec<String>,
    coefficients: usize,
    singular_values: Vec<f64>,
    reference: f64,
    estimable: DMatrix<f64>,
    invisible: DMatrix<f64>,
}

/// Singular values (descending) and right singular vectors (columns of $\mathbf V$, same
/// order) of a matrix with at least as many rows as columns, by the one-sided Jacobi method
/// (Hestenes): rotate column pairs until all are orthogonal, accumulating the rotations in
/// $\mathbf V$; the column norms are then the singular values, to high relative accuracy. A
/// wide matrix is padded with zero rows.
#[must_use]
pub fn jacobi_svd(m: &DMatrix<f64>) -> (Vec<f64>, DMatrix<f64>) {
    let k = m.ncols();
    let mut u = if m.nrows() >= k {
        m.clone()
    } else {
        let mut p = DMatrix::zeros(k, k);
        p.view_mut((0, 0), m.shape()).copy_from(m);
        p
    };
    let mut v = DMatrix::<f64>::identity(k, k);
    for _ in 0..crate::lsq::JACOBI_MAX_SWEEPS {
        let mut rotated = false;
        for p in 0..k {
            for q in (p + 1)..k {
                let alpha = u.column(p).norm_squared();
                let beta = u.column(q).norm_squared();
                let gamma = u.column(p).dot(&u.column(q));
                if gamma == 0.0 || gamma.abs() <= f64::EPSILON * (alpha * beta).sqrt() {
                    continue;
                }
                rotated = true;
                let zeta = (beta - alpha) / (2.0 * gamma);
                let t = zeta.signum() / (zeta.abs() + (1.0 + zeta * zeta).sqrt());
                let c = 1.0 / (1.0 + t * t).sqrt();
                let s = c * t;
                for w in [&mut u, &mut v] {
                    for i in 0..w.nrows() {
                        let (x, y) = (w[(i, p)], w[(i, q)]);
                        w[(i, p)] = c * x - s * y;
                        w[(i, q)] = s * x + c * y;
                    }
                }
            }
        }
        if !rotated {
            break;
        }
    }
    let mut order: Vec<(f64, usize)> = (0..k).map(|j| (u.column(j).norm(), j)).collect();
    order.sort_by(|x, y| y.0.total_cmp(&x.0).then(x.1.cmp(&y.1)));
    let mut vs = DMatrix::zeros(k, k);
    for (c, (_, j)) in order.iter().enumerate() {
        vs.set_column(c, &v.column(*j));
    }
    (order.into_iter().map(|(s, _)| s).collect(), vs)
}

/// Readable combinations spanning the same subspace as the orthonormal columns of `basis`:
/// reduced row echelon form of $\mathbf B^T$ (pivots in parameter order, partial pivoting),
/// each row scaled to unit norm with its pivot positive.
fn combinations(names: &[String], basis: &DMatrix<f64>) -> Vec<Combination> {
    let mut rows = basis.transpose();
    let (r, m) = rows.shape();
    let mut pivot_row = 0;
    for c in 0..m {
        if pivot_row == r {
            break;
        }
        let (best, val) = (pivot_row..r)
            .map(|i| (i, rows[(i, c)].abs()))
            .fold((pivot_row, -1.0), |b, x| if x.1 > b.1 { x } else { b });
        if val <= SHARE_TOL {
            continue;
        }
        rows.swap_rows(pivot_row, best);
        let p = rows[(pivot_row, c)];
        for j in 0..m {
            rows[(pivot_row, j)] /= p;
        }
        for i in 0..r {
            if i != pivot_row {
                let f = rows[(i, c)];
                if f != 0.0 {
                    for j in 0..m {
                        let v = rows[(pivot_row, j)];
                        rows[(i, j)] -= f * v;
                    }
                }
            }
        }
        pivot_row += 1;
    }
    rows.row_iter()
        .filter_map(|row| {
            let norm = row.norm();
            (norm > 0.0).then(|| Combination {
                terms: row
                    .iter()
                    .zip(names)
                    .map(|(v, n)| (n.clone(), v / norm))
                    .filter(|(_, v)| v.abs() > SHARE_TOL)
                    .collect(),
            })
        })
        .collect()
}

impl JointEstimability {
    /// The estimability of the parameters `names` (one per column of every block's effects)
    /// together with every block's coefficients.
    ///
    /// # Errors
    /// [`CalibError::Field`] for a length mismatch (names, rows), a non-finite effect or a
    /// weight that is not positive and finite, naming it.
    pub fn new(names: &[String], blocks: &[JointBlock<'_>]) -> Result<Self, CalibError> {
        let m = names.len();
        let mut stacked_raw = Vec::new();
        let mut stacked = Vec::new();
        let mut coefficients = 0;
        for (k, b) in blocks.iter().enumerate() {
            let a = b.regression.matrix();
            let field = |what: &str| format!("joint.blocks[{k}].{what}");
            if b.effects.ncols() != m || b.effects.nrows() != a.nrows() {
                return Err(tt_core::FieldError::Length {
                    field: field("effects"),
                    expected: a.nrows() * m,
                    found: b.effects.len(),
                }
                .into());
            }
            if !(b.weight.is_finite() && b.weight > 0.0) {
                return Err(tt_core::FieldError::NotPositive {
                    field: field("weight"),
                    value: b.weight,
                }
                .into());
            }
            if let Some(v) = b.effects.iter().find(|v| !v.is_finite()) {
                return Err(tt_core::FieldError::NonFinite {
                    field: field("effects"),
                    value: *v,
                }
                .into());
            }
            coefficients += a.ncols();
            let projected = b.effects - a * (b.regression.pinv() * b.effects);
            stacked_raw.push(b.effects * b.weight);
            stacked.push(projected * b.weight);
        }
        let stack = |parts: &[DMatrix<f64>]| {
            let rows: usize = parts.iter().map(DMatrix::nrows).sum();
            let mut s = DMatrix::zeros(rows, m);
            let mut r = 0;
            for p in parts {
                s.view_mut((r, 0), p.shape()).copy_from(p);
                r += p.nrows();
            }
            s
        };
        let reference = if m == 0 {
            0.0
        } else {
            jacobi_svd(&stack(&stacked_raw)).0[0]
        };
        let (singular_values, v) = jacobi_svd(&stack(&stacked));
        let rank = singular_values
            .iter()
            .take_while(|s| reference > 0.0 && **s > JOINT_RANK_RTOL * reference)
            .count();
        Ok(Self {
            names: names.to_vec(),
            coefficients,
            singular_values,
            reference,
            estimable: v.columns(0, rank).clone_owned(),
            invisible: v.columns(rank, m - rank).clone_owned(),
        })
    }

    /// The parameters' names.
    #[must_use]
    pub fn names(&self) -> &[String] {
        &self.names
    }

    /// Sensor coefficients of all blocks, $\sum_k p_k$.
    #[must_use]
    pub fn coefficients(&self) -> usize {
        self.coefficients
    }

    /// Columns of the joint Jacobian: coefficients plus parameters.
    #[must_use]
    pub fn columns(&self) -> usize {
        self.coefficients + self.names.len()
    }

    /// Rank of the parameters' part, $\operatorname{rank}\tilde{\mathbf D}$: the number of
    /// estimable combinations.
    #[must_use]
    pub fn table_rank(&self) -> usize {
        self.estimable.ncols()
    }

    /// Rank of the joint Jacobian, $\sum_k p_k + \operatorname{rank}\tilde{\mathbf D}$ (every
    /// block's regression has full column rank).
    #[must_use]
    pub fn rank(&self) -> usize {
        self.coefficients + self.table_rank()
    }

    /// Singular values of $\tilde{\mathbf D}$, descending (weighted output unit per parameter
    /// unit).
    #[must_use]
    pub fn singular_values(&self) -> &[f64] {
        &self.singular_values
    }

    /// $\sigma_{\mathrm{ref}}$: the largest singular value of the weighted raw effects (the
    /// rank tolerance is [`JOINT_RANK_RTOL`] of it).
    #[must_use]
    pub fn reference(&self) -> f64 {
        self.reference
    }

    /// Orthonormal basis of the estimable subspace ($m \times r$, right singular vectors).
    #[must_use]
    pub fn estimable_basis(&self) -> &DMatrix<f64> {
        &self.estimable
    }

    /// Orthonormal basis of the invisible subspace ($m \times (m - r)$).
    #[must_use]
    pub fn invisible_basis(&self) -> &DMatrix<f64> {
        &self.invisible
    }

    /// $\Pi_N = \mathbf N\mathbf N^T$: the projector onto the invisible subspace; the joint
    /// estimator leaves the effect of $\Pi_N\mathbf x$ (see the [module](self)).
    #[must_use]
    pub fn invisible_projector(&self) -> DMatrix<f64> {
        &self.invisible * self.invisible.transpose()
    }

    /// The estimable combinations in the parameters' names (reduced row echelon form of the
    /// basis, unit norm): as many as [`JointEstimability::table_rank`].
    #[must_use]
    pub fn estimable_combinations(&self) -> Vec<Combination> {
        combinations(&self.names, &self.estimable)
    }

    /// The invisible combinations in the parameters' names (as above).
    #[must_use]
    pub fn invisible_combinations(&self) -> Vec<Combination> {
        combinations(&self.names, &self.invisible)
    }

    /// Each parameter's status, in parameter order.
    #[must_use]
    pub fn identifiability(&self) -> Vec<Identifiability> {
        (0..self.names.len())
            .map(|j| {
                let in_n = self.invisible.row(j).norm();
                let in_e = self.estimable.row(j).norm();
                if in_n <= SHARE_TOL {
                    Identifiability::Alone
                } else if in_e <= SHARE_TOL {
                    Identifiability::Invisible
                } else {
                    Identifiability::Combined
                }
            })
            .collect()
    }
}

/// One step of a joint least squares: the corrections $(\mathrm d\boldsymbol\beta_k)_k$ and
/// $\mathrm d\mathbf z$ minimising $\sum_k w_k^2\lVert\mathbf r_k - \mathbf A_k\,
/// \mathrm d\boldsymbol\beta_k - \mathbf D_k\,\mathrm d\mathbf z\rVert^2$, with `blocks[k] =
/// (A_k, D_k, w_k)` (the Jacobians at the current point, $\mathbf D_k$ in whatever
/// coordinates $\mathbf z$ the caller uses) and `residuals[k]` = $\mathbf r_k$. A Gauss-Newton
/// iteration calls it with the Jacobians at each iterate.
///
/// # Errors
/// [`CalibError::Field`] for mismatched lengths; [`CalibError::Unidentifiable`] (output
/// `joint`) when the stacked Jacobian is rank deficient (threshold [`crate::RANK_RTOL`] of the
/// largest diagonal of its triangular factor).
pub fn joint_step(
    blocks: &[(&DMatrix<f64>, &DMatrix<f64>, f64)],
    residuals: &[DVector<f64>],
) -> Result<(Vec<DVector<f64>>, DVector<f64>), CalibError> {
    tt_core::length("joint residuals", blocks.len(), residuals.len())?;
    let z = blocks.first().map_or(0, |b| b.1.ncols());
    let rows: usize = blocks.iter().map(|b| b.0.nrows()).sum();
    let p: usize = blocks.iter().map(|b| b.0.ncols()).sum();
    let mut j = DMatrix::zeros(rows, p + z);
    let mut r = DVector::zeros(rows);
    let (mut row, mut col) = (0, 0);
    for (k, ((a, d, w), res)) in blocks.iter().zip(residuals).enumerate() {
        let n = a.nrows();
        if d.nrows() != n || d.ncols() != z || res.len() != n {
            return Err(tt_core::FieldError::Length {
                field: format!("joint.blocks[{k}]"),
                expected: n,
                found: res.len(),
            }
            .into());
        }
        j.view_mut((row, col), a.shape()).copy_from(&(*a * *w));
        j.view_mut((row, p), d.shape()).copy_from(&(*d * *w));
        r.rows_mut(row, n).copy_from(&(res * *w));
        row += n;
        col += a.ncols();
    }
    let cols = p + z;
    if rows < cols {
        return Err(CalibError::Unidentifiable {
            output: "joint".into(),
            coefficients: Vec::new(),
            rank: rows,
            columns: cols,
            positions: rows,
        });
    }
    let qr = j.qr();
    let (q, rr) = (qr.q(), qr.r());
    let d0 = (0..cols).map(|i| rr[(i, i)].abs()).fold(0.0, f64::max);
    let rank = (0..cols)
        .filter(|&i| rr[(i, i)].abs() > crate::RANK_RTOL * d0)
        .count();
    if rank < cols {
        return Err(CalibError::Unidentifiable {
            output: "joint".into(),
            coefficients: Vec::new(),
            rank,
            columns: cols,
            positions: rows,
        });
    }
    let x = rr
        .solve_upper_triangular(&(q.transpose() * r))
        .unwrap_or_else(|| unreachable!("full rank was checked"));
    let mut out = Vec::with_capacity(blocks.len());
    let mut c = 0;
    for (a, _, _) in blocks {
        out.push(x.rows(c, a.ncols()).clone_owned());
        c += a.ncols();
    }
    Ok((out, x.rows(p, z).clone_owned()))
}
