//! The power-law noise types the confidence bands are computed for.
//!
//! A noise whose two-sided power spectral density of the logged quantity (a rate) is
//! $S(f) \propto f^\alpha$ has an Allan variance $\sigma^2(\tau) \propto \tau^{\mu}$ with
//! $\mu = -\alpha - 1$ for $-3 < \alpha \le 1$ and $\mu = -2$ for $\alpha \ge 1$; the
//! Allan deviation's log-log slope is $\mu / 2$ (IEEE Std 952-1997, Annex C; NIST SP 1065,
//! §5.2). The names below are those of inertial sensors (the time-and-frequency names in
//! brackets, where the log is a fractional frequency).

/// One power-law noise type.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "snake_case"))]
pub enum PowerLaw {
    /// White noise of the integrated quantity (angle or velocity quantization), $\alpha = +2$,
    /// Allan deviation slope $-1$ [white phase modulation].
    Quantization,
    /// White noise of the logged quantity (angle / velocity random walk), $\alpha = 0$,
    /// slope $-1/2$ [white frequency modulation].
    White,
    /// Flicker noise (bias instability), $\alpha = -1$, slope $0$ [flicker frequency].
    Flicker,
    /// Random walk of the logged quantity (rate random walk), $\alpha = -2$, slope $+1/2$
    /// [random-walk frequency].
    RandomWalk,
}

impl PowerLaw {
    /// Every type, by increasing slope.
    pub const ALL: [PowerLaw; 4] = [
        PowerLaw::Quantization,
        PowerLaw::White,
        PowerLaw::Flicker,
        PowerLaw::RandomWalk,
    ];

    /// The exponent $\alpha$ of the rate's power spectral density $S(f) \propto f^\alpha$.
    #[must_use]
    pub fn alpha(self) -> i32 {
        match self {
            PowerLaw::Quantization => 2,
            PowerLaw::White => 0,
            PowerLaw::Flicker => -1,
            PowerLaw::RandomWalk => -2,
        }
    }

    /// The type whose slope is nearest to `slope` (midpoints go to the steeper rise); slopes
    /// below $-1$ are [`PowerLaw::Quantization`], above $+1/2$ (a ramp) [`PowerLaw::RandomWalk`];
    /// a non-finite slope is [`PowerLaw::White`].
    #[must_use]
    pub(crate) fn nearest_to_slope(slope: f64) -> PowerLaw {
        if !slope.is_finite() {
            PowerLaw::White
        } else if slope < -0.75 {
            PowerLaw::Quantization
        } else if slope < -0.25 {
            PowerLaw::White
        } else if slope < 0.25 {
            PowerLaw::Flicker
        } else {
            PowerLaw::RandomWalk
        }
    }

    /// A short name: `quantization`, `white`, `flicker`, `random_walk`.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            PowerLaw::Quantization => "quantization",
            PowerLaw::White => "white",
            PowerLaw::Flicker => "flicker",
            PowerLaw::RandomWalk => "random_walk",
        }
    }
}

impl std::fmt::Display for PowerLaw {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// Which noise type the equivalent degrees of freedom of a cluster time assume.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "snake_case"))]
pub enum NoiseModel {
    /// At each cluster time, the type nearest to the curve's local slope (a least-squares line
    /// through the point and its two neighbours in log-log; [`PowerLaw::nearest_to_slope`]).
    #[default]
    Identify,
    /// One type at every cluster time.
    Fixed(PowerLaw),
}
