//! The stepper parameters: ranges and rules, round trip through the
//! record, and a record saved before they existed.

extern crate std;

use super::super::stepper_params::STEPPER_PARAMS;
use crate::settings::*;

/// A version-3 record of the 54 parameters before the stepper's, written
/// by that firmware (main before issue 13's settings) with the values of
/// `record.rs`' fixture settings.
const V3_BEFORE_STEPPER: &[u8] = include_bytes!("fixtures/record_v3_before_stepper.bin");

fn param(name: &str) -> &'static ParamSpec {
    find_param(name).unwrap_or_else(|| panic!("no parameter {name}"))
}

/// Every stepper parameter changed from its default (and valid together).
fn changed() -> StepperSettings {
    StepperSettings {
        full_step_deg: 0.9,
        microsteps: 16.0,
        max_speed_deg_s: 120.0,
        accel_deg_s2: 1500.0,
        junction_deviation_deg: 0.02,
        pulse_us: 4.0,
        dir_setup_us: 2.5,
        enable_active_high: 1.0,
        idle_release_ms: 5000.0,
        home_seek_deg_s: 30.0,
        home_latch_deg_s: 1.5,
        home_pulloff_deg: 3.0,
        pan: StepperAxisSettings {
            direction: -1,
            zero_deg: 1.25,
            min_deg: -90.0,
            max_deg: 80.0,
            home_dir: 1.0,
            home_deg: 95.0,
        },
        tilt: StepperAxisSettings {
            direction: -1,
            zero_deg: -2.5,
            min_deg: -45.0,
            max_deg: 70.0,
            home_dir: -1.0,
            home_deg: -50.0,
        },
    }
}

#[test]
fn stepper_parameters_are_set_one_by_one_and_round_trip_through_the_record() {
    let target = Settings {
        stepper: changed(),
        ..Settings::default()
    };
    let mut s = Settings::default();
    // In an order where every step is valid on its own.
    for p in STEPPER_PARAMS.iter() {
        let value = target.get(p);
        assert_ne!(value, s.get(p), "{} is not changed by the fixture", p.name);
        s.set(p, value)
            .unwrap_or_else(|e| panic!("set {} {value}: {e}", p.name));
    }
    assert_eq!(s, target);
    let record = s.to_record();
    assert_eq!(record.len(), RECORD_LEN);
    let loaded = Settings::load_record(&record).expect("loads");
    assert!(loaded.is_exact());
    assert_eq!(loaded.settings, target);
}

#[test]
fn out_of_range_and_inconsistent_stepper_values_are_refused_and_change_nothing() {
    let mut s = Settings::default();
    let before = s;
    let refused = [
        ("stepper.full_step_deg", 0.0),
        ("stepper.full_step_deg", 20.0),
        ("stepper.microsteps", 0.0),
        ("stepper.microsteps", 12.5),
        ("stepper.microsteps", 512.0),
        ("stepper.max_speed_deg_s", f64::NAN),
        ("stepper.accel_deg_s2", -1.0),
        ("stepper.junction_deg", -0.1),
        ("stepper.pulse_us", 0.1),
        ("stepper.dir_setup_us", 101.0),
        ("stepper.enable_high", 0.5),
        ("stepper.enable_high", 2.0),
        ("stepper.idle_release_ms", -1.0),
        ("stepper.pan.dir", 0.0),
        ("stepper.tilt.dir", 0.5),
        ("stepper.pan.zero_deg", 181.0),
        ("stepper.tilt.max_deg", 91.0),
        ("stepper.pan.home_dir", 2.0),
        ("stepper.tilt.home_dir", 0.5),
        ("stepper.home_pulloff_deg", 0.0),
        // 0.02 °/s at 0.05625°/step is 0.36 steps/s.
        ("stepper.home_latch_deg_s", 0.02),
        // Rules between parameters: limits in order …
        ("stepper.pan.min_deg", 60.0),
        ("stepper.tilt.max_deg", -60.0),
        // … and 3000 °/s at 0.05625°/step is 53 333 steps/s.
        ("stepper.max_speed_deg_s", 3000.0),
    ];
    for (name, value) in refused {
        let error = s.set(param(name), value);
        assert!(error.is_err(), "{name} {value} accepted");
        assert_eq!(s, before, "{name} {value} changed something");
    }
    // The messages say what is wrong.
    let e = s.set(param("stepper.microsteps"), 300.0).unwrap_err();
    let text = std::format!("{e}");
    assert!(
        text.contains("stepper.microsteps") && text.contains("256"),
        "{text}"
    );
    let e = s.set(param("stepper.max_speed_deg_s"), 3000.0).unwrap_err();
    assert!(std::format!("{e}").contains("50000 steps/s"), "{e}");
    // 256 microsteps at 90 °/s: 12 800 steps/s, a 78 µs step period that
    // 100 µs pulses do not fit.
    assert!(s.set(param("stepper.microsteps"), 256.0).is_ok());
    let fine = s;
    assert!(s.set(param("stepper.pulse_us"), 100.0).is_err());
    assert_eq!(s, fine);
    // Whole microsteps that are not powers of two are fine (e.g. 25).
    assert!(s.set(param("stepper.microsteps"), 25.0).is_ok());
}

#[test]
fn a_record_saved_before_the_stepper_parameters_loads_them_at_their_defaults() {
    let loaded = Settings::load_record(V3_BEFORE_STEPPER).expect("loads");
    assert_eq!(loaded.layout, RecordLayout::IdKeyed);
    assert_eq!(
        (loaded.unknown, loaded.defaulted),
        // The stepper's, `$11`, the PELCO port's and the emission delay.
        (0, STEPPER_PARAMS.len() + 1 + 3 + 1)
    );
    assert_eq!(loaded.settings.stepper, StepperSettings::default());
    // The ones after them, `$11` and the emission delay, at their
    // defaults too.
    assert_eq!(loaded.settings.gcode_junction_mm, 0.01);
    // Its other values are those it was written with.
    assert_eq!(loaded.settings.dwell_ms, 250.0);
    assert_eq!(loaded.settings.yaw.direction, -1);
    assert_eq!(loaded.settings.galvo.d_mm, 350.0);
    // The next save writes every parameter; that record loads exactly.
    let again = Settings::load_record(&loaded.settings.to_record()).expect("loads");
    assert!(again.is_exact());
    assert_eq!(again.settings, loaded.settings);
}
