#![no_std]
//! Geometry layer of the laser pointing controller.
