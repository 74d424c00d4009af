//! The noise model of an output: datasheet unit conversions (checked against the definition
//! of a random walk), the bias-instability to Gauss-Markov mapping (IEEE Std 952-1997 Annex C,
//! El-Sheimy et al. 2008), the variance and covariance of window averages (checked against an
//! independent numerical integration of the autocovariance), and bad input.

use approx::assert_relative_eq;
use gw_model::ModelError;
use gw_model::noise::{
    FLICKER_BANK_RATIO, FLICKER_FLOOR_PER_BIAS_INSTABILITY, FlickerBank, GM_ADEV_PEAK_PER_SIGMA,
    GM_ADEV_PEAK_TAU_PER_TC, GaussMarkov, NoiseModel, OUTPUT_UNITS, OutputUnit,
    STANDARD_GRAVITY_M_PER_S2, UnitFamily, WhiteDensity, Window,
};
use rand_chacha::ChaCha8Rng;
use rand_core::SeedableRng;
use testkit::random::normals;
use tt_core::FieldError;

/// Unit conversions are products of a few exact constants: a few ulps, relative.
const CONVERSION_REL: f64 = 1e-14;
/// Closed forms of averages against a 10-point Gauss-Legendre rule on cells no longer than a
/// correlation time (error far below 1e-12), relative.
const QUADRATURE_REL: f64 = 1e-10;
/// The fast (recursive) matrix against the pairwise closed form: products of up to 40
/// exponentials, relative to the largest entry.
const RECURSION_REL: f64 = 1e-12;
/// A maximum located by golden-section search to 1e-12 in u: the value is flat there, so
/// it agrees to rounding and the location to about 1e-6 (square root of the rounding),
/// dimensionless.
const PEAK_VALUE_REL: f64 = 1e-12;
const PEAK_LOCATION_ABS: f64 = 1e-6;

// ---------------------------------------------------------------- unit conversions

/// The brief's and every datasheet's figure: 1 deg/sqrt(h) = 60 (deg/h)/sqrt(Hz); a STIM300's
/// 0.15 deg/sqrt(h) is 9 (deg/h)/sqrt(Hz). The same density in deg/s and rad/s.
#[test]
fn angle_random_walk_converts_to_60_deg_per_h_per_sqrt_hz() {
    let arw = WhiteDensity::DegPerSqrtH(0.15);
    for unit in ["deg_per_h", "deg/h"] {
        assert_relative_eq!(
            arw.in_output_unit(unit).unwrap(),
            9.0,
            max_relative = CONVERSION_REL
        );
    }
    for unit in ["deg_per_s", "deg/s"] {
        assert_relative_eq!(
            arw.in_output_unit(unit).unwrap(),
            0.15 / 60.0,
            max_relative = CONVERSION_REL
        );
    }
    for unit in ["rad_per_s", "rad/s"] {
        assert_relative_eq!(
            arw.in_output_unit(unit).unwrap(),
            0.15_f64.to_radians() / 60.0,
            max_relative = CONVERSION_REL
        );
    }
}

/// Velocity random walk: 1 (m/s)/sqrt(h) = 1/60 (m/s^2)/sqrt(Hz) = 1000/(60 * 9.80665)
/// mg/sqrt(Hz) = 1.69953 mg/sqrt(Hz); 1 ug/sqrt(Hz) = 1e-3 mg/sqrt(Hz) = 9.80665e-6
/// (m/s^2)/sqrt(Hz).
#[test]
fn velocity_random_walk_and_ug_density_convert_to_every_specific_force_unit() {
    let vrw = WhiteDensity::MPerSPerSqrtH(1.0);
    let expected = [
        ("m_per_s2", 1.0 / 60.0),
        ("m/s^2", 1.0 / 60.0),
        ("m/s2", 1.0 / 60.0),
        ("g", 1.0 / 60.0 / 9.80665),
        ("mg", 1000.0 / 60.0 / 9.80665),
        ("ug", 1e6 / 60.0 / 9.80665),
    ];
    for (unit, v) in expected {
        assert_relative_eq!(
            vrw.in_output_unit(unit).unwrap(),
            v,
            max_relative = CONVERSION_REL
        );
    }
    assert_relative_eq!(
        vrw.in_output_unit("mg").unwrap(),
        1.699_53,
        max_relative = 1e-5 // the five digits printed in the docs
    );
    let ug = WhiteDensity::UgPerSqrtHz(1.0);
    for (unit, v) in [
        ("ug", 1.0),
        ("mg", 1e-3),
        ("g", 1e-6),
        ("m_per_s2", 9.80665e-6),
    ] {
        assert_relative_eq!(
            ug.in_output_unit(unit).unwrap(),
            v,
            max_relative = CONVERSION_REL
        );
    }
}

/// The definition behind every `per sqrt(h)` conversion: integrating white rate noise of
/// density N for t seconds gives an angle random walk of standard deviation N sqrt(t). With
/// the converted density, the angle after 1 h (the 1-hour average times 1 h) has the
/// datasheet's coefficient as its standard deviation: 0.15 deg for 0.15 deg/sqrt(h), and
/// 0.07 m/s for 0.07 (m/s)/sqrt(h).
#[test]
fn random_walk_after_one_hour_equals_the_datasheet_coefficient() {
    let hour = Window::new(0.0, 3600.0).unwrap();
    let gyro = NoiseModel::from_datasheet(
        "deg_per_h",
        Some(WhiteDensity::DegPerSqrtH(0.15)),
        None,
        None,
    )
    .unwrap();
    // deg/h times 1 h = deg
    let angle_deg = gyro.white_variance_of_average(&hour, 1.0).sqrt() * 1.0;
    assert_relative_eq!(angle_deg, 0.15, max_relative = CONVERSION_REL);
    let acc = NoiseModel::from_datasheet("mg", Some(WhiteDensity::MPerSPerSqrtH(0.07)), None, None)
        .unwrap();
    // mg -> m/s^2, times 3600 s = m/s
    let velocity = acc.white_variance_of_average(&hour, 1.0).sqrt()
        * STANDARD_GRAVITY_M_PER_S2
        * 1e-3
        * 3600.0;
    assert_relative_eq!(velocity, 0.07, max_relative = CONVERSION_REL);
}

/// `white_per_sqrt_hz` is already in the output's unit: no conversion, any label, even one
/// no table knows.
#[test]
fn density_in_the_output_unit_needs_no_known_unit() {
    for unit in ["deg_per_h", "mg", "counts"] {
        assert_eq!(
            WhiteDensity::PerSqrtHz(2.5)
                .in_output_unit(unit)
                .unwrap()
                .to_bits(),
            2.5f64.to_bits()
        );
    }
    assert_eq!(OutputUnit::parse("counts"), None);
    assert_eq!(
        OutputUnit::parse("mg").unwrap().family(),
        UnitFamily::SpecificForce
    );
    assert_eq!(
        OutputUnit::parse("deg/h").unwrap().family(),
        UnitFamily::AngularRate
    );
    // every listed label parses to its row
    for &(label, family, si) in OUTPUT_UNITS {
        let u = OutputUnit::parse(label).unwrap();
        assert_eq!(
            (u.family(), u.si_per_unit().to_bits()),
            (family, si.to_bits()),
            "{label}"
        );
    }
}

/// A density of one family for an output of the other is a typed error naming the key and
/// the output's unit; a conversion to an unknown unit names both too.
#[test]
fn density_of_the_other_family_is_an_error_naming_key_and_unit() {
    let e = WhiteDensity::DegPerSqrtH(0.15)
        .in_output_unit("mg")
        .unwrap_err();
    assert_eq!(
        e,
        ModelError::UnitFamilyMismatch {
            key: "white_deg_per_sqrt_h".into(),
            unit: "mg".into(),
            key_family: UnitFamily::AngularRate,
            unit_family: UnitFamily::SpecificForce,
        }
    );
    let msg = e.to_string();
    assert!(
        msg.contains("white_deg_per_sqrt_h") && msg.contains("\"mg\""),
        "{msg}"
    );
    for key in [
        WhiteDensity::UgPerSqrtHz(30.0),
        WhiteDensity::MPerSPerSqrtH(0.07),
    ] {
        let msg = key.in_output_unit("deg_per_h").unwrap_err().to_string();
        assert!(
            msg.contains(key.key()) && msg.contains("deg_per_h") && msg.contains("an angular rate"),
            "{msg}"
        );
    }
    let e = WhiteDensity::DegPerSqrtH(0.15)
        .in_output_unit("furlong\n")
        .unwrap_err();
    assert!(matches!(e, ModelError::UnknownUnit { .. }));
    // the label is shown escaped, never as a raw control character
    let msg = e.to_string();
    assert!(msg.contains("furlong\\n") && !msg.contains('\n'), "{msg}");
}

// ---------------------------------------------------------------- bias instability

/// sqrt(2 ln 2 / pi), the flicker floor of IEEE Std 952-1997 Annex C.
#[test]
fn flicker_floor_constant_is_sqrt_2_ln2_over_pi() {
    assert_relative_eq!(
        FLICKER_FLOOR_PER_BIAS_INSTABILITY,
        (2.0 * std::f64::consts::LN_2 / std::f64::consts::PI).sqrt(),
        max_relative = 1e-15
    );
}

/// The Gauss-Markov Allan deviation (El-Sheimy et al. 2008, Table I) peaks at u* = 1.8926
/// with height 0.61736 sigma: u* solves u g'(u) = 2 g(u), and a golden-section search of the
/// Allan variance built from the window averages (Var - Cov of adjacent windows, not the
/// closed form) finds the same maximum.
#[test]
fn gauss_markov_allan_deviation_peaks_at_1_89_tc_with_0_6174_sigma() {
    let u = GM_ADEV_PEAK_TAU_PER_TC;
    let g = |u: f64| 2.0 * u - 3.0 + 4.0 * (-u).exp() - (-2.0 * u).exp();
    let dg = |u: f64| 2.0 * (1.0 - (-u).exp()).powi(2);
    assert!((u * dg(u) - 2.0 * g(u)).abs() < 1e-14);
    assert_relative_eq!(
        GM_ADEV_PEAK_PER_SIGMA,
        g(u).sqrt() / u,
        max_relative = 1e-15
    );
    let gm = GaussMarkov::new(1.0, 1.0).unwrap();
    let from_windows = |tau: f64| {
        let (w1, w2) = (
            Window::new(0.0, tau).unwrap(),
            Window::new(tau, tau).unwrap(),
        );
        gm.variance_of_average(&w1) - gm.covariance_of_averages(&w1, &w2)
    };
    let (mut a, mut b) = (0.5, 5.0);
    let r = (5f64.sqrt() - 1.0) / 2.0;
    while b - a > 1e-12 {
        let (c, d) = (b - r * (b - a), a + r * (b - a));
        if from_windows(c) > from_windows(d) {
            b = d;
        } else {
            a = c;
        }
    }
    let peak = 0.5 * (a + b);
    assert!(
        (peak - GM_ADEV_PEAK_TAU_PER_TC).abs() < PEAK_LOCATION_ABS,
        "{peak}"
    );
    assert_relative_eq!(
        from_windows(peak).sqrt(),
        GM_ADEV_PEAK_PER_SIGMA,
        max_relative = PEAK_VALUE_REL
    );
    // the closed form agrees with the window route everywhere (series and closed branches)
    for tau in [1e-4, 0.1, 0.49, 0.51, 1.0, 1.89, 10.0, 1e3] {
        assert_relative_eq!(
            gm.allan_variance(tau),
            from_windows(tau),
            max_relative = 1e-9
        );
    }
    // limits: rising as 2u/3 sigma^2, falling as 2 Tc / tau sigma^2
    assert_relative_eq!(gm.allan_variance(1e-6), 2e-6 / 3.0, max_relative = 1e-5);
    assert_relative_eq!(gm.allan_variance(1e6), 2e-6, max_relative = 1e-5);
}

/// Datasheet B -> sigma_b = 0.6643/0.6174 B = 1.0760 B, whose Allan deviation has its maximum,
/// at tau = 1.8926 Tc, equal to the datasheet's floor 0.6643 B (STIM300: 0.5 deg/h, Tc 1 h).
#[test]
fn bias_instability_maps_to_a_gauss_markov_whose_allan_peak_is_the_flicker_floor() {
    let (b, tc) = (0.5, 3600.0);
    let gm = GaussMarkov::from_bias_instability(b, tc).unwrap();
    assert_relative_eq!(gm.sigma(), 1.075_997_572_915 * b, max_relative = 1e-11);
    assert_relative_eq!(gm.bias_instability(), b, max_relative = 1e-15);
    let peak = gm.allan_variance(GM_ADEV_PEAK_TAU_PER_TC * tc).sqrt();
    assert_relative_eq!(
        peak,
        FLICKER_FLOOR_PER_BIAS_INSTABILITY * b,
        max_relative = 1e-14
    );
    for f in [0.9, 0.99, 1.01, 1.1] {
        assert!(gm.allan_variance(f * GM_ADEV_PEAK_TAU_PER_TC * tc).sqrt() < peak);
    }
    assert_relative_eq!(
        gm.autocovariance(-tc),
        gm.sigma().powi(2) / std::f64::consts::E,
        max_relative = 1e-15
    );
}

// ---------------------------------------------------------------- window averages

/// Gauss-Legendre nodes and weights on [0, 1] (Newton on P_n).
fn gauss_legendre(n: usize) -> Vec<(f64, f64)> {
    (0..n)
        .map(|i| {
            let mut x = (std::f64::consts::PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
            let mut dp = 0.0;
            for _ in 0..100 {
                let (mut p0, mut p1) = (1.0, x);
                for k in 2..=n {
                    let k = k as f64;
                    let p2 = ((2.0 * k - 1.0) * x * p1 - (k - 1.0) * p0) / k;
                    p0 = p1;
                    p1 = p2;
                }
                dp = n as f64 * (x * p1 - p0) / (x * x - 1.0);
                let dx = p1 / dp;
                x -= dx;
                if dx.abs() < 1e-16 {
                    break;
                }
            }
            let w = 2.0 / ((1.0 - x * x) * dp * dp);
            (0.5 * (1.0 - x), 0.5 * w)
        })
        .collect()
}

/// (1/(T1 T2)) * double integral of sigma^2 exp(-|s - u| / Tc) over s in w1, u in w2,
/// numerically: both axes cut at every window end and into cells no longer than Tc/2,
/// 10-point Gauss-Legendre per cell; cells on the diagonal (where the kink is) are two
/// triangles, each mapped to the unit square.
fn numerical_gm_covariance(sigma: f64, tc: f64, w1: (f64, f64), w2: (f64, f64)) -> f64 {
    let k = |s: f64, u: f64| (-(s - u).abs() / tc).exp();
    sigma * sigma * numerical_window_covariance(k, 0.5 * tc, &[], w1, w2)
}

/// (1/(T1 T2)) * double integral of a symmetric kernel k(s, u), smooth off the diagonal and
/// off the lines through `kinks`, over s in w1, u in w2: both axes cut at every window end
/// and kink and into cells no longer than `cell`, 10-point Gauss-Legendre per cell; cells on
/// the diagonal (where the kink is) are two triangles, each mapped to the unit square.
fn numerical_window_covariance(
    k: impl Fn(f64, f64) -> f64,
    cell: f64,
    kinks: &[f64],
    w1: (f64, f64),
    w2: (f64, f64),
) -> f64 {
    let gl = gauss_legendre(10);
    let mut cuts = vec![w1.0, w1.1, w2.0, w2.1];
    let (lo, hi) = (w1.0.min(w2.0), w1.1.max(w2.1));
    cuts.extend(kinks.iter().filter(|&&x| x > lo && x < hi));
    cuts.sort_by(f64::total_cmp);
    cuts.dedup();
    let mut edges = vec![cuts[0]];
    for p in cuts.windows(2) {
        let m = ((p[1] - p[0]) / cell).ceil().max(1.0) as usize;
        for k in 1..=m {
            edges.push(p[0] + (p[1] - p[0]) * k as f64 / m as f64);
        }
    }
    let mut sum = 0.0;
    for (a, ci) in edges.windows(2).enumerate() {
        for (b, cj) in edges.windows(2).enumerate() {
            let (p, q, r, t) = (ci[0], ci[1], cj[0], cj[1]);
            let in1 = p >= w1.0 && q <= w1.1;
            let in2 = r >= w2.0 && t <= w2.1;
            if !(in1 && in2) {
                continue;
            }
            if a == b {
                // same cell: triangle u <= s in [p, q]^2, twice (the integrand is symmetric)
                let h = q - p;
                for &(x, wx) in &gl {
                    let s = p + h * x;
                    for &(y, wy) in &gl {
                        let u = p + (s - p) * y;
                        sum += 2.0 * wx * wy * h * (s - p) * k(s, u);
                    }
                }
            } else {
                for &(x, wx) in &gl {
                    for &(y, wy) in &gl {
                        sum += wx * wy * (q - p) * (t - r) * k(p + (q - p) * x, r + (t - r) * y);
                    }
                }
            }
        }
    }
    sum / ((w1.1 - w1.0) * (w2.1 - w2.0))
}

/// Window pairs (ends, s) every closed form of a covariance of averages is checked on.
const WINDOW_PAIRS: [((f64, f64), (f64, f64)); 6] = [
    ((0.0, 60.0), (70.0, 130.0)), // disjoint, after
    ((70.0, 130.0), (0.0, 60.0)), // disjoint, before
    ((0.0, 60.0), (60.0, 120.0)), // adjacent
    ((0.0, 60.0), (40.0, 100.0)), // overlapping
    ((0.0, 100.0), (20.0, 50.0)), // nested
    ((10.0, 70.0), (10.0, 70.0)), // identical
];

/// The closed forms of the Gauss-Markov covariance of window averages (disjoint in both
/// orders, adjacent, overlapping, nested, identical; windows short and long against Tc) agree
/// with an independent numerical double integral of the autocovariance.
#[test]
fn gauss_markov_covariance_of_window_averages_matches_numerical_integration() {
    let (sigma, tc) = (0.7, 30.0);
    let gm = GaussMarkov::new(sigma, tc).unwrap();
    let cases = [
        ((0.0, 0.5), (3.0, 3.25)),       // short against Tc
        ((0.0, 400.0), (500.0, 1000.0)), // long against Tc
        ((0.0, 1.0), (0.5, 1.5)),        // short, overlapping
    ];
    for (w1, w2) in WINDOW_PAIRS.into_iter().chain(cases) {
        let expected = numerical_gm_covariance(sigma, tc, w1, w2);
        let a = Window::new(w1.0, w1.1 - w1.0).unwrap();
        let b = Window::new(w2.0, w2.1 - w2.0).unwrap();
        assert_relative_eq!(
            gm.covariance_of_averages(&a, &b),
            expected,
            max_relative = QUADRATURE_REL
        );
        if w1 == w2 {
            assert_relative_eq!(
                gm.variance_of_average(&a),
                expected,
                max_relative = QUADRATURE_REL
            );
        }
    }
    // limits of the variance: frozen for T << Tc, white-like 2 sigma^2 Tc / T for T >> Tc
    let short = Window::new(0.0, 1e-6 * tc).unwrap();
    assert_relative_eq!(
        gm.variance_of_average(&short),
        sigma * sigma,
        max_relative = 1e-6
    );
    let long = Window::new(0.0, 1e7 * tc).unwrap();
    assert_relative_eq!(
        gm.variance_of_average(&long),
        2.0 * sigma * sigma / 1e7,
        max_relative = 1e-6
    );
}

/// White noise and quantization: N^2/T and q^2/(12 fs T) for a window, which is the mean of
/// m = fs T samples of variance N^2 fs + q^2/12 each (the discrete form); overlapping windows
/// share the samples of their intersection.
#[test]
fn white_and_quantization_variances_of_an_average_are_n2_over_t_and_q2_over_12_fs_t() {
    let (n, q, fs) = (9.0, 0.5, 125.0);
    let noise = NoiseModel::new(n, None, q).unwrap();
    let w = Window::new(100.0, 60.0).unwrap();
    let m = fs * 60.0;
    assert_relative_eq!(
        noise.white_variance_of_average(&w, fs),
        n * n / 60.0 + q * q / (12.0 * fs * 60.0),
        max_relative = CONVERSION_REL
    );
    assert_relative_eq!(
        noise.white_variance_of_average(&w, fs),
        (n * n * fs + q * q / 12.0) / m,
        max_relative = CONVERSION_REL
    );
    assert_relative_eq!(
        noise.quantization_variance_of_average(&w, fs),
        q * q / (12.0 * m),
        max_relative = CONVERSION_REL
    );
    assert_eq!(noise.correlated_variance_of_average(&w).to_bits(), 0);
    // half of w shared with a window of the same length: half the variance
    let half = Window::new(130.0, 60.0).unwrap();
    assert_relative_eq!(
        noise.white_covariance_of_averages(&w, &half, fs),
        0.5 * noise.white_variance_of_average(&w, fs),
        max_relative = CONVERSION_REL
    );
    let later = Window::new(160.0, 60.0).unwrap();
    assert_eq!(noise.covariance_of_averages(&w, &later, fs).to_bits(), 0);
}

/// The n x n matrix of a schedule's windows (built with one exponential per gap, in time
/// order) equals the pairwise closed forms, whatever the order the windows are given in; and
/// overlapping windows take the general form.
#[test]
fn window_covariance_matrix_equals_pairwise_closed_forms_in_any_order() {
    let noise = NoiseModel::new(
        2.0,
        Some(GaussMarkov::from_bias_instability(0.5, 45.0).unwrap()),
        0.1,
    )
    .unwrap();
    let fs = 200.0;
    // 40 disjoint windows of varying dwell, listed out of time order
    let mut t = 0.0;
    let mut windows = Vec::new();
    for k in 0..40 {
        let dwell = 20.0 + 7.0 * f64::from(k % 5);
        windows.push(Window::new(t, dwell).unwrap());
        t += dwell + 8.0;
    }
    windows.swap(0, 17);
    windows.swap(3, 39);
    windows.reverse();
    let disjoint = windows.clone();
    let mut overlapping = windows;
    overlapping.push(Window::new(15.0, 100.0).unwrap());
    for ws in [disjoint, overlapping] {
        let c = noise.window_covariance(&ws, fs).unwrap();
        let scale = c.total().amax();
        for (i, a) in ws.iter().enumerate() {
            for (j, b) in ws.iter().enumerate() {
                let white = noise.white_covariance_of_averages(a, b, fs);
                let corr = noise.covariance_of_averages(a, b, fs) - white;
                assert!((c.white()[(i, j)] - white).abs() <= RECURSION_REL * scale);
                assert!(
                    (c.correlated()[(i, j)] - corr).abs() <= RECURSION_REL * scale,
                    "{i} {j}: {} vs {corr}",
                    c.correlated()[(i, j)]
                );
            }
        }
    }
    // far-apart windows underflow to exactly zero correlation, never to NaN
    let far = [
        Window::new(0.0, 10.0).unwrap(),
        Window::new(1e6, 10.0).unwrap(),
    ];
    let c = noise.window_covariance(&far, fs).unwrap();
    assert_eq!(c.correlated()[(0, 1)].to_bits(), 0);
    assert!(c.total().iter().all(|v| v.is_finite()));
}

// ---------------------------------------------------------------- flicker and angle quantization

/// The stated fit error of the flicker bank: its Allan deviation within 0.5% of the flicker
/// floor 0.6643 B over the time scales it stands for, dimensionless.
const FLICKER_FIT_REL: f64 = 5e-3;

/// The Allan variance of the averages of two adjacent windows $[0,\tau]$, $[\tau, 2\tau]$
/// from a covariance matrix: $\frac12(V_1 + V_2 - 2C)$.
fn allan_from(c: &nalgebra::DMatrix<f64>) -> f64 {
    0.5 * (c[(0, 0)] + c[(1, 1)] - 2.0 * c[(0, 1)])
}

/// The bank's terms have the variance $B^2\ln r/\pi$ (whose Allan variances sum to the
/// floor $2\ln 2 B^2/\pi$), reach two decades beyond the time scales, and its Allan
/// deviation stays within its stated fit error, itself below 0.5%, of the flicker floor from
/// a 60 s dwell to a 3.5-day test.
#[test]
fn flicker_bank_reproduces_the_flicker_floor_within_its_stated_error() {
    let b = 0.5;
    let bank = FlickerBank::new(b, 60.0, 3e5);
    let floor = b * FLICKER_FLOOR_PER_BIAS_INSTABILITY;
    assert!(bank.max_relative_adev_error() > 0.0);
    assert!(bank.max_relative_adev_error() < FLICKER_FIT_REL);
    let sigma2 = b * b * FLICKER_BANK_RATIO.ln() / std::f64::consts::PI;
    for t in bank.terms() {
        assert_relative_eq!(t.sigma().powi(2), sigma2, max_relative = 1e-12);
    }
    assert!(bank.terms()[0].correlation_s() <= 0.6 + 1e-9);
    assert!(bank.terms().last().unwrap().correlation_s() >= 3e7 - 1e-3);
    for tau in [60.0, 100.0, 1e3, 7e3, 5e4, 3e5] {
        let adev = bank.allan_variance(tau).sqrt();
        assert!(
            (adev / floor - 1.0).abs() <= bank.max_relative_adev_error() + 1e-12,
            "tau {tau}: {adev} vs floor {floor}"
        );
    }
    // outside the time scales the floor is not promised: far beyond, the bank falls off
    assert!(bank.allan_variance(3e9).sqrt() < 0.5 * floor);
}

/// Through `window_covariance`, a flicker term is the floor as the Allan data show it: two
/// adjacent windows' averages give the Allan variance $(0.6643 B)^2$ within the stated fit
/// error, at 1 s and at 10^4 s, and the matrix names the bank it used.
#[test]
fn window_covariance_of_flicker_has_the_flat_allan_floor() {
    let b = 0.5;
    let noise = NoiseModel::new(0.0, None, 0.0)
        .unwrap()
        .with_flicker(b)
        .unwrap();
    let floor2 = (b * FLICKER_FLOOR_PER_BIAS_INSTABILITY).powi(2);
    for tau in [1.0, 1e4] {
        let ws = [
            Window::new(0.0, tau).unwrap(),
            Window::new(tau, tau).unwrap(),
        ];
        let c = noise.window_covariance(&ws, 100.0).unwrap();
        let bank = c.flicker().expect("a flicker term has its bank");
        assert_relative_eq!(bank.time_scales_s().0, tau, max_relative = 1e-12);
        assert_relative_eq!(bank.time_scales_s().1, 2.0 * tau, max_relative = 1e-12);
        let err = bank.max_relative_adev_error();
        let avar = allan_from(c.correlated());
        assert!(
            (avar.sqrt() / floor2.sqrt() - 1.0).abs() <= err + 1e-9,
            "tau {tau}: {avar} vs {floor2} (fit error {err})"
        );
        assert!(c.white().iter().all(|v| v.abs() < 1e-300));
    }
    assert!(
        NoiseModel::new(1.0, None, 0.0)
            .unwrap()
            .window_covariance(&[Window::new(0.0, 1.0).unwrap()], 1.0)
            .unwrap()
            .flicker()
            .is_none()
    );
}

/// Angle quantization $Q$: a window's average carries $2Q^2/T^2$, a window that starts
/// where the other ends $-Q^2/(T_1T_2)$ (they share a reading), a window after a gap
/// nothing; two adjacent windows give IEEE 952's Allan variance $3Q^2/\tau^2$.
#[test]
fn angle_quantization_gives_the_allan_variance_three_q2_over_tau2() {
    let q = 0.02;
    let noise = NoiseModel::new(0.0, None, 0.0)
        .unwrap()
        .with_angle_quantization(q)
        .unwrap();
    let tau = 4.0;
    let ws = [
        Window::new(0.0, tau).unwrap(),
        Window::new(tau, tau).unwrap(),
        Window::new(3.0 * tau, 2.0 * tau).unwrap(),
    ];
    let c = noise.window_covariance(&ws, 50.0).unwrap();
    let w = c.white();
    assert_relative_eq!(w[(0, 0)], 2.0 * q * q / (tau * tau), max_relative = 1e-12);
    assert_relative_eq!(w[(0, 1)], -q * q / (tau * tau), max_relative = 1e-12);
    assert_relative_eq!(w[(1, 0)], w[(0, 1)], max_relative = 1e-12);
    assert_eq!(w[(1, 2)].to_bits(), 0);
    assert_relative_eq!(
        w[(2, 2)],
        2.0 * q * q / (4.0 * tau * tau),
        max_relative = 1e-12
    );
    assert_relative_eq!(
        allan_from(w),
        3.0 * q * q / (tau * tau),
        max_relative = 1e-12
    );
    // the pairwise form agrees with the matrix, also for overlapping windows
    let over = [
        Window::new(0.0, tau).unwrap(),
        Window::new(0.0, 2.0 * tau).unwrap(),
    ];
    let c = noise.window_covariance(&over, 50.0).unwrap();
    assert_relative_eq!(
        c.white()[(0, 1)],
        q * q / (2.0 * tau * tau),
        max_relative = 1e-12
    );
    assert_relative_eq!(
        noise.white_covariance_of_averages(&ws[0], &ws[1], 50.0),
        -q * q / (tau * tau),
        max_relative = 1e-12
    );
}

/// A parameter moved by k standard uncertainties: only that parameter moves, clipped at
/// zero; no uncertainty (or no such term) gives `None`; a bad uncertainty names its field.
#[test]
fn perturbed_noise_moves_one_parameter_by_its_uncertainty() {
    use gw_model::noise::NoiseParameter as P;
    let m = NoiseModel::new(2.0, Some(GaussMarkov::new(0.5, 60.0).unwrap()), 0.0)
        .unwrap()
        .with_flicker(0.3)
        .unwrap()
        .with_uncertainty(P::White, 0.5)
        .unwrap()
        .with_uncertainty(P::BiasCorrelation, 20.0)
        .unwrap()
        .with_uncertainty(P::Flicker, 0.4)
        .unwrap();
    let up = m.perturbed(P::White, 1.0).unwrap();
    assert_relative_eq!(up.white_per_sqrt_hz(), 2.5, max_relative = 1e-15);
    assert_eq!(up.flicker().to_bits(), 0.3f64.to_bits());
    let tc = m.perturbed(P::BiasCorrelation, -1.0).unwrap();
    assert_relative_eq!(
        tc.bias().unwrap().correlation_s(),
        40.0,
        max_relative = 1e-15
    );
    assert_eq!(tc.bias().unwrap().sigma().to_bits(), 0.5f64.to_bits());
    // clipped at zero
    assert_eq!(
        m.perturbed(P::Flicker, -1.0).unwrap().flicker().to_bits(),
        0
    );
    assert!(m.perturbed(P::RateRamp, 1.0).is_none());
    assert!(
        NoiseModel::new(1.0, None, 0.0)
            .unwrap()
            .with_uncertainty(P::BiasSigma, 0.1)
            .unwrap()
            .perturbed(P::BiasSigma, 1.0)
            .is_none()
    );
    let field = match m.clone().with_uncertainty(P::RateRamp, -1.0).unwrap_err() {
        ModelError::Field(f) => f.field().to_string(),
        other => panic!("{other:?}"),
    };
    assert_eq!(field, "rate_ramp_uncertainty");
}

// ---------------------------------------------------------------- bad input

/// Negative, non-finite and zero-where-positive values are typed errors naming the field.
#[test]
fn bad_noise_values_are_errors_naming_the_field() {
    let field = |e: ModelError| match e {
        ModelError::Field(
            FieldError::NonFinite { field, .. }
            | FieldError::NotPositive { field, .. }
            | FieldError::Negative { field, .. },
        ) => field,
        other => panic!("unexpected {other:?}"),
    };
    assert_eq!(
        field(NoiseModel::new(-1.0, None, 0.0).unwrap_err()),
        "white_per_sqrt_hz"
    );
    assert_eq!(
        field(NoiseModel::new(f64::NAN, None, 0.0).unwrap_err()),
        "white_per_sqrt_hz"
    );
    assert_eq!(
        field(NoiseModel::new(1.0, None, f64::INFINITY).unwrap_err()),
        "quantization"
    );
    assert_eq!(
        field(GaussMarkov::from_bias_instability(-0.5, 10.0).unwrap_err()),
        "bias_instability"
    );
    assert_eq!(
        field(GaussMarkov::from_bias_instability(0.5, 0.0).unwrap_err()),
        "bias_correlation_s"
    );
    assert_eq!(
        field(
            WhiteDensity::DegPerSqrtH(-0.15)
                .in_output_unit("deg_per_h")
                .unwrap_err()
        ),
        "white_deg_per_sqrt_h"
    );
    assert_eq!(
        field(
            WhiteDensity::PerSqrtHz(f64::NAN)
                .in_output_unit("deg_per_h")
                .unwrap_err()
        ),
        "white_per_sqrt_hz"
    );
    assert_eq!(field(Window::new(0.0, 0.0).unwrap_err()), "duration_s");
    assert_eq!(field(Window::new(f64::NAN, 1.0).unwrap_err()), "start_s");
    let noise = NoiseModel::new(1.0, None, 0.0).unwrap();
    assert_eq!(
        field(noise.window_covariance(&[], 0.0).unwrap_err()),
        "sample_rate_hz"
    );
    for bad in [-1e-3, f64::NAN, f64::INFINITY] {
        assert_eq!(
            field(noise.clone().with_flicker(bad).unwrap_err()),
            "flicker_bias_instability"
        );
        assert_eq!(
            field(noise.clone().with_angle_quantization(bad).unwrap_err()),
            "angle_quantization"
        );
        assert_eq!(
            field(noise.clone().with_rate_random_walk(bad).unwrap_err()),
            "rate_random_walk"
        );
        assert_eq!(
            field(noise.clone().with_rate_ramp(bad).unwrap_err()),
            "rate_ramp"
        );
    }
}

/// The README's noise example is the example file the test suite compiles.
#[test]
fn readme_noise_example_is_the_compiled_example() {
    let readme = include_str!("../README.md");
    let example = include_str!("../examples/noise_of_an_output.rs");
    assert!(
        readme.contains(example.trim()),
        "README.md must show examples/noise_of_an_output.rs verbatim"
    );
}

// ---------------------------------------------------------------- rate random walk and ramp

/// Rate random walk K (output unit per sqrt(s)) and rate ramp R (output unit per s) of the
/// drift tests, arbitrary.
const K_PER_SQRT_S: f64 = 0.3;
const R_PER_S: f64 = 0.01;

/// A window from its ends.
fn window(w: (f64, f64)) -> Window {
    Window::new(w.0, w.1 - w.0).unwrap()
}

/// The closed forms of the rate random walk (K^2 min(s, r) from the start t0 = 0, zero
/// before) and rate ramp (R^2 s r) covariances of window averages agree with a numerical
/// double integral of the autocovariance for windows disjoint in both orders, adjacent,
/// overlapping, nested, identical, late in a long test, and straddling the start; the
/// one-window variance is K^2 (t0 + T/3) and a disjoint pair K^2 times the earlier midpoint.
#[test]
fn rate_random_walk_and_ramp_covariances_match_numerical_integration() {
    let rrw = NoiseModel::new(0.0, None, 0.0)
        .unwrap()
        .with_rate_random_walk(K_PER_SQRT_S)
        .unwrap();
    let ramp = NoiseModel::new(0.0, None, 0.0)
        .unwrap()
        .with_rate_ramp(R_PER_S)
        .unwrap();
    let cases = [
        ((5e4, 5e4 + 60.0), (5e4 + 30.0, 5e4 + 90.0)), // overlapping, late
        ((-30.0, 30.0), (-10.0, 50.0)),                // straddling the start
        ((-30.0, -10.0), (0.0, 50.0)),                 // before the start
    ];
    let clip = |t: f64| t.max(0.0);
    for (w1, w2) in WINDOW_PAIRS.into_iter().chain(cases) {
        let (a, b) = (window(w1), window(w2));
        let span = w1.1.max(w2.1) - w1.0.min(w2.0);
        // the kernels are polynomials of degree <= 2 between kinks: exact on any cell
        let expected_k = K_PER_SQRT_S.powi(2)
            * numerical_window_covariance(|s, r| clip(s).min(clip(r)), span, &[0.0], w1, w2);
        let expected_r = R_PER_S.powi(2)
            * numerical_window_covariance(|s, r| clip(s) * clip(r), span, &[0.0], w1, w2);
        for (model, expected) in [(&rrw, expected_k), (&ramp, expected_r)] {
            let got = model.drift_covariance_of_averages(&a, &b);
            assert!(
                (got - expected).abs() <= QUADRATURE_REL * expected.abs().max(1e-300),
                "{w1:?} {w2:?}: {got} against {expected}"
            );
            assert_relative_eq!(
                model.covariance_of_averages(&a, &b, 100.0),
                got,
                max_relative = CONVERSION_REL
            );
        }
    }
    // the one-window variance and the disjoint covariance in their hand forms
    let w = Window::new(40.0, 30.0).unwrap();
    assert_relative_eq!(
        rrw.drift_variance_of_average(&w),
        K_PER_SQRT_S.powi(2) * (40.0 + 30.0 / 3.0),
        max_relative = CONVERSION_REL
    );
    let later = Window::new(500.0, 10.0).unwrap();
    assert_relative_eq!(
        rrw.drift_covariance_of_averages(&w, &later),
        K_PER_SQRT_S.powi(2) * 55.0,
        max_relative = CONVERSION_REL
    );
    assert_relative_eq!(
        ramp.drift_covariance_of_averages(&w, &later),
        R_PER_S.powi(2) * 55.0 * 505.0,
        max_relative = CONVERSION_REL
    );
}

/// IEEE Std 952-1997 Annex C: the Allan variance, from the window averages as
/// (Var[0, tau] + Var[tau, 2 tau] - 2 Cov) / 2, is K^2 tau / 3 for a rate random walk and
/// R^2 tau^2 / 2 for a rate ramp, at every cluster time.
#[test]
fn drift_allan_variances_from_window_averages_are_ieee_952_values() {
    let both = |k: f64, r: f64| {
        NoiseModel::new(0.0, None, 0.0)
            .unwrap()
            .with_rate_random_walk(k)
            .unwrap()
            .with_rate_ramp(r)
            .unwrap()
    };
    for tau in [0.01, 1.0, 60.0, 3600.0, 1e5] {
        let (first, second) = (
            Window::new(0.0, tau).unwrap(),
            Window::new(tau, tau).unwrap(),
        );
        let allan = |m: &NoiseModel| {
            0.5 * (m.drift_variance_of_average(&first) + m.drift_variance_of_average(&second)
                - 2.0 * m.drift_covariance_of_averages(&first, &second))
        };
        assert_relative_eq!(
            allan(&both(K_PER_SQRT_S, 0.0)),
            K_PER_SQRT_S.powi(2) * tau / 3.0,
            max_relative = CONVERSION_REL
        );
        assert_relative_eq!(
            allan(&both(0.0, R_PER_S)),
            R_PER_S.powi(2) * tau * tau / 2.0,
            max_relative = CONVERSION_REL
        );
    }
}

/// The matrix of `window_covariance` with every correlated term (Gauss-Markov, rate random
/// walk, ramp) is the pairwise sum of the closed forms, for disjoint windows in a shuffled
/// order (the recursive path) and for overlapping ones.
#[test]
fn window_covariance_adds_the_drifts_to_the_gauss_markov_part() {
    let noise = NoiseModel::new(0.5, Some(GaussMarkov::new(0.2, 40.0).unwrap()), 0.01)
        .unwrap()
        .with_rate_random_walk(K_PER_SQRT_S)
        .unwrap()
        .with_rate_ramp(R_PER_S)
        .unwrap();
    let fs = 50.0;
    let disjoint: Vec<Window> = [(130.0, 20.0), (0.0, 30.0), (300.0, 60.0), (40.0, 50.0)]
        .iter()
        .map(|&(a, t)| Window::new(a, t).unwrap())
        .collect();
    let overlapping: Vec<Window> = [(0.0, 30.0), (20.0, 30.0), (45.0, 10.0)]
        .iter()
        .map(|&(a, t)| Window::new(a, t).unwrap())
        .collect();
    for ws in [disjoint, overlapping] {
        let c = noise.window_covariance(&ws, fs).unwrap();
        for (i, wi) in ws.iter().enumerate() {
            for (j, wj) in ws.iter().enumerate() {
                let expected = noise.covariance_of_averages(wi, wj, fs);
                assert_relative_eq!(c.total()[(i, j)], expected, max_relative = RECURSION_REL);
                assert_relative_eq!(
                    c.correlated()[(i, j)],
                    noise.bias().unwrap().covariance_of_averages(wi, wj)
                        + noise.drift_covariance_of_averages(wi, wj),
                    max_relative = RECURSION_REL
                );
            }
        }
    }
}

/// Sample covariance of window averages of `runs` seeded simulations of white noise N, rate
/// random walk K and rate ramp R, sample by sample at `fs` from t = 0: each sample is the
/// mean of the output over its interval h (white: variance N^2 fs; rate random walk: the
/// exact joint law of W(t + h) - W(t) = sqrt(h) z1 and the interval's mean of W,
/// W(t) + sqrt(h) (z1 / 2 + z2 / sqrt(12)); ramp: rho (t + h / 2), rho ~ N(0, R^2) per run).
/// Windows are given in samples (start, count); the mean of the process is zero, so the
/// covariance is the mean of the products.
fn simulated_window_covariance(
    (n, k, r): (f64, f64, f64),
    fs: f64,
    windows: &[(usize, usize)],
    runs: usize,
    seed: u64,
) -> Vec<Vec<f64>> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let h = 1.0 / fs;
    let end = windows.iter().map(|w| w.0 + w.1).max().unwrap();
    let mut sum = vec![vec![0.0; windows.len()]; windows.len()];
    let mut avg = vec![0.0; windows.len()];
    for _ in 0..runs {
        let rho = r * normals(&mut rng).0;
        let mut w = 0.0;
        avg.iter_mut().for_each(|a| *a = 0.0);
        for i in 0..end {
            let (z1, z2) = normals(&mut rng);
            let mean_w = w + h.sqrt() * (0.5 * z1 + z2 / 12f64.sqrt());
            w += h.sqrt() * z1;
            let white = n * fs.sqrt() * normals(&mut rng).0;
            let x = k * mean_w + rho * (i as f64 + 0.5) * h + white;
            for (a, &(start, count)) in avg.iter_mut().zip(windows) {
                if (start..start + count).contains(&i) {
                    *a += x / count as f64;
                }
            }
        }
        for (i, row) in sum.iter_mut().enumerate() {
            for (j, s) in row.iter_mut().enumerate() {
                *s += avg[i] * avg[j];
            }
        }
    }
    sum.iter()
        .map(|row| row.iter().map(|s| s / runs as f64).collect())
        .collect()
}

/// Standard errors of a sample covariance element allowed: a Gaussian vector's sample second
/// moment over M runs has the standard error sqrt((C_ii C_jj + C_ij^2) / M). At 4.5 of them a
/// correct closed form fails one of the 30 elements below with probability about 2e-4 for a
/// random seed (the seed is fixed, so the test is deterministic); a wrong start convention
/// (a stationary-like K^2 T / 3 without the time since the start) is off by many.
const SAMPLING_SE: f64 = 4.5;

/// The time-domain simulation of each drift alone and of white noise with both drifts
/// together reproduces the predicted covariance of the window averages (seeded, 4,000 runs).
#[test]
fn simulated_drifts_match_the_predicted_window_covariance() {
    let fs = 4.0;
    // windows in samples: [0, 20 s], [25, 45 s], [50, 70 s], [100, 110 s]
    let windows = [(0, 80), (100, 80), (200, 80), (400, 40)];
    let runs = 4000;
    for (seed, (n, k, r)) in [
        (1, (0.0, K_PER_SQRT_S, 0.0)),
        (2, (0.0, 0.0, R_PER_S)),
        (3, (0.5, K_PER_SQRT_S, R_PER_S)),
    ] {
        let model = NoiseModel::new(n, None, 0.0)
            .unwrap()
            .with_rate_random_walk(k)
            .unwrap()
            .with_rate_ramp(r)
            .unwrap();
        let ws: Vec<Window> = windows
            .iter()
            .map(|&(a, m)| Window::new(a as f64 / fs, m as f64 / fs).unwrap())
            .collect();
        let predicted = model.window_covariance(&ws, fs).unwrap().total();
        let simulated = simulated_window_covariance((n, k, r), fs, &windows, runs, seed);
        for i in 0..ws.len() {
            for j in i..ws.len() {
                let c = predicted[(i, j)];
                let se = ((predicted[(i, i)] * predicted[(j, j)] + c * c) / runs as f64).sqrt();
                assert!(
                    (simulated[i][j] - c).abs() <= SAMPLING_SE * se,
                    "seed {seed}, ({i}, {j}): simulated {} against predicted {c} (se {se})",
                    simulated[i][j]
                );
            }
        }
    }
}
