//! The gimbal driver's G-code steps: a servo move per step, and the servo
//! move every point of the gimbal goes out as.

use crate::domain::{Aim, Target};
use crate::grbl::{Alarm, PointMm};
use crate::sequencer::drivers::stage::Stage;
use crate::sequencer::faults;
use crate::sequencer::gcode::queue::{CORNER_DEADBAND_TENTHS, cm};
use crate::sequencer::io::{Action, ActionSink};
use crate::sequencer::laser::LaserEvent;
use crate::servo::task::ServoRequest;
use crate::settings::Settings;

/// A servo move for the G-code step from `from` to `to` at `feed`
/// mm/min (rapid: servo speed; `corner`: it ends a block); its request
/// number, `None` when `to` is out of reach (alarm raised).
pub(in crate::sequencer) fn send_step(
    st: &mut Stage,
    from: PointMm,
    to: PointMm,
    feed: Option<f64>,
    corner: bool,
    out: &mut dyn ActionSink,
) -> Option<u32> {
    let point = cm(to);
    let Ok(aim) = st.aimer.aim(point) else {
        st.alarm = Some(Alarm::SoftLimit);
        return None;
    };
    let by_servo = interval_ms(st.settings, st.servo_at(), &aim);
    let by_feed = feed.map_or(0.0, |f| {
        let f = st.gcode.overrides.feed_mm_min(f);
        60_000.0 * from.distance_to(to) / f.max(1e-3)
    });
    let interval_ms = libm::fmax(f64::from(by_servo), by_feed).min(f64::from(u16::MAX)) as u16;
    st.gcode.step_speed_ratio = crate::sequencer::gcode::power::speed_ratio(by_feed, interval_ms);
    let target = Target { point, grid: None };
    Some(servo_move(st, target, aim, interval_ms, corner, out))
}

/// Sends the gimbal to `aim` (at `target`) over `interval_ms` under the
/// next request number (returned), arrival within the deadband (the
/// corner's, tighter, when `corner`: a block or the stream ends there);
/// notes the move for the laser logic and as the last aim.
pub(in crate::sequencer) fn servo_move(
    st: &mut Stage,
    target: Target,
    aim: Aim,
    interval_ms: u16,
    corner: bool,
    out: &mut dyn ActionSink,
) -> u32 {
    let settings = st.settings;
    let deadband_tenths = if corner {
        CORNER_DEADBAND_TENTHS
    } else {
        (settings.deadband_deg * 10.0) as u16
    };
    let seq = st.take_seq();
    out.act(Action::Servo(ServoRequest::Move {
        seq,
        yaw_tenths: aim.yaw_wire,
        pitch_tenths: aim.pitch_wire,
        interval_ms,
        ids: (settings.yaw.id, settings.pitch.id),
        deadband_tenths,
        ranges_tenths: faults::servo_ranges_tenths(settings),
    }));
    out.act(Action::Note(LaserEvent::GimbalMoveSent));
    *st.last_aim = Some((target, aim));
    seq
}

/// Travel time for a move from `at` (servo angles, 0.1°; `None`: 0, 0)
/// to `aim` at the configured speed, from the largest joint change, ms
/// (at least 20 ms, the SDK's minimum ramp).
pub(in crate::sequencer) fn interval_ms(
    settings: &Settings,
    at: Option<(i16, i16)>,
    aim: &Aim,
) -> u16 {
    let (from_yaw, from_pitch) = at.unwrap_or((0, 0));
    let travel_tenths = (i32::from(aim.yaw_wire) - i32::from(from_yaw))
        .abs()
        .max((i32::from(aim.pitch_wire) - i32::from(from_pitch)).abs());
    let travel_deg = f64::from(travel_tenths) / 10.0;
    let ms = 1000.0 * travel_deg / settings.servo_speed_deg_s;
    (ms as u32).clamp(20, u32::from(u16::MAX)) as u16
}
