//! Which table errors the calibration can estimate itself (issue 22, item 4): a joint least
//! squares of the sensor coefficients and the turntable's angular errors from the same
//! schedule data, with the outputs simulated at the actual orientation (the user's reading of
//! eq 13; under the paper's reading the outputs do not depend on the table and nothing is
//! estimable).
//!
//! The table's part of the joint Jacobian at $\chi = 0$ is, per output, the first-order
//! effect of each error on the outputs at the test positions, $\mathbf D_k = d\mathbf g +
//! d\mathbf e$ ([`crate::EstimableQuestions::table_effects`]: the linearisation of the reading whose error
//! vector is exactly $\mathbf g + \mathbf e$). calib-lsq's
//! [`JointEstimability`] gives the rank, the estimable
//! and the invisible combinations (rows weighted by $1/\omega_{m,k}$).
//!
//! # The allocation when the estimable errors are estimated
//! The joint estimator fits $\boldsymbol\beta$ and the estimable part $\Pi_E\chi$; the user
//! then evaluates the calibrated model at the orientation it estimated. To first order the
//! estimable part is recovered exactly and the coefficients absorb the invisible part's
//! effect (it lies in their columns), so the error vectors are those of the ordinary
//! calibration for the table error $\Pi_N\chi$: $\Delta\hat{\boldsymbol\omega} \approx
//! \mathbf M\,\Pi_N\chi$ ([`crate::EstimableQuestions::linearization_joint`]). An error with $\Pi_N\mathbf
//! e_j = 0$ needs no bound; the direct allocation of the rest takes that matrix unchanged.

use crate::angle::{AngleLinearization, check_expansion};
use crate::error::E2eError;
use crate::linear::Linearization;
use calib_lsq::joint::{JointBlock, JointEstimability, joint_step};
use calib_lsq::{ErrorForm, Estimate, OutputsAt, Reading, design_matrix, known_vector};
use nalgebra::{DMatrix, DVector, Matrix3};
use tt_kinematics::{ChainKind, Expansion};

/// The reading whose error vector is exactly the table's effect on the outputs,
/// $(\mathbf b_1 - \mathbf A\hat{\boldsymbol\beta}_2) - \mathbf b_2 = \mathbf g + \mathbf e$.
const EFFECT_READING: Reading = Reading {
    outputs: OutputsAt::Actual,
    estimate: Estimate::Beta2,
    form: ErrorForm::NominalRate,
};

/// Step of the central differences of the Gauss-Newton Jacobian (rad): the table part is
/// smooth (rotations), so the truncation error $O(h^2)$ is about $10^{-14}$ relative.
pub(crate) const JOINT_FD_STEP_RAD: f64 = 1e-7;

/// The rotations $\Delta\mathbf R_i$ of every test position for a parameter vector.
type DeltaRFn<'a> = dyn Fn(&[f64]) -> Result<Vec<Matrix3<f64>>, E2eError> + 'a;

/// The result of [`crate::EstimableQuestions::joint_estimate`].
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct JointEstimate {
    /// The estimated table errors (rad, order of $\chi$), in the estimable subspace.
    pub(crate) chi_rad: Vec<f64>,
    /// The estimated coefficients of every output (the estimated terms' order).
    pub(crate) coefficients: Vec<DVector<f64>>,
    /// The size of every Gauss-Newton step in the table errors, $\lVert\Delta\chi\rVert_2$
    /// (rad), first to last.
    pub(crate) steps_rad: Vec<f64>,
    /// Weighted residual norm at the end, $\lVert[(\mathbf b_{1,k} - \mathbf f_k)/\omega_{m,k}]_k
    /// \rVert_2$ (dimensionless).
    pub(crate) residual: f64,
}

/// Read access to the fields (crate-private, so the type can grow without breaking callers).
impl JointEstimate {
    /// The estimated table errors (rad, order of $\chi$), in the estimable subspace.
    #[must_use]
    pub fn chi_rad(&self) -> &[f64] {
        &self.chi_rad
    }

    /// The estimated coefficients of every output (the estimated terms' order).
    #[must_use]
    pub fn coefficients(&self) -> &[DVector<f64>] {
        &self.coefficients
    }

    /// The size of every Gauss-Newton step in the table errors, $\lVert\Delta\chi\rVert_2$
    /// (rad), first to last.
    #[must_use]
    pub fn steps_rad(&self) -> &[f64] {
        &self.steps_rad
    }

    /// Weighted residual norm at the end, $\lVert[(\mathbf b_{1,k} - \mathbf f_k)/\omega_{m,k}]_k
    /// \rVert_2$ (dimensionless).
    #[must_use]
    pub fn residual(&self) -> f64 {
        self.residual
    }
}

impl crate::EstimableQuestions<'_> {
    /// $\mathbf D_k$ of every output ($n \times$ errors, output unit per rad): the first-order
    /// effect of each angular error on the outputs at the test positions, simulated at the
    /// actual orientation.
    ///
    /// # Errors
    /// As [`crate::EndToEnd::with_reading`].
    pub fn table_effects(&self) -> Result<Vec<DMatrix<f64>>, E2eError> {
        self.static_only("the joint estimation of table errors")?;
        Ok(self.split_outputs(&self.with_reading(EFFECT_READING)?.linearization()))
    }

    /// [`crate::EstimableQuestions::table_effects`] with the errors expanded into the coefficients of
    /// `expansion` (errors that vary with a shaft angle, [`crate::angle`]): one column per
    /// coefficient, the error's effect at each position scaled by the coefficient's basis
    /// value there. With every error constant it is [`crate::EstimableQuestions::table_effects`].
    ///
    /// # Errors
    /// As [`crate::EstimableQuestions::table_effects`] and [`crate::AngleQuestions::linearization_expanded`].
    pub(crate) fn table_effects_expanded(
        &self,
        expansion: &Expansion,
    ) -> Result<Vec<DMatrix<f64>>, E2eError> {
        self.static_only("the joint estimation of table errors")?;
        let lin = self
            .with_reading(EFFECT_READING)?
            .angle()
            .linearization_expanded(expansion)?;
        Ok(self.split_outputs(&lin))
    }

    /// Every output's rows of a first-order model (rows output-major).
    fn split_outputs(&self, lin: &Linearization) -> Vec<DMatrix<f64>> {
        let n = self.len();
        (0..self.n_outputs())
            .map(|k| lin.matrix().rows(k * n, n).clone_owned())
            .collect()
    }

    /// The estimability of the angular errors together with the sensor coefficients (the
    /// [module](self)): rows weighted by $1/\omega_{m,k}$.
    ///
    /// # Errors
    /// As [`crate::EstimableQuestions::table_effects`] and [`JointEstimability::new`].
    pub fn estimability(&self) -> Result<JointEstimability, E2eError> {
        let names: Vec<String> = self
            .turntable()
            .rotation_error_names()
            .into_iter()
            .map(String::from)
            .collect();
        self.estimability_of(&self.table_effects()?, &names)
    }

    /// The estimability of the coefficients of `expansion` (the study's model of errors that
    /// vary with a shaft angle: each error's constant and harmonic coefficients, or its value
    /// at each angle) together with the sensor coefficients: [`crate::EstimableQuestions::estimability`] with
    /// the parameters named by [`Expansion::coefficient_names`].
    ///
    /// # Errors
    /// As [`crate::EstimableQuestions::table_effects_expanded`] and [`JointEstimability::new`].
    pub fn estimability_expanded(
        &self,
        expansion: &Expansion,
    ) -> Result<JointEstimability, E2eError> {
        let effects = self.table_effects_expanded(expansion)?;
        self.estimability_of(&effects, &expansion.coefficient_names())
    }

    fn estimability_of(
        &self,
        effects: &[DMatrix<f64>],
        names: &[String],
    ) -> Result<JointEstimability, E2eError> {
        self.static_only("the joint estimation of table errors")?;
        let acc = self.accuracies();
        let blocks: Vec<JointBlock<'_>> = self
            .calibration()
            .outputs()
            .iter()
            .zip(effects)
            .zip(&acc)
            .map(|((cal, d), a)| JointBlock {
                regression: cal.regression(),
                effects: d,
                weight: 1.0 / a,
            })
            .collect();
        Ok(JointEstimability::new(names, &blocks)?)
    }

    /// The first-order model of this simulator's reading when the estimable errors are
    /// estimated jointly: $\mathbf M\,\Pi_N$ (see the [module](self)), with the rounding level
    /// of column $j$ taken as $\sum_l \text{level}_l\,\lvert(\Pi_N)_{lj}\rvert$. Meant for
    /// the user's reading.
    ///
    /// # Errors
    /// A length error when `est` is not of this turntable.
    pub fn linearization_joint(&self, est: &JointEstimability) -> Result<Linearization, E2eError> {
        self.static_only("the joint estimation of table errors")?;
        tt_core::length("estimability errors", self.n_errors(), est.names().len())
            .map_err(|e| E2eError::Kinematics(e.into()))?;
        let lin = self.linearization();
        let pi = est.invisible_projector();
        let m = lin.matrix() * &pi;
        let noise = lin.rounding() * pi.abs();
        Ok(Linearization::from_parts(
            m,
            self.len(),
            self.n_outputs(),
            noise,
        ))
    }

    /// [`crate::EstimableQuestions::linearization_joint`] for errors expanded into the coefficients of
    /// `expansion` (`est` from [`crate::EstimableQuestions::estimability_expanded`]): the expanded model
    /// $\mathbf M_c\,\Pi_N$ and its reduction to one column per error by the dual norms of
    /// each error's bound set ([`crate::AngleQuestions::angle_linearization`]), which the direct allocation
    /// takes unchanged.
    ///
    /// # Errors
    /// A length error when `est` is not of this expansion; as
    /// [`crate::AngleQuestions::linearization_expanded`].
    pub fn linearization_joint_expanded(
        &self,
        expansion: &Expansion,
        est: &JointEstimability,
    ) -> Result<AngleLinearization, E2eError> {
        self.static_only("the joint estimation of table errors")?;
        tt_core::length(
            "estimability coefficients",
            expansion.n_coefficients(),
            est.names().len(),
        )
        .map_err(|e| E2eError::Kinematics(e.into()))?;
        let lin = self.angle().linearization_expanded(expansion)?;
        let pi = est.invisible_projector();
        let m = lin.matrix() * &pi;
        let noise = lin.rounding() * pi.abs();
        let joint = Linearization::from_parts(m, self.len(), self.n_outputs(), noise);
        Ok(self.angle().reduce_expanded(expansion, joint))
    }

    /// The outputs $\mathbf f_k = \mathbf A_k'\boldsymbol\beta_k + \mathbf b_{2,k}'$ of a sensor
    /// with the estimated terms' coefficients `coefficients[k]` (the study's known terms) on
    /// the turntable with errors `chi_rad`, at the actual orientation of every position (exact
    /// chain); with the study's coefficients, the data of a noiseless calibration.
    ///
    /// # Errors
    /// Lengths; a non-finite $\chi$ (as [`crate::EndToEnd::delta_r_reference`]).
    pub fn outputs_at(
        &self,
        chi_rad: &[f64],
        coefficients: &[DVector<f64>],
    ) -> Result<Vec<DVector<f64>>, E2eError> {
        self.outputs_at_dr(&self.delta_r_reference(chi_rad)?, coefficients)
    }

    /// [`crate::EstimableQuestions::outputs_at`] for the coefficients `c` of `expansion` (errors that vary
    /// with a shaft angle: the exact chain at $\chi(\phi_i)$ at every position).
    ///
    /// # Errors
    /// As [`crate::EstimableQuestions::outputs_at`]; an expansion not of this schedule.
    pub fn outputs_at_expanded(
        &self,
        expansion: &Expansion,
        c: &[f64],
        coefficients: &[DVector<f64>],
    ) -> Result<Vec<DVector<f64>>, E2eError> {
        self.outputs_at_dr(&self.delta_r_expanded(expansion, c)?, coefficients)
    }

    /// $\Delta\mathbf R_i$ of every position for the coefficients `c` of `expansion` (exact
    /// chain at $\chi(\phi_i)$).
    fn delta_r_expanded(
        &self,
        expansion: &Expansion,
        c: &[f64],
    ) -> Result<Vec<Matrix3<f64>>, E2eError> {
        check_expansion(self, expansion)?;
        let zero = vec![0.0; self.turntable().n_translation_errors()];
        Ok(self
            .poses()
            .iter()
            .enumerate()
            .map(|(i, pose)| {
                let x = expansion.errors_at(c, i, &zero)?;
                self.turntable().delta_r(pose, &x, ChainKind::Exact)
            })
            .collect::<Result<Vec<_>, tt_kinematics::KinematicsError>>()?)
    }

    fn outputs_at_dr(
        &self,
        dr: &[Matrix3<f64>],
        coefficients: &[DVector<f64>],
    ) -> Result<Vec<DVector<f64>>, E2eError> {
        let cal = self.calibration();
        tt_core::length("coefficients", self.n_outputs(), coefficients.len())
            .map_err(|e| E2eError::Kinematics(e.into()))?;
        let actual = cal.schedule().actual_inputs(cal.site(), dr)?;
        cal.outputs()
            .iter()
            .zip(coefficients)
            .map(|(oc, beta)| {
                let o = oc.output();
                tt_core::length("coefficients", o.n_estimated(), beta.len())
                    .map_err(|e| E2eError::Kinematics(e.into()))?;
                Ok(design_matrix(o, &actual) * beta + known_vector(o, &actual))
            })
            .collect()
    }

    /// The study's coefficients of the estimated terms of every output.
    #[must_use]
    pub fn true_coefficients(&self) -> Vec<DVector<f64>> {
        self.calibration()
            .outputs()
            .iter()
            .map(|oc| oc.beta().clone())
            .collect()
    }

    /// The joint estimator: Gauss-Newton from $\chi = 0$ (and the ordinary calibration's
    /// coefficients there) on the exact chain for the outputs
    /// `b1` (one vector per output), fitting every output's coefficients and the table errors
    /// in the estimable subspace of `est` ($\chi = \mathbf E\mathbf z$), at most `iterations`
    /// steps or until a step in $\chi$ is below `tol_rad`. The coefficients' Jacobian at an
    /// iterate is $\mathbf A_k'$ exactly; the table's by central differences
    /// (`JOINT_FD_STEP_RAD`); each step by [`joint_step`] with rows weighted by
    /// $1/\omega_{m,k}$.
    ///
    /// # Errors
    /// As [`crate::EstimableQuestions::outputs_at`]; [`E2eError::Calib`] when a step's system is rank deficient.
    pub fn joint_estimate(
        &self,
        b1: &[DVector<f64>],
        est: &JointEstimability,
        iterations: usize,
        tol_rad: f64,
    ) -> Result<JointEstimate, E2eError> {
        tt_core::length("estimability errors", self.n_errors(), est.names().len())
            .map_err(|err| E2eError::Kinematics(err.into()))?;
        self.joint_fit(
            &|chi| self.delta_r_reference(chi),
            b1,
            est,
            iterations,
            tol_rad,
        )
    }

    /// [`crate::EstimableQuestions::joint_estimate`] for errors expanded into the coefficients of `expansion`
    /// (`est` from [`crate::EstimableQuestions::estimability_expanded`]): the estimated parameters
    /// ([`JointEstimate::chi_rad`]) are the expansion's coefficients (rad), in its estimable
    /// subspace.
    ///
    /// # Errors
    /// As [`crate::EstimableQuestions::joint_estimate`]; an expansion not of this schedule.
    pub fn joint_estimate_expanded(
        &self,
        expansion: &Expansion,
        b1: &[DVector<f64>],
        est: &JointEstimability,
        iterations: usize,
        tol_rad: f64,
    ) -> Result<JointEstimate, E2eError> {
        check_expansion(self, expansion)?;
        tt_core::length(
            "estimability coefficients",
            expansion.n_coefficients(),
            est.names().len(),
        )
        .map_err(|err| E2eError::Kinematics(err.into()))?;
        self.joint_fit(
            &|c| self.delta_r_expanded(expansion, c),
            b1,
            est,
            iterations,
            tol_rad,
        )
    }

    /// Gauss-Newton of [`crate::EstimableQuestions::joint_estimate`] for parameters $\mathbf x$ (one per row
    /// of `est`'s estimable basis) whose rotations at the test positions `delta_r` gives.
    fn joint_fit(
        &self,
        delta_r: &DeltaRFn<'_>,
        b1: &[DVector<f64>],
        est: &JointEstimability,
        iterations: usize,
        tol_rad: f64,
    ) -> Result<JointEstimate, E2eError> {
        let e = est.estimable_basis();
        let r = e.ncols();
        let cal = self.calibration();
        let acc = self.accuracies();
        let mut z = DVector::zeros(r);
        tt_core::length("outputs", self.n_outputs(), b1.len())
            .map_err(|err| E2eError::Kinematics(err.into()))?;
        // start: the ordinary calibration (chi = 0), beta = A+ (b1 - b2)
        let mut beta: Vec<DVector<f64>> = cal
            .outputs()
            .iter()
            .zip(b1)
            .map(|(oc, b)| {
                tt_core::length("outputs", oc.b2().len(), b.len())
                    .map_err(|err| E2eError::Kinematics(err.into()))?;
                Ok(oc.regression().pinv() * (b - oc.b2()))
            })
            .collect::<Result<_, E2eError>>()?;
        let mut steps = Vec::new();
        let chi_of = |z: &DVector<f64>| -> Vec<f64> { (e * z).iter().copied().collect() };
        let f_of = |z: &DVector<f64>, beta: &[DVector<f64>]| {
            self.outputs_at_dr(&delta_r(&chi_of(z))?, beta)
        };
        for _ in 0..iterations {
            let dr = delta_r(&chi_of(&z))?;
            let f = self.outputs_at_dr(&dr, &beta)?;
            let actual = cal.schedule().actual_inputs(cal.site(), &dr)?;
            let a: Vec<DMatrix<f64>> = cal
                .outputs()
                .iter()
                .map(|oc| design_matrix(oc.output(), &actual))
                .collect();
            let mut d: Vec<DMatrix<f64>> = f.iter().map(|fk| DMatrix::zeros(fk.len(), r)).collect();
            for c in 0..r {
                let h = JOINT_FD_STEP_RAD;
                let mut zp = z.clone();
                zp[c] += h;
                let mut zm = z.clone();
                zm[c] -= h;
                let fp = f_of(&zp, &beta)?;
                let fm = f_of(&zm, &beta)?;
                for (k, dk) in d.iter_mut().enumerate() {
                    dk.set_column(c, &((&fp[k] - &fm[k]) / (2.0 * h)));
                }
            }
            let res: Vec<DVector<f64>> = b1.iter().zip(&f).map(|(b, fk)| b - fk).collect();
            let blocks: Vec<(&DMatrix<f64>, &DMatrix<f64>, f64)> = a
                .iter()
                .zip(&d)
                .zip(&acc)
                .map(|((ak, dk), w)| (ak, dk, 1.0 / w))
                .collect();
            let (db, dz) = joint_step(&blocks, &res)?;
            for (bk, dbk) in beta.iter_mut().zip(db) {
                *bk += dbk;
            }
            z += &dz;
            let step = (e * &dz).norm();
            steps.push(step);
            if step <= tol_rad {
                break;
            }
        }
        let chi = chi_of(&z);
        let f = f_of(&z, &beta)?;
        let res: Vec<DVector<f64>> = b1.iter().zip(&f).map(|(b, fk)| b - fk).collect();
        let residual = weighted_norm(&res, &acc);
        Ok(JointEstimate {
            chi_rad: chi,
            coefficients: beta,
            steps_rad: steps,
            residual,
        })
    }

    /// $\Delta\omega_k$ of every output (output unit) when the calibration is the joint
    /// estimator ([`crate::EstimableQuestions::joint_estimate`] with `iterations` steps from the noiseless
    /// outputs of the turntable `chi_rad`, exact chain): the user evaluates the calibrated model
    /// at the estimated orientation, $\Delta\hat\omega_i = b_{1,i} - (\mathbf
    /// A(\hat\chi)\hat{\boldsymbol\beta})_i - b'_{2,i}$ (eq 13's printed form with the
    /// estimated actual regressors), $\Delta\omega_k = \max_i\lvert\Delta\hat\omega_i\rvert$.
    /// To first order it is the ordinary calibration's error for $\Pi_N\chi$
    /// ([`crate::EstimableQuestions::linearization_joint`]).
    ///
    /// # Errors
    /// As [`crate::EstimableQuestions::joint_estimate`].
    pub fn joint_delta_omega(
        &self,
        chi_rad: &[f64],
        est: &JointEstimability,
        iterations: usize,
    ) -> Result<Vec<f64>, E2eError> {
        let beta = self.true_coefficients();
        let b1 = self.outputs_at(chi_rad, &beta)?;
        let j = self.joint_estimate(&b1, est, iterations, 0.0)?;
        let dr = self.delta_r_reference(chi_rad)?;
        let dr_hat = self.delta_r_reference(&j.chi_rad)?;
        self.joint_rate_errors(&b1, &dr, &dr_hat, &j)
    }

    /// [`crate::EstimableQuestions::joint_delta_omega`] for a turntable whose errors are the coefficients `c`
    /// of `expansion` (errors that vary with a shaft angle), the joint estimator fitting the
    /// expansion's coefficients ([`crate::EstimableQuestions::joint_estimate_expanded`]).
    ///
    /// # Errors
    /// As [`crate::EstimableQuestions::joint_estimate_expanded`].
    pub fn joint_delta_omega_expanded(
        &self,
        expansion: &Expansion,
        c: &[f64],
        est: &JointEstimability,
        iterations: usize,
    ) -> Result<Vec<f64>, E2eError> {
        let beta = self.true_coefficients();
        let dr = self.delta_r_expanded(expansion, c)?;
        let b1 = self.outputs_at_dr(&dr, &beta)?;
        let j = self.joint_estimate_expanded(expansion, &b1, est, iterations, 0.0)?;
        let dr_hat = self.delta_r_expanded(expansion, &j.chi_rad)?;
        self.joint_rate_errors(&b1, &dr, &dr_hat, &j)
    }

    /// $\Delta\omega_k$ of every output of the joint estimate `j` from the outputs `b1` of
    /// the table whose rotations are `dr`, evaluated at the estimated rotations `dr_hat`.
    fn joint_rate_errors(
        &self,
        b1: &[DVector<f64>],
        dr: &[Matrix3<f64>],
        dr_hat: &[Matrix3<f64>],
        j: &JointEstimate,
    ) -> Result<Vec<f64>, E2eError> {
        let cal = self.calibration();
        let actual = cal.schedule().actual_inputs(cal.site(), dr)?;
        let estimated = cal.schedule().actual_inputs(cal.site(), dr_hat)?;
        Ok(cal
            .outputs()
            .iter()
            .zip(b1)
            .zip(&j.coefficients)
            .map(|((oc, b), bh)| {
                let o = oc.output();
                (b - design_matrix(o, &estimated) * bh - known_vector(o, &actual)).amax()
            })
            .collect())
    }
}

fn weighted_norm(res: &[DVector<f64>], acc: &[f64]) -> f64 {
    res.iter()
        .zip(acc)
        .map(|(r, a)| (r / *a).norm_squared())
        .sum::<f64>()
        .sqrt()
}
