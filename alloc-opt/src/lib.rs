//! Tolerance allocation for turntable errors (paper §4.1-4.2, eq 29-38, Lemma 1, Table 4).
//!
//! **Not built yet.** This crate is a placeholder in the workspace layout; see issue 4.
//! It exposes no API until that work lands, so nothing here pretends to work.
#![forbid(unsafe_code)]
