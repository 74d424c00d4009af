//! Small building blocks of the answers' JSON views (serialised with the `serde` feature):
//! one value per orientation angle, keyed by the angle's one spelling.

use tt_core::OrientationAxis;

/// One value per orientation angle, keyed by its one spelling ([`OrientationAxis::name`]:
/// `psi`, `theta`, `gamma`).
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct PerAngle<T> {
    /// Delta psi, the rotation error about y.
    pub psi: T,
    /// Delta theta, the rotation error about z.
    pub theta: T,
    /// Delta gamma, the rotation error about x.
    pub gamma: T,
}

impl<T> PerAngle<T> {
    /// The value of every angle from `f`.
    pub fn new(f: impl Fn(OrientationAxis) -> T) -> Self {
        Self {
            psi: f(OrientationAxis::Psi),
            theta: f(OrientationAxis::Theta),
            gamma: f(OrientationAxis::Gamma),
        }
    }

    /// The value of angle `a`.
    pub fn get(&self, a: OrientationAxis) -> &T {
        match a {
            OrientationAxis::Psi => &self.psi,
            OrientationAxis::Theta => &self.theta,
            OrientationAxis::Gamma => &self.gamma,
        }
    }
}

/// A requirement-like triple (psi, theta, gamma; `None` where an angle has none) in degrees.
#[must_use]
pub fn deg3(r: &[Option<f64>; 3]) -> PerAngle<Option<f64>> {
    PerAngle::new(|a| r[a.index()].map(f64::to_degrees))
}
