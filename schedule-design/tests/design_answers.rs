//! What the schedule designer recommends: tolerances certified on the exact chain (they pass
//! the vendor check on the designed schedule), a worst case with the study's tolerances that
//! says what it is and is a number wherever one exists, and grid designs that are never worse
//! than the design of a coarser grid they contain.

use calib_lsq::Reading;
use e2e_verify::{EndToEnd, McSettings, Verdict};
use schedule_design::{
    DesignInputs, DesignSettings, ScheduleReport, StudyTolerances, design_on_grid,
};
use tt_core::DeltaRKind;
use tt_kinematics::paper;

/// Relative slack on comparing two objectives J found by searches on nested candidate sets
/// (dimensionless): the fine search evaluates the coarse optimum's positions again, which
/// may differ from the coarse grid's by rounding of the grid angles (at most 1e-9 deg).
const NESTED_J_REL: f64 = 1e-9;

fn paper_positions() -> Vec<Vec<f64>> {
    testkit::e2e::paper_positions_deg()
}

/// The designed schedule's simulator (same table, sensor, site and reading as the design).
fn simulator(positions_deg: &[Vec<f64>], reading: Reading) -> EndToEnd {
    testkit::e2e::paper_at(reading, positions_deg)
}

fn design(reading: Reading, step_deg: f64) -> schedule_design::ScheduleDesign {
    let table = paper::table3();
    let sensor = gw_model::paper::gyrowheel();
    let site = gw_model::paper::site();
    let study = paper_positions();
    let inputs = DesignInputs {
        turntable: &table,
        sensor: &sensor,
        site: &site,
        reading,
        delta_r_kind: DeltaRKind::SmallAngle,
        lower_bounds_rad: &[0.0; 8],
        study_positions_deg: &study,
        specifications: None,
    };
    design_on_grid(&inputs, step_deg, &DesignSettings::new(32, 2017), &|| {})
        .unwrap()
        .1
}

/// The vendor check of a schedule's recommended (certified) tolerances on that schedule.
fn check_certified(r: &ScheduleReport, reading: Reading) -> e2e_verify::TurntableCheck {
    let e2e = simulator(r.positions_deg(), reading);
    let ub = &r.certified().expect("certified").upper_bounds_rad();
    e2e.vendor()
        .check_tolerances(
            &e2e.linearization(),
            ub,
            &[0.0; 8],
            &McSettings::new(2_000, 2017),
        )
        .unwrap()
}

/// Issue 19: design-schedule's tolerances were the linearised direct allocation, whose worst
/// turntable misses the accuracy on the exact chain (0.0100436 deg/h > 0.01 for the designed
/// schedule of the paper's study, 0.0100025 for the study's own). The certified allocation of
/// each schedule is what it recommends now: every output of both schedules is proven to meet
/// its accuracy by the vendor check, and it costs more than the linearised one.
#[test]
fn recommended_tolerances_are_certified_and_pass_the_vendor_check() {
    let d = design(Reading::PAPER, 15.0);
    for (what, r) in [("designed", &d.designed()), ("study", &d.study())] {
        let c = r
            .certified()
            .expect("certifiable under the paper's reading");
        assert!(c.objective() > r.allocation().objective(), "{what}");
        let check = check_certified(r, Reading::PAPER);
        for o in check.outputs() {
            assert_eq!(
                o.verdict(),
                Verdict::Guaranteed,
                "{what} output {}",
                o.output()
            );
            assert!(o.worst_case().exact_at_vertex() <= o.accuracy());
        }
        assert_eq!(check.verdict(), Verdict::Guaranteed, "{what}");
    }
    // the linearised allocation of the designed schedule is what failed the check
    let e2e = simulator(d.designed().positions_deg(), Reading::PAPER);
    let lin = e2e.linearization();
    let wc = e2e
        .worst_case(&lin, d.designed().allocation().upper_bounds_rad())
        .unwrap();
    assert!(
        wc.outputs()
            .iter()
            .any(|o| o.exact_at_vertex() > o.linear_bound()),
        "the exact chain exceeds the linearised worst case somewhere"
    );
}

/// Issue 19: the "worst case with today's table" column read "unbounded" for every schedule.
/// It is the worst case over the study schedule's certified tolerances; an error those leave
/// free makes only the outputs that depend on it unbounded, every other output keeps a number.
#[test]
fn worst_case_with_study_tolerances_is_a_number_wherever_one_exists() {
    let d = design(Reading::PAPER, 30.0);
    for r in [&d.designed(), &d.study(), &d.d_optimal()] {
        let w = &r.with_study_tolerances();
        assert!(w.certified());
        assert!(w.unbounded().is_empty());
        assert!(w.outputs().iter().all(|o| {
            o.as_ref()
                .is_some_and(|o| o.exact_at_vertex().is_finite() && o.exact_at_vertex() > 0.0)
        }));
    }
    // the study's own schedule over its own certified tolerances meets every accuracy
    for o in d.study().with_study_tolerances().outputs().iter().flatten() {
        assert!(o.certified_bound().unwrap() <= 0.01);
    }
    // leave each error free in turn: exactly the outputs that depend on it lose their number
    let e2e = simulator(d.designed().positions_deg(), Reading::PAPER);
    let lin = e2e.linearization();
    let base = d.study().certified().unwrap().upper_bounds_rad().to_vec();
    let small = 1e-12 * lin.matrix().amax();
    for j in 0..8 {
        let mut ub = base.clone();
        ub[j] = f64::INFINITY;
        let w = StudyTolerances::new(ub, true)
            .worst_case(&e2e, &lin)
            .unwrap();
        assert_eq!(w.unbounded(), vec![j]);
        for (k, o) in w.outputs().iter().enumerate() {
            let reached = (0..lin.positions()).any(|i| lin.row(k, i)[j].abs() > small);
            assert_eq!(o.is_none(), reached, "error {j}, output {k}");
        }
    }
}

/// Issue 19: on the 15 deg grid the design found J = 42.03 arcmin^-2 where the 30 deg grid (a
/// subset) found 37.96 (reading actual/beta1/printed). Every coarser grid a fine grid
/// contains now starts the fine search, designed exactly as on its own, so the finer grid is
/// never worse: 15 deg against 30 and 45 deg.
#[test]
fn a_finer_grid_is_never_worse_than_a_coarser_grid_it_contains() {
    let j: Vec<(f64, f64)> = [15.0, 30.0, 45.0]
        .iter()
        .map(|&s| {
            (
                s,
                design(Reading::USER, s).designed().allocation().objective(),
            )
        })
        .collect();
    for &(fine, jf) in &j {
        for &(coarse, jc) in &j {
            let contains = coarse > fine && (coarse / fine).fract() == 0.0;
            if contains {
                assert!(
                    jf <= jc * (1.0 + NESTED_J_REL),
                    "{fine} deg: J {jf} > {coarse} deg: J {jc}"
                );
            }
        }
    }
}
