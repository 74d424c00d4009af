//! The shared set-up of these tests lives in the dev-only `testkit` crate ([`testkit::e2e`]).
#![allow(unused_imports)]

pub(crate) use testkit::e2e::*;
