//! The paper's Monte Carlo check (§4.3, Figure 9) of its allocation (Table 4), with 10^6
//! turntables instead of 10^4: extremes, worst samples, spread and the fraction inside the
//! requirement of eq 16.
//!
//! Run: `cargo run --release -p mc-verify --example figure9`.

use mc_verify::{ErrorBox, McConfig, MonteCarlo};
use tt_kinematics::units::{rad_to_arcmin, rad_to_deg};

/// Table 4 of the paper, arcmin, in the order of chi (eq 25).
const TABLE4_ARCMIN: [f64; 8] = [
    0.4235, 0.7800, 0.4234, 0.7800, 0.2825, 0.2824, 0.4234, 0.4233,
];

fn main() -> Result<(), mc_verify::McError> {
    let bounds = ErrorBox::from_arcmin([0.0; 8], TABLE4_ARCMIN)?;
    let mc = MonteCarlo::new(bounds, McConfig::new(1_000_000, 2017))?;
    let t = std::time::Instant::now();
    let r = mc.run();
    let seconds = t.elapsed().as_secs_f64();
    println!(
        "{} samples (seed {}) in {seconds:.3} s: {:.3e} samples/s",
        r.samples,
        r.seed,
        r.samples as f64 / seconds
    );
    let std = r.std_rad();
    for (a, sd) in r.axes.iter().zip(std) {
        println!(
            "{:>6}: max |.| = {:.6} deg, mean = {:+.2e} deg, std = {:.6} deg; worst sample #{} at phi2 = {:.2} deg, chi = {:.4?} arcmin",
            a.axis.name(),
            rad_to_deg(a.max_abs_rad),
            rad_to_deg(a.mean_rad),
            rad_to_deg(sd),
            a.worst.index,
            rad_to_deg(a.worst.pose.phi2_rad),
            a.worst.chi_rad.map(rad_to_arcmin),
        );
    }
    println!(
        "inside |angle| <= 0.027 deg (eq 16): {:.6} of the samples",
        r.within_requirement_fraction()
    );
    Ok(())
}
