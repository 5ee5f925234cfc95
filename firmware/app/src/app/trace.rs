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
//! with the trace off this costs one relaxed load per laser change.
//! The galvo's per-sample laser is not traced (it is not a switch).

use crate::command::CommandLink;
use crate::sequencer::{LaserEvent, LaserPower, LaserSwitch};

/// A laser output that reports to the console while the trace is on.
pub struct TracedLaser<L> {
    inner: L,
    link: &'static CommandLink,
    /// The power last set (changes only are traced).
    power: LaserPower,
    /// The board's clock, µs since boot.
    clock_us: fn() -> u64,
}

impl<L: LaserSwitch> TracedLaser<L> {
    /// Wraps the board's laser output `inner`; `clock_us` stamps the
    /// lines (µs since boot: `embassy_time::Instant` on the boards).
    pub fn new(inner: L, link: &'static CommandLink, clock_us: fn() -> u64) -> Self {
        Self {
            inner,
            link,
            power: LaserPower::OFF,
            clock_us,
        }
    }
}

impl<L: LaserSwitch> LaserSwitch for TracedLaser<L> {
    fn set(&mut self, power: LaserPower) {
        self.inner.set(power);
        if power != self.power && self.link.tracing() {
            self.link.notify(format_args!(
                "trace {} @laser {} {}",
                (self.clock_us)(),
                u8::from(power.is_on()),
                power.per_mille()
            ));
        }
        self.power = power;
    }

    fn note(&mut self, event: LaserEvent<'_>) {
        self.inner.note(event);
        if !self.link.tracing() {
            return;
        }
        let t = (self.clock_us)();
        match event {
            LaserEvent::Stopped { why } => self
                .link
                .notify(format_args!("trace {t} @event stopped {why}")),
            LaserEvent::RunStarted => self
                .link
                .notify(format_args!("trace {t} @event run-started")),
            LaserEvent::GimbalMoveSent => {
                self.link.notify(format_args!("trace {t} @event move-sent"))
            }
            LaserEvent::GimbalArrived => self.link.notify(format_args!("trace {t} @event arrived")),
        }
    }
}

#[cfg(test)]
mod tests {
    extern crate std;
    use std::borrow::ToOwned;
    use std::boxed::Box;
    use std::string::String;
    use std::vec::Vec;

    use super::*;
    use crate::outbound::LineKind;

    #[derive(Default)]
    struct Pin(Vec<u16>);
    impl LaserSwitch for Pin {
        fn set(&mut self, power: LaserPower) {
            self.0.push(power.per_mille());
        }
    }

    fn notices(link: &CommandLink) -> Vec<String> {
        let mut lines = Vec::new();
        while let Some(line) = link.outbound.take() {
            assert_eq!(line.kind, LineKind::Notice);
            lines.push(line.text.as_str().to_owned());
        }
        lines
    }

    #[test]
    fn changes_and_events_are_traced_only_while_the_trace_is_on() {
        let link: &'static CommandLink = Box::leak(Box::new(CommandLink::new()));
        let mut laser = TracedLaser::new(Pin::default(), link, || 1234);
        laser.set(LaserPower::FULL);
        laser.note(LaserEvent::RunStarted);
        assert!(notices(link).is_empty(), "off by default");
        link.set_tracing(true);
        laser.set(LaserPower::OFF);
        laser.set(LaserPower::OFF);
        laser.set(LaserPower::from_fraction(0.3));
        laser.note(LaserEvent::Stopped {
            why: "stop command",
        });
        laser.note(LaserEvent::GimbalArrived);
        let lines = notices(link);
        let shapes: Vec<String> = lines
            .iter()
            .map(|l| {
                let mut words = l.split(' ');
                assert_eq!(words.next(), Some("trace"));
                assert!(
                    words.next().is_some_and(|t| t.parse::<u64>().is_ok()),
                    "{l}"
                );
                words.collect::<Vec<_>>().join(" ")
            })
            .collect();
        assert_eq!(
            shapes,
            [
                "@laser 0 0",
                "@laser 1 300",
                "@event stopped stop command",
                "@event arrived"
            ]
        );
        // The output itself saw every set, repeated ones included.
        assert_eq!(laser.inner.0, [1000, 0, 0, 300]);
    }
}
