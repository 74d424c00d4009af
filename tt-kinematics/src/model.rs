//! The seam [`OrientationErrorModel`] and its implementations for any turntable.

use crate::error::KinematicsError;
use crate::linear::LinearModel;
use crate::pose::TurntableErrors;
use crate::rotation::rotation_vector;
use crate::turntable::{ChainKind, Turntable};
use nalgebra::{DMatrix, Matrix3, Vector3};
use tt_core::{DeltaRKind, OrientationError, Pose};

/// Step (rad) of the central differences of [`derived_first_order`] (the default
/// [`OrientationErrorModel::first_order`]): the truncation error of a smooth model is
/// $h^2|f^{(3)}|/6 \approx 2\cdot10^{-13}$, the rounding $\epsilon/h \approx 2\cdot10^{-10}$
/// relative to the coefficients (of order 1).
pub const FIRST_ORDER_STEP_RAD: f64 = 1e-6;

/// Bound (rad per rad, on every coefficient) on the error of [`derived_first_order`] for a
/// model whose angles come from unit-size rotation-matrix entries: rounding of a few ulps of 1
/// over the difference's width $2h$ ($\approx 10^{-9}$) plus truncation $h^2|f^{(3)}|/6$ with
/// $|f^{(3)}| \le 1$ for products of rotations by the errors ($\approx 2\cdot10^{-13}$), with a
/// factor 10 to spare. Measured: at most $1.4\cdot10^{-10}$ against the analytic coefficients
/// of the paper's table and the three-axis reference table (test
/// `derived_first_order_is_within_its_stated_bound_of_the_analytic_coefficients`) and of the
/// az/el example (test `the_derived_first_order_is_the_closed_form_within_its_stated_bound`). The conformance suite checks a model's
/// own [`OrientationErrorModel::first_order`] against the derived one within it.
pub const DERIVED_FIRST_ORDER_TOLERANCE: f64 = 1e-8;

/// The $3 \times n$ first-order coefficients of `model` at `pose` derived from its exact
/// orientation error alone ($n$ = [`OrientationErrorModel::n_errors`], `n_translations`
/// translations held at zero): central differences of step [`FIRST_ORDER_STEP_RAD`] at
/// $\chi = 0$, accurate to [`DERIVED_FIRST_ORDER_TOLERANCE`]. A model written once (its
/// [`OrientationErrorModel::orientation_error`]) gets its first order, linear model and worst
/// case from this; a model that supplies an analytic first order is checked against it by
/// the conformance suite.
///
/// # Errors
/// As [`OrientationErrorModel::orientation_error`].
pub fn derived_first_order<M: OrientationErrorModel + ?Sized>(
    model: &M,
    pose: &Pose,
    n_translations: usize,
) -> Result<DMatrix<f64>, KinematicsError> {
    let n = model.n_errors();
    let base = TurntableErrors::zero(n, n_translations);
    let h = FIRST_ORDER_STEP_RAD;
    let mut out = DMatrix::zeros(3, n);
    for j in 0..n {
        let plus = model
            .orientation_error(pose, &base.clone().with_chi(j, h)?)?
            .to_array();
        let minus = model
            .orientation_error(pose, &base.clone().with_chi(j, -h)?)?
            .to_array();
        for k in 0..3 {
            out[(k, j)] = (plus[k] - minus[k]) / (2.0 * h);
        }
    }
    Ok(out)
}

/// The stated fallback for a model that knows only its angles: the rotation whose rotation
/// vector is its [`OrientationErrorModel::orientation_error`] ([`DeltaRKind::Exact`]), equal to
/// the true $\Delta\mathbf R$ to first order only. A model opts in by returning it from its
/// [`OrientationErrorModel::delta_r`]; nothing calls it silently.
///
/// # Errors
/// As [`OrientationErrorModel::orientation_error`].
pub fn delta_r_of_angles<M: OrientationErrorModel + ?Sized>(
    model: &M,
    pose: &Pose,
    errors: &TurntableErrors,
) -> Result<Matrix3<f64>, KinematicsError> {
    Ok(model
        .orientation_error(pose, errors)?
        .delta_r(DeltaRKind::Exact))
}

/// Maps a turntable pose and its geometric errors to the orientation error of the platform.
///
/// Implemented for any turntable by [`ExactChain`], [`SmallAngleChain`] and [`LinearChain`],
/// and for the paper's table by `paper::ClosedForm` (eq 26, `paper` feature); all agree to
/// first order in the errors (the conformance suite, `crate::conformance` with the
/// `conformance` feature, checks it for any implementation).
///
/// # One definition
/// A model of its own (a mount that is no [`Turntable`]) implements three methods: its
/// [`OrientationErrorModel::error_names`] (the error count is their number, checked at every
/// entry of the workspace's analyses), its exact [`OrientationErrorModel::delta_r`] and
/// [`OrientationErrorModel::orientation_error`] (the angles read off it, for example by
/// eq 24). Its first order ([`derived_first_order`]), the linear model, its worst case and the
/// certificate (`alloc_opt::Linearised`) follow; an analytic first order may be supplied and
/// is then checked against the derived one by the conformance suite. `examples/azel` in the
/// repository is a complete model defined outside the library crates, taken through Monte
/// Carlo, allocation, the exact-chain margin, end to end and the conformance suite.
///
/// ```
/// use tt_kinematics::{ExactChain, FactorSpec, OrientationErrorModel, Pose, SignedAxis,
///     Turntable, TurntableDescription, TurntableErrors};
/// let table = Turntable::new(&TurntableDescription::new(vec![
///     FactorSpec::joint("outer", SignedAxis::Y), FactorSpec::error("d_outer", SignedAxis::Z),
///     FactorSpec::joint("inner", SignedAxis::Z), FactorSpec::error("d_inner", SignedAxis::Z),
/// ]))?;
/// assert_eq!(ExactChain::new(&table).error_names(), ["d_outer", "d_inner"]);
/// let chi = TurntableErrors::from_arcmin(&[1.0, 0.5], &[])?;
/// let e = ExactChain::new(&table).orientation_error(&Pose::from_deg(&[0.0, 0.0])?, &chi)?;
/// // the two errors about z add, to second order
/// assert!((e.delta_theta_rad - 1.5_f64.to_radians() / 60.0).abs() < 1e-9);
/// # Ok::<(), tt_kinematics::KinematicsError>(())
/// ```
pub trait OrientationErrorModel {
    /// $(\Delta\psi, \Delta\theta, \Delta\gamma)$ at `pose` for turntable `errors`.
    /// Default: read off the exact [`OrientationErrorModel::delta_r`] by eq 24
    /// ([`OrientationError::from_matrix_elements`]), so a model that knows its
    /// $\Delta\mathbf R$ implements only that; a model that knows only its angles implements
    /// this. A model that implements neither gets [`KinematicsError::NoDeltaR`] (typed, at the
    /// first call; the conformance suite names it).
    ///
    /// # Errors
    /// [`KinematicsError::Field`] ([`tt_core::FieldError::Length`]) when the pose or the errors do not fit the model's
    /// turntable; [`KinematicsError::WrongTurntable`] for a model of one specific table;
    /// [`KinematicsError::NoDeltaR`] by default without [`OrientationErrorModel::delta_r`].
    fn orientation_error(
        &self,
        pose: &Pose,
        errors: &TurntableErrors,
    ) -> Result<OrientationError, KinematicsError> {
        Ok(OrientationError::from_matrix_elements(
            &self.delta_r(pose, errors)?,
        ))
    }

    /// The names of the angular errors $\chi_j$, one per error in the order of $\chi$ (lower
    /// case, as every name of the workspace). Their number is the model's error count
    /// ([`OrientationErrorModel::n_errors`]): the analyses check every box and $\chi$ against
    /// it and name both sizes when they differ.
    fn error_names(&self) -> Vec<String>;

    /// Number of angular errors $\chi_j$: the length of
    /// [`OrientationErrorModel::error_names`].
    fn n_errors(&self) -> usize {
        self.error_names().len()
    }

    /// Number of translation errors the model's [`TurntableErrors`] carry (0 by default; a
    /// described turntable's chains return the turntable's).
    fn n_translation_errors(&self) -> usize {
        0
    }

    /// $\Delta\mathbf R = \mathbf R_d^T\mathbf R_t$ (eq 23) at `pose` for `errors`, exactly.
    /// There is no silent default: a model that does not implement it gives
    /// [`KinematicsError::NoDeltaR`] where the exact rotation is needed (a schedule's
    /// $\Delta\mathbf R_i$ through [`AtPoses`], the conformance suite's rotation checks). A
    /// model that knows only its angles may opt in to their rotation, [`delta_r_of_angles`],
    /// which equals the true $\Delta\mathbf R$ to first order only.
    ///
    /// # Errors
    /// As [`OrientationErrorModel::orientation_error`]; [`KinematicsError::NoDeltaR`] by
    /// default.
    fn delta_r(
        &self,
        pose: &Pose,
        errors: &TurntableErrors,
    ) -> Result<Matrix3<f64>, KinematicsError> {
        let _ = (pose, errors);
        Err(KinematicsError::NoDeltaR)
    }

    /// The $3 \times n$ first-order coefficients $\partial(\Delta\psi, \Delta\theta,
    /// \Delta\gamma)/\partial\chi_j$ at $\chi = 0$ and `pose` (rows $\psi, \theta, \gamma$), for
    /// errors shaped as `zero` (its values are ignored: the derivative is taken at zero).
    /// Default: [`derived_first_order`] (central differences of the exact orientation error);
    /// a model that knows its coefficients returns them, and the conformance suite checks them
    /// against the derived ones.
    ///
    /// # Errors
    /// As [`OrientationErrorModel::orientation_error`]; [`KinematicsError::Field`]
    /// ([`tt_core::FieldError::Length`], naming `chi` with both sizes) when `zero` does not
    /// have the model's error count.
    fn first_order(
        &self,
        pose: &Pose,
        zero: &TurntableErrors,
    ) -> Result<DMatrix<f64>, KinematicsError> {
        tt_core::length("chi", self.n_errors(), zero.chi_rad().len())?;
        derived_first_order(self, pose, zero.translations_m().len())
    }

    /// A bound on the sum of the rotation angles whose product is
    /// [`OrientationErrorModel::delta_r`], at every pose and for every $|\chi_j| \le
    /// \mathrm{UB}_j$ (`ub_rad`, rad; the library passes finite bounds only, an unbounded error
    /// held at 0 as 0), or `None` when the model does not know one (the default). It must be a
    /// gauge of the bounds as [`ScheduleErrorModel::angle_sum_bound`] says; [`AtPoses`] passes
    /// it on, so the end-to-end analysis derives its second-order bound.
    fn angle_sum_bound(&self, ub_rad: &[f64]) -> Option<f64> {
        let _ = ub_rad;
        None
    }
}

/// A schedule-bound model: an error vector $\chi$ to $\Delta\mathbf R_i$ at each position
/// $i$ of a calibration schedule (what the end-to-end analysis needs). [`AtPoses`] makes one of
/// any [`OrientationErrorModel`] at a list of poses.
pub trait ScheduleErrorModel {
    /// Number of errors $\chi_j$.
    fn n_errors(&self) -> usize;
    /// Number of positions.
    fn n_positions(&self) -> usize;
    /// $\Delta\mathbf R_i$ of every position into `out` (one per position).
    ///
    /// # Errors
    /// [`KinematicsError`] for $\chi$ or `out` of the wrong length or a failing model.
    fn delta_r_into(
        &self,
        chi_rad: &[f64],
        out: &mut [Matrix3<f64>],
    ) -> Result<(), KinematicsError>;
    /// The errors' names (lower case, as every name of the workspace); default `chi0`, `chi1`...
    fn error_names(&self) -> Vec<String> {
        (0..self.n_errors()).map(|j| format!("chi{j}")).collect()
    }
    /// The $3\times n$ first-order coefficients (rows $\psi, \theta, \gamma$) at `position`;
    /// default: central differences of [`ScheduleErrorModel::delta_r_into`] read by eq 24.
    ///
    /// # Errors
    /// As [`ScheduleErrorModel::delta_r_into`].
    fn first_order(&self, position: usize) -> Result<DMatrix<f64>, KinematicsError> {
        let n = self.n_errors();
        let h = FIRST_ORDER_STEP_RAD;
        let mut plus = vec![Matrix3::identity(); self.n_positions()];
        let mut minus = plus.clone();
        let mut out = DMatrix::zeros(3, n);
        let mut chi = vec![0.0; n];
        for j in 0..n {
            chi[j] = h;
            self.delta_r_into(&chi, &mut plus)?;
            chi[j] = -h;
            self.delta_r_into(&chi, &mut minus)?;
            chi[j] = 0.0;
            let p = OrientationError::from_matrix_elements(&plus[position]).to_array();
            let m = OrientationError::from_matrix_elements(&minus[position]).to_array();
            for k in 0..3 {
                out[(k, j)] = (p[k] - m[k]) / (2.0 * h);
            }
        }
        Ok(out)
    }

    /// The first-order rotation vectors $\mathbf v_j$ (x, y, z components) at `position`:
    /// $\Delta\mathbf R_i \approx \mathbf I + [\sum_j\chi_j\mathbf v_j]_\times$. Default:
    /// [`ScheduleErrorModel::first_order`] read as $\mathbf v_j = (c_{\gamma j}, c_{\psi j},
    /// c_{\theta j})$ ($\Delta\gamma$ about $x$, $\Delta\psi$ about $y$, $\Delta\theta$ about
    /// $z$, eq 7 and 24).
    ///
    /// # Errors
    /// As [`ScheduleErrorModel::first_order`].
    fn rotation_vectors(&self, position: usize) -> Result<Vec<Vector3<f64>>, KinematicsError> {
        let c = self.first_order(position)?;
        Ok((0..c.ncols())
            .map(|j| Vector3::new(c[(2, j)], c[(0, j)], c[(1, j)]))
            .collect())
    }

    /// A bound $s$ on the sum of the rotation angles whose product is $\Delta\mathbf R_i$, at
    /// every position and for every $|\chi_j| \le \mathrm{UB}_j$ (`ub_rad`, rad; infinite for
    /// an error held at 0), or `None` when the model does not know one (the default). With it
    /// the end-to-end analysis derives a second-order bound on its linearisation's error; without
    /// it that bound is not claimed. It must be a gauge of the bounds (non-negative, monotone,
    /// convex and positively homogeneous of degree 1, e.g. a weighted sum $\sum_j c_j
    /// \mathrm{UB}_j$), so that its largest value over the boxes with $\sum_j \mathrm{UB}_j \le
    /// S$ is $S \max_j$ of its value at the unit boxes (what the certified allocation uses).
    fn angle_sum_bound(&self, ub_rad: &[f64]) -> Option<f64> {
        let _ = ub_rad;
        None
    }

    /// The joints' ranges (rad, one `[lo, hi]` per joint) a Monte Carlo draws a pose word for,
    /// to keep the random streams of a turntable's Monte Carlo; default none (the positions
    /// are fixed by the schedule).
    fn joint_ranges_rad(&self) -> Vec<[f64; 2]> {
        Vec::new()
    }

    /// The turntable behind the model, for the compiled fast path of the end-to-end analysis;
    /// default `None`.
    #[doc(hidden)]
    fn as_turntable_schedule(&self) -> Option<&crate::TurntableSchedule> {
        None
    }
}

/// Any [`OrientationErrorModel`] at a list of poses, as a [`ScheduleErrorModel`]: position $i$
/// is pose $i$, translation errors (if the model has any) are zero.
///
/// # Example
/// ```
/// use tt_kinematics::{paper, AtPoses, ExactChain, Pose, ScheduleErrorModel};
/// let table = paper::table3();
/// let poses = vec![Pose::from_deg(&[0.0, 0.0])?, Pose::from_deg(&[90.0, 45.0])?];
/// let names = table.rotation_error_names().iter().map(|n| n.to_string()).collect();
/// let s = AtPoses::new(ExactChain::new(&table), poses, names, 1);
/// let mut dr = vec![nalgebra::Matrix3::identity(); 2];
/// s.delta_r_into(&[0.0; 8], &mut dr)?;
/// assert_eq!(dr[1], nalgebra::Matrix3::identity());
/// # Ok::<(), tt_kinematics::KinematicsError>(())
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct AtPoses<M> {
    model: M,
    poses: Vec<Pose>,
    names: Vec<String>,
    n_translations: usize,
}

impl<M: OrientationErrorModel> AtPoses<M> {
    /// `model` at `poses`, with its errors called `error_names` (their number is the model's
    /// error count) and `n_translations` translation errors held at zero.
    #[must_use]
    pub fn new(
        model: M,
        poses: Vec<Pose>,
        error_names: Vec<String>,
        n_translations: usize,
    ) -> Self {
        Self {
            model,
            poses,
            names: error_names,
            n_translations,
        }
    }

    /// `model` at `poses`, with the model's own error names
    /// ([`OrientationErrorModel::error_names`]) and translation count.
    #[must_use]
    pub fn of(model: M, poses: Vec<Pose>) -> Self {
        let (names, n_translations) = (model.error_names(), model.n_translation_errors());
        Self::new(model, poses, names, n_translations)
    }

    /// The model.
    #[must_use]
    pub fn model(&self) -> &M {
        &self.model
    }

    /// The poses.
    #[must_use]
    pub fn poses(&self) -> &[Pose] {
        &self.poses
    }

    fn errors(&self, chi_rad: &[f64]) -> Result<TurntableErrors, KinematicsError> {
        tt_core::length("error_names", self.model.n_errors(), self.names.len())?;
        tt_core::length("chi", self.names.len(), chi_rad.len())?;
        TurntableErrors::new(chi_rad.to_vec(), vec![0.0; self.n_translations])
    }
}

impl<M: OrientationErrorModel> ScheduleErrorModel for AtPoses<M> {
    fn n_errors(&self) -> usize {
        self.names.len()
    }
    fn n_positions(&self) -> usize {
        self.poses.len()
    }
    fn delta_r_into(
        &self,
        chi_rad: &[f64],
        out: &mut [Matrix3<f64>],
    ) -> Result<(), KinematicsError> {
        tt_core::length("delta_r", self.poses.len(), out.len())?;
        let errors = self.errors(chi_rad)?;
        for (o, p) in out.iter_mut().zip(&self.poses) {
            *o = self.model.delta_r(p, &errors)?;
        }
        Ok(())
    }
    fn error_names(&self) -> Vec<String> {
        self.names.clone()
    }
    fn first_order(&self, position: usize) -> Result<DMatrix<f64>, KinematicsError> {
        self.model.first_order(
            pose_at(&self.poses, position)?,
            &self.errors(&vec![0.0; self.names.len()])?,
        )
    }
    /// The model's own ([`OrientationErrorModel::angle_sum_bound`]).
    fn angle_sum_bound(&self, ub_rad: &[f64]) -> Option<f64> {
        self.model.angle_sum_bound(ub_rad)
    }
}

/// Owned copies of borrowed names.
fn owned(names: Vec<&str>) -> Vec<String> {
    names.into_iter().map(str::to_string).collect()
}

/// The methods the chains of a described turntable ([`ExactChain`], [`SmallAngleChain`],
/// [`LinearChain`]) share, in one definition: the names of its rotation errors and its count
/// of translation errors, read from the turntable at `self.` followed by the braced path;
/// with a documented `delta_r = delta_r_of_angles`, the opt-in to the stated fallback
/// [`delta_r_of_angles`] as its $\Delta\mathbf R$.
macro_rules! turntable_chain {
    ({ $($turntable:tt)+ }) => {
        fn error_names(&self) -> Vec<String> {
            owned(self.$($turntable)+.rotation_error_names())
        }

        fn n_translation_errors(&self) -> usize {
            self.$($turntable)+.n_translation_errors()
        }
    };
    ({ $($turntable:tt)+ } $(#[$doc:meta])+ delta_r = delta_r_of_angles) => {
        turntable_chain!({ $($turntable)+ });

        $(#[$doc])+
        fn delta_r(
            &self,
            pose: &Pose,
            errors: &TurntableErrors,
        ) -> Result<Matrix3<f64>, KinematicsError> {
            delta_r_of_angles(self, pose, errors)
        }
    };
}

/// The pose of schedule position `position`, or an error naming `position`.
pub(crate) fn pose_at(poses: &[Pose], position: usize) -> Result<&Pose, KinematicsError> {
    Ok(poses
        .get(position)
        .ok_or_else(|| tt_core::FieldError::OutOfRange {
            field: "position".into(),
            value: position as f64,
            range: format!("0..{}", poses.len()),
        })?)
}

/// How the exact chain turns $\Delta\mathbf R$ into three angles (NOTES item 7).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum ReadOut {
    /// The paper's eq 24: the elements $\Delta R_{13}, \Delta R_{21}, \Delta R_{32}$. These are
    /// the angles only to first order; this is also what the paper's Monte Carlo evaluates.
    #[default]
    MatrixElements,
    /// The rotation vector of $\Delta\mathbf R$ (axis times angle, the logarithm map), whose
    /// $y$, $z$, $x$ components are $\Delta\psi, \Delta\theta, \Delta\gamma$. Exact for a single
    /// rotation; differs from [`ReadOut::MatrixElements`] at second order.
    RotationVector,
}

/// The exact chain: every error a finite rotation in the order of the description.
#[derive(Debug, Clone, PartialEq)]
pub struct ExactChain {
    turntable: Turntable,
    /// How angles are read off $\Delta\mathbf R$.
    pub readout: ReadOut,
}

impl ExactChain {
    /// The exact chain of `turntable` with the eq-24 read-out.
    #[must_use]
    pub fn new(turntable: &Turntable) -> Self {
        Self {
            turntable: turntable.clone(),
            readout: ReadOut::MatrixElements,
        }
    }

    /// The same chain with another read-out.
    #[must_use]
    pub fn with_readout(self, readout: ReadOut) -> Self {
        Self { readout, ..self }
    }
}

impl OrientationErrorModel for ExactChain {
    turntable_chain!({ turntable });

    /// $\sum_j \mathrm{UB}_j$ over the finite bounds: $\Delta\mathbf R$ is a product of
    /// rotations by the errors themselves (conjugated).
    fn angle_sum_bound(&self, ub_rad: &[f64]) -> Option<f64> {
        Some(ub_rad.iter().filter(|u| u.is_finite()).sum())
    }

    fn delta_r(
        &self,
        pose: &Pose,
        errors: &TurntableErrors,
    ) -> Result<Matrix3<f64>, KinematicsError> {
        self.turntable.delta_r(pose, errors, ChainKind::Exact)
    }

    fn first_order(
        &self,
        pose: &Pose,
        zero: &TurntableErrors,
    ) -> Result<DMatrix<f64>, KinematicsError> {
        tt_core::length(
            "chi",
            self.turntable.n_rotation_errors(),
            zero.chi_rad().len(),
        )?;
        LinearModel::new(&self.turntable).coefficients(pose)
    }

    fn orientation_error(
        &self,
        pose: &Pose,
        errors: &TurntableErrors,
    ) -> Result<OrientationError, KinematicsError> {
        let dr = self.turntable.delta_r(pose, errors, ChainKind::Exact)?;
        Ok(match self.readout {
            ReadOut::MatrixElements => OrientationError::from_matrix_elements(&dr),
            ReadOut::RotationVector => {
                let v = rotation_vector(&dr);
                OrientationError {
                    delta_psi_rad: v.y,
                    delta_theta_rad: v.z,
                    delta_gamma_rad: v.x,
                }
            }
        })
    }
}

/// The chain with every run of consecutive error rotations replaced by one small-angle matrix
/// $I + [\delta]_\times$ ([`ChainKind::SmallAngle`]; eq 17-19 as printed for the paper's table),
/// read out by eq 24.
#[derive(Debug, Clone, PartialEq)]
pub struct SmallAngleChain {
    turntable: Turntable,
}

impl SmallAngleChain {
    /// The small-angle chain of `turntable`.
    #[must_use]
    pub fn new(turntable: &Turntable) -> Self {
        Self {
            turntable: turntable.clone(),
        }
    }
}

impl OrientationErrorModel for SmallAngleChain {
    turntable_chain!(
        { turntable }
        /// The rotation of its angles (stated fallback: the small-angle chain's own matrix is
        /// not a rotation).
        delta_r = delta_r_of_angles
    );

    fn orientation_error(
        &self,
        pose: &Pose,
        errors: &TurntableErrors,
    ) -> Result<OrientationError, KinematicsError> {
        Ok(OrientationError::from_matrix_elements(
            &self
                .turntable
                .delta_r(pose, errors, ChainKind::SmallAngle)?,
        ))
    }
}

/// The first-order model ([`LinearModel`]) as an [`OrientationErrorModel`].
#[derive(Debug, Clone, PartialEq)]
pub struct LinearChain {
    model: LinearModel,
}

impl LinearChain {
    /// The first-order model of `turntable`.
    #[must_use]
    pub fn new(turntable: &Turntable) -> Self {
        Self {
            model: LinearModel::new(turntable),
        }
    }
}

impl OrientationErrorModel for LinearChain {
    turntable_chain!(
        { model.turntable() }
        /// The rotation of its (first-order) angles: a first-order model has no exact
        /// $\Delta\mathbf R$ (stated fallback).
        delta_r = delta_r_of_angles
    );

    fn first_order(
        &self,
        pose: &Pose,
        zero: &TurntableErrors,
    ) -> Result<DMatrix<f64>, KinematicsError> {
        tt_core::length("chi", self.model.n_errors(), zero.chi_rad().len())?;
        self.model.coefficients(pose)
    }

    fn orientation_error(
        &self,
        pose: &Pose,
        errors: &TurntableErrors,
    ) -> Result<OrientationError, KinematicsError> {
        self.model.evaluate(pose, errors)
    }
}
