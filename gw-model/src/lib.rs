//! GyroWheel rate-sensing model (paper §2.1, eq 1 and 3, Table 1).
//!
//! **Not built yet.** This crate is a placeholder in the workspace layout; see issue 3.
//! It exposes no API until that work lands, so nothing here pretends to work.
#![forbid(unsafe_code)]
