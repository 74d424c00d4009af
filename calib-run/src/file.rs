//! The calibration file (JSON or TOML, by its extension: [`Format`]) and its application to a
//! recording.
//!
//! The file holds every output's model (each term's coefficient, regressor, unit, whether it
//! is known) with the estimated values and their standard and expanded uncertainties, and the
//! study and recording it came from with their SHA-256. [`write_new`] never overwrites a file:
//! it writes a temporary file beside the target and links it into place only if the name is
//! free. [`apply`] streams a recording of the outputs and writes the inputs the calibrated
//! model says produced them (specific force in g, rate in deg/h), solving the model for its
//! inputs at every sample.

use crate::error::RunError;
use crate::estimate::Run;
use crate::recording::{RecordingOptions, read_rows};
use gw_model::{Input, InputValues, Output, Regressor, Term};
use nalgebra::{DMatrix, DVector};
use std::io::{Read, Write};
use std::path::Path;

/// The format tag of a calibration file.
pub(crate) const FORMAT: &str = "calib-run/1";

/// The calibration file's format, chosen by its extension: `.json` or `.toml` (the same
/// content either way).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Format {
    /// JSON (`.json`).
    Json,
    /// TOML (`.toml`).
    Toml,
}

impl Format {
    /// The format of a file named `path` (its extension, case-insensitive); `flag` names
    /// where the path was given (`--out`).
    ///
    /// # Errors
    /// [`RunError::Option`] naming `flag` for any other extension.
    pub fn of_path(path: &Path, flag: &str) -> Result<Self, RunError> {
        Self::of_extension(path).ok_or_else(|| {
            RunError::option(
                flag,
                format!(
                    "`{}`: a calibration file is `.json` or `.toml` (the format is chosen by the extension)",
                    tt_core::human::visible(&path.display().to_string())
                ),
            )
        })
    }

    fn of_extension(path: &Path) -> Option<Self> {
        match path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase)
            .as_deref()
        {
            Some("json") => Some(Self::Json),
            Some("toml") => Some(Self::Toml),
            _ => None,
        }
    }
}

/// Gauss-Newton iterations of [`apply`] at most per sample.
const APPLY_MAX_ITER: usize = 20;

/// Relative step at which [`apply`]'s iteration stops.
const APPLY_TOL: f64 = 1e-13;

/// Where the calibration came from.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Origin {
    /// The path as given.
    pub path: String,
    /// SHA-256 of its bytes, hex.
    pub sha256: String,
}

/// One term.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FileTerm {
    /// Coefficient name.
    pub coefficient: String,
    /// Regressor as a study writes it (`1`, `a_x`, `w_y*a_z`, ...).
    pub regressor: String,
    /// The coefficient's unit.
    pub unit: String,
    /// Known (not estimated): its value is the study's.
    pub known: bool,
    /// The value.
    pub value: f64,
    /// Standard uncertainty (estimated terms).
    pub standard_uncertainty: Option<f64>,
    /// Expanded uncertainty (estimated terms).
    pub expanded_uncertainty: Option<f64>,
    /// Its coverage factor.
    pub coverage_factor: Option<f64>,
}

/// One output.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FileOutput {
    /// Name (the recording's column).
    pub name: String,
    /// Unit.
    pub unit: String,
    /// Terms.
    pub terms: Vec<FileTerm>,
}

/// A calibration file.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CalibrationFile {
    /// [`FORMAT`].
    pub format: String,
    /// The study.
    pub study: Origin,
    /// The recording.
    pub recording: Origin,
    /// Coverage probability of the expanded uncertainties.
    pub coverage: f64,
    /// The budget's rule.
    pub budget: String,
    /// Every output.
    pub outputs: Vec<FileOutput>,
}

impl CalibrationFile {
    /// The file of a processed run.
    #[must_use]
    pub fn of(run: &Run) -> Self {
        let outputs = run
            .models
            .iter()
            .zip(&run.outputs)
            .map(|(m, r)| FileOutput {
                name: m.name.clone(),
                unit: m.unit.clone(),
                terms: m
                    .terms
                    .iter()
                    .map(|t| {
                        let c = r.coefficients.iter().find(|c| c.name == t.coefficient);
                        FileTerm {
                            coefficient: t.coefficient.clone(),
                            regressor: t.regressor.to_string(),
                            unit: m.coefficient_unit(t),
                            known: t.known,
                            value: c.map_or(t.value, |c| c.value),
                            standard_uncertainty: c.map(|c| c.u_combined),
                            expanded_uncertainty: c.map(|c| c.expanded),
                            coverage_factor: c.map(|c| c.k),
                        }
                    })
                    .collect(),
            })
            .collect();
        CalibrationFile {
            format: FORMAT.into(),
            study: Origin {
                path: run.study.clone(),
                sha256: run.study_sha256.clone(),
            },
            recording: Origin {
                path: run.recording.source.clone(),
                sha256: run.recording.sha256.clone(),
            },
            coverage: run.coverage,
            budget: run.budget_rule.clone(),
            outputs,
        }
    }

    /// Parse a calibration file's text (`path` names it in messages; a path ending in `.toml`
    /// is read as TOML, any other as JSON).
    ///
    /// # Errors
    /// [`RunError::CalibrationFile`]: not JSON (TOML) of this form, another format, a
    /// regressor that does not parse, a non-finite value.
    pub fn parse(path: &str, text: &str) -> Result<Self, RunError> {
        let bad = |reason: String| RunError::CalibrationFile {
            path: path.into(),
            reason,
        };
        let f: CalibrationFile = match Format::of_extension(Path::new(path)) {
            Some(Format::Toml) => toml::from_str(text).map_err(|e| bad(e.to_string()))?,
            _ => serde_json::from_str(text).map_err(|e| bad(e.to_string()))?,
        };
        if f.format != FORMAT {
            return Err(bad(format!("format `{}`, expected `{FORMAT}`", f.format)));
        }
        f.model().map_err(bad)?;
        Ok(f)
    }

    /// The file's text in `format` (ending with a newline).
    ///
    /// # Errors
    /// [`RunError::Internal`] when serialization fails (it does not for a file of a run).
    pub(crate) fn to_text(&self, format: Format) -> Result<String, RunError> {
        let mut text = match format {
            Format::Json => {
                serde_json::to_string_pretty(self).map_err(|e| RunError::Internal(e.to_string()))?
            }
            Format::Toml => {
                toml::to_string_pretty(self).map_err(|e| RunError::Internal(e.to_string()))?
            }
        };
        if !text.ends_with('\n') {
            text.push('\n');
        }
        Ok(text)
    }

    /// The calibrated outputs as sensor-model outputs.
    fn model(&self) -> Result<Vec<Output>, String> {
        self.outputs
            .iter()
            .map(|o| {
                let terms = o
                    .terms
                    .iter()
                    .map(|t| {
                        if !t.value.is_finite() {
                            return Err(format!(
                                "{}.{}: value is not finite",
                                o.name, t.coefficient
                            ));
                        }
                        Ok(Term {
                            coefficient: t.coefficient.clone(),
                            regressor: Regressor::parse(&t.regressor)
                                .map_err(|e| format!("{}.{}: {e}", o.name, t.coefficient))?,
                            value: t.value,
                            known: t.known,
                        })
                    })
                    .collect::<Result<Vec<_>, _>>()?;
                Ok(Output {
                    name: o.name.clone(),
                    unit: o.unit.clone(),
                    accuracy: 1.0,
                    terms,
                })
            })
            .collect()
    }
}

/// Write `file` to `path`, which must not exist, in the format of its extension
/// ([`Format::of_path`]).
///
/// # Errors
/// [`RunError::Option`] naming `--out` for an extension other than `.json` or `.toml`;
/// [`RunError::Exists`] when `path` exists (nothing is written); [`RunError::Io`] when the
/// directory cannot be written.
pub fn write_new(path: &Path, file: &CalibrationFile) -> Result<(), RunError> {
    let format = Format::of_path(path, "--out")?;
    let shown = path.display().to_string();
    if path.symlink_metadata().is_ok() {
        return Err(RunError::Exists { path: shown });
    }
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    let io = |e: std::io::Error| RunError::Io {
        what: shown.clone(),
        source: e,
    };
    let mut tmp = tempfile::NamedTempFile::new_in(dir).map_err(io)?;
    let text = file.to_text(format)?;
    tmp.write_all(text.as_bytes()).map_err(io)?;
    tmp.as_file().sync_all().map_err(io)?;
    tmp.persist_noclobber(path).map_err(|e| {
        if e.error.kind() == std::io::ErrorKind::AlreadyExists {
            RunError::Exists {
                path: shown.clone(),
            }
        } else {
            io(e.error)
        }
    })?;
    Ok(())
}

/// What [`apply`] did.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct ApplySummary {
    /// Rows corrected.
    pub samples: u64,
    /// The inputs written, in order (`a_x`, ..., `w_z`), each with its unit.
    pub columns: Vec<String>,
    /// SHA-256 of the recording read.
    pub sha256: String,
    /// The largest model mismatch left after solving (output unit), over all samples.
    pub max_mismatch: f64,
}

/// Correct the recording read from `reader`: for every sample, the inputs (among those the
/// calibrated outputs involve) that the calibrated model maps to the recorded outputs, by
/// Gauss-Newton from the previous sample's solution; written as CSV `t_s,<input>_<unit>...`.
///
/// # Errors
/// [`RunError::CalibrationFile`] when the outputs do not determine the inputs they involve
/// (fewer independent outputs than inputs); the reader's errors ([`read_rows`]);
/// [`RunError::Io`] when writing fails.
pub fn apply<R: Read, W: Write>(
    file: &CalibrationFile,
    path: &str,
    reader: R,
    source: &str,
    options: &RecordingOptions,
    mut out: W,
) -> Result<ApplySummary, RunError> {
    let model = file.model().map_err(|reason| RunError::CalibrationFile {
        path: path.into(),
        reason,
    })?;
    let mut used = [false; 6];
    for o in &model {
        for t in &o.terms {
            for (q, i) in Input::ALL.iter().enumerate() {
                used[q] |= t.regressor.power(*i) > 0;
            }
        }
    }
    let unknown: Vec<usize> = (0..6).filter(|&q| used[q]).collect();
    let names: Vec<&str> = model.iter().map(|o| o.name.as_str()).collect();
    // identifiable at a neutral point (1 g down the z axis, no rate)
    let probe = InputValues([0.0, 0.0, 1.0, 0.0, 0.0, 0.0]);
    let rank = jacobian(&model, &probe, &unknown).rank(1e-9);
    if rank < unknown.len() {
        let list: Vec<&str> = unknown.iter().map(|&q| Input::ALL[q].symbol()).collect();
        return Err(RunError::CalibrationFile {
            path: path.into(),
            reason: format!(
                "its {} outputs ({}) do not determine the {} inputs they involve ({}): a correction needs as many independent outputs",
                model.len(),
                names.join(", "),
                unknown.len(),
                list.join(", ")
            ),
        });
    }
    let io = |e: std::io::Error| RunError::Io {
        what: "corrected recording".into(),
        source: e,
    };
    let columns: Vec<String> = unknown
        .iter()
        .map(|&q| {
            let i = Input::ALL[q];
            format!(
                "{}_{}",
                i.symbol(),
                if i.unit() == "g" { "g" } else { "deg_per_h" }
            )
        })
        .collect();
    writeln!(out, "t_s,{}", columns.join(",")).map_err(io)?;
    let mut x = probe;
    let mut max_mismatch: f64 = 0.0;
    let mut line = String::new();
    let summary = read_rows(reader, source, &names, &[], options, |row| {
        // Gauss-Newton on the involved inputs
        let target = DVector::from_column_slice(row.values);
        for _ in 0..APPLY_MAX_ITER {
            let f =
                DVector::from_iterator(model.len(), model.iter().map(|o| o.value(&x))) - &target;
            let j = jacobian(&model, &x, &unknown);
            let step = (j.transpose() * &j)
                .lu()
                .solve(&(j.transpose() * &f))
                .unwrap_or_else(|| DVector::zeros(unknown.len()));
            let mut size: f64 = 0.0;
            for (c, &q) in unknown.iter().enumerate() {
                x.0[q] -= step[c];
                size = size.max(step[c].abs() / x.0[q].abs().max(1.0));
            }
            if size <= APPLY_TOL {
                break;
            }
        }
        let mism = model
            .iter()
            .zip(row.values)
            .map(|(o, v)| (o.value(&x) - v).abs())
            .fold(0.0, f64::max);
        max_mismatch = max_mismatch.max(mism);
        line.clear();
        line.push_str(&row.t_s.to_string());
        for &q in &unknown {
            line.push(',');
            line.push_str(&x.0[q].to_string());
        }
        line.push('\n');
        out.write_all(line.as_bytes()).map_err(io)
    })?;
    out.flush().map_err(io)?;
    Ok(ApplySummary {
        samples: summary.samples,
        columns,
        sha256: summary.sha256,
        max_mismatch,
    })
}

fn jacobian(model: &[Output], x: &InputValues, unknown: &[usize]) -> DMatrix<f64> {
    let mut j = DMatrix::zeros(model.len(), unknown.len());
    for (r, o) in model.iter().enumerate() {
        for t in &o.terms {
            let g = t.regressor.gradient(x);
            for (c, &q) in unknown.iter().enumerate() {
                j[(r, c)] += t.value * g[q];
            }
        }
    }
    j
}
