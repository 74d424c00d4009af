//! The study a command works on, loaded by the study-level library ([`tt_lab::loaded`]).

pub(crate) use tt_lab::loaded::load;
