//! Monte Carlo verification of a tolerance allocation (paper §4.3, Figure 9).
//!
//! **Not built yet.** This crate is a placeholder in the workspace layout; see issue 5.
//! It exposes no API until that work lands, so nothing here pretends to work.
#![forbid(unsafe_code)]
