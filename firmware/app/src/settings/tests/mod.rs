//! Tests of the parameter table and of `set`; of the saved record in
//! `record.rs`.

mod record;
mod stepper;

use super::spec::{check_value, survives_f32};
use super::*;

#[test]
fn names_are_unique_and_defaults_are_in_range() {
    let d = Settings::default();
    for (i, p) in PARAMS.iter().enumerate() {
        assert!(
            PARAMS.iter().skip(i + 1).all(|q| q.name != p.name),
            "{}",
            p.name
        );
        let v = d.get(p);
        assert!(
            v >= p.min && v <= p.max,
            "{} default {v} out of range",
            p.name
        );
    }
    assert!(d.validate().is_ok());
}

#[test]
fn set_checks_range_and_changes_nothing_on_error() {
    let mut s = Settings::default();
    let dwell = find_param("dwell_ms").unwrap();
    assert!(s.set(dwell, 250.0).is_ok());
    assert_eq!(s.dwell_ms, 250.0);
    let before = s;
    assert!(s.set(dwell, -1.0).is_err());
    assert!(s.set(dwell, f64::NAN).is_err());
    assert!(s.set(find_param("grid.cols").unwrap(), 13.0).is_err());
    assert!(s.set(find_param("grid.cols").unwrap(), 12.5).is_err());
    assert!(s.set(find_param("yaw.dir").unwrap(), 0.0).is_err());
    assert!(
        s.set(find_param("pitch.id").unwrap(), 0.0).is_err(),
        "ids must differ"
    );
    assert!(
        s.set(find_param("yaw.min_deg").unwrap(), 150.0).is_err(),
        "min < max"
    );
    assert_eq!(s, before);
    assert!(s.set(find_param("YAW.DIR").unwrap(), -1.0).is_ok());
    assert_eq!(s.yaw.direction, -1);
}

/// Values to try around a parameter's range: the bounds, the values
/// just outside them, the values just inside its smallest magnitude,
/// tiny and huge magnitudes, and non-finite values.
fn probes(p: &ParamSpec) -> heapless::Vec<f64, 20> {
    let mut v: heapless::Vec<f64, 20> = heapless::Vec::new();
    let base = [
        p.min,
        p.max,
        p.min.next_down(),
        p.max.next_up(),
        1e-300,
        -1e-300,
        f64::MIN_POSITIVE,
        1e-40,
        1e39,
        -1e39,
        f64::MAX,
        f64::NAN,
        f64::INFINITY,
        f64::NEG_INFINITY,
        0.0,
    ];
    let m = p.min_magnitude;
    let near_zero = [m, -m, m.next_down(), -m.next_down()];
    for value in base.into_iter().chain(near_zero) {
        v.push(value).expect("20 probes fit");
    }
    v
}

/// What the firmware derives from the settings in the precision it uses
/// them in must stay finite and non-degenerate.
fn assert_usable(s: &Settings, what: &str) {
    for p in PARAMS {
        let v = s.get(p);
        assert!(v.is_finite(), "{what}: {} = {v}", p.name);
        if p.precision == Precision::F32 {
            assert!(survives_f32(v), "{what}: {} = {v} vanishes in f32", p.name);
        }
    }
    {
        // As the galvo loop takes them (`sequencer::config_from`).
        let g = &s.galvo;
        let galvo = g.galvo();
        for dac in [galvo.dac_x, galvo.dac_y] {
            assert!(
                dac.codes_per_rad.is_finite() && dac.codes_per_rad.abs() >= 1_000.0,
                "{what}: DAC scale {} in f32",
                dac.codes_per_rad
            );
            assert!(dac.offset_code.is_finite());
        }
        assert!(galvo.geometry.d_mm.is_finite() && galvo.geometry.d_mm > 0.0);
        assert!(galvo.geometry.e_mm.is_finite());
        assert!(g.sample_period_us > 0.0 && g.sample_period_us.is_finite());
        assert!((g.mark_accel_mm_s2 as f32).is_normal());
    }
}

#[test]
fn every_parameter_is_range_checked_in_the_precision_it_is_used_in() {
    let defaults = Settings::default();
    assert_usable(&defaults, "defaults");
    for p in PARAMS {
        assert!(
            p.min.is_finite() && p.max.is_finite() && p.min < p.max,
            "{}",
            p.name
        );
        assert!(!p.help.is_empty(), "{} documents its unit", p.name);
        let d = defaults.get(p);
        assert!(
            d >= p.min && d <= p.max && d.abs() >= p.min_magnitude,
            "{} default {d} out of range",
            p.name
        );
        assert!(check_value(p, d).is_ok(), "{} default refused", p.name);
        for value in probes(p) {
            let mut s = defaults;
            let in_range = value.is_finite()
                && value >= p.min
                && value <= p.max
                && value.abs() >= p.min_magnitude;
            let result = s.set(p, value);
            if !in_range {
                assert!(result.is_err(), "{} = {value} accepted", p.name);
            }
            match result {
                Ok(()) => {
                    assert_eq!(s.get(p), value, "{} stores {value}", p.name);
                    assert_usable(&s, p.name);
                }
                Err(_) => assert_eq!(s, defaults, "refused {} = {value} changed", p.name),
            }
        }
    }
}

#[test]
fn params_lines_show_the_range_and_fit_a_reply_line() {
    use core::fmt::Write as _;
    let d = Settings::default();
    // The default and in-range values with all 17 digits.
    for (p, value) in PARAMS.iter().flat_map(|p| {
        [
            (p, d.get(p)),
            (p, p.min * 0.987_654_321_098_765_4),
            (p, p.max * 0.123_456_789_012_345_67),
        ]
    }) {
        let mut line: heapless::String<256> = heapless::String::new();
        write!(line, "{}", ParamLine(p, value)).unwrap();
        assert!(
            line.len() <= crate::text::REPLY_LINE_LEN,
            "{} bytes: {line}",
            line.len()
        );
        assert!(line.ends_with(']') && line.contains(" # "), "{line}");
    }
}

#[test]
fn a_galvo_scale_too_close_to_zero_is_refused() {
    for name in ["galvo.x_codes_per_rad", "galvo.y_codes_per_rad"] {
        let mut s = Settings::default();
        let before = s;
        let Some(p) = find_param(name) else {
            panic!("no parameter {name}");
        };
        for value in [1e-300, -1e-300, 1e-45, 0.5, -999.0, 0.0] {
            assert!(s.set(p, value).is_err(), "{name} = {value}");
            assert_eq!(s, before);
        }
        assert!(s.set(p, -MIN_CODES_PER_RAD).is_ok());
        assert!(s.set(p, MAX_CODES_PER_RAD).is_ok());
    }
}
