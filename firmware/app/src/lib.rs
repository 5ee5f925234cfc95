#![no_std]
//! Firmware application logic, independent of the HAL.
