//! The conformance suite (library code behind the `conformance` feature) run on every model
//! of this crate, for the paper's table and a three-axis table, and shown to fail on a wrong
//! model.

mod common;

use common::*;
use tt_kinematics::conformance::{Tolerances, cases, cases_in, check_model, check_model_general};
use tt_kinematics::paper::ClosedForm;
use tt_kinematics::{
    ExactChain, KinematicsError, LinearChain, OrientationError, OrientationErrorModel, Pose,
    ReadOut, SmallAngleChain, Turntable, TurntableErrors,
};

fn all_models(t: &Turntable) -> Vec<(&'static str, Box<dyn OrientationErrorModel>)> {
    vec![
        ("exact", Box::new(ExactChain::new(t))),
        (
            "exact, rotation vector",
            Box::new(ExactChain::new(t).with_readout(ReadOut::RotationVector)),
        ),
        ("small-angle", Box::new(SmallAngleChain::new(t))),
        ("linear", Box::new(LinearChain::new(t))),
    ]
}

#[test]
fn every_model_passes_the_conformance_suite_on_the_paper_table() {
    let t = table3();
    let c = cases(&t, 200, MAX_ERROR_RAD);
    let mut models = all_models(&t);
    models.push(("eq 26", Box::new(ClosedForm)));
    for (name, m) in models {
        check_model(m.as_ref(), &t, &c, &Tolerances::default())
            .unwrap_or_else(|f| panic!("{name}: {f}"));
    }
}

#[test]
fn every_model_passes_the_conformance_suite_on_a_three_axis_table() {
    let t = three_axis();
    let c = cases(&t, 200, MAX_ERROR_RAD);
    for (name, m) in all_models(&t) {
        check_model(m.as_ref(), &t, &c, &Tolerances::default())
            .unwrap_or_else(|f| panic!("{name}: {f}"));
    }
}

/// A wrong model of a turntable, a mutation of its exact chain: the suite must reject it, so
/// it can fail.
struct Mutant(Turntable, Mutation);

/// The mutations of the exact chain.
#[derive(Clone, Copy)]
enum Mutation {
    /// A sign error in one angle: "Delta-R = R_t^T R_d".
    Transposed,
    /// R_d^T forgotten (the leading joint does not cancel).
    NoRdTranspose,
}

impl OrientationErrorModel for Mutant {
    fn error_names(&self) -> Vec<String> {
        self.0
            .rotation_error_names()
            .into_iter()
            .map(str::to_string)
            .collect()
    }
    fn orientation_error(
        &self,
        pose: &Pose,
        errors: &TurntableErrors,
    ) -> Result<OrientationError, KinematicsError> {
        let exact = tt_kinematics::ChainKind::Exact;
        let m = match self.1 {
            Mutation::Transposed => self.0.delta_r(pose, errors, exact)?.transpose(),
            Mutation::NoRdTranspose => {
                self.0.actual_rotation(pose, errors, exact)? - nalgebra::Matrix3::identity()
            }
        };
        Ok(OrientationError::from_matrix_elements(&m))
    }
}

#[test]
fn the_suite_rejects_wrong_models() {
    for t in [table3(), three_axis()] {
        let c = cases(&t, 50, MAX_ERROR_RAD);
        for (mutation, check) in [
            (Mutation::Transposed, "first-order"),
            (Mutation::NoRdTranspose, "zero"),
        ] {
            let m = Mutant(t.clone(), mutation);
            let f = check_model(&m, &t, &c, &Tolerances::default()).unwrap_err();
            assert_eq!(f.check(), check, "{f}");
        }
    }
    // eq 26 is a model of the paper's table only (8 errors): the suite names both counts
    let t = three_axis();
    let f = check_model(&ClosedForm, &t, &cases(&t, 3, 1e-4), &Tolerances::default()).unwrap_err();
    assert_eq!(f.check(), "error-count", "{f}");
    assert!(f.detail().contains("13 errors, the model names 8"), "{f}");
}

/// A correct model whose declared first-order coefficients are doubled: the general suite,
/// which compares a model with its OWN `first_order` (no turntable involved), rejects it.
struct DoubledCoefficients(ExactChain);

impl OrientationErrorModel for DoubledCoefficients {
    fn error_names(&self) -> Vec<String> {
        self.0.error_names()
    }
    fn orientation_error(
        &self,
        pose: &Pose,
        errors: &TurntableErrors,
    ) -> Result<OrientationError, KinematicsError> {
        self.0.orientation_error(pose, errors)
    }
    fn first_order(
        &self,
        pose: &Pose,
        zero: &TurntableErrors,
    ) -> Result<nalgebra::DMatrix<f64>, KinematicsError> {
        Ok(self.0.first_order(pose, zero)? * 2.0)
    }
}

#[test]
fn the_general_suite_checks_a_model_against_its_own_first_order() {
    for t in [table3(), three_axis()] {
        let zero = t.zero_errors();
        let c = cases_in(
            &t.joint_ranges_rad(),
            t.n_rotation_errors(),
            t.n_translation_errors(),
            50,
            MAX_ERROR_RAD,
        );
        check_model_general(&ExactChain::new(&t), &zero, &c, &Tolerances::default())
            .unwrap_or_else(|f| panic!("{f}"));
        // the default (central differences) first order of the small-angle chain passes too
        check_model_general(&SmallAngleChain::new(&t), &zero, &c, &Tolerances::default())
            .unwrap_or_else(|f| panic!("{f}"));
        let f = check_model_general(
            &DoubledCoefficients(ExactChain::new(&t)),
            &zero,
            &c,
            &Tolerances::default(),
        )
        .unwrap_err();
        assert_eq!(f.check(), "derived-first-order", "{f}");
    }
}

/// Central differences with h = 1e-6 rad: truncation O(h^2) ~ 1e-12 and rounding ~ eps/h
/// ~ 2e-10 per unit coefficient; 1e-8 bounds both with room.
const CENTRAL_DIFFERENCE_TOL: f64 = 1e-8;

#[test]
fn the_default_first_order_equals_the_linear_model_coefficients() {
    for t in [table3(), three_axis()] {
        let zero = t.zero_errors();
        for case in cases(&t, 10, MAX_ERROR_RAD) {
            let analytic = ExactChain::new(&t).first_order(&case.pose, &zero).unwrap();
            let numeric = SmallAngleChain::new(&t)
                .first_order(&case.pose, &zero)
                .unwrap();
            assert_eq!(analytic.shape(), (3, t.n_rotation_errors()));
            for (a, b) in analytic.iter().zip(numeric.iter()) {
                approx::assert_abs_diff_eq!(a, b, epsilon = CENTRAL_DIFFERENCE_TOL);
            }
        }
    }
}

#[test]
fn at_poses_gives_the_models_delta_r_and_first_order_at_each_position() {
    use tt_kinematics::{AtPoses, ScheduleErrorModel};
    let t = three_axis();
    let c = cases(&t, 4, MAX_ERROR_RAD);
    let poses: Vec<Pose> = c.iter().map(|k| k.pose.clone()).collect();
    let names: Vec<String> = t
        .rotation_error_names()
        .iter()
        .map(|n| n.to_string())
        .collect();
    let s = AtPoses::new(
        ExactChain::new(&t),
        poses.clone(),
        names.clone(),
        t.n_translation_errors(),
    );
    assert_eq!(s.n_positions(), 4);
    assert_eq!(s.error_names(), names);
    let chi = c[0].errors.chi_rad().to_vec();
    let mut dr = vec![nalgebra::Matrix3::identity(); 4];
    s.delta_r_into(&chi, &mut dr).unwrap();
    let errors = TurntableErrors::new(chi.clone(), vec![0.0; t.n_translation_errors()]).unwrap();
    for (i, p) in poses.iter().enumerate() {
        let want = t
            .delta_r(p, &errors, tt_kinematics::ChainKind::Exact)
            .unwrap();
        assert_eq!(dr[i], want);
        // AtPoses's first order is the model's own (here the turntable's coefficients)
        let own = s.first_order(i).unwrap();
        let lm = tt_kinematics::LinearModel::new(&t).coefficients(p).unwrap();
        for (a, b) in own.iter().zip(lm.iter()) {
            approx::assert_abs_diff_eq!(a, b, epsilon = CENTRAL_DIFFERENCE_TOL);
        }
    }
    // wrong lengths are typed errors naming the field
    let e = s.delta_r_into(&chi[1..], &mut dr).unwrap_err();
    assert!(e.to_string().contains("chi"), "{e}");
}

/// A mount whose "flexure" stretches the platform instead of turning it (wrong physics:
/// $\Delta\mathbf R = \mathbf I + [\boldsymbol\delta]_\times + \chi_1\,\mathrm{diag}(1, 0, 0)$
/// composed with the exact chain), with the angles read off it by eq 24 and the default
/// (derived) first order: self-consistent, so the checks against its own first order pass;
/// the physics checks (a rotation) reject it.
struct Stretching(ExactChain);

impl OrientationErrorModel for Stretching {
    fn error_names(&self) -> Vec<String> {
        self.0.error_names()
    }
    fn delta_r(
        &self,
        pose: &Pose,
        errors: &TurntableErrors,
    ) -> Result<nalgebra::Matrix3<f64>, KinematicsError> {
        let stretch = nalgebra::Matrix3::from_diagonal(&nalgebra::Vector3::new(
            1.0 + errors.chi_rad()[1],
            1.0,
            1.0,
        ));
        Ok(self.0.delta_r(pose, errors)? * stretch)
    }
}

/// The exact chain with the sign of psi flipped in its angles but not in its delta_r.
struct FlippedPsi(ExactChain);

impl OrientationErrorModel for FlippedPsi {
    fn error_names(&self) -> Vec<String> {
        self.0.error_names()
    }
    fn delta_r(
        &self,
        pose: &Pose,
        errors: &TurntableErrors,
    ) -> Result<nalgebra::Matrix3<f64>, KinematicsError> {
        self.0.delta_r(pose, errors)
    }
    fn orientation_error(
        &self,
        pose: &Pose,
        errors: &TurntableErrors,
    ) -> Result<OrientationError, KinematicsError> {
        let mut e = self.0.orientation_error(pose, errors)?;
        e.delta_psi_rad = -e.delta_psi_rad;
        Ok(e)
    }
}

/// Before the physics checks the general suite compared a model only with its own first
/// order, so both models passed it (checked by removing `check_rotation` from the suite).
#[test]
fn a_model_with_wrong_physics_and_the_default_first_order_fails_conformance() {
    for t in [table3(), three_axis()] {
        let zero = t.zero_errors();
        let c = cases(&t, 50, MAX_ERROR_RAD);
        let tol = Tolerances::default();
        let f = check_model_general(&Stretching(ExactChain::new(&t)), &zero, &c, &tol).unwrap_err();
        assert_eq!(f.check(), "rotation", "{f}");
        let f = check_model_general(&FlippedPsi(ExactChain::new(&t)), &zero, &c, &tol).unwrap_err();
        assert_eq!(f.check(), "readout", "{f}");
        // and the right physics passes, with its analytic first order checked
        check_model_general(&ExactChain::new(&t), &zero, &c, &tol).unwrap();
    }
}

/// The derived first order (central differences, h = 1e-6 rad) against the described
/// turntables' analytic coefficients: within its stated bound, and the measured error is
/// printed (`--nocapture`).
#[test]
fn derived_first_order_is_within_its_stated_bound_of_the_analytic_coefficients() {
    use tt_kinematics::{DERIVED_FIRST_ORDER_TOLERANCE, derived_first_order};
    for t in [table3(), three_axis()] {
        let mut worst = 0.0_f64;
        for case in cases(&t, 100, MAX_ERROR_RAD) {
            let analytic = tt_kinematics::LinearModel::new(&t)
                .coefficients(&case.pose)
                .unwrap();
            let derived =
                derived_first_order(&ExactChain::new(&t), &case.pose, t.n_translation_errors())
                    .unwrap();
            for (a, d) in analytic.iter().zip(derived.iter()) {
                worst = worst.max((a - d).abs());
            }
        }
        println!(
            "{} joints: derived first order within {worst:e} of the analytic one",
            t.n_joints()
        );
        assert!(worst <= DERIVED_FIRST_ORDER_TOLERANCE, "{worst}");
    }
}

/// A model without its own delta_r is a typed error where the exact rotation is needed, never
/// a silent rebuild from its angles.
#[test]
fn a_model_without_delta_r_is_a_typed_error_at_poses() {
    use tt_kinematics::{AtPoses, ScheduleErrorModel};
    let t = table3();
    let s = AtPoses::of(
        Mutant(t.clone(), Mutation::Transposed),
        vec![Pose::from_deg(&[0.0, 30.0]).unwrap()],
    );
    let mut dr = vec![nalgebra::Matrix3::identity(); 1];
    let e = s.delta_r_into(&[0.0; 8], &mut dr).unwrap_err();
    assert_eq!(e, KinematicsError::NoDeltaR);
    assert!(e.to_string().contains("delta_r"), "{e}");
    // the names and the count come from the model; a chi of another size names both
    assert_eq!(
        s.error_names(),
        Mutant(t.clone(), Mutation::Transposed).error_names()
    );
    assert_eq!(
        s.delta_r_into(&[0.0; 7], &mut dr).unwrap_err(),
        KinematicsError::Field(tt_core::FieldError::Length {
            field: "chi".into(),
            expected: 8,
            found: 7
        })
    );
}

/// A model that gives neither its $\Delta\mathbf R$ nor its angles compiles against the
/// trait's defaults (the angles are read off `delta_r`) and gets the typed `NoDeltaR` from its
/// orientation error, never a panic; a model that gives only `delta_r` (the stretching mount
/// above, the azel example) gets its angles read off it by eq 24.
#[test]
fn the_default_orientation_error_is_read_off_delta_r_or_is_a_typed_error() {
    struct NamesOnly;
    impl OrientationErrorModel for NamesOnly {
        fn error_names(&self) -> Vec<String> {
            vec!["a".into()]
        }
    }
    let pose = Pose::from_deg(&[0.0, 30.0]).unwrap();
    let e = NamesOnly
        .orientation_error(&pose, &TurntableErrors::new(vec![0.0], vec![]).unwrap())
        .unwrap_err();
    assert_eq!(e, KinematicsError::NoDeltaR);
    let t = table3();
    let chi = TurntableErrors::new(
        (0..8).map(|j| 1e-4 * (j as f64 + 1.0)).collect(),
        vec![0.0; t.n_translation_errors()],
    )
    .unwrap();
    let stretching = Stretching(ExactChain::new(&t));
    let want = OrientationError::from_matrix_elements(&stretching.delta_r(&pose, &chi).unwrap());
    let got = stretching.orientation_error(&pose, &chi).unwrap();
    // the same operations: bit for bit
    assert_eq!(
        got.to_array().map(f64::to_bits),
        want.to_array().map(f64::to_bits)
    );
}
