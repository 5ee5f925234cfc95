use proptest::prelude::*;

use super::*;

const CLOSED_ON: ControlInputs = ControlInputs {
    interlock_closed: true,
    key_on: true,
};
const DELAY_US: u64 = 3_000_000;

/// Controls that read closed and on for long enough to count.
fn settled(now_us: u64) -> ControlsLogic {
    let mut c = ControlsLogic::new();
    c.sample(now_us, CLOSED_ON);
    c.sample(now_us + SETTLE_US, CLOSED_ON);
    c
}

#[test]
fn power_up_is_latched_dark_and_arming_needs_settled_inputs() {
    let mut c = ControlsLogic::new();
    assert_eq!(c.arming(), Arming::Latched(LatchCause::PowerUp));
    assert!(!c.emission_permitted() && !c.indicator_on());
    assert_eq!(c.arm(0, DELAY_US), Err(ArmRefusal::InterlockOpen));
    c.sample(0, CLOSED_ON);
    assert_eq!(c.next_deadline_us(), Some(SETTLE_US));
    c.sample(SETTLE_US - 1, CLOSED_ON);
    assert_eq!(
        c.arm(SETTLE_US - 1, DELAY_US),
        Err(ArmRefusal::InterlockOpen),
        "closed for less than the settle time does not count"
    );
    c.sample(SETTLE_US, CLOSED_ON);
    assert_eq!(c.inputs(), CLOSED_ON);
    assert_eq!(
        c.arming(),
        Arming::Latched(LatchCause::PowerUp),
        "inputs alone never arm"
    );
}

#[test]
fn arm_lights_the_indicator_first_and_permits_after_the_delay() {
    let mut c = settled(0);
    let t = SETTLE_US + 1_000;
    assert_eq!(c.arm(t, DELAY_US), Ok(()));
    assert!(c.indicator_on());
    assert!(!c.emission_permitted());
    assert_eq!(c.next_deadline_us(), Some(t + DELAY_US));
    c.sample(t + DELAY_US - 1, CLOSED_ON);
    assert!(!c.emission_permitted());
    c.sample(t + DELAY_US, CLOSED_ON);
    assert!(c.emission_permitted() && c.indicator_on());
    assert_eq!(c.next_deadline_us(), None);
    // Arming again changes nothing.
    assert_eq!(c.arm(t + DELAY_US + 5, DELAY_US), Ok(()));
    assert_eq!(c.arming(), Arming::Armed);
}

#[test]
fn opening_latches_at_once_and_closing_alone_does_not_rearm() {
    let mut c = settled(0);
    c.arm(SETTLE_US, 0).unwrap();
    assert!(c.emission_permitted());
    let open = ControlInputs {
        interlock_closed: false,
        key_on: true,
    };
    c.sample(50_000, open);
    assert_eq!(c.arming(), Arming::Latched(LatchCause::InterlockOpened));
    assert!(!c.emission_permitted() && !c.indicator_on());
    // Closed again (and settled): still latched.
    c.sample(60_000, CLOSED_ON);
    c.sample(60_000 + SETTLE_US, CLOSED_ON);
    assert_eq!(c.arming(), Arming::Latched(LatchCause::InterlockOpened));
    // The reset re-arms, after the delay.
    c.arm(100_000, DELAY_US).unwrap();
    assert!(c.indicator_on() && !c.emission_permitted());
    c.sample(100_000 + DELAY_US, CLOSED_ON);
    assert!(c.emission_permitted());
}

#[test]
fn a_bounce_open_restarts_the_settle_time_and_trips_an_arming() {
    let mut c = settled(0);
    c.arm(SETTLE_US, DELAY_US).unwrap();
    c.sample(
        SETTLE_US + 10,
        ControlInputs {
            interlock_closed: true,
            key_on: false,
        },
    );
    assert_eq!(c.arming(), Arming::Latched(LatchCause::KeyOff));
    c.sample(SETTLE_US + 20, CLOSED_ON);
    assert_eq!(c.arm(SETTLE_US + 30, DELAY_US), Err(ArmRefusal::KeyOff));
    c.sample(2 * SETTLE_US + 20, CLOSED_ON);
    assert_eq!(c.arm(2 * SETTLE_US + 20, DELAY_US), Ok(()));
}

/// What happens at one step of a random session.
#[derive(Debug, Clone)]
enum Step {
    /// Raw inputs read after `dt_us`.
    Sample { dt_us: u64, raw: ControlInputs },
    /// `arm` after `dt_us`.
    Arm { dt_us: u64 },
}

fn step() -> impl Strategy<Value = Step> {
    prop_oneof![
        3 => (0u64..60_000, any::<bool>(), any::<bool>()).prop_map(|(dt_us, i, k)| Step::Sample {
            dt_us,
            raw: ControlInputs {
                interlock_closed: i,
                key_on: k,
            },
        }),
        1 => (0u64..60_000).prop_map(|dt_us| Step::Arm { dt_us }),
    ]
}

proptest! {
    /// Never emission while the interlock reads open or the key off (from
    /// that very reading on), never before the delay has passed since
    /// the indicator came on, and never without a reset after the last
    /// opening.
    #[test]
    fn never_emission_while_open_off_or_before_the_delay(
        steps in prop::collection::vec(step(), 1..200),
        delay_us in 0u64..200_000,
    ) {
        let mut c = ControlsLogic::new();
        let mut now_us = 0u64;
        let mut indicator_since: Option<u64> = None;
        let mut last_raw = ControlInputs::default();
        let mut reset_since_trip = false;
        for step in steps {
            match step {
                Step::Sample { dt_us, raw } => {
                    now_us += dt_us;
                    c.sample(now_us, raw);
                    last_raw = raw;
                    if !(raw.interlock_closed && raw.key_on) {
                        reset_since_trip = false;
                        prop_assert!(!c.emission_permitted());
                        prop_assert!(!c.indicator_on());
                    }
                }
                Step::Arm { dt_us } => {
                    now_us += dt_us;
                    let was_latched = matches!(c.arming(), Arming::Latched(_));
                    if c.arm(now_us, delay_us).is_ok() {
                        prop_assert!(last_raw.interlock_closed && last_raw.key_on);
                        if was_latched {
                            reset_since_trip = true;
                        }
                    }
                }
            }
            match (c.indicator_on(), indicator_since) {
                (true, None) => indicator_since = Some(now_us),
                (false, _) => indicator_since = None,
                _ => {}
            }
            if c.emission_permitted() {
                prop_assert!(reset_since_trip, "armed without a reset");
                let since = indicator_since.expect("emission without the indicator");
                prop_assert!(now_us >= since + delay_us, "emission before the delay");
                prop_assert!(last_raw.interlock_closed && last_raw.key_on);
            }
        }
    }
}
