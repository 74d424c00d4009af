//! Vendor tolerance files: the tolerance of every turntable error, as a data sheet gives
//! them, for the "will this turntable deliver my accuracy?" check.
//!
//! ```toml
//! name = "Vendor X, model Y, data sheet rev 3"   # optional
//! [tolerances_arcmin]   # every angular error of the study's turntable
//! dphi_y1 = 0.4
//! # ...
//! [tolerances_mm]       # optional: error translations (no effect on orientation; at a rate
//! deta = 0.1            # step the accelerometers feel omega^2 times them)
//! [tolerances_ppm]      # optional: a turning joint's rate errors (studies with rate steps)
//! phi1_rate_accuracy = 100   # rate averaged over whole revolutions, |error| <= 100 ppm
//! phi1_rate_ripple = 1000    # first-harmonic ripple over the revolution, each component
//! ```

use crate::Study;
use crate::error::StudyError;
use crate::limits;
use crate::schema::{in_range, one_line, read_text_file, toml_error};
use e2e_verify::E2eError;
use e2e_verify::sheet::{MeasuredError, SheetEntries, ToleranceSheet};
use serde::Deserialize;
use std::collections::BTreeMap;
use std::path::Path;
use tt_core::human::{exact, num};
use tt_core::units::RAD_PER_ARCMIN;
use tt_kinematics::Turntable;

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawTolerances {
    name: Option<String>,
    convention: Option<String>,
    conventions: Option<BTreeMap<String, String>>,
    #[serde(default)]
    tolerances_arcmin: BTreeMap<String, f64>,
    tolerances_mm: Option<BTreeMap<String, f64>>,
    tolerances_ppm: Option<BTreeMap<String, f64>>,
    axes: Option<BTreeMap<String, RawAxis>>,
}

/// A vendor's quantities for one axis (`[axes.<joint>]`), each with the description's errors
/// it bounds.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawAxis {
    wobble_arcsec: Option<f64>,
    wobble: Option<Vec<String>>,
    positioning_accuracy_arcsec: Option<f64>,
    positioning: Option<String>,
    orthogonality_arcsec: Option<f64>,
    orthogonality: Option<Vec<String>>,
    intersection_mm: Option<f64>,
    intersection: Option<Vec<String>>,
}

/// How a sheet's value bounds its error (`convention`, per value `[conventions]`): a $\pm$
/// bound (the default), one standard deviation (the bound taken as $3\sigma$) or
/// peak-to-peak (the bound is half of it).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum ValueConvention {
    /// `bound`: $\lvert\chi\rvert \le v$ (the default).
    Bound,
    /// `one-sigma`: $v = \sigma$, bound $3v$ (99.73% of a normal law).
    OneSigma,
    /// `peak-to-peak`: $\max\chi - \min\chi \le v$, bound $v/2$ about a zero mean.
    PeakToPeak,
}

impl ValueConvention {
    /// The factor from the sheet's value to the bound.
    #[must_use]
    pub(crate) fn factor(self) -> f64 {
        match self {
            ValueConvention::Bound => 1.0,
            ValueConvention::OneSigma => 3.0,
            ValueConvention::PeakToPeak => 0.5,
        }
    }

    /// The name a sheet writes (`bound`, `one-sigma`, `peak-to-peak`).
    #[must_use]
    pub(crate) fn name(self) -> &'static str {
        match self {
            ValueConvention::Bound => "bound",
            ValueConvention::OneSigma => "one-sigma",
            ValueConvention::PeakToPeak => "peak-to-peak",
        }
    }

    fn parse(at: &dyn Fn(&str) -> String, key: &str, v: &str) -> Result<Self, StudyError> {
        match v {
            "bound" => Ok(ValueConvention::Bound),
            "one-sigma" => Ok(ValueConvention::OneSigma),
            "peak-to-peak" => Ok(ValueConvention::PeakToPeak),
            other => Err(StudyError::new(
                at(key),
                format!(
                    "must be \"bound\", \"one-sigma\" or \"peak-to-peak\", found \"{}\"",
                    tt_core::human::visible(other)
                ),
            )),
        }
    }
}

/// A vendor quantity's value (`vkey`) and the list of the description's `what` it bounds
/// (`list_key`): both or neither (`None`); one without the other names the list's key.
fn value_with_list<L>(
    at: &dyn Fn(&str) -> String,
    vkey: &str,
    list_key: &str,
    value: Option<f64>,
    list: Option<L>,
    what: &str,
) -> Result<Option<(f64, L)>, StudyError> {
    match (value, list) {
        (None, None) => Ok(None),
        (Some(v), Some(l)) => Ok(Some((v, l))),
        (None, Some(_)) => Err(StudyError::new(
            at(list_key),
            format!("names the errors of `{vkey}`, which is not given"),
        )),
        (Some(_), None) => Err(StudyError::new(
            at(list_key),
            format!("`{vkey}` needs the description's {what} it bounds (`{list_key}`)"),
        )),
    }
}

/// A vendor quantity of an axis: name, value, the errors it names, the factor range they must
/// lie in, the model it implies.
type Quantity<'a> = (
    &'a str,
    Option<f64>,
    Option<Vec<String>>,
    (usize, usize),
    Option<tt_kinematics::ErrorVariation>,
);

/// A magnitude (disc) bound on two angular errors (e2e-verify's, which the sheet holds).
pub use e2e_verify::sheet::DiscBound;

/// A turntable's tolerances as the file gives them: $|\chi_i| \le \mathrm{UB}_i$ for every
/// angular error. A check takes the [`ToleranceSheet`] a study makes of them
/// ([`Tolerances::sheet`], [`Study::load_sheet`]).
#[derive(Debug, Clone, PartialEq)]
pub struct Tolerances {
    /// The path as the user gave it.
    pub path: String,
    /// The data sheet's name, if given.
    pub name: Option<String>,
    /// $\mathrm{UB}_i$, rad, in the turntable's order of $\chi$.
    pub ub_rad: Vec<f64>,
    /// Translation tolerances, metres, in the turntable's order (None when not given).
    pub translations_m: Vec<Option<f64>>,
    /// Magnitude bounds on pairs of errors (`[axes.<joint>]` wobble and orthogonality): the
    /// members' entries of `ub_rad` hold the square around the disc, $w$ each.
    pub discs: Vec<DiscBound>,
    /// The error model a vendor quantity implies per error (order of $\chi$): a wobble or a
    /// positioning accuracy bounds an error over the revolution of its axis (`any` of the
    /// joint), an orthogonality a constant; `None` for a value of `[tolerances_arcmin]`.
    pub implied: Vec<Option<tt_kinematics::ErrorVariation>>,
    /// Each joint's rate accuracy bound (relative; `[tolerances_ppm]`
    /// `<joint>_rate_accuracy` / $10^6$), `None` when not given.
    pub rate_accuracy: Vec<Option<f64>>,
    /// Each joint's rate ripple bound (relative, each of its two components;
    /// `<joint>_rate_ripple` / $10^6$), `None` when not given.
    pub rate_ripple: Vec<Option<f64>>,
}

impl Tolerances {
    /// Read and validate a tolerance file for `turntable`.
    ///
    /// # Errors
    /// A [`StudyError`] naming the file and key.
    pub fn load(path: &Path, turntable: &Turntable) -> Result<Self, StudyError> {
        let text = read_text_file(path, "tolerance file")?;
        // named in messages and outputs as one visible line (a line feed in the name cannot
        // forge a line)
        Self::parse(
            &tt_core::human::visible(&path.display().to_string()),
            &text,
            turntable,
        )
    }

    /// Parse tolerance text for `turntable`; `source` names it in errors.
    ///
    /// # Errors
    /// A [`StudyError`]: an unknown error name, a missing angular error, a value outside
    /// [`limits::ANGLE_TOLERANCE_ARCMIN`] or [`limits::TRANSLATION_TOLERANCE_MM`].
    pub fn parse(source: &str, text: &str, turntable: &Turntable) -> Result<Self, StudyError> {
        let raw: RawTolerances = toml::from_str(text).map_err(|e| toml_error(source, text, &e))?;
        let at = |key: &str| format!("{source}: key `{key}`");
        if let Some(name) = &raw.name {
            one_line(&at, "name", name)?;
        }
        let default = match &raw.convention {
            Some(c) => ValueConvention::parse(&at, "convention", c)?,
            None => ValueConvention::Bound,
        };
        let r = SheetReader {
            source,
            turntable,
            default,
            conventions: raw.conventions.clone().unwrap_or_default(),
        };
        r.check_convention_keys(&raw)?;
        let mut b = Bounds {
            ub: vec![None; turntable.n_rotation_errors()],
            implied: vec![None; turntable.n_rotation_errors()],
            discs: Vec::new(),
            translations_m: vec![None; turntable.n_translation_errors()],
        };
        r.angular_tolerances(&raw, &mut b)?;
        let mut axis_intersections = Vec::new();
        for (joint, ax) in raw.axes.iter().flatten() {
            axis_intersections.push(r.axis_quantities(joint, ax, &mut b)?);
        }
        r.check_every_angle_bounded(&b.ub)?;
        r.translation_tolerances(&raw, &mut b)?;
        // a vendor's axis intersection (the distance between this axis and the previous one):
        // each named translation between the two joints gets the bound (with two components,
        // the square around the disc: translations act only at rate steps, whose worst case
        // takes boxes)
        let axes = raw.axes.as_ref();
        for (j, jkey, prev, jf) in axis_intersections {
            let ax = &axes
                .and_then(|a| a.get(&jkey["axes.".len()..]))
                .unwrap_or_else(|| unreachable!("collected from the sheet's axes"));
            r.axis_intersection(j, &jkey, (prev, jf), ax, &mut b)?;
        }
        let (rate_accuracy, rate_ripple) = r.rate_tolerances(&raw)?;
        Ok(Self {
            rate_accuracy,
            rate_ripple,
            path: source.to_string(),
            name: raw.name,
            ub_rad: b
                .ub
                .into_iter()
                .map(|u| u.unwrap_or_else(|| unreachable!("checked")))
                .collect(),
            translations_m: b.translations_m,
            discs: b.discs,
            implied: b.implied,
        })
    }
}

/// The reading of one tolerance sheet: where it comes from, the turntable it describes, its
/// value conventions (`convention`, `[conventions]`).
struct SheetReader<'a> {
    source: &'a str,
    turntable: &'a Turntable,
    default: ValueConvention,
    conventions: BTreeMap<String, String>,
}

/// The bounds a sheet gives, read so far (radians, metres), in the turntable's orders.
struct Bounds {
    ub: Vec<Option<f64>>,
    implied: Vec<Option<tt_kinematics::ErrorVariation>>,
    discs: Vec<DiscBound>,
    translations_m: Vec<Option<f64>>,
}

/// An axis given in `[axes]`: its joint index, `axes.<joint>`, and the factor range of the
/// errors between the previous joint and this one.
type AxisIntersection = (usize, String, usize, usize);

/// Each joint's rate accuracy and rate ripple bounds (relative), `None` when not given.
type RateBounds = (Vec<Option<f64>>, Vec<Option<f64>>);

impl SheetReader<'_> {
    /// A key's location in messages.
    fn at(&self, key: &str) -> String {
        format!("{}: key `{key}`", self.source)
    }

    /// The value of `key` (its unit `unit`, limits `(lo, hi)`) checked as written, then the
    /// bound its convention makes of it checked against the same documented maximum
    /// (`[conventions]` names a value by `name`).
    fn bound_of(
        &self,
        key: &str,
        name: &str,
        v: f64,
        (lo, hi): (f64, f64),
        unit: &str,
    ) -> Result<f64, StudyError> {
        let at = |k: &str| self.at(k);
        let v = in_range(&at, key, v, lo, hi, false, unit)?;
        let (convention, ckey) = match self.conventions.get(name) {
            Some(c) => (
                ValueConvention::parse(&at, &format!("conventions.{name}"), c)?,
                format!("conventions.{name}"),
            ),
            None => (self.default, "convention".to_string()),
        };
        let bound = v * convention.factor();
        if bound > hi {
            return Err(StudyError::new(
                at(key),
                format!(
                    "{} {unit} read as `{ckey}` = \"{}\" bounds the error by {} {unit}, above the largest bound accepted ({} {unit})",
                    exact(v),
                    convention.name(),
                    num(bound),
                    num(hi)
                ),
            ));
        }
        Ok(bound)
    }

    /// Every key of `[conventions]` names a value of the sheet.
    fn check_convention_keys(&self, raw: &RawTolerances) -> Result<(), StudyError> {
        for key in self.conventions.keys() {
            let known = raw.tolerances_arcmin.contains_key(key)
                || key.strip_prefix("axes.").is_some_and(|rest| {
                    rest.rsplit_once('.').is_some_and(|(j, q)| {
                        raw.axes
                            .as_ref()
                            .and_then(|a| a.get(j))
                            .is_some_and(|ax| match q {
                                "wobble_arcsec" => ax.wobble_arcsec.is_some(),
                                "positioning_accuracy_arcsec" => {
                                    ax.positioning_accuracy_arcsec.is_some()
                                }
                                "orthogonality_arcsec" => ax.orthogonality_arcsec.is_some(),
                                "intersection_mm" => ax.intersection_mm.is_some(),
                                _ => false,
                            })
                    })
                });
            if !known {
                return Err(StudyError::new(
                    self.at(&format!("conventions.{key}")),
                    "names no value of this sheet (a [tolerances_arcmin] error or axes.<joint>.<quantity>)",
                ));
            }
        }
        Ok(())
    }

    /// `[tolerances_arcmin]`: one bound per named angular error.
    fn angular_tolerances(&self, raw: &RawTolerances, b: &mut Bounds) -> Result<(), StudyError> {
        let turntable = self.turntable;
        for (name, &v) in &raw.tolerances_arcmin {
            let key = format!("tolerances_arcmin.{name}");
            let i = turntable.rotation_error_index(name).ok_or_else(|| {
                let why = if turntable.translation_error_names().contains(&name.as_str()) {
                    format!("`{name}` is a translation: give it in [tolerances_mm]")
                } else {
                    format!(
                        "`{name}` is not an angular error of the study's turntable ({})",
                        turntable.rotation_error_names().join(", ")
                    )
                };
                StudyError::new(self.at(&key), why)
            })?;
            b.ub[i] = Some(
                self.bound_of(&key, name, v, limits::ANGLE_TOLERANCE_ARCMIN, "arcmin")?
                    * RAD_PER_ARCMIN,
            );
        }
        Ok(())
    }

    /// `[axes.<joint>]`: its wobble, positioning accuracy and orthogonality mapped onto the
    /// errors they name; the axis returned for its intersection (read after the translations).
    fn axis_quantities(
        &self,
        joint: &str,
        ax: &RawAxis,
        b: &mut Bounds,
    ) -> Result<AxisIntersection, StudyError> {
        let turntable = self.turntable;
        let jkey = format!("axes.{joint}");
        let Some(j) = turntable.joint_index(joint) else {
            return Err(StudyError::new(
                self.at(&jkey),
                format!(
                    "the sheet gives quantities of axis `{}`, which the study's turntable does not have (joints: {})",
                    tt_core::human::visible(joint),
                    turntable.joint_names().join(", ")
                ),
            ));
        };
        let jf = turntable.joints()[j].factor;
        let next = turntable
            .joints()
            .get(j + 1)
            .map_or(usize::MAX, |n| n.factor);
        let prev = if j == 0 {
            0
        } else {
            turntable.joints()[j - 1].factor
        };
        let any = || {
            Some(tt_kinematics::ErrorVariation::Any {
                joint: joint.to_string(),
            })
        };
        // (quantity, value, errors, where they must sit, implied model)
        let quantities: [Quantity<'_>; 3] = [
            (
                "wobble",
                ax.wobble_arcsec,
                ax.wobble.clone(),
                (jf, next),
                any(),
            ),
            (
                "positioning_accuracy",
                ax.positioning_accuracy_arcsec,
                ax.positioning.clone().map(|p| vec![p]),
                (jf, next),
                any(),
            ),
            (
                "orthogonality",
                ax.orthogonality_arcsec,
                ax.orthogonality.clone(),
                (prev, jf),
                Some(tt_kinematics::ErrorVariation::Constant),
            ),
        ];
        for quantity in quantities {
            self.axis_quantity(j, joint, &jkey, quantity, b)?;
        }
        Ok((j, jkey, prev, jf))
    }

    /// One quantity of axis `joint` (index `j`, key `jkey`): its bound on each error it names.
    fn axis_quantity(
        &self,
        j: usize,
        joint: &str,
        jkey: &str,
        (q, value, errors, (lo_f, hi_f), model): Quantity<'_>,
        b: &mut Bounds,
    ) -> Result<(), StudyError> {
        let turntable = self.turntable;
        let vkey = format!("{jkey}.{q}_arcsec");
        let list_key = format!(
            "{jkey}.{}",
            if q == "positioning_accuracy" {
                "positioning"
            } else {
                q
            }
        );
        let at = |k: &str| self.at(k);
        let Some((value, errors)) =
            value_with_list(&at, &vkey, &list_key, value, errors, "errors")?
        else {
            return Ok(());
        };
        let want = if q == "positioning_accuracy" { 1 } else { 2 };
        if errors.len() != want {
            return Err(StudyError::new(
                at(&list_key),
                format!(
                    "{q} bounds {want} error(s) of the axis, found {}",
                    errors.len()
                ),
            ));
        }
        let (lo, hi) = limits::ANGLE_TOLERANCE_ARCMIN;
        let bound = self.bound_of(&vkey, &vkey, value, (lo * 60.0, hi * 60.0), "arcsec")? / 60.0
            * RAD_PER_ARCMIN;
        let mut idx = Vec::with_capacity(want);
        for (k, e) in errors.iter().enumerate() {
            let ekey = format!("{list_key}[{k}]");
            let ekey = if want == 1 { list_key.clone() } else { ekey };
            let Some(i) = turntable.rotation_error_index(e) else {
                return Err(StudyError::new(
                    at(&ekey),
                    format!(
                        "`{}` is not an angular error of the study's turntable",
                        tt_core::human::visible(e)
                    ),
                ));
            };
            let f = turntable.rotation_errors()[i].factor;
            if !(f > lo_f && f < hi_f) || (q == "orthogonality" && j == 0) {
                return Err(StudyError::new(
                    at(&ekey),
                    format!(
                        "`{e}` does not map onto the {q} of axis `{joint}`: it is not {} in the chain",
                        if q == "orthogonality" {
                            "between the previous joint and this one"
                        } else {
                            "between this joint and the next"
                        }
                    ),
                ));
            }
            if q == "positioning_accuracy"
                && turntable.rotation_errors()[i].axis.axis != turntable.joints()[j].about.axis
            {
                return Err(StudyError::new(
                    at(&ekey),
                    format!(
                        "`{e}` does not turn about the axis of `{joint}`: it is not its position error"
                    ),
                ));
            }
            if b.ub[i].is_some() {
                return Err(StudyError::new(
                    at(&ekey),
                    format!("`{e}` is bounded twice (also by another value of this sheet)"),
                ));
            }
            b.ub[i] = Some(bound);
            b.implied[i] = model.clone();
            idx.push(i);
        }
        if want == 2 {
            b.discs.push(DiscBound {
                key: vkey,
                errors: [idx[0], idx[1]],
                bound_rad: bound,
            });
        }
        Ok(())
    }

    /// Every angular error has a bound.
    fn check_every_angle_bounded(&self, ub: &[Option<f64>]) -> Result<(), StudyError> {
        let missing: Vec<&str> = self
            .turntable
            .rotation_error_names()
            .into_iter()
            .zip(ub)
            .filter(|(_, u)| u.is_none())
            .map(|(n, _)| n)
            .collect();
        if !missing.is_empty() {
            return Err(StudyError::new(
                self.at("tolerances_arcmin"),
                format!(
                    "every angular error needs a tolerance; missing: {}",
                    missing.join(", ")
                ),
            ));
        }
        Ok(())
    }

    /// `[tolerances_mm]`: one bound per named translation error.
    fn translation_tolerances(
        &self,
        raw: &RawTolerances,
        b: &mut Bounds,
    ) -> Result<(), StudyError> {
        let at = |k: &str| self.at(k);
        for (name, &v) in raw.tolerances_mm.iter().flatten() {
            let key = format!("tolerances_mm.{name}");
            let i = self
                .turntable
                .translation_error_names()
                .iter()
                .position(|n| *n == name)
                .ok_or_else(|| {
                    StudyError::new(
                        at(&key),
                        format!("`{name}` is not a translation error of the study's turntable"),
                    )
                })?;
            let (lo, hi) = limits::TRANSLATION_TOLERANCE_MM;
            b.translations_m[i] = Some(in_range(&at, &key, v, lo, hi, false, "mm")? * 1e-3);
        }
        Ok(())
    }

    /// `axes.<joint>.intersection_mm` of axis `j` (key `jkey`, the factor range `(prev, jf)`
    /// of the errors before it): its bound on each translation it names.
    fn axis_intersection(
        &self,
        j: usize,
        jkey: &str,
        (prev, jf): (usize, usize),
        ax: &RawAxis,
        b: &mut Bounds,
    ) -> Result<(), StudyError> {
        let turntable = self.turntable;
        let at = |k: &str| self.at(k);
        let (vkey, list_key) = (
            format!("{jkey}.intersection_mm"),
            format!("{jkey}.intersection"),
        );
        let Some((value, errors)) = value_with_list(
            &at,
            &vkey,
            &list_key,
            ax.intersection_mm,
            ax.intersection.as_ref(),
            "translations",
        )?
        else {
            return Ok(());
        };
        if !(1..=2).contains(&errors.len()) {
            return Err(StudyError::new(
                at(&list_key),
                format!(
                    "an intersection bounds 1 or 2 translations, found {}",
                    errors.len()
                ),
            ));
        }
        let bound =
            self.bound_of(&vkey, &vkey, value, limits::TRANSLATION_TOLERANCE_MM, "mm")? * 1e-3;
        for (k, e) in errors.iter().enumerate() {
            let ekey = if errors.len() == 1 {
                list_key.clone()
            } else {
                format!("{list_key}[{k}]")
            };
            let Some(i) = turntable
                .translation_error_names()
                .iter()
                .position(|n| n == e)
            else {
                return Err(StudyError::new(
                    at(&ekey),
                    format!(
                        "`{}` is not a translation error of the study's turntable",
                        tt_core::human::visible(e)
                    ),
                ));
            };
            let f = turntable.translation_errors()[i].factor;
            if j == 0 || !(f > prev && f < jf) {
                return Err(StudyError::new(
                    at(&ekey),
                    format!(
                        "`{e}` does not map onto the intersection of axis `{}`: it is not between the previous joint and this one in the chain",
                        &jkey["axes.".len()..]
                    ),
                ));
            }
            if b.translations_m[i].is_some() {
                return Err(StudyError::new(
                    at(&ekey),
                    format!("`{e}` is bounded twice (also by another value of this sheet)"),
                ));
            }
            b.translations_m[i] = Some(bound);
        }
        Ok(())
    }

    /// `[tolerances_ppm]`: each joint's rate accuracy and rate ripple (relative).
    fn rate_tolerances(&self, raw: &RawTolerances) -> Result<RateBounds, StudyError> {
        let turntable = self.turntable;
        let at = |k: &str| self.at(k);
        let mut rate_accuracy = vec![None; turntable.n_joints()];
        let mut rate_ripple = vec![None; turntable.n_joints()];
        for (name, &v) in raw.tolerances_ppm.iter().flatten() {
            let key = format!("tolerances_ppm.{name}");
            let parsed = [("_rate_accuracy", 0), ("_rate_ripple", 1)]
                .iter()
                .find_map(|(suffix, kind)| {
                    name.strip_suffix(suffix)
                        .and_then(|j| turntable.joint_index(j))
                        .map(|j| (j, *kind))
                });
            let Some((j, kind)) = parsed else {
                return Err(StudyError::new(
                    at(&key),
                    format!(
                        "expected `<joint>_rate_accuracy` or `<joint>_rate_ripple` for a joint of the study's turntable ({})",
                        turntable.joint_names().join(", ")
                    ),
                ));
            };
            let (lo, hi) = limits::RATE_TOLERANCE_PPM;
            let value = in_range(&at, &key, v, lo, hi, false, "ppm")? * 1e-6;
            if kind == 0 {
                rate_accuracy[j] = Some(value);
            } else {
                rate_ripple[j] = Some(value);
            }
        }
        Ok((rate_accuracy, rate_ripple))
    }
}

impl Tolerances {
    /// The sheet's entries as e2e-verify's [`SheetEntries`].
    #[must_use]
    pub fn entries(&self) -> SheetEntries {
        SheetEntries {
            name: self.name.clone(),
            upper_bounds_rad: self.ub_rad.clone(),
            translations_m: self.translations_m.clone(),
            discs: self.discs.clone(),
            implied: self.implied.clone(),
            rate_accuracy: self.rate_accuracy.clone(),
            rate_ripple: self.rate_ripple.clone(),
        }
    }

    /// The [`ToleranceSheet`] of these tolerances for the study `s`: with its lower bounds
    /// (held within the sheet's) and its measured errors
    /// (`[[compensation.measured]]`).
    ///
    /// # Errors
    /// A [`StudyError`] naming the measurement's key and the sheet's bound when a measured
    /// error reaches, somewhere on the revolution, a magnitude above the sheet's bound (the
    /// measured table is outside its specification, which a check assumes it meets); naming
    /// the sheet otherwise.
    pub fn sheet(&self, s: &Study) -> Result<ToleranceSheet, StudyError> {
        let measured = s
            .measured
            .iter()
            .zip(&s.variations)
            .map(|(m, v)| {
                m.as_ref().map(|m| MeasuredError {
                    key: m.key.clone(),
                    variation: v.clone(),
                    coefficients_rad: m.coefficients_rad.clone(),
                    uncertainty_rad: m.uncertainty_rad,
                })
            })
            .collect();
        ToleranceSheet::new(
            &s.turntable,
            &self.path,
            self.entries(),
            &s.lower_bounds_rad,
            measured,
        )
        .map_err(|e| match e {
            E2eError::MeasuredOutsideSheet {
                reached_rad, error, ..
            } => {
                let j = s
                    .turntable
                    .rotation_error_index(&error)
                    .unwrap_or_else(|| unreachable!("named by the sheet's turntable"));
                let m = s.measured[j]
                    .as_ref()
                    .unwrap_or_else(|| unreachable!("a measured error"));
                let written: Vec<String> = m.written_arcmin.iter().map(|v| exact(*v)).collect();
                let value = if written.len() == 1 {
                    written[0].clone()
                } else {
                    format!("[{}]", written.join(", "))
                };
                StudyError::new(
                    format!("{}: key `{}`", s.path, m.key),
                    format!(
                        "the measured `{error}` = {value} arcmin reaches {} arcmin, above the sheet's {}: the measured table is outside its specification, which the check assumes it meets; check the measurement, or check a sheet that bounds this table",
                        num(tt_core::units::rad_to_arcmin(reached_rad)),
                        bound_words(s, self.implied[j].is_none(), &self.path, j, self.ub_rad[j]),
                    ),
                )
            }
            other => StudyError::new(&self.path, other.to_string()),
        })
    }
}

/// The sheet's bound of error `j` in words, as messages and notes name it: its key
/// (`` `tolerances_arcmin.<error>` `` when `plain`, else the bound its `[axes]` entry gives),
/// value in arcmin and the sheet's path.
fn bound_words(s: &Study, plain: bool, path: &str, j: usize, ub_rad: f64) -> String {
    let name = s.turntable.rotation_error_names()[j];
    let key = if plain {
        format!("`tolerances_arcmin.{name}`")
    } else {
        format!("the bound of `{name}` its `[axes]` entry gives")
    };
    format!(
        "{key} = {} arcmin of {}",
        num(tt_core::units::rad_to_arcmin(ub_rad)),
        tt_core::human::visible(path)
    )
}

/// The sheet's bound of error `j` of `sheet` in words (its key, value in arcmin and path),
/// as a note about a measured error names it.
#[must_use]
pub fn sheet_bound_words(s: &Study, sheet: &ToleranceSheet, j: usize) -> String {
    bound_words(
        s,
        sheet.implied()[j].is_none(),
        sheet.source(),
        j,
        sheet.upper_bounds_rad()[j],
    )
}

impl Study {
    /// Read the tolerance file at `path` and make its [`ToleranceSheet`] for this study
    /// ([`Tolerances::load`], [`Tolerances::sheet`]).
    ///
    /// # Errors
    /// As [`Tolerances::load`] and [`Tolerances::sheet`].
    pub fn load_sheet(&self, path: &Path) -> Result<ToleranceSheet, StudyError> {
        Tolerances::load(path, &self.turntable)?.sheet(self)
    }
}
