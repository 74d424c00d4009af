//! The JCGM 101 Monte Carlo of the whole calibration (issue 34 item 3): on the exact chain it
//! agrees with the GUM budget where the chain is linear (small tolerances), shows where it
//! does not (large tolerances: second-order errors the first-order budget cannot see), and
//! gives the same answer for any number of threads.

mod common;

use e2e_verify::budget_mc::SpecificationMonteCarlo;
use metrology::montecarlo::McSettings;
use study::Study;

fn arcsec(v: f64) -> f64 {
    v * std::f64::consts::PI / (180.0 * 3600.0)
}

/// The IMU example with a bias, a scale factor, a misalignment and an accuracy specified.
fn imu_with_specs() -> Study {
    let extra = "[[specifications]]\noutput = \"gx\"\ncoefficient = \"bg_x\"\nlimit = 0.05\nunit = \"deg_per_h\"\n\
[[specifications]]\noutput = \"ax\"\ncoefficient = \"sf_x\"\nlimit = 100.0\nunit = \"ppm\"\n\
[[specifications]]\noutput = \"ay\"\ncoefficient = \"mis_yz\"\nlimit = 20.0\nunit = \"arcsec\"\n\
[[specifications]]\noutput = \"gz\"\nquantity = \"accuracy\"\nlimit = 0.1\nunit = \"deg_per_h\"\n";
    common::imu_study_with(extra)
}

/// The laws of the table's errors in a run.
#[derive(Clone, Copy)]
enum Law {
    /// Rectangular on the tolerance (type B, a vendor's bound).
    Rectangular,
    /// Normal with the rectangular's standard uncertainty (a measured table).
    Normal,
}

/// Budgets and Monte Carlo of the IMU example's specifications with every angular error of
/// tolerance `tol_rad` under `law`, without noise (the table's part alone: the part the Monte
/// Carlo tests); the budgets' combined standard uncertainties and the runs.
fn run(tol_rad: f64, law: Law, digits: u32) -> (Vec<f64>, Vec<SpecificationMonteCarlo>) {
    let s = imu_with_specs();
    let e2e = common::simulator_of(&s);
    let tolerances = vec![tol_rad; e2e.n_errors()];
    let law = move |n: &str, a: f64| match law {
        Law::Rectangular => metrology::Input::rectangular(n, 0.0, a),
        Law::Normal => metrology::Input::normal(n, 0.0, a / 3.0_f64.sqrt()),
    };
    let verdict = e2e
        .budget()
        .plan_verdict(&s.specifications, &tolerances, law, &[], None)
        .unwrap();
    let table: Vec<_> = e2e
        .error_names()
        .iter()
        .map(|n| law(n, tol_rad).unwrap())
        .collect();
    let settings = McSettings {
        significant_digits: digits,
        seed: 7,
        ..McSettings::default()
    };
    let mc = e2e
        .budget()
        .specification_monte_carlo(&s.specifications, &verdict, &table, &settings)
        .unwrap();
    let u = verdict
        .budgets()
        .iter()
        .map(|b| b.output().combined())
        .collect();
    (u, mc)
}

/// The mean of each quantity the exact chain predicts for independent zero-mean errors of
/// variance `var`: the even part of the chain, $\sum_j \kappa_j \operatorname{var}_j$ with
/// $\kappa_j = (q(h\mathbf e_j) + q(-h\mathbf e_j)) / 2h^2$ (cross terms average out; the
/// cubic and higher even terms are below 1e-8 of it at these angles).
fn second_order_means(tol_rad: f64, var: f64) -> Vec<f64> {
    let s = imu_with_specs();
    let e2e = common::simulator_of(&s);
    let n = e2e.n_errors();
    let outputs = s.calibration.outputs();
    // the specified coefficients' places in coefficient_errors: bg_x of gx, sf_x of ax,
    // mis_yz of ay (study order of the estimated terms)
    let place = |output: &str, coef: &str| {
        let k = outputs
            .iter()
            .position(|o| o.output().name == output)
            .unwrap();
        let offset: usize = outputs[..k].iter().map(|o| o.beta().len()).sum();
        let t = outputs[k]
            .output()
            .estimated()
            .position(|t| t.coefficient == coef)
            .unwrap();
        offset + t
    };
    let places = [
        place("gx", "bg_x"),
        place("ax", "sf_x"),
        place("ay", "mis_yz"),
    ];
    let mut means = vec![0.0; places.len()];
    for j in 0..n {
        let mut chi = vec![0.0; n];
        chi[j] = tol_rad;
        let p = e2e.coefficient_errors(&chi).unwrap();
        chi[j] = -tol_rad;
        let m = e2e.coefficient_errors(&chi).unwrap();
        for (mean, &i) in means.iter_mut().zip(&places) {
            *mean += (p[i] + m[i]) / (2.0 * tol_rad * tol_rad) * var;
        }
    }
    means
}

/// At 10 arcsec per error the chain's first order carries the spread: the Monte Carlo's
/// standard uncertainty of each quantity equals the GUM budget's combined standard
/// uncertainty within the run's numerical tolerance (JCGM 101 7.9, two significant digits of
/// u(y)). Its mean is the chain's second order (the cosine of a tilt: the scale factor of an
/// accelerometer reads g cos(tilt), always low), which the first-order budget cannot see: the
/// Monte Carlo's mean equals the even part of the exact chain within the same tolerance.
#[test]
fn monte_carlo_spread_is_the_budgets_and_its_mean_the_chains_second_order() {
    let tol = arcsec(10.0);
    let (u, mc) = run(tol, Law::Rectangular, 2);
    assert_eq!(mc.len(), 4);
    let means = second_order_means(tol, tol * tol / 3.0);
    for (m, uc) in mc.iter().zip(&u) {
        let o = m.output();
        assert!(m.stabilized(), "spec {}", m.spec());
        assert!(
            (o.standard_uncertainty() - uc).abs() <= o.tolerance(),
            "spec {}: u_mc {} vs u_c {uc} (delta {})",
            m.spec(),
            o.standard_uncertainty(),
            o.tolerance()
        );
    }
    for (i, mean) in means.iter().enumerate() {
        let o = mc[i].output();
        assert!(
            (o.estimate() - mean).abs() <= o.tolerance(),
            "spec {i}: mean {} vs second order {mean} (delta {})",
            o.estimate(),
            o.tolerance()
        );
    }
    // the scale factor's bias is visible: more than twice the run's tolerance, always low
    assert!(means[1] < -2.0 * mc[1].output().tolerance());
}

/// With normal laws the chain's first order is a normal quantity and the GUM interval 0 +- U
/// is validated (JCGM 101 8.2) for the bias, the misalignment and eq 14's accuracy; the scale
/// factor's second-order bias (above) moves its interval by more than the tolerance, and the
/// Monte Carlo says so.
#[test]
fn monte_carlo_validates_the_gum_interval_on_the_linear_quantities_only() {
    let (_, mc) = run(arcsec(10.0), Law::Normal, 2);
    let validated: Vec<bool> = mc.iter().map(|m| m.validation().validated()).collect();
    assert_eq!(validated, [true, false, true, true], "{mc:#?}");
}

/// Rectangular laws: a sum of few rectangular errors has lighter tails than a normal one, so
/// the GUM's interval (k = 1.96 for infinite degrees of freedom) is wider than the Monte
/// Carlo's and not validated, on the conservative side; at 1 degree the scale factor's
/// second order dominates its spread (a mean of about -u) and nothing is validated.
#[test]
fn monte_carlo_shows_where_the_gum_budget_does_not_hold() {
    let (u, mc) = run(arcsec(10.0), Law::Rectangular, 2);
    for (m, uc) in mc.iter().zip(&u) {
        let (lo, hi) = m.output().symmetric();
        assert!(!m.validation().validated(), "spec {}", m.spec());
        assert!(hi - lo < 2.0 * 1.96 * uc, "spec {}", m.spec());
    }
    let (_, mc) = run(1.0_f64.to_radians(), Law::Rectangular, 2);
    assert!(mc.iter().all(|m| !m.validation().validated()));
    let sf = mc[1].output();
    assert!(sf.estimate() < -sf.standard_uncertainty());
    assert!(sf.symmetric().1 < 0.0);
}

/// The same seed gives the same answer on one thread and on all of them.
#[test]
fn monte_carlo_is_the_same_for_any_number_of_threads() {
    let one = common::on_threads(1, || run(arcsec(30.0), Law::Rectangular, 1).1);
    let all = run(arcsec(30.0), Law::Rectangular, 1).1;
    assert_eq!(one, all);
}
