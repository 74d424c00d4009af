//! The text blocks more than one command (or the report) prints, one module per part of an
//! answer; the results and their JSON views are the study-level library's ([`tt_lab`]).

pub(crate) mod angle;
pub(crate) mod angle_alloc;
pub(crate) mod jcgm101;
/// The groups' sentence, shared with the report: the study-level library's.
pub(crate) use tt_lab::groups;
pub(crate) mod noise;
pub(crate) mod rate;
pub(crate) mod spec_verdict;
