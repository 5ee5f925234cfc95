//! grbl's `$N` settings as this controller answers them: the ones whose
//! meaning matches a product parameter read and write it (`$110`/`$111`
//! max rate ↔ `galvo.mark_speed_mm_s`, `$120`/`$121` acceleration ↔
//! `galvo.mark_accel_mm_s2`, `$130`/`$131` travel = the board extent from
//! `grid.*`, read-only; `$11` ↔ `gcode.junction_mm`); grbl-only ones
//! (`$10`, `$12`, `$30`–`$32`) are kept here; the rest answer their fixed
//! value.

use super::machine::{ActionSink, Core};
use crate::grbl::GrblError;
use crate::grbl::settings_map::{self, Binding, GrblSetting};
use crate::settings::find_param;

/// grbl-only settings the session keeps (RAM; defaults at boot and after
/// `$RST=$`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct GrblValues {
    /// `$10`: bit 0 MPos (else WPos), bit 1 `Bf:`.
    pub(super) report_mask: u8,
    /// `$12`: arc chord tolerance, mm.
    pub(super) arc_tolerance_mm: f64,
    /// `$30`: S for full laser power.
    pub(super) s_max: f64,
    /// `$31`: S for the lowest power.
    pub(super) s_min: f64,
    /// `$32`: laser mode (G0 dark, M4 speed-scaled).
    pub(super) laser_mode: bool,
}

fn default_of(number: u16) -> f64 {
    settings_map::find(number).map_or(0.0, |s| s.default)
}

impl Default for GrblValues {
    fn default() -> Self {
        Self {
            report_mask: default_of(10) as u8,
            arc_tolerance_mm: default_of(12),
            s_max: default_of(30),
            s_min: default_of(31),
            laser_mode: default_of(32) != 0.0,
        }
    }
}

/// The product parameter a grbl setting reads and writes, with the factor
/// grbl value = parameter × factor.
fn product_param(number: u16) -> Option<(&'static str, f64)> {
    match number {
        11 => Some(("gcode.junction_mm", 1.0)),
        110 | 111 => Some(("galvo.mark_speed_mm_s", 60.0)),
        120 | 121 => Some(("galvo.mark_accel_mm_s2", 1.0)),
        _ => None,
    }
}

impl Core {
    /// The value `$$` shows for `setting`.
    pub(super) fn grbl_setting_value(&self, setting: &GrblSetting) -> f64 {
        let v = &self.gcode.values;
        let s = &self.settings;
        match setting.number {
            10 => f64::from(v.report_mask),
            12 => v.arc_tolerance_mm,
            30 => v.s_max,
            31 => v.s_min,
            32 => f64::from(u8::from(v.laser_mode)),
            130 => s.grid_pitch_cm * f64::from(s.grid_cols) * 10.0,
            131 => s.grid_pitch_cm * f64::from(s.grid_rows) * 10.0,
            n => match product_param(n).and_then(|(name, k)| Some((find_param(name)?, k))) {
                Some((param, k)) => s.get(param) * k,
                None => setting.default,
            },
        }
    }

    /// `$N=value`; on error nothing changed.
    pub(super) fn grbl_set_setting(
        &mut self,
        number: u16,
        value: f64,
        out: &mut dyn ActionSink,
    ) -> Result<(), GrblError> {
        let setting = settings_map::find(number).ok_or(GrblError::InvalidStatement)?;
        let v = &mut self.gcode.values;
        match number {
            10 if value <= 3.0 => v.report_mask = value as u8,
            12 if value > 0.0 => v.arc_tolerance_mm = value,
            30 if value > v.s_min => v.s_max = value,
            31 if value < v.s_max => v.s_min = value,
            32 if value == 0.0 || value == 1.0 => v.laser_mode = value == 1.0,
            n if product_param(n).is_some() => {
                let (name, k) = product_param(n).ok_or(GrblError::InvalidStatement)?;
                let param = find_param(name).ok_or(GrblError::InvalidStatement)?;
                self.settings
                    .set(param, value / k)
                    .map_err(|_| GrblError::InvalidStatement)?;
                self.configure_galvo(out);
            }
            // Fixed ones (and the board extent) take only their value.
            _ if setting.binding == Binding::Fixed || matches!(number, 130 | 131) => {
                if value != self.grbl_setting_value(setting) {
                    return Err(GrblError::InvalidStatement);
                }
            }
            _ => return Err(GrblError::InvalidStatement),
        }
        Ok(())
    }
}
