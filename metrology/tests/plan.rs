//! A plan against a specification: by expanded uncertainty and by yield.

use approx::assert_relative_eq;
use metrology::plan::{
    IntervalMethod, SpecificationCheck, YieldCheck, YieldVerdict, fraction_interval,
};
use metrology::{Budget, BudgetSettings, Input};
use nalgebra::DMatrix;
use tt_core::ErrorClass;

/// Published intervals print four decimals.
const TABLE_4_DECIMALS: f64 = 5e-5;

#[test]
fn a_budget_output_meets_its_specification_by_the_ratio_of_u_to_the_limit() {
    let budget = Budget::new(
        vec![
            Input::normal("noise", 0.0, 0.1)
                .unwrap()
                .with_dof(20.0)
                .unwrap(),
            Input::rectangular("table", 0.0, 0.2).unwrap(),
        ],
        BudgetSettings::default(),
    )
    .unwrap();
    let r = budget
        .evaluate(&["bias"], &DMatrix::from_row_slice(1, 2, &[1.0, 1.0]))
        .unwrap();
    let out = &r.outputs()[0];
    let check = SpecificationCheck::of_output(out, r.coverage(), 0.5).unwrap();
    assert_relative_eq!(check.ratio(), out.expanded() / 0.5, max_relative = 1e-15);
    assert!(check.meets());
    let tight = SpecificationCheck::of_output(out, r.coverage(), 0.2).unwrap();
    assert!(!tight.meets());
    let text = tight.to_string();
    assert!(
        text.starts_with("does not meet: expanded uncertainty U = 0."),
        "{text}"
    );
    assert!(
        text.contains("p = 95 %) exceeds the specification 0.2000 (ratio 1."),
        "{text}"
    );
    assert!(text.ends_with("rule: U <= specification)"), "{text}");
}

#[test]
fn fraction_intervals_match_closed_forms_and_tables() {
    // Clopper-Pearson at the ends: (alpha/2)^(1/n)
    let (lo, hi) = fraction_interval(20, 20, 0.95, IntervalMethod::ClopperPearson).unwrap();
    assert_relative_eq!(lo, 0.025_f64.powf(1.0 / 20.0), max_relative = 1e-12);
    assert_relative_eq!(hi, 1.0);
    // 5 of 10: Clopper-Pearson [0.1871, 0.8129], Wilson [0.2366, 0.7634]
    let (lo, hi) = fraction_interval(5, 10, 0.95, IntervalMethod::ClopperPearson).unwrap();
    assert!(
        (lo - 0.1871).abs() < TABLE_4_DECIMALS && (hi - 0.8129).abs() < TABLE_4_DECIMALS,
        "{lo} {hi}"
    );
    let (lo, hi) = fraction_interval(5, 10, 0.95, IntervalMethod::Wilson).unwrap();
    assert!(
        (lo - 0.2366).abs() < TABLE_4_DECIMALS && (hi - 0.7634).abs() < TABLE_4_DECIMALS,
        "{lo} {hi}"
    );
    // 0 of 10, Wilson: [0, z^2 / (n + z^2)]
    let z2 = 1.959_963_984_540_054_f64.powi(2);
    let (lo, hi) = fraction_interval(0, 10, 0.95, IntervalMethod::Wilson).unwrap();
    assert_relative_eq!(lo, 0.0);
    assert_relative_eq!(hi, z2 / (10.0 + z2), max_relative = 1e-12);
}

#[test]
fn a_yield_meets_fails_or_is_undecided_by_its_interval() {
    let check = |s, n| YieldCheck::new(s, n, 0.95, 0.95, IntervalMethod::Wilson).unwrap();
    assert_eq!(check(9_580, 10_000).verdict(), YieldVerdict::Meets);
    assert_eq!(check(9_510, 10_000).verdict(), YieldVerdict::Undecided);
    assert_eq!(check(9_000, 10_000).verdict(), YieldVerdict::DoesNotMeet);
    let text = check(9_510, 10_000).to_string();
    assert!(text.starts_with("undecided (run more trials): 9510 of 10000 calibrations meet (95.10 %; 95 % Wilson interval 94."), "{text}");
}

#[test]
fn bad_plan_input_names_the_field() {
    assert_eq!(
        SpecificationCheck::new(1.0, 2.0, 1.0, 1.0)
            .unwrap_err()
            .input_field(),
        Some("coverage")
    );
    assert_eq!(
        SpecificationCheck::new(1.0, 2.0, 0.95, 0.0)
            .unwrap_err()
            .input_field(),
        Some("limit")
    );
    assert_eq!(
        fraction_interval(3, 2, 0.95, IntervalMethod::Wilson)
            .unwrap_err()
            .input_field(),
        Some("successes")
    );
    assert_eq!(
        fraction_interval(0, 0, 0.95, IntervalMethod::Wilson)
            .unwrap_err()
            .input_field(),
        Some("trials")
    );
    assert_eq!(
        YieldCheck::new(1, 2, 1.5, 0.95, IntervalMethod::Wilson)
            .unwrap_err()
            .input_field(),
        Some("required")
    );
}
