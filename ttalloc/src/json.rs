//! The building blocks of the command line's `--json` schema (issue 20 item 4): every command's
//! output is a tree of typed view structs (`#[derive(Serialize)]`) built from the library's
//! results, its field names the printed keys, the units stated at the edge (degrees,
//! arcminutes, deg/h: the unit is in the key, `bounds_arcmin`, `objective_arcmin`) where the
//! library works in radians. Each command's views sit next to the command, each field's doc
//! comment giving its unit: that is the documented schema.
//!
//! Key order: [`print`] writes through a [`serde_json::Value`], whose map (serde_json without
//! its `preserve_order` feature) sorts keys, so every object's keys come out in alphabetical
//! order at every level, whatever the struct's field order; a field skipped
//! (`skip_serializing_if`) is a key absent from the output, an `Option` serialised as `None`
//! is `null`, and a non-finite number is `null` (serde_json's rule).

use serde::Serialize;
pub(crate) use tt_lab::json::*;

/// Print `v` as pretty JSON, keys in alphabetical order (see the module's documentation), and a
/// newline.
///
/// # Errors
/// A value serde_json cannot represent (a map with non-string keys); writing standard output
/// ([`crate::out::print`]).
pub(crate) fn print(v: &impl Serialize) -> anyhow::Result<()> {
    crate::out::print(&(serde_json::to_string_pretty(&serde_json::to_value(v)?)? + "\n"))
}
