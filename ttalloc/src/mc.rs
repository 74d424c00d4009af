//! `cargo xtask mc [--study FILE] [--samples N] [--seed S] [--threads T]
//! [--bounds two-step|table4] [--tolerances FILE] [--json] [--baselines]`: the Monte Carlo check
//! of a tolerance box (paper §4.3, Figure 9) for the study's turntable, fast and reproducible.
//!
//! Draws `N` random turntables (|chi_i| uniform in [LB_i, UB_i], fair random signs, poses
//! uniform over the joint ranges; see `mc_verify::sampler`), evaluates the exact chain with the
//! eq-24 read-out and reports the extremes (with their worst samples), mean, standard deviation,
//! histograms and the fraction inside the study's orientation requirement.
//!
//! Boxes: `two-step` (default) is the study's two-step allocation (alloc-opt against the
//! study's requirement and lower bounds); `table4` the paper's Table 4 (the paper's table only);
//! `--tolerances FILE` a vendor's tolerances. Defaults for `--samples` and `--seed` are the
//! study's `monte_carlo` values.
//!
//! `--json` prints one object with at least `samples`, `seed`, `threads`, `seconds`,
//! `samples_per_sec`, `max_abs_deg {psi, theta, gamma}` and `within_requirement_fraction`,
//! plus the bounds, mean, std, worst samples, histograms, the certificate's worst case and the
//! SIMD level chosen at run time. `cargo xtask mc --baselines` (a benchmark: xtask's
//! `mc_baselines`, not in the user's binary) adds the same-run baselines and throughput ratios
//! ([`run_with`]). The result does not depend on `--threads` (nor on the SIMD level).

use anyhow::{Context, Result};
use clap::{Parser, ValueEnum};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use mc_verify::{MonteCarlo, SimdLevel};
use serde::Serialize;
use serde_json::Value;
use std::io::IsTerminal;
use std::path::PathBuf;
use study::Study;
use tt_core::human::num;
use tt_core::units::rad_to_deg;
use tt_lab::monte_carlo::{Bounds, McJson, Options};

/// Which tolerance box to verify.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub(crate) enum BoundsChoice {
    /// The study's two-step allocation (the paper's method solved to the optimum).
    TwoStep,
    /// The paper's Table 4 (the paper's table only).
    Table4,
}

/// Arguments of `mc`.
#[derive(Debug, Parser)]
pub struct Args {
    /// `--study` (default: the paper's).
    #[command(flatten)]
    pub(crate) study: crate::args::StudyFile,
    /// `--samples` and `--seed` (default: the study's `monte_carlo`).
    #[command(flatten)]
    pub(crate) sampling: crate::args::Sampling,
    /// Worker threads (default: all cores). The result does not depend on it.
    #[arg(long, allow_negative_numbers = true, value_parser = crate::args::threads)]
    pub(crate) threads: Option<u32>,
    /// Tolerance box to verify.
    #[arg(long, value_enum, default_value_t = BoundsChoice::TwoStep, conflicts_with = "tolerances")]
    pub(crate) bounds: BoundsChoice,
    /// A vendor's tolerance file instead of `--bounds`.
    #[arg(long)]
    pub(crate) tolerances: Option<PathBuf>,
    /// Samples per random stream (part of the reproducibility contract).
    #[arg(long, allow_negative_numbers = true, default_value_t = mc_verify::DEFAULT_CHUNK_SIZE, value_parser = crate::args::count_u32)]
    pub(crate) chunk_size: u32,
    /// Histogram bins per angle (1 to 10,000).
    #[arg(long, allow_negative_numbers = true, default_value_t = mc_verify::DEFAULT_HISTOGRAM_BINS, value_parser = parse_bins)]
    pub(crate) bins: usize,
    /// Print JSON instead of text.
    #[arg(long)]
    pub(crate) json: bool,
}

fn parse_bins(s: &str) -> Result<usize, String> {
    crate::args::count(s, mc_verify::MAX_HISTOGRAM_BINS as u64).map(|v| v as usize)
}

/// The study-level options of the arguments.
fn options(args: &Args) -> Options {
    let mut o = Options::default();
    o.samples = args.sampling.samples;
    o.seed = args.sampling.seed;
    o.chunk_size = args.chunk_size;
    o.bins = args.bins;
    o.bounds = match (&args.tolerances, args.bounds) {
        (Some(p), _) => Bounds::Tolerances(p.clone()),
        (None, BoundsChoice::TwoStep) => Bounds::TwoStep,
        (None, BoundsChoice::Table4) => Bounds::Table4,
    };
    o
}

/// `mc --json`: the run's view, with the baselines when measured.
#[derive(Debug, Serialize)]
struct McOut<'a> {
    /// The run (its keys at the top level).
    #[serde(flatten)]
    run: McJson<'a>,
    /// With `cargo xtask mc --baselines`: the same-run baselines and throughput ratios;
    /// absent otherwise.
    #[serde(skip_serializing_if = "Option::is_none")]
    baselines: Option<Value>,
}

fn progress_bar(samples: u64) -> Option<ProgressBar> {
    // only for an interactive terminal and a run long enough to watch (about a second)
    if !std::io::stderr().is_terminal() || samples < 100_000_000 {
        return None;
    }
    let pb = ProgressBar::with_draw_target(Some(samples), ProgressDrawTarget::stderr());
    if let Ok(style) =
        ProgressStyle::with_template("{bar:40} {human_pos}/{human_len} samples, eta {eta}")
    {
        pb.set_style(style);
    }
    Some(pb)
}

/// A same-run benchmark measured after the run (`cargo xtask mc --baselines`): from the study,
/// the run's Monte Carlo, its thread pool and the run's rate (samples per second), its JSON
/// view, printed under `baselines`.
pub type Bench<'a> =
    &'a (dyn Fn(&Study, &MonteCarlo, &rayon::ThreadPool, f64) -> Result<Value> + 'a);

/// Run the command.
pub(crate) fn run(args: &Args) -> Result<()> {
    run_with(args, None)
}

/// Run the command, then `bench` if given.
///
/// # Errors
/// As `run`, and the benchmark's.
pub fn run_with(args: &Args, bench: Option<Bench<'_>>) -> Result<()> {
    let s = args.study.load()?;
    let plan = tt_lab::monte_carlo::plan(&s, &options(args)).map_err(crate::input::lab)?;
    let threads = match args.threads {
        Some(t) => t as usize,
        None => std::thread::available_parallelism().map_or(1, usize::from),
    };
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .context("building the thread pool")?;
    let pb = progress_bar(plan.monte_carlo().config().samples);
    let answer = pool.install(|| {
        plan.run(&|done| {
            if let Some(pb) = &pb {
                pb.set_position(done);
            }
        })
    });
    if let Some(pb) = pb {
        pb.finish_and_clear();
    }
    let (r, seconds, name) = (answer.result(), answer.seconds(), answer.plan().name());
    let note = answer.plan().requirement_note();
    let mut report = McOut {
        run: answer.view(&s, threads),
        baselines: None,
    };
    if let Some(bench) = bench {
        report.baselines = Some(bench(
            &s,
            answer.plan().monte_carlo(),
            &pool,
            r.count().samples() as f64 / seconds,
        )?);
    }
    if args.json {
        return crate::json::print(&report);
    }
    let mut t = format!(
        "{} samples, seed {}, {} threads ({}), bounds {}, study {}: {:.3} s, {} samples/s\n",
        r.count().samples(),
        r.count().seed(),
        threads,
        SimdLevel::detected().name(),
        name,
        s.path,
        seconds,
        num(r.count().samples() as f64 / seconds)
    );
    let std = r.std_rad();
    for a in r.axes() {
        let k = a.axis().index();
        t.push_str(&format!(
            "{:>6}: max |.| {} deg (requirement {}), mean {} deg, std {} deg, worst sample #{}\n",
            a.axis().name(),
            num(rad_to_deg(a.max_abs_rad())),
            r.requirement().to_array()[k].map_or("none".into(), |v| num(rad_to_deg(v))),
            num(rad_to_deg(a.mean_rad())),
            num(rad_to_deg(std[k])),
            a.worst().index(),
        ));
    }
    t.push_str(&format!(
        "inside the requirement (all three angles): {} of {} = {}\n",
        r.count().meeting(),
        r.count().samples(),
        tt_core::human::sig(r.count().fraction(), 9)
    ));
    if let Some(n) = &note {
        t.push_str(n);
        t.push('\n');
    }
    if let Some(b) = &report.baselines {
        t.push_str(&format!(
            "baselines: {}\n",
            serde_json::to_string_pretty(b)?
        ));
    }
    crate::out::print(&t)
}
