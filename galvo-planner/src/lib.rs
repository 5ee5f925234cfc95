#![no_std]
//! Galvo motion planning.
