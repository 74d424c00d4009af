//! Turntables as CSV rows (for `orientation-error` and `calibration-error`): a header naming
//! every joint `<joint>_deg` (when the rows are poses, [`JointColumns::Required`]; rows that
//! act at every position of a schedule have none, [`JointColumns::Absent`]), every angular
//! error `<error>_arcmin` and every error translation `<error>_mm` of a study's turntable, in
//! any order, all required; one turntable per row.
//!
//! A UTF-8 byte-order mark before the header is accepted; blank lines are skipped; fields may
//! be surrounded by spaces. Every problem is a [`StudyError`] at `file:line` (and column).
//! A CSV reader that unquotes fields (RFC 4180, `tt_lab::rows::read_rows`) hands them over
//! already split ([`TurntableColumns::from_header_fields`], [`TurntableColumns::parse_fields`]).

use crate::error::StudyError;
use crate::limits;
use tt_core::units::{RAD_PER_ARCMIN, RAD_PER_DEG};
use tt_kinematics::Turntable;

/// What one CSV column holds.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Slot {
    Joint(usize),
    Rotation(usize),
    Translation(usize),
}

/// One parsed row: the pose and the errors of one turntable (radians, metres).
#[derive(Debug, Clone, PartialEq)]
pub struct TurntableRow {
    /// Joint angles, rad, joint order.
    pub pose_rad: Vec<f64>,
    /// Angular errors, rad, order of chi.
    pub chi_rad: Vec<f64>,
    /// Error translations, m.
    pub translations_m: Vec<f64>,
}

/// The column layout of a turntable CSV, from its header.
#[derive(Debug, Clone, PartialEq)]
pub struct TurntableColumns {
    slots: Vec<Slot>,
    names: Vec<String>,
    joints: usize,
    rotations: usize,
    translations: usize,
}

/// Whether the rows carry joint angles.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum JointColumns {
    /// Every joint has a `<joint>_deg` column (each row is a turntable at a pose).
    Required,
    /// No joint column is accepted (each row is a turntable; the poses come from elsewhere,
    /// for example a study's schedule).
    Absent,
}

/// The output columns of `calibration-error` for a sensor, each with the study key it is
/// derived from: `<coefficient>_error` for every estimated coefficient (study order), then
/// `<output>_rate_error` for every output. A study whose columns collide (a coefficient
/// named `x_rate` beside an output `x`) is refused when read.
#[must_use]
pub fn calibration_error_columns(sensor: &gw_model::SensorModel) -> Vec<(String, String)> {
    let mut cols = Vec::new();
    for (k, o) in sensor.outputs().iter().enumerate() {
        for (t, term) in o.terms.iter().enumerate() {
            if !term.known {
                cols.push((
                    format!("{}_error", term.coefficient),
                    format!("sensor.outputs[{k}].terms[{t}].coefficient"),
                ));
            }
        }
    }
    for (k, o) in sensor.outputs().iter().enumerate() {
        cols.push((
            format!("{}_rate_error", o.name),
            format!("sensor.outputs[{k}].name"),
        ));
    }
    cols
}

/// The header the turntable's CSV uses in the study's order: joints, angular errors,
/// translations.
#[must_use]
pub fn expected_header(turntable: &Turntable) -> String {
    expected_header_for(turntable, JointColumns::Required)
}

/// The header for rows with or without joint columns, in the study's order.
#[must_use]
pub fn expected_header_for(turntable: &Turntable, joints: JointColumns) -> String {
    let mut cols: Vec<String> = match joints {
        JointColumns::Required => turntable
            .joint_names()
            .iter()
            .map(|n| format!("{n}_deg"))
            .collect(),
        JointColumns::Absent => Vec::new(),
    };
    cols.extend(
        turntable
            .rotation_error_names()
            .iter()
            .map(|n| format!("{n}_arcmin")),
    );
    cols.extend(
        turntable
            .translation_error_names()
            .iter()
            .map(|n| format!("{n}_mm")),
    );
    cols.join(",")
}

/// Decode one line of bytes as UTF-8 (a BOM removed on the first line), naming the line.
///
/// # Errors
/// A [`StudyError`] at `source:line` for invalid UTF-8.
pub fn decode_line<'a>(
    source: &str,
    line_no: usize,
    bytes: &'a [u8],
) -> Result<&'a str, StudyError> {
    let s = std::str::from_utf8(bytes).map_err(|e| {
        StudyError::new(
            format!("{source}:{line_no}"),
            format!("not valid UTF-8 (byte {} of the line)", e.valid_up_to() + 1),
        )
    })?;
    let s = if line_no == 1 {
        s.strip_prefix('\u{feff}').unwrap_or(s)
    } else {
        s
    };
    Ok(s.trim_end_matches(['\r', '\n']))
}

impl TurntableColumns {
    /// Map a header line to the turntable's joints and errors.
    ///
    /// # Errors
    /// A [`StudyError`] at `source:line` naming unknown, duplicate or missing columns.
    pub fn from_header(
        source: &str,
        line_no: usize,
        header: &str,
        turntable: &Turntable,
    ) -> Result<Self, StudyError> {
        Self::from_header_for(source, line_no, header, turntable, JointColumns::Required)
    }

    /// Map a header line with or without joint columns.
    ///
    /// # Errors
    /// As [`TurntableColumns::from_header`]; with [`JointColumns::Absent`] a joint column is an
    /// error naming it.
    pub(crate) fn from_header_for(
        source: &str,
        line_no: usize,
        header: &str,
        turntable: &Turntable,
        joints: JointColumns,
    ) -> Result<Self, StudyError> {
        let header = header.strip_prefix('\u{feff}').unwrap_or(header);
        let fields: Vec<&str> = header.split(',').collect();
        Self::from_header_fields(source, line_no, &fields, turntable, joints)
    }

    /// Map a header's fields (already split, for example by a CSV reader that unquotes them)
    /// with or without joint columns.
    ///
    /// # Errors
    /// As [`TurntableColumns::from_header_for`].
    pub fn from_header_fields(
        source: &str,
        line_no: usize,
        fields: &[&str],
        turntable: &Turntable,
        joints: JointColumns,
    ) -> Result<Self, StudyError> {
        let at = format!("{source}:{line_no}");
        let mut slots = Vec::new();
        let mut names = Vec::new();
        let mut seen = std::collections::BTreeSet::new();
        for (c, raw) in fields.iter().enumerate() {
            let col = raw.trim();
            let slot = if let Some(j) = col
                .strip_suffix("_deg")
                .and_then(|n| turntable.joint_index(n))
            {
                if joints == JointColumns::Absent {
                    return Err(StudyError::new(
                        format!("{at} column {}", c + 1),
                        format!(
                            "column `{col}`: these rows take no joint angles (the errors act at every position of the study's schedule); the columns are {}",
                            expected_header_for(turntable, joints)
                        ),
                    ));
                }
                Slot::Joint(j)
            } else if let Some(i) = col
                .strip_suffix("_arcmin")
                .and_then(|n| turntable.rotation_error_index(n))
            {
                Slot::Rotation(i)
            } else if let Some(t) = col.strip_suffix("_mm").and_then(|n| {
                turntable
                    .translation_error_names()
                    .iter()
                    .position(|x| *x == n)
            }) {
                Slot::Translation(t)
            } else {
                return Err(StudyError::new(
                    format!("{at} column {}", c + 1),
                    format!(
                        "unknown column `{col}`; the study's turntable has the columns {}",
                        expected_header_for(turntable, joints)
                    ),
                ));
            };
            if !seen.insert(col.to_string()) {
                return Err(StudyError::new(
                    format!("{at} column {}", c + 1),
                    format!("column `{col}` appears twice"),
                ));
            }
            slots.push(slot);
            names.push(col.to_string());
        }
        let expected: Vec<String> = expected_header_for(turntable, joints)
            .split(',')
            .map(String::from)
            .collect();
        let missing: Vec<&str> = expected
            .iter()
            .filter(|e| !seen.contains(*e))
            .map(String::as_str)
            .collect();
        if !missing.is_empty() {
            return Err(StudyError::new(
                at,
                format!("missing columns: {}", missing.join(", ")),
            ));
        }
        Ok(Self {
            slots,
            names,
            joints: match joints {
                JointColumns::Required => turntable.n_joints(),
                JointColumns::Absent => 0,
            },
            rotations: turntable.n_rotation_errors(),
            translations: turntable.n_translation_errors(),
        })
    }

    /// Parse one data line.
    ///
    /// # Errors
    /// A [`StudyError`] at `source:line column c` for a wrong field count, a field that is not
    /// a number, or a value outside its range (joint angles [`limits::ANGLE_ABS_MAX_DEG`],
    /// errors [`limits::ANGLE_TOLERANCE_ARCMIN`] in magnitude, translations
    /// [`limits::TRANSLATION_TOLERANCE_MM`] in magnitude).
    pub fn parse_row(
        &self,
        source: &str,
        line_no: usize,
        line: &str,
    ) -> Result<TurntableRow, StudyError> {
        let fields: Vec<&str> = line.split(',').collect();
        self.parse_fields(source, line_no, &fields)
    }

    /// Parse one data record's fields (already split, for example by a CSV reader that
    /// unquotes them; surrounding spaces are ignored).
    ///
    /// # Errors
    /// As [`TurntableColumns::parse_row`].
    pub fn parse_fields(
        &self,
        source: &str,
        line_no: usize,
        fields: &[&str],
    ) -> Result<TurntableRow, StudyError> {
        if fields.len() != self.slots.len() {
            return Err(StudyError::new(
                format!("{source}:{line_no}"),
                format!(
                    "expected {} columns, found {}",
                    self.slots.len(),
                    fields.len()
                ),
            ));
        }
        let mut row = TurntableRow {
            pose_rad: vec![0.0; self.joints],
            chi_rad: vec![0.0; self.rotations],
            translations_m: vec![0.0; self.translations],
        };
        for (c, ((field, slot), name)) in
            fields.iter().zip(&self.slots).zip(&self.names).enumerate()
        {
            let at = || format!("{source}:{line_no} column {}", c + 1);
            let field = field.trim();
            let x: f64 = field.parse().map_err(|_| {
                StudyError::new(at(), format!("`{name}`: `{field}` is not a number"))
            })?;
            let (max, unit) = match slot {
                Slot::Joint(_) => (limits::ANGLE_ABS_MAX_DEG, "deg"),
                Slot::Rotation(_) => (limits::ANGLE_TOLERANCE_ARCMIN.1, "arcmin"),
                Slot::Translation(_) => (limits::TRANSLATION_TOLERANCE_MM.1, "mm"),
            };
            if !x.is_finite() || x.abs() > max {
                return Err(StudyError::new(
                    at(),
                    format!("`{name}` must lie in [-{max}, {max}] {unit}, found `{field}`"),
                ));
            }
            match *slot {
                Slot::Joint(j) => row.pose_rad[j] = x * RAD_PER_DEG,
                Slot::Rotation(i) => row.chi_rad[i] = x * RAD_PER_ARCMIN,
                Slot::Translation(t) => row.translations_m[t] = x * 1e-3,
            }
        }
        Ok(row)
    }
}
