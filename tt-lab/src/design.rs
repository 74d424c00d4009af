//! Schedule design for a study: the positions ([`schedule`]), the positions and dwell under a
//! time budget ([`budget`]), the rate of its rate steps chosen among candidates ([`rates`]).

pub mod budget;
pub mod rates;
pub mod schedule;
