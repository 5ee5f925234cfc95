//! What the simulation records: the laser spot over time, the dwell points,
//! laser switching and every frame on the servo bus.

use std::fmt::Write as _;

use laser_app::domain::units::mm_from_cm;

/// A sample of the simulated laser spot (from the simulated servos' actual
/// angles through the exact forward kinematics).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SpotSample {
    /// Simulated time, µs.
    pub t_us: u64,
    /// Board x, cm.
    pub x_cm: f64,
    /// Board y, cm.
    pub y_cm: f64,
    /// Laser output at that time.
    pub laser: bool,
    /// Laser power at that time, ‰ of full (0 dark; an on/off output
    /// records 1000 when on).
    pub power: u16,
}

/// The spot while the sequencer dwelt on a point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DwellRecord {
    /// When the dwell started, µs.
    pub t_us: u64,
    /// Commanded board point, cm.
    pub target_cm: (f64, f64),
    /// Grid index of the target, if it is a grid point.
    pub grid: Option<(i8, i8)>,
    /// Where the spot actually was, cm.
    pub spot_cm: (f64, f64),
    /// Laser state during the dwell.
    pub laser: bool,
}

impl DwellRecord {
    /// The commanded board point, mm.
    pub fn target_mm(&self) -> [f64; 2] {
        [mm_from_cm(self.target_cm.0), mm_from_cm(self.target_cm.1)]
    }

    /// Where the spot really was, mm.
    pub fn spot_mm(&self) -> [f64; 2] {
        [mm_from_cm(self.spot_cm.0), mm_from_cm(self.spot_cm.1)]
    }

    /// The spot minus the commanded point, mm (what a calibration measures).
    pub fn error_mm(&self) -> [f64; 2] {
        let (target, spot) = (self.target_mm(), self.spot_mm());
        [spot[0] - target[0], spot[1] - target[1]]
    }
}

/// Direction of a frame on the servo bus.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Direction {
    /// Firmware → servo.
    Tx,
    /// Servo → firmware.
    Rx,
}

/// One frame on the servo bus.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct FrameRecord {
    /// When its first byte went on the wire, µs.
    pub t_us: u64,
    /// Direction.
    pub direction: Direction,
    /// The bytes as sent (after any injected corruption).
    pub bytes: Vec<u8>,
}

/// A sequencer event that decides when a laser may be lit, as processed by
/// the firmware (see `laser_app::sequencer::LaserEvent`).
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum SequencerEvent {
    /// The sequencer stopped; `why` as logged (`"stop command"`,
    /// `"stop button"`, `"servo fault"`, `"galvo underrun"`, …).
    Stopped {
        /// Reason.
        why: String,
    },
    /// A pattern or goto started.
    RunStarted,
    /// A servo move was sent.
    GimbalMoveSent,
    /// The servo task's arrival confirmation was accepted.
    GimbalArrived,
}

/// A [`SequencerEvent`] with the simulated time it was processed.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct EventRecord {
    /// Simulated time, µs.
    pub t_us: u64,
    /// What happened.
    pub event: SequencerEvent,
    /// Laser switches (`Recording::laser_events`) recorded before it: the
    /// order of events and switches within one instant.
    pub laser_switches_before: usize,
}

/// One gimbal servo's true state.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ServoState {
    /// True angle, degrees (unquantised).
    pub angle_deg: f64,
    /// Target of its current (or last) move, degrees (0.1° resolution).
    pub target_deg: f64,
}

/// The gimbal servos' true angles and targets at one time, with the
/// gimbal laser's state.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ServoSample {
    /// Simulated time, µs.
    pub t_us: u64,
    /// Yaw servo (`None`: no such servo on the bus).
    pub yaw: Option<ServoState>,
    /// Pitch servo.
    pub pitch: Option<ServoState>,
    /// Gimbal laser output at that time (after any switch at `t_us`).
    pub laser: bool,
}

/// A response frame the fault injection corrupted on the wire.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct CorruptedFrame {
    /// When its first byte went on the wire, µs (as in [`FrameRecord`]).
    pub t_us: u64,
    /// The bytes as the servo sent them.
    pub sent: Vec<u8>,
    /// The bytes as the firmware received them.
    pub received: Vec<u8>,
}

/// Everything recorded during a run.
#[derive(Debug, Default, Clone)]
pub struct Recording {
    /// Spot samples.
    pub spot: Vec<SpotSample>,
    /// Dwell points.
    pub dwells: Vec<DwellRecord>,
    /// Laser switching: (t µs, on).
    pub laser_events: Vec<(u64, bool)>,
    /// Gimbal laser power changes: (t µs, duty ‰ of full; 0 dark).
    pub laser_power: Vec<(u64, u16)>,
    /// Servo-bus frames.
    pub frames: Vec<FrameRecord>,
    /// Sequencer events that decide when a laser may be lit, in order.
    pub events: Vec<EventRecord>,
    /// Servo angles and targets: every spot sample period and at every
    /// gimbal laser switch and sequencer event.
    pub servos: Vec<ServoSample>,
    /// Response frames corrupted by the fault injection (their clean
    /// bytes), in order.
    pub clean_rx: Vec<CorruptedFrame>,
}

impl Recording {
    /// `--frames` format: `t_ms direction hex-bytes`, one frame per line.
    pub fn frames_text(&self) -> String {
        let mut out = String::new();
        for f in &self.frames {
            let dir = match f.direction {
                Direction::Tx => "tx",
                Direction::Rx => "rx",
            };
            let _ = write!(out, "{:.3} {dir}", f.t_us as f64 / 1000.0);
            for b in &f.bytes {
                let _ = write!(out, " {b:02x}");
            }
            out.push('\n');
        }
        out
    }

    /// `--trace` format: CSV `t_ms,x_cm,y_cm,laser,power` (power: duty
    /// ‰ of full).
    pub fn trace_csv(&self) -> String {
        let mut out = String::from("t_ms,x_cm,y_cm,laser,power\n");
        for s in &self.spot {
            let _ = writeln!(
                out,
                "{:.3},{:.4},{:.4},{},{}",
                s.t_us as f64 / 1000.0,
                s.x_cm,
                s.y_cm,
                u8::from(s.laser),
                s.power
            );
        }
        out
    }

    /// Every dwell as a measurement for `cargo xtask calib fit`: CSV
    /// `x,y,dx,dy`, mm — the commanded board point and where the spot
    /// really was minus it (what a user measures with a ruler).
    pub fn dwells_csv(&self) -> String {
        let mut out = String::from("x,y,dx,dy\n");
        for d in &self.dwells {
            let ([x, y], [dx, dy]) = (d.target_mm(), d.error_mm());
            let _ = writeln!(out, "{x:.4},{y:.4},{dx:.4},{dy:.4}");
        }
        out
    }

    /// The largest distance between a dwell's commanded point and the
    /// spot, mm (`None` without dwells).
    pub fn worst_dwell_error_mm(&self) -> Option<f64> {
        self.dwells
            .iter()
            .map(|d| {
                let [dx, dy] = d.error_mm();
                dx.hypot(dy)
            })
            .reduce(f64::max)
    }

    /// Gimbal laser power at time `t_us`, ‰ (0 before the first change).
    pub fn power_at(&self, t_us: u64) -> u16 {
        self.laser_power
            .iter()
            .take_while(|(t, _)| *t <= t_us)
            .last()
            .map_or(0, |(_, p)| *p)
    }

    /// Laser state at time `t_us` (off before the first event).
    pub fn laser_at(&self, t_us: u64) -> bool {
        self.laser_events
            .iter()
            .take_while(|(t, _)| *t <= t_us)
            .last()
            .is_some_and(|(_, on)| *on)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frames_dump_is_time_direction_hex() {
        let rec = Recording {
            frames: vec![FrameRecord {
                t_us: 1500,
                direction: Direction::Tx,
                bytes: vec![0x12, 0x4c, 0x01, 0x01, 0x00, 0x60],
            }],
            ..Default::default()
        };
        assert_eq!(rec.frames_text(), "1.500 tx 12 4c 01 01 00 60\n");
    }

    #[test]
    fn laser_state_follows_events() {
        let rec = Recording {
            laser_events: vec![(100, true), (300, false)],
            ..Default::default()
        };
        assert!(!rec.laser_at(50));
        assert!(rec.laser_at(100));
        assert!(rec.laser_at(299));
        assert!(!rec.laser_at(300));
    }
}
