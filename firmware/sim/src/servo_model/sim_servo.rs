//! One simulated servo: its state, the requests it obeys and the
//! responses it gives (the behaviour modelled is listed in [`super`]).

use fashionstar::{
    MAX_SERVO_ID, Monitor, MotionCommand, ReadData, Request, Response, SetAngle,
    SetAngleByInterval, SetAngleByVelocity, WriteResult, address,
};

use super::motion::Motion;

/// Servo bus baud rate, bit/s.
pub const BAUD: u64 = 115_200;
/// Bits on the wire per byte (8N1: start, 8 data, stop).
pub const BITS_PER_BYTE: u64 = 10;
/// Time one byte takes on the wire, µs: 10 bits at 115200 baud is 86.8 µs,
/// rounded up to whole µs so that byte times add up exactly whatever the
/// chunking (0.2 % slow; the simulated UART uses the same value).
pub const BYTE_TIME_US: u64 = (BITS_PER_BYTE * 1_000_000).div_ceil(BAUD);
/// Delay between the last byte of a request and the first byte of the
/// answer, µs.
pub const PROCESSING_DELAY_US: u64 = 200;
/// The servo's angle range, 0.1° (±180.0°).
pub const RANGE_TENTHS_DEG: i16 = 1800;
/// Supply voltage reported by query monitor and read data, mV.
pub const SUPPLY_MV: u16 = 7400;
/// Temperature reported, raw NTC ADC value (≈ 30 °C by the SDK's
/// conversion with B = 3435 and 2048 = 25 °C).
pub const TEMPERATURE_RAW: u16 = 1854;
/// Current drawn while holding, mA.
pub const IDLE_CURRENT_MA: u16 = 20;
/// Current drawn while moving, mA.
pub const MOVING_CURRENT_MA: u16 = 150;
/// Slowest velocity a servo moves at, °/s.
const MIN_VELOCITY_DEG_S: f64 = 1.0;

/// Time `bytes` bytes take on the wire, µs ([`BYTE_TIME_US`] each).
pub fn wire_time_us(bytes: usize) -> u64 {
    bytes as u64 * BYTE_TIME_US
}

/// `deg` as the servo reports it: 0.1° steps, within ±180.0°.
pub fn quantise_tenths(deg: f64) -> i16 {
    let tenths = (deg * 10.0).round();
    let limit = f64::from(RANGE_TENTHS_DEG);
    // Clamped to ±1800 first, so the cast is exact (NaN casts to 0).
    tenths.clamp(-limit, limit) as i16
}

fn clamp_target_deg(angle_tenths_deg: i16) -> f64 {
    f64::from(angle_tenths_deg.clamp(-RANGE_TENTHS_DEG, RANGE_TENTHS_DEG)) / 10.0
}

/// One simulated servo.
#[derive(Debug, Clone, PartialEq)]
pub struct SimServo {
    /// Bus id (the bus finds its servos by it).
    pub(super) id: u8,
    motion: Motion,
    slow_factor: f64,
    silent: bool,
}

impl SimServo {
    /// Servo `id` at 0°, normal speed, answering.
    pub fn new(id: u8) -> Self {
        Self {
            id,
            motion: Motion::hold(0.0),
            slow_factor: 1.0,
            silent: false,
        }
    }

    /// The same servo standing at `deg` degrees instead.
    pub fn with_angle_deg(mut self, deg: f64) -> Self {
        self.motion = Motion::hold(deg);
        self
    }

    /// Bus id.
    pub fn id(&self) -> u8 {
        self.id
    }

    /// True angle at `now_us`, degrees (unquantised, for drawing).
    pub fn angle_deg(&self, now_us: u64) -> f64 {
        self.motion.angle_at(now_us as f64)
    }

    /// Angle at `now_us` as the servo reports it, 0.1°.
    pub fn angle_tenths(&self, now_us: u64) -> i16 {
        quantise_tenths(self.angle_deg(now_us))
    }

    /// Target of the current (or last) move, 0.1°.
    pub fn target_tenths(&self) -> i16 {
        quantise_tenths(self.motion.target_deg())
    }

    /// When the current move ends, µs (rounded up).
    pub fn arrival_us(&self) -> u64 {
        self.motion.end_us().max(0.0).ceil() as u64
    }

    /// Whether the servo is still moving at `now_us`.
    pub fn is_moving(&self, now_us: u64) -> bool {
        (now_us as f64) < self.motion.end_us()
    }

    /// Movement slowness: every move commanded from now on takes this many
    /// times longer (fault injection `servo-slow:<factor>`).
    pub fn slow_factor(&self) -> f64 {
        self.slow_factor
    }

    /// Sets the slowness factor (values that are not finite and positive
    /// mean 1).
    pub fn set_slow_factor(&mut self, factor: f64) {
        self.slow_factor = if factor.is_finite() && factor > 0.0 {
            factor
        } else {
            1.0
        };
    }

    /// Whether the servo answers nothing.
    pub fn is_silent(&self) -> bool {
        self.silent
    }

    /// Silences the servo (it still obeys commands) or lets it answer again.
    pub fn set_silent(&mut self, silent: bool) {
        self.silent = silent;
    }

    /// Carries out `request`, received completely at `now_us`, if it
    /// addresses this servo; returns the answer the servo sends, if any.
    pub fn execute(&mut self, now_us: u64, request: &Request) -> Option<Response> {
        let t = now_us as f64;
        let from = self.angle_deg(now_us);
        match request.motion_for(self.id) {
            Some(MotionCommand::SetAngle(c)) => self.set_angle(t, from, &c),
            Some(MotionCommand::SetAngleByInterval(c)) => self.by_interval(t, from, &c),
            Some(MotionCommand::SetAngleByVelocity(c)) => self.by_velocity(t, from, &c),
            Some(MotionCommand::Damping { .. }) => self.motion = Motion::hold(from),
            None => {}
        }
        if self.silent || request.id() != Some(self.id) {
            return None;
        }
        if let Request::WriteData { address, data, .. } = request {
            return Some(self.write(*address, data));
        }
        self.answer(now_us, request)
    }

    /// A write to the data table: only the id (address 34) is modelled.
    fn write(&mut self, address: u8, data: &[u8]) -> Response {
        let id = self.id;
        let result = match (address, data) {
            (address::SERVO_ID, &[new_id]) if new_id <= MAX_SERVO_ID => {
                self.id = new_id;
                1
            }
            _ => 0,
        };
        Response::WriteData(WriteResult {
            id,
            address,
            result,
        })
    }

    fn set_angle(&mut self, t: f64, from: f64, c: &SetAngle) {
        let to = clamp_target_deg(c.angle_tenths_deg);
        let interval = f64::from(c.interval_ms) * 1000.0 * self.slow_factor;
        self.motion = Motion::by_interval(t, from, to, interval, 0.0, 0.0);
    }

    fn by_interval(&mut self, t: f64, from: f64, c: &SetAngleByInterval) {
        let to = clamp_target_deg(c.angle_tenths_deg);
        let k = 1000.0 * self.slow_factor;
        self.motion = Motion::by_interval(
            t,
            from,
            to,
            f64::from(c.interval_ms) * k,
            f64::from(c.t_acc_ms) * k,
            f64::from(c.t_dec_ms) * k,
        );
    }

    fn by_velocity(&mut self, t: f64, from: f64, c: &SetAngleByVelocity) {
        let to = clamp_target_deg(c.angle_tenths_deg);
        let k = 1000.0 * self.slow_factor;
        let velocity = (f64::from(c.velocity_tenths_deg_s) / 10.0).max(MIN_VELOCITY_DEG_S);
        self.motion = Motion::by_velocity(
            t,
            from,
            to,
            velocity / self.slow_factor,
            f64::from(c.t_acc_ms) * k,
            f64::from(c.t_dec_ms) * k,
        );
    }

    fn monitor(&self, now_us: u64) -> Monitor {
        let moving = self.is_moving(now_us);
        let current_ma = if moving {
            MOVING_CURRENT_MA
        } else {
            IDLE_CURRENT_MA
        };
        Monitor {
            id: self.id,
            voltage_mv: SUPPLY_MV,
            current_ma,
            power_mw: (u32::from(SUPPLY_MV) * u32::from(current_ma) / 1000) as u16,
            temperature_raw: TEMPERATURE_RAW,
            status: u8::from(moving),
            angle_tenths_deg: i32::from(self.angle_tenths(now_us)),
            turns: 0,
        }
    }

    fn answer(&self, now_us: u64, request: &Request) -> Option<Response> {
        let id = self.id;
        match request {
            Request::Ping { .. } => Some(Response::Ping { id }),
            Request::QueryAngle { .. } => Some(Response::Angle {
                id,
                angle_tenths_deg: self.angle_tenths(now_us),
            }),
            Request::QueryMonitor { .. } => Some(Response::Monitor(self.monitor(now_us))),
            Request::ReadData { address, .. } => {
                let m = self.monitor(now_us);
                let data: &[u8] = match address {
                    1 => &m.voltage_mv.to_le_bytes(),
                    2 => &m.current_ma.to_le_bytes(),
                    3 => &m.power_mw.to_le_bytes(),
                    4 => &m.temperature_raw.to_le_bytes(),
                    5 => &[m.status],
                    34 => &[id],
                    _ => return None,
                };
                Some(Response::ReadData(ReadData {
                    id,
                    address: *address,
                    data: heapless::Vec::from_slice(data).ok()?,
                }))
            }
            _ => None,
        }
    }
}
