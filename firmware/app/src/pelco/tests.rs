//! The session on realistic frame sequences, and `pelco status`.

extern crate std;

use std::string::ToString;
use std::vec::Vec;
use std::{panic, vec};

use ::pelco::{Command as Pelco, Frame, Motion, PanDirection, Protocol, TiltDirection};

use super::session::{CHUNK_MS, LEAD_MS};
use super::sight::{angles_deg, point};
use super::speed::rate_deg_s;
use super::*;
use crate::command::{Command, PresetCommand};
use crate::domain::PointCm;
use crate::settings::LaserMode;

const OQ_CM: f64 = 100.0;

fn view(now_ms: u64, at: Option<PointCm>) -> View {
    View {
        now_ms,
        at,
        oq_cm: OQ_CM,
    }
}

fn frame(c: Pelco) -> Frame {
    c.frame(Protocol::D, 1)
}

fn moving(pan: PanDirection, tilt: TiltDirection, pan_speed: u8, tilt_speed: u8) -> Frame {
    frame(Pelco::Motion(Motion {
        pan,
        tilt,
        pan_speed,
        tilt_speed,
    }))
}

fn on_frame(s: &mut Session, f: Frame, v: View) -> Vec<Request> {
    let mut out = Vec::new();
    s.on_frame(&f, v, &mut |r| out.push(r));
    out
}

/// `(x_mm, y_mm, feed_mm_min)` of a jog request.
fn jog(r: &Request) -> Option<[f64; 3]> {
    let Request::Command(Command::Grbl(line)) = r else {
        return None;
    };
    let rest = line.as_str().strip_prefix("$J=G53G90G21X")?;
    let (x, rest) = rest.split_once('Y')?;
    let (y, f) = rest.split_once('F')?;
    Some([x.parse().ok()?, y.parse().ok()?, f.parse().ok()?])
}

/// Runs a move from `start` for `ms`, ticking when due; the jogs.
fn run_move(f: Frame, start: PointCm, ms: u64) -> (Session, Vec<[f64; 3]>) {
    let mut s = Session::new();
    let mut jogs: Vec<[f64; 3]> = on_frame(&mut s, f, view(0, Some(start)))
        .iter()
        .filter_map(jog)
        .collect();
    while let Some(t) = s.next_tick_ms().filter(|t| *t <= ms) {
        s.on_tick(view(t, Some(start)), &mut |r| jogs.extend(jog(&r)));
    }
    (s, jogs)
}

#[test]
fn pan_right_jogs_along_the_line_of_sight_at_the_table_rate() {
    for speed in [0x01, 0x10, 0x3F, 0xFF] {
        let f = moving(PanDirection::Right, TiltDirection::Stop, speed, 0);
        let start = PointCm::new(-20.0, 10.0);
        let (_, jogs) = run_move(f, start, 1000);
        let rate = f64::from(rate_deg_s(speed));
        // Queued LEAD_MS ahead of the last tick at 1 s.
        let chunks = (1000 + LEAD_MS) / CHUNK_MS;
        assert_eq!(jogs.len() as u64, chunks, "speed {speed:#x}");
        let [x, y, _] = jogs[jogs.len() - 1];
        let [pan, tilt] = angles_deg(PointCm::new(x / 10.0, y / 10.0), OQ_CM);
        let [pan0, tilt0] = angles_deg(start, OQ_CM);
        let expected = rate * chunks as f64 * CHUNK_MS as f64 / 1000.0;
        assert!(
            (pan - pan0 - expected).abs() < 1e-3,
            "{pan} {pan0} {expected}"
        );
        assert!((tilt - tilt0).abs() < 1e-3);
        // Each jog's feed covers its chord in one chunk.
        let mut from = [start.x_cm * 10.0, start.y_cm * 10.0];
        for [x, y, feed] in &jogs {
            let chord = (x - from[0]).hypot(y - from[1]);
            let t_min = CHUNK_MS as f64 / 60_000.0;
            assert!(
                (chord / feed - t_min).abs() < 1e-3 * t_min + 1e-6,
                "{chord} {feed}"
            );
            from = [*x, *y];
        }
    }
}

#[test]
fn tilt_down_goes_negative_and_stop_cancels_the_jog() {
    let f = moving(PanDirection::Stop, TiltDirection::Down, 0, 0x20);
    let (mut s, jogs) = run_move(f, PointCm::new(0.0, 0.0), 500);
    assert!(jogs.iter().all(|[x, y, _]| x.abs() < 1e-3 && *y < 0.0));
    let stop = on_frame(
        &mut s,
        frame(Pelco::Motion(Motion {
            pan: PanDirection::Stop,
            tilt: TiltDirection::Stop,
            pan_speed: 0,
            tilt_speed: 0,
        })),
        view(510, None),
    );
    assert_eq!(stop, vec![Request::JogCancel]);
    assert!(!s.is_moving() && s.next_tick_ms().is_none());
    // A second stop asks nothing.
    let again = on_frame(
        &mut s,
        moving(PanDirection::Stop, TiltDirection::Stop, 9, 9),
        view(520, None),
    );
    assert!(again.is_empty());
}

#[test]
fn motion_stops_at_the_angle_limit() {
    let f = moving(PanDirection::Left, TiltDirection::Stop, 0xFF, 0);
    let (s, jogs) = run_move(f, PointCm::new(0.0, 0.0), 5000);
    let [x, y, _] = jogs[jogs.len() - 1];
    let [pan, _] = angles_deg(PointCm::new(x / 10.0, y / 10.0), OQ_CM);
    assert!((pan + sight::MAX_ANGLE_DEG).abs() < 1e-3, "{pan}");
    assert!(s.is_moving(), "held at the limit until a stop");
}

#[test]
fn motion_timeout_stops_a_silent_bus() {
    let mut s = Session::new();
    s.set_motion_timeout_ms(300);
    let f = moving(PanDirection::Right, TiltDirection::Up, 4, 4);
    on_frame(&mut s, f, view(0, None));
    let mut cancelled_at = None;
    while let Some(t) = s.next_tick_ms() {
        s.on_tick(view(t, None), &mut |r| {
            if r == Request::JogCancel {
                cancelled_at = Some(t);
            }
        });
        assert!(t <= 400, "still moving at {t} ms");
    }
    assert_eq!(cancelled_at, Some(300));
}

fn preset(c: PresetCommand) -> Vec<Request> {
    vec![Request::Command(Command::Preset(c))]
}

#[test]
fn presets_are_the_products_preset_commands_in_both_dialects() {
    let mut s = Session::new();
    let a = PointCm::new(12.5, -7.25);
    let set = on_frame(&mut s, frame(Pelco::SetPreset(3)), view(0, Some(a)));
    assert_eq!(set, preset(PresetCommand::Set(3)));
    let p = Pelco::GotoPreset(255).frame(Protocol::P, 0);
    assert_eq!(
        on_frame(&mut s, p, view(10, None)),
        preset(PresetCommand::Goto(255))
    );
    let clear = on_frame(&mut s, frame(Pelco::ClearPreset(1)), view(30, None));
    assert_eq!(clear, preset(PresetCommand::Clear(1)));
    // Preset 0 does not exist: nothing is asked.
    for c in [
        Pelco::SetPreset(0),
        Pelco::ClearPreset(0),
        Pelco::GotoPreset(0),
    ] {
        assert!(on_frame(&mut s, frame(c), view(50, Some(a))).is_empty());
    }
    assert!(!s.is_moving());
}

#[test]
fn recall_during_a_move_cancels_the_jog_first() {
    let mut s = Session::new();
    let a = PointCm::new(1.0, 2.0);
    on_frame(
        &mut s,
        moving(PanDirection::Right, TiltDirection::Stop, 8, 0),
        view(0, Some(a)),
    );
    let recall = on_frame(&mut s, frame(Pelco::GotoPreset(1)), view(20, Some(a)));
    assert_eq!(
        recall,
        vec![
            Request::JogCancel,
            Request::Command(Command::Preset(PresetCommand::Goto(1)))
        ]
    );
    assert!(!s.is_moving());
}

#[test]
fn absolute_pan_and_tilt_keep_the_other_axis() {
    let mut s = Session::new();
    let at = point([10.0, -5.0], OQ_CM);
    let r = on_frame(&mut s, frame(Pelco::SetPan(2550)), view(0, Some(at)));
    let [Request::Command(Command::Goto(p))] = r[..] else {
        panic!("{r:?}");
    };
    let [pan, tilt] = angles_deg(p, OQ_CM);
    assert!((pan - 25.5).abs() < 1e-9 && (tilt + 5.0).abs() < 1e-9);
    // Tilt counts downwards on the wire: 1 000 hundredths is 10° down.
    let r = on_frame(&mut s, frame(Pelco::SetTilt(1000)), view(0, Some(at)));
    let [Request::Command(Command::Goto(p))] = r[..] else {
        panic!("{r:?}");
    };
    let [pan, tilt] = angles_deg(p, OQ_CM);
    assert!((pan - 10.0).abs() < 1e-9 && (tilt + 10.0).abs() < 1e-9);
}

#[test]
fn queries_answer_the_spot_angles_in_the_asking_dialect() {
    let mut s = Session::new();
    let at = point([12.34, -3.21], OQ_CM);
    let r = on_frame(&mut s, frame(Pelco::QueryPan), view(0, Some(at)));
    assert_eq!(
        r,
        vec![Request::Reply(
            Pelco::PanPosition(1234).frame(Protocol::D, 1)
        )]
    );
    let q = Pelco::QueryTilt.frame(Protocol::P, 0);
    let r = on_frame(&mut s, q, view(0, Some(at)));
    // 3.21° below level: 321 on the wire (tilt counts downwards).
    assert_eq!(
        r,
        vec![Request::Reply(
            Pelco::TiltPosition(321).frame(Protocol::P, 0)
        )]
    );
}

#[test]
fn aux_1_is_the_laser_and_others_are_ignored() {
    let mut s = Session::new();
    let on = on_frame(&mut s, frame(Pelco::SetAux(1)), view(0, None));
    assert_eq!(on, vec![Request::Command(Command::Laser(LaserMode::Auto))]);
    let off = on_frame(&mut s, frame(Pelco::ClearAux(1)), view(0, None));
    assert_eq!(off, vec![Request::Command(Command::Laser(LaserMode::Off))]);
    assert!(on_frame(&mut s, frame(Pelco::SetAux(2)), view(0, None)).is_empty());
    assert!(on_frame(&mut s, frame(Pelco::Other([0, 0x25, 0, 1])), view(0, None)).is_empty());
}

#[test]
fn remote_reset_is_a_stop() {
    let mut s = Session::new();
    on_frame(
        &mut s,
        moving(PanDirection::Right, TiltDirection::Stop, 8, 0),
        view(0, None),
    );
    let r = on_frame(&mut s, frame(Pelco::RemoteReset), view(10, None));
    assert_eq!(r, vec![Request::Command(Command::Stop)]);
    assert!(!s.is_moving());
}

#[test]
fn status_report_lines() {
    let status = PelcoStatus::new();
    let mut lines = Vec::new();
    status.report(|a| lines.push(a.to_string()));
    assert_eq!(lines, ["pelco: no port on this board"]);
    status.set_address(7);
    status.publish(::pelco::Counters {
        frames: 3,
        bad_checksums: 1,
        other_addresses: 2,
        discarded_bytes: 5,
    });
    status.note_frame(&Pelco::GotoPreset(4).frame(Protocol::P, 6));
    lines.clear();
    status.report(|a| lines.push(a.to_string()));
    assert_eq!(
        lines,
        [
            "pelco: address 7",
            "frames 3 bad_checksums 1 other_addresses 2 discarded_bytes 5",
            "last: PELCO-P goto-preset (00 07 00 04)",
        ]
    );
}
