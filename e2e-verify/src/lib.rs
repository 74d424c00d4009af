//! End-to-end verification of a turntable tolerance allocation (issue 7).
//!
//! **Not built yet.** Placeholder in the workspace layout; it exposes no API until that work
//! lands, so nothing here pretends to work.
#![forbid(unsafe_code)]
