//! Positions and dwell chosen together under a total test-time budget (issue 21 item 4):
//! the Pareto front is monotone, every point is end-to-end's J for its schedule and dwell,
//! the chosen point is within the budget and bad budgets are refused naming the field.

use testkit::e2e as common;

use approx::assert_relative_eq;
use calib_lsq::Timing;
use e2e_verify::noise::DEFAULT_K_SIGMA;
use e2e_verify::{E2eError, EndToEnd, NoisyAllocation};
use schedule_design::{
    BudgetDesign, BudgetParams, BudgetPoint, DesignProblem, ScheduleOrigin, TimeBudget,
    budget_counts, candidates_with, design_with_budget, grid_positions_deg, pareto_front,
    shortest_test_s, total_test_s,
};
use study::Study;

/// Relative agreement of a front point's J with end-to-end's allocation for the same schedule
/// and dwell (dimensionless): the same path from the same positions, so only rounding of the
/// same operations may differ.
const SAME_PATH_REL: f64 = 1e-9;

/// The design problem of study `s` on the grid of `step_deg` plus the study's positions.
fn study_problem(s: &Study, step_deg: f64) -> DesignProblem {
    let grid = grid_positions_deg(&s.turntable, step_deg).unwrap();
    DesignProblem::new(
        &s.turntable,
        &s.sensor,
        &s.site,
        s.reading,
        &s.lower_bounds_rad,
        candidates_with(grid, &s.positions_deg),
    )
    .unwrap()
}

/// The paper's noisy copy on a 45 deg grid (64 candidates and the study's positions), with a
/// table design of the study's size by the greedy construction and the exchange.
fn noisy_paper() -> (Study, DesignProblem, Vec<usize>, Option<Vec<usize>>) {
    let s = common::study("gyrowheel-2017-noise-assumed");
    let problem = study_problem(&s, 45.0);
    let n = s.positions_deg.len();
    let start = problem.greedy(n, 10.0).unwrap();
    let table = problem
        .exchange(start.schedule(), 10.0)
        .unwrap()
        .evaluation()
        .schedule()
        .to_vec();
    let study: Option<Vec<usize>> = s
        .positions_deg
        .iter()
        .map(|p| problem.index_of(p))
        .collect();
    (s, problem, table, study)
}

fn budget_of(s: &Study, budget_s: f64) -> TimeBudget<'_> {
    let t = s.timing.as_ref().expect("the noisy copy has a timing");
    TimeBudget {
        noise: &s.noise,
        move_s: t.move_s(),
        sample_rate_hz: t.sample_rate_hz(),
        k_sigma: DEFAULT_K_SIGMA,
        budget_s,
        max_dwell_s: 86_400.0,
        study_dwell_s: Some(t.dwell_s()[0]),
        search_counts: true,
        params: BudgetParams::default(),
        rate_steps: &[],
        rate_step_s: &[],
    }
}

/// The budget design of the paper's noisy copy ([`noisy_paper`]) under `b`, with the table
/// design and the study's schedule, no other schedules, condition bound 10.
fn design(
    s: &Study,
    problem: &DesignProblem,
    table: &[usize],
    study: Option<&[usize]>,
    b: &TimeBudget<'_>,
) -> Result<BudgetDesign, E2eError> {
    design_with_budget(problem, table, study, &s.positions_deg, &[], 10.0, b)
}

/// The end-to-end model of `positions_deg` and its direct allocation at `dwell_s` with the
/// noise part kept free (end-to-end's path).
fn direct_at(
    s: &Study,
    problem: &DesignProblem,
    positions_deg: &[Vec<f64>],
    dwell_s: f64,
) -> (EndToEnd, NoisyAllocation) {
    let t = s.timing.as_ref().unwrap();
    let timing =
        Timing::uniform(positions_deg.len(), dwell_s, t.move_s(), t.sample_rate_hz()).unwrap();
    let e2e = problem.end_to_end(positions_deg).unwrap();
    let noise = e2e.noise().noise_budget(&s.noise, &timing).unwrap();
    let lin = e2e.linearization();
    let direct = e2e
        .noise()
        .allocate_direct_with_noise(&lin, &s.lower_bounds_rad, &noise, DEFAULT_K_SIGMA, None)
        .unwrap();
    (e2e, direct)
}

/// $J$ (rad$^{-2}$) of `positions_deg` at `dwell_s` by end-to-end's path (direct allocation
/// with the noise part kept free; `+inf` when no table suffices).
fn objective_at(
    s: &Study,
    problem: &DesignProblem,
    positions_deg: &[Vec<f64>],
    dwell_s: f64,
) -> f64 {
    let (_, direct) = direct_at(s, problem, positions_deg, dwell_s);
    direct.map_or(f64::INFINITY, |d| d.objective())
}

/// On the paper's noisy copy: the front is ordered by total time with J strictly falling (more
/// time never needs a better table), each point's total is N (T + move), each point's J is
/// end-to-end's direct allocation with the noise part kept free for that schedule at that
/// dwell, and the chosen point is the front's last within the budget.
#[test]
fn pareto_front_is_monotone_agrees_with_end_to_end_and_the_choice_fits_the_budget() {
    let (s, problem, table, study) = noisy_paper();
    let budget_s = 25_000.0;
    let b = budget_of(&s, budget_s);
    let d = design(&s, &problem, &table, study.as_deref(), &b).unwrap();
    assert!(d.pareto().len() >= 3, "{:?}", d.pareto());
    for w in d.pareto().windows(2) {
        assert!(w[1].total_s() > w[0].total_s(), "{w:?}");
        assert!(w[1].objective() < w[0].objective(), "{w:?}");
    }
    let timing = s.timing.as_ref().unwrap();
    for p in d.pareto() {
        assert_relative_eq!(
            p.total_s(),
            total_test_s(p.n_positions(), p.dwell_s(), timing.move_s()),
            max_relative = 1e-15
        );
        let (_, direct) = direct_at(&s, &problem, p.positions_deg(), p.dwell_s());
        let j = direct.expect("a table suffices on the front").objective();
        assert_relative_eq!(p.objective(), j, max_relative = SAME_PATH_REL);
    }
    let chosen = d.chosen().expect("a table suffices within the budget");
    assert!(chosen.total_s() <= budget_s);
    // nothing on the front within the budget is cheaper, and the next point is over it
    let i = d.pareto().iter().position(|p| p == chosen).unwrap();
    assert!(
        d.pareto()[..i]
            .iter()
            .all(|p| p.objective() > chosen.objective())
    );
    if let Some(next) = d.pareto().get(i + 1) {
        assert!(next.total_s() > budget_s);
    }
    // the study's and the table's schedules are among those evaluated
    assert!(
        d.schedules()
            .iter()
            .any(|(o, _)| *o == ScheduleOrigin::Table)
    );
    assert!(
        d.schedules()
            .iter()
            .any(|(_, p)| p.as_slice() == s.positions_deg.as_slice())
    );
}

/// A budget that affords the fewest positions but below the shortest test at which any table
/// suffices chooses nothing, and the front starts above it.
#[test]
fn a_budget_too_short_for_any_table_chooses_nothing() {
    let (s, problem, table, study) = noisy_paper();
    let budget_s = 1.5 * shortest_test_s(&problem, &budget_of(&s, 1.0));
    let b = budget_of(&s, budget_s);
    let d = design(&s, &problem, &table, study.as_deref(), &b).unwrap();
    assert!(d.chosen().is_none());
    assert!(d.pareto().first().is_some_and(|p| p.total_s() > budget_s));
}

/// A budget shorter than the fewest positions that identify every output, at one move and one
/// sample each, is a typed error naming `time_budget_s`, with the count and the time it needs;
/// a budget of exactly that time is accepted.
#[test]
fn a_budget_too_short_for_the_fewest_positions_is_refused_naming_time_budget_s() {
    let (s, problem, table, study) = noisy_paper();
    let shortest = shortest_test_s(&problem, &budget_of(&s, 1.0));
    let n_min = problem.min_positions();
    // n_min moves of 60 s and one sample at 100 Hz each
    assert_relative_eq!(shortest, n_min as f64 * 60.01, max_relative = 1e-15);
    let run = |budget_s: f64| {
        design(
            &s,
            &problem,
            &table,
            study.as_deref(),
            &budget_of(&s, budget_s),
        )
    };
    let e = run(0.99 * shortest).unwrap_err();
    let E2eError::BudgetTooShort {
        positions,
        needed_s,
        ..
    } = &e
    else {
        panic!("{e:?}")
    };
    assert_eq!(*positions, n_min);
    assert_relative_eq!(*needed_s, shortest, max_relative = 1e-15);
    assert!(e.to_string().contains("time_budget_s"), "{e}");
    let d = run(shortest).unwrap();
    assert!(
        d.chosen().is_none(),
        "one sample per position suffices for no table"
    );
}

/// With the number of positions searched: the counts are the table design's and those
/// [`budget_counts`] derives from the budget (the fewest positions among them); the chosen
/// count fits the budget (N (T + move) <= budget); the choice is at least as good as the
/// fixed-count design's at the same budget (a budget affording more positions than the study
/// uses), and never loses to the study's schedule at the study's own dwell.
#[test]
fn searching_the_count_fits_the_budget_and_never_loses_to_the_fixed_count_design() {
    let (s, problem, table, study) = noisy_paper();
    let timing = s.timing.as_ref().unwrap();
    let n = table.len();
    // twice the study's own test (32 x (600 + 60) s): room for more positions or longer dwells
    let budget_s = 2.0 * total_test_s(n, timing.dwell_s()[0], timing.move_s());
    let run = |search_counts: bool| {
        let b = TimeBudget {
            search_counts,
            ..budget_of(&s, budget_s)
        };
        design(&s, &problem, &table, study.as_deref(), &b).unwrap()
    };
    let fixed = run(false);
    let searched = run(true);
    assert_eq!(fixed.counts(), vec![n]);
    // the count search only adds: every schedule of the fixed-count design is searched too
    for (_, positions) in fixed.schedules() {
        assert!(
            searched.schedules().iter().any(|(_, q)| q == positions),
            "{positions:?}"
        );
    }
    let want = budget_counts(&problem, &budget_of(&s, budget_s), n, s.positions_deg.len());
    // the fewest positions that identify every output plus the default redundancy
    assert!(
        want.contains(&(problem.min_positions() + schedule_design::DEFAULT_REDUNDANCY)),
        "{want:?}"
    );
    // the study's dwell affords 64 positions in twice its time
    assert!(want.contains(&(2 * n)), "{want:?}");
    let mut all: Vec<usize> = searched
        .counts()
        .iter()
        .chain(searched.counts_skipped())
        .copied()
        .collect();
    all.sort_unstable();
    let mut expected = want.clone();
    expected.push(n);
    expected.extend(searched.counts_refined());
    expected.sort_unstable();
    assert_eq!(all, expected);
    assert!(
        searched.counts().len() > 1,
        "{:?}",
        searched.counts_skipped()
    );
    let chosen = searched.chosen().expect("a table suffices");
    let fixed_chosen = fixed.chosen().expect("a table suffices");
    assert!(chosen.total_s() <= budget_s);
    assert_relative_eq!(
        chosen.total_s(),
        total_test_s(chosen.n_positions(), chosen.dwell_s(), timing.move_s()),
        max_relative = 1e-15
    );
    assert!(searched.counts().contains(&chosen.n_positions()));
    assert!(
        chosen.objective() <= fixed_chosen.objective(),
        "{chosen:?} against {fixed_chosen:?}"
    );
    // every count's points are on the same path as end-to-end
    assert_relative_eq!(
        chosen.objective(),
        objective_at(&s, &problem, chosen.positions_deg(), chosen.dwell_s()),
        max_relative = SAME_PATH_REL
    );
    // the study's own test (32 x 600 s) fits the budget: the choice never loses to it
    let study_j = objective_at(&s, &problem, &s.positions_deg, timing.dwell_s()[0]);
    assert!(study_j.is_finite());
    assert!(
        chosen.objective() <= study_j,
        "{} against {study_j}",
        chosen.objective()
    );
}

/// The front keeps exactly the undominated points: ordered by total time, each strictly
/// cheaper than every point before it (a point with more time and no lower J is dropped, and
/// so is a point without a table).
#[test]
fn pareto_front_drops_dominated_points() {
    let p = |total_s: f64, objective: f64| {
        BudgetPoint::new(
            ScheduleOrigin::Table,
            vec![vec![0.0]],
            total_s,
            total_s,
            objective,
        )
    };
    let front = pareto_front(&[
        p(3.0, 5.0),
        p(1.0, 10.0),
        p(2.0, 10.0),
        p(2.5, f64::INFINITY),
        p(4.0, 6.0),
        p(5.0, 1.0),
        p(1.0, 12.0),
    ]);
    let got: Vec<(f64, f64)> = front.iter().map(|q| (q.total_s(), q.objective())).collect();
    assert_eq!(got, vec![(1.0, 10.0), (3.0, 5.0), (5.0, 1.0)]);
}

/// A budget, longest dwell or sample rate that is not finite and positive is refused naming
/// the field.
#[test]
fn bad_budgets_are_refused_naming_the_field() {
    let (s, problem, table, study) = noisy_paper();
    for (budget_s, field) in [
        (0.0, "budget_s"),
        (-5.0, "budget_s"),
        (f64::NAN, "budget_s"),
        (f64::INFINITY, "budget_s"),
    ] {
        let b = budget_of(&s, budget_s);
        let e = design(&s, &problem, &table, study.as_deref(), &b).unwrap_err();
        assert!(matches!(e, E2eError::Field(_)), "{e:?}");
        assert!(e.to_string().contains(field), "{e}");
    }
    let mut b = budget_of(&s, 1000.0);
    b.sample_rate_hz = 0.0;
    let e = design(&s, &problem, &table, study.as_deref(), &b).unwrap_err();
    assert!(e.to_string().contains("sample_rate_hz"), "{e}");
}

/// The tried counts (designed or skipped) nearest below and above `count`.
fn neighbours(d: &BudgetDesign, count: usize) -> (Option<usize>, Option<usize>) {
    let tried: Vec<usize> = d
        .counts()
        .iter()
        .chain(d.counts_skipped())
        .copied()
        .collect();
    (
        tried.iter().filter(|&&c| c < count).max().copied(),
        tried.iter().filter(|&&c| c > count).min().copied(),
    )
}

/// The refinement of the count (bisection between the best count and its tried neighbours):
/// on the paper's noisy copy at twice its test time, it tries a count strictly between the
/// coarse search's best count and each neighbour a gap separates it from; the chosen point's
/// J is at most that of every schedule evaluated (every tried count) at every dwell within the
/// budget (recomputed on end-to-end's path), and at most the coarse search's choice; with
/// designs to spare (four times the default), the chosen count's tried neighbours are
/// adjacent counts (a local optimum over the tried neighbours).
#[test]
fn count_refinement_bisects_towards_the_best_count_and_the_choice_is_best_of_all_tried() {
    let (s, problem, table, study) = noisy_paper();
    let timing = s.timing.as_ref().unwrap();
    let budget_s = 2.0 * total_test_s(table.len(), timing.dwell_s()[0], timing.move_s());
    let run = |count_refinements: usize| {
        let mut b = budget_of(&s, budget_s);
        b.params.count_refinements = count_refinements;
        design(&s, &problem, &table, study.as_deref(), &b).unwrap()
    };
    let coarse = run(0);
    assert!(coarse.counts_refined().is_empty());
    let refined = run(BudgetParams::default().count_refinements);
    let c0 = coarse.chosen().expect("a table suffices").n_positions();
    let (below, above) = neighbours(&coarse, c0);
    for nb in [below, above].into_iter().flatten() {
        if nb.abs_diff(c0) > 1 {
            let (lo, hi) = (nb.min(c0), nb.max(c0));
            assert!(
                refined.counts_refined().iter().any(|&c| c > lo && c < hi),
                "nothing tried between {c0} and {nb}: {:?}",
                refined.counts_refined()
            );
        }
    }
    let chosen = refined.chosen().expect("a table suffices");
    assert!(chosen.total_s() <= budget_s);
    assert!(chosen.objective() <= coarse.chosen().unwrap().objective());
    for (_, positions) in refined.schedules() {
        let e2e = problem.end_to_end(positions).unwrap();
        let linear = e2e.linearization();
        for &t in refined.dwells_s() {
            if total_test_s(positions.len(), t, timing.move_s()) > budget_s {
                continue;
            }
            let noise = e2e
                .noise()
                .noise_budget(
                    &s.noise,
                    &Timing::uniform(positions.len(), t, timing.move_s(), timing.sample_rate_hz())
                        .unwrap(),
                )
                .unwrap();
            let j = e2e
                .noise()
                .allocate_direct_with_noise(
                    &linear,
                    &s.lower_bounds_rad,
                    &noise,
                    DEFAULT_K_SIGMA,
                    None,
                )
                .unwrap()
                .map_or(f64::INFINITY, |d| d.objective());
            assert!(
                chosen.objective() <= j * (1.0 + SAME_PATH_REL),
                "{} positions at {t} s: {j} below the chosen {}",
                positions.len(),
                chosen.objective()
            );
        }
    }
    // with designs to spare the bisection ends at adjacent neighbours
    let spare = 4 * BudgetParams::default().count_refinements;
    let converged = run(spare);
    assert!(converged.counts_refined().len() < spare);
    let best = converged.chosen().expect("a table suffices");
    assert!(best.objective() <= chosen.objective());
    let c = best.n_positions();
    let (below, above) = neighbours(&converged, c);
    assert!(below.is_none_or(|b| b + 1 == c), "{below:?} {c}");
    assert!(above.is_none_or(|a| a == c + 1), "{above:?} {c}");
    println!(
        "coarse counts {:?} (skipped {:?}) chose {} x {} s, J = {} arcmin^-2; refined tried {:?}, chose {} x {} s, J = {} arcmin^-2; with designs to spare tried {:?}, chose {} x {} s, J = {} arcmin^-2",
        coarse.counts(),
        coarse.counts_skipped(),
        c0,
        coarse.chosen().unwrap().dwell_s(),
        coarse.chosen().unwrap().objective_arcmin(),
        refined.counts_refined(),
        chosen.n_positions(),
        chosen.dwell_s(),
        chosen.objective_arcmin(),
        converged.counts_refined(),
        c,
        best.dwell_s(),
        best.objective_arcmin()
    );
}

/// Rate steps keep their whole-revolution windows in the time budget (issue 35): on the
/// STIM300-class rate-table study (24 static positions of 300 s, then six steps of 84
/// revolutions at 100 deg/s, 302.4 s each, kept whatever the static dwell) the budget's noise
/// sigma for the study's schedule at 3000 s per static position equals end-to-end's for the
/// study at that dwell, its total time is end-to-end's plus the one move the budget counts
/// before the first entry (72,000 + 1,814.4 + 30 x 10 s = 74,114.4 s), and the budget
/// design's front point at that dwell has end-to-end's J of the direct allocation with the
/// noise kept free for the study with that point's positions. Before, the budget built the static positions alone
/// (24 x 3010 s = 72,240 s, no rate step in the noise or the table).
#[test]
fn rate_steps_keep_their_whole_revolution_windows_in_the_time_budget() {
    let s = common::study("stim300-rate-table-example");
    let timing = s.timing.as_ref().expect("a timing");
    let n = s.positions_deg.len();
    let rate_steps = &s.calibration.schedule().positions()[n..];
    assert_eq!(rate_steps.len(), 6);
    let problem = study_problem(&s, 90.0);
    // past the study's shortest dwell (1,595 s), so a table suffices
    let dwell = 3000.0;
    let at_dwell = timing.with_dwell_s(vec![dwell; n]).unwrap();
    let b = TimeBudget {
        rate_steps,
        rate_step_s: timing.rate_step_s(),
        search_counts: false,
        study_dwell_s: Some(dwell),
        ..budget_of(&s, 100_000.0)
    };
    let poses: Vec<tt_core::Pose> = s
        .schedule_angles_deg()
        .iter()
        .map(|p| tt_core::Pose::from_deg(p).unwrap())
        .collect();
    let study_e2e = e2e_verify::EndToEnd::new(&s.turntable, &s.calibration, &poses, s.reading)
        .expect("the study's simulator");
    let want = study_e2e.noise().noise_budget(&s.noise, &at_dwell).unwrap();
    let designed_e2e = problem
        .end_to_end_with_rate_steps(&s.positions_deg, rate_steps)
        .unwrap();
    let got = designed_e2e
        .noise()
        .noise_budget(&s.noise, &b.timing(n, dwell).unwrap())
        .unwrap();
    for (g, w) in got.sigma().iter().zip(want.sigma()) {
        assert_relative_eq!(*g, w, max_relative = SAME_PATH_REL);
    }
    assert_relative_eq!(
        b.test_s(n, dwell),
        at_dwell.total_s() + timing.move_s(),
        max_relative = SAME_PATH_REL
    );
    assert_relative_eq!(b.test_s(n, dwell), 74_114.4, max_relative = SAME_PATH_REL);
    let study_idx: Vec<usize> = s
        .positions_deg
        .iter()
        .map(|p| problem.index_of(p).expect("a candidate"))
        .collect();
    let d = design(&s, &problem, &study_idx, Some(&study_idx), &b).unwrap();
    // every front point at 3000 s: J is end-to-end's for the study with that point's positions
    // (the study loader's path: its schedule, rate steps and timing), total as above
    let at: Vec<&BudgetPoint> = d
        .pareto()
        .iter()
        .filter(|p| p.dwell_s().to_bits() == dwell.to_bits())
        .collect();
    assert_eq!(at.len(), 1);
    for p in at {
        let s2 = s.with_positions_deg(p.positions_deg().to_vec()).unwrap();
        let poses: Vec<tt_core::Pose> = s2
            .schedule_angles_deg()
            .iter()
            .map(|q| tt_core::Pose::from_deg(q).unwrap())
            .collect();
        let e2e =
            e2e_verify::EndToEnd::new(&s2.turntable, &s2.calibration, &poses, s2.reading).unwrap();
        let t2 = s2
            .timing
            .as_ref()
            .unwrap()
            .with_dwell_s(vec![dwell; p.n_positions()])
            .unwrap();
        let noise = e2e.noise().noise_budget(&s2.noise, &t2).unwrap();
        let a = e2e
            .noise()
            .allocate_direct_with_noise(
                &e2e.linearization(),
                &s2.lower_bounds_rad,
                &noise,
                DEFAULT_K_SIGMA,
                None,
            )
            .unwrap()
            .expect("a table suffices at 3000 s");
        assert_relative_eq!(p.objective(), a.objective(), max_relative = SAME_PATH_REL);
        assert_relative_eq!(
            p.total_s(),
            t2.total_s() + t2.move_s(),
            max_relative = SAME_PATH_REL
        );
    }
}

/// The front never proposes fewer positions than the fewest that identify every output plus
/// the stated redundancy (issue 35: a front whose shortest point had exactly as many positions
/// as unknowns): every searched count and every point not of the study's own schedule keeps
/// at least `min_positions + redundancy` positions, for the default redundancy (2) and for 5.
#[test]
fn the_front_keeps_the_stated_redundancy_beyond_the_fewest_positions() {
    let (s, problem, table, study) = noisy_paper();
    let timing = s.timing.as_ref().unwrap();
    let budget_s = 2.0 * total_test_s(table.len(), timing.dwell_s()[0], timing.move_s());
    for redundancy in [schedule_design::DEFAULT_REDUNDANCY, 5] {
        let b = TimeBudget {
            params: BudgetParams {
                redundancy,
                ..BudgetParams::default()
            },
            ..budget_of(&s, budget_s)
        };
        let fewest = problem.min_positions() + redundancy;
        assert_eq!(schedule_design::fewest_proposed(&problem, &b), fewest);
        for c in budget_counts(&problem, &b, table.len(), s.positions_deg.len()) {
            assert!(c >= fewest, "count {c} below {fewest}");
        }
        let d = design(&s, &problem, &table, study.as_deref(), &b).unwrap();
        assert!(!d.pareto().is_empty());
        for p in d.pareto() {
            assert!(
                p.origin() == ScheduleOrigin::Study || p.n_positions() >= fewest,
                "{} positions ({:?}) below {fewest}",
                p.n_positions(),
                p.origin()
            );
        }
    }
}

/// The points `end-to-end` lists for the study's schedule (its trade-off over the dwells the
/// budget searches, from one sample to the longest dwell): (dwell, the budget's total (end-to-end's
/// plus the one move the budget counts before the first position), J), where a table suffices.
fn study_tradeoff(s: &Study, problem: &DesignProblem) -> Vec<(f64, f64, f64)> {
    let timing = s.timing.as_ref().unwrap();
    let e2e = problem.end_to_end(&s.positions_deg).unwrap();
    let tradeoff = e2e
        .noise()
        .tradeoff(&e2e_verify::TradeoffInputs {
            linear: &e2e.linearization(),
            lower_bounds_rad: &s.lower_bounds_rad,
            noise: &s.noise,
            timing,
            k_sigma: DEFAULT_K_SIGMA,
            dwell_range_s: (f64::MIN_POSITIVE, 86_400.0),
        })
        .unwrap();
    tradeoff
        .points()
        .iter()
        .filter_map(|p| {
            p.objective()
                .map(|j| (p.dwell_s(), p.total_s() + timing.move_s(), j))
        })
        .collect()
}

/// Checks that every point of `listed` is on `d`'s front for the study's positions (same
/// total and J to rounding) or dominated by a front point (no longer, no costlier); the
/// number on the front.
fn on_front_or_dominated(s: &Study, d: &BudgetDesign, listed: &[(f64, f64, f64)]) -> usize {
    let same_schedule = |q: &[Vec<f64>]| {
        let key = |v: &[Vec<f64>]| {
            let mut v = v.to_vec();
            v.sort_by(|a, b| a.partial_cmp(b).unwrap());
            v
        };
        key(q) == key(&s.positions_deg)
    };
    let mut on_front = 0;
    for &(dwell, total, j) in listed {
        let same = d.pareto().iter().find(|p| {
            same_schedule(p.positions_deg()) && (p.dwell_s() - dwell).abs() <= SAME_PATH_REL * dwell
        });
        if let Some(p) = same {
            assert_relative_eq!(p.total_s(), total, max_relative = SAME_PATH_REL);
            assert_relative_eq!(p.objective(), j, max_relative = SAME_PATH_REL);
            on_front += 1;
        } else {
            assert!(
                d.pareto()
                    .iter()
                    .any(|p| p.total_s() <= total * (1.0 + SAME_PATH_REL)
                        && p.objective() <= j * (1.0 + SAME_PATH_REL)),
                "end-to-end's point {dwell} s ({total} s, J {j}) is neither on the front nor dominated: {:?}",
                d.pareto()
                    .iter()
                    .map(|p| (p.total_s(), p.objective()))
                    .collect::<Vec<_>>()
            );
        }
    }
    on_front
}

/// The front never misses the study's own trade-off (issue 35 item 6: it missed the study's
/// own 24 x 12,246 s point): every point that `end-to-end` lists for the study's schedule is
/// on the budget's front with the budget's total and end-to-end's J, or a front point
/// dominates it. With the study's schedule alone (no other count, no noise-aware search) its
/// first listed point, just above its shortest dwell at which a table suffices and between
/// the grid's dwells, is the front's first (before, the front started at the next grid
/// dwell and missed it: this test failed). The front is sorted by total time with J strictly
/// falling and no point dominates another.
#[test]
fn the_front_holds_or_dominates_every_point_end_to_end_lists_for_the_study() {
    let (s, problem, table, study) = noisy_paper();
    let listed = study_tradeoff(&s, &problem);
    assert!(listed.len() >= 10, "{listed:?}");
    let study_idx = study.clone().expect("the study's positions are candidates");
    let mut alone = budget_of(&s, 25_000.0);
    alone.search_counts = false;
    alone.params.fixed_point_steps = 0;
    let d = design(&s, &problem, &study_idx, study.as_deref(), &alone).unwrap();
    assert!(
        on_front_or_dominated(&s, &d, &listed) >= 1,
        "{:?}",
        d.pareto()
    );
    let first = d.pareto().first().expect("a front");
    assert_relative_eq!(first.dwell_s(), listed[0].0, max_relative = SAME_PATH_REL);
    let b = budget_of(&s, 25_000.0);
    let d = design(&s, &problem, &table, study.as_deref(), &b).unwrap();
    on_front_or_dominated(&s, &d, &listed);
    for (i, p) in d.pareto().iter().enumerate() {
        if let Some(q) = d.pareto().get(i + 1) {
            assert!(q.total_s() > p.total_s() && q.objective() < p.objective());
        }
        assert!(
            d.pareto()
                .iter()
                .all(|q| q == p || !(q.total_s() <= p.total_s() && q.objective() <= p.objective()))
        );
    }
}

/// Every front point carries its tolerance box: the direct allocation with the noise part
/// kept free for its schedule at its dwell, per rotation error, as end-to-end allocates it
/// (same path, so equal to rounding), and the box's J is the point's J.
#[test]
fn every_front_point_carries_the_tolerance_box_end_to_end_allocates() {
    let (s, problem, table, study) = noisy_paper();
    let b = budget_of(&s, 25_000.0);
    let d = design(&s, &problem, &table, study.as_deref(), &b).unwrap();
    assert!(!d.pareto().is_empty());
    for p in d.pareto() {
        let (e2e, direct) = direct_at(&s, &problem, p.positions_deg(), p.dwell_s());
        let direct = direct.expect("a table suffices on the front");
        assert_eq!(p.tolerances_rad().len(), direct.upper_bounds_rad().len());
        for (a, e) in p.tolerances_rad().iter().zip(direct.upper_bounds_rad()) {
            assert_relative_eq!(*a, *e, max_relative = SAME_PATH_REL);
        }
        assert_relative_eq!(
            e2e.objective(p.tolerances_rad()),
            p.objective(),
            max_relative = SAME_PATH_REL
        );
    }
}

/// The budget design runs its counts, searches and evaluations in parallel with every
/// reduction in a fixed order: one thread and two give the same design, front, tolerances
/// and choice, bit for bit.
#[test]
fn one_thread_and_two_give_the_same_budget_design() {
    let (s, problem, table, study) = noisy_paper();
    let b = budget_of(&s, 25_000.0);
    let on = |threads: usize| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| design(&s, &problem, &table, study.as_deref(), &b).unwrap())
    };
    let one = on(1);
    let two = on(2);
    assert!(!one.pareto().is_empty());
    assert_eq!(one, two);
}
