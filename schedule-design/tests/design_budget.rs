//! Positions and dwell chosen together under a total test-time budget (issue 21 item 4):
//! the Pareto front is monotone, every point is end-to-end's J for its schedule and dwell,
//! the chosen point is within the budget and bad budgets are refused naming the field.

mod common;

use approx::assert_relative_eq;
use calib_lsq::Timing;
use e2e_verify::E2eError;
use e2e_verify::noise::DEFAULT_K_SIGMA;
use schedule_design::{
    BudgetPoint, DesignProblem, ScheduleOrigin, TimeBudget, candidates_with, design_with_budget,
    grid_positions_deg, pareto_front, total_test_s,
};
use study::Study;

/// Relative agreement of a front point's J with end-to-end's allocation for the same schedule
/// and dwell (dimensionless): the same path from the same positions, so only rounding of the
/// same operations may differ.
const SAME_PATH_REL: f64 = 1e-9;

/// The paper's noisy copy on a 45 deg grid (64 candidates and the study's positions), with a
/// table design of the study's size by the greedy construction and the exchange.
fn noisy_paper() -> (Study, DesignProblem, Vec<usize>, Option<Vec<usize>>) {
    let s = common::study("gyrowheel-2017-noise-assumed");
    let problem = DesignProblem::new(
        &s.turntable,
        &s.sensor,
        &s.site,
        s.reading,
        &s.lower_bounds_rad,
        candidates_with(
            grid_positions_deg(&s.turntable, 45.0).unwrap(),
            &s.positions_deg,
        ),
    )
    .unwrap();
    let n = s.positions_deg.len();
    let start = problem.greedy(n, 10.0).unwrap();
    let table = problem
        .exchange(&start.schedule, 10.0)
        .unwrap()
        .evaluation
        .schedule;
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
    }
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
    let d = design_with_budget(
        &problem,
        &table,
        study.as_deref(),
        &s.positions_deg,
        &[],
        10.0,
        &b,
    )
    .unwrap();
    assert!(d.pareto.len() >= 3, "{:?}", d.pareto);
    for w in d.pareto.windows(2) {
        assert!(w[1].total_s > w[0].total_s, "{w:?}");
        assert!(w[1].objective < w[0].objective, "{w:?}");
    }
    let timing = s.timing.as_ref().unwrap();
    for p in &d.pareto {
        assert_relative_eq!(
            p.total_s,
            total_test_s(p.n_positions(), p.dwell_s, timing.move_s()),
            max_relative = 1e-15
        );
        let e2e = problem.end_to_end(&p.positions_deg).unwrap();
        let noise = e2e
            .noise_budget(
                &s.noise,
                &Timing::uniform(
                    p.n_positions(),
                    p.dwell_s,
                    timing.move_s(),
                    timing.sample_rate_hz(),
                )
                .unwrap(),
            )
            .unwrap();
        let j = e2e
            .allocate_direct_with_noise(
                &e2e.linearization(),
                &s.lower_bounds_rad,
                &noise,
                DEFAULT_K_SIGMA,
            )
            .unwrap()
            .expect("a table suffices on the front")
            .objective;
        assert_relative_eq!(p.objective, j, max_relative = SAME_PATH_REL);
    }
    let chosen = d
        .chosen
        .as_ref()
        .expect("a table suffices within the budget");
    assert!(chosen.total_s <= budget_s);
    // nothing on the front within the budget is cheaper, and the next point is over it
    let i = d.pareto.iter().position(|p| p == chosen).unwrap();
    assert!(d.pareto[..i].iter().all(|p| p.objective > chosen.objective));
    if let Some(next) = d.pareto.get(i + 1) {
        assert!(next.total_s > budget_s);
    }
    // the study's and the table's schedules are among those evaluated
    assert!(d.schedules.iter().any(|(o, _)| *o == ScheduleOrigin::Table));
    assert!(
        d.schedules
            .iter()
            .any(|(_, p)| p.as_slice() == s.positions_deg.as_slice())
    );
}

/// A budget below the shortest test at which any table suffices chooses nothing; the front
/// is unchanged by the budget (it depends on the budget only through the dwells added).
#[test]
fn a_budget_too_short_for_any_table_chooses_nothing() {
    let (s, problem, table, study) = noisy_paper();
    let b = budget_of(&s, 60.0);
    let d = design_with_budget(
        &problem,
        &table,
        study.as_deref(),
        &s.positions_deg,
        &[],
        10.0,
        &b,
    )
    .unwrap();
    assert!(d.chosen.is_none());
    assert!(d.pareto.first().is_some_and(|p| p.total_s > 60.0));
}

/// The front keeps exactly the undominated points: ordered by total time, each strictly
/// cheaper than every point before it (a point with more time and no lower J is dropped, and
/// so is a point without a table).
#[test]
fn pareto_front_drops_dominated_points() {
    let p = |total_s: f64, objective: f64| BudgetPoint {
        origin: ScheduleOrigin::Table,
        positions_deg: vec![vec![0.0]],
        dwell_s: total_s,
        total_s,
        objective,
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
    let got: Vec<(f64, f64)> = front.iter().map(|q| (q.total_s, q.objective)).collect();
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
        let e = design_with_budget(
            &problem,
            &table,
            study.as_deref(),
            &s.positions_deg,
            &[],
            10.0,
            &b,
        )
        .unwrap_err();
        assert!(matches!(e, E2eError::Field(_)), "{e:?}");
        assert!(e.to_string().contains(field), "{e}");
    }
    let mut b = budget_of(&s, 1000.0);
    b.sample_rate_hz = 0.0;
    let e = design_with_budget(
        &problem,
        &table,
        study.as_deref(),
        &s.positions_deg,
        &[],
        10.0,
        &b,
    )
    .unwrap_err();
    assert!(e.to_string().contains("sample_rate_hz"), "{e}");
}
