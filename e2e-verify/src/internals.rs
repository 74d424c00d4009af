//! Internals for the sibling crate `schedule-design` (hidden from the docs, not a stable
//! API): the direct allocation's set-up, the lower-bound check, the certified allocation with
//! its note, and the pieces of the linearisation the designer evaluates per candidate.

pub use crate::allocate::{
    DirectSetup, certified_or_note, certified_or_note_specified, check_lower_bounds,
};
pub use crate::linear::{DerivativeTerms, directional, rounding_level};
