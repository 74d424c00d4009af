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
    let settings = SimSettings::for_study(&s, num(3, 100.0)?, num(4, 20.0)?, num(5, 1.0)? as u64);
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
