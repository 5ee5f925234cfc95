//! Command-line text handling: line assembly, argument parsing, command
//! parsing and the error messages users see. Pure code, tested on the host.

pub mod args;
pub mod error;
pub mod line;
pub mod parse;
