//! Multiposition least-squares calibration and orientation-error analysis (paper §2, eq 2-16).
//!
//! **Not built yet.** This crate is a placeholder in the workspace layout; see issue 3.
//! It exposes no API until that work lands, so nothing here pretends to work.
#![forbid(unsafe_code)]
