//! The event trace on the console (`trace on`): every change of the
//! gimbal/stepper laser output and every laser-deciding sequencer event
//! as a notice stamped with the board's clock, so a host that only has
//! the serial port (`cargo xtask hil` on a real board) sees what the
//! simulator and the QEMU board record. Lines, inside `[…]`:
//!
//! ```text
//! trace <µs since boot> @laser <0|1> <power ‰>
//! trace <µs since boot> @event run-started|move-sent|arrived
//! trace <µs since boot> @event stopped <why>
//! ```
//!
//! (the QEMU board log's grammar behind the word `trace`). Off by default;
//! the shell calls these only while [`CommandLink::tracing`]. The galvo's
//! per-sample laser is not traced (it is not a switch).

use super::laser::{LaserEvent, LaserPower};
use crate::command::CommandLink;

/// Reports that the laser output was set to `power` at `t_us`. Out of
/// line: its formatting stays out of the sequencer task's frame.
#[inline(never)]
pub(super) fn laser(link: &CommandLink, t_us: u64, power: LaserPower) {
    link.notify(format_args!(
        "trace {t_us} @laser {} {}",
        u8::from(power.is_on()),
        power.per_mille()
    ));
}

/// Reports `event` at `t_us`.
#[inline(never)]
pub(super) fn event(link: &CommandLink, t_us: u64, event: LaserEvent<'_>) {
    match event {
        LaserEvent::Stopped { why } => {
            link.notify(format_args!("trace {t_us} @event stopped {why}"))
        }
        LaserEvent::RunStarted => link.notify(format_args!("trace {t_us} @event run-started")),
        LaserEvent::GimbalMoveSent => link.notify(format_args!("trace {t_us} @event move-sent")),
        LaserEvent::GimbalArrived => link.notify(format_args!("trace {t_us} @event arrived")),
    }
}

#[cfg(test)]
mod tests {
    extern crate std;
    use std::borrow::ToOwned;
    use std::string::String;
    use std::vec::Vec;

    use super::*;
    use crate::outbound::LineKind;

    #[test]
    fn lines_follow_the_board_log_grammar() {
        let link = CommandLink::new();
        laser(&link, 12, LaserPower::OFF);
        laser(&link, 13, LaserPower::from_fraction(0.3));
        event(
            &link,
            14,
            LaserEvent::Stopped {
                why: "stop command",
            },
        );
        event(&link, 15, LaserEvent::RunStarted);
        event(&link, 16, LaserEvent::GimbalMoveSent);
        event(&link, 17, LaserEvent::GimbalArrived);
        let mut lines: Vec<String> = Vec::new();
        while let Some(line) = link.outbound.take() {
            assert_eq!(line.kind, LineKind::Notice);
            lines.push(line.text.as_str().to_owned());
        }
        assert_eq!(
            lines,
            [
                "trace 12 @laser 0 0",
                "trace 13 @laser 1 300",
                "trace 14 @event stopped stop command",
                "trace 15 @event run-started",
                "trace 16 @event move-sent",
                "trace 17 @event arrived"
            ]
        );
    }
}
