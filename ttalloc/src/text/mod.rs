//! The text blocks more than one command (or the report) prints, one module per part of an
//! answer; the results and their JSON views are the study-level library's ([`tt_lab`]).

pub mod angle;
pub mod angle_alloc;
pub mod jcgm101;
/// The groups' sentence, shared with the report: the study-level library's.
pub use tt_lab::groups;
pub mod noise;
pub mod rate;
pub mod spec_verdict;
