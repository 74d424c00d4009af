//! The end-to-end linearisation through alloc-opt's seam: `Linearization` is a
//! `LinearErrorModel` (outputs over the schedule's positions), so alloc-opt's certificate and
//! allocators work against the calibration accuracies themselves.

mod common;

use alloc_opt::{AllocationProblem, Allocator, Certificate, EqualEffects, LinearErrorModel};
use approx::assert_relative_eq;
use calib_lsq::Reading;

/// Both sides sum the same |M| UB products; only the order of a few additions may differ.
const SAME_SUM_REL: f64 = 1e-12;

/// Equal effects ends its bisection at one ulp of the common effect.
const EQUAL_EFFECTS_LOAD_REL: f64 = 1e-9;

#[test]
fn alloc_opts_certificate_of_a_linearization_is_the_end_to_end_linear_worst_case() {
    for reading in [Reading::PAPER, Reading::USER] {
        let e2e = common::paper(reading);
        let lin = e2e.linearization();
        let ub = alloc_opt::paper::table4_rad();
        let limits: Vec<Option<f64>> = e2e.accuracies().into_iter().map(Some).collect();
        let cert = Certificate::compute(&lin, &limits, &[0.0; 8], &ub).unwrap();
        let wc = e2e.worst_case(&lin, &ub).unwrap();
        for (c, o) in cert.axes().iter().zip(wc.outputs()) {
            assert_relative_eq!(
                c.worst_case_rad(),
                o.linear_bound(),
                max_relative = SAME_SUM_REL
            );
            // the maximiser is a worst position (ties between positions are common)
            let i = c.worst_pose_rad()[0] as usize;
            assert_relative_eq!(
                o.per_position()[i],
                o.linear_bound(),
                max_relative = SAME_SUM_REL
            );
        }
    }
}

#[test]
fn equal_effects_on_a_linearization_meets_every_accuracy_with_a_certificate() {
    let e2e = common::paper(Reading::USER);
    let lin = e2e.linearization();
    let acc = e2e.accuracies();
    let problem = AllocationProblem::with_limits(
        lin.clone(),
        acc.iter().copied().map(Some).collect(),
        vec![0.0; lin.n_errors()],
    )
    .unwrap();
    let b = EqualEffects.allocate(&problem).unwrap();
    assert!(b.certificate().lemma1_holds());
    // the errors no output depends on are the linearisation's own
    assert_eq!(b.unconstrained(), lin.unconstrained());
    // the box, checked by the end-to-end worst case, uses an output's whole accuracy
    let wc = e2e.worst_case(&lin, b.upper_bounds_rad()).unwrap();
    let top = wc
        .outputs()
        .iter()
        .zip(&acc)
        .map(|(o, a)| o.linear_bound() / a)
        .fold(0.0_f64, f64::max);
    assert_relative_eq!(top, 1.0, max_relative = EQUAL_EFFECTS_LOAD_REL);
}
