//! The GUM budget against an independent linear propagation and JCGM 100 example H.1.

use approx::assert_relative_eq;
use metrology::{Budget, BudgetSettings, Input, MetrologyError};
use nalgebra::DMatrix;
use tt_core::ErrorClass;

/// Budget against the explicit double sum: rounding only (relative).
const PROPAGATION_REL: f64 = 1e-9;

/// A deterministic pseudo-random number in [-1, 1) (no generator needed for a fixed matrix).
fn entry(i: usize, j: usize) -> f64 {
    let h = ((i * 7919 + j * 104_729 + 13) * 2_654_435_761) % 1_000_003;
    2.0 * h as f64 / 1_000_003.0 - 1.0
}

fn mixed_inputs() -> Vec<Input> {
    vec![
        Input::normal("a", 1.0, 0.3).unwrap().with_dof(4.0).unwrap(),
        Input::rectangular("b", 0.0, 2.0).unwrap(),
        Input::triangular("c", 0.0, 0.6)
            .unwrap()
            .with_dof(12.0)
            .unwrap(),
        Input::arcsine("d", 0.0, 1.5).unwrap(),
        Input::disc("e", [0.0, 0.0], 0.8).unwrap(),
        Input::normal("f", 3.0, 0.05).unwrap(),
    ]
}

#[test]
fn standard_uncertainties_follow_each_distribution_law() {
    let u: Vec<f64> = mixed_inputs()
        .iter()
        .map(Input::standard_uncertainty)
        .collect();
    assert_relative_eq!(u[0], 0.3);
    assert_relative_eq!(u[1], 2.0 / 3.0_f64.sqrt(), max_relative = 1e-15);
    assert_relative_eq!(u[2], 0.6 / 6.0_f64.sqrt(), max_relative = 1e-15);
    assert_relative_eq!(u[3], 1.5 / 2.0_f64.sqrt(), max_relative = 1e-15);
    assert_relative_eq!(u[4], 0.4, max_relative = 1e-15);
}

#[test]
fn budget_equals_an_independent_linear_propagation_with_correlations() {
    let inputs = mixed_inputs();
    let n = 7; // the disc has two components
    let u = [
        0.3,
        2.0 / 3.0_f64.sqrt(),
        0.6 / 6.0_f64.sqrt(),
        1.5 / 2.0_f64.sqrt(),
        0.4,
        0.4,
        0.05,
    ];
    // a valid correlation: R = normalised B B^T
    let b = DMatrix::from_fn(n, n, |i, j| entry(i, j) + if i == j { 1.5 } else { 0.0 });
    let s = &b * b.transpose();
    let r = DMatrix::from_fn(n, n, |i, j| s[(i, j)] / (s[(i, i)] * s[(j, j)]).sqrt());
    let c = DMatrix::from_fn(4, n, |i, j| 3.0 * entry(i + 11, j + 5));
    let names = ["y0", "y1", "y2", "y3"];
    let result = Budget::new(inputs, BudgetSettings::default())
        .unwrap()
        .with_correlation(r.clone())
        .unwrap()
        .evaluate(&names, &c)
        .unwrap();
    for j in 0..4 {
        for l in 0..4 {
            let mut cov = 0.0;
            for i in 0..n {
                for k in 0..n {
                    cov += c[(j, i)] * c[(l, k)] * u[i] * u[k] * r[(i, k)];
                }
            }
            assert_relative_eq!(
                result.covariance()[(j, l)],
                cov,
                max_relative = PROPAGATION_REL
            );
        }
        let out = &result.outputs()[j];
        assert_relative_eq!(
            out.combined(),
            result.covariance()[(j, j)].sqrt(),
            max_relative = 1e-15
        );
        for i in 0..n {
            assert_relative_eq!(
                out.contributions()[i],
                c[(j, i)].abs() * u[i],
                max_relative = 1e-15
            );
        }
        // Welch-Satterthwaite over the rows with finite dof (a: 4, c: 12)
        let ws = out.combined().powi(4)
            / (out.contributions()[0].powi(4) / 4.0 + out.contributions()[2].powi(4) / 12.0);
        assert_relative_eq!(out.dof_eff(), ws, max_relative = PROPAGATION_REL);
        assert_relative_eq!(out.dof_used(), ws.floor());
    }
    let rows: Vec<&str> = result.rows().iter().map(|r| r.name()).collect();
    assert_eq!(rows, ["a", "b", "c", "d", "e[x]", "e[y]", "f"]);
}

#[test]
fn a_linear_map_of_independent_sources_carries_the_same_covariance_as_its_correlation_matrix() {
    // x = A s: 5 derived inputs from 4 independent sources
    let sources = vec![
        Input::normal("s0", 0.0, 1.0).unwrap(),
        Input::rectangular("s1", 0.0, 0.5).unwrap(),
        Input::normal("s2", 0.0, 0.2).unwrap(),
        Input::arcsine("s3", 0.0, 0.7).unwrap(),
    ];
    let us: Vec<f64> = sources.iter().map(Input::standard_uncertainty).collect();
    let a = DMatrix::from_fn(5, 4, |i, j| entry(i + 3, j + 17));
    let c = DMatrix::from_fn(3, 5, |i, j| entry(i + 29, j + 2));
    let mapped = Budget::new(sources, BudgetSettings::default())
        .unwrap()
        .evaluate_mapped(&["p", "q", "r"], &c, &a)
        .unwrap();
    // the same through the derived inputs' correlation matrix
    let vs = DMatrix::from_diagonal(&nalgebra::DVector::from_iterator(
        4,
        us.iter().map(|u| u * u),
    ));
    let vx = &a * vs * a.transpose();
    let ux: Vec<f64> = (0..5).map(|i| vx[(i, i)].sqrt()).collect();
    let rx = DMatrix::from_fn(5, 5, |i, j| vx[(i, j)] / (ux[i] * ux[j]));
    let derived: Vec<Input> = (0..5)
        .map(|i| Input::normal(&format!("x{i}"), 0.0, ux[i]).unwrap())
        .collect();
    let correlated = Budget::new(derived, BudgetSettings::default())
        .unwrap()
        .with_correlation(rx)
        .unwrap()
        .evaluate(&["p", "q", "r"], &c)
        .unwrap();
    for j in 0..3 {
        for l in 0..3 {
            assert_relative_eq!(
                mapped.covariance()[(j, l)],
                correlated.covariance()[(j, l)],
                max_relative = PROPAGATION_REL
            );
        }
    }
    assert_eq!(mapped.rows().len(), 4);
}

/// JCGM 100:2008 example H.1 (calibration of an end gauge of nominal length 50 mm), first
/// order, lengths in nm. The GUM's table H.1 and H.1.6: u_c(l) = 32 nm, contributions 25, 9.7,
/// 0, 0, 2.9 and 16.6 nm, nu_eff = 16.7 truncated to 16, t_99(16) = 2.92, U_99 = 93 nm. The
/// comparator difference d is carried as its three sources (d-bar, random and systematic
/// comparator effects: 5.8 nm with 24, 3.9 nm with 5, 6.7 nm with 8 degrees of freedom) and
/// theta as its mean and cyclic variation (normal 0.2 degC, arcsine 0.5 degC).
#[test]
fn gum_example_h1_end_gauge_reproduces_the_published_budget() {
    let l_s = 50_000_623.0; // nm
    let (theta, alpha_s) = (-0.1, 11.5e-6);
    let inputs = vec![
        Input::normal("l_s", l_s, 25.0)
            .unwrap()
            .with_dof(18.0)
            .unwrap(),
        Input::normal("d_bar", 215.0, 5.8)
            .unwrap()
            .with_dof(24.0)
            .unwrap(),
        Input::normal("d_random", 0.0, 3.9)
            .unwrap()
            .with_dof(5.0)
            .unwrap(),
        Input::normal("d_systematic", 0.0, 6.7)
            .unwrap()
            .with_dof(8.0)
            .unwrap(),
        Input::rectangular("alpha_s", alpha_s, 2e-6).unwrap(),
        Input::normal("theta_bar", theta, 0.2).unwrap(),
        Input::arcsine("delta", 0.0, 0.5).unwrap(),
        Input::rectangular("delta_alpha", 0.0, 1e-6)
            .unwrap()
            .with_dof(50.0)
            .unwrap(),
        Input::rectangular("delta_theta", 0.0, 0.05)
            .unwrap()
            .with_dof(2.0)
            .unwrap(),
    ];
    // l = l_s + d - l_s (delta_alpha theta + alpha_s delta_theta), at the estimates
    // (delta_alpha = delta_theta = 0)
    let c = DMatrix::from_row_slice(
        1,
        9,
        &[
            1.0,
            1.0,
            1.0,
            1.0,
            0.0,
            0.0,
            0.0,
            -l_s * theta,
            -l_s * alpha_s,
        ],
    );
    let settings = BudgetSettings {
        coverage: 0.99,
        ..BudgetSettings::default()
    };
    let result = Budget::new(inputs, settings)
        .unwrap()
        .evaluate(&["l"], &c)
        .unwrap();
    let l = &result.outputs()[0];
    let round = |v: f64, digits: i32| (v * 10f64.powi(digits)).round() / 10f64.powi(digits);
    assert_relative_eq!(round(l.combined(), 0), 32.0);
    let contribution = |i: usize| l.contributions()[i];
    let u_d = (contribution(1).powi(2) + contribution(2).powi(2) + contribution(3).powi(2)).sqrt();
    assert_relative_eq!(round(u_d, 1), 9.7);
    assert_relative_eq!(round(contribution(7), 1), 2.9);
    assert_relative_eq!(round(contribution(8), 1), 16.6);
    assert_relative_eq!(round(l.dof_eff(), 0), 17.0); // 16.7 in the GUM (two-stage: 16.7)
    assert_relative_eq!(l.dof_used(), 16.0);
    assert_relative_eq!(round(l.coverage_factor(), 2), 2.92);
    // the GUM multiplies the rounded figures: 2.92 x 32 nm = 93 nm; unrounded 92.5 nm
    assert_relative_eq!(
        round(round(l.coverage_factor(), 2) * round(l.combined(), 0), 0),
        93.0
    );
    assert!((l.expanded() - 93.0).abs() < 1.0, "{}", l.expanded());
    assert_eq!(l.dominant(), Some(0));
}

#[test]
fn bad_budget_input_names_the_field_and_value() {
    let e = Budget::new(
        mixed_inputs(),
        BudgetSettings {
            coverage: 1.0,
            ..BudgetSettings::default()
        },
    )
    .unwrap_err();
    assert_eq!(e.input_field(), Some("coverage"));
    assert!(e.to_string().contains('1'), "{e}");

    let e = Input::rectangular("tilt", 0.0, -1.0).unwrap_err();
    assert_eq!(e.input_field(), Some("tilt.half_width"));
    let e = Input::normal("bias", 0.0, 1.0)
        .unwrap()
        .with_dof(0.0)
        .unwrap_err();
    assert_eq!(e.input_field(), Some("bias.dof"));

    let twice = vec![
        Input::normal("x", 0.0, 1.0).unwrap(),
        Input::normal("x", 0.0, 2.0).unwrap(),
    ];
    let e = Budget::new(twice, BudgetSettings::default()).unwrap_err();
    assert_eq!(e, MetrologyError::DuplicateName { name: "x".into() });

    let two = || {
        vec![
            Input::normal("x", 0.0, 1.0).unwrap(),
            Input::normal("y", 0.0, 2.0).unwrap(),
        ]
    };
    let budget = Budget::new(two(), BudgetSettings::default()).unwrap();
    let e = budget
        .evaluate(&["out"], &DMatrix::zeros(1, 3))
        .unwrap_err();
    assert_eq!(e.input_field(), Some("sensitivities"));
    let mut c = DMatrix::zeros(1, 2);
    c[(0, 1)] = f64::NAN;
    let e = budget.evaluate(&["out"], &c).unwrap_err();
    assert!(e.to_string().starts_with("sensitivities[0, 1]"), "{e}");

    // finite, but the covariance overflows: an error, never an infinite or NaN budget
    let e = budget
        .evaluate(&["out"], &DMatrix::from_row_slice(1, 2, &[1e300, 1e300]))
        .unwrap_err();
    assert_eq!(e.input_field(), Some("sensitivities"));

    let not_psd = DMatrix::from_row_slice(2, 2, &[1.0, 1.5, 1.5, 1.0]);
    let e = Budget::new(two(), BudgetSettings::default())
        .unwrap()
        .with_correlation(not_psd)
        .unwrap_err();
    assert_eq!(e.input_field(), Some("correlation[1, 0]"));
    let not_psd = DMatrix::from_row_slice(3, 3, &[1.0, 0.9, -0.9, 0.9, 1.0, 0.9, -0.9, 0.9, 1.0]);
    let three = vec![
        Input::normal("x", 0.0, 1.0).unwrap(),
        Input::normal("y", 0.0, 2.0).unwrap(),
        Input::normal("z", 0.0, 2.0).unwrap(),
    ];
    let e = Budget::new(three, BudgetSettings::default())
        .unwrap()
        .with_correlation(not_psd)
        .unwrap_err();
    assert_eq!(e.input_field(), Some("correlation"));
}
