//! The sampling toolkit: random numbers, piecewise-constant distributions,
//! warps from the unit square with their densities, MIS heuristics, and a
//! reusable chi-square harness ([`chi2`]) to test any of them.

pub mod alias;
pub mod bounded_fast;
pub mod chi2;
pub mod distribution;
pub mod distribution_guide;
pub mod interpolation;
pub mod rng;
pub mod warps;

pub use distribution::{DiscreteCdf, Distribution1D, Distribution2D};
pub use rng::{Pcg32, ONE_MINUS_EPSILON};
pub use warps::*;
