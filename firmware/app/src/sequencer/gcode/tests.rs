//! The grbl session in the core: `ok` once queued (back-pressure when the
//! queue is full), jog cancel, check mode, status states.

extern crate std;

use crate::command::{Command, GrblLine, RealtimeRequest};
use crate::galvo::ScanPhase;
use crate::grbl::realtime::{OverrideStep, Realtime};
use crate::sequencer::gcode::queue::PLANNER_BLOCKS;
use crate::sequencer::machine::{Action, Core, Event, GalvoReadout, Inputs, Line, Readings};
use crate::servo::task::{ServoOutcome, ServoRequest};
use embassy_time::Instant;
use std::string::String;
use std::vec::Vec;

pub(crate) const READINGS: Readings = Readings {
    galvo: GalvoReadout {
        phase: ScanPhase::Idle,
        queued: 0,
        underruns: 0,
        halves: 0,
        refill: None,
    },
    implausible_readings: 0,
};

pub(crate) fn on(core: &mut Core, ms: u64, event: Event) -> Vec<Action> {
    let inputs = Inputs {
        now: Instant::from_millis(ms),
        galvo_room: Some(8),
        galvo_bisection: false,
        stepper_attached: false,
    };
    let mut out = Vec::new();
    core.on(inputs, event, &mut out);
    out
}

pub(crate) fn line(core: &mut Core, ms: u64, text: &str) -> Vec<Action> {
    let command = Command::Grbl(GrblLine::new(text).expect("short line"));
    on(
        core,
        ms,
        Event::Command {
            command,
            readings: READINGS,
        },
    )
}

pub(crate) fn closers(actions: &[Action]) -> usize {
    actions
        .iter()
        .filter(|a| matches!(a, Action::Line(Line::Ok | Line::GrblError(_))))
        .count()
}

pub(crate) fn texts(actions: &[Action]) -> Vec<String> {
    actions
        .iter()
        .filter_map(|a| match a {
            Action::Line(Line::Data(t) | Line::Notice(t) | Line::Push(t)) => {
                Some(String::from(t.as_str()))
            }
            _ => None,
        })
        .collect()
}

pub(crate) fn move_seq(actions: &[Action]) -> Option<u32> {
    actions.iter().find_map(|a| match a {
        Action::Servo(ServoRequest::Move { seq, .. }) => Some(*seq),
        _ => None,
    })
}

pub(crate) fn arrive(core: &mut Core, ms: u64, seq: u32) -> Vec<Action> {
    on(
        core,
        ms,
        Event::Servo(ServoOutcome::Arrived {
            seq,
            yaw_tenths: 0,
            pitch_tenths: 0,
        }),
    )
}

pub(crate) fn realtime(core: &mut Core, ms: u64, command: Realtime) -> Vec<Action> {
    let request = RealtimeRequest {
        command,
        rx_free_bytes: 100,
    };
    on(core, ms, Event::Realtime(request))
}

pub(crate) fn status(core: &mut Core, ms: u64) -> String {
    let out = realtime(core, ms, Realtime::StatusReport);
    texts(&out).pop().expect("a status report")
}

/// One step of [`pump`]: confirms the pending servo move 1 ms on, or
/// ends the dwell/tick at its deadline; `None` when nothing is pending.
/// Advances `ms` and notes the next pending move.
fn pump_step(core: &mut Core, ms: &mut u64, pending: &mut Option<u32>) -> Option<Vec<Action>> {
    let out = match (pending.take(), core.dwell_deadline()) {
        (Some(seq), _) => {
            *ms += 1;
            arrive(core, *ms, seq)
        }
        (None, Some(deadline)) => {
            *ms = (*ms).max(deadline.as_micros().div_ceil(1000));
            on(core, *ms, Event::DwellEnded)
        }
        (None, None) => return None,
    };
    *pending = move_seq(&out);
    Some(out)
}

/// Runs the core's time on from `ms`: each streaming tick or settle at
/// its deadline, each servo move confirmed 1 ms after it was sent, until
/// `done` holds for what came out (or nothing is pending). Returns the
/// time reached and everything that came out.
pub(in crate::sequencer) fn pump(
    core: &mut Core,
    mut ms: u64,
    done: impl Fn(&[Action]) -> bool,
) -> (u64, Vec<Action>) {
    let mut all = Vec::new();
    let mut pending: Option<u32> = None;
    for _ in 0..10_000 {
        if done(&all) {
            break;
        }
        let Some(out) = pump_step(core, &mut ms, &mut pending) else {
            break;
        };
        all.extend(out);
    }
    (ms, all)
}

#[test]
fn ok_waits_for_room_in_the_queue() {
    let mut core = Core::new(Instant::from_millis(0));
    // The first block starts at once; PLANNER_BLOCKS more fit the queue.
    for k in 0..=PLANNER_BLOCKS {
        let out = line(&mut core, 1, &std::format!("G0 X{} Y0", k % 2 + 1));
        assert_eq!(closers(&out), 1, "line {k} answered at once");
        assert_eq!(move_seq(&out).is_some(), k == 0, "line {k}");
    }
    let full = line(&mut core, 2, "G0 X5 Y5");
    assert_eq!(closers(&full), 0, "no room: the ok waits");
    assert!(status(&mut core, 3).starts_with("<Run|"));
    // The first block ends (a reversal follows: at rest, settled): its
    // successor starts, the waiting line fits.
    let (_, out) = pump(&mut core, 3, |out| closers(out) > 0);
    assert_eq!(closers(&out), 1, "the waiting line's ok");
    assert_eq!(core.gcode.motion.queue.len(), PLANNER_BLOCKS);
}

#[test]
fn jog_cancel_brakes_on_the_path_and_the_parser_follows() {
    let mut core = Core::new(Instant::from_millis(0));
    let out = line(&mut core, 1, "$J=G91 X50 F600");
    assert_eq!(closers(&out), 1);
    assert!(move_seq(&out).is_some(), "jog streams");
    assert!(status(&mut core, 2).starts_with("<Jog|"));
    assert_eq!(
        closers(&line(&mut core, 3, "G1 X1 F100")),
        1,
        "G-code refused while jogging"
    );
    // Cruising at 10 mm/s after 0.2 s.
    let (ms, _) = pump(&mut core, 3, |out| out.len() > 40);
    let before = core.gcode.motion.position.x_mm;
    assert!(before > 1.0 && before < 3.0, "{before}");
    realtime(&mut core, ms, Realtime::JogCancel);
    pump(&mut core, ms, |_| false);
    let report = status(&mut core, ms + 500);
    assert!(report.starts_with("<Idle|MPos:"), "{report}");
    // Braked within one period at 10 mm/s: 0.2 mm.
    let stopped = core.gcode.motion.position.x_mm;
    assert!(
        stopped >= before && stopped <= before + 0.21,
        "{before} {stopped}"
    );
    // The parser continues from where the jog stopped.
    let out = line(&mut core, ms + 600, "$J=G91 X1 F600");
    assert!(move_seq(&out).is_some());
    assert!((core.gcode.parser.position.x_mm - stopped - 1.0).abs() < 1e-9);
}

#[test]
fn jog_cancel_between_joined_jogs_leaves_the_parser_where_the_gimbal_is() {
    // Two jogs that join at speed (a PELCO port's continuous move); the
    // cancel lands after the first one's last tick reached its end and
    // before the second was taken: the next jog must start where the
    // gimbal is, not at the cancelled one's end.
    let mut core = Core::new(Instant::from_millis(0));
    line(&mut core, 1, "$J=G91 X2 F600");
    line(&mut core, 2, "$J=G91 X2 F600");
    let (mut ms, mut pending) = (2, None);
    while core.gcode.motion.current.is_none_or(|c| c.index == 0) {
        assert!(pump_step(&mut core, &mut ms, &mut pending).is_some());
    }
    realtime(&mut core, ms, Realtime::JogCancel);
    let (ms, _) = pump(&mut core, ms, |_| false);
    assert!(status(&mut core, ms + 500).starts_with("<Idle|"));
    let at = core.gcode.motion.position;
    assert!(
        (at.x_mm - 2.0).abs() < 1e-9,
        "at the first jog's end: {at:?}"
    );
    assert_eq!(core.gcode.parser.position, at);
}

/// grbl's `error:N` closer in `actions`, if any.
fn grbl_error_code(actions: &[Action]) -> Option<u8> {
    actions.iter().find_map(|a| match a {
        Action::Line(Line::GrblError(e)) => Some(e.code()),
        _ => None,
    })
}

#[test]
fn jog_while_not_idle_is_refused_with_grbls_error_8() {
    // grbl 1.1 runs `$J=` only when idle or jogging: a running job, an
    // alarm and check mode answer error:8 (issue 25, defect 9), not 9.
    let mut core = Core::new(Instant::from_millis(0));
    let out = line(&mut core, 1, "G1 X20 F300");
    assert_eq!(closers(&out), 1);
    assert!(status(&mut core, 2).starts_with("<Run|"));
    assert_eq!(
        grbl_error_code(&line(&mut core, 3, "$J=G91 X1 F600")),
        Some(8)
    );
    realtime(&mut core, 4, Realtime::SoftReset);
    assert!(status(&mut core, 5).starts_with("<Alarm|"));
    assert_eq!(
        grbl_error_code(&line(&mut core, 6, "$J=G91 X1 F600")),
        Some(8)
    );
    assert_eq!(grbl_error_code(&line(&mut core, 7, "G0 X1")), Some(9));
    assert_eq!(grbl_error_code(&line(&mut core, 8, "$X")), None);
    assert_eq!(grbl_error_code(&line(&mut core, 9, "$C")), None);
    assert_eq!(
        grbl_error_code(&line(&mut core, 10, "$J=G91 X1 F600")),
        Some(8)
    );
}

#[test]
fn check_mode_parses_without_moving_and_leaving_resets_the_modes() {
    let mut core = Core::new(Instant::from_millis(0));
    let out = line(&mut core, 1, "$C");
    assert!(texts(&out).contains(&String::from("MSG:Enabled")));
    let out = line(&mut core, 2, "G1 X10 F100 M3 S500");
    assert_eq!(closers(&out), 1);
    assert_eq!(move_seq(&out), None, "check mode does not move");
    assert!(status(&mut core, 3).starts_with("<Check|"));
    let out = line(&mut core, 4, "$C");
    assert!(texts(&out).contains(&String::from("MSG:Disabled")));
    let out = line(&mut core, 5, "$G");
    assert_eq!(
        texts(&out),
        [String::from("[GC:G0 G54 G17 G21 G90 G94 M5 M9 T0 F0 S0]")]
    );
}

#[test]
fn settings_map_to_product_parameters() {
    let mut core = Core::new(Instant::from_millis(0));
    let out = line(&mut core, 1, "$110=30000");
    assert_eq!(closers(&out), 1);
    assert_eq!(core.settings.galvo.mark_speed_mm_s, 500.0);
    let out = line(&mut core, 2, "$130=1");
    assert!(out.contains(&Action::Line(Line::GrblError(
        crate::grbl::GrblError::InvalidStatement
    ))));
    let out = line(&mut core, 3, "$$");
    let settings = texts(&out);
    assert!(settings.contains(&String::from("$110=30000.000")));
    assert!(settings.contains(&String::from("$32=1")));
    assert!(settings.iter().any(|s| s.starts_with("$130=229.9")));
}

#[test]
fn buffer_state_shows_with_report_mask_2() {
    let mut core = Core::new(Instant::from_millis(0));
    assert!(!status(&mut core, 1).contains("|Bf:"));
    assert_eq!(closers(&line(&mut core, 2, "$10=3")), 1);
    assert_eq!(closers(&line(&mut core, 3, "G0 X1")), 1);
    assert_eq!(closers(&line(&mut core, 4, "G0 X2")), 1);
    let report = status(&mut core, 5);
    // One block runs, one waits: 15 of 16 free; the console had 100 bytes.
    assert!(report.contains("|Bf:15,100|"), "{report}");
}

#[test]
fn laser_off_darkens_a_lit_gcode_step_at_once() {
    let mut core = Core::new(Instant::from_millis(0));
    let out = line(&mut core, 1, "G0 X1");
    assert!(move_seq(&out).is_some(), "rapid");
    pump(&mut core, 1, |_| false);
    let out = line(&mut core, 100, "G1 X20 F600 M3 S1000");
    assert!(out.contains(&Action::GimbalLaser(true)), "lit G1 step");
    let command = Command::Laser(crate::settings::LaserMode::Off);
    let out = on(
        &mut core,
        101,
        Event::Command {
            command,
            readings: READINGS,
        },
    );
    assert!(out.contains(&Action::GimbalLaser(false)), "{out:?}");
    assert!(!core.laser_on());
}

/// The marking speed of the galvo path request in `actions`, mm/s.
fn mark_speed(actions: &[Action]) -> Option<(u32, Option<f32>)> {
    actions.iter().find_map(|a| match a {
        Action::Galvo(crate::galvo::GalvoRequest::Path {
            seq,
            mark_speed_mm_s,
            ..
        }) => Some((*seq, *mark_speed_mm_s)),
        _ => None,
    })
}

#[test]
fn the_galvo_marks_at_f_with_the_feed_override_capped_by_its_marking_speed() {
    let mut core = Core::new(Instant::from_millis(0));
    core.actuator = crate::domain::Actuator::Galvo;
    let out = line(&mut core, 1, "G1 X10 F600 M3 S1000");
    let (seq, speed) = mark_speed(&out).expect("a lit galvo stroke");
    assert_eq!(speed, Some(10.0), "600 mm/min = 10 mm/s");
    assert!(status(&mut core, 2).contains("|FS:600,1000"));
    realtime(
        &mut core,
        3,
        Realtime::FeedOverride(OverrideStep::CoarsePlus),
    );
    realtime(
        &mut core,
        4,
        Realtime::FeedOverride(OverrideStep::CoarsePlus),
    );
    let report = status(&mut core, 5);
    assert!(report.contains("|FS:720,1000"), "{report}");
    // A feed beyond the galvo's marking speed (1000 mm/s) marks at it.
    // (Sent ahead of the stroke in flight, as the piece continuing it.)
    let out = line(&mut core, 6, "G1 X20 F120000");
    assert_eq!(closers(&out), 1);
    let (_, speed) = mark_speed(&out).expect("the next stroke");
    assert_eq!(speed, Some(1000.0));
    on(
        &mut core,
        7,
        Event::Galvo(crate::galvo::GalvoEvent::Done { seq }),
    );
    let report = status(&mut core, 8);
    assert!(report.contains("|FS:60000,1000"), "{report}");
}

/// The speed (mm/s) and position (mm) the gimbal's cursor had at each
/// step of `pump` until idle.
fn follow(core: &mut Core, ms: u64) -> Vec<(f64, [f64; 2])> {
    let mut trace = Vec::new();
    let mut ms = ms;
    let mut pending: Option<u32> = None;
    for _ in 0..100_000 {
        if pump_step(core, &mut ms, &mut pending).is_none() {
            break;
        }
        let p = core.gcode.motion.position;
        trace.push((core.jobs.gimbal.speed_mm_s(), [p.x_mm, p.y_mm]));
    }
    trace
}

#[test]
fn the_gimbal_cruises_through_gentle_junctions_and_slows_at_sharp_ones() {
    let mut core = Core::new(Instant::from_millis(0));
    // 100 mm/s; a straight run cut in three, then a 90° corner.
    // The first block (the G0) ends at rest: dark until the gimbal arrived.
    for text in ["G0 X-5", "G1 X10 F6000", "G1 X20", "G1 X30", "G1 X30 Y10"] {
        assert_eq!(closers(&line(&mut core, 1, text)), 1);
    }
    let trace = follow(&mut core, 1);
    let speed_at = |x: f64, y: f64| {
        trace
            .iter()
            .filter(|(_, p)| (p[0] - x).hypot(p[1] - y) < 1e-6)
            .map(|(v, _)| *v)
            .fold(f64::NAN, f64::max)
    };
    // Through X10 and X20 at the feed.
    assert!((speed_at(10.0, 0.0) - 100.0).abs() < 1e-6, "{trace:?}");
    assert!((speed_at(20.0, 0.0) - 100.0).abs() < 1e-6, "{trace:?}");
    // The corner at X30: grbl's junction speed √(a·δ·s/(1−s)), s = sin 45°
    // (a ≈ 8 800 mm/s², δ = 0.01 mm: ≈ 15 mm/s), far below the feed.
    let corner = speed_at(30.0, 0.0);
    assert!(corner > 5.0 && corner < 25.0, "{corner} {trace:?}");
    let end = trace.last().expect("moved").1;
    assert_eq!(end, [30.0, 10.0]);
    assert!(core.gcode.motion.is_idle());
}

/// Turns the feed override down to its 10 % floor.
fn feed_override_to_10_percent(core: &mut Core, ms: u64) {
    for _ in 0..9 {
        realtime(core, ms, Realtime::FeedOverride(OverrideStep::CoarseMinus));
    }
}

#[test]
fn the_minimum_feed_holds_after_the_feed_override_on_the_galvo() {
    let mut core = Core::new(Instant::from_millis(0));
    core.actuator = crate::domain::Actuator::Galvo;
    feed_override_to_10_percent(&mut core, 1);
    // F1 at 10 % would be 0.1 mm/min: grbl runs it at its 1 mm/min floor.
    let out = line(&mut core, 2, "G1 X1 F1 M3 S1000");
    let (_, speed) = mark_speed(&out).expect("a lit galvo stroke");
    let speed = speed.expect("a marking speed");
    assert!((speed - 1.0 / 60.0).abs() < 1e-6, "{speed} mm/s");
    let report = status(&mut core, 3);
    assert!(report.contains("|FS:1,1000"), "{report}");
}

#[test]
fn the_minimum_feed_holds_after_the_feed_override_on_the_gimbal() {
    let mut core = Core::new(Instant::from_millis(0));
    feed_override_to_10_percent(&mut core, 1);
    assert_eq!(closers(&line(&mut core, 2, "G1 X0.05 F1")), 1);
    let trace = follow(&mut core, 3);
    let top = trace.iter().map(|(v, _)| *v).fold(0.0, f64::max);
    // 1 mm/min, not 0.1: the 0.05 mm take 3 s, not 30 s.
    assert!((top - 1.0 / 60.0).abs() < 1e-6, "{top} mm/s");
    let end = trace.last().expect("moved").1;
    assert!((end[0] - 0.05).abs() < 1e-9 && end[1] == 0.0, "{end:?}");
}

#[test]
fn restoring_the_settings_tells_the_galvo_loop_the_default_junction_deviation() {
    let mut core = Core::new(Instant::from_millis(0));
    let junctions = |out: &[Action]| -> Vec<f64> {
        out.iter()
            .filter_map(|a| match a {
                Action::ConfigureGalvo(c) => Some(c.junction_deviation_mm),
                _ => None,
            })
            .collect()
    };
    assert_eq!(junctions(&line(&mut core, 1, "$11=2")), [2.0]);
    // `$RST=$` puts `$11` back to its default: the galvo loop marks with it
    // from now on, not with the 2 mm it was last told.
    let out = line(&mut core, 2, "$RST=$");
    assert_eq!(out.last(), Some(&Action::Line(Line::Ok)));
    assert_eq!(junctions(&out), [0.01]);
    assert_eq!(core.settings.gcode_junction_mm, 0.01);
}
