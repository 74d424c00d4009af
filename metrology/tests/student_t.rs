//! Student's t and normal quantiles against published tables and their own distribution
//! functions.

use approx::assert_relative_eq;
use metrology::special::{
    beta_quantile, inc_beta, normal_cdf, normal_quantile, student_t_cdf, student_t_quantile,
};

/// Tables print three decimals: half a unit of the last digit.
const TABLE_3_DECIMALS: f64 = 5e-4;

/// Round trips through the distribution function: a few units of double rounding in p
/// (absolute), and relative to p in the tails: 1e-11 (at 1e5 degrees of freedom the
/// logarithm of the prefactor, about 5e4 ln x, carries a few 1e-12).
const ROUND_TRIP_P: f64 = 1e-14;
const ROUND_TRIP_REL: f64 = 1e-11;

#[test]
fn t_quantiles_match_the_printed_tables_to_their_digits() {
    // JCGM 100 table G.2 / any statistics table: two-sided 95 % (t_0.975) and 99 % (t_0.995)
    let cases = [
        (0.975, 1.0, 12.706),
        (0.975, 2.0, 4.303),
        (0.975, 3.0, 3.182),
        (0.975, 5.0, 2.571),
        (0.975, 10.0, 2.228),
        (0.975, 16.0, 2.120),
        (0.975, 20.0, 2.086),
        (0.975, 30.0, 2.042),
        (0.975, 100.0, 1.984),
        (0.995, 1.0, 63.657),
        (0.995, 10.0, 3.169),
        (0.995, 16.0, 2.921),
        (0.95, 5.0, 2.015),
        (0.8413, 1.0, 1.837),
    ];
    for (p, nu, table) in cases {
        let t = student_t_quantile(p, nu);
        assert!(
            (t - table).abs() <= TABLE_3_DECIMALS,
            "t_{p}({nu}) = {t}, table {table}"
        );
    }
    // more digits (R qt): t_0.975(10) = 2.228138851986274, t_0.975(1) = 12.70620473617471
    assert_relative_eq!(
        student_t_quantile(0.975, 10.0),
        2.228_138_851_986_274,
        max_relative = 1e-13
    );
    assert_relative_eq!(
        student_t_quantile(0.975, 1.0),
        12.706_204_736_174_71,
        max_relative = 1e-13
    );
}

#[test]
fn infinite_dof_gives_the_normal_quantile_1_95996() {
    let k = student_t_quantile(0.975, f64::INFINITY);
    assert_relative_eq!(k, 1.959_963_984_540_054, max_relative = 1e-15);
    // and the t quantile tends to it: 1e5 and 1e7 degrees of freedom
    assert!(student_t_quantile(0.975, 1e5) > k);
    // the first term of the difference is (z^3 + z) / (4 nu) = 2.4e-7 at 1e7
    let first_term = (k.powi(3) + k) / 4e7;
    assert_relative_eq!(
        student_t_quantile(0.975, 1e7) - k,
        first_term,
        max_relative = 1e-6
    );
}

#[test]
fn t_quantile_inverts_the_distribution_function_for_real_dof() {
    for nu in [
        0.5, 1.0, 1.5, 2.0, 2.7, 4.0, 16.7, 50.0, 999.0, 5e4, 99_999.0,
    ] {
        for p in [
            1e-10, 1e-4, 0.005, 0.025, 0.3, 0.5, 0.75, 0.975, 0.995, 0.999_999,
        ] {
            let t = student_t_quantile(p, nu);
            let back = student_t_cdf(t, nu);
            assert!(
                (back - p).abs() <= ROUND_TRIP_P.max(ROUND_TRIP_REL * p),
                "nu {nu} p {p}: t {t}, F(t) {back}"
            );
        }
    }
}

#[test]
fn t_quantile_is_continuous_where_the_expansion_takes_over() {
    // below 1e5 the root of the distribution function, above the Cornish-Fisher expansion
    let below = student_t_quantile(0.995, 99_999.999);
    let above = student_t_quantile(0.995, 1e5);
    assert_relative_eq!(below, above, max_relative = 1e-12);
}

#[test]
fn normal_quantile_inverts_phi_in_both_tails() {
    for p in [1e-300, 1e-20, 1e-8, 0.01, 0.2, 0.5, 0.8, 0.99, 1.0 - 1e-12] {
        let x = normal_quantile(p);
        let back = normal_cdf(x);
        assert_relative_eq!(back, p, max_relative = 1e-13);
    }
    // tabulated: Phi(1) = 0.841344746068543, Phi^-1(0.995) = 2.575829303548901
    assert_relative_eq!(normal_cdf(1.0), 0.841_344_746_068_543, max_relative = 1e-14);
    assert_relative_eq!(
        normal_quantile(0.995),
        2.575_829_303_548_901,
        max_relative = 1e-14
    );
}

#[test]
fn incomplete_beta_matches_closed_forms_and_its_quantile() {
    // I_x(a, 1) = x^a, I_x(1, b) = 1 - (1 - x)^b
    for x in [0.01, 0.3, 0.77, 0.999] {
        assert_relative_eq!(inc_beta(3.5, 1.0, x), x.powf(3.5), max_relative = 1e-13);
        assert_relative_eq!(
            inc_beta(1.0, 4.0, x),
            1.0 - (1.0 - x).powi(4),
            max_relative = 1e-13
        );
        let p = inc_beta(7.0, 3.0, x);
        assert_relative_eq!(beta_quantile(7.0, 3.0, p), x, max_relative = 1e-12);
    }
}
