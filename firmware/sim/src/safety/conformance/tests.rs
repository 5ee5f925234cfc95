//! The path and duration rules on small synthetic runs: issue 25's
//! runaway stepper arc (recorded before the fix: the spot kept circling,
//! lit) fails both; the arc as it runs now passes.

use super::super::tests::inputs_with_spot;
use super::super::{ViolationKind, check_inputs};
use crate::recorder::SpotSample;
use crate::usb_host::Transcript;

/// `target stepper` / `$X` / `G0 X10 Y0` / `M3 S1000` /
/// `G2 X0 Y-10 I-10 J0 F600`, all accepted at once.
fn arc_transcript() -> Transcript {
    let lines = [
        "target stepper",
        "$X",
        "G0 X10 Y0",
        "M3 S1000",
        "G2 X0 Y-10 I-10 J0 F600",
    ];
    let mut t = Transcript::default();
    for (k, line) in lines.iter().enumerate() {
        t.lines.push((k as u64 * 10, format!("> {line}")));
        t.lines.push((k as u64 * 10 + 5, "ok".to_owned()));
    }
    t
}

/// The stepper's spot every 2 ms: at (10, 0) mm dark for 0.1 s, then
/// clockwise about the origin at 10 mm/s, lit, for `lit_s`, then dark
/// where it stopped, until 10 s.
fn circling(lit_s: f64) -> Vec<SpotSample> {
    (0..5000u64)
        .map(|k| {
            let t_s = k as f64 * 0.002;
            let moving_s = (t_s - 0.1).clamp(0.0, lit_s);
            let angle = -moving_s; // 10 mm/s on a 10 mm radius: 1 rad/s.
            SpotSample {
                t_us: k * 2000,
                x_cm: angle.cos(),
                y_cm: angle.sin(),
                laser: t_s > 0.1 && t_s - 0.1 <= lit_s,
                power: 0,
            }
        })
        .collect()
}

fn kinds(spot: &[SpotSample]) -> Vec<ViolationKind> {
    let transcript = arc_transcript();
    let inputs = inputs_with_spot(&transcript, spot, 10_000_000);
    let found = check_inputs(&inputs);
    found.iter().map(|v| v.kind).collect()
}

#[test]
fn a_runaway_stepper_arc_fails_the_path_and_the_duration_rules() {
    // Before the fix: 9.9 s of circling (567°) for a planned quarter.
    let found = kinds(&circling(9.9));
    assert!(found.contains(&ViolationKind::OffPath), "{found:?}");
    assert!(found.contains(&ViolationKind::LateMotion), "{found:?}");
}

#[test]
fn the_arc_that_ends_at_its_end_passes() {
    // A quarter at 10 mm/s: π/2 s.
    assert_eq!(kinds(&circling(std::f64::consts::FRAC_PI_2)), []);
}

#[test]
fn an_arc_that_ends_early_or_a_bit_late_is_judged_by_its_bound() {
    // 0.2 rad (2 mm) short of its end: never arrives.
    let short = kinds(&circling(std::f64::consts::FRAC_PI_2 - 0.2));
    assert_eq!(short, [ViolationKind::LateMotion]);
    // 0.03 rad (0.3 mm) past its end: inside the stepper's 0.6 mm.
    assert_eq!(kinds(&circling(std::f64::consts::FRAC_PI_2 + 0.03)), []);
}
