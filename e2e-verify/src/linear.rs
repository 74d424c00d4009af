//! The linearised end-to-end map $\Delta\hat{\boldsymbol\omega} \approx \mathbf M\chi$ and the
//! worst case of a tolerance box, found exactly for the linear model (a vertex) and confirmed
//! on the exact chain.

use crate::error::E2eError;
use crate::simulate::{AXES, EndToEnd, check_chi};
use calib_lsq::{ErrorForm, Estimate, OutputsAt};
use gw_model::SensingAxis;
use gw_model::units::rad_per_s_to_deg_per_h;
use mc_verify::ErrorBox;
use nalgebra::{DMatrix, DVector, Vector3};
use tt_kinematics::{CHI_LEN, LinearModel, OrientationAxis};

/// The Jacobian $\mathbf M$ ($2n \times 8$) of the error vectors with respect to $\chi$ at
/// $\chi = 0$: rows $0..n$ are the $x$ axis at positions $0..n$, rows $n..2n$ the $y$ axis.
/// Units: rad/s per rad.
#[derive(Debug, Clone, PartialEq)]
pub struct Linearization {
    m: DMatrix<f64>,
    n: usize,
}

impl Linearization {
    /// The matrix $\mathbf M$ (rad/s per rad).
    #[must_use]
    pub fn matrix(&self) -> &DMatrix<f64> {
        &self.m
    }

    /// Number of positions $n$.
    #[must_use]
    pub fn positions(&self) -> usize {
        self.n
    }

    /// Row index of (axis, position).
    #[must_use]
    pub fn row_index(&self, axis: SensingAxis, position: usize) -> usize {
        match axis {
            SensingAxis::X => position,
            SensingAxis::Y => self.n + position,
        }
    }

    /// One row $\mathbf M_r$ (rad/s per rad).
    #[must_use]
    pub fn row(&self, axis: SensingAxis, position: usize) -> [f64; CHI_LEN] {
        let r = self.row_index(axis, position);
        std::array::from_fn(|j| self.m[(r, j)])
    }

    /// The linearised worst case of every row over the box $|\chi_j| \le \mathrm{UB}_j$:
    /// $\sum_j |M_{rj}|\,\mathrm{UB}_j$ (rad/s), in row order.
    #[must_use]
    pub fn row_worst_cases(&self, ub_rad: &[f64; CHI_LEN]) -> DVector<f64> {
        DVector::from_iterator(
            2 * self.n,
            self.m
                .row_iter()
                .map(|r| r.iter().zip(ub_rad).map(|(m, u)| m.abs() * u).sum::<f64>()),
        )
    }
}

/// The worst case of one axis over a tolerance box.
#[derive(Debug, Clone, PartialEq)]
pub struct AxisWorstCase {
    /// The axis.
    pub axis: SensingAxis,
    /// $\max_r \sum_j |M_{rj}|\,\mathrm{UB}_j$ over this axis's rows (rad/s): the exact worst
    /// case of the linearised model (a maximum of absolute linear forms peaks at a vertex).
    pub linear_bound_rad_per_s: f64,
    /// The position (index in the schedule) of the worst row.
    pub position: usize,
    /// The worst vertex $\chi_j = \operatorname{sign}(M_{rj})\,\mathrm{UB}_j$ (rad).
    pub worst_chi_rad: [f64; CHI_LEN],
    /// $\Delta\omega$ of this axis on the exact chain at $\pm$ the worst vertex (the larger),
    /// rad/s: a point of the box, so a lower bound on the exact worst case.
    pub exact_at_vertex_rad_per_s: f64,
    /// The derived bound $\tau$ on $|\Delta\hat\omega_{exact} - \mathbf M\chi|$ over the box
    /// (rad/s; see [`EndToEnd::second_order_bound`]); `None` for readings without one. The
    /// exact worst case lies in [`exact_at_vertex_rad_per_s`](Self::exact_at_vertex_rad_per_s)
    /// $\ldots$ `linear_bound + tau`.
    pub second_order_bound_rad_per_s: Option<f64>,
    /// Linearised worst case of every position (rad/s), the data of the per-position figure.
    pub per_position_rad_per_s: Vec<f64>,
}

impl AxisWorstCase {
    /// The confirmed (exact-chain) worst case, deg/h.
    #[must_use]
    pub fn exact_deg_per_h(&self) -> f64 {
        rad_per_s_to_deg_per_h(self.exact_at_vertex_rad_per_s)
    }

    /// The linearised worst case, deg/h.
    #[must_use]
    pub fn linear_deg_per_h(&self) -> f64 {
        rad_per_s_to_deg_per_h(self.linear_bound_rad_per_s)
    }
}

/// The worst case of both axes over a tolerance box.
#[derive(Debug, Clone, PartialEq)]
pub struct WorstCase {
    /// The upper bounds of the box (rad, order of eq 25).
    pub upper_bounds_rad: [f64; CHI_LEN],
    /// $x$ then $y$.
    pub axes: [AxisWorstCase; 2],
}

impl WorstCase {
    /// Confirmed worst cases $(\Delta\omega_x, \Delta\omega_y)$ on the exact chain, deg/h.
    #[must_use]
    pub fn exact_deg_per_h(&self) -> [f64; 2] {
        [
            self.axes[0].exact_deg_per_h(),
            self.axes[1].exact_deg_per_h(),
        ]
    }

    /// Linearised worst cases, deg/h.
    #[must_use]
    pub fn linear_deg_per_h(&self) -> [f64; 2] {
        [
            self.axes[0].linear_deg_per_h(),
            self.axes[1].linear_deg_per_h(),
        ]
    }
}

impl EndToEnd {
    /// The Jacobian $\mathbf M$ analytically: eq 26 per position chained with the derivative of
    /// the reading's error vector with respect to the orientation error.
    ///
    /// # Formula
    /// At position $i$ the rotation vector of $\Delta\mathbf R_i$ is, to first order,
    /// $\boldsymbol\delta_i = (\Delta\gamma, \Delta\psi, \Delta\theta) = \mathbf K(\phi_{2i})\chi$
    /// (eq 26), and $\mathbf v' = \Delta\mathbf R^T\mathbf v \approx \mathbf v + \mathbf v \times
    /// \boldsymbol\delta$ for $\mathbf a$ and $\boldsymbol\omega$ (eq 8). With the local first
    /// variations $d\mathbf e_i = (\boldsymbol\omega_i\times\boldsymbol\delta_i)_{axis}$ (rate),
    /// $d\mathbf g_i = \sum_j \beta_j \nabla r_j(\mathbf a_i)\cdot(\mathbf a_i\times\boldsymbol\delta_i)$
    /// (gravity), $d\mathbf b_1 = d\mathbf e + d\mathbf g$ (outputs at the actual orientation) or
    /// $0$ (intended), $d\hat{\boldsymbol\beta}_1 = \mathbf A^+ d\mathbf b_1$,
    /// $d\hat{\boldsymbol\beta}_2 = \mathbf A^+(d\mathbf b_1 - d\mathbf e - d\mathbf g)$:
    /// printed form $d\mathbf b_1 - \mathbf A\,d\hat{\boldsymbol\beta} - d\mathbf e$, nominal
    /// rate $d\mathbf b_1 - \mathbf A\,d\hat{\boldsymbol\beta}$, actual regressors subtract
    /// $d\mathbf g$ as well, $\mathbf A\Delta\boldsymbol\beta$ gives
    /// $\mathbf A(d\hat{\boldsymbol\beta}_1 - d\hat{\boldsymbol\beta}_2)$. $\nabla r\cdot\mathbf d$
    /// is evaluated as $(r(\mathbf a+\mathbf d) - r(\mathbf a-\mathbf d))/2$, exact for the
    /// quadratic regressors of eq 1.
    ///
    /// # Reference
    /// Eq 1, 8-13, 26.
    #[must_use]
    pub fn linearization(&self) -> Linearization {
        let model = LinearModel::paper_eq26();
        let n = self.len();
        let mut m = DMatrix::zeros(2 * n, CHI_LEN);
        for j in 0..CHI_LEN {
            // Per-position first variations of a and omega.
            let d: Vec<(Vector3<f64>, Vector3<f64>)> = self
                .poses()
                .iter()
                .zip(self.nominal_inputs())
                .map(|(p, inp)| {
                    let k = model.coefficients(p.phi2_rad);
                    let delta = Vector3::new(
                        k[(OrientationAxis::Gamma.index(), j)],
                        k[(OrientationAxis::Psi.index(), j)],
                        k[(OrientationAxis::Theta.index(), j)],
                    );
                    (
                        inp.specific_force_g.cross(&delta),
                        inp.rate_rad_per_s.cross(&delta),
                    )
                })
                .collect();
            for (k, axis) in AXES.into_iter().enumerate() {
                let ad = &self.axes[k];
                let de = DVector::from_iterator(n, d.iter().map(|(_, dw)| axis.rate_component(dw)));
                let dg = DVector::from_iterator(
                    n,
                    self.nominal_inputs().iter().zip(&d).map(|(inp, (da, _))| {
                        let a = inp.specific_force_g;
                        0.5 * (ad.coefficients.drift_rad_per_s(&(a + da))
                            - ad.coefficients.drift_rad_per_s(&(a - da)))
                    }),
                );
                let db1 = match self.reading().outputs {
                    OutputsAt::Actual => &de + &dg,
                    OutputsAt::Intended => DVector::zeros(n),
                };
                let dbeta_1 = &ad.pinv * &db1;
                let dbeta_2 = &ad.pinv * (&db1 - &de - &dg);
                let dbeta = match self.reading().estimate {
                    Estimate::Beta1 => &dbeta_1,
                    Estimate::Beta2 => &dbeta_2,
                };
                let col = match self.reading().form {
                    ErrorForm::Printed => &db1 - &ad.a * dbeta - &de,
                    ErrorForm::NominalRate => &db1 - &ad.a * dbeta,
                    ErrorForm::ActualRegressors => &db1 - &dg - &ad.a * dbeta - &de,
                    ErrorForm::ActualRegressorsNominalRate => &db1 - &dg - &ad.a * dbeta,
                    ErrorForm::DeltaBeta => &ad.a * (&dbeta_1 - &dbeta_2),
                };
                m.view_mut((k * n, j), (n, 1)).copy_from(&col);
            }
        }
        Linearization { m, n }
    }

    /// The Jacobian $\mathbf M$ by central differences of the reference path
    /// ([`EndToEnd::run`], calib-lsq's analysis with the exact chain):
    /// $\mathbf M_{:j} \approx (\Delta\hat{\boldsymbol\omega}(h\mathbf e_j) -
    /// \Delta\hat{\boldsymbol\omega}(-h\mathbf e_j))/(2h)$, error $O(h^2)$.
    ///
    /// # Errors
    /// [`E2eError::OutOfRange`] naming `step_rad` unless $0 < h \le 10^{-2}$;
    /// [`E2eError::Calib`] as [`EndToEnd::run`].
    pub fn linearization_numerical(&self, step_rad: f64) -> Result<Linearization, E2eError> {
        if !(step_rad > 0.0 && step_rad <= 1e-2) {
            return Err(E2eError::OutOfRange {
                field: "step_rad",
                value: step_rad,
                range: "(0, 1e-2] rad",
            });
        }
        let n = self.len();
        let mut m = DMatrix::zeros(2 * n, CHI_LEN);
        for j in 0..CHI_LEN {
            let mut chi = [0.0; CHI_LEN];
            chi[j] = step_rad;
            let plus = self.run(&chi)?;
            chi[j] = -step_rad;
            let minus = self.run(&chi)?;
            for k in 0..2 {
                let col = (&plus.analyses[k].error_vector - &minus.analyses[k].error_vector)
                    / (2.0 * step_rad);
                m.view_mut((k * n, j), (n, 1)).copy_from(&col);
            }
        }
        Ok(Linearization { m, n })
    }

    /// A derived bound $\tau$ (rad/s) on $\lVert\Delta\hat{\boldsymbol\omega}(\chi) -
    /// \mathbf M\chi\rVert_\infty$ of one axis for every $\chi$ with $\lVert\chi\rVert_1 \le s$,
    /// or `None` for a reading it is not derived for (those with
    /// $\hat{\boldsymbol\beta}_2$, $\mathbf A\Delta\boldsymbol\beta$, or actual regressors
    /// with outputs at the actual orientation).
    ///
    /// # Formula
    /// $\Delta\mathbf R = \prod_{k=1}^8 \exp(\tilde{\mathbf A}_k)$ with skew
    /// $\tilde{\mathbf A}_k$ of norm $|\chi_k|$ (the $R_z(\phi_2)$ conjugations keep norms) and
    /// $\sum_k\tilde{\mathbf A}_k = [\boldsymbol\delta]_\times$ (eq 26). Expanding the product,
    /// $\lVert\Delta\mathbf R - \mathbf I - [\boldsymbol\delta]_\times\rVert_2 \le e^s - 1 - s
    /// \le \rho = \tfrac12 s^2 e^s$, and the same for $\Delta\mathbf R^T$; the rotation angle
    /// of $\Delta\mathbf R$ is at most $s$, so $|\Delta\mathbf a| \le s$. With
    /// $|\mathbf a_i| = 1$ g and $|\boldsymbol\omega_i| = \omega_e$, the remainders of the rate
    /// and gravity perturbations are $|r_{e,i}| \le \omega_e\rho$ and
    /// $|r_{g,i}| \le \sum_j |\beta_j| c_j$ with $c_j = 0$ (constant), $\rho$ (linear
    /// regressors), $2\rho + s^2$ (quadratic regressors). The readings map them as
    /// - intended outputs: printed $-\mathbf e$: $\tau = \omega_e\rho$; nominal rate: $0$;
    ///   actual regressors $-\mathbf g - \mathbf e$; actual regressors, nominal rate
    ///   $-\mathbf g$;
    /// - actual outputs, $\hat{\boldsymbol\beta}_1$: printed
    ///   $(\mathbf I-\mathbf P)\mathbf g - \mathbf P\mathbf e$:
    ///   $\tau = \lVert\mathbf I-\mathbf P\rVert_\infty r_g + \lVert\mathbf P\rVert_\infty r_e$;
    ///   nominal rate $(\mathbf I-\mathbf P)(\mathbf g+\mathbf e)$.
    ///
    /// # Errors
    /// [`E2eError::NonFinite`]/[`E2eError::NotPositive`] naming `l1_norm_rad` if $s$ is not
    /// finite and non-negative.
    pub fn second_order_bound(
        &self,
        axis: SensingAxis,
        l1_norm_rad: f64,
    ) -> Result<Option<f64>, E2eError> {
        let s = crate::error::finite("l1_norm_rad", l1_norm_rad)?;
        if s < 0.0 {
            return Err(E2eError::NotPositive {
                field: "l1_norm_rad".into(),
                value: s,
            });
        }
        if self.reading().estimate != Estimate::Beta1 {
            return Ok(None);
        }
        let rho = 0.5 * s * s * s.exp();
        let r_e = self.site().earth_rate_rad_per_s() * rho;
        let k = match axis {
            SensingAxis::X => 0,
            SensingAxis::Y => 1,
        };
        let ad = &self.axes[k];
        let c = [
            0.0,
            rho,
            rho,
            rho,
            2.0 * rho + s * s,
            2.0 * rho + s * s,
            2.0 * rho + s * s,
        ];
        let r_g: f64 = ad
            .coefficients
            .rad_per_s()
            .iter()
            .zip(c)
            .map(|(b, c)| b.abs() * c)
            .sum();
        let tau = match (self.reading().outputs, self.reading().form) {
            (OutputsAt::Intended, ErrorForm::Printed) => Some(r_e),
            (OutputsAt::Intended, ErrorForm::NominalRate) => Some(0.0),
            (OutputsAt::Intended, ErrorForm::ActualRegressors) => Some(r_g + r_e),
            (OutputsAt::Intended, ErrorForm::ActualRegressorsNominalRate) => Some(r_g),
            (OutputsAt::Actual, ErrorForm::Printed) => {
                Some(ad.i_minus_p_norm_inf * r_g + ad.p_norm_inf * r_e)
            }
            (OutputsAt::Actual, ErrorForm::NominalRate) => {
                Some(ad.i_minus_p_norm_inf * (r_g + r_e))
            }
            _ => None,
        };
        Ok(tau)
    }

    /// The worst case over the box $|\chi_j| \le \mathrm{UB}_j$ (the lower bounds do not
    /// matter: the maximum is at $|\chi_j| = \mathrm{UB}_j$): exact for the linearised model,
    /// confirmed on the exact chain at the worst vertex, with the second-order bound.
    ///
    /// # Errors
    /// [`E2eError::Bounds`] naming the component for a negative or non-finite bound.
    pub fn worst_case(
        &self,
        linear: &Linearization,
        ub_rad: &[f64; CHI_LEN],
    ) -> Result<WorstCase, E2eError> {
        ErrorBox::from_upper_rad(*ub_rad)?;
        check_chi(ub_rad)?;
        let rows = linear.row_worst_cases(ub_rad);
        let n = self.len();
        let s: f64 = ub_rad.iter().sum();
        let mut axes = Vec::with_capacity(2);
        for (k, axis) in AXES.into_iter().enumerate() {
            let per: Vec<f64> = rows.rows(k * n, n).iter().copied().collect();
            let (position, bound) =
                per.iter()
                    .copied()
                    .enumerate()
                    .fold(
                        (0, f64::NEG_INFINITY),
                        |b, (i, v)| if v > b.1 { (i, v) } else { b },
                    );
            let row = linear.row(axis, position);
            let chi: [f64; CHI_LEN] =
                std::array::from_fn(|j| if row[j] < 0.0 { -ub_rad[j] } else { ub_rad[j] });
            let plus = self.delta_omega(&chi)?[k];
            let minus = self.delta_omega(&chi.map(|v| -v))?[k];
            axes.push(AxisWorstCase {
                axis,
                linear_bound_rad_per_s: bound,
                position,
                worst_chi_rad: if plus >= minus { chi } else { chi.map(|v| -v) },
                exact_at_vertex_rad_per_s: plus.max(minus),
                second_order_bound_rad_per_s: self.second_order_bound(axis, s)?,
                per_position_rad_per_s: per,
            });
        }
        let [x, y]: [AxisWorstCase; 2] = axes
            .try_into()
            .unwrap_or_else(|_| unreachable!("two axes pushed"));
        Ok(WorstCase {
            upper_bounds_rad: *ub_rad,
            axes: [x, y],
        })
    }
}
