//! `ttalloc`: how accurate must a turntable be so that the sensor calibrated on it meets its
//! accuracy? See `ttalloc --help` and the workspace README.

use std::process::ExitCode;

fn main() -> ExitCode {
    ttalloc::run(std::env::args_os(), "ttalloc")
}
