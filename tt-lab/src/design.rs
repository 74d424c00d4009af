//! Schedule design for a study: the positions ([`schedule`]), the positions and dwell under a
//! time budget ([`budget`]), the rate of its rate steps chosen among candidates ([`rates`]),
//! and the study file written with the choice ([`written`]).

pub mod budget;
pub mod rates;
pub mod schedule;
pub mod written;
