//! Host simulator.
