//! Bad input: every invalid number is rejected by name, infeasible lower bounds name the
//! problem and the components, and nothing panics.

use alloc_opt::{
    AllocError, AllocationProblem, Allocator, EqualEffects, Requirement, SensitivityWeighted,
    WeightRule, Weights,
};
use nalgebra::SMatrix;
use proptest::prelude::*;
use tt_kinematics::units::arcmin_to_rad;
use tt_kinematics::{ErrorComponent as C, LinearModel, OrientationAxis as A};

fn field_of(e: &AllocError) -> &str {
    match e {
        AllocError::NonFinite { field, .. }
        | AllocError::NotPositive { field, .. }
        | AllocError::Negative { field, .. } => field,
        other => panic!("expected a field error, got {other:?}"),
    }
}

#[test]
fn requirement_nan_infinite_zero_or_negative_is_rejected_by_name() {
    let e = Requirement::new(f64::NAN, 1e-4, 1e-4).unwrap_err();
    assert!(matches!(e, AllocError::NonFinite { .. }));
    assert_eq!(field_of(&e), "requirement.psi");
    let e = Requirement::new(1e-4, 0.0, 1e-4).unwrap_err();
    assert!(matches!(e, AllocError::NotPositive { .. }));
    assert_eq!(field_of(&e), "requirement.theta");
    let e = Requirement::new(1e-4, 1e-4, f64::INFINITY).unwrap_err();
    assert_eq!(field_of(&e), "requirement.gamma");
    let e = Requirement::new(1e-4, -1e-4, 1e-4).unwrap_err();
    assert_eq!(field_of(&e), "requirement.theta");
}

#[test]
fn lower_bound_negative_or_not_finite_is_rejected_by_name() {
    let req = Requirement::uniform_deg(0.027).unwrap();
    let mut lb = [0.0; 8];
    lb[C::DepsX.index()] = -1e-6;
    let e = AllocationProblem::new(LinearModel::paper_eq26(), req, lb).unwrap_err();
    assert!(matches!(e, AllocError::Negative { .. }));
    assert_eq!(field_of(&e), "lower_bounds.deps_x");
    lb[C::DepsX.index()] = f64::NEG_INFINITY;
    let e = AllocationProblem::new(LinearModel::paper_eq26(), req, lb).unwrap_err();
    assert!(matches!(e, AllocError::NonFinite { .. }));
    lb[C::DepsX.index()] = 0.0;
    lb[C::DalphaZ1.index()] = f64::NAN;
    let e = AllocationProblem::new(LinearModel::paper_eq26(), req, lb).unwrap_err();
    assert_eq!(field_of(&e), "lower_bounds.dalpha_z1");
}

#[test]
fn weight_zero_negative_or_nan_is_rejected_by_name() {
    let model = LinearModel::paper_eq26();
    let mut w = Weights::inverse_average_sensitivity(&model).matrix();
    w[(A::Gamma.index(), C::DalphaX2.index())] = 0.0;
    let e = Weights::new(&model, w).unwrap_err();
    assert!(matches!(e, AllocError::NotPositive { .. }));
    assert_eq!(field_of(&e), "weights.gamma.dalpha_x2");
    w[(A::Gamma.index(), C::DalphaX2.index())] = f64::NAN;
    assert_eq!(
        field_of(&Weights::new(&model, w).unwrap_err()),
        "weights.gamma.dalpha_x2"
    );
    // A weight where the component is not involved is ignored.
    let mut ok = Weights::inverse_average_sensitivity(&model).matrix();
    ok[(A::Theta.index(), C::DphiY1.index())] = -5.0;
    assert!(Weights::new(&model, ok).is_ok());
    // Explicit weights are re-validated at allocation time.
    let bad = SMatrix::<f64, 3, 8>::from_element(-1.0);
    let weights_unchecked = Weights::inverse_average_sensitivity(&model);
    let allocator = SensitivityWeighted {
        weights: WeightRule::Explicit(weights_unchecked),
        ..SensitivityWeighted::paper()
    };
    assert!(
        allocator
            .allocate(&AllocationProblem::paper_example().unwrap())
            .is_ok()
    );
    assert!(Weights::new(&model, bad).is_err());
}

#[test]
fn safety_margin_out_of_range_is_rejected_by_name() {
    let p = AllocationProblem::paper_example().unwrap();
    assert_eq!(
        field_of(&p.with_safety_margin(-0.1).unwrap_err()),
        "safety_margin"
    );
    assert!(p.with_safety_margin(1.0).is_err());
    assert!(p.with_safety_margin(f64::NAN).is_err());
    let shrunk = p.with_safety_margin(0.1).unwrap();
    approx::assert_relative_eq!(
        shrunk.requirement().get(A::Psi),
        0.9 * p.requirement().get(A::Psi),
        max_relative = 1e-15
    );
}

/// Lower bounds that alone exceed a requirement: a typed error naming the problem (gamma,
/// theta or psi) and the components whose bounds conflict, from both allocators.
#[test]
fn infeasible_lower_bounds_name_the_problem_and_the_components() {
    let req = Requirement::uniform_deg(0.027).unwrap();
    /// (lower bounds in arcmin, expected problem, expected components)
    type Case = (Vec<(C, f64)>, A, Vec<C>);
    let cases: [Case; 3] = [
        (vec![(C::DalphaX2, 2.0)], A::Gamma, vec![C::DalphaX2]),
        (
            vec![(C::DphiZ2, 1.0), (C::DalphaZ1, 0.7)],
            A::Theta,
            vec![C::DphiZ2, C::DalphaZ1],
        ),
        (
            vec![(C::DalphaY2, 1.0), (C::DepsX, 0.7)],
            A::Psi,
            vec![C::DalphaY2, C::DepsX],
        ),
    ];
    for (bounds, axis, comps) in cases {
        let mut lb = [0.0; 8];
        for (c, v) in &bounds {
            lb[c.index()] = arcmin_to_rad(*v);
        }
        let problem = AllocationProblem::new(LinearModel::paper_eq26(), req, lb).unwrap();
        for allocator in [
            &SensitivityWeighted::paper() as &dyn Allocator,
            &EqualEffects,
        ] {
            match allocator.allocate(&problem) {
                Err(AllocError::InfeasibleLowerBounds {
                    problem,
                    components,
                    worst_case_rad,
                    requirement_rad,
                }) => {
                    assert_eq!(problem, axis, "{}", allocator.name());
                    assert_eq!(components, comps, "{}", allocator.name());
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

    /// Arbitrary numbers (NaN, infinities, negatives, huge and tiny values) never panic: the
    /// result is an allocation satisfying Lemma 1 or a typed error.
    #[test]
    fn arbitrary_inputs_never_panic(
        req in proptest::array::uniform3(prop_oneof![
            Just(f64::NAN), Just(f64::INFINITY), Just(-1.0), Just(0.0), 1e-8_f64..1e-2]),
        lb in proptest::array::uniform8(prop_oneof![
            4 => Just(0.0), 1 => Just(f64::NAN), 1 => Just(-1e-5), 2 => 0.0_f64..3e-4]),
    ) {
        let Ok(r) = Requirement::new(req[0], req[1], req[2]) else { return Ok(()); };
        let Ok(problem) = AllocationProblem::new(LinearModel::paper_eq26(), r, lb) else {
            return Ok(());
        };
        for allocator in [&SensitivityWeighted::paper() as &dyn Allocator, &EqualEffects] {
            if let Ok(a) = allocator.allocate(&problem) {
                prop_assert!(a.certificate.lemma1_holds());
                for (u, l) in a.upper_bounds_rad.iter().zip(&lb) {
                    prop_assert!(u >= l);
                }
            }
        }
    }
}
