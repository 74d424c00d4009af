//! The GUM budget of each specified quantity (issue 34 item 2): the coefficient Jacobian is
//! the exact chain's derivative, and every budget equals an independent linear propagation
//! of the table's tolerances and the noise covariance.

mod common;

use approx::assert_relative_eq;
use e2e_verify::EndToEnd;
use e2e_verify::budget::EvaluatedAt;
use nalgebra::DMatrix;
use study::Study;

/// The budget is assembled in double precision from the same numbers: the independent
/// propagation agrees to rounding, 1e-9 relative is the bar.
const PROPAGATION_REL: f64 = 1e-9;

/// Central differences of the exact chain at h = 1e-6 rad: truncation O(h^2) and rounding
/// eps * |beta| / h, both far below 1e-6 of the largest entry of a column.
const JACOBIAN_REL: f64 = 1e-6;

/// Each angular error's tolerance in the tests, rad (10 arcsec).
const TOL_RAD: f64 = 10.0 * std::f64::consts::PI / (180.0 * 3600.0);

fn spec(output: &str, coefficient: &str, limit: f64, unit: &str) -> String {
    format!(
        "[[specifications]]\noutput = \"{output}\"\ncoefficient = \"{coefficient}\"\nlimit = {limit:?}\nunit = \"{unit}\"\n"
    )
}

/// The IMU example with a bias, a scale factor, a misalignment, a g-sensitivity, an error over
/// a range and an accuracy specified.
fn imu_with_specs() -> Study {
    let coefficients = [
        ("gx", "bg_x", 0.05, "deg_per_h"),
        ("gy", "gs_yx", 0.1, "deg/h/g"),
        ("ax", "sf_x", 100.0, "ppm"),
        ("ay", "mis_yz", 20.0, "arcsec"),
        ("az", "ba_z", 50.0, "ug"),
    ];
    let extra = [
        coefficients.map(|(o, c, limit, unit)| spec(o, c, limit, unit)).concat(),
        "[[specifications]]\noutput = \"ax\"\nquantity = \"error_over_range\"\nrange = 2\nrange_unit = \"g\"\nlimit = 0.5\nunit = \"mg\"\n".into(),
        "[[specifications]]\noutput = \"gz\"\nquantity = \"accuracy\"\nlimit = 0.1\nunit = \"deg_per_h\"\n".into(),
    ]
    .concat();
    common::imu_study_with(&extra)
}

fn table_inputs(s: &Study, e2e: &EndToEnd) -> Vec<metrology::Input> {
    e2e.error_names()
        .iter()
        .map(|n| {
            s.uncertainty
                .tolerance_distribution
                .input(n, TOL_RAD)
                .unwrap()
        })
        .collect()
}

#[test]
fn the_coefficient_jacobian_is_the_exact_chains_derivative() {
    let s = imu_with_specs();
    let e2e = common::simulator_of(&s);
    let jac = e2e.coefficient_linearization();
    let h = 1e-6;
    for j in 0..e2e.n_errors() {
        let mut chi = vec![0.0; e2e.n_errors()];
        chi[j] = h;
        let plus = e2e.coefficient_errors(&chi).unwrap();
        chi[j] = -h;
        let minus = e2e.coefficient_errors(&chi).unwrap();
        let numeric: Vec<f64> = plus
            .iter()
            .zip(&minus)
            .map(|(p, m)| (p - m) / (2.0 * h))
            .collect();
        let analytic: Vec<f64> = jac
            .iter()
            .flat_map(|m| m.column(j).iter().copied().collect::<Vec<_>>())
            .collect();
        assert_eq!(numeric.len(), analytic.len());
        let scale = numeric.iter().fold(1.0_f64, |m, v| m.max(v.abs()));
        for (a, n) in analytic.iter().zip(&numeric) {
            assert!(
                (a - n).abs() <= JACOBIAN_REL * scale,
                "error {j}: {a} vs {n}"
            );
        }
    }
}

#[test]
fn each_budget_equals_an_independent_linear_propagation() {
    let s = imu_with_specs();
    let e2e = common::simulator_of(&s);
    let table = table_inputs(&s, &e2e);
    let budgets = e2e
        .budget()
        .specification_budgets(&s.specifications, &table, &s.noise, s.timing.as_ref())
        .unwrap();
    assert_eq!(budgets.len(), s.specifications.len());
    // independent: the full coefficient covariance J diag(u^2) J^T + W + C per output
    let u_rect = TOL_RAD / 3.0_f64.sqrt();
    let covs = e2e
        .calibration()
        .noise_covariances(&s.noise, s.timing.as_ref().unwrap())
        .unwrap();
    let jac = e2e.coefficient_linearization();
    let cov: Vec<DMatrix<f64>> = jac
        .iter()
        .zip(&covs)
        .map(|(j, c)| {
            let c = c.as_ref().unwrap().coefficients();
            j * j.transpose() * (u_rect * u_rect) + c.white() + c.correlated()
        })
        .collect();
    for b in &budgets {
        let sp = &s.specifications[b.spec()];
        let k = sp.output();
        let var = match b.at() {
            EvaluatedAt::Coefficient => {
                let gw_model::spec::Resolved::Coefficient { index, .. } = *sp.resolved() else {
                    panic!()
                };
                cov[k][(index, index)]
            }
            EvaluatedAt::RangeEnd { positive } => {
                // ax: bias, scale-factor error, a_x^2 at a_x = +-2 g
                let o = &s.sensor.outputs()[k];
                let a = if positive { 2.0 } else { -2.0 };
                let w: Vec<f64> = o
                    .estimated()
                    .map(|t| match t.regressor.to_string().as_str() {
                        "1" => 1.0,
                        "a_x" => a,
                        "a_x^2" => a * a,
                        _ => 0.0,
                    })
                    .collect();
                let wv = nalgebra::DVector::from_vec(w);
                (wv.transpose() * &cov[k] * &wv)[(0, 0)]
            }
            EvaluatedAt::Position(i) => {
                let row = e2e.linearization().row(k, i);
                let table: f64 = row.iter().map(|c| (c * u_rect).powi(2)).sum();
                let r = covs[k].as_ref().unwrap().rate_error();
                table + r.white_sigma()[i].powi(2) + r.correlated_sigma()[i].powi(2)
            }
        };
        let out = b.output();
        assert_relative_eq!(out.combined(), var.sqrt(), max_relative = PROPAGATION_REL);
        // infinite degrees of freedom everywhere (type B and modelled noise): k = z_0.975
        assert_relative_eq!(
            out.coverage_factor(),
            1.959_963_984_540_054,
            max_relative = 1e-12
        );
        assert_relative_eq!(
            out.expanded(),
            out.coverage_factor() * out.combined(),
            max_relative = 1e-15
        );
        assert_relative_eq!(
            b.check().ratio(),
            out.expanded() / sp.limit(),
            max_relative = 1e-15
        );
        assert!(b.noise_modelled());
    }
    // the error over a range is at the end with the larger uncertainty, the accuracy at the
    // position with the largest one
    assert!(matches!(budgets[5].at(), EvaluatedAt::RangeEnd { .. }));
    assert!(matches!(budgets[6].at(), EvaluatedAt::Position(_)));
}

#[test]
fn the_noise_rows_carry_the_schedules_correlations() {
    let s = imu_with_specs();
    let e2e = common::simulator_of(&s);
    let table = table_inputs(&s, &e2e);
    let b = &e2e
        .budget()
        .specification_budgets(&s.specifications[..1], &table, &s.noise, s.timing.as_ref())
        .unwrap()[0];
    let rows = b.result().rows();
    assert_eq!(rows.len(), e2e.n_errors() + 2);
    assert_eq!(rows[e2e.n_errors()].name(), "noise, white (gx)");
    assert_eq!(rows[e2e.n_errors() + 1].name(), "noise, correlated (gx)");
    let c = e2e
        .calibration()
        .noise_covariances(&s.noise, s.timing.as_ref().unwrap())
        .unwrap()[0]
        .clone()
        .unwrap();
    // bg_x is the first estimated coefficient of gx
    let t = 0;
    assert_relative_eq!(
        rows[e2e.n_errors()].standard_uncertainty(),
        c.coefficients().white()[(t, t)].sqrt(),
        max_relative = 1e-15
    );
    assert_relative_eq!(
        rows[e2e.n_errors() + 1].standard_uncertainty(),
        c.coefficients().correlated()[(t, t)].sqrt(),
        max_relative = 1e-15
    );
    // the bias instability's averages are correlated between positions: the correlated part
    // is not the sum of independent per-position variances
    assert!(rows[e2e.n_errors() + 1].standard_uncertainty() > 0.0);
}

#[test]
fn without_a_timing_the_budget_has_the_table_only_and_says_so() {
    let s = imu_with_specs();
    let e2e = common::simulator_of(&s);
    let table = table_inputs(&s, &e2e);
    let budgets = e2e
        .budget()
        .specification_budgets(&s.specifications, &table, &s.noise, None)
        .unwrap();
    for b in &budgets {
        assert!(!b.noise_modelled());
        assert_eq!(b.result().rows().len(), e2e.n_errors());
        assert_relative_eq!(
            b.table_combined(),
            b.output().combined(),
            max_relative = 1e-12
        );
    }
    // one input per angular error, else an error naming the field
    let e = e2e
        .budget()
        .specification_budgets(&s.specifications, &table[1..], &s.noise, None)
        .unwrap_err();
    assert!(e.to_string().contains("table inputs"), "{e}");
}
