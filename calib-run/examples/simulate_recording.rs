//! Write a simulated recording of a study's schedule (the study's coefficients as truth, its
//! white noise, a perfect table) to try the loop plan -> run -> calibrate:
//!
//! `cargo run -p calib-run --example simulate_recording -- STUDY.toml OUT.csv [RATE_HZ] [DWELL_S] [SEED]`
//!
//! OUT.csv must not exist.

use calib_run::simulate::{SimSettings, simulate_recording};
use std::io::Write;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    if args.len() < 3 {
        return Err(
            "usage: simulate_recording STUDY.toml OUT.csv [RATE_HZ] [DWELL_S] [SEED]".into(),
        );
    }
    let text = std::fs::read_to_string(&args[1])?;
    let s = study::Study::parse(&args[1], &text)?;
    let num = |i: usize, d: f64| args.get(i).map_or(Ok(d), |v| v.parse::<f64>());
    let settings = SimSettings {
        sample_rate_hz: num(3, 100.0)?,
        dwell_s: num(4, 20.0)?,
        move_s: 2.0,
        rest_s: 3.0,
        rotation_s: 8.0,
        white_per_sqrt_hz: s
            .noise
            .iter()
            .map(|n| {
                n.as_ref()
                    .map_or(0.0, gw_model::noise::NoiseModel::white_per_sqrt_hz)
            })
            .collect(),
        table_errors_rad: None,
        log_angles: false,
        seed: num(5, 1.0)? as u64,
        repeats: 1,
    };
    let f = std::fs::OpenOptions::new()
        .write(true)
        .create_new(true)
        .open(&args[2])?;
    let mut w = std::io::BufWriter::new(f);
    let n = simulate_recording(&s, &s.sensor, &settings, &mut w)?;
    w.flush()?;
    eprintln!("{n} samples written to {}", args[2]);
    Ok(())
}
