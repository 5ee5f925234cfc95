//! Random campaigns under the safety checker (`laser_sim::safety`): the
//! 1000 random commands of `galvo_sim.rs`, and seeded random sessions
//! mixing stops, the stop button, `model`/`target`/`planner`/`laser`
//! switches, `set`s in the middle of runs, host stalls (`@stall-read`,
//! `@type-ahead`) and servo faults (silent servos, corrupted responses).
//!
//! The campaigns tolerate long task steps (`UNTIL_STEP_FIXES`, host
//! noise); `random_sessions_have_short_task_steps` demands them.

use laser_sim::safety::{check, report_text};
use laser_sim::servo_port::{BusFaults, SilentWindow};
use laser_sim::world::{SimOptions, SimReport};
use system_tests::{
    NOISE_RUNS, UNTIL_STEP_FIXES, XorShift, assert_safe_allowing, random_meaningful_commands,
    run_with, steady_steps,
};

/// Random sessions per campaign.
const SESSIONS: u64 = 24;
/// Command lines per session.
const LINES_PER_SESSION: usize = 150;

/// One random session: faults and a script.
fn random_session(seed: u64) -> (String, SimOptions) {
    let mut rng = XorShift(seed.wrapping_mul(0x9e37_79b9_7f4a_7c15) | 1);
    let faults = random_faults(&mut rng);
    let mut script = String::new();
    for _ in 0..LINES_PER_SESSION {
        script.push_str(&random_line(&mut rng));
        script.push('\n');
    }
    script.push_str("stop\nwait 30\nstatus\n");
    let options = SimOptions {
        faults,
        max_time_ms: 120_000,
        ..SimOptions::default()
    };
    (script, options)
}

/// No fault, a servo silent for good or for a while, or corrupted
/// responses.
fn random_faults(rng: &mut XorShift) -> BusFaults {
    let mut faults = BusFaults::default();
    match rng.below(4) {
        0 => {}
        1 => faults.silent.push(SilentWindow {
            id: rng.below(2) as u8,
            from_ms: 300 + rng.below(6000),
            until_ms: None,
        }),
        2 => {
            let from_ms = 300 + rng.below(6000);
            faults.silent.push(SilentWindow {
                id: rng.below(2) as u8,
                from_ms,
                until_ms: Some(from_ms + 50 + rng.below(1500)),
            });
        }
        _ => faults.corrupt_probability = [0.002, 0.01, 0.03][rng.below(3) as usize],
    }
    faults
}

/// One random command line (or script directive) of a session.
fn random_line(rng: &mut XorShift) -> String {
    let r = rng.next_u64();
    match rng.below(32) {
        0 => ["target galvo", "target gimbal", "target both"][(r % 3) as usize].to_owned(),
        1 => format!("planner {}", ["optimal", "seed"][(r % 2) as usize]),
        2 => format!("model {}", ["exact", "seed"][(r % 2) as usize]),
        3 => format!(
            "laser {}",
            ["auto", "dwell", "on", "dwell"][(r % 4) as usize]
        ),
        4 | 5 => format!(
            "pattern {}{}",
            ["corner", "home", "horizontal", "vertical", "visit-all"][(r % 5) as usize],
            if r.is_multiple_of(3) { "" } else { " once" }
        ),
        6 => format!(
            "pattern line {} {} {} {}{}",
            (r % 9) as f64 - 4.5,
            (r % 7) as f64 - 3.0,
            ((r >> 8) % 9) as f64 - 4.0,
            ((r >> 16) % 7) as f64 - 3.5,
            if r.is_multiple_of(2) { " once" } else { "" }
        ),
        7 => format!(
            "pattern circle {} {} 2.5 ccw once",
            (r % 5) as f64 - 2.0,
            1.0
        ),
        8 => "pattern rect -4 3 4 -3 once".to_owned(),
        9 => "pattern tuning 1 -1 5 once".to_owned(),
        10 => format!(
            "goto {} {}",
            (r % 17) as f64 - 8.0,
            ((r >> 8) % 11) as f64 - 5.0
        ),
        11 => format!("grid {} {}", (r % 13) as i64 - 6, ((r >> 8) % 9) as i64 - 4),
        12 | 13 => "stop".to_owned(),
        14 => "@button".to_owned(),
        15 => format!("set dwell_ms {}", r % 150),
        16 => format!("set servo.speed_deg_s {}", 60 + r % 300),
        17 => format!(
            "set servo.deadband_deg {}",
            [0.3, 0.5, 1.0][(r % 3) as usize]
        ),
        18 => format!("set path.step_cm {}", [0.1, 0.2, 0.4][(r % 3) as usize]),
        19 => format!("set galvo.mark_speed_mm_s {}", 200 + r % 4000),
        20 => format!(
            "set galvo.laser_{}_delay_us {}",
            ["on", "off"][(r % 2) as usize],
            (r >> 8) % 400
        ),
        21 => format!("set galvo.ts_us {}", [10, 10, 20][(r % 3) as usize]),
        22 => ["status", "galvo status", "params"][(r % 3) as usize].to_owned(),
        // The host stops reading for up to 3 s; the script goes on.
        23 => format!("@stall-read {}", 100 + r % 3000),
        24 => format!(
            "@type-ahead {}",
            ["params", "status", "stop"][(r % 3) as usize]
        ),
        // Waits of up to 0.6 s (a sixth of the lines) let runs go on.
        _ => format!("wait {}", r % 600),
    }
}

fn run_session(seed: u64) -> SimReport {
    let (script, options) = random_session(seed);
    let report = run_with(&script, options);
    assert!(
        report.transcript.script_done,
        "session {seed}: the script did not finish"
    );
    report
}

#[test]
fn thousand_random_commands_are_safe() {
    let report = run_with(&random_meaningful_commands(), SimOptions::default());
    assert!(report.transcript.script_done);
    assert_safe_allowing(&report, UNTIL_STEP_FIXES);
}

#[test]
fn random_sessions_with_faults_and_stalls_are_safe() {
    let wall = std::time::Instant::now();
    let mut simulated_us = 0;
    for seed in 0..SESSIONS {
        let report = run_session(seed);
        simulated_us += report.end_time_us;
        let violations: Vec<_> = check(&report)
            .into_iter()
            .filter(|v| !UNTIL_STEP_FIXES.contains(&v.kind))
            .collect();
        assert!(
            violations.is_empty(),
            "session {seed} ({:?}):\n{}",
            random_session(seed).0,
            report_text(&violations)
        );
    }
    eprintln!(
        "{SESSIONS} random sessions: {:.1} s simulated in {:.2} s wall",
        simulated_us as f64 * 1e-6,
        wall.elapsed().as_secs_f64()
    );
}

#[test]
fn random_sessions_have_short_task_steps() {
    for seed in 0..SESSIONS {
        // A long step must recur in every run (see `steady_steps`).
        let violations = check(&steady_steps(|| run_session(seed)));
        assert!(
            violations.is_empty(),
            "session {seed}, in each of {NOISE_RUNS} runs:\n{}",
            report_text(&violations)
        );
    }
}
