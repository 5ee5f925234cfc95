//! The laser controls on the emulated board (feature `laser-controls`):
//! the remote interlock and key switch are set by bytes on the log
//! channel's input (the host's `@interlock open|closed` and `@key off|on`),
//! read by the stop button's reader ([`note_control_byte`]); the emission
//! indicator is reported on the log channel (`@indicator on=0|1`). The
//! wiring starts as on a bench with the jumpers fitted: closed and on.

use core::sync::atomic::{AtomicBool, Ordering};

use embassy_sync::blocking_mutex::raw::CriticalSectionRawMutex;
use embassy_sync::signal::Signal;
use laser_app::app::LaserControls;
use laser_app::laser_controls::ControlInputs;

use crate::log_channel;

/// Opens the remote interlock.
pub const INTERLOCK_OPEN_BYTE: u8 = b'I';
/// Closes the remote interlock.
pub const INTERLOCK_CLOSED_BYTE: u8 = b'i';
/// Turns the key switch off.
pub const KEY_OFF_BYTE: u8 = b'K';
/// Turns the key switch on.
pub const KEY_ON_BYTE: u8 = b'k';

static INTERLOCK_CLOSED: AtomicBool = AtomicBool::new(true);
static KEY_ON: AtomicBool = AtomicBool::new(true);
static EDGE: Signal<CriticalSectionRawMutex, ()> = Signal::new();

/// Applies a control byte from the log channel; `false` when `byte` is
/// none of them.
pub fn note_control_byte(byte: u8) -> bool {
    let (input, level) = match byte {
        INTERLOCK_OPEN_BYTE => (&INTERLOCK_CLOSED, false),
        INTERLOCK_CLOSED_BYTE => (&INTERLOCK_CLOSED, true),
        KEY_OFF_BYTE => (&KEY_ON, false),
        KEY_ON_BYTE => (&KEY_ON, true),
        _ => return false,
    };
    input.store(level, Ordering::Release);
    EDGE.signal(());
    true
}

/// The board part: the two inputs as the host set them, the indicator on
/// the log channel.
pub struct ChannelLaserControls {
    /// The indicator level last reported.
    pub shown: Option<bool>,
}

impl LaserControls for ChannelLaserControls {
    fn read(&mut self) -> ControlInputs {
        ControlInputs {
            interlock_closed: INTERLOCK_CLOSED.load(Ordering::Acquire),
            key_on: KEY_ON.load(Ordering::Acquire),
        }
    }

    async fn changed(&mut self) {
        EDGE.wait().await;
    }

    fn set_indicator(&mut self, on: bool) {
        if self.shown != Some(on) {
            self.shown = Some(on);
            log_channel::line(format_args!("@indicator on={}", u8::from(on)));
        }
    }
}
