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
pub mod linalg;
pub mod model;

pub use error::Error;
