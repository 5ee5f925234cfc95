//! Presets in the core: `preset set|clear|goto <n>` (the PELCO port sends
//! the same commands), board points kept in the settings store.
//!
//! * Setting or clearing writes the store at once ([`Action::SavePreset`],
//!   answered by [`Event::Saved`](super::io::Event::Saved)): no `save`, as
//!   on a PTZ head, and a power cut leaves the old or the new preset. A
//!   write may have to erase a flash sector (when one fills: about once
//!   per 6 000 preset writes), which stalls the CPU for 1–2 s on the
//!   target; so, as `save` is, a preset write is refused while a pattern
//!   runs or the spot travels to a goto target. Idle, after G-code or jog
//!   motion, or at a goto's point (dwelling or holding), the spot is still
//!   and the write goes ahead.
//! * A preset is the spot's board point: the last point aimed (`status`'s
//!   target), cm, whichever actuator aimed it.
//! * Calling reads the preset from the store ([`Action::LoadPreset`],
//!   answered by [`Event::PresetLoaded`](super::io::Event::PresetLoaded))
//!   and is a `goto` of its point, checked for the actuator that aims
//!   now: a preset set on the gimbal is called on the stepper.

use crate::command::PresetCommand;
use crate::domain::{PointCm, Target};
use crate::sequencer::machine::{Action, ActionSink, Core, Pending};
use crate::sequencer::run::RunKind;
use crate::settings::{is_preset, savable};

/// Why a preset write is refused while something runs.
const NOT_STILL: &str =
    "stop the running pattern, or wait until the goto arrives, before preset set/clear";

impl Core {
    /// `preset set|clear|goto <n>`.
    pub(super) fn preset(&mut self, command: PresetCommand, out: &mut dyn ActionSink) {
        let (PresetCommand::Set(n) | PresetCommand::Clear(n) | PresetCommand::Goto(n)) = command;
        if !is_preset(n) {
            return self.error(out, "presets are numbered 1-255");
        }
        let point = match command {
            PresetCommand::Goto(_) => {
                self.pending = Some(Pending::Preset(n));
                return out.act(Action::LoadPreset(n));
            }
            _ if !self.still() => return self.error(out, NOT_STILL),
            PresetCommand::Clear(_) => None,
            PresetCommand::Set(_) => match self.last_aim {
                None => return self.error(out, "nothing aimed yet: the preset has no point"),
                Some((target, _)) if !savable(target.point) => {
                    return self.error(out, "the spot is beyond the board limit (200 cm)");
                }
                Some((target, _)) => Some(target.point),
            },
        };
        self.pending = Some(Pending::Save);
        out.act(Action::SavePreset { n, point });
    }

    /// The store's answer to a [`PresetCommand::Goto`]: aim there, or
    /// refuse when preset `n` is not saved.
    pub(super) fn preset_loaded(
        &mut self,
        n: u8,
        point: Option<PointCm>,
        out: &mut dyn ActionSink,
    ) {
        if !matches!(self.pending, Some(Pending::Preset(m)) if m == n) {
            return;
        }
        self.pending = None;
        match point {
            Some(point) => self.goto(Target { point, grid: None }, out),
            None => self.error(out, format_args!("no preset {n}")),
        }
    }

    /// Whether the spot is still: nothing runs, or a goto has arrived
    /// (dwelling at its point, then holding it).
    fn still(&self) -> bool {
        self.run
            .is_none_or(|run| matches!(run.kind, RunKind::Goto(_)) && !run.phase.is_travel())
    }
}

#[cfg(test)]
mod tests {
    extern crate std;
    use std::vec;

    use super::*;
    use crate::command::Command;
    use crate::sequencer::gcode::tests::{READINGS, on};
    use crate::sequencer::machine::{Event, Line};
    use crate::servo::task::{ServoOutcome, ServoRequest};
    use crate::status::Phase;
    use crate::text::reply_text;
    use embassy_time::Instant;

    fn command(core: &mut Core, ms: u64, command: Command) -> std::vec::Vec<Action> {
        let readings = READINGS;
        on(core, ms, Event::Command { command, readings })
    }

    fn preset(core: &mut Core, ms: u64, c: PresetCommand) -> std::vec::Vec<Action> {
        command(core, ms, Command::Preset(c))
    }

    fn error(text: &str) -> Action {
        Action::Line(Line::Error(reply_text(format_args!("{text}"))))
    }

    /// A goto of `p` that has arrived and holds.
    fn holding(core: &mut Core, p: PointCm) {
        let started = command(core, 10, Command::Goto(p));
        let Some(seq) = started.iter().find_map(|a| match a {
            Action::Servo(ServoRequest::Move { seq, .. }) => Some(*seq),
            _ => None,
        }) else {
            panic!("no servo move: {started:?}");
        };
        let arrived = ServoOutcome::Arrived {
            seq,
            yaw_tenths: 0,
            pitch_tenths: 0,
        };
        on(core, 500, Event::Servo(arrived));
        let end = core.dwell_deadline().expect("a dwell").as_millis();
        on(core, end, Event::DwellEnded);
        assert_eq!(core.status().phase, Some(Phase::Holding));
    }

    /// A goto that has arrived and still dwells (its `dwell_ms`, 1 s or so
    /// after arriving, as a PTZ client sets a preset) is still: the write
    /// goes ahead. (Refused before: the PELCO client's presets were lost.)
    #[test]
    fn set_is_taken_while_an_arrived_goto_dwells() {
        let mut core = Core::new(Instant::from_millis(0));
        let a = PointCm::new(-4.0, 1.5);
        let started = command(&mut core, 10, Command::Goto(a));
        let seq = started
            .iter()
            .find_map(|a| match a {
                Action::Servo(ServoRequest::Move { seq, .. }) => Some(*seq),
                _ => None,
            })
            .expect("a servo move");
        let arrived = ServoOutcome::Arrived {
            seq,
            yaw_tenths: 0,
            pitch_tenths: 0,
        };
        on(&mut core, 500, Event::Servo(arrived));
        assert_eq!(core.status().phase, Some(Phase::Dwelling));
        assert_eq!(
            preset(&mut core, 600, PresetCommand::Set(9)),
            vec![Action::SavePreset {
                n: 9,
                point: Some(a)
            }]
        );
    }

    #[test]
    fn set_writes_the_held_spot_at_once_and_is_refused_while_it_travels() {
        let mut core = Core::new(Instant::from_millis(0));
        let nothing = preset(&mut core, 1, PresetCommand::Set(1));
        assert_eq!(
            nothing,
            vec![error("nothing aimed yet: the preset has no point")]
        );
        let a = PointCm::new(3.5, -2.25);
        command(&mut core, 5, Command::Goto(a));
        assert_eq!(
            preset(&mut core, 6, PresetCommand::Set(1)),
            vec![error(NOT_STILL)],
            "travelling"
        );
        assert_eq!(
            preset(&mut core, 7, PresetCommand::Clear(1)),
            vec![error(NOT_STILL)]
        );
        holding(&mut core, a);
        let set = preset(&mut core, 2_000, PresetCommand::Set(7));
        assert_eq!(
            set,
            vec![Action::SavePreset {
                n: 7,
                point: Some(a)
            }]
        );
        assert_eq!(
            on(&mut core, 2_001, Event::Saved(Err("flash write failed"))),
            vec![error("flash write failed")]
        );
        let clear = preset(&mut core, 2_002, PresetCommand::Clear(7));
        assert_eq!(clear, vec![Action::SavePreset { n: 7, point: None }]);
        assert_eq!(
            on(&mut core, 2_003, Event::Saved(Ok(()))),
            vec![Action::Line(Line::Ok)]
        );
        assert_eq!(core.status().phase, Some(Phase::Holding), "still held");
        assert_eq!(
            preset(&mut core, 2_004, PresetCommand::Set(0)),
            vec![error("presets are numbered 1-255")]
        );
        // A pattern draws: refused.
        let pattern = Command::Pattern {
            pattern: crate::domain::Pattern::Grid(crate::domain::GridPattern::Corner),
            once: false,
        };
        let mut actions = command(&mut core, 3_000, pattern);
        while actions.last() == Some(&Action::Yield) {
            actions = on(&mut core, 3_000, Event::CheckStep);
        }
        assert!(core.run.is_some());
        assert_eq!(
            preset(&mut core, 3_001, PresetCommand::Set(2)),
            vec![error(NOT_STILL)]
        );
    }

    #[test]
    fn goto_reads_the_store_then_aims_there_or_says_there_is_none() {
        let mut core = Core::new(Instant::from_millis(0));
        assert_eq!(
            preset(&mut core, 1, PresetCommand::Goto(9)),
            vec![Action::LoadPreset(9)]
        );
        // Another preset's answer is not this call's.
        let other = Event::PresetLoaded {
            n: 8,
            point: Some(PointCm::new(0.0, 0.0)),
        };
        assert!(on(&mut core, 2, other).is_empty());
        let none = Event::PresetLoaded { n: 9, point: None };
        assert_eq!(on(&mut core, 3, none), vec![error("no preset 9")]);
        assert!(core.run.is_none());

        preset(&mut core, 4, PresetCommand::Goto(9));
        let p = PointCm::new(-4.0, 1.5);
        let aimed = on(
            &mut core,
            5,
            Event::PresetLoaded {
                n: 9,
                point: Some(p),
            },
        );
        assert_eq!(aimed.last(), Some(&Action::Line(Line::Ok)));
        assert!(
            aimed
                .iter()
                .any(|a| matches!(a, Action::Servo(ServoRequest::Move { .. })))
        );
        assert!(matches!(core.run.map(|r| r.kind), Some(RunKind::Goto(t)) if t.point == p));
        // A late answer is ignored (nothing pending).
        assert!(on(&mut core, 6, Event::PresetLoaded { n: 9, point: None }).is_empty());
    }
}
