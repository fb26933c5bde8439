//! Helpers shared by the test binaries (and the solver and QP benches), included with
//! `mod common;`: one seeded random generator, one counting allocator, random robot models,
//! task hierarchies and QPs.
#![allow(dead_code)]

pub mod alloc;
pub mod bounds;
pub mod model;
pub mod qp;
pub mod solver;

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

/// The seeded generator of every randomised test.
pub fn rng(seed: u64) -> ChaCha8Rng {
    ChaCha8Rng::seed_from_u64(seed)
}
