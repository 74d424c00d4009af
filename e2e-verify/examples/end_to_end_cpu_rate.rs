//! Turntables per CPU-second of the end-to-end Monte Carlo on one thread, per reading of
//! eq 13, for the paper's study: the thread's own CPU time (`/proc/thread-self/schedstat`,
//! Linux), so the figure holds on a loaded host where wall-clock rates do not. Prints
//! nothing where that file is absent.
//!
//! Run: `cargo run --release -p e2e-verify --example end_to_end_cpu_rate [samples] [rounds]
//! [reading]` (a reading such as `actual/beta1/printed` measures that one only, e.g. to
//! profile it).

use calib_lsq::Reading;
use e2e_verify::McSettings;

/// The paper's simulator, shared with the tests.
use testkit::e2e as common;

/// CPU time of the calling thread, seconds.
fn thread_cpu_s() -> Option<f64> {
    let s = std::fs::read_to_string("/proc/thread-self/schedstat").ok()?;
    let ns: f64 = s.split_whitespace().next()?.parse().ok()?;
    Some(ns * 1e-9)
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let n: u64 = args.next().and_then(|a| a.parse().ok()).unwrap_or(200_000);
    let rounds: usize = args.next().and_then(|a| a.parse().ok()).unwrap_or(3);
    let one = rayon::ThreadPoolBuilder::new().num_threads(1).build()?;
    let only: Option<Reading> = args.next().map(|r| r.parse()).transpose()?;
    for reading in [Reading::PAPER, Reading::USER] {
        if only.is_some_and(|o| o != reading) {
            continue;
        }
        let e2e = common::paper(reading);
        let linear = e2e.linearization();
        let bounds = e2e.box_of(&alloc_opt::paper::table4_rad(), &[0.0; 8])?;
        let mut best = 0.0f64;
        for _ in 0..rounds {
            let rate = one.install(|| -> Result<Option<f64>, e2e_verify::E2eError> {
                let t0 = thread_cpu_s();
                e2e.monte_carlo()
                    .rate_distribution(&linear, &bounds, &McSettings::new(n, 2017))?;
                Ok(t0.zip(thread_cpu_s()).map(|(a, b)| n as f64 / (b - a)))
            })?;
            if let Some(r) = rate {
                best = best.max(r);
            }
        }
        println!("{reading}: {best:.3e} turntables per CPU-second (one thread, best of {rounds})");
    }
    Ok(())
}
