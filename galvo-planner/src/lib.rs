#![no_std]
#![cfg_attr(
    not(test),
    deny(
        clippy::unwrap_used,
        clippy::expect_used,
        clippy::indexing_slicing,
        clippy::panic
    )
)]
//! Galvo motion planning.

pub mod error;
pub mod jump;
pub mod linalg;
pub mod min_energy;
pub mod model;
pub mod optimal;
pub mod path;
pub mod profile;
pub mod stepper;
#[cfg(test)]
mod test_support;

pub use error::Error;
