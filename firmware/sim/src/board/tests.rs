//! The simulated board's LEDs, stop button and watchdog, driven by the
//! same task bodies as the target's, in whole runs.

use laser_app::app::{HEARTBEAT_TICKS, INDICATOR_PERIOD, Leds, WATCHDOG_CHECK_PERIOD};

use crate::recorder::SequencerEvent;
use crate::script::parse_script;
use crate::servo_port::{BusFaults, SilentWindow};
use crate::world::{SimOptions, SimReport, run};

fn run_script(script: &str, options: SimOptions) -> SimReport {
    run(SimOptions {
        script: parse_script(script).expect("test script parses"),
        until_idle: true,
        ..options
    })
}

/// When the LEDs first showed something matching `lit`, µs.
fn first_lit(report: &SimReport, lit: impl Fn(&Leds) -> bool) -> Option<u64> {
    report
        .panel
        .leds
        .iter()
        .find(|(_, leds)| lit(leds))
        .map(|(t_us, _)| *t_us)
}

#[test]
fn the_laser_led_follows_the_laser_and_the_heartbeat_blinks_once_a_second() {
    let report = run_script(
        "laser dwell\ngoto 0 0\nwait 2000\nstop\nwait 1000\n",
        SimOptions::default(),
    );
    let lit_at = report
        .recording
        .laser_events
        .iter()
        .find(|(_, on)| *on)
        .map(|(t_us, _)| *t_us)
        .expect("the goto lit the laser");
    let led_at = first_lit(&report, |l| l.laser).expect("the laser LED lit");
    let period_us = INDICATOR_PERIOD.as_micros();
    assert!(
        (lit_at..=lit_at + period_us).contains(&led_at),
        "laser at {lit_at} µs, LED at {led_at} µs"
    );
    let last = report.panel.leds.last().expect("LEDs shown").1;
    assert!(!last.laser && !last.fault, "after the stop: {last:?}");
    let blinks = report.panel.leds.iter().filter(|(_, l)| l.heartbeat);
    let blink_period_us = period_us * u64::from(HEARTBEAT_TICKS);
    assert_eq!(
        blinks.clone().count() as u64,
        report.end_time_us / blink_period_us + 1
    );
    assert!(blinks.map(|(t, _)| t).all(|t| t % blink_period_us == 0));
}

#[test]
fn the_fault_led_shows_a_silent_servo() {
    let options = SimOptions {
        faults: BusFaults {
            silent: vec![SilentWindow {
                id: 1,
                from_ms: 300,
                until_ms: None,
            }],
            ..BusFaults::default()
        },
        ..SimOptions::default()
    };
    let report = run_script("pattern corner\nwait 3000\nstop\n", options);
    let fault_at = first_lit(&report, |l| l.fault).expect("the fault LED lit");
    assert!(fault_at > 300_000, "fault LED at {fault_at} µs");
}

#[test]
fn a_button_press_stops_the_run_through_the_stop_button_task() {
    let report = run_script(
        "pattern corner\nwait 500\n@button\nwait 100\n",
        SimOptions::default(),
    );
    assert_eq!(report.panel.button_presses, [500_000]);
    let stopped = report.recording.events.iter().find(
        |e| matches!(&e.event, SequencerEvent::Stopped { why } if why.as_str() == "stop button"),
    );
    assert_eq!(stopped.map(|e| e.t_us), Some(500_000));
    assert!(report.idle_at_end);
}

#[test]
fn the_watchdog_is_fed_every_second_and_would_never_reset() {
    let report = run_script(
        "pattern corner\nwait 2500\nsave\nwait 3000\nstop\n",
        SimOptions::default(),
    );
    let dog = &report.panel.watchdog;
    assert_eq!(dog.started_at_us, Some(0));
    assert!(dog.resets_at_us.is_empty(), "{dog:?}");
    let checks = report.end_time_us / WATCHDOG_CHECK_PERIOD.as_micros();
    assert!(
        dog.feeds + 2 >= checks && dog.feeds <= checks,
        "{} feeds in {checks} checks",
        dog.feeds
    );
}

#[test]
fn a_board_without_a_galvo_dac_runs_no_galvo_loop_and_refuses_the_galvo() {
    let script = "target galvo\ntarget gimbal\npattern corner once\n";
    let without = run_script(
        script,
        SimOptions {
            galvo_dac: false,
            ..SimOptions::default()
        },
    );
    assert!(without.task_steps.iter().all(|t| t.name != "galvo"));
    let replies: Vec<&str> = without
        .transcript
        .lines
        .iter()
        .map(|(_, line)| line.as_str())
        .collect();
    assert_eq!(
        replies[..4],
        [
            "> target galvo",
            "error: this build has no galvo output",
            "> target gimbal",
            "ok"
        ]
    );
    assert!(without.dac.is_empty());
    assert!(without.recording.dwells.len() >= 4, "the gimbal drew");
    let with = run_script(script, SimOptions::default());
    assert!(with.task_steps.iter().any(|t| t.name == "galvo"));
    assert_eq!(with.transcript.lines[1].1, "ok");
}
