//! The paper's Monte Carlo check (§4.3, Figure 9) of its allocation (Table 4), with 10^6
//! turntables instead of 10^4: extremes with their worst samples, spread, the fraction inside
//! the requirement of eq 16, and the maxima against the certified worst case (first-order
//! worst case over the poses, and the rigorous bound with the remainder term).
//!
//! Run: `cargo run --release -p mc-verify --example figure9 [-- SAMPLES]`.

use mc_verify::{ErrorBox, McConfig, MonteCarlo};
use tt_core::units::{rad_to_arcmin, rad_to_deg};
use tt_kinematics::{LinearModel, OrientationAxis, paper};

/// Table 4 of the paper, arcmin, in the order of chi (eq 25).
const TABLE4_ARCMIN: [f64; 8] = [
    0.4235, 0.7800, 0.4234, 0.7800, 0.2825, 0.2824, 0.4234, 0.4233,
];

/// The requirement of eq 16, deg.
const EQ16_DEG: f64 = 0.027;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let samples = std::env::args()
        .nth(1)
        .and_then(|s| s.parse::<f64>().ok())
        .map_or(1_000_000, |v| v as u64);
    let table = paper::table3();
    let bounds = ErrorBox::from_arcmin(&table, vec![0.0; 8], TABLE4_ARCMIN.to_vec())?;
    let req = tt_core::Requirement::from_options([Some(EQ16_DEG.to_radians()); 3])?;
    let mc = MonteCarlo::new(&table, bounds, McConfig::new(samples, 2017, req))?;
    let t = std::time::Instant::now();
    let r = mc.run();
    let seconds = t.elapsed().as_secs_f64();
    println!(
        "{} samples (seed {}, tier {}) in {seconds:.3} s: {:.3e} samples/s",
        r.count().samples(),
        r.count().seed(),
        mc.tier().name(),
        r.count().samples() as f64 / seconds
    );
    let model = LinearModel::new(&table);
    let bound = mc.half_range_rad();
    let std = r.std_rad();
    for ((a, sd), h) in r.axes().iter().zip(std).zip(bound) {
        let worst = model.worst_pose_certified(a.axis(), mc.bounds().ub_rad(), true, None)?;
        println!(
            "{:>6}: max |.| = {:.6} deg = {:.4} of the linear worst case {:.6} deg (rigorous bound {:.6} deg, eq 16: {EQ16_DEG}), mean = {:+.2e} deg, std = {:.6} deg",
            a.axis().name(),
            rad_to_deg(a.max_abs_rad()),
            a.max_abs_rad() / worst.value(),
            rad_to_deg(worst.value()),
            rad_to_deg(h),
            rad_to_deg(a.mean_rad()),
            rad_to_deg(sd),
        );
        println!(
            "        worst sample #{} at pose {:.2?} deg, chi = {:.4?} arcmin",
            a.worst().index(),
            a.worst().pose().angles_deg(),
            a.worst()
                .chi_rad()
                .iter()
                .map(|&x| rad_to_arcmin(x))
                .collect::<Vec<_>>(),
        );
    }
    println!(
        "inside |angle| <= {EQ16_DEG} deg (eq 16): {:.6} of the samples; theta's linear worst case uses {:.1} % of it",
        r.count().fraction(),
        100.0
            * rad_to_deg(
                model
                    .worst_pose_certified(OrientationAxis::Theta, mc.bounds().ub_rad(), true, None)?
                    .value()
            )
            / EQ16_DEG
    );
    Ok(())
}
