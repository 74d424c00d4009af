//! The JSON of the end-to-end answer, read the same way by every test that checks it: a
//! reading's box by its name.

use serde_json::Value;

/// The box named `name` (`Table 4`, `two-step`, ...) of `reading`: one of `end-to-end
/// --json`'s `readings[]` (or the report's `results.json` `end_to_end[]`).
///
/// # Panics
/// When the reading has no box of that name.
#[must_use]
pub fn box_named<'a>(reading: &'a Value, name: &str) -> &'a Value {
    reading["boxes"]
        .as_array()
        .and_then(|boxes| boxes.iter().find(|b| b["name"] == name))
        .unwrap_or_else(|| panic!("no box {name} in {reading}"))
}
