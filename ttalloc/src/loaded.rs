//! The study a command works on, loaded by the study-level library ([`tt_lab::loaded`]).

pub use tt_lab::loaded::load;
