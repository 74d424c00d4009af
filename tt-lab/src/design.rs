//! Schedule design for a study: the rate of its rate steps chosen among candidates
//! ([`rates`]). The position search and the time-budget designer are still in the command
//! line (`ttalloc`'s `design_schedule` and `design_budget`) and move here next.

pub mod rates;
