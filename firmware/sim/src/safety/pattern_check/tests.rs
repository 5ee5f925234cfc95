//! The figure rule on small synthetic runs: a circle drawn on its figure
//! passes and the same circle shifted fails; grid points lit only at the
//! points pass in `laser dwell`, and a lit travel between them fails
//! there but passes in `laser auto`, where it is part of the figure.

use super::super::pattern_figure::{FigureSettings, travel};
use super::super::tests::inputs_with_spot;
use super::super::{SafetyInputs, Violation, ViolationKind, check_inputs};
use crate::recorder::{EventRecord, SequencerEvent, SpotSample};
use crate::usb_host::Transcript;

/// `lines` sent 10 ms apart, each accepted 5 ms after it was sent.
fn accepted(lines: &[&str]) -> Transcript {
    let mut t = Transcript::default();
    for (k, line) in lines.iter().enumerate() {
        let sent = k as u64 * 10_000;
        t.lines.push((sent, format!("> {line}")));
        t.lines.push((sent + 5_000, "ok".to_owned()));
    }
    t
}

/// The run started by the last line starts 1 ms after it was sent.
fn started(transcript: &Transcript) -> Vec<EventRecord> {
    let sent = transcript.lines.iter().rev().find(|l| l.1.starts_with('>'));
    vec![EventRecord {
        t_us: sent.map_or(0, |l| l.0) + 1_000,
        event: SequencerEvent::RunStarted,
        laser_switches_before: 0,
    }]
}

/// Off-figure breaches of `spot` (board mm, lit) sampled every 2 ms from
/// 0.1 s on, after `lines`.
fn off_figure(lines: &[&str], spot: &[([f64; 2], bool)]) -> Vec<Violation> {
    let transcript = accepted(lines);
    let events = started(&transcript);
    let samples: Vec<SpotSample> = spot
        .iter()
        .enumerate()
        .map(|(k, &(p, laser))| SpotSample {
            t_us: 100_000 + k as u64 * 2_000,
            x_cm: p[0] / 10.0,
            y_cm: p[1] / 10.0,
            laser,
            power: if laser { 1000 } else { 0 },
        })
        .collect();
    let end_us = 100_000 + spot.len() as u64 * 2_000 + 1_000;
    let inputs = SafetyInputs {
        events: &events,
        ..inputs_with_spot(&transcript, &samples, end_us)
    };
    check_inputs(&inputs)
        .into_iter()
        .filter(|v| v.kind == ViolationKind::OffFigure)
        .collect()
}

/// A circle of `radius` mm about `centre` mm, 500 samples, lit.
fn circle(centre: [f64; 2], radius: f64) -> Vec<([f64; 2], bool)> {
    (0..500)
        .map(|k| {
            let a = k as f64 / 500.0 * std::f64::consts::TAU;
            (
                [centre[0] + radius * a.cos(), centre[1] + radius * a.sin()],
                true,
            )
        })
        .collect()
}

#[test]
fn a_circle_on_its_figure_passes_and_a_shifted_one_fails() {
    let line = "pattern circle 2 1 4 ccw once";
    assert_eq!(off_figure(&[line], &circle([20.0, 10.0], 40.0)), vec![]);
    // Within the gimbal's 2 mm plus half the 2 mm step: still on it.
    assert_eq!(off_figure(&[line], &circle([22.5, 10.0], 40.0)), vec![]);
    // 5 mm off: lit off the figure where the shifted circle leaves it
    // (left and right; the top and bottom stay within the tolerance).
    let found = off_figure(&[line], &circle([25.0, 10.0], 40.0));
    assert_eq!(found.len(), 3, "{found:?}");
    assert_eq!(found[0].kind.name(), "off-figure");
    assert!(found[0].detail.contains("worst 5.00 mm"), "{found:?}");
    // The stepper's 0.6 mm, no step added: 0.5 mm is on, 0.8 mm off.
    let stepper = off_figure(&["target stepper", line], &circle([20.5, 10.0], 40.0));
    assert_eq!(stepper.len(), 0, "the stepper's 0.6 mm takes 0.5 mm");
    let stepper = off_figure(&["target stepper", line], &circle([20.8, 10.0], 40.0));
    assert!(!stepper.is_empty(), "{stepper:?}");
}

/// Grid points (−6, 4) and (6, 4) at the default pitch, mm.
fn corners() -> ([f64; 2], [f64; 2]) {
    let s = FigureSettings::default();
    (s.grid_mm(-6, 4), s.grid_mm(6, 4))
}

/// Dwelling lit at `a`, travelling from `a` to `b` along `path` with the
/// laser `lit_travel`, dwelling lit at `b`.
fn visit(a: [f64; 2], b: [f64; 2], path: &[[f64; 2]], lit_travel: bool) -> Vec<([f64; 2], bool)> {
    let mut out = vec![(a, true); 50];
    out.extend(path.iter().map(|&p| (p, lit_travel)));
    out.extend(vec![(b, true); 50]);
    out
}

/// The gimbal's travel (joint space) from `a` to `b`, 200 points.
fn joint_travel(a: [f64; 2], b: [f64; 2]) -> Vec<[f64; 2]> {
    let s = FigureSettings::default();
    let pieces = travel(a, b, &s, s.ol_cm);
    (0..200)
        .map(|k| {
            let f = k as f64 / 200.0 * pieces.len() as f64;
            let piece = &pieces[f as usize];
            let (p, q) = (piece.start(), piece.end());
            let r = f.fract();
            [p[0] + r * (q[0] - p[0]), p[1] + r * (q[1] - p[1])]
        })
        .collect()
}

#[test]
fn a_lit_travel_between_grid_points_fails_in_dwell_mode_only() {
    let (a, b) = corners();
    let path = joint_travel(a, b);
    let dark = visit(a, b, &path, false);
    let lit = visit(a, b, &path, true);
    assert_eq!(
        off_figure(&["laser dwell", "pattern corner"], &dark),
        vec![]
    );
    let found = off_figure(&["laser dwell", "pattern corner"], &lit);
    assert_eq!(found.len(), 1, "{found:?}");
    assert!(found[0].detail.contains("pattern corner"), "{found:?}");
    // In auto mode the gimbal is lit along its joint-space travel …
    assert_eq!(off_figure(&["laser auto", "pattern corner"], &lit), vec![]);
    // … but not along the chord, which it never takes (~7 mm off).
    let chord: Vec<[f64; 2]> = (0..200)
        .map(|k| {
            let f = k as f64 / 200.0;
            [a[0] + f * (b[0] - a[0]), a[1]]
        })
        .collect();
    let found = off_figure(&["pattern corner"], &visit(a, b, &chord, true));
    assert_eq!(found.len(), 1, "{found:?}");
}

#[test]
fn the_grid_settings_and_the_target_are_those_in_force() {
    let s = FigureSettings::default();
    // Pitch 2 cm: the point (1, 1) is (20, 20) mm, not (19.16, 19.16).
    let at = |p: [f64; 2]| vec![(p, true); 100];
    let pitch = ["set grid.pitch_cm 2", "grid 1 1"];
    assert_eq!(off_figure(&pitch, &at([20.0, 20.0])), vec![]);
    assert_eq!(off_figure(&pitch, &at(s.grid_mm(1, 1))), vec![]);
    assert_eq!(
        off_figure(
            &["target stepper", "set grid.pitch_cm 2", "grid 1 1"],
            &at(s.grid_mm(1, 1))
        )
        .len(),
        1,
        "0.84 mm is off for the stepper"
    );
    // A goto holds one board point.
    assert_eq!(off_figure(&["goto 3 -2"], &at([30.0, -20.0])), vec![]);
    assert_eq!(off_figure(&["goto 3 -2"], &at([30.0, -23.0])).len(), 1);
    // A refused line draws nothing: its run is not judged.
    let mut refused = accepted(&["goto 3 -2"]);
    refused.lines[1].1 = "error: unreachable".to_owned();
    let judged = super::super::pattern_model::judged_runs(&refused, &started(&refused));
    assert!(judged.is_empty(), "{judged:?}");
}
