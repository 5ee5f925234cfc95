//! Seeded random G-code campaigns on every actuator (gimbal, galvo,
//! stepper), judged by the safety checker with its G-code rules (lit
//! samples on the commanded path, motions ending within their bound;
//! issue 25): lines, arcs in the I/J, full-circle and R forms, G91, lit
//! and dark, M3/M4/M5 and S, dwells, feed holds (`!` … `~`) and soft
//! resets (0x18) at random moments.
//!
//! [`SEEDS`] sessions of [`LINES`] random lines per actuator: about 20–40 s
//! of simulated time each, a few seconds of wall time per actuator.

use laser_sim::safety::{check, report_text};
use laser_sim::world::{SimOptions, SimReport};
use system_tests::{UNTIL_STEP_FIXES, XorShift, run_with};

/// Random sessions per actuator.
const SEEDS: u64 = 4;
/// Random lines per session.
const LINES: usize = 40;
/// Half the square the random points lie in, mm.
const FIELD_MM: f64 = 25.0;

/// A number with at most three decimals, as a sender writes it.
fn num(v: f64) -> String {
    let s = format!("{v:.3}");
    let s = s.trim_end_matches('0').trim_end_matches('.');
    if s == "-0" { "0".into() } else { s.into() }
}

/// A random point of the field, mm.
fn point(rng: &mut XorShift) -> [f64; 2] {
    let mut c = || (rng.below(2001) as f64 / 1000.0 - 1.0) * FIELD_MM;
    [c(), c()]
}

/// One random G-code session on `target`.
fn session(target: &str, seed: u64) -> String {
    let mut rng = XorShift(seed.wrapping_mul(0x9e37_79b9_7f4a_7c15) ^ 0x5eed | 1);
    let mut out = format!("target {target}\n$X\nG21 G90\nG0 X0 Y0\n");
    // The position as programmed (after a reset: where it was sent to last).
    let mut at = [0.0, 0.0];
    for _ in 0..LINES {
        let feed = 300 + rng.below(2700);
        let line = match rng.below(20) {
            0..=2 => {
                let p = point(&mut rng);
                at = p;
                format!("G0 X{} Y{}", num(p[0]), num(p[1]))
            }
            3..=6 => {
                let p = point(&mut rng);
                at = p;
                format!("G1 X{} Y{} F{feed}", num(p[0]), num(p[1]))
            }
            7..=9 => {
                // An arc about a random centre to a random angle (a full
                // circle one time in four), G2 or G3.
                let (i, j) = (
                    rng.below(2001) as f64 / 100.0 - 10.0,
                    rng.below(2001) as f64 / 100.0 - 10.0,
                );
                let centre = [at[0] + i, at[1] + j];
                let r = i.hypot(j);
                let to = if rng.below(4) == 0 {
                    at
                } else {
                    let a = rng.below(6283) as f64 / 1000.0;
                    [centre[0] + r * a.cos(), centre[1] + r * a.sin()]
                };
                at = to;
                format!(
                    "G{} X{} Y{} I{} J{} F{feed}",
                    2 + rng.below(2),
                    num(to[0]),
                    num(to[1]),
                    num(i),
                    num(j)
                )
            }
            10 => {
                // The R form (short or long way) to a point up to 10 mm away.
                let to = [
                    at[0] + rng.below(2001) as f64 / 100.0 - 10.0,
                    at[1] + rng.below(2001) as f64 / 100.0 - 10.0,
                ];
                let chord = (to[0] - at[0]).hypot(to[1] - at[1]);
                let r = chord / 2.0 + 0.5 + rng.below(1000) as f64 / 100.0;
                let sign = if rng.below(2) == 0 { "" } else { "-" };
                at = to;
                format!(
                    "G{} X{} Y{} R{sign}{} F{feed}",
                    2 + rng.below(2),
                    num(to[0]),
                    num(to[1]),
                    num(r)
                )
            }
            11 => {
                let d = [rng.below(11) as f64 - 5.0, rng.below(11) as f64 - 5.0];
                at = [at[0] + d[0], at[1] + d[1]];
                format!("G91 G1 X{} Y{} F{feed}\nG90", num(d[0]), num(d[1]))
            }
            12 | 13 => format!("M{} S{}", [3, 4, 5][rng.below(3) as usize], rng.below(1001)),
            14 => format!("G4 P0.{}", 1 + rng.below(3)),
            15 => format!("@realtime !\nwait {}\n@realtime ~", 100 + rng.below(400)),
            16 => {
                // A sender re-establishes the position with a G0 after a
                // reset (the galvo's first lit motion after one starts
                // from the field centre: reported, not yet fixed).
                let p = point(&mut rng);
                at = p;
                format!(
                    "@realtime 0x18\nwait 200\n$X\nG0 X{} Y{}\nM3 S{}",
                    num(p[0]),
                    num(p[1]),
                    rng.below(1001)
                )
            }
            _ => format!("wait {}", rng.below(800)),
        };
        out.push_str(&line);
        out.push('\n');
    }
    out.push_str("M5\n");
    out
}

fn run_session(target: &str, seed: u64) -> SimReport {
    run_with(
        &session(target, seed),
        SimOptions {
            max_time_ms: 300_000,
            ..SimOptions::default()
        },
    )
}

/// Runs the campaign on `target`: every session keeps every invariant.
fn campaign(target: &str) {
    let mut simulated_s = 0.0;
    for seed in 0..SEEDS {
        let report = run_session(target, seed);
        simulated_s += report.end_time_us as f64 * 1e-6;
        let violations: Vec<_> = check(&report)
            .into_iter()
            .filter(|v| !UNTIL_STEP_FIXES.contains(&v.kind))
            .collect();
        assert!(
            violations.is_empty(),
            "{target} session {seed}:\n{}\n{}",
            session(target, seed),
            report_text(&violations)
        );
        assert!(
            report.transcript.script_done && report.idle_at_end,
            "{target} session {seed} did not finish ({:?}):\n{}",
            report.end,
            session(target, seed)
        );
    }
    eprintln!("{target}: {SEEDS} random G-code sessions, {simulated_s:.1} s simulated");
}

#[test]
fn random_gcode_on_the_gimbal_keeps_every_invariant() {
    campaign("gimbal");
}

#[test]
fn random_gcode_on_the_galvo_keeps_every_invariant() {
    campaign("galvo");
}

#[test]
fn random_gcode_on_the_stepper_keeps_every_invariant() {
    campaign("stepper");
}
