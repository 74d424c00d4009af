//! The JCGM 101 Monte Carlo of the whole calibration per specification (issue 34 item 3),
//! beside the GUM budget's verdict ([`crate::vendor::spec`]): one library call
//! ([`e2e_verify::BudgetQuestions::specification_monte_carlo`]) for the tolerances of
//! `check-turntable` (the sheet's) or `end-to-end` (the direct allocation's box), and its
//! JSON view. Each specification gets the Monte Carlo's mean, $u(y)$, the probabilistically
//! symmetric and the shortest coverage intervals, the trials, whether the run stabilized,
//! whether the GUM interval $0 \pm U$ is validated at the numerical tolerance, and the verdict
//! under [`MC_RULE`]. Seeded: the same answer for any number of threads.

use crate::{InputError, Result};
use e2e_verify::EndToEnd;
use e2e_verify::budget::PlanVerdict;
pub use e2e_verify::budget_mc::{MC_RULE, SpecificationMonteCarlo};
use metrology::montecarlo::McSettings;
use study::Study;
use tt_core::human::num;

/// The default trial limit of a run: at about $10^5$ trials/s on two cores a run that does
/// not stabilize stops within minutes and says so.
pub const DEFAULT_MAX_TRIALS: u64 = 10_000_000;

/// The largest number of significant digits of $u(y)$ a run stabilizes (JCGM 101 7.9).
pub const MAX_DIGITS: u32 = 6;

/// The options of [`compute`]: the numerical tolerance as significant digits of $u(y)$,
/// the seed and the trial limit.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Options {
    /// Significant digits of $u(y)$ the adaptive run stabilizes, 1 to [`MAX_DIGITS`]
    /// (`--mc-digits`). Default 2.
    pub significant_digits: u32,
    /// The seed (`None`: the study's `monte_carlo.seed`).
    pub seed: Option<u64>,
    /// At most this many trials per run (whole blocks); the run then says it did not
    /// stabilize.
    pub max_trials: u64,
}

impl Default for Options {
    fn default() -> Self {
        Self {
            significant_digits: 2,
            seed: None,
            max_trials: DEFAULT_MAX_TRIALS,
        }
    }
}

/// The Monte Carlo answer of every specification ([`compute`]).
#[derive(Debug, Clone)]
#[non_exhaustive]
pub struct Jcgm101 {
    runs: Vec<SpecificationMonteCarlo>,
    significant_digits: u32,
    seed: u64,
    unbounded: Vec<bool>,
}

impl Jcgm101 {
    /// One answer per specification, in the study's order.
    #[must_use]
    pub fn runs(&self) -> &[SpecificationMonteCarlo] {
        &self.runs
    }

    /// The significant digits of $u(y)$ the runs stabilized.
    #[must_use]
    pub fn significant_digits(&self) -> u32 {
        self.significant_digits
    }

    /// The seed used.
    #[must_use]
    pub fn seed(&self) -> u64 {
        self.seed
    }

    /// Whether specification `i` is met under [`MC_RULE`]; never when an error without a
    /// finite tolerance moves its quantity (the Monte Carlo draws it as zero).
    #[must_use]
    pub fn meets(&self, i: usize) -> bool {
        self.runs[i].meets() && !self.unbounded[i]
    }

    /// Whether every specification is met under [`MC_RULE`].
    #[must_use]
    pub(crate) fn meets_all(&self) -> bool {
        (0..self.runs.len()).all(|i| self.meets(i))
    }
}

/// The JCGM 101 Monte Carlo of every specification of `verdict` (from
/// [`crate::vendor::spec::compute`] for the tolerances `ub_rad`, the same simulator `e2e`),
/// each table error drawn from the study's law (`[uncertainty] tolerance_distribution`) on
/// its tolerance, the noise drawn with the budget's standard uncertainties.
///
/// # Errors
/// An [`InputError`] naming `--mc-digits` for digits outside 1 to [`MAX_DIGITS`] or
/// `--mc-max-trials` for a zero limit; a library error if the chain fails.
pub fn compute(
    s: &Study,
    e2e: &EndToEnd,
    ub_rad: &[f64],
    verdict: &PlanVerdict,
    o: &Options,
) -> Result<Jcgm101> {
    if !(1..=MAX_DIGITS).contains(&o.significant_digits) {
        return Err(InputError::new(
            "--mc-digits",
            format!(
                "{}: the significant digits of u(y) must be 1 to {MAX_DIGITS}",
                o.significant_digits
            ),
        )
        .into());
    }
    if o.max_trials == 0 {
        return Err(InputError::new("max_trials", "0: at least one trial").into());
    }
    let law = s.uncertainty.tolerance_distribution;
    let table = e2e
        .error_names()
        .iter()
        .zip(ub_rad)
        .map(|(n, &a)| law.input(n, if a.is_finite() { a } else { 0.0 }))
        .collect::<std::result::Result<Vec<_>, _>>()
        .map_err(|e| crate::error::library(e, s))?;
    let seed = o.seed.unwrap_or(s.monte_carlo.seed);
    let settings = McSettings {
        significant_digits: o.significant_digits,
        seed,
        max_trials: o.max_trials,
        ..McSettings::default()
    };
    let runs = e2e
        .budget()
        .specification_monte_carlo(&s.specifications, verdict, &table, &settings)
        .map_err(|e| crate::error::library(e, s))?;
    let unbounded = (0..runs.len())
        .map(|i| !verdict.unbounded()[i].is_empty())
        .collect();
    Ok(Jcgm101 {
        runs,
        significant_digits: o.significant_digits,
        seed,
        unbounded,
    })
}

/// One specification's Monte Carlo (`jcgm101.specifications[]`), in the specification's unit.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct McSpecJson {
    /// The quantity, as in `decision.specifications[].quantity`.
    pub quantity: String,
    /// The unit of every figure (as written in the study).
    pub unit: String,
    /// The limit.
    pub limit: f64,
    /// The coverage probability of the intervals.
    pub coverage: f64,
    /// The Monte Carlo's mean of the quantity.
    pub mean: f64,
    /// Its standard deviation $u(y)$.
    pub standard_uncertainty: f64,
    /// The probabilistically symmetric coverage interval [low, high].
    pub symmetric_interval: [f64; 2],
    /// The shortest coverage interval [low, high].
    pub shortest_interval: [f64; 2],
    /// The numerical tolerance of $u(y)$ at the run's significant digits.
    pub numerical_tolerance: f64,
    /// The trials of the run.
    pub trials: u64,
    /// Whether the run stabilized before its trial limit.
    pub stabilized: bool,
    /// Whether the GUM interval 0 +- U is validated against the symmetric interval at the
    /// numerical tolerance (JCGM 101 8.2).
    pub gum_validated: bool,
    /// Whether met under the Monte Carlo's rule (`jcgm101.rule`).
    pub meets: bool,
}

/// The Monte Carlo of every specification (`jcgm101` of `--json`).
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct Jcgm101Json {
    /// The decision rule in words.
    pub rule: &'static str,
    /// Whether every specification is met under it.
    pub meets: bool,
    /// The significant digits of u(y) the runs stabilized.
    pub significant_digits: u32,
    /// The seed.
    pub seed: u64,
    /// One per specification.
    pub specifications: Vec<McSpecJson>,
}

impl Jcgm101Json {
    /// The JSON view of `mc`.
    #[must_use]
    pub fn new(s: &Study, mc: &Jcgm101) -> Self {
        let specifications = mc
            .runs
            .iter()
            .enumerate()
            .map(|(i, m)| {
                let sp = &s.specifications[m.spec()];
                let f = sp.to_written();
                let o = m.output();
                let pair = |(a, b): (f64, f64)| [a * f, b * f];
                McSpecJson {
                    quantity: sp.label(&s.sensor),
                    unit: sp.unit().to_string(),
                    limit: sp.written_limit(),
                    coverage: sp.coverage(),
                    mean: o.estimate() * f,
                    standard_uncertainty: o.standard_uncertainty() * f,
                    symmetric_interval: pair(o.symmetric()),
                    shortest_interval: pair(o.shortest()),
                    numerical_tolerance: o.tolerance() * f,
                    trials: m.trials(),
                    stabilized: m.stabilized(),
                    gum_validated: m.validation().validated(),
                    meets: mc.meets(i),
                }
            })
            .collect();
        Self {
            rule: MC_RULE,
            meets: mc.meets_all(),
            significant_digits: mc.significant_digits,
            seed: mc.seed,
            specifications,
        }
    }
}

/// One line per specification (plain text, the study's names unescaped): the mean, u(y),
/// both intervals, the trials, stabilized, the GUM validation and the verdict.
#[must_use]
pub fn spec_lines(s: &Study, mc: &Jcgm101) -> Vec<String> {
    let interval = |v: [f64; 2]| format!("[{}, {}]", num(v[0]), num(v[1]));
    Jcgm101Json::new(s, mc)
        .specifications
        .iter()
        .map(|j| {
            format!(
                "{}: mean {} {u}, u(y) {} {u}, {}% symmetric {} {u}, shortest {} {u}; {} trials{}; GUM interval {} at the numerical tolerance {} {u}; against {} {u}: {}",
                j.quantity,
                num(j.mean),
                num(j.standard_uncertainty),
                num(100.0 * j.coverage),
                interval(j.symmetric_interval),
                interval(j.shortest_interval),
                j.trials,
                if j.stabilized {
                    ", stabilized"
                } else {
                    ", NOT stabilized (trial limit reached)"
                },
                if j.gum_validated {
                    "validated"
                } else {
                    "not validated"
                },
                num(j.numerical_tolerance),
                num(j.limit),
                if j.meets { "meets" } else { "does NOT meet" },
                u = j.unit,
            )
        })
        .collect()
}

/// The headline (plain text): met or not, how many, the rule.
#[must_use]
pub fn headline(mc: &Jcgm101) -> String {
    let n = mc.runs.len();
    format!(
        "Monte Carlo verdict: {} every specification ({} of {n} met; {} significant digits of u(y), seed {}); rule: {MC_RULE}",
        if mc.meets_all() {
            "MEETS"
        } else {
            "does NOT meet"
        },
        (0..n).filter(|&i| mc.meets(i)).count(),
        mc.significant_digits,
        mc.seed,
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The call's answer is the e2e-verify call's on the same inputs (the study's law on the
    /// tolerances, its seed), and its view converts model units to the written ones.
    #[test]
    fn jcgm101_answer_equals_the_e2e_verify_monte_carlo() {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../studies/imu-triad-example.toml");
        let s = crate::loaded::load(Some(&path)).expect("the IMU example loads");
        let e2e = crate::loaded::simulator(&s).expect("its simulator");
        let ub = vec![(10.0_f64 / 3600.0).to_radians(); e2e.n_errors()];
        let verdict = crate::vendor::spec::compute(&s, &e2e, &ub)
            .expect("budgets")
            .expect("the example has specifications");
        let o = Options {
            significant_digits: 1,
            seed: Some(11),
            ..Options::default()
        };
        let mc = compute(&s, &e2e, &ub, &verdict, &o).expect("runs");
        let law = s.uncertainty.tolerance_distribution;
        let table: Vec<_> = e2e
            .error_names()
            .iter()
            .zip(&ub)
            .map(|(n, &a)| law.input(n, a).expect("a law"))
            .collect();
        let settings = McSettings {
            significant_digits: 1,
            seed: 11,
            max_trials: DEFAULT_MAX_TRIALS,
            ..McSettings::default()
        };
        let direct = e2e
            .budget()
            .specification_monte_carlo(&s.specifications, &verdict, &table, &settings)
            .expect("runs");
        assert_eq!(mc.runs(), &direct[..]);
        assert_eq!(mc.runs().len(), s.specifications.len());
        let j = Jcgm101Json::new(&s, &mc);
        for ((js, m), sp) in j.specifications.iter().zip(&direct).zip(&s.specifications) {
            // one multiplication by the unit's factor: exact to the last bit but one
            approx::assert_relative_eq!(
                js.standard_uncertainty,
                m.output().standard_uncertainty() * sp.to_written(),
                max_relative = 1e-15
            );
            assert_eq!(js.meets, m.meets());
            assert_eq!(js.gum_validated, m.validation().validated());
        }
        assert_eq!(j.rule, MC_RULE);
        let bad = Options {
            significant_digits: 7,
            ..o
        };
        let e = compute(&s, &e2e, &ub, &verdict, &bad).expect_err("7 digits refused");
        assert!(e.to_string().contains("--mc-digits"), "{e}");
    }
}
