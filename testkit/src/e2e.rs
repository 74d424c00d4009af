//! Shared set-up of the end-to-end tests: the paper's simulator built from the paper modules
//! (no file), and the shipped example studies loaded through the study crate.

use calib_lsq::{Calibration, Position, Reading, Schedule};
use e2e_verify::EndToEnd;
use std::path::Path;
use study::Study;
use tt_kinematics::{Pose, paper};

/// The paper's simulator: Table 3's turntable, eq 1 / Table 1's sensor, the paper's site and
/// schedule, under `reading`.
pub fn paper(reading: Reading) -> EndToEnd {
    let cal = Calibration::new(
        &gw_model::paper::gyrowheel(),
        &gw_model::paper::site(),
        &calib_lsq::paper::schedule(),
    )
    .expect("the paper's schedule identifies every coefficient");
    let poses = poses_of(&cal);
    EndToEnd::new(&paper::table3(), &cal, &poses, reading).expect("paper simulator")
}

/// The joint angles (deg) of the paper's schedule's positions.
pub fn paper_positions_deg() -> Vec<Vec<f64>> {
    calib_lsq::paper::schedule()
        .positions()
        .iter()
        .map(|p| p.joint_angles_deg().to_vec())
        .collect()
}

/// The paper's simulator (Table 3's turntable, the paper's sensor and site) on the schedule
/// of `positions_deg` (joint angles, deg), under `reading`.
pub fn paper_at(reading: Reading, positions_deg: &[Vec<f64>]) -> EndToEnd {
    let table = paper::table3();
    let poses: Vec<Pose> = positions_deg
        .iter()
        .map(|p| Pose::from_deg(p).expect("finite joint angles"))
        .collect();
    let positions = positions_deg
        .iter()
        .zip(&poses)
        .map(|(p, q)| {
            let rotation = table.nominal_rotation(q).expect("a pose of the table");
            Position::new(rotation, p.clone()).expect("finite")
        })
        .collect();
    let schedule = Schedule::new(positions).expect("positions");
    let cal = Calibration::new(
        &gw_model::paper::gyrowheel(),
        &gw_model::paper::site(),
        &schedule,
    )
    .expect("the schedule identifies every coefficient");
    EndToEnd::new(&table, &cal, &poses, reading).expect("paper simulator")
}

/// The turntable poses of a calibration's positions.
pub fn poses_of(cal: &Calibration) -> Vec<Pose> {
    cal.schedule()
        .positions()
        .iter()
        .map(|p| Pose::from_deg(p.joint_angles_deg()))
        .collect::<Result<_, _>>()
        .expect("finite joint angles")
}

/// A shipped study (`studies/<name>.toml`).
pub fn study(name: &str) -> Study {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../studies")
        .join(format!("{name}.toml"));
    Study::load(&path).unwrap_or_else(|e| panic!("{name}: {e}"))
}

/// The simulator of a shipped study under `reading` (`None`: the study's reading).
pub fn study_e2e(name: &str, reading: Option<Reading>) -> EndToEnd {
    let s = study(name);
    let poses = poses_of(&s.calibration);
    EndToEnd::new(
        &s.turntable,
        &s.calibration,
        &poses,
        reading.unwrap_or(s.reading),
    )
    .expect("study simulator")
}

/// The IMU example (`studies/imu-triad-example.toml`) without its own specifications, with
/// `extra` (TOML tables) appended.
pub fn imu_study_with(extra: &str) -> Study {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../studies/imu-triad-example.toml");
    let text = std::fs::read_to_string(&path).expect("the IMU example");
    let bare = &text[..text
        .find("# Specifications per calibrated quantity")
        .expect("the IMU example's specifications")];
    Study::parse("imu.toml", &format!("{bare}\n{extra}")).expect("a valid study")
}

/// The simulator of a study under its own reading.
pub fn simulator_of(s: &Study) -> EndToEnd {
    let poses = poses_of(&s.calibration);
    EndToEnd::new(&s.turntable, &s.calibration, &poses, s.reading).expect("study simulator")
}

/// The largest |value| of any term of the sensor (output unit per regressor unit): the scale
/// of the outputs, against which rounding is measured.
pub fn output_scale(e2e: &EndToEnd) -> f64 {
    e2e.calibration()
        .sensor()
        .outputs()
        .iter()
        .flat_map(|o| o.terms.iter().map(|t| t.value.abs()))
        .fold(1.0, f64::max)
}

/// `f` run on a rayon pool of `threads` threads: the "same answer for any thread count"
/// tests.
pub fn on_threads<T: Send>(threads: usize, f: impl FnOnce() -> T + Send) -> T {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .expect("a thread pool")
        .install(f)
}

/// Errors drawn uniformly in `[-ub, ub]` (component-wise) from a seeded stream.
pub fn random_chi(rng: &mut rand_chacha::ChaCha8Rng, ub: &[f64]) -> Vec<f64> {
    use rand_core::Rng;
    ub.iter()
        .map(|u| {
            let v = f64::from(rng.next_u32()) / f64::from(u32::MAX);
            (2.0 * v - 1.0) * u
        })
        .collect()
}
