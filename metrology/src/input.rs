//! Input quantities: a name, a best estimate, a probability distribution and the degrees of
//! freedom of the standard uncertainty.
//!
//! | distribution | parameter | standard uncertainty | JCGM 100 / 101 |
//! |---|---|---|---|
//! | normal | $u$ | $u$ | 4.2, 4.3.4; JCGM 101 6.4.7 |
//! | rectangular | half-width $a$ | $a/\sqrt3$ | 4.3.7; JCGM 101 6.4.2 |
//! | triangular | half-width $a$ | $a/\sqrt6$ | 4.3.9; JCGM 101 6.4.5 |
//! | arcsine (U-shaped) | amplitude $a$ | $a/\sqrt2$ | JCGM 101 6.4.6 |
//! | disc (2-D) | radius $w$ | $w/2$ per component | JCGM 102 (uniform in a disc) |
//!
//! The arcsine law is that of $a \sin\phi$ with $\phi$ uniform: a sinusoid's value at an
//! unknown phase. The disc is a 2-D vector uniform in a disc of radius $w$ (an eccentricity,
//! a wobble of unknown direction): two components, each of variance
//! $E[r^2]/2 = w^2/4$, uncorrelated but not independent (the Monte Carlo draws them jointly).
//!
//! Degrees of freedom default to infinite (a type B evaluation known exactly, or a normal
//! with a well-known $u$); [`Input::with_dof`] sets them: $n - 1$ for a type A mean of $n$
//! indications, or $\nu \approx \tfrac12 (\Delta u / u)^{-2}$ for a type B value whose
//! relative reliability $\Delta u/u$ is judged (JCGM 100 G.4.2).
//!
//! # Reference
//! JCGM 100:2008 (GUM) 4.3; JCGM 101:2008 6.4 (sampling of the distributions).

use crate::error::MetrologyError;
use std::f64::consts::TAU;
use tt_core::{finite, positive};

/// The probability distribution of an input quantity, with its parameter.
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub enum Distribution {
    /// Normal with standard uncertainty $u$.
    Normal {
        /// $u$.
        standard_uncertainty: f64,
    },
    /// Uniform on $[x - a, x + a]$.
    Rectangular {
        /// $a$.
        half_width: f64,
    },
    /// Symmetric triangular on $[x - a, x + a]$.
    Triangular {
        /// $a$.
        half_width: f64,
    },
    /// Arcsine (U-shaped) on $[x - a, x + a]$: $x + a \sin\phi$, $\phi$ uniform.
    Arcsine {
        /// $a$.
        amplitude: f64,
    },
    /// A 2-D vector uniform in a disc of radius $w$ about $(x, y)$.
    Disc {
        /// $w$.
        radius: f64,
    },
}

impl Distribution {
    /// The name in a budget row (`normal`, `rectangular`, `triangular`, `arcsine`, `disc`).
    #[must_use]
    pub fn name(&self) -> &'static str {
        match self {
            Distribution::Normal { .. } => "normal",
            Distribution::Rectangular { .. } => "rectangular",
            Distribution::Triangular { .. } => "triangular",
            Distribution::Arcsine { .. } => "arcsine",
            Distribution::Disc { .. } => "disc",
        }
    }

    /// The standard uncertainty of each component.
    #[must_use]
    pub fn standard_uncertainty(&self) -> f64 {
        match *self {
            Distribution::Normal {
                standard_uncertainty,
            } => standard_uncertainty,
            Distribution::Rectangular { half_width } => half_width / 3.0_f64.sqrt(),
            Distribution::Triangular { half_width } => half_width / 6.0_f64.sqrt(),
            Distribution::Arcsine { amplitude } => amplitude / 2.0_f64.sqrt(),
            Distribution::Disc { radius } => 0.5 * radius,
        }
    }

    /// Components: 2 for a disc, else 1.
    #[must_use]
    pub(crate) fn components(&self) -> usize {
        if matches!(self, Distribution::Disc { .. }) {
            2
        } else {
            1
        }
    }

    /// Uniform draws one sample of each component takes (fixed, so that streams are
    /// reproducible): 2 for a normal (Box-Muller, cosine branch), a triangle and a disc, 1
    /// otherwise.
    pub(crate) fn uniforms(&self) -> usize {
        match self {
            Distribution::Rectangular { .. } | Distribution::Arcsine { .. } => 1,
            _ => 2,
        }
    }

    /// The deviation from the estimate of each component from the uniforms `w` in (0, 1)
    /// (JCGM 101 6.4: normal by Box-Muller, rectangular $a(2w - 1)$, triangular
    /// $a(w_1 + w_2 - 1)$, arcsine $a \sin 2\pi w$, disc $w\sqrt{w_1}(\cos 2\pi w_2,
    /// \sin 2\pi w_2)$).
    pub(crate) fn deviation(&self, w: &[f64], out: &mut [f64]) {
        match *self {
            Distribution::Normal {
                standard_uncertainty,
            } => {
                out[0] = standard_uncertainty * (-2.0 * w[0].ln()).sqrt() * (TAU * w[1]).cos();
            }
            Distribution::Rectangular { half_width } => out[0] = half_width * (2.0 * w[0] - 1.0),
            Distribution::Triangular { half_width } => {
                out[0] = half_width * (w[0] + w[1] - 1.0);
            }
            Distribution::Arcsine { amplitude } => out[0] = amplitude * (TAU * w[0]).sin(),
            Distribution::Disc { radius } => {
                let r = radius * w[0].sqrt();
                let (s, c) = (TAU * w[1]).sin_cos();
                out[0] = r * c;
                out[1] = r * s;
            }
        }
    }
}

/// An input quantity: its name, best estimate (one value per component), distribution and
/// degrees of freedom.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct Input {
    pub(crate) name: String,
    pub(crate) estimate: [f64; 2],
    pub(crate) distribution: Distribution,
    pub(crate) dof: f64,
}

impl Input {
    fn new(
        name: &str,
        estimate: [f64; 2],
        distribution: Distribution,
        parameter: (&str, f64),
    ) -> Result<Self, MetrologyError> {
        finite(format!("{name}.estimate"), estimate[0])?;
        finite(format!("{name}.estimate"), estimate[1])?;
        // zero is accepted: an input known exactly contributes nothing
        let (key, value) = parameter;
        tt_core::non_negative(format!("{name}.{key}"), value)?;
        Ok(Input {
            name: name.to_string(),
            estimate,
            distribution,
            dof: f64::INFINITY,
        })
    }

    /// A normal input with estimate `estimate` and standard uncertainty `u` (>= 0).
    ///
    /// # Errors
    /// A non-finite estimate (`NAME.estimate`) or a negative or non-finite `u`
    /// (`NAME.standard_uncertainty`).
    pub fn normal(name: &str, estimate: f64, u: f64) -> Result<Self, MetrologyError> {
        let d = Distribution::Normal {
            standard_uncertainty: u,
        };
        Self::new(name, [estimate, 0.0], d, ("standard_uncertainty", u))
    }

    /// A rectangular input on `[estimate - a, estimate + a]`.
    ///
    /// # Errors
    /// `NAME.estimate`, `NAME.half_width` as for [`Input::normal`].
    pub fn rectangular(name: &str, estimate: f64, a: f64) -> Result<Self, MetrologyError> {
        let d = Distribution::Rectangular { half_width: a };
        Self::new(name, [estimate, 0.0], d, ("half_width", a))
    }

    /// A symmetric triangular input on `[estimate - a, estimate + a]`.
    ///
    /// # Errors
    /// `NAME.estimate`, `NAME.half_width` as for [`Input::normal`].
    pub fn triangular(name: &str, estimate: f64, a: f64) -> Result<Self, MetrologyError> {
        let d = Distribution::Triangular { half_width: a };
        Self::new(name, [estimate, 0.0], d, ("half_width", a))
    }

    /// An arcsine (U-shaped) input `estimate + a sin(phi)`, phi uniform: a sinusoid of
    /// amplitude `a` at an unknown phase.
    ///
    /// # Errors
    /// `NAME.estimate`, `NAME.amplitude` as for [`Input::normal`].
    pub fn arcsine(name: &str, estimate: f64, a: f64) -> Result<Self, MetrologyError> {
        let d = Distribution::Arcsine { amplitude: a };
        Self::new(name, [estimate, 0.0], d, ("amplitude", a))
    }

    /// A 2-D vector uniform in the disc of radius `w` about `centre`: two components, rows
    /// `NAME[x]` and `NAME[y]` of a budget.
    ///
    /// # Errors
    /// `NAME.estimate`, `NAME.radius` as for [`Input::normal`].
    pub fn disc(name: &str, centre: [f64; 2], w: f64) -> Result<Self, MetrologyError> {
        let d = Distribution::Disc { radius: w };
        Self::new(name, centre, d, ("radius", w))
    }

    /// The same input with `dof` degrees of freedom (> 0; infinite allowed).
    ///
    /// # Errors
    /// `NAME.dof` if `dof` is NaN, zero or negative, or minus infinity.
    pub fn with_dof(mut self, dof: f64) -> Result<Self, MetrologyError> {
        if !(dof.is_infinite() && dof > 0.0) {
            positive(format!("{}.dof", self.name), dof)?;
        }
        self.dof = dof;
        Ok(self)
    }

    /// The name.
    #[must_use]
    pub fn name(&self) -> &str {
        &self.name
    }

    /// The best estimate of each component (one value unless a disc).
    #[must_use]
    pub fn estimate(&self) -> &[f64] {
        &self.estimate[..self.distribution.components()]
    }

    /// The distribution.
    #[must_use]
    pub fn distribution(&self) -> Distribution {
        self.distribution
    }

    /// The standard uncertainty of each component.
    #[must_use]
    pub fn standard_uncertainty(&self) -> f64 {
        self.distribution.standard_uncertainty()
    }

    /// The degrees of freedom (infinite unless set).
    #[must_use]
    pub fn dof(&self) -> f64 {
        self.dof
    }

    /// The number of components (2 for a disc, else 1).
    #[must_use]
    pub fn components(&self) -> usize {
        self.distribution.components()
    }

    /// The row name of component `c`: the name, or `NAME[x]` / `NAME[y]` for a disc.
    pub(crate) fn component_name(&self, c: usize) -> String {
        if self.components() == 1 {
            self.name.clone()
        } else {
            format!("{}[{}]", self.name, ["x", "y"][c])
        }
    }
}
