//! Servo faults end to end (issue 9, defects 6 and 10): a servo known dead
//! gets no lit run and no command that needs it is accepted until it
//! answers again; corrupted angle readings that pass the checksum never
//! declare an arrival.

use fashionstar::{Response, ResponseDecoder};
use laser_sim::recorder::Direction;
use laser_sim::servo_port::{BusFaults, SilentWindow};
use laser_sim::world::{SimOptions, SimReport};
use system_tests::{XorShift, commanded_at, notice_at, run_with};

/// Commands that move the gimbal when it is the target.
fn needs_gimbal(line: &str) -> bool {
    ["goto ", "grid ", "pattern "]
        .iter()
        .any(|p| line.starts_with(p))
}

/// A random command line (gimbal moves, laser modes, targets, stops).
fn random_command(rng: &mut XorShift) -> String {
    match rng.below(12) {
        0..=2 => format!(
            "goto {} {}",
            rng.below(17) as i64 - 8,
            rng.below(11) as i64 - 5
        ),
        3 => format!(
            "grid {} {}",
            rng.below(13) as i64 - 6,
            rng.below(9) as i64 - 4
        ),
        4..=5 => rng
            .pick(&[
                "pattern corner",
                "pattern visit-all once",
                "pattern horizontal",
                "pattern line -5 0 5 2 once",
                "pattern circle 0 0 4 once",
            ])
            .to_owned(),
        6 => rng.pick(&["stop", "status"]).to_owned(),
        7 => rng.pick(&["laser auto", "laser dwell"]).to_owned(),
        8 => rng.pick(&["model seed", "model exact"]).to_owned(),
        9 => rng
            .pick(&["target gimbal", "target galvo", "target both"])
            .to_owned(),
        10 => rng
            .pick(&["set dwell_ms 50", "set dwell_ms 300"])
            .to_owned(),
        _ => format!("wait {}", 20 + rng.below(400)),
    }
}

/// Each sent line with its send time and closing reply.
fn replies(report: &SimReport) -> Vec<(u64, String, String)> {
    let lines = &report.transcript.lines;
    let mut out = Vec::new();
    for (i, (t, line)) in lines.iter().enumerate() {
        let Some(cmd) = line.strip_prefix("> ") else {
            continue;
        };
        let reply = lines[i + 1..]
            .iter()
            .map(|(_, l)| l)
            .find(|l| *l == "ok" || l.starts_with("error:"))
            .cloned()
            .unwrap_or_default();
        out.push((*t, cmd.to_owned(), reply));
    }
    out
}

/// Time the gimbal laser was on within `[from, to)`, µs.
fn lit_us(report: &SimReport, from: u64, to: u64) -> u64 {
    let mut on_since: Option<u64> = None;
    let mut total = 0;
    for &(t, on) in &report.recording.laser_events {
        let t = t.clamp(from, to);
        match (on, on_since) {
            (true, None) => on_since = Some(t),
            (false, Some(s)) => {
                total += t - s;
                on_since = None;
            }
            _ => {}
        }
    }
    if let Some(s) = on_since {
        total += to - s.min(to);
    }
    total
}

/// Runs a random campaign with servo `id` silent from 1.5 s until
/// `silent_until_ms`; returns the report and the script.
fn campaign(id: u8, seed: u64, silent_until_ms: u64) -> (SimReport, String) {
    let mut rng = XorShift(seed);
    let mut script = String::from("set dwell_ms 100\npattern corner\nwait 2000\n");
    for _ in 0..30 {
        script.push_str(&random_command(&mut rng));
        script.push('\n');
    }
    // After the servo answers again (pinged every 500 ms): the gimbal
    // works again.
    let quiet = silent_until_ms.saturating_sub(1500) + 1200;
    script.push_str(&format!(
        "wait {quiet}\ntarget gimbal\nlaser auto\npattern corner once\n"
    ));
    let options = SimOptions {
        faults: BusFaults {
            silent: vec![SilentWindow {
                id,
                from_ms: 1500,
                until_ms: Some(silent_until_ms),
            }],
            ..BusFaults::default()
        },
        ..SimOptions::default()
    };
    (run_with(&script, options), script)
}

#[test]
fn a_dead_servo_gets_no_lit_run_and_refuses_gimbal_commands_until_it_answers() {
    let mut checked_refusals = 0;
    let mut checked_galvo = 0;
    for id in [0u8, 1] {
        for seed in 1..=4u64 {
            let silent_until = 3_500 + 700 * seed;
            let (report, script) = campaign(id, seed * 0x9e37_79b9 + u64::from(id), silent_until);
            let ctx = format!("servo {id} seed {seed}\n{script}");
            assert!(report.transcript.script_done, "{ctx}");
            let fault = notice_at(&report, &format!("[error: servo {id} fault"))
                .unwrap_or_else(|| panic!("no fault notice: {ctx}"));
            let recovered = notice_at(&report, &format!("[info: servo {id} answering again"))
                .unwrap_or_else(|| panic!("no recovery notice: {ctx}"));
            assert!(fault < 1_700_000, "fault found at {fault} µs: {ctx}");
            assert!(recovered >= silent_until * 1000, "{ctx}");
            // No light while the servo is known dead.
            assert_eq!(
                lit_us(&report, fault, recovered),
                0,
                "laser lit while servo {id} was known dead: {:?}\n{ctx}",
                report.recording.laser_events
            );
            assert!(
                report
                    .recording
                    .spot
                    .iter()
                    .filter(|s| s.t_us > fault && s.t_us < recovered)
                    .all(|s| !s.laser),
                "{ctx}"
            );
            // Every command that needs the gimbal was refused, naming the
            // servo and how to recover; galvo-only runs were accepted.
            let mut actuator = "gimbal";
            for (t, cmd, reply) in replies(&report) {
                if let Some(a) = cmd.strip_prefix("target ")
                    && reply == "ok"
                {
                    actuator = if a == "galvo" { "galvo" } else { "gimbal" };
                }
                if t <= fault || t >= recovered || !needs_gimbal(&cmd) {
                    continue;
                }
                if actuator == "gimbal" {
                    assert!(
                        reply.starts_with(&format!("error: servo {id} not responding"))
                            && reply.contains("answering again"),
                        "{cmd:?} at {t} µs got {reply:?}: {ctx}"
                    );
                    checked_refusals += 1;
                } else {
                    assert_eq!(reply, "ok", "galvo-only {cmd:?} at {t} µs: {ctx}");
                    checked_galvo += 1;
                }
            }
            // After the recovery the gimbal runs again, dark until its
            // first arrival is confirmed.
            let last = replies(&report).pop().unwrap();
            assert_eq!(
                (last.1.as_str(), last.2.as_str()),
                ("pattern corner once", "ok"),
                "{ctx}"
            );
            let first_dwell = report
                .recording
                .dwells
                .iter()
                .find(|d| d.t_us > last.0)
                .unwrap_or_else(|| panic!("no arrival after recovery: {ctx}"));
            let first_on = report
                .recording
                .laser_events
                .iter()
                .find(|&&(t, on)| on && t > recovered)
                .unwrap_or_else(|| panic!("never lit after recovery: {ctx}"));
            assert!(
                first_on.0 + 2_000 >= first_dwell.t_us,
                "lit at {} µs before the first arrival at {} µs: {ctx}",
                first_on.0,
                first_dwell.t_us
            );
        }
    }
    assert!(
        checked_refusals >= 20,
        "{checked_refusals} refusals checked"
    );
    assert!(
        checked_galvo >= 1,
        "{checked_galvo} galvo-only runs checked"
    );
}

/// The last angle response of servo `id` before `t_us`: (time, angle as
/// received, angle as the servo sent it).
fn last_reading(report: &SimReport, id: u8, t_us: u64) -> Option<(u64, i16, i16)> {
    let decode = |bytes: &[u8]| {
        let mut d = ResponseDecoder::new();
        bytes.iter().find_map(|&b| match d.feed(b) {
            Some(Ok(Response::Angle {
                id: got,
                angle_tenths_deg,
            })) if got == id => Some(angle_tenths_deg),
            _ => None,
        })
    };
    report
        .recording
        .frames
        .iter()
        .filter(|f| f.direction == Direction::Rx && f.t_us < t_us)
        .filter_map(|f| {
            let received = decode(&f.bytes)?;
            let sent = report
                .recording
                .clean_rx
                .iter()
                .find(|c| c.t_us == f.t_us && c.received == f.bytes)
                .map_or(Some(received), |c| decode(&c.sent))?;
            Some((f.t_us, received, sent))
        })
        .next_back()
}

/// Runs 100 random short gotos per seed with the given bus faults and
/// checks every declared arrival against what the servos really sent.
/// Returns (arrivals checked, corrupted frames that passed the checksum,
/// readings the firmware rejected as implausible per its `status`).
fn arrivals_on_real_readings_only(faults: impl Fn(u64) -> BusFaults) -> (usize, usize, u64) {
    let mut passed_checksum = 0;
    let mut dwells = 0;
    let mut rejected = 0;
    for seed in 1..=12u64 {
        let options = SimOptions {
            faults: faults(seed),
            ..SimOptions::default()
        };
        // At 10 % of bytes corrupted many queries fail three times (a
        // NoResponse fault, refused commands until the servo answers a
        // ping again): many short gotos give many arrivals anyway.
        let mut rng = XorShift(seed.wrapping_mul(0x9e37_79b9_7f4a_7c15));
        let mut script = String::from("set dwell_ms 20\n");
        for _ in 0..100 {
            script.push_str(&format!(
                "grid {} {}\nwait 400\n",
                rng.below(13) as i64 - 6,
                rng.below(9) as i64 - 4
            ));
        }
        script.push_str("status\n");
        let report = run_with(&script, options);
        rejected += report
            .transcript
            .lines
            .iter()
            .rev()
            .find_map(|(_, l)| l.strip_prefix("servo readings rejected as implausible: "))
            .and_then(|n| n.parse::<u64>().ok())
            .expect("status counts rejected readings");
        // Frames that were corrupted on the wire yet decode as a valid
        // angle response with another angle.
        for c in &report.recording.clean_rx {
            let angle = |bytes: &[u8]| {
                let mut d = ResponseDecoder::new();
                bytes.iter().find_map(|&b| match d.feed(b) {
                    Some(Ok(Response::Angle {
                        angle_tenths_deg, ..
                    })) => Some(angle_tenths_deg),
                    _ => None,
                })
            };
            if let (Some(a), Some(b)) = (angle(&c.received), angle(&c.sent))
                && a != b
            {
                passed_checksum += 1;
            }
        }
        // At every declared arrival, the readings it was declared on are
        // what the servos really sent, inside the deadband of the target.
        for d in &report.recording.dwells {
            dwells += 1;
            for (id, target) in commanded_at(&report, d.t_us) {
                let (t, received, sent) = last_reading(&report, id, d.t_us)
                    .unwrap_or_else(|| panic!("no reading before the arrival at {}", d.t_us));
                assert!(
                    (i32::from(sent) - i32::from(target)).abs() <= 5,
                    "seed {seed}: arrival at {} µs on servo {id} reading {received} \
                     (sent {sent}, at {t} µs), target {target}",
                    d.t_us
                );
            }
        }
    }
    (dwells, passed_checksum, rejected)
}

#[test]
fn at_ten_percent_byte_corruption_no_arrival_is_declared_on_a_corrupted_reading() {
    let (dwells, passed, _) = arrivals_on_real_readings_only(|seed| BusFaults {
        corrupt_probability: 0.1,
        seed: seed.wrapping_mul(0x2545_f491),
        ..BusFaults::default()
    });
    eprintln!("{dwells} arrivals checked, {passed} corrupted frames passed the checksum");
    assert!(dwells >= 50, "{dwells} arrivals checked");
    assert!(
        passed >= 1,
        "the campaign must contain corrupted frames that pass the checksum"
    );
}

#[test]
fn wrong_angles_the_checksum_cannot_catch_never_declare_an_arrival() {
    // One angle response in five is wrong with a valid checksum.
    let (dwells, passed, rejected) = arrivals_on_real_readings_only(|seed| BusFaults {
        forge_probability: 0.2,
        seed: seed.wrapping_mul(0x2545_f491),
        ..BusFaults::default()
    });
    eprintln!("{dwells} arrivals checked, {passed} forged frames, {rejected} rejected");
    assert!(
        rejected >= 100,
        "{rejected} readings rejected as implausible"
    );
    assert!(dwells >= 300, "{dwells} arrivals checked");
    assert!(passed >= 1_000, "{passed} forged frames");
}
