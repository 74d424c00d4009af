//! Throughput of the Monte Carlo core against its baselines, measured in one run:
//! interleaved rounds (every contender timed once per round, in turn, on the same samples)
//! and the best rate of each over the rounds, so that load from other jobs on a shared
//! machine hits both sides of a ratio alike.
//!
//! Contenders (one thread by default):
//! - the paper's table (Table 3, Table 4 bounds, LB = 0) through the general plan
//!   (`MonteCarlo::run`), through the kept specialised kernel
//!   (`mc_verify::baseline::paper_kernel_run`), and its generator alone (`draw_only`: words
//!   and their decoding) and raw words (`draw_words_only`);
//! - a three-axis table (13 angular errors, 3 joints; bounds 0.3-0.6 arcmin, LB = 0) through
//!   the general plan, and its generator alone and raw words;
//! - both tables through the general plan on every SIMD level of the CPU.
//!
//! Two clocks: wall time (best of the rounds) and, with one thread on Linux, the CPU time of
//! the worker thread (`/proc/thread-self/schedstat`), which time slices given to other jobs
//! do not inflate. That counter advances in scheduler ticks (4 ms on the project's machine),
//! too coarse for one timing, so the CPU-time rates are totals over all rounds (samples over
//! CPU time), not the best round. The README quotes both.
//!
//! Run: `cargo run --release -p mc-verify --example throughput [-- SAMPLES ROUNDS THREADS]`
//! (defaults 2^22, 15, 1).

use mc_verify::baseline::paper_kernel_run_with_simd;
use mc_verify::{ErrorBox, McConfig, MonteCarlo, SimdLevel};
use std::time::Instant;
use tt_kinematics::paper;

/// Table 4 of the paper, arcmin (order of eq 25).
const TABLE4_ARCMIN: [f64; 8] = [
    0.4235, 0.7800, 0.4234, 0.7800, 0.2825, 0.2824, 0.4234, 0.4233,
];

/// The paper's requirement, eq 16, deg.
const EQ16_DEG: f64 = 0.027;

/// CPU time of the calling thread, ns (Linux; `None` elsewhere).
fn thread_cpu_ns() -> Option<u64> {
    let s = std::fs::read_to_string("/proc/thread-self/schedstat").ok()?;
    s.split_whitespace().next()?.parse().ok()
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let arg = |i: usize, default: u64| -> u64 {
        args.get(i)
            .and_then(|s| s.replace('_', "").parse::<f64>().ok())
            .map_or(default, |v| v as u64)
    };
    let samples = arg(0, 1 << 22);
    let rounds = arg(1, 15) as usize;
    let threads = arg(2, 1) as usize;
    let req = tt_core::Requirement::from_options([Some(EQ16_DEG.to_radians()); 3])?;

    let paper_table = paper::table3();
    let paper_box = ErrorBox::from_arcmin(&paper_table, vec![0.0; 8], TABLE4_ARCMIN.to_vec())?;
    let paper_mc = MonteCarlo::new(&paper_table, paper_box, McConfig::new(samples, 2017, req))?;
    let three = tt_kinematics::conformance::three_axis();
    let ub: Vec<f64> = (0..13).map(|i| 0.3 + 0.025 * f64::from(i)).collect();
    let three_box = ErrorBox::from_arcmin(&three, vec![0.0; 13], ub)?;
    let three_mc = MonteCarlo::new(&three, three_box, McConfig::new(samples, 2017, req))?;

    let (paper_mc, three_mc) = (&paper_mc, &three_mc);
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()?;
    let detected = SimdLevel::detected();
    type Job<'a> = Box<dyn Fn() -> u64 + Sync + 'a>;
    let mut jobs: Vec<(String, Job<'_>)> = vec![
        (
            "paper: general plan".into(),
            Box::new(|| paper_mc.run().count().samples()),
        ),
        (
            "paper: specialised kernel".into(),
            Box::new(|| {
                paper_kernel_run_with_simd(paper_mc, detected)
                    .expect("the paper's table")
                    .count()
                    .samples()
            }),
        ),
        (
            "paper: generator alone".into(),
            Box::new(|| paper_mc.draw_only()),
        ),
        (
            "paper: raw words".into(),
            Box::new(|| paper_mc.draw_words_only()),
        ),
        (
            "three-axis: general plan".into(),
            Box::new(|| three_mc.run().count().samples()),
        ),
        (
            "three-axis: generator alone".into(),
            Box::new(|| three_mc.draw_only()),
        ),
        (
            "three-axis: raw words".into(),
            Box::new(|| three_mc.draw_words_only()),
        ),
    ];
    for level in SimdLevel::available() {
        if level != detected {
            jobs.push((
                format!("paper: general plan, {}", level.name()),
                Box::new(move || {
                    paper_mc
                        .run_with_simd(level)
                        .map_or(0, |r| r.count().samples())
                }),
            ));
            jobs.push((
                format!("three-axis: general plan, {}", level.name()),
                Box::new(move || {
                    three_mc
                        .run_with_simd(level)
                        .map_or(0, |r| r.count().samples())
                }),
            ));
        }
    }
    let mut best = vec![0.0_f64; jobs.len()];
    // totals over the rounds: samples and CPU ns
    let mut cpu_total = vec![(0u64, 0u64); jobs.len()];
    println!(
        "{samples} samples per timing, {rounds} interleaved rounds, {threads} thread(s), SIMD level {}",
        detected.name()
    );
    for round in 0..rounds {
        let mut line = Vec::new();
        for (((_, job), b), total) in jobs.iter().zip(&mut best).zip(&mut cpu_total) {
            let t = Instant::now();
            let (n, cpu_ns) = pool.install(|| {
                let c0 = thread_cpu_ns();
                let n = job();
                (n, thread_cpu_ns().zip(c0).map(|(c1, c0)| c1 - c0))
            });
            let rate = n as f64 / t.elapsed().as_secs_f64();
            *b = b.max(rate);
            if let (Some(ns), 1) = (cpu_ns, threads) {
                total.0 += n;
                total.1 += ns;
            }
            line.push(format!("{rate:.3e}"));
        }
        println!("round {}: {}", round + 1, line.join(" "));
    }
    report("wall clock, best round", &jobs, &best);
    if cpu_total.iter().all(|&(_, ns)| ns > 0) {
        let rates: Vec<f64> = cpu_total
            .iter()
            .map(|&(n, ns)| n as f64 / (ns as f64 * 1e-9))
            .collect();
        report("thread CPU time, all rounds", &jobs, &rates);
    }
    Ok(())
}

fn report<T>(clock: &str, jobs: &[(String, T)], best: &[f64]) {
    println!("{clock}: rates (samples/s):");
    for ((name, _), b) in jobs.iter().zip(best) {
        println!("  {name:<36} {b:.4e}");
    }
    println!("{clock}: ratios:");
    // (what, numerator job, denominator job, goal if any)
    for (what, num, den, goal) in [
        ("paper general / specialised kernel:", 0, 1, Some(0.90)),
        (
            "three-axis general / its generator alone:",
            4,
            5,
            Some(0.35),
        ),
        ("three-axis general / its raw words:", 4, 6, None),
        ("paper general / its generator alone:", 0, 2, None),
        ("paper general / its raw words:", 0, 3, None),
    ] {
        let goal = goal.map_or(String::new(), |g: f64| format!("  (goal >= {g:.2})"));
        println!("  {what:<43}{:.3}{goal}", best[num] / best[den]);
    }
    for (k, (name, _)) in jobs.iter().enumerate().skip(7) {
        let base = if name.starts_with("paper") { 0 } else { 4 };
        println!("  {} / {name}: {:.3}", jobs[base].0, best[base] / best[k]);
    }
}
