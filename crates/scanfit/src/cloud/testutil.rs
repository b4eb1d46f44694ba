//! Deterministic random numbers for the geometry tests: the library's shared
//! generator ([`crate::testdata::SplitMix64`]).

pub(crate) use crate::testdata::SplitMix64 as Rng;
