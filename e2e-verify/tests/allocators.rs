//! The allocations against every output's accuracy through alloc-opt's one `Allocator` seam
//! (issue 20, item 1): `Direct`, `DirectCertified` and `YieldBased` return alloc-opt's
//! `ToleranceBox` with the same bounds as the crate's own methods, a certificate from
//! `alloc_opt::finish`, the analysis's names, and the problem's limits honoured.

mod common;

use alloc_opt::{AllocError, Allocator, MethodDetails};
use approx::assert_relative_eq;
use calib_lsq::Reading;
use common::*;
use e2e_verify::{Direct, DirectCertified, EndToEnd, McSettings, YieldBased};
use tt_core::ErrorClass;

/// alloc-opt's $J$ from per-output weights $w_j/\sqrt{q_j}$ against this crate's
/// $\sum_j w_j^2/\mathrm{UB}_j^2$: the same terms summed in another order and through a square
/// root and its square, a few ulp apart (dimensionless).
const OBJECTIVE_REL: f64 = 1e-12;

/// The conic solver's relative accuracy on the bounds (dimensionless): a problem whose limits
/// are all halved has exactly half the bounds, found to this.
const SOLVER_REL: f64 = 1e-6;

fn studies() -> Vec<EndToEnd> {
    vec![
        paper(Reading::PAPER),
        paper(Reading::USER),
        study_e2e("imu-triad-example", None),
    ]
}

/// The `Direct` allocator returns the direct allocation's bounds bit for bit, its objective,
/// a certificate that holds (every output's worst case over the schedule within its
/// accuracy), and the analysis's error and output names.
#[test]
fn direct_allocator_gives_the_direct_allocation_with_a_holding_certificate() {
    for e2e in studies() {
        let linear = e2e.linearization();
        let lb = vec![0.0; e2e.n_errors()];
        let own = e2e.allocate_direct(&linear, &lb).unwrap();
        let problem = e2e.allocation_problem(linear, lb).unwrap();
        let tb = Direct::new(&e2e).allocate(&problem).unwrap();
        assert_eq!(tb.method(), "direct");
        assert_eq!(tb.upper_bounds_rad(), own.upper_bounds_rad());
        assert_relative_eq!(
            tb.objective(),
            own.objective(),
            max_relative = OBJECTIVE_REL
        );
        assert!(tb.certificate().lemma1_holds());
        assert_eq!(tb.error_names(), e2e.error_names().as_slice());
        let outputs: Vec<String> = tb
            .certificate()
            .axes()
            .iter()
            .map(|a| a.name().to_string())
            .collect();
        assert_eq!(outputs, e2e.output_names());
        // the weights of the errors with a bound are the analysis's (an unbounded error
        // counts 0 in either objective)
        let combined = tb.weights().combined();
        for (j, c) in e2e.combined_weights().iter().enumerate() {
            if tb.upper_bounds_rad()[j].is_finite() {
                assert_relative_eq!(combined[j], *c, max_relative = OBJECTIVE_REL);
            }
        }
        match tb.details() {
            MethodDetails::Joint {
                margins,
                iterations,
                ..
            } => {
                assert!(margins.iter().all(|&m| m == 0.0));
                assert_eq!(*iterations, own.iterations());
            }
            other => panic!("direct details: {other:?}"),
        }
    }
}

/// The `DirectCertified` allocator returns the certified allocation's bounds bit for bit and
/// states its second-order margins (positive: kept free for the exact chain).
#[test]
fn certified_allocator_gives_the_certified_allocation_and_its_margins() {
    let e2e = paper(Reading::USER);
    let linear = e2e.linearization();
    let lb = vec![0.0; e2e.n_errors()];
    let own = e2e.allocate_direct_certified(&linear, &lb).unwrap();
    let problem = e2e.allocation_problem(linear, lb).unwrap();
    let tb = DirectCertified::new(&e2e).allocate(&problem).unwrap();
    assert_eq!(tb.method(), "direct-certified");
    assert_eq!(tb.upper_bounds_rad(), own.upper_bounds_rad());
    assert!(tb.certificate().lemma1_holds());
    match tb.details() {
        MethodDetails::Joint { margins, .. } => {
            assert_eq!(margins, &own.second_order_margins());
            assert!(margins.iter().all(|&m| m > 0.0));
        }
        other => panic!("certified details: {other:?}"),
    }
}

/// The `YieldBased` allocator scales the direct shape exactly as the crate's own method
/// (same draws, same scale, same bounds) and states the yield it reached.
#[test]
fn yield_allocator_gives_the_yield_allocation_and_states_its_yield() {
    let e2e = paper(Reading::USER);
    let linear = e2e.linearization();
    let lb = vec![0.0; e2e.n_errors()];
    let settings = McSettings::new(2_000, 11);
    let shape = e2e
        .allocate_direct(&linear, &lb)
        .unwrap()
        .upper_bounds_rad()
        .to_vec();
    let own = e2e.allocate_yield(&shape, &lb, 0.9973, &settings).unwrap();
    let problem = e2e.allocation_problem(linear, lb).unwrap();
    let tb = YieldBased::new(&e2e, 0.9973, settings)
        .allocate(&problem)
        .unwrap();
    assert_eq!(tb.upper_bounds_rad(), own.upper_bounds_rad());
    match tb.details() {
        MethodDetails::Scaled {
            scale,
            meeting,
            samples,
            shape_rad,
            ..
        } => {
            assert_eq!(
                scale.to_bits(),
                own.scale().to_bits(),
                "same scale bit for bit"
            );
            assert_eq!(
                (*meeting, *samples),
                (
                    own.counted().count().meeting(),
                    own.counted().count().samples()
                )
            );
            assert_eq!(shape_rad, &shape);
            assert!(*meeting as f64 >= 0.9973 * *samples as f64);
        }
        other => panic!("yield details: {other:?}"),
    }
    // the yield box is larger than the worst-case one: its certificate exceeds an accuracy
    assert!(own.scale() > 1.0);
    assert!(!tb.certificate().lemma1_holds());
}

/// Limits below the accuracies keep the rest free: with every limit halved and no lower
/// bounds, the direct problem is the same up to scale, so every bound halves (J quadruples)
/// and the certificate holds against the halved limits.
#[test]
fn halved_limits_halve_every_direct_bound() {
    let e2e = paper(Reading::USER);
    let lb = vec![0.0; e2e.n_errors()];
    let full = e2e
        .allocation_problem(e2e.linearization(), lb.clone())
        .unwrap();
    let half_limits = full.limits().iter().map(|l| l.map(|v| v / 2.0)).collect();
    let half =
        alloc_opt::AllocationProblem::with_limits(e2e.linearization(), half_limits, lb).unwrap();
    let a = Direct::new(&e2e).allocate(&full).unwrap();
    let b = Direct::new(&e2e).allocate(&half).unwrap();
    for (x, y) in a.upper_bounds_rad().iter().zip(b.upper_bounds_rad()) {
        if x.is_finite() {
            assert_relative_eq!(*y, x / 2.0, max_relative = SOLVER_REL);
        } else {
            assert!(y.is_infinite());
        }
    }
    assert!(b.certificate().lemma1_holds());
    assert_relative_eq!(
        b.objective(),
        4.0 * a.objective(),
        max_relative = SOLVER_REL
    );
}

/// A limit above an output's accuracy is refused as the caller's input, naming the output's
/// limit; the yield-based method also refuses a limit below it (it counts draws against the
/// accuracy itself).
#[test]
fn limits_beyond_what_a_method_supports_are_input_errors_naming_the_output() {
    let e2e = paper(Reading::USER);
    let lb = vec![0.0; e2e.n_errors()];
    let name = &e2e.output_names()[0];
    let full = e2e
        .allocation_problem(e2e.linearization(), lb.clone())
        .unwrap();
    let scaled = |f: f64| {
        let limits = full.limits().iter().map(|l| l.map(|v| v * f)).collect();
        alloc_opt::AllocationProblem::with_limits(e2e.linearization(), limits, lb.clone()).unwrap()
    };
    let field = |e: AllocError| e.input_field().map(str::to_string);
    let above = Direct::new(&e2e).allocate(&scaled(2.0)).unwrap_err();
    assert_eq!(field(above), Some(format!("limits.{name}")));
    let below = YieldBased::new(&e2e, 0.9973, McSettings::new(2_000, 1))
        .allocate(&scaled(0.5))
        .unwrap_err();
    assert!(matches!(below, AllocError::Method { ref method, .. } if method == "yield-based"));
    assert_eq!(field(below), Some(format!("limits.{name}")));
}

/// A linearisation of another study (other positions) is refused when the problem is built.
#[test]
fn a_linearisation_of_another_schedule_is_refused() {
    let e2e = paper(Reading::USER);
    let other = study_e2e("imu-triad-example", None);
    let err = e2e
        .allocation_problem(other.linearization(), vec![0.0; e2e.n_errors()])
        .unwrap_err();
    assert!(err.input_field().unwrap().starts_with("linearization"));
}
