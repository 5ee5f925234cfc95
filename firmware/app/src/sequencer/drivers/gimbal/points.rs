//! The gimbal driver's points: a pattern's or a goto's point as one
//! servo move.

use crate::domain::Target;
use crate::log;
use crate::sequencer::drivers::gimbal::step::{interval_ms, servo_move};
use crate::sequencer::drivers::stage::{Stage, StopAsked};
use crate::sequencer::io::ActionSink;
use crate::text::{Fixed, reply_text};

/// Aims the gimbal at the run's current point `target` and sends the
/// servo move; `false` on an unreachable target (the run stops with an
/// error notice: [`Stage::stop`]).
pub(in crate::sequencer) fn aim(st: &mut Stage, target: Target, out: &mut dyn ActionSink) -> bool {
    let aim = match st.aimer.aim(target.point) {
        Ok(aim) => aim,
        Err(e) => {
            let why = reply_text(format_args!("{e}"));
            log::warning!("target unreachable: {}", why.as_str());
            // What happened first: the reason may be cut at the
            // reply line length.
            let name = st.run.map_or("goto", |r| r.kind.name());
            let notice = reply_text(format_args!(
                "error: {name} stopped, laser off: point ({}, {}) cm unreachable: {}",
                Fixed::<2>(target.point.x_cm),
                Fixed::<2>(target.point.y_cm),
                why
            ));
            st.stop = Some(StopAsked {
                notice: Some(notice),
                why: "unreachable target",
            });
            return false;
        }
    };
    let interval_ms = interval_ms(st.settings, st.servo_at(), &aim);
    let seq = servo_move(st, target, aim, interval_ms, false, out);
    log::info!(
        "target ({}, {}) cm -> servo {} {} (0.1 deg) over {} ms",
        target.point.x_cm,
        target.point.y_cm,
        aim.yaw_wire,
        aim.pitch_wire,
        interval_ms
    );
    if let Some(run) = st.run.as_mut() {
        run.seq = seq;
    }
    true
}
