//! What a frame means: the command table shared by PELCO-D and PELCO-P.
//!
//! A frame whose cmd2 (PELCO-P d2) has bit 0 clear is a standard command:
//! pan/tilt direction bits in cmd2 (right 0x02, left 0x04, up 0x08, down
//! 0x10; zoom 0x20/0x40 and focus 0x80 ignored), pan speed in data1, tilt
//! speed in data2; cmd1 holds camera bits (focus, iris, camera on/off,
//! auto scan), accepted and ignored. A frame with bit 0 set is an extended
//! command selected by cmd2 (see [`Command`]).

use crate::frame::{Frame, Protocol};

/// Pan direction of a standard command.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum PanDirection {
    /// No pan (neither bit, or both).
    Stop,
    /// Bit 0x04.
    Left,
    /// Bit 0x02.
    Right,
}

/// Tilt direction of a standard command.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum TiltDirection {
    /// No tilt (neither bit, or both).
    Stop,
    /// Bit 0x08.
    Up,
    /// Bit 0x10.
    Down,
}

/// A standard (motion) command: directions and raw speed bytes (0x00–0x3F
/// for PELCO-D, 0x00–0x40 for PELCO-P, 0xFF = turbo for pan).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Motion {
    /// Pan direction.
    pub pan: PanDirection,
    /// Tilt direction.
    pub tilt: TiltDirection,
    /// Pan speed byte (data1).
    pub pan_speed: u8,
    /// Tilt speed byte (data2).
    pub tilt_speed: u8,
}

impl Motion {
    /// Whether the frame stops both axes.
    pub fn is_stop(&self) -> bool {
        self.pan == PanDirection::Stop && self.tilt == TiltDirection::Stop
    }
}

/// What one frame asks.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Command {
    /// Pan/tilt at the given speeds until the next motion command (a frame
    /// of zeros is "stop").
    Motion(Motion),
    /// 0x03: store the current aim as preset `data2` (1–255).
    SetPreset(u8),
    /// 0x05: forget preset `data2`.
    ClearPreset(u8),
    /// 0x07: aim at preset `data2`.
    GotoPreset(u8),
    /// 0x09: switch auxiliary `data2` on.
    SetAux(u8),
    /// 0x0B: switch auxiliary `data2` off.
    ClearAux(u8),
    /// 0x0F: remote reset.
    RemoteReset,
    /// 0x4B: absolute pan, hundredths of a degree (data1 MSB, data2 LSB).
    SetPan(u16),
    /// 0x4D: absolute tilt, hundredths of a degree.
    SetTilt(u16),
    /// 0x51: query pan position (answered with [`Command::PanPosition`]).
    QueryPan,
    /// 0x53: query tilt position (answered with [`Command::TiltPosition`]).
    QueryTilt,
    /// 0x59: pan position reply, hundredths of a degree.
    PanPosition(u16),
    /// 0x5B: tilt position reply, hundredths of a degree.
    TiltPosition(u16),
    /// Any other extended command (cmd1, cmd2, data1, data2), ignored
    /// (zoom speed, pattern, menu, …). cmd2 has bit 0 set.
    Other([u8; 4]),
}

const SET_PRESET: u8 = 0x03;
const CLEAR_PRESET: u8 = 0x05;
const GOTO_PRESET: u8 = 0x07;
const SET_AUX: u8 = 0x09;
const CLEAR_AUX: u8 = 0x0B;
const REMOTE_RESET: u8 = 0x0F;
const SET_PAN: u8 = 0x4B;
const SET_TILT: u8 = 0x4D;
const QUERY_PAN: u8 = 0x51;
const QUERY_TILT: u8 = 0x53;
const PAN_POSITION: u8 = 0x59;
const TILT_POSITION: u8 = 0x5B;

impl Command {
    /// The command a frame's four bytes carry.
    pub fn from_bytes(bytes: [u8; 4]) -> Command {
        let [_, cmd2, d1, d2] = bytes;
        if cmd2 & 1 == 0 {
            let pan = match cmd2 & 0x06 {
                0x02 => PanDirection::Right,
                0x04 => PanDirection::Left,
                _ => PanDirection::Stop,
            };
            let tilt = match cmd2 & 0x18 {
                0x08 => TiltDirection::Up,
                0x10 => TiltDirection::Down,
                _ => TiltDirection::Stop,
            };
            return Command::Motion(Motion {
                pan,
                tilt,
                pan_speed: d1,
                tilt_speed: d2,
            });
        }
        let word = u16::from_be_bytes([d1, d2]);
        match cmd2 {
            SET_PRESET => Command::SetPreset(d2),
            CLEAR_PRESET => Command::ClearPreset(d2),
            GOTO_PRESET => Command::GotoPreset(d2),
            SET_AUX => Command::SetAux(d2),
            CLEAR_AUX => Command::ClearAux(d2),
            REMOTE_RESET => Command::RemoteReset,
            SET_PAN => Command::SetPan(word),
            SET_TILT => Command::SetTilt(word),
            QUERY_PAN => Command::QueryPan,
            QUERY_TILT => Command::QueryTilt,
            PAN_POSITION => Command::PanPosition(word),
            TILT_POSITION => Command::TiltPosition(word),
            _ => Command::Other(bytes),
        }
    }

    /// The four bytes that carry this command (cmd1 zero, unused data
    /// zero). [`Command::Other`] gives its bytes back as they are.
    pub fn to_bytes(&self) -> [u8; 4] {
        let ext = |code: u8, d1: u8, d2: u8| [0, code, d1, d2];
        let word = |code: u8, w: u16| {
            let [hi, lo] = w.to_be_bytes();
            [0, code, hi, lo]
        };
        match *self {
            Command::Motion(m) => {
                let pan = match m.pan {
                    PanDirection::Stop => 0,
                    PanDirection::Left => 0x04,
                    PanDirection::Right => 0x02,
                };
                let tilt = match m.tilt {
                    TiltDirection::Stop => 0,
                    TiltDirection::Up => 0x08,
                    TiltDirection::Down => 0x10,
                };
                [0, pan | tilt, m.pan_speed, m.tilt_speed]
            }
            Command::SetPreset(n) => ext(SET_PRESET, 0, n),
            Command::ClearPreset(n) => ext(CLEAR_PRESET, 0, n),
            Command::GotoPreset(n) => ext(GOTO_PRESET, 0, n),
            Command::SetAux(n) => ext(SET_AUX, 0, n),
            Command::ClearAux(n) => ext(CLEAR_AUX, 0, n),
            Command::RemoteReset => ext(REMOTE_RESET, 0, 0),
            Command::SetPan(w) => word(SET_PAN, w),
            Command::SetTilt(w) => word(SET_TILT, w),
            Command::QueryPan => ext(QUERY_PAN, 0, 0),
            Command::QueryTilt => ext(QUERY_TILT, 0, 0),
            Command::PanPosition(w) => word(PAN_POSITION, w),
            Command::TiltPosition(w) => word(TILT_POSITION, w),
            Command::Other(bytes) => bytes,
        }
    }

    /// The frame that carries this command to (or from) `address`.
    pub fn frame(&self, protocol: Protocol, address: u8) -> Frame {
        Frame {
            protocol,
            address,
            bytes: self.to_bytes(),
        }
    }

    /// The command a frame carries.
    pub fn of(frame: &Frame) -> Command {
        Command::from_bytes(frame.bytes)
    }

    /// Short name for logs and `pelco status`.
    pub fn name(&self) -> &'static str {
        match self {
            Command::Motion(m) if m.is_stop() => "stop",
            Command::Motion(_) => "move",
            Command::SetPreset(_) => "set-preset",
            Command::ClearPreset(_) => "clear-preset",
            Command::GotoPreset(_) => "goto-preset",
            Command::SetAux(_) => "set-aux",
            Command::ClearAux(_) => "clear-aux",
            Command::RemoteReset => "remote-reset",
            Command::SetPan(_) => "set-pan",
            Command::SetTilt(_) => "set-tilt",
            Command::QueryPan => "query-pan",
            Command::QueryTilt => "query-tilt",
            Command::PanPosition(_) => "pan-position",
            Command::TiltPosition(_) => "tilt-position",
            Command::Other(_) => "other",
        }
    }
}

/// Hundredths of a degree on the wire (0–35 999) to degrees in
/// (−180, 180]: values above 18 000 are negative angles (36 000 − x).
/// Values of 36 000 and above wrap.
pub fn hundredths_to_deg(hundredths: u16) -> f32 {
    let h = i32::from(hundredths) % 36_000;
    let signed = if h > 18_000 { h - 36_000 } else { h };
    signed as f32 / 100.0
}

/// Degrees to hundredths of a degree on the wire (0–35 999, negative
/// angles as 36 000 − x), rounded to the nearest; NaN gives 0.
pub fn deg_to_hundredths(deg: f32) -> u16 {
    let scaled = deg * 100.0;
    let rounded = if scaled >= 0.0 {
        scaled + 0.5
    } else {
        scaled - 0.5
    } as i32;
    // `as` saturates (NaN → 0); rem_euclid keeps it in 0..36 000.
    rounded.rem_euclid(36_000) as u16
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn angles_wrap_and_sign() {
        assert_eq!(deg_to_hundredths(12.345), 1235);
        assert_eq!(deg_to_hundredths(-10.0), 35_000);
        assert_eq!(hundredths_to_deg(35_000), -10.0);
        assert_eq!(hundredths_to_deg(18_000), 180.0);
        assert_eq!(deg_to_hundredths(f32::NAN), 0);
        assert_eq!(deg_to_hundredths(360.0), 0);
    }

    #[test]
    fn goto_preset_frame_matches_the_published_example() {
        // Go to preset 1 on camera 1: FF 01 00 07 00 01 09.
        let raw = Command::GotoPreset(1).frame(Protocol::D, 1).encode();
        assert_eq!(raw.as_slice(), &[0xFF, 0x01, 0x00, 0x07, 0x00, 0x01, 0x09]);
    }

    #[test]
    fn zoom_and_camera_bits_do_not_move() {
        // Zoom tele with focus near: a stop as far as pan/tilt go.
        let c = Command::from_bytes([0x01, 0x20, 0x00, 0x00]);
        assert!(matches!(c, Command::Motion(m) if m.is_stop()));
        let both = Command::from_bytes([0, 0x06 | 0x18, 9, 9]);
        assert!(matches!(both, Command::Motion(m) if m.is_stop()));
    }
}
