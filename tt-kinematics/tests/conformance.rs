//! The conformance suite (library code behind the `conformance` feature) run on every model
//! of this crate, for the paper's table and a three-axis table, and shown to fail on a wrong
//! model.

mod common;

use common::*;
use tt_kinematics::conformance::{Tolerances, cases, check_model};
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

/// A model with a sign error in one angle (the mutation "Delta-R = R_t^T R_d"): the suite
/// must reject it, so it can fail.
struct Transposed(Turntable);

impl OrientationErrorModel for Transposed {
    fn orientation_error(
        &self,
        pose: &Pose,
        errors: &TurntableErrors,
    ) -> Result<OrientationError, KinematicsError> {
        let dr = self
            .0
            .delta_r(pose, errors, tt_kinematics::ChainKind::Exact)?;
        Ok(OrientationError::from_matrix_elements(&dr.transpose()))
    }
}

/// A model that forgets R_d^T (the leading joint does not cancel).
struct NoRdTranspose(Turntable);

impl OrientationErrorModel for NoRdTranspose {
    fn orientation_error(
        &self,
        pose: &Pose,
        errors: &TurntableErrors,
    ) -> Result<OrientationError, KinematicsError> {
        let rt = self
            .0
            .actual_rotation(pose, errors, tt_kinematics::ChainKind::Exact)?;
        Ok(OrientationError::from_matrix_elements(
            &(rt - nalgebra::Matrix3::identity()),
        ))
    }
}

#[test]
fn the_suite_rejects_wrong_models() {
    for t in [table3(), three_axis()] {
        let c = cases(&t, 50, MAX_ERROR_RAD);
        let f = check_model(&Transposed(t.clone()), &t, &c, &Tolerances::default()).unwrap_err();
        assert_eq!(f.check, "first-order", "{f}");
        let f = check_model(&NoRdTranspose(t.clone()), &t, &c, &Tolerances::default()).unwrap_err();
        assert_eq!(f.check, "zero", "{f}");
    }
    // eq 26 is a model of the paper's table only: a typed error, reported by the suite
    let t = three_axis();
    let f = check_model(&ClosedForm, &t, &cases(&t, 3, 1e-4), &Tolerances::default()).unwrap_err();
    assert_eq!(f.check, "evaluation", "{f}");
}
