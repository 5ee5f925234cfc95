//! The library half of xtask: host-tool code that other crates call too
//! (the fuzz targets and their property checks in `tests/fuzz-props`).

pub mod calib_csv;
