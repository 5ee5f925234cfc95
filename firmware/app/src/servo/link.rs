//! What the sequencer and the servo task say to each other: the bus
//! configuration, the requests, the faults and outcomes, and the channels
//! that carry them ([`ServoLink`]).

use core::sync::atomic::AtomicU32;

use embassy_sync::blocking_mutex::raw::CriticalSectionRawMutex;
use embassy_sync::channel::Channel;

use super::plausibility::WIRE_LIMIT_TENTHS;
use crate::text::Int;

/// Servo ids and timing of the servo bus. All durations in ms, angles in
/// the servo's wire unit (0.1°).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct ServoBusConfig {
    /// Bus id of the yaw servo.
    pub yaw_id: u8,
    /// Bus id of the pitch servo.
    pub pitch_id: u8,
    /// Arrived when both measured angles are within this many 0.1° steps.
    pub deadband_tenths: u16,
    /// How long to wait for a response frame, ms.
    pub response_timeout_ms: u16,
    /// Extra attempts after a query got no valid response.
    pub retries: u8,
    /// Period of angle polls while waiting for arrival, ms.
    pub poll_period_ms: u16,
    /// Arrival deadline beyond the commanded interval, ms (plus 50 % of
    /// the interval); a move not finished by then is a fault.
    pub arrival_margin_ms: u16,
    /// Period of the health check while no move runs (both angles are
    /// queried, so a servo that stops answering during a dwell or a held
    /// goto is a fault within this period plus the retries), ms.
    pub health_check_ms: u16,
    /// Configured angle range of the yaw and the pitch servo, 0.1°
    /// (`(min, max)`; readings outside are implausible).
    pub ranges_tenths: [(i16, i16); 2],
}

impl Default for ServoBusConfig {
    fn default() -> Self {
        Self {
            yaw_id: 0,
            pitch_id: 1,
            deadband_tenths: 5,
            response_timeout_ms: 20,
            retries: 2,
            poll_period_ms: 10,
            arrival_margin_ms: 300,
            health_check_ms: 100,
            ranges_tenths: [(-WIRE, WIRE); 2],
        }
    }
}

/// What the sequencer asks of the servo task. `seq` ties the outcome to
/// the request.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum ServoRequest {
    /// Start both servos towards the given wire angles (0.1°) together,
    /// taking `interval_ms`, and report when both have arrived.
    Move {
        /// Request number.
        seq: u32,
        /// Yaw servo target, 0.1°.
        yaw_tenths: i16,
        /// Pitch servo target, 0.1°.
        pitch_tenths: i16,
        /// Commanded travel time, ms.
        interval_ms: u16,
        /// Bus ids `(yaw, pitch)` (from the settings; used from now on).
        ids: (u8, u8),
        /// Arrival deadband, 0.1° (used from now on).
        deadband_tenths: u16,
        /// Configured range `(min, max)` of the yaw and the pitch servo,
        /// 0.1° (used from now on by the plausibility filter).
        ranges_tenths: [(i16, i16); 2],
    },
    /// A bus set-up job (console `servo …`): reported with
    /// [`ServoOutcome::Bus`] lines and one [`BusReport::Done`].
    Setup {
        /// Request number.
        seq: u32,
        /// What to do.
        job: BusJob,
    },
}

impl ServoRequest {
    /// The request number.
    pub fn seq(&self) -> u32 {
        match self {
            ServoRequest::Move { seq, .. } | ServoRequest::Setup { seq, .. } => *seq,
        }
    }
}

/// A servo-bus set-up job (the procedures are in `task/setup.rs`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum BusJob {
    /// Ping every id 0–254, then read the monitor data of each that
    /// answered.
    Scan,
    /// Ping servo `id` and read its monitor data.
    Ping {
        /// Bus id.
        id: u8,
    },
    /// Give servo `id` the bus id `new_id` (data-table address 34),
    /// only when it is the one servo answering on the bus.
    SetId {
        /// Its id now.
        id: u8,
        /// Its new id (0–254).
        new_id: u8,
    },
    /// Read servo `id`'s angle (for `servo zero`).
    ReadAngle {
        /// Bus id.
        id: u8,
    },
}

/// One servo as a scan or ping found it (its monitor data).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct ServoReading {
    /// Bus id.
    pub id: u8,
    /// Angle, 0.1°.
    pub angle_tenths: i32,
    /// Supply voltage, mV.
    pub voltage_mv: u16,
    /// Temperature as the raw NTC ADC value (see
    /// [`fashionstar::Monitor::temperature_raw`]).
    pub temperature_raw: u16,
}

/// What a set-up job reports: zero or more lines, then its end.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum BusReport {
    /// A servo answered (a data line).
    Servo(ServoReading),
    /// Servo id `id` answered with garbled frames: more than one servo
    /// has this id (a data line).
    Collision {
        /// Bus id.
        id: u8,
    },
    /// The job ended.
    Done(BusEnd),
}

/// How a set-up job ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum BusEnd {
    /// A scan: this many ids answered cleanly, this many garbled.
    Scanned {
        /// Ids that answered.
        answering: u8,
        /// Ids whose answers collided.
        collisions: u8,
    },
    /// A ping was answered.
    Answered,
    /// Servo `id` now answers as `new_id`.
    IdChanged {
        /// Its old id.
        id: u8,
        /// Its new id.
        new_id: u8,
    },
    /// The angle of a [`BusJob::ReadAngle`], 0.1°.
    Angle {
        /// Bus id.
        id: u8,
        /// Angle, 0.1°.
        tenths: i16,
    },
    /// Servo `id` did not answer (or only garbled).
    NoAnswer {
        /// Bus id.
        id: u8,
    },
    /// `servo id` refused: not exactly one servo (`id`) answers on the
    /// bus.
    NotAlone {
        /// Ids that answered cleanly.
        answering: u8,
        /// Ids whose answers collided.
        collisions: u8,
    },
    /// The servo answered the write with a failure result, or did not
    /// answer as `new_id` afterwards.
    WriteFailed {
        /// Its id.
        id: u8,
    },
    /// Writing to the UART failed.
    BusError,
}

/// Why a servo is considered faulty. `Debug` prints what `derive(Debug)`
/// would (`NotArrived { at_tenths: 12, target_tenths: 30 }`; replies show
/// it), written out: the derived one links `core`'s struct-debug builder
/// (~800 B of flash) for this one type.
#[derive(Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum ServoFault {
    /// No valid response after all retries.
    NoResponse,
    /// Still away from the target at the arrival deadline (measured angle,
    /// 0.1°).
    NotArrived {
        /// Last measured angle, 0.1°.
        at_tenths: i16,
        /// Target angle, 0.1°.
        target_tenths: i16,
    },
    /// Writing to the UART failed.
    BusError,
    /// [`IMPLAUSIBLE_RUN`](super::plausibility::IMPLAUSIBLE_RUN) angle readings in a row were physically
    /// impossible (outside the range, or a jump no servo can make): the
    /// bus delivers corrupted frames that pass the checksum.
    ImplausibleReading {
        /// The last rejected reading, 0.1°.
        at_tenths: i16,
    },
}

impl core::fmt::Debug for ServoFault {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match *self {
            ServoFault::NoResponse => f.write_str("NoResponse"),
            ServoFault::NotArrived {
                at_tenths,
                target_tenths,
            } => write!(
                f,
                "NotArrived {{ at_tenths: {}, target_tenths: {} }}",
                Int(at_tenths.into()),
                Int(target_tenths.into())
            ),
            ServoFault::BusError => f.write_str("BusError"),
            ServoFault::ImplausibleReading { at_tenths } => {
                write!(
                    f,
                    "ImplausibleReading {{ at_tenths: {} }}",
                    Int(at_tenths.into())
                )
            }
        }
    }
}

/// What the servo task reports.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum ServoOutcome {
    /// Both servos are within the deadband of the targets of `Move` `seq`.
    Arrived {
        /// Request number.
        seq: u32,
        /// Measured yaw angle, 0.1°.
        yaw_tenths: i16,
        /// Measured pitch angle, 0.1°.
        pitch_tenths: i16,
    },
    /// Request `seq` failed because servo `id` is faulty.
    Fault {
        /// Request number.
        seq: u32,
        /// Bus id of the faulty servo.
        id: u8,
        /// What went wrong.
        fault: ServoFault,
    },
    /// Request `seq` was abandoned because a newer request arrived.
    Superseded {
        /// Request number.
        seq: u32,
    },
    /// A previously faulty servo answers again (found while idle).
    Recovered {
        /// Bus id.
        id: u8,
    },
    /// A line or the end of set-up job `seq`.
    Bus {
        /// Request number.
        seq: u32,
        /// What it reports.
        report: BusReport,
    },
}

/// Channels between the sequencer and the servo task.
pub struct ServoLink {
    /// Sequencer → servo task.
    pub requests: Channel<CriticalSectionRawMutex, ServoRequest, 1>,
    /// Servo task → sequencer.
    pub outcomes: Channel<CriticalSectionRawMutex, ServoOutcome, 4>,
    /// Incremented by the servo task at least every
    /// [`IDLE_TICK`](super::task::IDLE_TICK)
    /// (liveness for the watchdog).
    pub alive: AtomicU32,
    /// Angle readings rejected as physically impossible since boot.
    pub implausible_readings: AtomicU32,
}

impl ServoLink {
    /// Empty channels (usable in a `static`).
    pub const fn new() -> Self {
        Self {
            requests: Channel::new(),
            outcomes: Channel::new(),
            alive: AtomicU32::new(0),
            implausible_readings: AtomicU32::new(0),
        }
    }
}

impl Default for ServoLink {
    fn default() -> Self {
        Self::new()
    }
}

/// Largest single-turn angle, 0.1° (default range before the first move).
const WIRE: i16 = WIRE_LIMIT_TENTHS as i16;

#[cfg(test)]
mod tests {
    extern crate std;
    use super::ServoFault;
    use std::format;

    /// The same shape with the derived `Debug`: what replies printed before.
    #[derive(Debug)]
    #[allow(dead_code)] // the fields are read by the derived Debug only
    enum Derived {
        NoResponse,
        NotArrived { at_tenths: i16, target_tenths: i16 },
        BusError,
        ImplausibleReading { at_tenths: i16 },
    }

    #[test]
    fn fault_debug_text_is_the_derived_one() {
        for (a, b) in [(0, 0), (12, -30), (i16::MIN, i16::MAX), (-1, 1800)] {
            let cases = [
                (ServoFault::NoResponse, Derived::NoResponse),
                (
                    ServoFault::NotArrived {
                        at_tenths: a,
                        target_tenths: b,
                    },
                    Derived::NotArrived {
                        at_tenths: a,
                        target_tenths: b,
                    },
                ),
                (ServoFault::BusError, Derived::BusError),
                (
                    ServoFault::ImplausibleReading { at_tenths: a },
                    Derived::ImplausibleReading { at_tenths: a },
                ),
            ];
            for (ours, derived) in cases {
                assert_eq!(format!("{ours:?}"), format!("{derived:?}"));
            }
        }
    }
}
