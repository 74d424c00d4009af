//! Throughput: a 2 h, 400 Hz, 6-channel recording (17 million values) of the imu-triad study's
//! schedule, segmented, estimated and written, against reading the file alone (same run).
//!
//! `cargo bench -p calib-run --bench throughput [-- HOURS]` (default 2 h). The recording is
//! written once to `target/calib-run-bench-<hours>h.csv` (kept for later runs). Prints the
//! samples, the CPU (both threads of the reader) and wall seconds of each pass, the whole run's
//! ratio to reading alone (CPU and wall, measured in the same run), and the SHA-256 of the
//! calibration file written (its estimates' fingerprint: a speed-up leaves it unchanged).

use calib_run::recording::{RecordingOptions, read_rows};
use calib_run::simulate::{SimSettings, simulate_recording};
use calib_run::{CalibrateOptions, calibrate};
use std::io::{BufReader, BufWriter, Write};
use std::time::Instant;

/// This process's CPU time, s (wall time is unreliable on a shared machine).
fn cpu_s() -> f64 {
    let t = rustix::time::clock_gettime(rustix::time::ClockId::ProcessCPUTime);
    t.tv_sec as f64 + t.tv_nsec as f64 * 1e-9
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let hours: f64 = std::env::args()
        .skip(1)
        .find(|a| !a.starts_with('-'))
        .map_or(Ok(2.0), |a| a.parse())?;
    let root = concat!(env!("CARGO_MANIFEST_DIR"), "/..");
    let path = format!("{root}/studies/imu-triad-example.toml");
    let s = study::Study::parse(&path, &std::fs::read_to_string(&path)?)?;
    let rate_hz = 400.0;
    let n_pos = s.positions_deg.len() as f64;
    let move_s = 10.0;
    let dwell_s = hours * 3600.0 / n_pos - move_s;
    let file = format!("{root}/target/calib-run-bench-{hours}h.csv");
    if std::fs::metadata(&file).is_err() {
        let settings = SimSettings {
            move_s,
            ..SimSettings::for_study(&s, rate_hz, dwell_s, 1)
        };
        let tmp = format!("{file}.partial");
        let mut w = BufWriter::new(std::fs::File::create(&tmp)?);
        simulate_recording(&s, &s.sensor, &settings, &mut w)?;
        w.flush()?;
        std::fs::rename(&tmp, &file)?;
    }
    let bytes = std::fs::metadata(&file)?.len();
    let names: Vec<&str> = s.sensor.outputs().iter().map(|o| o.name.as_str()).collect();
    let joints = s.turntable.joint_names();
    // reading alone: the same reader, every cell parsed and checked, nothing else
    let t0 = Instant::now();
    let c0 = cpu_s();
    let mut sum = 0.0;
    let summary = read_rows(
        BufReader::new(std::fs::File::open(&file)?),
        &file,
        &names,
        &joints,
        &RecordingOptions::default(),
        |r| {
            sum += r.values[0];
            Ok(())
        },
    )?;
    let read_s = t0.elapsed().as_secs_f64();
    let read_cpu = cpu_s() - c0;
    // segmented, estimated and written
    let t1 = Instant::now();
    let c1 = cpu_s();
    let run = calibrate(
        &s,
        BufReader::new(std::fs::File::open(&file)?),
        &file,
        &CalibrateOptions::default(),
    )?;
    let out = format!(
        "{root}/target/calib-run-bench-{hours}h-{}.json",
        std::process::id()
    );
    calib_run::file::write_new(
        std::path::Path::new(&out),
        &calib_run::file::CalibrationFile::of(&run),
    )?;
    let full_s = t1.elapsed().as_secs_f64();
    let full_cpu = cpu_s() - c1;
    // the estimates' fingerprint: equal before and after a speed-up
    let written = calib_run::recording::sha256_hex(&std::fs::read(&out)?);
    std::fs::remove_file(&out)?;
    println!(
        "{} samples x {} outputs ({} values, {:.0} MB), {} segments: read alone {:.2} s CPU ({:.2} s wall), segmented + estimated + written {:.2} s CPU ({:.2} s wall), ratio to reading alone {:.2} CPU, {:.2} wall (checksum {sum:.3e}, calibration file sha256 {written})",
        summary.samples,
        names.len(),
        summary.samples * names.len() as u64,
        bytes as f64 / 1e6,
        run.segments().len(),
        read_cpu,
        read_s,
        full_cpu,
        full_s,
        full_cpu / read_cpu,
        full_s / read_s
    );
    Ok(())
}
