//! The timing of a calibration: how long the sensor dwells at each test position, how long
//! the table takes to move to the next one, and the sample rate. It places each position's
//! averaging window on the time axis, which is what correlated noise sees.
//!
//! # Windows
//! Positions are visited in an order $o_0, o_1, \dots$ (the schedule's order unless another
//! is given); the first dwell starts at $t = 0$ and each move takes $t_m$, so the position
//! visited $r$-th is averaged over
//! $$W_{o_r} = \Big[\sum_{s<r}(T_{o_s} + t_m),\ \sum_{s<r}(T_{o_s} + t_m) + T_{o_r}\Big],$$
//! $T_k$ being position $k$'s dwell (a dwell belongs to its position, whatever the order).
//!
//! # Rate steps
//! A schedule with rate steps ([`crate::RateMotion`]) holds them after its static positions
//! (the regression's rows are the positions, then the rate steps). Each rate step's output is
//! averaged over its turning time, its whole revolutions ([`Timing::with_rate_steps`]): a
//! window like a position's dwell, placed in the same time order (positions first, then the
//! rate steps, each followed by a move), so the correlated noise between a rate step's average
//! and a position's is counted as between two positions'. [`Timing::dwell_s`] and what acts on
//! it ([`Timing::with_dwell_s`], [`Timing::with_len`], [`Timing::is_uniform`]) concern the
//! static positions only; a rate step's window is fixed by its revolutions.

use crate::error::{CalibError, finite, positive};
use gw_model::noise::Window;

/// Dwell per position (schedule order), move time and sample rate of a calibration.
#[derive(Debug, Clone, PartialEq)]
pub struct Timing {
    dwell_s: Vec<f64>,
    rate_step_s: Vec<f64>,
    move_s: f64,
    sample_rate_hz: f64,
}

impl Timing {
    /// A timing: `dwell_s[k]` is position $k$'s dwell (s), `move_s` the time between two
    /// dwells (s), `sample_rate_hz` the output's sample rate.
    ///
    /// # Errors
    /// [`CalibError::Field`] (not finite, not positive) naming `dwell_s[k]` or
    /// `sample_rate_hz`; [`CalibError::Timing`] naming `move_s` when negative, `dwell_s` when
    /// empty, and `dwell_s[k]` when a dwell holds less than one sample ($f_s T_k < 1$).
    pub fn new(dwell_s: Vec<f64>, move_s: f64, sample_rate_hz: f64) -> Result<Self, CalibError> {
        if dwell_s.is_empty() {
            return Err(CalibError::Timing {
                field: "dwell_s".into(),
                reason: "no position has a dwell time".into(),
            });
        }
        positive("sample_rate_hz", sample_rate_hz)?;
        finite("move_s", move_s)?;
        if move_s < 0.0 {
            return Err(CalibError::Timing {
                field: "move_s".into(),
                reason: format!("must not be negative, got {move_s}"),
            });
        }
        for (k, &t) in dwell_s.iter().enumerate() {
            let field = format!("dwell_s[{k}]");
            positive(&field, t)?;
            if t * sample_rate_hz < 1.0 {
                return Err(CalibError::Timing {
                    field,
                    reason: format!(
                        "{t} s at {sample_rate_hz} Hz holds less than one sample; dwell at least {} s",
                        1.0 / sample_rate_hz
                    ),
                });
            }
        }
        let total: f64 = dwell_s.iter().sum::<f64>() + move_s * (dwell_s.len() - 1) as f64;
        finite("total test time", total)?;
        Ok(Self {
            dwell_s,
            rate_step_s: Vec::new(),
            move_s,
            sample_rate_hz,
        })
    }

    /// The same timing with the rate steps' averaging windows after the static positions:
    /// `rate_step_s[j]` is rate step $j$'s turning time (s; its whole revolutions over its
    /// rate), replacing any the timing had.
    ///
    /// # Errors
    /// [`CalibError::Field`] (not finite, not positive) naming `rate_step_s[j]`;
    /// [`CalibError::Timing`] naming `rate_step_s[j]` when it holds less than one sample, or
    /// `total test time` when the whole test is not finite.
    pub fn with_rate_steps(self, rate_step_s: Vec<f64>) -> Result<Self, CalibError> {
        for (j, &t) in rate_step_s.iter().enumerate() {
            let field = format!("rate_step_s[{j}]");
            positive(&field, t)?;
            if t * self.sample_rate_hz < 1.0 {
                return Err(CalibError::Timing {
                    field,
                    reason: format!(
                        "{t} s at {} Hz holds less than one sample; turn at least {} s",
                        self.sample_rate_hz,
                        1.0 / self.sample_rate_hz
                    ),
                });
            }
        }
        let out = Self {
            rate_step_s,
            ..self
        };
        finite("total test time", out.total_s())?;
        Ok(out)
    }

    /// The same timing with other static dwells (`dwell_s[k]` for position $k$), the rate
    /// steps' windows, move time and sample rate kept.
    ///
    /// # Errors
    /// As [`new`](Self::new).
    pub fn with_dwell_s(&self, dwell_s: Vec<f64>) -> Result<Self, CalibError> {
        Self::new(dwell_s, self.move_s, self.sample_rate_hz)?
            .with_rate_steps(self.rate_step_s.clone())
    }

    /// The same dwell at each of `n` positions.
    ///
    /// # Errors
    /// As [`new`](Self::new).
    pub fn uniform(
        n: usize,
        dwell_s: f64,
        move_s: f64,
        sample_rate_hz: f64,
    ) -> Result<Self, CalibError> {
        Self::new(vec![dwell_s; n], move_s, sample_rate_hz)
    }

    /// Dwell per static position (schedule order), s.
    #[must_use]
    pub fn dwell_s(&self) -> &[f64] {
        &self.dwell_s
    }

    /// Each rate step's averaging window (its turning time), s, in schedule order (empty
    /// without rate steps).
    #[must_use]
    pub fn rate_step_s(&self) -> &[f64] {
        &self.rate_step_s
    }

    /// Number of static positions.
    #[must_use]
    pub fn positions(&self) -> usize {
        self.dwell_s.len()
    }

    /// Time between two dwells, s.
    #[must_use]
    pub fn move_s(&self) -> f64 {
        self.move_s
    }

    /// Sample rate, Hz.
    #[must_use]
    pub fn sample_rate_hz(&self) -> f64 {
        self.sample_rate_hz
    }

    /// Number of averaging windows: the static positions, then the rate steps (the
    /// regression's rows).
    #[must_use]
    pub fn len(&self) -> usize {
        self.dwell_s.len() + self.rate_step_s.len()
    }

    /// Whether there are no windows (never true for a constructed timing).
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Whether every static position has the same dwell.
    #[must_use]
    pub fn is_uniform(&self) -> bool {
        self.dwell_s
            .iter()
            .all(|&t| t.to_bits() == self.dwell_s[0].to_bits())
    }

    /// The same timing for `n` static positions, if every dwell is the same (`None` otherwise:
    /// a per-position dwell does not carry over to other positions); the rate steps' windows
    /// kept.
    #[must_use]
    pub fn with_len(&self, n: usize) -> Option<Self> {
        (self.is_uniform() && n > 0).then(|| Self {
            dwell_s: vec![self.dwell_s[0]; n],
            ..self.clone()
        })
    }

    /// Total test time: every dwell and rate step and the moves between them, s.
    #[must_use]
    pub fn total_s(&self) -> f64 {
        self.dwell_s.iter().chain(&self.rate_step_s).sum::<f64>()
            + self.move_s * (self.len() - 1) as f64
    }

    /// Entry $k$'s averaging time: a position's dwell or a rate step's turning time, s.
    fn window_s(&self, k: usize) -> f64 {
        self.dwell_s
            .get(k)
            .copied()
            .unwrap_or_else(|| self.rate_step_s[k - self.dwell_s.len()])
    }

    /// Each entry's averaging window (static positions, then rate steps) when visited in the
    /// schedule's order.
    #[must_use]
    pub fn windows(&self) -> Vec<Window> {
        let order: Vec<usize> = (0..self.len()).collect();
        self.windows_unchecked(&order)
    }

    /// Each entry's averaging window (indexed by entry, schedule order: static positions, then
    /// rate steps) when the entries are visited in `order` (`order[r]` is the entry visited
    /// $r$-th).
    ///
    /// # Errors
    /// [`CalibError::Field`] ([`tt_core::FieldError::Length`]) unless `order` is a permutation of `0..n`.
    pub fn windows_in_order(&self, order: &[usize]) -> Result<Vec<Window>, CalibError> {
        let n = self.len();
        let bad = CalibError::Field(tt_core::FieldError::Length {
            field: "visiting order (a permutation of the positions)".into(),
            expected: n,
            found: order.len(),
        });
        if order.len() != n {
            return Err(bad);
        }
        let mut seen = vec![false; n];
        for &k in order {
            if k >= n || seen[k] {
                return Err(bad);
            }
            seen[k] = true;
        }
        Ok(self.windows_unchecked(order))
    }

    fn windows_unchecked(&self, order: &[usize]) -> Vec<Window> {
        let mut out = vec![None; self.len()];
        let mut t = 0.0;
        for &k in order {
            let dwell = self.window_s(k);
            out[k] =
                Some(Window::new(t, dwell).unwrap_or_else(|_| {
                    unreachable!("dwell and total time checked finite, positive")
                }));
            t += dwell + self.move_s;
        }
        out.into_iter()
            .map(|w| w.unwrap_or_else(|| unreachable!("order is a permutation")))
            .collect()
    }
}
