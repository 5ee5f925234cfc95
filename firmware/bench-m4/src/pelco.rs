//! The PELCO port's work per frame (issue 23): the streaming decoder takes
//! the frame's bytes and the session turns the frame into the product's
//! commands (jogs, `goto`, preset, laser, stop) or a position reply, as the
//! port task does for each frame (its channel sends not included).
//!
//! * `pelco.frame.*`: chosen frames (a move from rest, an absolute pan, a
//!   position query, a preset call);
//! * `sweep.pelco.frame`: the dearest of [`FRAMES`] seeded random frames
//!   over every frame kind of both dialects (moves from rest and while
//!   moving at random speeds, stops, presets, aux, reset, absolute pan and
//!   tilt at random angles, queries, ignored commands), the spot at a
//!   random board point, one window per frame.

use core::fmt::Write;
use core::hint::black_box;

use laser_app::domain::PointCm;
use laser_app::pelco::{Request, Session, View};
use pelco::{Command, Decoder, Frame, Motion, PanDirection, Protocol, TiltDirection};

use crate::harness::{Bench, window};
use crate::sweep::{Rng, SEED};

/// Frames tried by the sweep.
pub const FRAMES: u32 = 2000;
/// Aiming centre to board distance, cm (the default `oq_cm`).
const OQ_CM: f64 = 25.0;

/// One input: the frame, the spot, and whether a move already runs.
#[derive(Clone, Copy)]
struct Input {
    frame: Frame,
    at: PointCm,
    moving: bool,
}

/// Ticks to decode `input`'s bytes and hand the frame to the session.
fn measure(input: &Input) -> Result<u32, &'static str> {
    let mut session = Session::new();
    let view = |now_ms| View {
        now_ms,
        at: Some(input.at),
        oq_cm: OQ_CM,
    };
    if input.moving {
        let right = Command::Motion(Motion {
            pan: PanDirection::Right,
            tilt: TiltDirection::Up,
            pan_speed: 0x10,
            tilt_speed: 0x08,
        });
        session.on_frame(&right.frame(Protocol::D, 1), view(0), &mut |r| {
            black_box(r);
        });
    }
    let raw = input.frame.encode();
    let mut decoder = Decoder::new(1);
    let mut decoded = 0u32;
    let ticks = window(|| {
        for &byte in black_box(raw.as_slice()) {
            if let Some(frame) = decoder.feed(byte) {
                decoded += 1;
                session.on_frame(&frame, view(20), &mut |r: Request| {
                    black_box(r);
                });
            }
        }
    });
    if decoded == 1 {
        Ok(ticks)
    } else {
        Err("frame not decoded")
    }
}

/// The `i`th frame of the sweep: every kind in turn, random contents.
fn input(rng: &mut Rng, i: u32) -> Input {
    let protocol = if rng.below(2) == 0 {
        Protocol::D
    } else {
        Protocol::P
    };
    let byte = |rng: &mut Rng| rng.below(256) as u8;
    let speed = |rng: &mut Rng| match rng.below(4) {
        0 => 0xFF,
        _ => rng.below(0x41) as u8,
    };
    let preset = |rng: &mut Rng| 1 + rng.below(255) as u8;
    let angle = |rng: &mut Rng| rng.below(36_000) as u16;
    let command = match i % 12 {
        0 | 1 => Command::Motion(Motion {
            pan: [PanDirection::Left, PanDirection::Right, PanDirection::Stop]
                [rng.below(3) as usize],
            tilt: [TiltDirection::Up, TiltDirection::Down, TiltDirection::Stop]
                [rng.below(3) as usize],
            pan_speed: speed(rng),
            tilt_speed: speed(rng),
        }),
        2 => Command::SetPreset(preset(rng)),
        3 => Command::ClearPreset(preset(rng)),
        4 => Command::GotoPreset(preset(rng)),
        5 => Command::SetAux(1 + rng.below(3) as u8),
        6 => Command::ClearAux(1 + rng.below(3) as u8),
        7 => Command::RemoteReset,
        8 => Command::SetPan(angle(rng)),
        9 => Command::SetTilt(angle(rng)),
        10 => [Command::QueryPan, Command::QueryTilt][rng.below(2) as usize],
        // Zoom, focus, iris, camera: ignored.
        _ => Command::from_bytes([byte(rng), byte(rng) & 0xE0, byte(rng), byte(rng)]),
    };
    Input {
        frame: command.frame(protocol, protocol.wire_address(1)),
        at: PointCm::new(rng.range(-40.0, 40.0), rng.range(-30.0, 30.0)),
        moving: rng.below(2) == 0,
    }
}

/// Writes `input` as the frame's bytes, its command, the spot and state.
fn describe(out: &mut impl Write, input: &Input) {
    for b in input.frame.encode().as_slice() {
        let _ = write!(out, "{b:02X}");
    }
    let _ = write!(
        out,
        " ({} {}) at ({:.2},{:.2}) cm{}",
        input.frame.protocol.name(),
        Command::of(&input.frame).name(),
        input.at.x_cm,
        input.at.y_cm,
        if input.moving { " while moving" } else { "" }
    );
}

/// The chosen frames and the sweep.
pub fn pelco(b: &mut Bench) {
    let at = PointCm::new(-12.0, 4.5);
    let move_right = Command::Motion(Motion {
        pan: PanDirection::Right,
        tilt: TiltDirection::Up,
        pan_speed: 0x20,
        tilt_speed: 0x20,
    });
    for (id, command) in [
        ("pelco.frame.move", move_right),
        ("pelco.frame.set_pan", Command::SetPan(2550)),
        ("pelco.frame.query_pan", Command::QueryPan),
        ("pelco.frame.goto_preset", Command::GotoPreset(5)),
    ] {
        let input = Input {
            frame: command.frame(Protocol::D, 1),
            at,
            moving: false,
        };
        match measure(&input) {
            Ok(ticks) => b.report(id, ticks, 1),
            Err(e) => b.fail(id, e),
        }
    }
    sweep(b);
}

/// [`FRAMES`] seeded random frames; reports the dearest with its input.
fn sweep(b: &mut Bench) {
    let id = "sweep.pelco.frame";
    let mut rng = Rng::new(SEED ^ 0x5E1C0);
    let mut worst: Option<(u32, Input)> = None;
    for i in 0..FRAMES {
        let input = input(&mut rng, i);
        match measure(&input) {
            Ok(ticks) if worst.is_none_or(|(w, _)| ticks > w) => worst = Some((ticks, input)),
            Ok(_) => {}
            Err(e) => {
                let _ = write!(b.out, "error {id} frame {i} {e}: ");
                describe(&mut b.out, &input);
                let _ = writeln!(b.out);
                b.failures += 1;
            }
        }
    }
    let Some((ticks, input)) = worst else {
        return b.fail(id, "no frame");
    };
    b.report(id, ticks, 1);
    let _ = write!(b.out, "worst {id} {FRAMES} ");
    describe(&mut b.out, &input);
    let _ = writeln!(b.out);
    b.out.flush();
}
