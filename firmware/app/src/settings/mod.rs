//! User parameters: one table gives every parameter's name, unit, range and
//! storage, so `set`, `get`, `params` and the saved record cannot disagree.
//!
//! Values are f64 in the unit in the parameter's name (cm, mm, deg, ms,
//! deg/s). Every parameter has a physically meaningful range (its
//! [`ParamSpec`]: `min..=max`, a smallest magnitude for signed scales, and
//! the precision it is used in); a value outside it, non-finite, or one
//! that would vanish or overflow in f32 where it is used as f32, is refused
//! and changes nothing. Integer parameters (ids, counts, directions) are
//! checked to be whole numbers.
//!
//! `spec.rs` describes a parameter and checks its values, `params.rs` holds
//! the table (with every parameter's stable id), `record.rs` the saved form
//! (id-keyed; `legacy.rs` reads the earlier positional one), `store.rs`
//! where it is kept (two flash sectors, power-fail safe). Errors are
//! [`SettingsError`]s; the command line prints them as they are.

mod access;
mod controls;
mod error;
mod gcode;
mod geometry;
mod legacy;
mod loading;
mod migrate;
mod params;
mod pelco;
mod pelco_params;
mod presets;
mod record;
mod spec;
mod stepper;
mod stepper_params;
pub mod store;
#[cfg(test)]
mod tests;
mod values;

pub use error::SettingsError;
pub use loading::{LoadedRecord, RecordError, RecordLayout, crc32};
pub use params::{MAX_CODES_PER_RAD, MIN_CODES_PER_RAD, PARAMS, find_param};
pub use pelco::{PELCO_BAUDS, PelcoSettings};
pub use presets::{MAX_PRESET, is_preset, savable};
pub use record::{
    MAX_RECORD_LEN, RECORD_LEN, RECORD_VERSION, claimed_record_len, intact_record_len,
};
pub use spec::{ParamLine, ParamSpec, Precision};
pub use stepper::{MAX_STEP_RATE_STEPS_S, StepperAxisSettings, StepperSettings};
pub use values::{AxisSettings, GalvoSettings, JumpPlanner, LaserMode, Settings};
