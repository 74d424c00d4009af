#![doc = include_str!("../README.md")]
// The JSON views' fields are read only by their derived Serialize: without the `serde`
// feature they are dead code, in every module that has views. Dead code of any other kind is
// dead with the feature too, where the lint still denies it (`clippy --workspace` builds this
// crate with it: the command line and the report enable it).
#![cfg_attr(
    not(feature = "serde"),
    allow(
        dead_code,
        reason = "the JSON views' fields are read only by their derived Serialize"
    )
)]

pub mod allocation;
pub mod budget_mc;
pub mod calibrate;
pub mod design;
pub mod end_to_end;
pub mod error;
pub mod estimable;
pub mod groups;
pub mod json;
pub mod loaded;
pub mod monte_carlo;
pub mod newfile;
pub mod noise_log;
pub mod outdir;
pub mod paths;
pub mod records;
pub mod requirement;
pub mod rows;
pub mod vendor;

pub use error::{InputError, LabError, Result};
