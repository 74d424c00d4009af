//! `browser-check REPORT.html [--out DIR] [--width W] [--height H] [--timeout SECS] [--json]`
//!
//! Opens the report in headless Chromium, prints what it found and the
//! problems, and exits 1 when there are problems (2 on an error).

use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Duration;

use browser_check::{CheckOptions, check_report_with};

fn main() -> ExitCode {
    let mut args = std::env::args().skip(1);
    let mut html = None;
    let mut opts = CheckOptions::default();
    let mut json = false;
    while let Some(a) = args.next() {
        let mut value = |name: &str| {
            args.next()
                .unwrap_or_else(|| panic!("{name} needs a value"))
        };
        match a.as_str() {
            "--out" => opts.screenshot_dir = PathBuf::from(value("--out")),
            "--width" => opts.width = value("--width").parse().expect("--width: a number"),
            "--height" => opts.height = value("--height").parse().expect("--height: a number"),
            "--timeout" => {
                opts.timeout =
                    Duration::from_secs(value("--timeout").parse().expect("--timeout: seconds"))
            }
            "--json" => json = true,
            "-h" | "--help" => {
                println!(
                    "browser-check REPORT.html [--out DIR] [--width W] [--height H] [--timeout SECS] [--json]"
                );
                return ExitCode::SUCCESS;
            }
            _ => html = Some(PathBuf::from(a)),
        }
    }
    let Some(html) = html else {
        eprintln!(
            "usage: browser-check REPORT.html [--out DIR] [--width W] [--height H] [--timeout SECS] [--json]"
        );
        return ExitCode::from(2);
    };
    match check_report_with(&html, &opts) {
        Ok(report) => {
            if json {
                println!(
                    "{}",
                    serde_json::to_string_pretty(&report).expect("serializable")
                );
            } else {
                println!(
                    "{} in {} ({:.1} s)",
                    report.url,
                    report.browser,
                    report.elapsed.as_secs_f64()
                );
                println!(
                    "window {}x{}: inner width {}, client width {}, page {}x{}",
                    report.window.0,
                    report.window.1,
                    report.inner_width,
                    report.client_width,
                    report.scroll_width,
                    report.scroll_height
                );
                println!(
                    "{} images, {} inline svg, {} internal links, {} console messages",
                    report.images.len(),
                    report.inline_svgs,
                    report.links.len(),
                    report.console.len()
                );
                println!(
                    "screenshots: {} {}",
                    report.screenshots.viewport.display(),
                    report.screenshots.full_page.display()
                );
            }
            let problems = report.problems();
            for p in &problems {
                eprintln!("problem: {p}");
            }
            if problems.is_empty() {
                ExitCode::SUCCESS
            } else {
                ExitCode::from(1)
            }
        }
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::from(2)
        }
    }
}
