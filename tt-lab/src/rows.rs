//! The orientation error (eq 24-26) and the calibration error of turntables given as rows
//! (one turntable per row: a pose and its errors, [`study::csv::TurntableRow`]): a library
//! call per row, or over an iterator of rows (streaming: nothing is kept between rows). Where
//! the rows come from (a CSV file, standard input) is the caller's concern; each row carries
//! its location (`file:line`) for the messages. [`read_rows`] reads them from CSV text
//! (RFC 4180, streamed by [`crate::records`]: a header naming the columns, then one
//! turntable per record).

use crate::error::{InputError, Result};
use e2e_verify::{EndToEnd, ExtraError};
use study::Study;
use study::csv::{JointColumns, TurntableColumns, TurntableRow};
use tt_core::units::rad_to_arcmin;
use tt_kinematics::{
    ExactChain, LinearChain, OrientationErrorModel, Pose, SmallAngleChain, Turntable,
    TurntableErrors,
};

/// Which orientation-error model to evaluate.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
#[non_exhaustive]
pub enum Model {
    /// Every error a finite rotation, in the order of the study's factors (eq 17-24).
    #[default]
    Exact,
    /// Runs of error rotations as small-angle matrices (the printed eq 17-19 for the paper).
    SmallAngle,
    /// The first-order model built from the description (eq 26 for the paper's table).
    Linear,
    /// The paper's printed eq 26 (the paper's table only).
    #[cfg(feature = "paper")]
    ClosedForm,
}

/// Options of [`orientation_rows`].
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
#[non_exhaustive]
pub struct OrientationOptions {
    /// The model evaluated.
    pub model: Model,
}

impl OrientationOptions {
    /// The options with model `m`.
    #[must_use]
    pub fn model(mut self, m: Model) -> Self {
        self.model = m;
        self
    }
}

/// The columns of the orientation error, one row per turntable, arcminutes.
pub const ORIENTATION_COLUMNS: &str = "dpsi_arcmin,dtheta_arcmin,dgamma_arcmin";

/// The orientation error of turntables of a study, one row at a time.
pub struct OrientationRows {
    model: Box<dyn OrientationErrorModel>,
}

impl std::fmt::Debug for OrientationRows {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("OrientationRows").finish_non_exhaustive()
    }
}

/// The orientation-error evaluator of the study's turntable under the options' model.
///
/// # Errors
/// An [`InputError`] naming `--model` when the closed form is asked of a table that is not
/// the paper's.
pub fn orientation_rows(s: &Study, o: &OrientationOptions) -> Result<OrientationRows> {
    let t = &s.turntable;
    let model: Box<dyn OrientationErrorModel> = match o.model {
        Model::Exact => Box::new(ExactChain::new(t)),
        Model::SmallAngle => Box::new(SmallAngleChain::new(t)),
        Model::Linear => Box::new(LinearChain::new(t)),
        #[cfg(feature = "paper")]
        Model::ClosedForm => {
            if *t != tt_kinematics::paper::table3() {
                return Err(InputError::new("--model", "closed-form is the paper's eq 26 and applies only to the paper's table; use `linear` for any table").into());
            }
            Box::new(tt_kinematics::paper::ClosedForm)
        }
    };
    Ok(OrientationRows { model })
}

impl OrientationRows {
    /// The orientation error of one turntable (psi, theta, gamma), arcminutes.
    ///
    /// # Errors
    /// An [`InputError`] at `at` for a pose or errors the model rejects, or a non-finite
    /// result.
    pub fn row(&self, at: &str, row: &TurntableRow) -> Result<[f64; 3], InputError> {
        let pose =
            Pose::new(row.pose_rad.clone()).map_err(|e| InputError::new(at, e.to_string()))?;
        let errors = TurntableErrors::new(row.chi_rad.clone(), row.translations_m.clone())
            .map_err(|e| InputError::new(at, e.to_string()))?;
        let e = self
            .model
            .orientation_error(&pose, &errors)
            .map_err(|e| InputError::new(at, e.to_string()))?;
        let v = e.to_array().map(rad_to_arcmin);
        if v.iter().any(|x| !x.is_finite()) {
            return Err(InputError::new(
                at,
                "the model gave a non-finite orientation error",
            ));
        }
        Ok(v)
    }
}

/// The orientation error of every row (`(location, row)`), lazily, in order.
///
/// # Errors
/// As [`orientation_rows`]; each item as [`OrientationRows::row`].
pub fn orientation_errors<I>(
    s: &Study,
    o: &OrientationOptions,
    rows: I,
) -> Result<impl Iterator<Item = Result<[f64; 3], InputError>>>
where
    I: IntoIterator<Item = (String, TurntableRow)>,
{
    let eval = orientation_rows(s, o)?;
    Ok(rows.into_iter().map(move |(at, r)| eval.row(&at, &r)))
}

/// The calibration error of turntables of a study, one row at a time: the errors act at
/// every entry of the study's schedule; the outputs are simulated at the actual orientation
/// and calibrated at the intended one (eq 6).
#[derive(Debug)]
pub struct CalibrationRows {
    e2e: EndToEnd,
    work: e2e_verify::DrawWork,
}

/// The calibration-error evaluator of the study.
///
/// # Errors
/// An [`InputError`] naming the study when its simulator cannot be built.
pub fn calibration_rows(s: &Study) -> Result<CalibrationRows> {
    let e2e = crate::loaded::simulator(s)?;
    let work = e2e.work();
    Ok(CalibrationRows { e2e, work })
}

impl CalibrationRows {
    /// The columns of a row's answer ([`study::csv::calibration_error_columns`]): every
    /// coefficient's error, then every output's rate error.
    #[must_use]
    pub fn columns(&self) -> Vec<String> {
        study::csv::calibration_error_columns(self.e2e.calibration().sensor())
            .into_iter()
            .map(|(c, _)| c)
            .collect()
    }

    /// The calibration error of one turntable: every estimated coefficient's error (estimate
    /// minus true value, its unit) in study order, then every output's rate error (eq 14,
    /// output unit; 0 at or below the computation's precision). With rate steps, the row's
    /// translations act there (rate accuracy and ripple held at zero).
    ///
    /// # Errors
    /// An [`InputError`] at `at` for errors the simulator rejects, or a non-finite result.
    pub fn row(&mut self, at: &str, row: &TurntableRow) -> Result<Vec<f64>, InputError> {
        let with_rows;
        let e2e = if self.e2e.has_rate_steps() {
            let mut extra = vec![0.0; self.e2e.extra_errors().len()];
            for (x, v) in self.e2e.extra_errors().iter().zip(extra.iter_mut()) {
                if let ExtraError::Translation(i) = *x {
                    *v = row.translations_m[i];
                }
            }
            with_rows = self
                .e2e
                .with_extra_values(&extra)
                .map_err(|e| InputError::new(at, e.to_string()))?;
            &with_rows
        } else {
            &self.e2e
        };
        let mut v = e2e
            .coefficient_errors(&row.chi_rad)
            .map_err(|e| InputError::new(at, e.to_string()))?;
        e2e.delta_omega_into(&row.chi_rad, &mut self.work)
            .map_err(|e| InputError::new(at, e.to_string()))?;
        // a rate error at or below the computation's precision is reported as 0
        v.extend(
            self.work
                .delta_omega
                .iter()
                .zip(e2e.precisions())
                .map(|(d, p)| e2e_verify::resolved(*d, *p)),
        );
        if v.iter().any(|x| !x.is_finite()) {
            return Err(InputError::new(
                at,
                "the calibration gave a non-finite result",
            ));
        }
        Ok(v)
    }
}

/// Read turntables as CSV rows from `input` (named `name` in messages) once, streaming: the
/// header maps the columns to `turntable`'s joints and errors ([`TurntableColumns`]), then
/// every data record goes to `visit` with the line it starts on, in order. Stops at the first
/// error.
///
/// # Errors
/// An [`InputError`] at `name:line` (and column) for an unreadable input, a record longer than
/// [`crate::records::MAX_LINE_BYTES`], malformed quoting, a field that is not UTF-8, a bad
/// header or row, or an empty input; or the first error `visit` returns.
pub fn read_rows<R, F>(
    input: R,
    name: &str,
    turntable: &Turntable,
    joints: JointColumns,
    mut visit: F,
) -> std::result::Result<(), InputError>
where
    R: std::io::Read,
    F: FnMut(usize, TurntableRow) -> std::result::Result<(), InputError>,
{
    let mut columns: Option<TurntableColumns> = None;
    crate::records::for_each_record(input, name, |line_no, fields| match &columns {
        None => {
            columns = Some(TurntableColumns::from_header_fields(
                name, line_no, fields, turntable, joints,
            )?);
            Ok(())
        }
        Some(c) => visit(line_no, c.parse_fields(name, line_no, fields)?),
    })?;
    if columns.is_none() {
        return Err(InputError::new(
            name,
            format!(
                "empty input: expected a header line ({})",
                study::csv::expected_header_for(turntable, joints)
            ),
        ));
    }
    Ok(())
}
