//! The gimbal's side of the simulated board: its laser output (the gated
//! pin plus the sequencer's events, recorded with the servos' true state
//! for the safety checker) and the spot sampler that follows where the
//! gimbal points.

use std::cell::RefCell;
use std::rc::Rc;

use embassy_time::Timer;
use laser_app::sequencer::{LaserEvent, LaserPower, LaserSwitch};
use laser_app::status::{Phase, StatusBoard};

use crate::laser::GatedLaserPin;
use crate::physics::PhysicalGimbal;
use crate::recorder::{
    DwellRecord, EventRecord, Recording, SequencerEvent, ServoSample, ServoState, SpotSample,
};
use crate::servo_model::SimServoBus;

/// The gimbal laser output: the gated pin (which records the effective
/// laser), plus every sequencer event with its time and the servos' true
/// state at each switch and event (for the safety checker).
pub struct RecordingLaser {
    /// The gated pin that records the effective gimbal laser.
    pub pin: GatedLaserPin,
    /// Where the events and servo samples go.
    pub recording: Rc<RefCell<Recording>>,
    /// The simulated servos (their true state at each event).
    pub bus: Rc<RefCell<SimServoBus>>,
    /// The true gimbal.
    pub gimbal: PhysicalGimbal,
}

impl RecordingLaser {
    fn record_servos(&self, rec: &mut Recording, t_us: u64) {
        let laser = rec.laser_at(t_us);
        rec.servos
            .push(servo_sample(&self.bus.borrow(), self.gimbal, t_us, laser));
    }
}

impl LaserSwitch for RecordingLaser {
    fn set(&mut self, power: LaserPower) {
        self.pin.set(power);
        crate::executor::simulator_work(|| {
            let t = crate::clock::now_us();
            let mut rec = self.recording.borrow_mut();
            self.record_servos(&mut rec, t);
        });
    }

    fn note(&mut self, event: LaserEvent<'_>) {
        crate::executor::simulator_work(|| self.record_event(event));
    }
}

impl RecordingLaser {
    fn record_event(&self, event: LaserEvent<'_>) {
        let t_us = crate::clock::now_us();
        let event = match event {
            LaserEvent::Stopped { why } => SequencerEvent::Stopped {
                why: why.to_owned(),
            },
            LaserEvent::RunStarted => SequencerEvent::RunStarted,
            LaserEvent::GimbalMoveSent => SequencerEvent::GimbalMoveSent,
            LaserEvent::GimbalArrived => SequencerEvent::GimbalArrived,
        };
        let mut rec = self.recording.borrow_mut();
        let laser_switches_before = rec.laser_events.len();
        rec.events.push(EventRecord {
            t_us,
            event,
            laser_switches_before,
        });
        self.record_servos(&mut rec, t_us);
    }
}

/// The gimbal servos' true angles and targets at `t_us`.
fn servo_sample(bus: &SimServoBus, gimbal: PhysicalGimbal, t_us: u64, laser: bool) -> ServoSample {
    let state = |id| {
        bus.servo(id).map(|s| ServoState {
            angle_deg: s.angle_deg(t_us),
            target_deg: f64::from(s.target_tenths()) / 10.0,
        })
    };
    ServoSample {
        t_us,
        yaw: state(gimbal.yaw_id),
        pitch: state(gimbal.pitch_id),
        laser,
    }
}

/// Where the pointing actuator's spot is at a time (µs), cm (`None`: off
/// the board).
pub type SpotFn = Rc<dyn Fn(u64) -> Option<(f64, f64)>>;

/// Where the gimbal spot is at `t_us` (from the simulated servos' true
/// angles through the exact forward kinematics), board cm.
pub fn gimbal_spot_cm(
    bus: &Rc<RefCell<SimServoBus>>,
    gimbal: PhysicalGimbal,
    t_us: u64,
) -> Option<(f64, f64)> {
    let bus = bus.borrow();
    let yaw_deg = bus.angle_deg(gimbal.yaw_id, t_us).unwrap_or(0.0);
    let pitch_deg = bus.angle_deg(gimbal.pitch_id, t_us).unwrap_or(0.0);
    gimbal.spot_cm(yaw_deg, pitch_deg)
}

/// Samples the spot (`spot_at`: the gimbal's from the simulated servos'
/// true angles, or the stepper's from its counted steps), and records
/// where it was at the end of each dwell.
pub async fn spot_sampler(
    bus: Rc<RefCell<SimServoBus>>,
    spot_at: SpotFn,
    recording: Rc<RefCell<Recording>>,
    status: &'static StatusBoard,
    gimbal: PhysicalGimbal,
    period_us: u64,
) {
    let mut open_dwell: Option<(DwellKey, usize)> = None;
    loop {
        let t_us = crate::clock::now_us();
        let spot = spot_at(t_us);
        {
            let mut rec = recording.borrow_mut();
            let laser = rec.laser_at(t_us);
            let power = rec.power_at(t_us);
            rec.servos
                .push(servo_sample(&bus.borrow(), gimbal, t_us, laser));
            if let Some((x_cm, y_cm)) = spot {
                rec.spot.push(SpotSample {
                    t_us,
                    x_cm,
                    y_cm,
                    laser,
                    power,
                });
            }
            let s = status.snapshot();
            let dwelling = matches!(s.phase, Some(Phase::Dwelling | Phase::Holding));
            let key = DwellKey {
                index: s.point_index,
                pass: s.pass,
                target: s
                    .target
                    .map(|(t, _)| (t.point.x_cm.to_bits(), t.point.y_cm.to_bits())),
            };
            match (dwelling, s.target, spot) {
                (true, Some((target, _)), Some(spot_cm)) => {
                    // The dwell record keeps the last spot seen during the dwell
                    // (the servos settle onto their quantised target).
                    match open_dwell {
                        Some((open_key, i)) if open_key == key => {
                            if let Some(record) = rec.dwells.get_mut(i) {
                                record.spot_cm = spot_cm;
                                record.laser &= laser;
                            }
                        }
                        _ => {
                            rec.dwells.push(DwellRecord {
                                t_us,
                                target_cm: (target.point.x_cm, target.point.y_cm),
                                grid: target.grid,
                                spot_cm,
                                laser,
                            });
                            open_dwell = Some((key, rec.dwells.len() - 1));
                        }
                    }
                }
                _ => open_dwell = None,
            }
        }
        Timer::after_micros(period_us).await;
    }
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct DwellKey {
    index: Option<usize>,
    pass: u32,
    target: Option<(u64, u64)>,
}
