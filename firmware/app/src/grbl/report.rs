//! grbl 1.1's replies, formatted into any [`core::fmt::Write`] (grbl's
//! `doc/markdown/interface.md`). One function per line; the caller adds
//! the line terminator (grbl sends `\r\n`). Positions print in mm with 3
//! decimals, feeds and powers as integers, as grbl does with `$13=0`.

use core::fmt::{self, Write};

use super::block::{PointMm, SpindleMode, clamped_feed_mm_min};
use super::error::{Alarm, GrblError};
use super::settings_map::GrblSetting;
use super::state::{Distance, FeedMode, MotionMode, ParserState, Units};
use crate::text::Fixed;

/// grbl's version as senders detect it.
pub const BANNER: &str = "Grbl 1.1h ['$' for help]";
/// `$` help line.
pub const HELP: &str = "[HLP:$$ $# $G $I $N $x=val $Nx=line $J=line $SLP $C $X $H ~ ! ? ctrl-x]";

/// `ok`.
pub fn write_ok(w: &mut impl Write) -> fmt::Result {
    w.write_str("ok")
}

/// `error:N`.
pub fn write_error(w: &mut impl Write, error: GrblError) -> fmt::Result {
    write!(w, "error:{}", error.code())
}

/// `ALARM:N`.
pub fn write_alarm(w: &mut impl Write, alarm: Alarm) -> fmt::Result {
    write!(w, "ALARM:{}", alarm.code())
}

/// `[MSG:text]`.
pub fn write_message(w: &mut impl Write, text: &str) -> fmt::Result {
    write!(w, "[MSG:{text}]")
}

/// Machine state in a status report.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum MachineState {
    /// Nothing queued or moving.
    Idle,
    /// Running queued motion.
    Run,
    /// Feed hold: `Hold:0` stopped (ready to resume), `Hold:1` decelerating.
    Hold {
        /// Whether the spot is still decelerating.
        decelerating: bool,
    },
    /// Jogging.
    Jog,
    /// Alarm (locked until `$X` or reset).
    Alarm,
    /// Check mode (`$C`).
    Check,
    /// Homing (`$H`, aiming at the origin).
    Home,
    /// `$SLP`.
    Sleep,
    /// grbl's safety door, here the laser controls keeping the laser off:
    /// `Door:1` interlock open or key off, `Door:0` closed and waiting for
    /// the reset (`arm`), `Door:3` the emission indicator's delay runs.
    Door(u8),
}

/// Override values, % (grbl's `Ov:feed,rapid,spindle`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Overrides {
    /// Feed override, %.
    pub feed: u8,
    /// Rapid override, %.
    pub rapid: u8,
    /// Spindle (laser power) override, %.
    pub spindle: u8,
}

impl Overrides {
    /// `programmed_mm_min` (a block's F, mm/min) with the feed override
    /// applied, never below [`MIN_FEED_MM_MIN`](super::block::MIN_FEED_MM_MIN) (grbl's planner clamps
    /// after the override too: F1 at 10 % still runs at 1 mm/min), mm/min.
    pub fn feed_mm_min(&self, programmed_mm_min: f64) -> f64 {
        clamped_feed_mm_min(programmed_mm_min * f64::from(self.feed) / 100.0)
    }
}

/// Everything a status report can show.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Status {
    /// State.
    pub state: MachineState,
    /// Machine position of the spot, mm.
    pub machine_mm: PointMm,
    /// Work coordinate offset, mm (WPos = MPos − WCO).
    pub work_offset_mm: PointMm,
    /// `$10` bit 0: report MPos (else WPos).
    pub report_machine: bool,
    /// `Bf:` planner blocks free and RX bytes free, when `$10` bit 1 is set.
    pub buffer: Option<(u16, u16)>,
    /// `Ln:` line number being executed, when known.
    pub line_number: Option<u32>,
    /// Current feed, mm/min.
    pub feed_mm_min: f64,
    /// Current laser power S.
    pub power: f64,
    /// Send `WCO:` in this report (grbl: every 10–30 reports or on change).
    pub show_work_offset: bool,
    /// `Ov:` (and `A:`) in this report (grbl: every 10–20 reports or on change).
    pub overrides: Option<(Overrides, SpindleMode, crate::grbl::state::Coolant)>,
}

fn write_point(w: &mut impl Write, p: PointMm) -> fmt::Result {
    // Z is accepted and ignored; always 0.
    write!(w, "{},{},0.000", Fixed::<3>(p.x_mm), Fixed::<3>(p.y_mm))
}

fn write_state(w: &mut impl Write, state: MachineState) -> fmt::Result {
    w.write_str(match state {
        MachineState::Idle => "Idle",
        MachineState::Run => "Run",
        MachineState::Hold {
            decelerating: false,
        } => "Hold:0",
        MachineState::Hold { decelerating: true } => "Hold:1",
        MachineState::Jog => "Jog",
        MachineState::Alarm => "Alarm",
        MachineState::Check => "Check",
        MachineState::Home => "Home",
        MachineState::Sleep => "Sleep",
        MachineState::Door(substate) => return write!(w, "Door:{substate}"),
    })
}

/// `<Idle|MPos:0.000,0.000,0.000|FS:0,0>` with the optional fields in
/// grbl's order: Bf, Ln, FS, WCO, Ov (+A).
pub fn write_status(w: &mut impl Write, s: &Status) -> fmt::Result {
    w.write_char('<')?;
    write_state(w, s.state)?;
    if s.report_machine {
        w.write_str("|MPos:")?;
        write_point(w, s.machine_mm)?;
    } else {
        w.write_str("|WPos:")?;
        write_point(
            w,
            PointMm {
                x_mm: s.machine_mm.x_mm - s.work_offset_mm.x_mm,
                y_mm: s.machine_mm.y_mm - s.work_offset_mm.y_mm,
            },
        )?;
    }
    if let Some((blocks, bytes)) = s.buffer {
        write!(w, "|Bf:{},{}", u32::from(blocks), u32::from(bytes))?;
    }
    if let Some(n) = s.line_number {
        write!(w, "|Ln:{n}")?;
    }
    write!(
        w,
        "|FS:{},{}",
        Fixed::<0>(s.feed_mm_min),
        Fixed::<0>(s.power)
    )?;
    if s.show_work_offset {
        w.write_str("|WCO:")?;
        write_point(w, s.work_offset_mm)?;
    }
    if let Some((ov, spindle, coolant)) = s.overrides {
        // As u32: the u8 writer is not linked (text::Int).
        let [feed, rapid, power] = [ov.feed, ov.rapid, ov.spindle].map(u32::from);
        write!(w, "|Ov:{feed},{rapid},{power}")?;
        let mut accessories = heapless::String::<4>::new();
        let _ = match spindle {
            SpindleMode::Constant => accessories.push('S'),
            SpindleMode::Dynamic => accessories.push('C'),
            SpindleMode::Off => Ok(()),
        };
        if coolant.flood {
            let _ = accessories.push('F');
        }
        if coolant.mist {
            let _ = accessories.push('M');
        }
        if !accessories.is_empty() {
            write!(w, "|A:{accessories}")?;
        }
    }
    w.write_char('>')
}

/// `$G`: `[GC:G0 G54 G17 G21 G90 G94 M5 M9 T0 F0 S0]`.
pub fn write_parser_state(w: &mut impl Write, s: &ParserState) -> fmt::Result {
    let motion = match s.motion {
        MotionMode::Rapid => "G0",
        MotionMode::Linear => "G1",
        MotionMode::ArcClockwise => "G2",
        MotionMode::ArcCounterClockwise => "G3",
        MotionMode::Cancel => "G80",
    };
    let units = if s.units == Units::Inches {
        "G20"
    } else {
        "G21"
    };
    let distance = if s.distance == Distance::Incremental {
        "G91"
    } else {
        "G90"
    };
    let feed = if s.feed_mode == FeedMode::InverseTime {
        "G93"
    } else {
        "G94"
    };
    let spindle = match s.spindle {
        SpindleMode::Off => "M5",
        SpindleMode::Constant => "M3",
        SpindleMode::Dynamic => "M4",
    };
    write!(
        w,
        "[GC:{motion} G54 G17 {units} {distance} {feed} {spindle}"
    )?;
    match (s.coolant.mist, s.coolant.flood) {
        (false, false) => w.write_str(" M9")?,
        (mist, flood) => {
            if mist {
                w.write_str(" M7")?;
            }
            if flood {
                w.write_str(" M8")?;
            }
        }
    }
    write!(
        w,
        " T{} F{} S{}]",
        u32::from(s.tool),
        Fixed::<0>(s.feed_mm_min),
        Fixed::<0>(s.power)
    )
}

/// Number of lines `$#` sends.
pub const PARAMETER_LINES: usize = 11;

/// Line `index` (0..[`PARAMETER_LINES`]) of `$#`: `[G54:…]`, `[G55:…]` …
/// `[G59:…]` (unsupported, 0), `[G28:…]`, `[G30:…]` (0), `[G92:…]`,
/// `[TLO:0.000]`, `[PRB:0.000,0.000,0.000:0]`. Out of range: nothing.
pub fn write_parameter_line(w: &mut impl Write, index: usize, s: &ParserState) -> fmt::Result {
    const NAMES: [&str; 8] = ["G54", "G55", "G56", "G57", "G58", "G59", "G28", "G30"];
    match index {
        0 => {
            w.write_str("[G54:")?;
            write_point(w, s.g54)?;
            w.write_char(']')
        }
        1..=7 => {
            write!(w, "[{}:", NAMES[index])?;
            write_point(w, PointMm::ZERO)?;
            w.write_char(']')
        }
        8 => {
            w.write_str("[G92:")?;
            write_point(w, s.g92)?;
            w.write_char(']')
        }
        9 => w.write_str("[TLO:0.000]"),
        10 => w.write_str("[PRB:0.000,0.000,0.000:0]"),
        _ => Ok(()),
    }
}

/// `$I` first line: `[VER:1.1h.<date>:<build info>]`.
pub fn write_version(w: &mut impl Write, build_date: &str, info: &str) -> fmt::Result {
    write!(w, "[VER:1.1h.{build_date}:{info}]")
}

/// `$I` second line: `[OPT:<codes>,<planner blocks>,<rx buffer bytes>]`
/// (codes: `V` variable laser power, `N` line numbers, …).
pub fn write_options(
    w: &mut impl Write,
    codes: &str,
    planner_blocks: u16,
    rx_bytes: u16,
) -> fmt::Result {
    write!(w, "[OPT:{codes},{planner_blocks},{rx_bytes}]")
}

/// One `$$` line: `$N=value` with grbl's decimals for N.
pub fn write_setting(w: &mut impl Write, setting: &GrblSetting, value: f64) -> fmt::Result {
    write!(w, "${}=", u32::from(setting.number))?;
    match setting.decimals {
        0 => write!(w, "{}", Fixed::<0>(value)),
        1 => write!(w, "{}", Fixed::<1>(value)),
        2 => write!(w, "{}", Fixed::<2>(value)),
        _ => write!(w, "{}", Fixed::<3>(value)),
    }
}

#[cfg(test)]
mod tests;
