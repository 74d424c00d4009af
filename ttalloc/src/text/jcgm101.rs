//! `--jcgm101` of `check-turntable` and `end-to-end`: the JCGM 101 Monte Carlo of every
//! specification (the study-level library's [`tt_lab::budget_mc`]) run, its progress on
//! standard error, its text block and its `jcgm101` key of `--json`.

use e2e_verify::EndToEnd;
use e2e_verify::budget::PlanVerdict;
use std::io::IsTerminal;
use study::Study;
use tt_lab::budget_mc::{Jcgm101, Jcgm101Json, Options};

/// The flags of the Monte Carlo (flattened into both commands' arguments).
#[derive(Debug, Clone, clap::Args)]
pub(crate) struct Flags {
    /// Also run the JCGM 101 Monte Carlo of the whole calibration for every specification
    /// (table errors drawn from their laws on the exact chain, noise drawn, the estimator run;
    /// adaptive to the significant digits of u(y) below, with the seed above): mean, u(y),
    /// the symmetric and shortest coverage intervals, the GUM validation and its verdict.
    #[arg(long)]
    pub jcgm101: bool,
    /// Significant digits of u(y) the JCGM 101 Monte Carlo stabilizes, 1 to 6 (default 2;
    /// only with the Monte Carlo).
    #[arg(long, value_parser = crate::args::mc_digits, requires = "jcgm101")]
    pub mc_digits: Option<u32>,
}

impl Flags {
    /// The library's options when `--jcgm101` is given (`None` otherwise), seeded by `seed`.
    #[must_use]
    pub(crate) fn options(&self, seed: Option<u64>) -> Option<Options> {
        self.jcgm101.then(|| Options {
            significant_digits: self
                .mc_digits
                .unwrap_or(Options::default().significant_digits),
            seed,
            ..Options::default()
        })
    }
}

/// The Monte Carlo of `verdict`'s specifications when `--jcgm101` is given and the study has
/// specifications (`None` otherwise), with a line on standard error before and after (an
/// interactive terminal only).
///
/// # Errors
/// As [`tt_lab::budget_mc::compute`].
pub(crate) fn run(
    flags: &Flags,
    seed: Option<u64>,
    s: &Study,
    e2e: &EndToEnd,
    ub_rad: &[f64],
    verdict: Option<&PlanVerdict>,
) -> anyhow::Result<Option<Jcgm101>> {
    let (Some(options), Some(verdict)) = (flags.options(seed), verdict) else {
        return Ok(None);
    };
    let digits = options.significant_digits;
    let tell = std::io::stderr().is_terminal();
    if tell {
        eprintln!(
            "JCGM 101 Monte Carlo of {} specifications, adaptive to {} significant digits of u(y)...",
            verdict.budgets().len(),
            digits
        );
    }
    let t0 = std::time::Instant::now();
    let mc =
        tt_lab::budget_mc::compute(s, e2e, ub_rad, verdict, &options).map_err(crate::input::lab)?;
    if tell {
        eprintln!(
            "JCGM 101 Monte Carlo: done in {:.1} s",
            t0.elapsed().as_secs_f64()
        );
    }
    Ok(Some(mc))
}

/// The Monte Carlo as text: one line per specification, then its verdict with its rule; a
/// note when `--jcgm101` was given to a study without specifications.
#[must_use]
pub(crate) fn text(flags: &Flags, s: &Study, mc: Option<&Jcgm101>) -> String {
    let Some(mc) = mc else {
        return if flags.jcgm101 {
            "  JCGM 101 Monte Carlo: not run (the study gives no [[specifications]])\n".into()
        } else {
            String::new()
        };
    };
    let mut t = String::from("\nJCGM 101 Monte Carlo of each specification, same tolerances:\n");
    for line in tt_lab::budget_mc::spec_lines(s, mc) {
        t.push_str(&format!("  {line}\n"));
    }
    t.push_str(&format!("  {}\n", tt_lab::budget_mc::headline(mc)));
    t
}

/// `view` (a command's `--json` view) with the key `jcgm101` added when the Monte Carlo ran.
///
/// # Errors
/// A view serde_json cannot represent.
pub(crate) fn with_json(
    view: &impl serde::Serialize,
    s: &Study,
    mc: Option<&Jcgm101>,
) -> anyhow::Result<serde_json::Value> {
    let mut v = serde_json::to_value(view)?;
    if let (Some(mc), Some(map)) = (mc, v.as_object_mut()) {
        map.insert(
            "jcgm101".into(),
            serde_json::to_value(Jcgm101Json::new(s, mc))?,
        );
    }
    Ok(v)
}
