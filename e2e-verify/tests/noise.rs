//! One answer for both error sources (issue 21, items 3 and 4): the table's worst case plus
//! the noise part from calib-lsq's covariance, the combined yield over turntables and noise,
//! the direct allocation that gives the table what the noise leaves, and the time/table
//! trade-off.

mod common;

use approx::assert_relative_eq;
use calib_lsq::Timing;
use e2e_verify::{
    CertifyParams, DEFAULT_K_SIGMA, Dominant, EndToEnd, Linearization, McSettings, NoiseBudget,
    TradeoffInputs, TradeoffParams, Verdict, check_k_sigma,
};
use gw_model::noise::NoiseModel;

/// Rounding of sums of a few dozen products (relative).
const ROUNDING_REL: f64 = 1e-12;

/// The IMU example's simulator, noise and timing.
fn imu() -> (EndToEnd, Vec<Option<NoiseModel>>, Timing) {
    let s = common::study("imu-triad-example");
    let e2e = common::study_e2e("imu-triad-example", None);
    (
        e2e,
        s.noise.clone(),
        s.timing.clone().expect("the IMU example has a timing"),
    )
}

/// White noise only, `density` per sqrt(Hz) on every output.
fn white(e2e: &EndToEnd, density: f64) -> Vec<Option<NoiseModel>> {
    (0..e2e.n_outputs())
        .map(|_| Some(NoiseModel::new(density, None, 0.0).expect("valid white noise")))
        .collect()
}

/// The time/table trade-off's inputs at $\kappa = 3$.
fn at_3_sigma<'a>(
    linear: &'a Linearization,
    lower_bounds_rad: &'a [f64],
    noise: &'a [Option<NoiseModel>],
    timing: &'a Timing,
    dwell_range_s: (f64, f64),
) -> TradeoffInputs<'a> {
    TradeoffInputs {
        linear,
        lower_bounds_rad,
        noise,
        timing,
        k_sigma: 3.0,
        dwell_range_s,
    }
}

/// A small box around the direct allocation's shape (rad).
fn direct_box(e2e: &EndToEnd) -> Vec<f64> {
    let d = e2e
        .allocate_direct(&e2e.linearization(), &vec![0.0; e2e.n_errors()])
        .expect("direct allocation");
    d.upper_bounds_rad()
        .iter()
        .map(|u| if u.is_finite() { *u } else { 1e-5 })
        .collect()
}

#[test]
fn noise_sigma_is_calib_lsq_rate_error_sigma_at_the_worst_position() {
    let (e2e, noise, timing) = imu();
    let b = e2e.noise().noise_budget(&noise, &timing).unwrap();
    let covs = e2e
        .calibration()
        .noise_covariances(&noise, &timing)
        .unwrap();
    for (k, c) in covs.iter().enumerate() {
        let c = c.as_ref().expect("every IMU output has noise");
        let expected = c.rate_error().max_sigma().1;
        assert_relative_eq!(b.sigma()[k], expected, max_relative = ROUNDING_REL);
    }
}

#[test]
fn a_study_without_noise_keeps_every_answer() {
    // no noise: sigma 0, the combined answer is the table's, the verdict today's, and the
    // combined yield counts exactly the turntables the table-only Monte Carlo counts
    let e2e = common::study_e2e("three-axis-example", None);
    let none: Vec<Option<NoiseModel>> = vec![None; e2e.n_outputs()];
    let timing = Timing::uniform(e2e.len(), 10.0, 0.0, 100.0).unwrap();
    let budget = e2e.noise().noise_budget(&none, &timing).unwrap();
    assert!(!budget.any());
    let linear = e2e.linearization();
    let ub = direct_box(&e2e);
    let lb = vec![0.0; e2e.n_errors()];
    let settings = McSettings::new(3000, 5);
    let check = e2e
        .vendor()
        .check_tolerances(&linear, &ub, &lb, &settings)
        .unwrap();
    let comb = e2e
        .noise()
        .combined_box(
            "direct",
            &e2e.worst_case(&linear, &ub).unwrap(),
            &ub,
            &lb,
            &budget,
            DEFAULT_K_SIGMA,
            &settings,
        )
        .unwrap();
    for (c, o) in comb.outputs().iter().zip(check.outputs()) {
        assert_eq!(c.verdict(), o.verdict());
        assert_eq!(c.noise_sigma().to_bits(), 0.0_f64.to_bits());
        assert_eq!(c.combined().to_bits(), c.table_part().to_bits());
        assert_eq!(c.dominant(), Dominant::Table);
    }
    assert_eq!(comb.verdict(), check.verdict());
    assert_eq!(
        comb.combined_yield().meeting(),
        check.distribution().count().meeting()
    );
    assert_eq!(
        comb.combined_yield().meeting_per_output(),
        check.distribution().count().meeting_per_output()
    );
}

#[test]
fn combined_yield_is_identical_for_any_thread_count() {
    let (e2e, noise, timing) = imu();
    let budget = e2e.noise().noise_budget(&noise, &timing).unwrap();
    let ub = direct_box(&e2e);
    let bounds = e2e.box_of(&ub, &vec![0.0; e2e.n_errors()]).unwrap();
    let settings = McSettings {
        chunk_size: 97,
        ..McSettings::new(2000, 11)
    };
    let run = |threads| {
        common::on_threads(threads, || {
            e2e.noise()
                .combined_yield(&bounds, &budget, &settings)
                .unwrap()
        })
    };
    assert_eq!(run(1), run(3));
}

#[test]
fn noise_that_takes_the_accuracy_fails_a_box_the_table_alone_meets() {
    // the example: the IMU at 24 x 60 s with STIM300 noise; the direct box meets
    // every accuracy for the table alone, and noise alone at 3 sigma exceeds the gyros'
    let (e2e, noise, timing) = imu();
    let budget = e2e.noise().noise_budget(&noise, &timing).unwrap();
    let linear = e2e.linearization();
    let ub = direct_box(&e2e);
    let lb = vec![0.0; e2e.n_errors()];
    let wc = e2e.worst_case(&linear, &ub).unwrap();
    let comb = e2e.noise().combine(&wc, &budget, DEFAULT_K_SIGMA);
    let acc = e2e.accuracies();

    let mut noise_dominated = 0;
    for (c, w) in comb.iter().zip(wc.outputs()) {
        let k = c.output();
        assert_relative_eq!(
            c.combined(),
            c.table_part() + 3.0 * budget.sigma()[k],
            max_relative = ROUNDING_REL
        );
        assert!(c.table_part() >= w.exact_at_vertex());
        if 3.0 * budget.sigma()[k] > acc[k] {
            assert_eq!(c.verdict(), Verdict::Fails);
            assert!(!c.meets());
            noise_dominated += 1;
        }
        if 3.0 * budget.sigma()[k] > c.table_part() {
            assert_eq!(c.dominant(), Dominant::Noise);
        } else {
            assert_eq!(c.dominant(), Dominant::Table);
        }
    }
    assert!(
        noise_dominated > 0,
        "the STIM300 gyros' noise exceeds 0.1 deg/h at 60 s"
    );
    // and the allocation says no table suffices: an answer, not an error
    let d = e2e
        .noise()
        .allocate_direct_with_noise(&linear, &lb, &budget, DEFAULT_K_SIGMA, None)
        .unwrap();
    let blocked = d.expect_err("no table suffices at 60 s");
    assert!(blocked.iter().all(|b| b.noise_part() >= acc[b.output()]));
}

#[test]
fn combined_yield_of_a_perfect_table_is_the_gaussian_probability_of_the_noise() {
    // a perfect table (all bounds 0): a calibration meets its accuracy when its noise does;
    // for white noise at one output the error at the worst position is normal with the
    // budget's sigma, so the per-output yield lies between the Bonferroni bound
    // 1 - sum_i P(|nu_i| > acc) and min_i P(|nu_i| <= acc)
    // density chosen so that the worst position's sigma is a third of the accuracy
    let (e2e, budget) = three_axis_with_white_noise(3.0);
    let acc = e2e.accuracies();
    let zero = vec![0.0; e2e.n_errors()];
    let bounds = e2e.box_of(&zero, &zero).unwrap();
    let settings = McSettings::new(20_000, 3);
    let y = e2e
        .noise()
        .combined_yield(&bounds, &budget, &settings)
        .unwrap();
    let erf_tail = |x: f64| libm_erfc(x / std::f64::consts::SQRT_2);
    let sig = &budget.per_position()[0];
    let upper = sig
        .iter()
        .map(|s| 1.0 - erf_tail(acc[0] / s))
        .fold(1.0, f64::min);
    let lower = 1.0 - sig.iter().map(|s| erf_tail(acc[0] / s)).sum::<f64>();
    let (lo, hi) = e2e_verify::wilson_interval_95(y.meeting_per_output()[0], y.samples());
    assert!(
        hi >= lower.max(0.0),
        "{hi} below the Bonferroni bound {lower}"
    );
    assert!(
        lo <= upper,
        "{lo} above the single-position probability {upper}"
    );
    assert!(upper < 0.999, "the noise matters at this density");
}

/// erfc(x) by Simpson's rule on [x, x + 10] (2000 panels: error far below 1e-10, far below
/// the Monte Carlo's resolution).
fn libm_erfc(x: f64) -> f64 {
    // erfc(x) = 2/sqrt(pi) int_x^inf e^{-t^2} dt, integrate to x + 10
    let (a, b, n) = (x, x + 10.0, 2000);
    let h = (b - a) / n as f64;
    let f = |t: f64| (-t * t).exp();
    let mut s = f(a) + f(b);
    for i in 1..n {
        let t = a + i as f64 * h;
        s += if i % 2 == 1 { 4.0 } else { 2.0 } * f(t);
    }
    s * h / 3.0 * 2.0 / std::f64::consts::PI.sqrt()
}

/// The noise's part at 3 sigma a quarter of the first output's accuracy: sigma = accuracy / 12.
const QUARTER_OF_THE_ACCURACY_AT_3_SIGMA: f64 = 12.0;

/// The three-axis example with white noise whose sigma at the first output's worst position
/// is its accuracy divided by `sigmas_per_accuracy` (30 s per position at 100 Hz).
fn three_axis_with_white_noise(sigmas_per_accuracy: f64) -> (EndToEnd, NoiseBudget) {
    let e2e = common::study_e2e("three-axis-example", None);
    let acc = e2e.accuracies();
    let timing = Timing::uniform(e2e.len(), 30.0, 0.0, 100.0).unwrap();
    let unit = e2e
        .noise()
        .noise_budget(&white(&e2e, 1.0), &timing)
        .unwrap();
    let density = acc[0] / sigmas_per_accuracy / unit.sigma()[0];
    let budget = e2e
        .noise()
        .noise_budget(&white(&e2e, density), &timing)
        .unwrap();
    (e2e, budget)
}

#[test]
fn direct_allocation_with_noise_gives_the_table_what_the_noise_leaves() {
    let (e2e, budget) = three_axis_with_white_noise(QUARTER_OF_THE_ACCURACY_AT_3_SIGMA);
    let acc = e2e.accuracies();
    let linear = e2e.linearization();
    let lb = vec![0.0; e2e.n_errors()];
    let d = e2e
        .noise()
        .allocate_direct_with_noise(&linear, &lb, &budget, 3.0, None)
        .unwrap()
        .expect("a table suffices");
    let plain = e2e.allocate_direct(&linear, &lb).unwrap();
    assert!(
        d.objective() > plain.objective(),
        "a tighter table costs more"
    );
    let n = e2e.len();
    let rows = linear.row_worst_cases(d.upper_bounds_rad());
    for (k, a) in acc.iter().enumerate() {
        let worst = rows.rows(k * n, n).max();
        assert!(
            worst + 3.0 * budget.sigma()[k] <= a * (1.0 + 1e-9),
            "output {k}: {worst} + noise exceeds {a}"
        );
    }
}

#[test]
fn shortest_dwell_for_white_noise_is_the_closed_form() {
    // white noise only, equal dwells: sigma(T) = sigma(T0) sqrt(T0 / T), so with no lower
    // bounds the shortest dwell at which some table suffices is
    // T* = T0 (k sigma(T0) / acc)^2 for the output that needs the longest
    let e2e = common::study_e2e("three-axis-example", None);
    let acc = e2e.accuracies();
    let t0 = 10.0;
    let timing = Timing::uniform(e2e.len(), t0, 2.0, 100.0).unwrap();
    let noise = white(&e2e, 0.05);
    let b0 = e2e.noise().noise_budget(&noise, &timing).unwrap();
    let expected = b0
        .sigma()
        .iter()
        .zip(&acc)
        .map(|(s, a)| t0 * (3.0 * s / a).powi(2))
        .fold(0.0, f64::max);
    let linear = e2e.linearization();
    let lb = vec![0.0; e2e.n_errors()];
    let tr = e2e
        .noise()
        .tradeoff(&at_3_sigma(&linear, &lb, &noise, &timing, (1e-3, 86_400.0)))
        .unwrap();
    let t = tr.min_dwell_s().expect("a dwell within a day suffices");
    assert!(
        expected > 0.01,
        "the closed form lies inside the range: {expected}"
    );
    // bisection to 2^-48 of the log width, sigma rounding 1e-12
    assert_relative_eq!(t, expected, max_relative = 1e-9);
    // the curve: J falls with the dwell towards the noiseless J, every point feasible
    let js: Vec<f64> = tr.points().iter().map(|p| p.objective().unwrap()).collect();
    assert!(js.windows(2).all(|w| w[1] < w[0]));
    assert!(*js.last().unwrap() > tr.noiseless_objective());
    assert!(*js.last().unwrap() < 1.2 * tr.noiseless_objective());
    let knee = tr.knee_dwell_s().expect("the curve crosses slope -1");
    assert!(knee > tr.points()[0].dwell_s() && knee < tr.points().last().unwrap().dwell_s());
}

#[test]
fn shortest_dwell_is_none_when_no_dwell_in_the_range_suffices() {
    let (e2e, noise, timing) = imu();
    let linear = e2e.linearization();
    let lb = vec![0.0; e2e.n_errors()];
    let tr = e2e
        .noise()
        .tradeoff(&at_3_sigma(&linear, &lb, &noise, &timing, (1e-3, 60.0)))
        .unwrap();
    assert_eq!(tr.min_dwell_s(), None);
    assert!(tr.points().is_empty());
}

#[test]
fn k_sigma_must_be_positive_and_finite() {
    for bad in [0.0, -1.0, f64::NAN, f64::INFINITY, 11.0] {
        let e = check_k_sigma(bad).unwrap_err();
        assert!(e.to_string().contains("k_sigma"), "{e}");
    }
    assert_relative_eq!(check_k_sigma(3.0).unwrap(), 3.0);
}

#[test]
fn tradeoff_of_a_quiet_sensor_starts_at_one_sample_per_position() {
    // noise far below every accuracy: one sample per position already suffices, and the
    // range's lower end (one sample at the shortest dwell) is a valid timing despite rounding
    let e2e = common::study_e2e("three-axis-example", None);
    let timing = Timing::new(
        (0..e2e.len()).map(|i| 1.0 + 0.37 * i as f64).collect(),
        0.5,
        3.0,
    )
    .unwrap();
    let noise = white(&e2e, 1e-12);
    let tr = e2e
        .noise()
        .tradeoff(&at_3_sigma(
            &e2e.linearization(),
            &vec![0.0; e2e.n_errors()],
            &noise,
            &timing,
            (f64::MIN_POSITIVE, 86_400.0),
        ))
        .unwrap();
    assert!(tr.min_dwell_at_range_start());
    let shortest = timing
        .dwell_s()
        .iter()
        .copied()
        .fold(f64::INFINITY, f64::min);
    let mean = timing.dwell_s().iter().sum::<f64>() / timing.len() as f64;
    assert_relative_eq!(
        tr.min_dwell_s().unwrap(),
        mean / shortest / 3.0,
        max_relative = 1e-8
    );
}

/// The direct allocation with noise recommended by the commands is certified on the exact
/// chain with the noise part kept free: its certified worst case plus k sigma is within every
/// accuracy (the first-order allocation only meets it to first order), and it costs at least
/// the first-order one.
#[test]
fn certified_direct_allocation_with_noise_meets_its_own_combined_verdict() {
    let (e2e, budget) = three_axis_with_white_noise(QUARTER_OF_THE_ACCURACY_AT_3_SIGMA);
    let acc = e2e.accuracies();
    let linear = e2e.linearization();
    let lb = vec![0.0; e2e.n_errors()];
    let first = e2e
        .noise()
        .allocate_direct_with_noise(&linear, &lb, &budget, 3.0, None)
        .unwrap()
        .expect("a table suffices");
    let cert = e2e
        .noise()
        .allocate_direct_with_noise(&linear, &lb, &budget, 3.0, Some(&CertifyParams::default()))
        .unwrap()
        .expect("a table suffices");
    assert!(cert.objective() >= first.objective());
    let n = e2e.len();
    let rows = linear.row_worst_cases(cert.upper_bounds_rad());
    let s: f64 = cert
        .upper_bounds_rad()
        .iter()
        .filter(|u| u.is_finite())
        .sum();
    for (k, a) in acc.iter().enumerate() {
        let tau = e2e
            .second_order_bound(k, s)
            .unwrap()
            .expect("the study's reading has a derived bound");
        let certified = rows.rows(k * n, n).max() + tau;
        assert!(
            certified + 3.0 * budget.sigma()[k] <= *a,
            "output {k}: {certified} + noise exceeds {a}"
        );
    }
}

/// `certify` of the allocation with the noise part kept free is the certificate's tuning:
/// without noise the certified allocation is `allocate_direct_certified_with` itself, bit for
/// bit, for the default tuning and for a larger round-trip share (which moves the box), and
/// `None` is `allocate_direct`.
#[test]
fn certify_is_the_certificates_tuning_in_the_allocation_with_noise() {
    let e2e = common::study_e2e("three-axis-example", None);
    let none: Vec<Option<NoiseModel>> = vec![None; e2e.n_outputs()];
    let timing = Timing::uniform(e2e.len(), 10.0, 0.0, 100.0).unwrap();
    let budget = e2e.noise().noise_budget(&none, &timing).unwrap();
    let linear = e2e.linearization();
    let lb = vec![0.0; e2e.n_errors()];
    let with_noise = |certify: Option<&CertifyParams>| {
        e2e.noise()
            .allocate_direct_with_noise(&linear, &lb, &budget, 3.0, certify)
            .unwrap()
            .expect("without noise a table suffices")
    };
    let first = with_noise(None);
    assert_eq!(first, e2e.allocate_direct(&linear, &lb).unwrap());
    let mut wide = CertifyParams::default();
    wide.round_trip_rel = 1e-3;
    let mut boxes = Vec::new();
    for params in [CertifyParams::default(), wide] {
        let certified = with_noise(Some(&params));
        assert_eq!(
            certified,
            e2e.allocate_direct_certified_with(&linear, &lb, &params)
                .unwrap()
        );
        boxes.push(certified);
    }
    // the tuning reaches the search: a thousandth of every accuracy kept free moves the box
    assert_ne!(boxes[0].upper_bounds_rad(), boxes[1].upper_bounds_rad());
}

#[test]
fn tradeoff_params_set_the_curve_and_default_is_the_tradeoff() {
    // the tuning is a parameter struct: its default gives `tradeoff`'s curve bit for bit, a
    // coarser curve has the asked number of points over the same span, and bad values are
    // typed errors naming the field
    let e2e = common::study_e2e("three-axis-example", None);
    let timing = Timing::uniform(e2e.len(), 10.0, 2.0, 100.0).unwrap();
    let noise = white(&e2e, 0.05);
    let linear = e2e.linearization();
    let lb = vec![0.0; e2e.n_errors()];
    let inputs = at_3_sigma(&linear, &lb, &noise, &timing, (1e-3, 86_400.0));
    let plain = e2e.noise().tradeoff(&inputs).unwrap();
    let default = e2e
        .noise()
        .tradeoff_with(&inputs, &TradeoffParams::default())
        .unwrap();
    assert_eq!(plain, default);
    assert_eq!(plain.points().len(), TradeoffParams::default().points);
    let mut coarse = TradeoffParams::default();
    coarse.points = 5;
    let c = e2e.noise().tradeoff_with(&inputs, &coarse).unwrap();
    assert_eq!(c.points().len(), 5);
    assert_eq!(c.noise_curve().len(), 5);
    // same bisection: the same shortest dwell; same span: the same first and last dwells
    assert_eq!(c.min_dwell_s(), plain.min_dwell_s());
    assert_eq!(
        c.points()[0].dwell_s().to_bits(),
        plain.points()[0].dwell_s().to_bits()
    );
    assert_relative_eq!(
        c.points()[4].dwell_s(),
        plain.points().last().unwrap().dwell_s(),
        max_relative = 1e-12 // exp(ln) round trip of the log-spaced grid, relative
    );
    for (field, bad) in [
        ("points", {
            let mut p = TradeoffParams::default();
            p.points = 1;
            p
        }),
        ("span", {
            let mut p = TradeoffParams::default();
            p.span = 0.5;
            p
        }),
        ("first", {
            let mut p = TradeoffParams::default();
            p.first = f64::NAN;
            p
        }),
    ] {
        let e = e2e.noise().tradeoff_with(&inputs, &bad).unwrap_err();
        assert!(e.to_string().contains(field), "{field}: {e}");
    }
}

/// Issue 35's rate random walk of a STIM300-class gyro, (deg/h)/sqrt(s).
const STIM300_RRW_DEG_PER_H_PER_SQRT_S: f64 = 0.005;

/// A rate random walk written as the study key `rate_random_walk` reaches the noise answer
/// unchanged by e2e-verify: every gyro's noise part grows, the accelerometers' (no key) stay.
/// With white noise N beside it alone, each output's noise part is the worst-position sigma
/// computed here by hand from the closed form, C_ii = N^2/T + K^2 (t_i + T/3) and
/// C_ij = K^2 (t_e + T_e/2) for the earlier window e, through the regression's A and A^+:
/// max_p sqrt(a_p^T A^+ C A^+T a_p).
#[test]
fn rate_random_walk_from_the_study_key_enlarges_the_noise_part_by_its_closed_form() {
    let text = include_str!("../../studies/imu-triad-example.toml").replace(
        "bias_correlation_s = 3600   # s, assumption (the datasheet gives none)\n",
        &format!(
            "bias_correlation_s = 3600   # s, assumption (the datasheet gives none)\n\
             rate_random_walk = {STIM300_RRW_DEG_PER_H_PER_SQRT_S}\n"
        ),
    );
    let with_rrw = study::Study::parse("imu.toml", &text).unwrap();
    let (e2e, noise, timing) = imu();
    let plain = e2e.noise().noise_budget(&noise, &timing).unwrap().sigma();
    let drifting = e2e
        .noise()
        .noise_budget(&with_rrw.noise, &timing)
        .unwrap()
        .sigma();
    let mut gyros = 0;
    for (k, n) in with_rrw.noise.iter().enumerate() {
        if n.as_ref().unwrap().rate_random_walk() > 0.0 {
            gyros += 1;
            assert!(drifting[k] > plain[k], "output {k}: {drifting:?} {plain:?}");
        } else {
            assert_relative_eq!(drifting[k], plain[k], max_relative = ROUNDING_REL);
        }
    }
    assert_eq!(gyros, 3);

    // white noise and rate random walk alone, against the hand covariance
    let k_rrw = STIM300_RRW_DEG_PER_H_PER_SQRT_S;
    let simple: Vec<Option<NoiseModel>> = noise
        .iter()
        .map(|n| {
            let n = n.as_ref().unwrap();
            Some(
                NoiseModel::new(n.white_per_sqrt_hz(), None, 0.0)
                    .and_then(|m| m.with_rate_random_walk(k_rrw))
                    .unwrap(),
            )
        })
        .collect();
    let sigma = e2e.noise().noise_budget(&simple, &timing).unwrap().sigma();
    let windows = timing.windows();
    let m = windows.len();
    for (k, out) in e2e.calibration().outputs().iter().enumerate() {
        let density = simple[k].as_ref().unwrap().white_per_sqrt_hz();
        let c = nalgebra::DMatrix::from_fn(m, m, |i, j| {
            let (wi, wj) = (&windows[i], &windows[j]);
            if i == j {
                density.powi(2) / wi.duration_s()
                    + k_rrw.powi(2) * (wi.start_s() + wi.duration_s() / 3.0)
            } else {
                let e = if wi.start_s() < wj.start_s() { wi } else { wj };
                k_rrw.powi(2) * (e.start_s() + 0.5 * e.duration_s())
            }
        });
        let (a, p) = (out.regression().matrix(), out.regression().pinv());
        let rate = a * p * c * p.transpose() * a.transpose();
        let worst = (0..m).map(|i| rate[(i, i)]).fold(0.0, f64::max).sqrt();
        assert_relative_eq!(sigma[k], worst, max_relative = HAND_REL);
        assert!(sigma[k] > 0.0);
    }
}

/// The noise part through calib-lsq's factored sandwich against the plain product
/// A A^+ C A^+T A^T on 24 positions: a few thousand ulps, relative.
const HAND_REL: f64 = 1e-10;

/// With a rate random walk the noise part grows again at long dwells: the longest dwell of
/// the range fails while shorter ones fit. The shortest dwell is still found (the first
/// fitting dwell of the curve's grid closes the bisection's bracket), it fits, and a dwell
/// slightly shorter does not; before, the failing longest dwell gave "no dwell suffices".
#[test]
fn shortest_dwell_is_found_when_a_drift_makes_the_longest_dwell_fail() {
    let e2e = common::study_e2e("three-axis-example", None);
    let acc = e2e.accuracies();
    let (t0, hi) = (10.0, 86_400.0);
    let timing = Timing::uniform(e2e.len(), t0, 2.0, 100.0).unwrap();
    let density = 0.05;
    // the rate random walk alone at the longest dwell, per unit density
    let unit_rrw: Vec<Option<NoiseModel>> = (0..e2e.n_outputs())
        .map(|_| {
            Some(
                NoiseModel::new(0.0, None, 0.0)
                    .unwrap()
                    .with_rate_random_walk(1.0)
                    .unwrap(),
            )
        })
        .collect();
    let at_hi = Timing::uniform(e2e.len(), hi, 2.0, 100.0).unwrap();
    let unit_sigma = e2e.noise().noise_budget(&unit_rrw, &at_hi).unwrap().sigma();
    // K such that 3 sigma of the walk alone is twice the tightest accuracy at the longest dwell
    let k_rrw = unit_sigma
        .iter()
        .zip(&acc)
        .map(|(s, a)| 2.0 * a / (3.0 * s))
        .fold(f64::INFINITY, f64::min);
    let noise: Vec<Option<NoiseModel>> = (0..e2e.n_outputs())
        .map(|_| {
            Some(
                NoiseModel::new(density, None, 0.0)
                    .and_then(|m| m.with_rate_random_walk(k_rrw))
                    .unwrap(),
            )
        })
        .collect();
    let fits = |t: f64| {
        let timing = Timing::uniform(e2e.len(), t, 2.0, 100.0).unwrap();
        let sigma = e2e.noise().noise_budget(&noise, &timing).unwrap().sigma();
        sigma.iter().zip(&acc).all(|(s, a)| 3.0 * s <= *a)
    };
    assert!(!fits(hi), "the walk makes the longest dwell fail");
    let linear = e2e.linearization();
    let lb = vec![0.0; e2e.n_errors()];
    let tr = e2e
        .noise()
        .tradeoff(&at_3_sigma(&linear, &lb, &noise, &timing, (1e-3, hi)))
        .unwrap();
    let t = tr.min_dwell_s().expect("a dwell between the ends suffices");
    assert!(t < hi);
    assert!(fits(t), "the shortest dwell fits: {t} s");
    assert!(
        !fits(t * (1.0 - 1e-6)),
        "a dwell 1e-6 shorter does not: {t} s"
    );
}
