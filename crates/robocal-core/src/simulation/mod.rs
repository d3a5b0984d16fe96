//! The virtual cell: a "true" robot measured by a simulated laser tracker (paper, section IV).
//!
//! Everything is driven by a seeded ChaCha RNG, so the same seed gives the same data.

mod poses;
mod tracker;

pub use poses::{random_poses, PoseSampler};
pub use tracker::Tracker;
