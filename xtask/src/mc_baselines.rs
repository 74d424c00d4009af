//! `cargo xtask mc --baselines`: the Monte Carlo's same-run baselines and throughput ratios (a
//! benchmark, not in the user's binary). After the run, the generator alone (the same random
//! turntables drawn and decoded, and its raw words only) and the portable SIMD level, in three
//! interleaved rounds with the fast path on the same samples (best of each), the plain
//! dense-matrix chain on the same samples, and the NumPy baseline
//! (`shared/bench/numpy_mc_anchor.py` beside the workspace, if present); the throughput ratios
//! in `mc`'s output under `baselines`.

use anyhow::Result;
use clap::{Arg, ArgAction, FromArgMatches};
use mc_verify::{MonteCarlo, SimdLevel};
use serde::Serialize;
use serde_json::Value;
use std::ffi::OsString;
use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Instant;
use study::Study;
use tt_kinematics::ExactChain;

/// `cargo xtask mc`: the command line's `mc` with `--baselines` added.
pub(crate) fn run(cmd: clap::Command, argv: &[OsString]) -> ExitCode {
    let mut cmd = cmd.mut_subcommand("mc", |c| {
        c.arg(
            Arg::new("baselines")
                .long("baselines")
                .action(ArgAction::SetTrue)
                .help("Also measure the generator alone (decoded and raw words), the portable SIMD level, the plain dense-matrix chain and the NumPy baseline, and report the throughput ratios"),
        )
    });
    let matches = match cmd.try_get_matches_from_mut(argv) {
        Ok(m) => m,
        Err(e) => e.exit(),
    };
    let sub = matches.subcommand_matches("mc").expect("the mc subcommand");
    let args = match ttalloc::bench::McArgs::from_arg_matches(sub) {
        Ok(a) => a,
        Err(e) => e.format(&mut cmd).exit(),
    };
    let bench =
        |s: &Study, mc: &MonteCarlo, pool: &rayon::ThreadPool, rate: f64| -> Result<Value> {
            Ok(serde_json::to_value(baselines(s, mc, pool, rate)?)?)
        };
    let with: Option<ttalloc::bench::Bench<'_>> = if sub.get_flag("baselines") {
        Some(&bench)
    } else {
        None
    };
    ttalloc::finish(ttalloc::bench::mc(&args, with))
}

/// One interleaved round of the baselines, samples per second.
#[derive(Debug, Serialize)]
struct RoundJson {
    /// The fast path.
    fast: f64,
    /// The generator alone (drawn and decoded).
    generator_alone: f64,
    /// The generator's raw words only.
    generator_words_only: f64,
    /// The portable SIMD level.
    portable_simd: f64,
}

/// `mc --baselines`: the same-run baselines and throughput ratios (rates in samples per
/// second, ratios dimensionless).
#[derive(Debug, Serialize)]
struct Baselines {
    /// Samples per timing in the interleaved rounds.
    interleaved_samples: u64,
    /// Every round's rates.
    interleaved_rounds: Vec<RoundJson>,
    /// The fast path's best rate over the rounds.
    fast_best_samples_per_sec: f64,
    /// The generator alone, best rate.
    generator_alone_samples_per_sec: f64,
    /// The generator's raw words only, best rate.
    generator_words_only_samples_per_sec: f64,
    /// The portable SIMD level, best rate.
    portable_simd_samples_per_sec: f64,
    /// Samples of the plain dense-matrix chain.
    plain_chain_samples: u64,
    /// Its rate.
    plain_chain_samples_per_sec: f64,
    /// The NumPy baseline's own JSON as it printed it, or `{"error": why}`.
    numpy: Numpy,
    /// Fast path over the generator alone.
    ratio_fast_over_generator_alone: f64,
    /// Fast path over the generator's raw words.
    ratio_fast_over_generator_words_only: f64,
    /// Fast path over the portable SIMD level.
    ratio_fast_over_portable_simd: f64,
    /// The main run over the plain chain.
    ratio_fast_over_plain_chain: f64,
    /// The main run over NumPy, `null` without its rate.
    ratio_fast_over_numpy: Option<f64>,
}

/// The NumPy baseline's answer.
#[derive(Debug, Serialize)]
#[serde(untagged)]
enum Numpy {
    /// The script's own JSON, passed through as it printed it (an external program's schema,
    /// not this command's).
    Output(Value),
    /// Why there is none.
    Error {
        /// In words.
        error: String,
    },
}

impl Numpy {
    /// The script's samples per second, if it printed them.
    fn samples_per_sec(&self) -> Option<f64> {
        match self {
            Self::Output(v) => v.get("samples_per_sec").and_then(Value::as_f64),
            Self::Error { .. } => None,
        }
    }
}

/// The NumPy baseline script: `shared/bench/numpy_mc_anchor.py` beside the workspace root
/// (found at run time), if present.
fn numpy_script() -> Option<PathBuf> {
    let root = ttalloc::paths::workspace_root().ok()?;
    let script = root.parent()?.join("shared/bench/numpy_mc_anchor.py");
    script.is_file().then_some(script)
}

/// Samples of the NumPy baseline run (its own default scale: 2e6).
const NUMPY_SAMPLES: &str = "2e6";

fn run_numpy(seed: u64) -> Numpy {
    let Some(script) = numpy_script() else {
        return Numpy::Error {
            error: "shared/bench/numpy_mc_anchor.py not found beside the workspace".into(),
        };
    };
    match std::process::Command::new("python3")
        .arg(&script)
        .arg(NUMPY_SAMPLES)
        .arg(seed.to_string())
        .output()
    {
        Ok(out) if out.status.success() => serde_json::from_slice(&out.stdout).map_or_else(
            |e| Numpy::Error {
                error: e.to_string(),
            },
            Numpy::Output,
        ),
        Ok(out) => Numpy::Error {
            error: String::from_utf8_lossy(&out.stderr).to_string(),
        },
        Err(e) => Numpy::Error {
            error: e.to_string(),
        },
    }
}

/// Interleaved rounds of the generator-ratio measurement.
const RATIO_ROUNDS: usize = 3;

/// Samples per timing in the interleaved rounds (or the run's count, if smaller).
const RATIO_SAMPLES: u64 = 200_000_000;

/// The same-run baselines and throughput ratios.
///
/// The ratios to the generator (decoded and raw words) and to the portable SIMD level are
/// the closest to the goals' limits, so they are measured robustly against other load on
/// the machine: [`RATIO_ROUNDS`] rounds, each timing the fast path and every baseline in
/// turn on the same samples (the first [`RATIO_SAMPLES`]), and the best rate of each over
/// the rounds. The plain chain and NumPy (far from their limits) are timed once and compared
/// with the main run (`fast_rate`).
fn baselines(
    s: &Study,
    mc: &MonteCarlo,
    pool: &rayon::ThreadPool,
    fast_rate: f64,
) -> Result<Baselines> {
    let samples = mc.config().samples;
    let rate_of = |f: &(dyn Fn() -> u64 + Sync)| {
        let t = Instant::now();
        let n = pool.install(f);
        n as f64 / t.elapsed().as_secs_f64()
    };
    let mut cfg = *mc.config();
    cfg.samples = samples.min(RATIO_SAMPLES);
    let sub = MonteCarlo::new(&s.turntable, mc.bounds().clone(), cfg)?;
    let mut rounds = Vec::with_capacity(RATIO_ROUNDS);
    for _ in 0..RATIO_ROUNDS {
        rounds.push([
            rate_of(&|| sub.run().count().samples()),
            rate_of(&|| sub.draw_only()),
            rate_of(&|| sub.draw_words_only()),
            rate_of(&|| {
                sub.run_with_simd(SimdLevel::Portable)
                    .map_or(0, |r| r.count().samples())
            }),
        ]);
    }
    let best = |i: usize| rounds.iter().map(|r| r[i]).fold(0.0, f64::max);
    let (fast_best, gen_rate, words_rate, portable_rate) = (best(0), best(1), best(2), best(3));
    // the plain chain is ~10x slower: run it on at most 2e7 of the same samples
    cfg.samples = samples.min(20_000_000);
    let plain_mc = MonteCarlo::new(&s.turntable, mc.bounds().clone(), cfg)?;
    let t = Instant::now();
    let plain = pool.install(|| plain_mc.run_model(&ExactChain::new(&s.turntable)))?;
    let plain_rate = plain.count().samples() as f64 / t.elapsed().as_secs_f64();
    let numpy = if s.turntable == tt_kinematics::paper::table3() {
        run_numpy(mc.config().seed)
    } else {
        Numpy::Error {
            error: "the NumPy baseline models the paper's table only".into(),
        }
    };
    let numpy_rate = numpy.samples_per_sec();
    Ok(Baselines {
        interleaved_samples: sub.config().samples,
        interleaved_rounds: rounds
            .iter()
            .map(|r| RoundJson {
                fast: r[0],
                generator_alone: r[1],
                generator_words_only: r[2],
                portable_simd: r[3],
            })
            .collect(),
        fast_best_samples_per_sec: fast_best,
        generator_alone_samples_per_sec: gen_rate,
        generator_words_only_samples_per_sec: words_rate,
        portable_simd_samples_per_sec: portable_rate,
        plain_chain_samples: plain.count().samples(),
        plain_chain_samples_per_sec: plain_rate,
        numpy,
        ratio_fast_over_generator_alone: fast_best / gen_rate,
        ratio_fast_over_generator_words_only: fast_best / words_rate,
        ratio_fast_over_portable_simd: fast_best / portable_rate,
        ratio_fast_over_plain_chain: fast_rate / plain_rate,
        ratio_fast_over_numpy: numpy_rate.map(|r| fast_rate / r),
    })
}
