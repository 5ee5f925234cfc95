//! The scenarios on the simulator (the emulated board runs them in
//! `cargo xtask test`), and the checks against outcomes that break them.

use super::*;

fn scenario(name: &str) -> Scenario {
    Scenario::load(&workspace_root().join(DIR).join(format!("{name}.txt"))).unwrap()
}

#[test]
fn every_scenario_passes_on_the_simulator() {
    let scenarios = all().unwrap();
    assert!(scenarios.len() >= 6, "{} scenarios", scenarios.len());
    for s in scenarios {
        let outcome = on_simulator(&s).unwrap();
        if let Err(e) = check(&s.name, &outcome) {
            panic!("{}: {e:#}\n{}", s.name, outcome.transcript.join("\n"));
        }
    }
}

#[test]
fn a_laser_lit_after_the_fault_fails_the_silent_servo_scenario() {
    let mut outcome = on_simulator(&scenario("silent_servo")).unwrap();
    let fault_at = outcome
        .events
        .iter()
        .find(|(_, e)| matches!(e, BoardEvent::Stopped(why) if why.contains("fault")))
        .map(|(t, _)| *t)
        .unwrap();
    outcome.laser_events.push((fault_at + 5_000, true));
    outcome.laser_events.sort_by_key(|(t, _)| *t);
    assert!(check("silent_servo", &outcome).is_err());
}

#[test]
fn a_missing_reply_fails_the_garbage_flood() {
    let mut outcome = on_simulator(&scenario("garbage_flood")).unwrap();
    let i = outcome
        .transcript
        .iter()
        .position(|l| l.starts_with("error:"))
        .unwrap();
    outcome.transcript.remove(i);
    assert!(check("garbage_flood", &outcome).is_err());
}

#[test]
fn a_setting_lost_over_the_reset_fails_save_reset() {
    let mut outcome = on_simulator(&scenario("save_reset")).unwrap();
    for line in &mut outcome.transcript {
        *line = line.replace("321", "1000");
    }
    assert!(check("save_reset", &outcome).is_err());
}

#[test]
fn an_unknown_scenario_name_is_refused() {
    assert!(check("no-such-scenario", &Outcome::default()).is_err());
}

#[test]
fn an_underrun_fails_the_galvo_scenario() {
    let mut outcome = on_simulator(&scenario("galvo_tuning")).unwrap();
    assert!(check("galvo_tuning", &outcome).is_ok());
    for line in &mut outcome.transcript {
        if line.starts_with("underruns: 0,") {
            *line = line.replacen("underruns: 0,", "underruns: 2,", 1);
        }
    }
    assert!(check("galvo_tuning", &outcome).is_err());
}
