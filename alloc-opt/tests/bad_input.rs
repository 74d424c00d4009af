//! Bad input: every invalid number is rejected by name (the turntable's error names),
//! infeasible lower bounds name the problem and the errors, a method that does not apply to a
//! table says so, and nothing panics.

mod common;

use alloc_opt::{
    AllocError, AllocationProblem, Allocator, Certificate, EqualEffects, Requirement,
    SensitivityWeighted, WeightRule, Weights, paper,
};
use common::*;
use nalgebra::DMatrix;
use proptest::prelude::*;
use tt_core::FieldError;
use tt_core::units::arcmin_to_rad;
use tt_kinematics::{LinearModel, OrientationAxis as A};

fn field_of(e: &AllocError) -> &str {
    match e {
        AllocError::Field(f) => f.field(),
        other => panic!("expected a field error, got {other:?}"),
    }
}

#[test]
fn requirement_nan_infinite_zero_or_negative_is_rejected_by_name() {
    let e = Requirement::new(f64::NAN, 1e-4, 1e-4).unwrap_err();
    assert!(matches!(e, FieldError::NonFinite { .. }));
    assert_eq!(e.field(), "requirement.psi");
    let e = Requirement::new(1e-4, 0.0, 1e-4).unwrap_err();
    assert!(matches!(e, FieldError::NotPositive { .. }));
    assert_eq!(e.field(), "requirement.theta");
    let e = Requirement::new(1e-4, 1e-4, f64::INFINITY).unwrap_err();
    assert_eq!(e.field(), "requirement.gamma");
    let e = Requirement::new(1e-4, -1e-4, 1e-4).unwrap_err();
    assert_eq!(e.field(), "requirement.theta");
    // An absent requirement is fine; a present one is still checked.
    assert!(Requirement::from_options([None, Some(1e-4), None]).is_ok());
    let e = Requirement::from_options([None, None, Some(-1.0)]).unwrap_err();
    assert_eq!(e.field(), "requirement.gamma");
    assert_eq!(
        Requirement::uniform_deg(f64::NAN).unwrap_err().field(),
        "requirement_deg"
    );
}

#[test]
fn lower_bound_negative_or_not_finite_is_rejected_by_name() {
    let req = Requirement::uniform_deg(0.027).unwrap();
    let mut lb = vec![0.0; 8];
    lb[idx("dalpha_x2")] = -1e-6;
    let e = AllocationProblem::new(paper_model(), req, lb.clone()).unwrap_err();
    assert!(matches!(e, AllocError::Field(FieldError::Negative { .. })));
    assert_eq!(field_of(&e), "lower_bounds.dalpha_x2");
    assert!(e.to_string().contains("lower_bounds.dalpha_x2"), "{e}");
    lb[idx("dalpha_x2")] = f64::NEG_INFINITY;
    let e = AllocationProblem::new(paper_model(), req, lb.clone()).unwrap_err();
    assert!(matches!(e, AllocError::Field(FieldError::NonFinite { .. })));
    assert_eq!(field_of(&e), "lower_bounds.dalpha_x2");
    lb[idx("dalpha_x2")] = 0.0;
    lb[idx("dalpha_z1")] = f64::NAN;
    let e = AllocationProblem::new(paper_model(), req, lb).unwrap_err();
    assert_eq!(field_of(&e), "lower_bounds.dalpha_z1");
    // The three-axis table's own names.
    let mut lb = vec![0.0; 13];
    lb[8] = -1.0;
    let e = AllocationProblem::new(LinearModel::new(&three_axis()), req, lb).unwrap_err();
    assert_eq!(field_of(&e), "lower_bounds.deps_mi_z");
}

#[test]
fn vectors_of_the_wrong_length_are_rejected_by_name() {
    let req = Requirement::uniform_deg(0.027).unwrap();
    let e = AllocationProblem::new(paper_model(), req, vec![0.0; 13]).unwrap_err();
    assert_eq!(
        e,
        AllocError::Field(FieldError::Length {
            field: "lower_bounds".into(),
            expected: 8,
            found: 13
        })
    );
    let e = Weights::new(&paper_model(), DMatrix::from_element(3, 7, 1.0)).unwrap_err();
    assert_eq!(field_of(&e), "weights");
    let p = paper_problem();
    let e = Certificate::compute(p.model(), p.limits(), &[0.0; 8], &[1e-4; 9]).unwrap_err();
    assert_eq!(field_of(&e), "upper_bounds");
}

#[test]
fn weight_zero_negative_or_nan_is_rejected_by_name() {
    let model = paper_model();
    let mut w = Weights::inverse_average_sensitivity(&model)
        .matrix()
        .clone();
    w[(A::Gamma.index(), idx("dalpha_x2"))] = 0.0;
    let e = Weights::new(&model, w.clone()).unwrap_err();
    assert!(matches!(
        e,
        AllocError::Field(FieldError::NotPositive { .. })
    ));
    assert_eq!(field_of(&e), "weights.gamma.dalpha_x2");
    w[(A::Gamma.index(), idx("dalpha_x2"))] = f64::NAN;
    assert_eq!(
        field_of(&Weights::new(&model, w).unwrap_err()),
        "weights.gamma.dalpha_x2"
    );
    // A weight where the error is not involved is ignored.
    let mut ok = Weights::inverse_average_sensitivity(&model)
        .matrix()
        .clone();
    ok[(A::Theta.index(), idx("dphi_y1"))] = -5.0;
    assert!(Weights::new(&model, ok).is_ok());
    // Explicit weights are re-validated against the problem's model at allocation time.
    let allocator = SensitivityWeighted {
        weights: WeightRule::Explicit(Weights::inverse_average_sensitivity(&model)),
        ..SensitivityWeighted::paper()
    };
    assert!(allocator.allocate(&paper_problem()).is_ok());
    let three = three_axis_problem();
    let e = SensitivityWeighted {
        form: alloc_opt::ConstraintForm::FullRange,
        ..allocator
    }
    .allocate(&three)
    .unwrap_err();
    assert_eq!(field_of(&e), "weights");
    assert!(Weights::new(&model, DMatrix::from_element(3, 8, -1.0)).is_err());
}

#[test]
fn safety_margin_out_of_range_is_rejected_by_name() {
    let p = paper_problem();
    assert_eq!(
        field_of(&p.with_safety_margin(-0.1).unwrap_err()),
        "safety_margin"
    );
    assert!(p.with_safety_margin(1.0).is_err());
    assert!(p.with_safety_margin(f64::NAN).is_err());
    let shrunk = p.with_safety_margin(0.1).unwrap();
    approx::assert_relative_eq!(
        shrunk.requirement().get(A::Psi).unwrap(),
        0.9 * p.requirement().get(A::Psi).unwrap(),
        max_relative = ULP_REL
    );
}

/// The paper's quarter ranges are ranges of the single free joint phi2: on a table with two
/// free joints (the three-axis table) they are a typed error naming the joints, from both the
/// allocator and the form itself; the full-range form applies.
#[test]
fn quarter_ranges_on_a_table_with_two_free_joints_are_a_typed_error() {
    let problem = three_axis_problem();
    let expected = AllocError::QuarterRangesNeedOneFreeJoint {
        free_joints: vec!["phi_m".into(), "phi_i".into()],
    };
    let e = SensitivityWeighted::paper().allocate(&problem).unwrap_err();
    assert_eq!(e, expected);
    assert!(e.to_string().contains("phi_m, phi_i"), "{e}");
    assert!(e.to_string().contains("full-range"), "{e}");
    assert_eq!(
        alloc_opt::ConstraintForm::PaperQuarterRanges
            .pose_ranges(problem.model(), A::Gamma)
            .unwrap_err(),
        expected
    );
    assert!(
        alloc_opt::ConstraintForm::FullRange
            .pose_ranges(problem.model(), A::Gamma)
            .is_ok()
    );
}

/// Upper bounds given to the certificate are checked by name: NaN or negative anywhere,
/// infinite on an angle with a requirement.
#[test]
fn certificate_rejects_bad_upper_bounds_by_name() {
    let p = paper_problem();
    let mut ub = paper::table4_rad();
    ub[idx("deps_y")] = f64::NAN;
    let e = Certificate::compute(p.model(), p.limits(), &[0.0; 8], &ub).unwrap_err();
    assert_eq!(field_of(&e), "upper_bounds.deps_y");
    ub[idx("deps_y")] = -1e-5;
    let e = Certificate::compute(p.model(), p.limits(), &[0.0; 8], &ub).unwrap_err();
    assert_eq!(field_of(&e), "upper_bounds.deps_y");
    ub[idx("deps_y")] = f64::INFINITY;
    let e = Certificate::compute(p.model(), p.limits(), &[0.0; 8], &ub).unwrap_err();
    assert_eq!(field_of(&e), "upper_bounds.deps_y");
}

/// Lower bounds that alone exceed a requirement: a typed error naming the problem (gamma,
/// theta or psi) and the errors whose bounds conflict, from both allocators.
#[test]
fn infeasible_lower_bounds_name_the_problem_and_the_components() {
    let req = Requirement::uniform_deg(0.027).unwrap();
    /// (lower bounds in arcmin, expected problem, expected errors)
    type Case = (Vec<(&'static str, f64)>, A, Vec<&'static str>);
    let cases: [Case; 3] = [
        (vec![("dalpha_x2", 2.0)], A::Gamma, vec!["dalpha_x2"]),
        (
            vec![("dphi_z2", 1.0), ("dalpha_z1", 0.7)],
            A::Theta,
            vec!["dphi_z2", "dalpha_z1"],
        ),
        (
            vec![("dalpha_y2", 1.0), ("deps_x", 0.7)],
            A::Psi,
            vec!["dalpha_y2", "deps_x"],
        ),
    ];
    for (bounds, axis, names) in cases {
        let mut lb = vec![0.0; 8];
        for (c, v) in &bounds {
            lb[idx(c)] = arcmin_to_rad(*v);
        }
        let problem = AllocationProblem::new(paper_model(), req, lb).unwrap();
        for allocator in [
            &SensitivityWeighted::paper() as &dyn Allocator,
            &SensitivityWeighted::general(),
            &EqualEffects,
        ] {
            match allocator.allocate(&problem) {
                Err(AllocError::InfeasibleLowerBounds {
                    problem,
                    components,
                    worst_case_rad,
                    requirement_rad,
                }) => {
                    assert_eq!(problem, axis.name(), "{}", allocator.name());
                    assert_eq!(components, names, "{}", allocator.name());
                    assert!(worst_case_rad > requirement_rad);
                }
                other => panic!(
                    "{}: expected InfeasibleLowerBounds, got {other:?}",
                    allocator.name()
                ),
            }
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 64, ..ProptestConfig::default() })]

    /// Arbitrary numbers (NaN, infinities, negatives, huge and tiny values, absent
    /// requirements) never panic: the result is an allocation satisfying Lemma 1 with every
    /// number finite (bar the +inf of unconstrained errors) or a typed error.
    #[test]
    fn arbitrary_inputs_never_panic(
        req in proptest::array::uniform3(prop_oneof![
            Just(None), Just(Some(f64::NAN)), Just(Some(f64::INFINITY)), Just(Some(-1.0)),
            Just(Some(0.0)), (1e-8_f64..1e-2).prop_map(Some)]),
        lb in proptest::collection::vec(prop_oneof![
            4 => Just(0.0), 1 => Just(f64::NAN), 1 => Just(-1e-5), 2 => 0.0_f64..3e-4], 8),
    ) {
        let Ok(r) = Requirement::from_options(req) else { return Ok(()); };
        let Ok(problem) = AllocationProblem::new(paper_model(), r, lb.clone()) else {
            return Ok(());
        };
        for allocator in [
            &SensitivityWeighted::paper() as &dyn Allocator,
            &SensitivityWeighted::general(),
            &EqualEffects,
        ] {
            if let Ok(a) = allocator.allocate(&problem) {
                prop_assert!(a.certificate().lemma1_holds());
                prop_assert!(a.objective().is_finite());
                for (i, (u, l)) in a.upper_bounds_rad().iter().zip(&lb).enumerate() {
                    prop_assert!(u >= l);
                    prop_assert!(u.is_finite() || a.unconstrained().contains(&i));
                }
            }
        }
    }
}
