//! The calibration schedule designer (`schedule_design`): its exact evaluation equals the
//! end-to-end path, its screening bounds are rigorous, the exchange never returns worse than
//! its start, the D-optimal baseline is optimal on an enumerable case, bad inputs are typed
//! errors, and the paper's study gets a cheaper turntable from a designed schedule.

use approx::assert_relative_eq;
use calib_lsq::Reading;
use e2e_verify::{E2eError, EndToEnd};
use schedule_design::{
    DesignProblem, DesignSettings, candidates_with, design_schedule, grid_positions_deg,
};
use tt_core::DeltaRKind;
use tt_kinematics::paper;

/// Relative agreement of two evaluations of the same quantity by different floating-point
/// paths (dimensionless): rounding of a few hundred operations on values of order 1.
const ROUNDING_REL: f64 = 1e-10;

/// Relative slack of a rigorous bound computed in floating point (dimensionless): the dual
/// and fixed-shape bounds are exact in real arithmetic, rounding moves them by ~1e-13.
const BOUND_SLACK_REL: f64 = 1e-9;

/// The paper study's bound on the condition numbers used by the small cases (its schedule
/// has 5.91; the default bound is 10).
const MAX_CONDITION: f64 = 10.0;

fn paper_positions() -> Vec<Vec<f64>> {
    testkit::e2e::paper_positions_deg()
}

/// The paper's table, sensor and site with the candidates `grid`.
fn try_problem_on(reading: Reading, grid: Vec<Vec<f64>>) -> Result<DesignProblem, E2eError> {
    DesignProblem::new(
        &paper::table3(),
        &gw_model::paper::gyrowheel(),
        &gw_model::paper::site(),
        reading,
        &[0.0; 8],
        grid,
    )
}

/// [`try_problem_on`], which must succeed.
fn problem_on(reading: Reading, grid: Vec<Vec<f64>>) -> DesignProblem {
    try_problem_on(reading, grid).unwrap()
}

/// The paper's table, sensor and site with the grid of `step_deg` (plus the study's
/// positions when they are not on it).
fn paper_problem(reading: Reading, step_deg: f64) -> DesignProblem {
    let grid = grid_positions_deg(&paper::table3(), step_deg).unwrap();
    problem_on(reading, candidates_with(grid, &paper_positions()))
}

/// The paper's table, sensor and site with the grid of `step_deg` alone.
fn grid_problem(reading: Reading, step_deg: f64) -> DesignProblem {
    problem_on(
        reading,
        grid_positions_deg(&paper::table3(), step_deg).unwrap(),
    )
}

/// The end-to-end path every command takes for a schedule: positions to a calibration,
/// `EndToEnd::new`, `linearization`, `allocate_direct`.
fn end_to_end(
    reading: Reading,
    positions_deg: &[Vec<f64>],
) -> (EndToEnd, e2e_verify::Linearization) {
    let e2e = testkit::e2e::paper_at(reading, positions_deg);
    let linear = e2e.linearization();
    (e2e, linear)
}

/// A fixed, irregular schedule of 12 grid candidates (identifies every coefficient).
fn irregular(problem: &DesignProblem) -> Vec<usize> {
    let picks = [
        [0.0, 30.0],
        [30.0, 90.0],
        [60.0, 150.0],
        [90.0, 0.0],
        [120.0, 240.0],
        [150.0, 300.0],
        [180.0, 60.0],
        [210.0, 120.0],
        [240.0, 210.0],
        [270.0, 330.0],
        [300.0, 180.0],
        [330.0, 270.0],
    ];
    picks.iter().map(|p| problem.index_of(p).unwrap()).collect()
}

/// The precomputed path (candidate blocks gathered, the same dispatch of eq 13) gives the
/// same M as `EndToEnd::linearization`, for every reading of eq 13, and the same J as
/// `allocate_direct`.
#[test]
fn precomputed_evaluation_equals_the_end_to_end_path_for_every_reading() {
    for reading in Reading::all() {
        let problem = paper_problem(reading, 30.0);
        let s = irregular(&problem);
        let mine = problem.linearization(&s).unwrap();
        let (e2e, theirs) = end_to_end(reading, &problem.positions_deg(&s));
        let scale = theirs.matrix().amax();
        let diff = (mine.matrix() - theirs.matrix()).amax();
        assert!(
            diff <= ROUNDING_REL * scale,
            "{reading}: |dM| = {diff:e} of {scale:e}"
        );
        // readings whose error vector is identically zero to first order leave nothing to
        // allocate: both paths refuse alike
        match (
            problem.evaluate(&s),
            e2e.allocate_direct(&theirs, &[0.0; 8]),
        ) {
            (Ok(e), Ok(direct)) => {
                assert_relative_eq!(
                    e.objective(),
                    direct.objective(),
                    max_relative = ROUNDING_REL
                );
                assert_eq!(e.condition_numbers(), e2e.calibration().condition_numbers());
            }
            (Err(a), Err(b)) => assert_eq!(a, b, "{reading}"),
            (a, b) => panic!("{reading}: {a:?} vs {b:?}"),
        }
    }
}

/// Every screened swap's lower bound is at most its exact J and, with zero lower bounds, its
/// estimate at least the exact J: the bounds that prune the exchange are rigorous, for the
/// paper's reading (fixed rows) and the user's (rows through the projection, Woodbury update).
#[test]
fn screening_bounds_bracket_the_exact_objective_of_every_swap() {
    // the paper's (fixed rows), the user's (projection with d = -1), beta-hat-2 at the intended
    // orientation (projection with d = +1)
    let beta2: Reading = "intended/beta2/printed".parse().unwrap();
    for reading in [Reading::PAPER, Reading::USER, beta2] {
        let problem = paper_problem(reading, 30.0);
        let s = irregular(&problem);
        let hood = problem.neighbourhood(&s, f64::INFINITY).unwrap();
        let mut checked = 0;
        for slot in [0, 5, 11] {
            for b in hood.screen(slot).unwrap() {
                let mut t = s.clone();
                t[slot] = b.candidate();
                let e = problem.evaluate(&t).unwrap();
                if e.unidentified_output().is_some() {
                    continue;
                }
                if b.lower().is_infinite() {
                    // screened as (nearly) rank deficient: determinant ratio below 1e-10
                    assert!(
                        e.max_condition() > 1e3,
                        "{reading}: cond {}",
                        e.max_condition()
                    );
                    continue;
                }
                assert!(
                    b.lower() <= e.objective() * (1.0 + BOUND_SLACK_REL),
                    "{reading} slot {slot} candidate {}: lower {} > J {}",
                    b.candidate(),
                    b.lower(),
                    e.objective()
                );
                assert!(
                    b.estimate() >= e.objective() * (1.0 - BOUND_SLACK_REL),
                    "{reading} slot {slot} candidate {}: upper {} < J {}",
                    b.candidate(),
                    b.estimate(),
                    e.objective()
                );
                checked += 1;
            }
        }
        assert!(checked > 300, "{reading}: only {checked} swaps checked");
    }
}

/// The exchange only takes exactly evaluated improvements: from the study's schedule and
/// from seeded random feasible starts its result is never worse than the start, and stays
/// feasible (identifiable, condition numbers within the bound).
#[test]
fn exchange_never_returns_a_schedule_worse_than_its_start() {
    for reading in [Reading::PAPER, Reading::USER] {
        let problem = paper_problem(reading, 30.0);
        let study: Vec<usize> = paper_positions()
            .iter()
            .map(|p| problem.index_of(p).unwrap())
            .collect();
        let mut starts = vec![study];
        let mut rng = 0x9e37_79b9_7f4a_7c15_u64;
        while starts.len() < 4 {
            // a seeded random 12-subset (xorshift), kept when feasible
            let mut s: Vec<usize> = Vec::new();
            while s.len() < 12 {
                rng ^= rng << 13;
                rng ^= rng >> 7;
                rng ^= rng << 17;
                let c = (rng % problem.n_candidates() as u64) as usize;
                if !s.contains(&c) {
                    s.push(c);
                }
            }
            if problem.evaluate(&s).unwrap().is_feasible(MAX_CONDITION) {
                starts.push(s);
            }
        }
        for start in starts {
            let before = problem.evaluate(&start).unwrap();
            let out = problem.exchange(&start, MAX_CONDITION).unwrap();
            assert_relative_eq!(
                out.start_objective(),
                before.objective(),
                max_relative = ROUNDING_REL
            );
            assert!(
                out.evaluation().objective() <= before.objective(),
                "{reading}: {} > {}",
                out.evaluation().objective(),
                before.objective()
            );
            assert!(out.evaluation().is_feasible(MAX_CONDITION));
            assert_eq!(out.evaluation().schedule().len(), start.len());
            // its J is what a fresh evaluation gives
            let again = problem.evaluate(out.evaluation().schedule()).unwrap();
            assert_relative_eq!(
                again.objective(),
                out.evaluation().objective(),
                max_relative = ROUNDING_REL
            );
        }
    }
}

/// Every k-subset of `0..n`, in lexicographic order.
fn subsets(n: usize, k: usize) -> Vec<Vec<usize>> {
    let mut out = Vec::new();
    let mut idx: Vec<usize> = (0..k).collect();
    loop {
        out.push(idx.clone());
        let Some(i) = (0..k).rev().find(|&i| idx[i] != i + n - k) else {
            return out;
        };
        idx[i] += 1;
        for j in i + 1..k {
            idx[j] = idx[j - 1] + 1;
        }
    }
}

/// A two-output gyro with bias and g-sensitivity only (4 coefficients each), for cases small
/// enough to enumerate.
fn small_gyro() -> gw_model::SensorModel {
    let term = |c: &str, r: &str, v: f64, known: bool| gw_model::Term {
        coefficient: c.to_string(),
        regressor: gw_model::Regressor::parse(r).unwrap(),
        value: v,
        known,
    };
    let output = |name: &str, rate: &str, b: f64| gw_model::Output {
        name: name.to_string(),
        unit: "deg_per_h".to_string(),
        accuracy: 0.1,
        terms: vec![
            term(&format!("omega_{name}"), rate, 1.0, true),
            term(&format!("b_{name}"), "1", b, false),
            term(&format!("g_{name}x"), "a_x", 0.3, false),
            term(&format!("g_{name}y"), "a_y", -0.2, false),
            term(&format!("g_{name}z"), "a_z", 0.1, false),
        ],
    };
    gw_model::SensorModel::new(vec![output("x", "w_x", 0.5), output("y", "w_y", -0.4)]).unwrap()
}

/// On the 60 deg grid of the paper's table (36 candidates) with a 4-coefficient gyro pair,
/// the D-optimal baseline for 5 positions reaches the largest sum of log det(A^T A) over all
/// 376,992 schedules.
#[test]
fn d_optimal_baseline_equals_the_enumeration_optimum_on_a_small_case() {
    let table = paper::table3();
    let grid = grid_positions_deg(&table, 60.0).unwrap();
    let problem = DesignProblem::new(
        &table,
        &small_gyro(),
        &gw_model::paper::site(),
        Reading::PAPER,
        &[0.0; 8],
        grid,
    )
    .unwrap();
    assert_eq!(problem.n_candidates(), 36);
    let all = subsets(36, 5);
    assert_eq!(all.len(), 376_992);
    let best = all
        .iter()
        .map(|s| problem.log_det_information(s))
        .fold(f64::NEG_INFINITY, f64::max);
    assert!(best.is_finite());
    let d = problem.d_optimal(5, 2017, 4, &|| {}).unwrap();
    assert_relative_eq!(d.log_det(), best, max_relative = ROUNDING_REL);
    assert_relative_eq!(
        problem.log_det_information(d.schedule()),
        best,
        max_relative = ROUNDING_REL
    );
    assert!(d.stop().local_optimum());
}

/// Candidates at a single inner-axis angle leave the specific force in the x-z plane of the
/// sensor: no schedule drawn from them separates the a_y terms; the error names the output
/// and the coefficients.
#[test]
fn unidentifiable_candidate_set_is_a_typed_error_naming_the_coefficients() {
    let candidates: Vec<Vec<f64>> = (0..24).map(|k| vec![15.0 * f64::from(k), 0.0]).collect();
    let err = try_problem_on(Reading::PAPER, candidates).unwrap_err();
    match &err {
        E2eError::UnidentifiableCandidates {
            output,
            coefficients,
            candidates,
        } => {
            assert_eq!(output, "x");
            assert!(
                coefficients.contains(&"dx_y".to_string()),
                "{coefficients:?}"
            );
            assert!(
                coefficients.contains(&"dx_xy".to_string()),
                "{coefficients:?}"
            );
            assert_eq!(*candidates, 24);
        }
        other => panic!("expected UnidentifiableCandidates, got {other:?}"),
    }
    let text = err.to_string();
    assert!(
        text.contains("output `x`") && text.contains("dx_xy"),
        "{text}"
    );
}

/// Too few positions to identify an output, more positions than candidates, no candidates
/// and a grid step out of range are typed errors naming what is wrong.
#[test]
fn bad_sizes_and_steps_are_typed_errors() {
    let problem = grid_problem(Reading::PAPER, 60.0);
    match problem.greedy(6, MAX_CONDITION).unwrap_err() {
        E2eError::TooFewPositions {
            positions: 6,
            coefficients: 7,
            output,
        } => assert_eq!(output, "x"),
        other => panic!("{other:?}"),
    }
    assert!(matches!(
        problem.greedy(37, MAX_CONDITION).unwrap_err(),
        E2eError::TooManyPositions {
            positions: 37,
            candidates: 36
        }
    ));
    let table = paper::table3();
    let err = try_problem_on(Reading::PAPER, vec![]).unwrap_err();
    assert!(matches!(err, E2eError::EmptyCandidates));
    for bad in [0.0, -15.0, 361.0, f64::NAN] {
        assert!(
            matches!(
                grid_positions_deg(&table, bad).unwrap_err(),
                E2eError::Field(tt_core::FieldError::OutOfRange { ref field, .. }) if field == "step_deg"
            ),
            "{bad}"
        );
    }
    // a repeated candidate in a schedule
    assert!(matches!(
        problem.evaluate(&[0, 1, 2, 3, 4, 5, 6, 6]).unwrap_err(),
        E2eError::RepeatedCandidate { candidate: 6 }
    ));
}

/// The grid covers each joint's range with the step; a full turn leaves out its end point.
#[test]
fn grid_covers_full_turns_without_repeating_the_start() {
    let g = grid_positions_deg(&paper::table3(), 15.0).unwrap();
    assert_eq!(g.len(), 24 * 24);
    // the 90 deg grid never tilts a sensor axis off the horizontal-vertical, so a_x a_y is
    // always zero: a typed error, not a silent design
    let e = try_problem_on(
        Reading::PAPER,
        grid_positions_deg(&paper::table3(), 90.0).unwrap(),
    )
    .unwrap_err();
    assert!(
        matches!(&e, E2eError::UnidentifiableCandidates { coefficients, .. } if coefficients == &["dx_xy".to_string()]),
        "{e:?}"
    );
    assert_eq!(g[0], vec![0.0, 0.0]);
    assert_eq!(g[1], vec![0.0, 15.0]);
    assert_eq!(g.last().unwrap(), &vec![345.0, 345.0]);
    assert_eq!(
        grid_positions_deg(&paper::table3(), 100.0).unwrap().len(),
        16
    );
}

/// The acceptance for the paper's study (15 deg grid, 32 positions, its reading):
/// the designed schedule's J is strictly below the study schedule's and the D-optimal
/// schedule's, every output stays identifiable within the condition bound, and the report's
/// J (the end-to-end path) equals the search's. The study's J is `end-to-end`'s
/// `direct_objective` for the paper study.
#[test]
fn designed_schedule_beats_the_study_and_d_optimal_schedules_for_the_paper_study() {
    let problem = paper_problem(Reading::PAPER, 15.0);
    let settings = DesignSettings::new(32, 2017);
    let d = design_schedule(
        &problem,
        &paper_positions(),
        DeltaRKind::SmallAngle,
        &settings,
        &[],
        &|| {},
    )
    .unwrap();
    let (designed, study, dopt) = (
        d.designed().allocation().objective(),
        d.study().allocation().objective(),
        d.d_optimal().allocation().objective(),
    );
    assert!(
        designed < study && designed < dopt,
        "designed {designed}, study {study}, D-optimal {dopt}"
    );
    // the paper study's direct allocation (end-to-end, reading intended/beta1/printed)
    assert_relative_eq!(
        d.study().allocation().objective_arcmin(),
        54.652_234_256_453_7,
        max_relative = 1e-9
    );
    assert!(
        d.designed()
            .condition_numbers()
            .iter()
            .all(|&k| k <= settings.max_condition)
    );
    assert_eq!(d.designed().positions_deg().len(), 32);
    // the same path from the same positions: bit-identical
    assert_eq!(
        d.designed().allocation().objective().to_bits(),
        d.search().designed().evaluation().objective().to_bits()
    );
    // the study's schedule was a start, so the best restart is at least as good
    assert!(d.search().designed().stop().local_optimum());
    if let Some(r) = &d.random_best() {
        assert!(designed < r.allocation().objective());
    }
    // with the study's tolerances (its certified allocation) the designed schedule meets every
    // accuracy with room to spare
    let wc = &d.designed().with_study_tolerances();
    assert!(wc.certified() && wc.unbounded().is_empty());
    for o in wc.outputs() {
        let o = o.as_ref().unwrap();
        assert!(o.linear_bound() < 0.01, "{}", o.linear_bound());
    }
}

/// The search's result does not depend on the number of threads: the same seed gives the
/// same schedule and the same J on one thread and on four.
#[test]
fn same_seed_same_design_for_one_and_four_threads() {
    for reading in [Reading::PAPER, Reading::USER] {
        let problem = paper_problem(reading, 30.0);
        let mut settings = DesignSettings::new(12, 99);
        settings.restarts = 4;
        settings.random_schedules = 16;
        settings.d_optimal_restarts = 3;
        let run = |threads: usize| {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            pool.install(|| problem.design(&settings, &[], &|| {}).unwrap())
        };
        let (one, four) = (run(1), run(4));
        assert_eq!(
            one.designed().evaluation().schedule(),
            four.designed().evaluation().schedule(),
            "{reading}"
        );
        assert_eq!(
            one.designed().evaluation().objective().to_bits(),
            four.designed().evaluation().objective().to_bits()
        );
        assert_eq!(one.d_optimal().schedule(), four.d_optimal().schedule());
        assert_eq!(
            one.random_best().map(|e| e.schedule()),
            four.random_best().map(|e| e.schedule())
        );
        // and another seed draws other random starts
        let mut other = settings.clone();
        other.seed = 100;
        let third = problem.design(&other, &[], &|| {}).unwrap();
        assert!(
            third
                .restarts()
                .iter()
                .zip(one.restarts())
                .any(|(a, b)| a.start_objective().to_bits() != b.start_objective().to_bits())
        );
    }
}
