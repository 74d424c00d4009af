//! Shared set-up of the workspace's tests and examples, in one place instead of a file of one
//! crate included into another by `#[path]`. A dev-dependency only: no library crate and not
//! the `ttalloc` binary depends on it.
//!
//! - [`e2e`]: the paper's end-to-end simulator built from the paper modules, and the shipped
//!   example studies loaded through the study crate (e2e-verify's tests and examples,
//!   schedule-design's tests).
//! - [`json`]: a box of `end-to-end --json`'s readings by its name (tt-lab's and ttalloc's
//!   tests of the same answer).
//! - [`random`]: seeded uniform and normal draws of the noise tests' Monte Carlo (gw-model's
//!   and calib-lsq's tests).
//! - [`peak_kib`]: the peak resident memory of a command while it runs (the memory tests of
//!   `ttalloc` and of `cargo xtask fuzz`).
//! - [`output_within`]: a command's output, the test failed when it does not end in time (the
//!   inputs that must be refused at once).

pub mod e2e;
pub mod json;
pub mod random;

use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

/// The output of `cmd` (standard input empty, both outputs captured), killed and the test
/// failed when it does not end within `limit`. `what` names the run in that message.
///
/// # Panics
/// When the command cannot start, or runs longer than `limit`.
pub fn output_within(mut cmd: Command, limit: Duration, what: &str) -> Output {
    let mut child = cmd
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap_or_else(|e| panic!("{what}: {e}"));
    let start = Instant::now();
    while child.try_wait().expect("the command's status").is_none() {
        if start.elapsed() > limit {
            let _ = child.kill();
            let _ = child.wait();
            panic!("{what} still running after {} s", limit.as_secs_f64());
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    child.wait_with_output().expect("the command's output")
}

/// Peak resident set of `cmd` in KiB: the largest `VmHWM` of `/proc/<pid>/status` (Linux)
/// seen while polling every 5 ms. Standard output is discarded; standard error is kept for the
/// message. `what` names the run in that message.
///
/// # Panics
/// Unless the command starts and succeeds.
pub fn peak_kib(mut cmd: Command, what: &str) -> u64 {
    let mut child = cmd
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap_or_else(|e| panic!("{what}: {e}"));
    let status_path = format!("/proc/{}/status", child.id());
    let mut peak = 0;
    loop {
        if let Ok(text) = std::fs::read_to_string(&status_path) {
            if let Some(v) = text.lines().find_map(|l| l.strip_prefix("VmHWM:")) {
                peak = peak.max(
                    v.trim()
                        .trim_end_matches("kB")
                        .trim()
                        .parse::<u64>()
                        .unwrap_or(0),
                );
            }
        }
        if let Some(status) = child.try_wait().expect("the command's status") {
            let mut err = String::new();
            if let Some(mut e) = child.stderr.take() {
                std::io::Read::read_to_string(&mut e, &mut err).expect("its standard error");
            }
            assert!(status.success(), "{what}: {err}");
            return peak;
        }
        std::thread::sleep(Duration::from_millis(5));
    }
}
