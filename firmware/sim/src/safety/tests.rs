use super::*;
use crate::executor::{TaskKind, TaskSteps};
use crate::physics::PhysicalGalvo;
use crate::recorder::SequencerEvent;
use crate::recorder::{EventRecord, ServoSample};
use crate::usb_host::Transcript;

fn transcript(lines: &[(u64, &str)]) -> Transcript {
    Transcript {
        lines: lines.iter().map(|(t, l)| (*t, (*l).to_owned())).collect(),
        ..Transcript::default()
    }
}

fn inputs<'a>(
    transcript: &'a Transcript,
    events: &'a [EventRecord],
    gimbal_laser: &'a [(u64, bool)],
    galvo: Vec<GalvoStretch>,
) -> SafetyInputs<'a> {
    SafetyInputs {
        gimbal_laser,
        galvo,
        underruns_ns: &[],
        events,
        servos: &[],
        spot: &[],
        transcript,
        task_steps: &[],
        galvo_physics: PhysicalGalvo::default(),
        end_us: 1_000_000,
        controls: None,
    }
}

fn event(t_us: u64, event: SequencerEvent) -> EventRecord {
    EventRecord {
        t_us,
        event,
        laser_switches_before: 0,
    }
}

fn stopped(t_us: u64, why: &str) -> EventRecord {
    event(t_us, SequencerEvent::Stopped { why: why.into() })
}

/// 100 samples at 10 µs from `start_us`, computed at `computed_us`.
fn stretch(start_us: u64, code: u16, laser: bool, computed_us: u64) -> GalvoStretch {
    GalvoStretch {
        start_ns: start_us * 1000,
        period_ns: 10_000,
        count: 100,
        x_code: code,
        y_code: 2048,
        laser,
        computed_ns: computed_us * 1000,
    }
}

fn kinds(v: &[Violation]) -> Vec<ViolationKind> {
    v.iter().map(|v| v.kind).collect()
}

#[test]
fn one_closing_reply_per_line_and_whole_notices() {
    let good = transcript(&[
        (0, "> status"),
        (0, "uptime: 1.000 s"),
        (
            5,
            "[error: servo 1 fault (NoResponse); pattern stopped, laser off]",
        ),
        (0, "ok"),
        (9, "[info: servo 1 answering again]"),
        (10, "> set dwell_ms -4"),
        (10, "error: dwell_ms out of range [0, 60000]"),
    ]);
    assert_eq!(one_reply_per_line(&good), []);
    // A host typing ahead gets the replies in order.
    let ahead = transcript(&[
        (0, "> get dwell_ms"),
        (0, "> status"),
        (1, "dwell_ms = 1000"),
        (1, "ok"),
        (1, "uptime: 1.000 s"),
        (1, "ok"),
    ]);
    assert_eq!(one_reply_per_line(&ahead), []);
    // grbl realtime bytes owe no reply; their answers come between lines.
    let realtime = transcript(&[
        (0, "> G1 X20 F600 M3 S500"),
        (0, "ok"),
        (1, ">> 0x3f"),
        (1, "<Run|MPos:1.000,0.000,0.000|FS:600,500>"),
        (2, ">> 0x18"),
        (2, "ALARM:3"),
        (2, "Grbl 1.1h ['$' for help]"),
        (3, "> $X"),
        (3, "ok"),
    ]);
    assert_eq!(one_reply_per_line(&realtime), []);
    let cases: &[(&[(u64, &str)], &str)] = &[
        (
            &[(0, "> params"), (1, "oq_cm = 25")],
            "got no closing reply",
        ),
        (
            &[(0, "> stop"), (0, "ok"), (0, "ok")],
            "second closing reply",
        ),
        (
            &[(0, "> stop"), (0, "ok"), (0, "oq_cm = 25")],
            "after the closing reply",
        ),
        (&[(0, "ok")], "before any command line"),
        (&[(0, ">> 0x3f"), (0, "ok")], "before any command line"),
        // A reply glued onto a cut line: its closer is not a line.
        (
            &[
                (0, "> params"),
                (1, "oq_cm = 2ok"),
                (2, "> stop"),
                (2, "ok"),
            ],
            "got no closing reply",
        ),
        (
            &[(0, "> params"), (1, "[error: servo 1 fauok"), (2, "ok")],
            "cut or glued",
        ),
    ];
    for (lines, want) in cases {
        let found = one_reply_per_line(&transcript(lines));
        assert!(
            found.iter().any(|v| v.detail.contains(want)),
            "{lines:?}: {found:?}"
        );
        assert!(found.iter().all(|v| v.kind == ViolationKind::Replies));
    }
}

#[test]
fn galvo_samples_computed_before_the_next_start_are_dark_from_1_ms_after_a_stop() {
    let t = transcript(&[]);
    let events = [
        stopped(1_000, "stop command"),
        event(5_000, SequencerEvent::RunStarted),
    ];
    // Lit from 1.5 to 2.49 ms (computed before the stop): the samples
    // from 2 ms on are too late.
    let late = vec![
        stretch(1_500, 100, true, 900),
        stretch(2_500, 100, false, 1_900),
    ];
    let found = dark_after_stops(&inputs(&t, &events, &[], late));
    assert_eq!(kinds(&found), [ViolationKind::LitAfterStop]);
    assert_eq!(found[0].t_us, 2_000);
    assert!(found[0].detail.contains("50 lit samples"), "{found:?}");
    // Dark in time (the last lit sample at 1.99 ms), then lit by the new
    // run (computed after its start).
    let fine = vec![
        stretch(1_000, 100, true, 900),
        stretch(6_000, 100, true, 5_000),
    ];
    assert_eq!(dark_after_stops(&inputs(&t, &events, &[], fine)), []);
    // Old content output after the new start is still the old run's.
    let stale = vec![stretch(6_000, 100, true, 4_000)];
    assert_eq!(
        kinds(&dark_after_stops(&inputs(&t, &events, &[], stale))),
        [ViolationKind::LitAfterStop]
    );
    // A completed pattern's last samples may still be lit.
    let complete = [stopped(1_000, "pattern complete")];
    let tail = vec![
        stretch(1_000, 100, true, 900),
        stretch(2_000, 100, true, 1_000),
    ];
    assert_eq!(dark_after_stops(&inputs(&t, &complete, &[], tail)), []);
}

#[test]
fn the_gimbal_laser_is_off_from_1_ms_after_a_stop_until_the_next_start() {
    let t = transcript(&[]);
    let events = [
        stopped(1_000, "servo fault"),
        event(9_000, SequencerEvent::RunStarted),
    ];
    let switched_late = [(0, true), (2_500, false)];
    let found = dark_after_stops(&inputs(&t, &events, &switched_late, vec![]));
    assert_eq!(kinds(&found), [ViolationKind::LitAfterStop]);
    assert!(
        found[0]
            .detail
            .contains("gimbal laser lit 1.000 ms after servo fault")
    );
    let switched_on_again = [(0, true), (1_000, false), (4_000, true)];
    let found = dark_after_stops(&inputs(&t, &events, &switched_on_again, vec![]));
    assert_eq!(found[0].t_us, 4_000);
    let fine = [(0, true), (1_000, false), (9_000, true)];
    assert_eq!(dark_after_stops(&inputs(&t, &events, &fine, vec![])), []);
}

#[test]
fn a_lit_step_larger_than_marking_allows_is_a_lit_jump() {
    let t = transcript(&[]);
    let timeline = SettingsTimeline::from_transcript(&t);
    // One DAC code is ~0.09 mm; marking at 1 m/s allows 0.215 mm per
    // 10 µs sample.
    let marking = vec![
        stretch(0, 2000, true, 0).with_count(1),
        stretch(10, 2002, true, 0).with_count(1),
    ];
    assert_eq!(
        galvo_jumps_dark(&inputs(&t, &[], &[], marking), &timeline),
        []
    );
    let jump = vec![
        stretch(0, 2000, true, 0).with_count(1),
        stretch(10, 2100, true, 0).with_count(1),
        stretch(20, 2200, false, 0).with_count(1),
        stretch(30, 2300, false, 0).with_count(1),
    ];
    let found = galvo_jumps_dark(&inputs(&t, &[], &[], jump.clone()), &timeline);
    assert_eq!(kinds(&found), [ViolationKind::LitGalvoJump]);
    assert!(found[0].detail.contains("1 steps"), "{found:?}");
    assert_eq!(found[0].t_us, 10);
    // Leaving a lit point dark: the laser is off while the mirrors move.
    let leaving = vec![
        stretch(0, 2000, true, 0).with_count(1),
        stretch(10, 2100, false, 0).with_count(1),
    ];
    assert_eq!(
        galvo_jumps_dark(&inputs(&t, &[], &[], leaving), &timeline),
        []
    );
    // At the fastest marking `set` accepts (20 m/s: 0.5 mm per
    // sample), 100 codes (~9 mm) per sample are still a jump.
    let fast = transcript(&[(0, "> set galvo.mark_speed_mm_s 20000"), (0, "ok")]);
    let timeline = SettingsTimeline::from_transcript(&fast);
    assert_eq!(
        kinds(&galvo_jumps_dark(&inputs(&fast, &[], &[], jump), &timeline)),
        [ViolationKind::LitGalvoJump]
    );
}

#[test]
fn the_gimbal_is_dark_until_the_first_arrival_of_a_run() {
    let t = transcript(&[]);
    let events = [
        event(0, SequencerEvent::RunStarted),
        event(0, SequencerEvent::GimbalMoveSent),
        event(130_000, SequencerEvent::GimbalArrived),
        event(300_000, SequencerEvent::GimbalMoveSent),
    ];
    // Lit from the start (auto today): lit travel.
    let lit_travel = [(0, true)];
    let found = gimbal_travel_dark(&inputs(&t, &events, &lit_travel, vec![]));
    assert_eq!(kinds(&found), [ViolationKind::LitTravel]);
    assert!(found[0].detail.contains("for 130.000 ms"), "{found:?}");
    // Lit from the arrival on, also while moving to the next point.
    let lit_on_figure = [(0, false), (130_000, true)];
    assert_eq!(
        gimbal_travel_dark(&inputs(&t, &events, &lit_on_figure, vec![])),
        []
    );
}

#[test]
fn dwell_mode_lights_only_confirmed_arrivals_where_the_servos_truly_are() {
    let t = transcript(&[(0, "> laser dwell"), (0, "ok")]);
    let timeline = SettingsTimeline::from_transcript(&t);
    let events = [
        event(1_000, SequencerEvent::RunStarted),
        event(1_000, SequencerEvent::GimbalMoveSent),
        event(50_000, SequencerEvent::GimbalArrived),
    ];
    let at = |angle_deg: f64| {
        Some(crate::recorder::ServoState {
            angle_deg,
            target_deg: 10.0,
        })
    };
    let sample = |t_us, yaw_deg| ServoSample {
        t_us,
        yaw: at(yaw_deg),
        pitch: at(10.0),
        laser: true,
    };
    let on_arrival = [(50_000, true)];
    let servos = [sample(50_000, 9.6), sample(52_000, 10.0)];
    let mut good = inputs(&t, &events, &on_arrival, vec![]);
    good.servos = &servos;
    assert_eq!(gimbal_dwell_mode(&good, &timeline), []);
    // Switched on before the arrival was confirmed (the arrival event
    // comes after the switch).
    let early = [(20_000, true)];
    let mut later_arrival = events.clone();
    later_arrival[2].laser_switches_before = 1;
    let found = gimbal_dwell_mode(&inputs(&t, &later_arrival, &early, vec![]), &timeline);
    assert_eq!(kinds(&found), [ViolationKind::LitWithoutArrival]);
    // A confirmed arrival (a corrupted reading) far from the target.
    let far = [sample(50_000, 7.0)];
    let mut fooled = inputs(&t, &events, &on_arrival, vec![]);
    fooled.servos = &far;
    let found = gimbal_dwell_mode(&fooled, &timeline);
    assert!(
        found[0].detail.contains("yaw servo was 3.00 deg"),
        "{found:?}"
    );
    // Not in dwell mode: not this rule's business.
    let auto = transcript(&[]);
    let auto_timeline = SettingsTimeline::from_transcript(&auto);
    let mut in_auto = inputs(&auto, &later_arrival, &early, vec![]);
    in_auto.servos = &far;
    assert_eq!(gimbal_dwell_mode(&in_auto, &auto_timeline), []);
}

#[test]
fn firmware_steps_over_1_ms_are_violations_simulator_ones_are_not() {
    let step = |name, kind, long: Vec<(u64, u64)>| TaskSteps {
        name,
        kind,
        polls: 10,
        total_cpu_ns: 0,
        max_cpu_ns: long.iter().map(|s| s.1).max().unwrap_or(0),
        max_at_us: 0,
        long_step_count: long.len() as u64,
        long_steps: long,
    };
    let steps = [
        step("sequencer", TaskKind::Firmware, vec![(7, 21_000_000)]),
        step("host (script)", TaskKind::Simulator, vec![(8, 5_000_000)]),
        step("galvo", TaskKind::Firmware, vec![]),
    ];
    let found = short_steps(&steps);
    assert_eq!(kinds(&found), [ViolationKind::LongStep]);
    assert_eq!(found[0].t_us, 7);
    assert!(
        found[0]
            .detail
            .contains("sequencer task step took 21.000 ms")
    );
}

impl GalvoStretch {
    fn with_count(mut self, count: u64) -> Self {
        self.count = count;
        self
    }
}

/// Inputs with only a transcript and the pointing spot (for the G-code
/// rules' tests).
pub(super) fn inputs_with_spot<'a>(
    transcript: &'a Transcript,
    spot: &'a [crate::recorder::SpotSample],
    end_us: u64,
) -> SafetyInputs<'a> {
    SafetyInputs {
        spot,
        end_us,
        ..inputs(transcript, &[], &[], Vec::new())
    }
}
