//! `$` settings of the G-code session.

use crate::grbl::GrblError;
use crate::grbl::settings_map::{self, Binding, GrblSetting};
use crate::sequencer::gcode::{GcodeSession, product_param};
use crate::settings::{Settings, find_param};

/// What a `$N=value` changed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(in crate::sequencer) enum Written {
    /// Only the session's own values (or nothing: a fixed one).
    Session,
    /// A product parameter: the core sends the galvo loop its parameters.
    Product,
}

impl GcodeSession {
    /// The value `$$` shows for `setting`, the product's parameters read
    /// from `settings`.
    pub(in crate::sequencer) fn setting_value(
        &self,
        setting: &GrblSetting,
        settings: &Settings,
    ) -> f64 {
        let v = &self.values;
        let s = settings;
        match setting.number {
            10 => f64::from(v.report_mask),
            12 => v.arc_tolerance_mm,
            30 => v.s_max,
            31 => v.s_min,
            32 => f64::from(u8::from(v.laser_mode)),
            130 => s.board_size_mm()[0],
            131 => s.board_size_mm()[1],
            n => match product_param(n).and_then(|(name, k)| Some((find_param(name)?, k))) {
                Some((param, k)) => s.get(param) * k,
                None => setting.default,
            },
        }
    }

    /// `$N=value`, a product parameter written into `settings`; on error
    /// nothing changed.
    pub(in crate::sequencer) fn set_setting(
        &mut self,
        number: u16,
        value: f64,
        settings: &mut Settings,
    ) -> Result<Written, GrblError> {
        let setting = settings_map::find(number).ok_or(GrblError::InvalidStatement)?;
        let v = &mut self.values;
        match number {
            10 if value <= 3.0 => v.report_mask = value as u8,
            12 if value > 0.0 => v.arc_tolerance_mm = value,
            30 if value > v.s_min => v.s_max = value,
            31 if value < v.s_max => v.s_min = value,
            32 if value == 0.0 || value == 1.0 => v.laser_mode = value == 1.0,
            n if product_param(n).is_some() => {
                let (name, k) = product_param(n).ok_or(GrblError::InvalidStatement)?;
                let param = find_param(name).ok_or(GrblError::InvalidStatement)?;
                settings
                    .set(param, value / k)
                    .map_err(|_| GrblError::InvalidStatement)?;
                return Ok(Written::Product);
            }
            // Fixed ones (and the board extent) take only their value.
            _ if setting.binding == Binding::Fixed || matches!(number, 130 | 131) => {
                if value != self.setting_value(setting, settings) {
                    return Err(GrblError::InvalidStatement);
                }
            }
            _ => return Err(GrblError::InvalidStatement),
        }
        Ok(Written::Session)
    }
}
