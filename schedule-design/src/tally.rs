//! The budget design's work in counts (exchanges, their passes, screened swaps, exact
//! evaluations, schedule-dwell evaluations) and each step's wall time: printed to standard
//! error when `XTASK_TIMING` is set (as the report's phases), so a profile of the front says
//! where the time goes in numbers that do not depend on the machine.

use crate::ExchangeOutcome;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::Instant;

/// Counts of the expensive steps of one budget design (shared by its threads).
#[derive(Debug, Default)]
pub(crate) struct Tally {
    /// Exchanges run (table designs of other counts and noise-aware searches' steps).
    exchanges: AtomicUsize,
    /// Their passes over every slot.
    passes: AtomicUsize,
    /// Swaps screened by a bound.
    screened: AtomicUsize,
    /// Swaps evaluated exactly (a conic solve each).
    exact: AtomicUsize,
    /// Schedules whose simulator and linearisation were built.
    evaluators: AtomicUsize,
    /// Schedule-dwell pairs evaluated ($J$ at one dwell: a noise budget and a conic solve).
    dwell_evaluations: AtomicUsize,
    /// Trade-offs listed (`EndToEnd::tradeoff`, one per non-searched schedule).
    tradeoffs: AtomicUsize,
}

impl Tally {
    /// Count one exchange's work.
    pub(crate) fn exchange(&self, e: &ExchangeOutcome) {
        self.exchanges.fetch_add(1, Ordering::Relaxed);
        self.passes.fetch_add(e.stop().passes(), Ordering::Relaxed);
        self.screened
            .fetch_add(e.screened_swaps(), Ordering::Relaxed);
        self.exact
            .fetch_add(e.exact_evaluations(), Ordering::Relaxed);
    }

    /// Count one schedule's simulator and linearisation.
    pub(crate) fn evaluator(&self) {
        self.evaluators.fetch_add(1, Ordering::Relaxed);
    }

    /// Count one schedule-dwell evaluation.
    pub(crate) fn dwell_evaluation(&self) {
        self.dwell_evaluations.fetch_add(1, Ordering::Relaxed);
    }

    /// Count one trade-off listed.
    pub(crate) fn tradeoff(&self) {
        self.tradeoffs.fetch_add(1, Ordering::Relaxed);
    }

    /// The counts in words.
    fn counts(&self) -> String {
        let g = |a: &AtomicUsize| a.load(Ordering::Relaxed);
        format!(
            "{} exchanges, {} passes, {} screened swaps, {} exact evaluations, {} simulators, {} schedule-dwell evaluations, {} trade-offs",
            g(&self.exchanges),
            g(&self.passes),
            g(&self.screened),
            g(&self.exact),
            g(&self.evaluators),
            g(&self.dwell_evaluations),
            g(&self.tradeoffs),
        )
    }
}

/// Each step's wall time and the work counted up to its end, printed when `XTASK_TIMING` is
/// set (nothing is measured otherwise).
pub(crate) struct Phases {
    since: Option<Instant>,
}

impl Phases {
    /// Start timing (only with `XTASK_TIMING` set).
    pub(crate) fn start() -> Self {
        Self {
            since: std::env::var_os("XTASK_TIMING").map(|_| Instant::now()),
        }
    }

    /// Print the step `what` just ended: its wall time and the counts so far.
    pub(crate) fn step(&mut self, what: &str, tally: &Tally) {
        if let Some(t) = self.since {
            eprintln!(
                "timing: budget: {what}: {:.2} s (so far: {})",
                t.elapsed().as_secs_f64(),
                tally.counts()
            );
            self.since = Some(Instant::now());
        }
    }
}
