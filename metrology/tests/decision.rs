//! ILAC-G8:09/2019 decision rules and JCGM 106 risks against closed forms.

use approx::assert_relative_eq;
use metrology::decision::{
    DecisionRule, Measured, Prior, Statement, Tolerance, decide, global_risks, probability_outside,
    statement,
};
use metrology::special::normal_cdf;
use tt_core::ErrorClass;

/// Risks against closed forms (the issue asks 1e-6; the quadrature holds far better).
const RISK_ABS: f64 = 1e-9;

/// 97.5 % point of the normal distribution.
const K95: f64 = 1.959_963_984_540_054;

#[test]
fn simple_acceptance_has_a_50_percent_false_accept_risk_at_the_limit() {
    let tol = Tolerance::upper(10.0).unwrap();
    let d = decide(
        DecisionRule::SimpleAcceptance,
        &tol,
        &Measured::new(10.0, 0.4, 2.0).unwrap(),
    );
    assert!(d.accepted());
    assert_relative_eq!(d.specific_risk(), 0.5, epsilon = RISK_ABS);
    assert!(d.to_string().starts_with("accept: measured 10 (U = 0.4) in the acceptance interval [-inf, 10] by simple acceptance (w = 0; ILAC-G8:09/2019 4.2.1)"), "{d}");
    // the specific risk is 1 - Phi((TU - y) / u) below the limit
    let d = decide(
        DecisionRule::SimpleAcceptance,
        &tol,
        &Measured::new(9.7, 0.4, 2.0).unwrap(),
    );
    assert_relative_eq!(
        d.specific_risk(),
        1.0 - normal_cdf(0.3 / 0.2),
        epsilon = RISK_ABS
    );
}

#[test]
fn guard_band_w_equals_u_at_95_percent_caps_the_false_accept_risk_at_2_5_percent() {
    let tol = Tolerance::upper(10.0).unwrap();
    let m = Measured::new(10.0 - 0.4, 0.4, K95).unwrap(); // on the acceptance limit
    let d = decide(DecisionRule::GuardBandExpanded, &tol, &m);
    assert!(d.accepted());
    assert_relative_eq!(
        d.acceptance().interval().upper_limit().unwrap(),
        9.6,
        epsilon = 1e-12
    );
    assert_relative_eq!(d.specific_risk(), 0.025, epsilon = RISK_ABS);
    // just above: rejected, with the probability that it conforms after all
    let m = Measured::new(9.7, 0.4, K95).unwrap();
    let d = decide(DecisionRule::GuardBandExpanded, &tol, &m);
    assert!(!d.accepted());
    assert_relative_eq!(
        d.specific_risk(),
        normal_cdf(0.3 * K95 / 0.4),
        epsilon = RISK_ABS
    );
    assert!(
        d.to_string()
            .contains("specific probability of false reject"),
        "{d}"
    );
}

#[test]
fn guard_band_for_a_stated_risk_puts_that_risk_on_the_acceptance_limit() {
    let rule = DecisionRule::guard_band_for_risk(0.01).unwrap();
    // one limit: w = z_0.99 u
    let tol = Tolerance::lower(5.0).unwrap();
    let m = Measured::new(5.0, 0.2, 2.0).unwrap();
    let a = rule.acceptance(&tol, 0.1, 0.2);
    assert_relative_eq!(
        a.guard_band(),
        0.1 * 2.326_347_874_040_841,
        max_relative = 1e-12
    );
    let at_limit = Measured::new(a.interval().lower_limit().unwrap(), 0.2, 2.0).unwrap();
    assert_relative_eq!(
        probability_outside(&tol, &at_limit, None),
        0.01,
        epsilon = RISK_ABS
    );
    assert!(!decide(rule, &tol, &m).accepted());
    // two limits close together: both tails count
    let tol = Tolerance::two_sided(-0.3, 0.3).unwrap();
    let a = rule.acceptance(&tol, 0.1, 0.2);
    let at_limit = Measured::new(a.interval().upper_limit().unwrap(), 0.2, 2.0).unwrap();
    assert_relative_eq!(
        probability_outside(&tol, &at_limit, None),
        0.01,
        epsilon = RISK_ABS
    );
    assert!(a.guard_band() > 0.1 * 2.326_347_874_040_841 - 1e-12);
    // too narrow for the risk: nothing is accepted
    let narrow = Tolerance::two_sided(-0.2, 0.2).unwrap();
    let a = rule.acceptance(&narrow, 0.1, 0.2);
    assert!(a.is_empty() && !a.contains(0.0));
    assert!(!decide(rule, &narrow, &Measured::new(0.0, 0.2, 2.0).unwrap()).accepted());
}

#[test]
fn non_binary_statements_follow_ilac_g8_figure_5_at_both_limits() {
    let tol = Tolerance::two_sided(1.0, 2.0).unwrap();
    let cases = [
        (1.5, Statement::Pass),
        (1.85, Statement::ConditionalPass),
        (1.05, Statement::ConditionalPass),
        (2.15, Statement::ConditionalFail),
        (0.9, Statement::ConditionalFail),
        (2.3, Statement::Fail),
        (0.7, Statement::Fail),
    ];
    for (y, expected) in cases {
        let s = statement(&tol, &Measured::new(y, 0.2, 2.0).unwrap());
        assert_eq!(s, expected, "y = {y}");
    }
    assert_eq!(Statement::ConditionalPass.to_string(), "conditional pass");
    // upper limit only
    let tol = Tolerance::upper(0.5).unwrap();
    assert_eq!(
        statement(&tol, &Measured::new(-100.0, 0.1, 2.0).unwrap()),
        Statement::Pass
    );
}

#[test]
fn the_posterior_specific_risk_shrinks_towards_the_prior() {
    // y = 1, u = 1, prior N(0, 1): posterior N(0.5, 1/2)
    let tol = Tolerance::upper(1.0).unwrap();
    let m = Measured::new(1.0, 2.0, 2.0).unwrap();
    let p = probability_outside(&tol, &m, Some(&Prior::new(0.0, 1.0).unwrap()));
    assert_relative_eq!(
        p,
        1.0 - normal_cdf(0.5 / 0.5_f64.sqrt()),
        epsilon = RISK_ABS
    );
}

/// Owen's T function by composite Simpson (independent of the crate's quadrature):
/// T(h, a) = 1/(2 pi) int_0^a exp(-h^2 (1 + x^2) / 2) / (1 + x^2) dx.
fn owen_t(h: f64, a: f64) -> f64 {
    let n = 20_000;
    let f = |x: f64| (-0.5 * h * h * (1.0 + x * x)).exp() / (1.0 + x * x);
    let dx = a / n as f64;
    let mut s = f(0.0) + f(a);
    for i in 1..n {
        s += f(i as f64 * dx) * if i % 2 == 1 { 4.0 } else { 2.0 };
    }
    s * dx / 3.0 / std::f64::consts::TAU
}

/// The bivariate normal distribution function by Owen (1956): Phi_2(h, k; rho).
fn bivariate_normal(h: f64, k: f64, rho: f64) -> f64 {
    let r = (1.0 - rho * rho).sqrt();
    let beta = if h * k > 0.0 || (h * k == 0.0 && h + k >= 0.0) {
        0.0
    } else {
        0.5
    };
    0.5 * normal_cdf(h) + 0.5 * normal_cdf(k)
        - owen_t(h, (k - rho * h) / (h * r))
        - owen_t(k, (h - rho * k) / (k * r))
        - beta
}

#[test]
fn global_risks_equal_the_bivariate_normal_closed_forms() {
    // prior centred on the limit, simple acceptance: the orthant probability
    let tol = Tolerance::upper(2.0).unwrap();
    let (u0, um) = (0.8, 0.3);
    let prior = Prior::new(2.0, u0).unwrap();
    let a = DecisionRule::SimpleAcceptance.acceptance(&tol, um, 2.0 * um);
    let r = global_risks(&tol, &a, &prior, um).unwrap();
    let rho = u0 / (u0 * u0 + um * um).sqrt();
    let orthant = 0.25 - rho.asin() / std::f64::consts::TAU;
    assert_relative_eq!(r.false_accept(), orthant, epsilon = RISK_ABS);
    assert_relative_eq!(r.false_reject(), orthant, epsilon = RISK_ABS);
    assert_relative_eq!(r.conforming(), 0.5, epsilon = 1e-15);

    // prior off the limit, guard band w = U: R_C = P(Y > TU, Ym <= AU) = Phi(k) - Phi_2(h, k),
    // R_P = P(Y <= TU, Ym > AU) = Phi(h) - Phi_2(h, k); h, k standardised limits
    let prior = Prior::new(1.5, u0).unwrap();
    let a = DecisionRule::GuardBandExpanded.acceptance(&tol, um, 2.0 * um);
    let r = global_risks(&tol, &a, &prior, um).unwrap();
    let sm = (u0 * u0 + um * um).sqrt();
    let h = (2.0 - 1.5) / u0;
    let k = (2.0 - 0.6 - 1.5) / sm;
    let both = bivariate_normal(h, k, rho);
    assert_relative_eq!(r.false_accept(), normal_cdf(k) - both, epsilon = RISK_ABS);
    assert_relative_eq!(r.false_reject(), normal_cdf(h) - both, epsilon = RISK_ABS);
}

#[test]
fn global_risks_of_a_two_sided_tolerance_balance_the_acceptance_probability() {
    // P(accept) = P(conform) - R_P + R_C, and P(accept) = Phi((AU-y0)/sm) - Phi((AL-y0)/sm)
    let tol = Tolerance::two_sided(-1.0, 1.5).unwrap();
    let prior = Prior::new(0.2, 0.7).unwrap();
    for rule in [
        DecisionRule::SimpleAcceptance,
        DecisionRule::GuardBandExpanded,
        DecisionRule::guard_band_for_risk(0.05).unwrap(),
    ] {
        let um = 0.25;
        let a = rule.acceptance(&tol, um, 2.0 * um);
        let r = global_risks(&tol, &a, &prior, um).unwrap();
        let sm = (0.49_f64 + um * um).sqrt();
        let accept = normal_cdf((a.interval().upper_limit().unwrap() - 0.2) / sm)
            - normal_cdf((a.interval().lower_limit().unwrap() - 0.2) / sm);
        assert_relative_eq!(
            r.conforming() - r.false_reject() + r.false_accept(),
            accept,
            epsilon = RISK_ABS
        );
        assert!(r.false_accept() > 0.0 && r.false_reject() > 0.0);
    }
}

#[test]
fn bad_decision_input_names_the_key() {
    assert_eq!(
        Prior::new(0.0, 0.0).unwrap_err().input_field(),
        Some("prior.sd")
    );
    assert_eq!(
        Prior::new(0.0, -1.0).unwrap_err().input_field(),
        Some("prior.sd")
    );
    assert_eq!(
        Prior::new(f64::NAN, 1.0).unwrap_err().input_field(),
        Some("prior.mean")
    );
    assert_eq!(
        DecisionRule::guard_band_for_risk(0.0)
            .unwrap_err()
            .input_field(),
        Some("max_false_accept")
    );
    assert_eq!(
        DecisionRule::guard_band_for_risk(1.0)
            .unwrap_err()
            .input_field(),
        Some("max_false_accept")
    );
    assert_eq!(
        Tolerance::two_sided(1.0, 1.0).unwrap_err().input_field(),
        Some("tolerance.upper")
    );
    assert_eq!(
        Measured::new(1.0, -0.1, 2.0).unwrap_err().input_field(),
        Some("measured.expanded")
    );
    assert_eq!(
        Measured::new(1.0, 0.1, 0.0).unwrap_err().input_field(),
        Some("measured.coverage_factor")
    );
    let e = Prior::new(0.0, 0.0).unwrap_err();
    assert_eq!(e.to_string(), "prior.sd must be positive, got 0");
}
