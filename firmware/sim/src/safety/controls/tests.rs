use super::*;
use crate::physics::PhysicalGalvo;
use crate::usb_host::Transcript;

const S: u64 = 1_000_000;

/// Bench wiring, armed at 1 s (indicator on), default delay (3 s).
fn armed_at_1s() -> ControlsRecord {
    ControlsRecord {
        interlock_closed: vec![(0, true)],
        key_on: vec![(0, true)],
        indicator: vec![(0, false), (S, true)],
    }
}

fn check(record: &ControlsRecord, gimbal_laser: &[(u64, bool)]) -> Vec<Violation> {
    let transcript = Transcript::default();
    let inputs = SafetyInputs {
        gimbal_laser,
        galvo: Vec::new(),
        underruns_ns: &[],
        events: &[],
        servos: &[],
        transcript: &transcript,
        task_steps: &[],
        galvo_physics: PhysicalGalvo::default(),
        end_us: 20 * S,
        spot: &[],
        controls: Some(record),
    };
    laser_controls_obeyed(&inputs, &SettingsTimeline::from_transcript(&transcript))
}

#[test]
fn lit_after_the_delay_with_everything_closed_holds() {
    assert!(check(&armed_at_1s(), &[(4 * S, true), (5 * S, false)]).is_empty());
}

#[test]
fn lit_before_the_delay_or_without_the_indicator_is_a_violation() {
    let early = check(&armed_at_1s(), &[(3 * S, true), (5 * S, false)]);
    assert_eq!(early.len(), 1, "{early:?}");
    assert!(
        early[0]
            .detail
            .contains("after the emission indicator came on")
    );
    let dark_indicator = check(&armed_at_1s(), &[(S / 2, true), (S, false)]);
    assert!(dark_indicator[0].detail.contains("indicator off"));
}

#[test]
fn lit_after_an_opening_without_a_reset_is_a_violation_within_1_ms_is_not() {
    let mut record = armed_at_1s();
    record
        .interlock_closed
        .extend([(6 * S, false), (7 * S, true)]);
    // The firmware darkened at once: fine.
    assert!(check(&record, &[(4 * S, true), (6 * S + 500, false)]).is_empty());
    // Still lit 2 ms after the opening.
    let late = check(&record, &[(4 * S, true), (6 * S + 2_000, false)]);
    assert_eq!(late.len(), 1);
    assert!(late[0].detail.contains("interlock was open"), "{late:?}");
    // Lit again after the close with the indicator still on from the
    // old reset: no reset since the opening.
    let relit = check(&record, &[(8 * S, true), (9 * S, false)]);
    assert_eq!(relit.len(), 1, "{relit:?}");
    // The key too.
    let mut key = armed_at_1s();
    key.key_on.push((5 * S, false));
    assert_eq!(check(&key, &[(6 * S, true), (7 * S, false)]).len(), 1);
}
