//! The PELCO session: what a frame for this device asks, as the product's
//! own commands (the ones the console sends), so every actuator obeys it
//! the same way and the sequencer has no PELCO branch.
//!
//! | frame                         | becomes                                   |
//! |-------------------------------|-------------------------------------------|
//! | pan/tilt at speed             | `$J=G53G90G21X…Y…F…` jogs of [`CHUNK_MS`] each, kept [`LEAD_MS`] ahead, at the [`speed`](super::speed) table's rate along the line of sight |
//! | stop (both axes 0 / no bits)  | jog cancel (grbl 0x85)                    |
//! | zoom / focus / iris / camera  | nothing (a frame without pan/tilt bits is a stop) |
//! | set preset n (1–255)          | `preset set n` (the spot's board point, saved at once) |
//! | clear preset n                | `preset clear n`                          |
//! | go to preset n                | jog cancel, then `preset goto n`          |
//! | set / clear aux 1             | `laser on` / `laser off`                  |
//! | remote reset                  | `stop` (motion stopped, laser off)        |
//! | absolute pan / tilt (0x4B/4D) | `goto` of the point at that angle, the other axis kept |
//! | query pan / tilt (0x51/0x53)  | a 0x59 / 0x5B reply of the spot's angle   |
//!
//! Presets live in the settings store, not here (see
//! `crate::sequencer::presets`): the session keeps no table of them.
//!
//! Angles are those of the line of sight ([`super::sight`]); the spot's
//! position is the last aimed board point the sequencer published. On the
//! wire, tilt counts downwards (PTZ heads' convention: 0 level, 0–9 000
//! below, 36 000 − x above), pan to the right (36 000 − x to the left).

use core::fmt::Write as _;

use ::pelco::{Command as Pelco, Frame, Motion, PanDirection, TiltDirection};

use super::sight::{MAX_ANGLE_DEG, angles_deg, point};
use super::speed::rate_deg_s;
use crate::command::{Command, GrblLine, PresetCommand};
use crate::domain::PointCm;
use crate::settings::{LaserMode, is_preset};
use crate::text::{Fixed, ReplyText};

/// Length of one jog of a continuous move, ms.
pub const CHUNK_MS: u64 = 50;
/// How far ahead of now the jogs are queued, ms (a new speed or a stop
/// takes effect within this, plus the actuator's braking).
pub const LEAD_MS: u64 = 100;

/// What the session asks of the port task.
#[derive(Debug, Clone, PartialEq)]
pub enum Request {
    /// Send this command through the command channel (quietly).
    Command(Command),
    /// grbl's jog cancel (realtime 0x85): the running jog stops.
    JogCancel,
    /// Write this frame to the bus.
    Reply(Frame),
}

/// What the session needs to know of the world for one step.
#[derive(Debug, Clone, Copy)]
pub struct View {
    /// Now, ms.
    pub now_ms: u64,
    /// The spot's board point (last aimed), if any yet.
    pub at: Option<PointCm>,
    /// Aiming centre to board distance OQ, cm.
    pub oq_cm: f64,
}

/// A continuous move.
#[derive(Debug, Clone, Copy)]
struct Move {
    /// Line-of-sight rate (pan, tilt), deg/s.
    rate_deg_s: [f64; 2],
    /// Angles the queued jogs end at, deg.
    planned: [f64; 2],
    /// When the queued jogs end, ms.
    planned_until_ms: u64,
    /// When the last motion frame arrived, ms.
    last_frame_ms: u64,
}

/// The session state.
pub struct Session {
    moving: Option<Move>,
    /// Motion timeout, ms (0: off).
    timeout_ms: u64,
}

impl Default for Session {
    fn default() -> Self {
        Self::new()
    }
}

impl Session {
    /// At rest, no motion timeout.
    pub const fn new() -> Self {
        Self {
            moving: None,
            timeout_ms: 0,
        }
    }

    /// Motion stops after `timeout_ms` without a frame (0: never).
    pub fn set_motion_timeout_ms(&mut self, timeout_ms: u64) {
        self.timeout_ms = timeout_ms;
    }

    /// Whether a continuous move runs.
    pub fn is_moving(&self) -> bool {
        self.moving.is_some()
    }

    /// When [`Session::on_tick`] is next due, ms: when only
    /// `LEAD_MS − CHUNK_MS` of jogs remain queued.
    pub fn next_tick_ms(&self) -> Option<u64> {
        self.moving
            .map(|m| (m.planned_until_ms + CHUNK_MS).saturating_sub(LEAD_MS))
    }

    /// Acts on one frame for this device.
    pub fn on_frame(&mut self, frame: &Frame, view: View, out: &mut dyn FnMut(Request)) {
        let here = view.at.map_or([0.0; 2], |p| angles_deg(p, view.oq_cm));
        let reply = |c: Pelco| Request::Reply(c.frame(frame.protocol, frame.address));
        match Pelco::of(frame) {
            Pelco::Motion(m) => self.motion(m, here, view, out),
            // Preset 0 does not exist: ignored, as an unknown command.
            Pelco::SetPreset(n) if is_preset(n) => {
                out(Request::Command(Command::Preset(PresetCommand::Set(n))))
            }
            Pelco::ClearPreset(n) if is_preset(n) => {
                out(Request::Command(Command::Preset(PresetCommand::Clear(n))))
            }
            Pelco::GotoPreset(n) if is_preset(n) => {
                self.stop(out);
                out(Request::Command(Command::Preset(PresetCommand::Goto(n))));
            }
            Pelco::SetAux(1) => out(Request::Command(Command::Laser(LaserMode::Auto))),
            Pelco::ClearAux(1) => out(Request::Command(Command::Laser(LaserMode::Off))),
            Pelco::RemoteReset => {
                self.moving = None;
                out(Request::Command(Command::Stop));
            }
            Pelco::SetPan(h) => {
                self.aim([::pelco::hundredths_to_deg(h).into(), here[1]], view, out)
            }
            Pelco::SetTilt(h) => {
                let up = -f64::from(::pelco::hundredths_to_deg(h));
                self.aim([here[0], up], view, out)
            }
            Pelco::QueryPan => out(reply(Pelco::PanPosition(hundredths(here[0])))),
            Pelco::QueryTilt => out(reply(Pelco::TiltPosition(hundredths(-here[1])))),
            Pelco::SetPreset(_)
            | Pelco::ClearPreset(_)
            | Pelco::GotoPreset(_)
            | Pelco::SetAux(_)
            | Pelco::ClearAux(_)
            | Pelco::PanPosition(_)
            | Pelco::TiltPosition(_)
            | Pelco::Other(_) => {}
        }
    }

    /// Queues the jogs of a continuous move up to [`LEAD_MS`] ahead, and
    /// stops one that outlived the motion timeout.
    pub fn on_tick(&mut self, view: View, out: &mut dyn FnMut(Request)) {
        let Some(mut m) = self.moving else {
            return;
        };
        if self.timeout_ms > 0 && view.now_ms.saturating_sub(m.last_frame_ms) >= self.timeout_ms {
            return self.stop(out);
        }
        m.planned_until_ms = m.planned_until_ms.max(view.now_ms);
        let step_s = CHUNK_MS as f64 / 1000.0;
        while m.planned_until_ms < view.now_ms + LEAD_MS {
            let next = [0, 1].map(|i| {
                (m.planned[i] + m.rate_deg_s[i] * step_s).clamp(-MAX_ANGLE_DEG, MAX_ANGLE_DEG)
            });
            let from = point(m.planned, view.oq_cm);
            let to = point(next, view.oq_cm);
            let chord_mm = crate::domain::units::mm_from_cm(kinematics_core::numeric::hypot(
                to.x_cm - from.x_cm,
                to.y_cm - from.y_cm,
            ));
            if chord_mm < 1e-3 {
                // At the limit: nothing to queue, held until a stop.
                m.planned_until_ms = view.now_ms + LEAD_MS;
                break;
            }
            if let Some(line) = jog_line(to, chord_mm * 60_000.0 / CHUNK_MS as f64) {
                out(Request::Command(Command::Grbl(line)));
            }
            m.planned = next;
            m.planned_until_ms += CHUNK_MS;
        }
        self.moving = Some(m);
    }

    fn motion(&mut self, m: Motion, here: [f64; 2], view: View, out: &mut dyn FnMut(Request)) {
        let pan = match m.pan {
            PanDirection::Stop => 0.0,
            PanDirection::Left => -rate_deg_s(m.pan_speed),
            PanDirection::Right => rate_deg_s(m.pan_speed),
        };
        let tilt = match m.tilt {
            TiltDirection::Stop => 0.0,
            TiltDirection::Down => -rate_deg_s(m.tilt_speed),
            TiltDirection::Up => rate_deg_s(m.tilt_speed),
        };
        if pan == 0.0 && tilt == 0.0 {
            return self.stop(out);
        }
        let mut moving = self.moving.unwrap_or(Move {
            rate_deg_s: [0.0; 2],
            planned: here,
            planned_until_ms: view.now_ms,
            last_frame_ms: view.now_ms,
        });
        moving.rate_deg_s = [f64::from(pan), f64::from(tilt)];
        moving.last_frame_ms = view.now_ms;
        self.moving = Some(moving);
        self.on_tick(view, out);
    }

    /// Stops a continuous move (nothing when none runs).
    fn stop(&mut self, out: &mut dyn FnMut(Request)) {
        if self.moving.take().is_some() {
            out(Request::JogCancel);
        }
    }

    /// Aims at the line of sight `angles` (deg).
    fn aim(&mut self, angles: [f64; 2], view: View, out: &mut dyn FnMut(Request)) {
        self.stop(out);
        out(Request::Command(Command::Goto(point(angles, view.oq_cm))));
    }
}

/// An angle on the wire, hundredths of a degree.
fn hundredths(deg: f64) -> u16 {
    ::pelco::deg_to_hundredths(deg as f32)
}

/// The jog to board point `to` at `feed_mm_min`: absolute, machine
/// coordinates, mm, to the µm. Three fixed decimals by integer arithmetic
/// (not the shortest form, whose exact digits cost ~60 000 M4 instructions
/// a number: a move frame's two jogs took 2.9 ms on the M4, see
/// `docs/pelco.md`).
fn jog_line(to: PointCm, feed_mm_min: f64) -> Option<GrblLine> {
    let mut text = ReplyText::new();
    write!(
        text,
        "$J=G53G90G21X{}Y{}F{}",
        Fixed::<3>(crate::domain::units::mm_from_cm(to.x_cm)),
        Fixed::<3>(crate::domain::units::mm_from_cm(to.y_cm)),
        Fixed::<3>(feed_mm_min)
    )
    .ok()?;
    GrblLine::new(&text)
}
