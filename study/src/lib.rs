//! Study files: every input of a turntable error-allocation study in one strict TOML file,
//! parsed into the library values of tt-kinematics (the turntable), gw-model (the sensor,
//! the site) and calib-lsq (the schedule, the reading), so that any program reads the same
//! files as the project's commands.
//!
//! Parsing is strict: an unknown key, a missing key, a value of the wrong type, a number
//! outside its physical range ([`limits`]), a turntable or sensor description that does not
//! hold together, or a schedule that cannot identify the sensor's coefficients is a
//! [`StudyError`] naming the file, the key (with the index in a list) and the reason. Units
//! are part of the key names (`latitude_deg`, `earth_rate_rad_per_s`, `positions_deg`,
//! `lower_bounds_arcmin`), or, for the sensor, given by each output's `unit`.
//!
//! # Example
//! ```
//! let text = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/../studies/gyrowheel-2017.toml")).unwrap();
//! let s = study::Study::parse("gyrowheel-2017.toml", &text)?;
//! assert_eq!(s.turntable.joint_names(), ["phi1", "phi2"]);
//! assert_eq!(s.sensor.n_outputs(), 2);
//! assert_eq!(s.calibration.schedule().len(), 32);
//! # Ok::<(), study::StudyError>(())
//! ```
#![doc = include_str!("../README.md")]
#![forbid(unsafe_code)]

pub mod csv;
mod error;
pub mod limits;
mod noise;
mod schema;
pub mod spec;
mod tolerances;

pub use error::StudyError;
pub use schema::{
    Measured, MonteCarloSettings, RequirementSource, Study, StudyRateStep, default_revolutions,
    is_name_slug,
};
pub use tolerances::{DiscBound, Tolerances, sheet_bound_words};
