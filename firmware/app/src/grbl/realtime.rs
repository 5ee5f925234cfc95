//! grbl's realtime commands: single bytes taken out of the incoming byte
//! stream wherever they occur (mid-line too), before line assembly, so they
//! act at once however full the line buffer is.
//!
//! Taken out: `?`, `!`, `~`, 0x18 and every byte grbl 1.1 defines above
//! 0x7F (0x84, 0x85, 0x90–0x9F, 0xA0, 0xA1). Other bytes above 0x7F are
//! line bytes: the line assembler rejects the line holding them, as the
//! console always did (grbl drops them silently; rejecting is stricter and
//! keeps the console's answer to binary garbage unchanged).

/// One step of a feed or spindle (laser power) override.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum OverrideStep {
    /// Back to 100 %.
    Reset,
    /// +10 percentage points.
    CoarsePlus,
    /// −10 percentage points.
    CoarseMinus,
    /// +1 percentage point.
    FinePlus,
    /// −1 percentage point.
    FineMinus,
}

impl OverrideStep {
    /// The override after this step, %, from `percent`, kept within
    /// `[min, max]` % (grbl: feed 10–200 %, spindle 10–200 %).
    pub fn apply(self, percent: u8, min: u8, max: u8) -> u8 {
        let next = match self {
            OverrideStep::Reset => 100,
            OverrideStep::CoarsePlus => i16::from(percent) + 10,
            OverrideStep::CoarseMinus => i16::from(percent) - 10,
            OverrideStep::FinePlus => i16::from(percent) + 1,
            OverrideStep::FineMinus => i16::from(percent) - 1,
        };
        next.clamp(i16::from(min), i16::from(max)) as u8
    }
}

/// A realtime command.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Realtime {
    /// `?`: send a status report.
    StatusReport,
    /// `!`: feed hold (decelerate to a stop along the path, laser dark).
    FeedHold,
    /// `~`: cycle start / resume after a hold.
    CycleStart,
    /// 0x18 (Ctrl-X): soft reset.
    SoftReset,
    /// 0x85: cancel the running jog.
    JogCancel,
    /// 0x90–0x94: feed override.
    FeedOverride(OverrideStep),
    /// 0x95–0x97: rapid override, % (100, 50 or 25).
    RapidOverride(u8),
    /// 0x99–0x9D: spindle override, i.e. laser power.
    SpindleOverride(OverrideStep),
    /// 0x9E: toggle spindle (laser) stop during a hold.
    SpindleStop,
    /// A byte grbl defines that this controller accepts and ignores
    /// (0x84 safety door, 0x98, 0x9F, 0xA0/0xA1 coolant toggles).
    Ignored(u8),
}

impl Realtime {
    /// The realtime command `byte` stands for, if it is one.
    pub const fn from_byte(byte: u8) -> Option<Realtime> {
        use OverrideStep::*;
        Some(match byte {
            b'?' => Realtime::StatusReport,
            b'!' => Realtime::FeedHold,
            b'~' => Realtime::CycleStart,
            0x18 => Realtime::SoftReset,
            0x85 => Realtime::JogCancel,
            0x90 => Realtime::FeedOverride(Reset),
            0x91 => Realtime::FeedOverride(CoarsePlus),
            0x92 => Realtime::FeedOverride(CoarseMinus),
            0x93 => Realtime::FeedOverride(FinePlus),
            0x94 => Realtime::FeedOverride(FineMinus),
            0x95 => Realtime::RapidOverride(100),
            0x96 => Realtime::RapidOverride(50),
            0x97 => Realtime::RapidOverride(25),
            0x99 => Realtime::SpindleOverride(Reset),
            0x9A => Realtime::SpindleOverride(CoarsePlus),
            0x9B => Realtime::SpindleOverride(CoarseMinus),
            0x9C => Realtime::SpindleOverride(FinePlus),
            0x9D => Realtime::SpindleOverride(FineMinus),
            0x9E => Realtime::SpindleStop,
            0x84 | 0x98 | 0x9F | 0xA0 | 0xA1 => Realtime::Ignored(byte),
            _ => return None,
        })
    }
}

/// One item of a filtered byte chunk.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Filtered {
    /// A byte for line assembly.
    Line(u8),
    /// A realtime command, to act on at once.
    Realtime(Realtime),
}

/// Splits an incoming byte chunk into line bytes and realtime commands, in
/// arrival order. Each byte is classified on its own, so chunk boundaries
/// never matter (a realtime byte is never split, and no state is carried).
pub fn split(chunk: &[u8]) -> impl Iterator<Item = Filtered> + '_ {
    chunk.iter().map(|&byte| match Realtime::from_byte(byte) {
        Some(command) => Filtered::Realtime(command),
        None => Filtered::Line(byte),
    })
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;
    use std::vec::Vec;

    fn run(chunks: &[&[u8]]) -> (Vec<u8>, Vec<Realtime>) {
        let (mut line, mut events) = (Vec::new(), Vec::new());
        for chunk in chunks {
            for item in split(chunk) {
                match item {
                    Filtered::Line(b) => line.push(b),
                    Filtered::Realtime(r) => events.push(r),
                }
            }
        }
        (line, events)
    }

    #[test]
    fn realtime_bytes_inside_a_line_are_taken_out() {
        let (line, events) = run(&[b"G1 X1?0 Y\x185!\n"]);
        assert_eq!(line, b"G1 X10 Y5\n");
        assert_eq!(
            events,
            [
                Realtime::StatusReport,
                Realtime::SoftReset,
                Realtime::FeedHold
            ]
        );
    }

    #[test]
    fn chunk_boundaries_do_not_matter() {
        let stream: &[u8] = b"G1 X1\x91 Y2~\n?G0\x9aX0\x85\n\x99!";
        let whole = run(&[stream]);
        for cut in 0..=stream.len() {
            let (a, b) = stream.split_at(cut);
            assert_eq!(run(&[a, b]), whole, "cut at {cut}");
        }
        assert_eq!(whole.0, b"G1 X1 Y2\nG0X0\n");
        assert_eq!(
            whole.1,
            [
                Realtime::FeedOverride(OverrideStep::CoarsePlus),
                Realtime::CycleStart,
                Realtime::StatusReport,
                Realtime::SpindleOverride(OverrideStep::CoarsePlus),
                Realtime::JogCancel,
                Realtime::SpindleOverride(OverrideStep::Reset),
                Realtime::FeedHold,
            ]
        );
    }

    #[test]
    fn every_override_byte_is_taken_out_and_undefined_high_bytes_stay() {
        for byte in 0x90..=0x9Fu8 {
            assert!(Realtime::from_byte(byte).is_some(), "0x{byte:02x}");
        }
        for byte in [0x80u8, 0x83, 0x86, 0x8F, 0xA2, 0xFE, 0xFF] {
            assert_eq!(Realtime::from_byte(byte), None, "0x{byte:02x}");
        }
        // Plain printable text other than ?!~ passes unchanged.
        for byte in 0x20..0x7Fu8 {
            let taken = Realtime::from_byte(byte).is_some();
            assert_eq!(taken, matches!(byte, b'?' | b'!' | b'~'), "{byte}");
        }
    }

    #[test]
    fn override_steps_stay_within_limits() {
        assert_eq!(OverrideStep::CoarsePlus.apply(195, 10, 200), 200);
        assert_eq!(OverrideStep::CoarseMinus.apply(15, 10, 200), 10);
        assert_eq!(OverrideStep::FinePlus.apply(100, 10, 200), 101);
        assert_eq!(OverrideStep::FineMinus.apply(100, 10, 200), 99);
        assert_eq!(OverrideStep::Reset.apply(150, 10, 200), 100);
    }
}
