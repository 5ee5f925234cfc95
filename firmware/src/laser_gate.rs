//! The master laser gate of the board and what closing it does to the
//! laser output (the galvo's laser stream and PB0).

use laser_app::laser_gate::{GateState, LaserGate};

use crate::galvo_dac::buffers::darken_laser_stream;
use crate::laser_pwm::laser_dark;

/// The master laser gate (see `laser_app::laser_gate`): the sequencer
/// closes it on every stop, fault and button press, the galvo loop on an
/// underrun; closing darkens the galvo's laser stream and pulls PB0 low
/// at once.
pub static LASER_GATE: LaserGate = LaserGate::with_hook(laser_gate_changed);

/// The gate's hook: when it closes, every word of the galvo's laser
/// stream is zeroed (none can set the pin again), then PB0 goes low at
/// once, PWM or not ([`laser_dark`]: TIM3_CH3 forced inactive, the pin's
/// ODR bit cleared through BSRR, PB0 a GPIO output again), whoever holds
/// the pin.
pub fn laser_gate_changed(state: GateState) {
    if !state.open {
        darken_laser_stream();
        laser_dark();
    }
}
