//! The buyer's question for the paper's inputs: does a turntable built to Table 4 (or to the
//! two-step optimum) let me calibrate to 0.01 deg/h? And what do the direct and yield-based
//! allocations cost?
//!
//! Run with `cargo run --release -p e2e-verify --example buyers_question`.

use e2e_verify::{EndToEndInputs, answer, objective_to_arcmin};
use gw_model::units::rad_per_s_to_deg_per_h;
use std::time::Instant;
use tt_kinematics::units::RAD_PER_ARCMIN;

fn main() -> Result<(), e2e_verify::E2eError> {
    let inputs = EndToEndInputs::paper();
    let t0 = Instant::now();
    let a = answer(&inputs)?;
    let secs = t0.elapsed().as_secs_f64();
    println!(
        "omega_m = {} deg/h, {} turntables per box, seed {}",
        rad_per_s_to_deg_per_h(inputs.omega_m_rad_per_s),
        inputs.samples,
        inputs.seed
    );
    println!(
        "J (arcmin^-2): Table 4 {:.3}, two-step optimum {:.3}",
        objective_to_arcmin(a.table4_objective),
        objective_to_arcmin(a.two_step_objective)
    );
    for r in &a.readings {
        println!("\nreading {}", r.reading);
        for (name, b) in [
            ("table4", &r.table4),
            ("ours", &r.ours),
            ("direct", &r.direct_box),
            ("yield", &r.yield_box),
        ] {
            let [x, y] = b.worst_case.exact_deg_per_h();
            let [lx, ly] = b.worst_case.linear_deg_per_h();
            let (lo, hi) = b.distribution.yield_interval_95();
            println!(
                "  {name:7} worst x {x:.6} y {y:.6} (linear {lx:.6} {ly:.6}) deg/h, yield {:.5} [{lo:.5}, {hi:.5}], J {:.3}",
                b.distribution.yield_fraction(),
                objective_to_arcmin(b.objective)
            );
            println!(
                "          UB arcmin {:?}",
                b.upper_bounds_rad
                    .map(|u| (u / RAD_PER_ARCMIN * 1e4).round() / 1e4)
            );
        }
        println!(
            "  direct active rows: {:?}",
            r.direct
                .active_rows()
                .iter()
                .map(|l| (l.axis.name(), l.position))
                .collect::<Vec<_>>()
        );
        println!(
            "  yield: scale {:.4}, design yield {:.5} [{:.5}, {:.5}]",
            r.yield_based.scale,
            r.yield_based.yield_fraction(),
            r.yield_based.interval_95.0,
            r.yield_based.interval_95.1
        );
    }
    println!("\n{secs:.2} s");
    Ok(())
}
