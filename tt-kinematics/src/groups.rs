//! Errors that only act together: sets of angular errors whose first-order effects are
//! proportional at every pose, so that no calibration, tolerance check or allocation can tell
//! them apart; only their signed sum matters.
//!
//! # Formula
//! To first order the orientation error is $\boldsymbol\delta = \sum_i \chi_i\mathbf v_i(\phi)$
//! with $\mathbf v_i(\phi) = \mathbf S_j^T\hat e_j$ ([`crate::linear`]): $\hat e_j$ the (signed)
//! axis of the error's factor $F_j$, $\mathbf S_j = \mathbf N_1\cdots\mathbf N_m$ the nominal
//! factors (joints and fixed rotations) after it. Every $\mathbf v_i$ is a unit vector, so two
//! columns are proportional at every pose only with ratio $\pm1$, and then every output of any
//! sensor, under any schedule and reading, sees $\chi_a \pm \chi_b$ only.
//!
//! # Structural detection (exact)
//! Walk from the error towards the platform with $\mathbf w = \hat e_j$: skip translations and
//! other error rotations (zero at the linearisation point), replace $\mathbf w$ by
//! $\mathbf F^T\mathbf w$ at a fixed rotation $\mathbf F$, and pass a joint whose axis is
//! $\pm\mathbf w$ (a rotation leaves its own axis fixed); stop at the first joint whose axis is
//! not $\pm\mathbf w$, at factor $k$ (or at the end of the chain, $k = n$). Then
//! $\mathbf v_i(\phi) = (\mathbf N_k\cdots\mathbf N_m)^T\mathbf w$: the error's **key** is
//! $(k, \pm\mathbf w)$, and two errors are proportional at every pose **if and only if** their
//! keys are equal:
//!
//! - equal keys: the same orthogonal matrix applied to $\mathbf w = \pm\mathbf w'$;
//! - the same $k$, $\mathbf w \ne \pm\mathbf w'$: the same orthogonal matrix applied to two
//!   unit vectors that are not $\pm$ each other, at every pose;
//! - $k < k'$: multiply both by $(\mathbf N_{k'}\cdots\mathbf N_m)$; the second becomes the
//!   constant $\mathbf w'$, the first $\mathbf M^T R_a(\phi_k)^T\mathbf w$ with $\mathbf M$ free
//!   of $\phi_k$ (every joint appears once). Since $\mathbf w$ is not along the joint's axis
//!   $a$, $R_a(\phi_k)^T\mathbf w$ runs along a circle of positive radius while $\phi_k$ sweeps
//!   its range (a range has positive width), so it cannot stay equal to $\pm\mathbf w'$.
//!
//! Axes of joints and errors are exact unit vectors, so without fixed rotations every
//! comparison is exact. A fixed rotation puts rounding of order $10^{-16}$ into $\mathbf w$:
//! components are compared within [`GROUP_AXIS_TOLERANCE`].
//!
//! # Example: a wobble about the next joint's axis is that joint's position error
//! ```
//! use tt_kinematics::{FactorSpec, SignedAxis, Turntable, TurntableDescription};
//! let j = FactorSpec::joint;
//! let e = FactorSpec::error;
//! let t = Turntable::new(&TurntableDescription::new(vec![
//!     j("outer", SignedAxis::Z), e("wobble_x", SignedAxis::X), e("tilt_y", SignedAxis::Y),
//!     j("inner", SignedAxis::X), e("d_inner", SignedAxis::X),
//! ]))?;
//! let groups = t.proportional_groups();
//! assert_eq!(groups.len(), 1);
//! assert_eq!(groups[0].combination(&t.rotation_error_names()), "wobble_x + d_inner");
//! # Ok::<(), tt_kinematics::KinematicsError>(())
//! ```

use crate::rotation::rot_signed;
use crate::turntable::{Factor, Turntable};
use nalgebra::Vector3;

/// Two unit vectors of the structural walk are the same (or opposite) when every component
/// differs by at most this (unitless). Rounding of a chain of fixed rotations stays near
/// $10^{-16}$ per rotation; a vector off an axis by less than $10^{-12}$ rad turns through a
/// circle of radius below $10^{-12}$, an effect below any turntable error ($10^{-7}$ rad is
/// 0.02 arcsec) by five orders of magnitude.
pub const GROUP_AXIS_TOLERANCE: f64 = 1e-12;

/// A set of angular errors (two or more, or one for [`Turntable::error_groups`]) whose
/// first-order effects are proportional at every pose: $\mathbf v_{e_k} = s_k\mathbf v_{e_0}$.
/// Only the combination $\sum_k s_k\chi_{e_k}$ reaches the orientation, so only it matters to
/// any output, share or allocation.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct ErrorGroup {
    /// The errors (indices in $\chi$, increasing).
    pub errors: Vec<usize>,
    /// The sign $s_k = \pm1$ of each error relative to the first (the first is $+1$).
    pub signs: Vec<f64>,
}

impl ErrorGroup {
    /// Whether the group has two or more errors.
    #[must_use]
    pub(crate) fn is_proper(&self) -> bool {
        self.errors.len() > 1
    }

    /// The combination that matters, e.g. `dphi_o + deps_om_z` (or `a - b` for an opposite
    /// sign); a single error's name for a group of one. `names` are the turntable's
    /// [`Turntable::rotation_error_names`].
    #[must_use]
    pub fn combination(&self, names: &[&str]) -> String {
        let mut s = String::new();
        for (k, (&e, &sign)) in self.errors.iter().zip(&self.signs).enumerate() {
            if k > 0 {
                s.push_str(if sign < 0.0 { " - " } else { " + " });
            }
            s.push_str(names.get(e).copied().unwrap_or("?"));
        }
        s
    }

    /// The members' names, in order.
    #[must_use]
    pub fn names<'a>(&self, names: &[&'a str]) -> Vec<&'a str> {
        self.errors
            .iter()
            .map(|&e| names.get(e).copied().unwrap_or("?"))
            .collect()
    }

    /// The largest $|\sum_k s_k\chi_{e_k}|$ over $|\chi_i| \le \mathrm{UB}_i$: the sum of the
    /// members' bounds (rad; infinite when one is).
    #[must_use]
    pub fn combined_bound(&self, upper_bounds: &[f64]) -> f64 {
        self.errors
            .iter()
            .map(|&e| upper_bounds.get(e).copied().unwrap_or(f64::INFINITY))
            .sum()
    }

    /// The sum of `per_error[e]` over the members (shares of a worst case or of a variance).
    #[must_use]
    pub fn sum(&self, per_error: &[f64]) -> f64 {
        self.errors
            .iter()
            .map(|&e| per_error.get(e).copied().unwrap_or(0.0))
            .sum()
    }
}

/// The key of the structural walk: factor index of the first joint that moves the vector (or
/// the number of factors), and the vector there.
fn key(t: &Turntable, start: usize, axis: Vector3<f64>) -> (usize, Vector3<f64>) {
    let factors = t.factors();
    let mut w = axis;
    for (k, f) in factors.iter().enumerate().skip(start + 1) {
        match *f {
            Factor::Joint { about, .. } => {
                let a = about.unit();
                if !same_line(&w, &a) {
                    return (k, w);
                }
            }
            Factor::Fixed { angle_rad, about } => w = rot_signed(about, angle_rad).transpose() * w,
            Factor::Rotation { .. } | Factor::Translation { .. } => {}
        }
    }
    (factors.len(), w)
}

fn close(a: &Vector3<f64>, b: &Vector3<f64>) -> bool {
    (a - b).amax() <= GROUP_AXIS_TOLERANCE
}

fn same_line(a: &Vector3<f64>, b: &Vector3<f64>) -> bool {
    close(a, b) || close(a, &-b)
}

impl Turntable {
    /// Every angular error in exactly one group, groups ordered by their first error (the
    /// order of $\chi$): singletons for errors that act alone. See the [module](crate::groups).
    #[must_use]
    pub fn error_groups(&self) -> Vec<ErrorGroup> {
        let keys: Vec<(usize, Vector3<f64>)> = self
            .rotation_errors()
            .iter()
            .map(|e| key(self, e.factor, e.axis.unit()))
            .collect();
        let mut groups: Vec<ErrorGroup> = Vec::new();
        let mut assigned = vec![false; keys.len()];
        for i in 0..keys.len() {
            if assigned[i] {
                continue;
            }
            let mut g = ErrorGroup {
                errors: vec![i],
                signs: vec![1.0],
            };
            for j in i + 1..keys.len() {
                if assigned[j] || keys[j].0 != keys[i].0 {
                    continue;
                }
                let sign = if close(&keys[j].1, &keys[i].1) {
                    1.0
                } else if close(&keys[j].1, &-keys[i].1) {
                    -1.0
                } else {
                    continue;
                };
                assigned[j] = true;
                g.errors.push(j);
                g.signs.push(sign);
            }
            groups.push(g);
        }
        groups
    }

    /// The groups of two or more angular errors whose first-order effects are proportional at
    /// every pose (exact structural detection, see the [module](crate::groups)); empty when
    /// every error acts on its own.
    #[must_use]
    pub fn proportional_groups(&self) -> Vec<ErrorGroup> {
        self.error_groups()
            .into_iter()
            .filter(ErrorGroup::is_proper)
            .collect()
    }
}
