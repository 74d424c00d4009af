//! Coordinate axes and signed axes of the current (moving) frame, right-handed.

use nalgebra::Vector3;
use std::fmt;

/// A coordinate axis of a rotation.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize),
    serde(rename_all = "snake_case")
)]
pub enum Axis {
    /// The $x$ axis.
    X,
    /// The $y$ axis.
    Y,
    /// The $z$ axis.
    Z,
}

impl Axis {
    /// The three axes, $x$ first.
    pub const ALL: [Axis; 3] = [Axis::X, Axis::Y, Axis::Z];

    /// The unit vector along this axis.
    #[must_use]
    pub fn unit(self) -> Vector3<f64> {
        match self {
            Axis::X => Vector3::x(),
            Axis::Y => Vector3::y(),
            Axis::Z => Vector3::z(),
        }
    }

    /// Index of the axis (0, 1, 2 for $x$, $y$, $z$).
    #[must_use]
    pub fn index(self) -> usize {
        match self {
            Axis::X => 0,
            Axis::Y => 1,
            Axis::Z => 2,
        }
    }

    /// `"x"`, `"y"` or `"z"`.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Axis::X => "x",
            Axis::Y => "y",
            Axis::Z => "z",
        }
    }
}

/// An axis of the current (moving) frame with a sign: `x`, `y`, `z`, `-x`, `-y`, `-z`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct SignedAxis {
    /// The coordinate axis.
    pub axis: Axis,
    /// Whether the axis points the other way ($-x$ etc.).
    pub negative: bool,
}

impl SignedAxis {
    /// `+x`.
    pub const X: SignedAxis = SignedAxis::positive(Axis::X);
    /// `+y`.
    pub const Y: SignedAxis = SignedAxis::positive(Axis::Y);
    /// `+z`.
    pub const Z: SignedAxis = SignedAxis::positive(Axis::Z);

    /// The positive direction of `axis`.
    #[must_use]
    pub const fn positive(axis: Axis) -> Self {
        Self {
            axis,
            negative: false,
        }
    }

    /// Parse `x`, `y`, `z`, `-x`, `-y`, `-z` (also `+x` etc.).
    #[must_use]
    pub fn parse(s: &str) -> Option<Self> {
        let (negative, rest) = match s.as_bytes().first() {
            Some(b'-') => (true, &s[1..]),
            Some(b'+') => (false, &s[1..]),
            _ => (false, s),
        };
        let axis = match rest {
            "x" => Axis::X,
            "y" => Axis::Y,
            "z" => Axis::Z,
            _ => return None,
        };
        Some(Self { axis, negative })
    }

    /// $+1$ or $-1$.
    #[must_use]
    pub fn sign(self) -> f64 {
        if self.negative { -1.0 } else { 1.0 }
    }

    /// The unit vector (with its sign).
    #[must_use]
    pub fn unit(self) -> Vector3<f64> {
        self.axis.unit() * self.sign()
    }
}

impl fmt::Display for SignedAxis {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.negative {
            write!(f, "-{}", self.axis.name())
        } else {
            f.write_str(self.axis.name())
        }
    }
}
