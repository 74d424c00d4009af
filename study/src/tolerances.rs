//! Vendor tolerance files: the tolerance of every turntable error, as a data sheet gives
//! them, for the "will this turntable deliver my accuracy?" check.
//!
//! ```toml
//! name = "Vendor X, model Y, data sheet rev 3"   # optional
//! [tolerances_arcmin]   # every angular error of the study's turntable
//! dphi_y1 = 0.4
//! # ...
//! [tolerances_mm]       # optional: error translations (no effect on orientation)
//! deta = 0.1
//! ```

use crate::error::StudyError;
use crate::limits;
use crate::schema::{in_range, one_line, read_text_file, toml_error};
use serde::Deserialize;
use std::collections::BTreeMap;
use std::path::Path;
use tt_core::units::RAD_PER_ARCMIN;
use tt_kinematics::Turntable;

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawTolerances {
    name: Option<String>,
    tolerances_arcmin: BTreeMap<String, f64>,
    tolerances_mm: Option<BTreeMap<String, f64>>,
}

/// A turntable's tolerances: $|\chi_i| \le \mathrm{UB}_i$ for every angular error.
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
}

impl Tolerances {
    /// Read and validate a tolerance file for `turntable`.
    ///
    /// # Errors
    /// A [`StudyError`] naming the file and key.
    pub fn load(path: &Path, turntable: &Turntable) -> Result<Self, StudyError> {
        let text = read_text_file(path, "tolerance file")?;
        Self::parse(&path.display().to_string(), &text, turntable)
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
        let mut ub = vec![None; turntable.n_rotation_errors()];
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
                StudyError::new(at(&key), why)
            })?;
            let (lo, hi) = limits::ANGLE_TOLERANCE_ARCMIN;
            ub[i] = Some(in_range(&at, &key, v, lo, hi, false, "arcmin")? * RAD_PER_ARCMIN);
        }
        let missing: Vec<&str> = turntable
            .rotation_error_names()
            .into_iter()
            .zip(&ub)
            .filter(|(_, u)| u.is_none())
            .map(|(n, _)| n)
            .collect();
        if !missing.is_empty() {
            return Err(StudyError::new(
                at("tolerances_arcmin"),
                format!(
                    "every angular error needs a tolerance; missing: {}",
                    missing.join(", ")
                ),
            ));
        }
        let mut translations_m = vec![None; turntable.n_translation_errors()];
        for (name, &v) in raw.tolerances_mm.iter().flatten() {
            let key = format!("tolerances_mm.{name}");
            let i = turntable
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
            translations_m[i] = Some(in_range(&at, &key, v, lo, hi, false, "mm")? * 1e-3);
        }
        Ok(Self {
            path: source.to_string(),
            name: raw.name,
            ub_rad: ub
                .into_iter()
                .map(|u| u.unwrap_or_else(|| unreachable!("checked")))
                .collect(),
            translations_m,
        })
    }
}
