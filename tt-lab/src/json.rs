//! The building blocks of the `--json` schema (issue 20 item 4), shared by every question's
//! view: every answer's JSON is a tree of typed view structs (`Serialize` with the `serde`
//! feature) built from the library's results, its field names the printed keys (the public
//! schema: the Python package's `to_dict()` gives the same), the units stated at the edge
//! (degrees, arcminutes, deg/h: the unit is in the key, `bounds_arcmin`, `objective_arcmin`)
//! where the libraries work in radians. Each question's views sit next to its result, each
//! field's doc comment giving its unit.
//!
//! The command line prints a view through a `serde_json::Value`, so keys come out in
//! alphabetical order; a field skipped (`skip_serializing_if`) is a key absent from the output,
//! an `Option` serialised as `None` is `null`, and a non-finite number is `null`.

use e2e_verify::{CombinedOutput, YieldCount};
use std::collections::BTreeMap;
use tt_core::OrientationAxis;
use tt_kinematics::{ErrorGroup, Turntable};

/// Bounds in arcminutes keyed by error name: `None` (`null`) for an error with no bound (a
/// non-finite bound).
pub(crate) type ArcminBounds = BTreeMap<String, Option<f64>>;

/// [`ArcminBounds`] of upper bounds in radians, `ub_rad[k]` the bound of `names[k]`.
#[must_use]
pub(crate) fn arcmin_bounds(names: &[&str], ub_rad: &[f64]) -> ArcminBounds {
    names
        .iter()
        .zip(ub_rad)
        .map(|(n, u)| {
            (
                (*n).to_string(),
                u.is_finite().then(|| tt_core::units::rad_to_arcmin(*u)),
            )
        })
        .collect()
}

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
pub(crate) fn deg3(r: &[Option<f64>; 3]) -> PerAngle<Option<f64>> {
    PerAngle::new(|a| r[a.index()].map(f64::to_degrees))
}

/// The split of one output's answer between the table and the noise (issue 21), in the
/// output's unit; flattened into the output's object.
#[derive(Debug, Clone)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub(crate) struct Split {
    /// The table's part (the certified worst case, else the linear one), output's unit.
    pub table_part: f64,
    /// Whether `table_part` is certified (second-order bound).
    pub table_certified: bool,
    /// One standard deviation of the noise part, output's unit.
    pub noise_sigma: f64,
    /// The confidence multiplier of the noise part (combined = table + k sigma).
    pub k_sigma: f64,
    /// `table_part + k_sigma * noise_sigma`, output's unit.
    pub combined: f64,
    /// Whether `combined` is within the output's accuracy.
    pub combined_meets: bool,
    /// `table` or `noise`: the larger part.
    pub dominant: &'static str,
}

impl From<&CombinedOutput> for Split {
    fn from(c: &CombinedOutput) -> Self {
        Self {
            table_part: c.table_part(),
            table_certified: c.table_certified(),
            noise_sigma: c.noise_sigma(),
            k_sigma: c.k_sigma(),
            combined: c.combined(),
            combined_meets: c.meets(),
            dominant: c.dominant().name(),
        }
    }
}

/// The yield over turntables and noise.
#[derive(Debug, Clone)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub(crate) struct CombinedYieldJson {
    /// Fraction of calibrations meeting every accuracy, in [0, 1].
    #[cfg_attr(feature = "serde", serde(rename = "yield"))]
    pub yield_fraction: f64,
    /// Its 95% interval (fractions).
    pub yield_interval_95: (f64, f64),
    /// Calibrations simulated (`samples`), the seed of the random streams (`seed`), those
    /// meeting every accuracy (`meeting`) and each output's (`meeting_per_output`).
    #[cfg_attr(feature = "serde", serde(flatten))]
    pub count: YieldCount,
}

impl From<&YieldCount> for CombinedYieldJson {
    fn from(y: &YieldCount) -> Self {
        Self {
            yield_fraction: y.fraction(),
            yield_interval_95: y.interval_95(),
            count: y.clone(),
        }
    }
}

/// A group of errors that act only together ([`tt_kinematics::Turntable::proportional_groups`]).
#[derive(Debug, Clone)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct GroupJson {
    /// The members' names.
    pub errors: Vec<String>,
    /// Their signs relative to the first member.
    pub signs: Vec<f64>,
    /// The combination that matters (`dphi_y1 + deps_y`).
    pub combination: String,
    /// Per labelled box, the combination's bound in arcminutes (`null` when unbounded); absent
    /// when no box is given.
    #[cfg_attr(feature = "serde", serde(skip_serializing_if = "Option::is_none"))]
    pub combined_bound_arcmin: Option<BTreeMap<String, Option<f64>>>,
}

impl GroupJson {
    /// The group `g` of `t`, with its combination's bound under each labelled box of
    /// `bounds` (upper bounds in rad) when there is one.
    #[must_use]
    pub fn new(t: &Turntable, g: &ErrorGroup, bounds: &[(&str, &[f64])]) -> Self {
        let names = t.rotation_error_names();
        Self {
            errors: g.names(&names).into_iter().map(String::from).collect(),
            signs: g.signs.clone(),
            combination: g.combination(&names),
            combined_bound_arcmin: (!bounds.is_empty()).then(|| {
                bounds
                    .iter()
                    .map(|(label, ub)| {
                        let b = g.combined_bound(ub);
                        (
                            (*label).to_string(),
                            b.is_finite().then(|| tt_core::units::rad_to_arcmin(b)),
                        )
                    })
                    .collect()
            }),
        }
    }

    /// Every group of errors that act only together of `t` (none when every error acts alone).
    #[must_use]
    pub fn all(t: &Turntable, bounds: &[(&str, &[f64])]) -> Vec<Self> {
        t.proportional_groups()
            .iter()
            .map(|g| Self::new(t, g, bounds))
            .collect()
    }
}

/// The keys `allocate --json` and `end-to-end --json` both add (flattened into their
/// objects), each absent when it does not apply.
#[derive(Debug, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct ExtrasJson<'a> {
    /// With errors that vary with the shaft angle or measured errors: the allocations under
    /// the study's model.
    #[cfg_attr(feature = "serde", serde(skip_serializing_if = "Option::is_none"))]
    pub angle_dependent: Option<crate::allocation::angle::AngleDependentJson<'a>>,
    /// With `--tolerances`: the sheet's pairs allocated with one tolerance each.
    #[cfg_attr(feature = "serde", serde(skip_serializing_if = "Option::is_none"))]
    pub disc_allocation: Option<crate::vendor::angle::SheetAllocationsJson<'a>>,
    /// With rate steps in the study: the rate tolerances allocated with the angles.
    #[cfg_attr(feature = "serde", serde(skip_serializing_if = "Option::is_none"))]
    pub rate_allocation: Option<crate::vendor::rate::RateAllocationJson<'a>>,
}
