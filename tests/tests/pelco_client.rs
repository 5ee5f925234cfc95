//! A real PELCO client from PyPI — `pyptzcontroller` 0.1.2 over pyserial
//! 3.5 — drives the simulator's PELCO port on its PTY (`cargo xtask sim
//! --pelco-pty`, here in-process), in PELCO-D (the library's own protocol
//! table) and PELCO-P (its frame given to the library as a protocol
//! table): home, pan and tilt at several speeds each ended by a stop,
//! absolute positions with position queries, preset set / call / clear
//! (`tests/senders/ptz_pty.py`), on the gimbal.
//!
//! Measured in the simulator's time, from its record of the port's
//! traffic (when the firmware read each frame, when it wrote each reply)
//! and of the spot, so the host's load changes nothing but the windows'
//! lengths:
//! * the line-of-sight rate of each move equals the speed table's within
//!   2 % (least-squares slope over the steady part of the move);
//! * after each stop frame the spot is at rest within one jog lead
//!   (`LEAD_MS`, the jogs queued ahead, which the jog cancel drops) plus
//!   the gimbal's braking and the servos' last 20 ms step;
//! * the query replies the library decodes equal the angles of the point
//!   the firmware aimed at (its dwell record) within 0.01°, and the
//!   physical spot is within the servos' 0.1° of them;
//! * absolute positions and the preset recall land within 0.1°; a
//!   cleared preset does not move the spot;
//! * `pelco status` counts every frame, no bad checksum.
//!
//! The library is installed into a private directory when missing
//! (`target/senders/ptz`); real time and the first install need the
//! network, so the test is `#[ignore]`d like the G-code senders and run
//! by `cargo xtask senders`.

use std::io::{BufRead, BufReader, Write};
use std::path::{Path, PathBuf};
use std::process::Command;

use laser_app::domain::PointCm;
use laser_app::pelco::session::LEAD_MS;
use laser_app::pelco::sight::angles_deg;
use laser_app::pelco::speed::rate_deg_s;
use laser_sim::on_pty::SimOnPty;
use laser_sim::pelco_port::PelcoPtyOptions;
use laser_sim::world::{SimOptions, SimReport};
use pelco::{Command as Pelco, Decoder, Frame, PanDirection, TiltDirection};

const REPO: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/..");
/// The client, pinned (MIT), and the serial library it imports.
const PY_PACKAGES: &[&str] = &["pyptzcontroller==0.1.2", "pyserial==3.5"];
/// Largest error of a measured rate, relative.
const RATE_TOLERANCE: f64 = 0.02;
/// The part of a move left out of its rate (the gimbal's speed-up and
/// the first jog's start), µs.
const RAMP_US: u64 = 300_000;
/// Query replies against the aimed point, deg (the wire's resolution).
const REPLY_TOLERANCE_DEG: f64 = 0.01;
/// The gimbal's resolution: the servos' 0.1°.
const GIMBAL_RESOLUTION_DEG: f64 = 0.1;
/// The gimbal's last servo step after braking, µs (one stream period).
const SERVO_STEP_US: u64 = 20_000;

/// Installs the client when missing; its directory.
fn installed() -> PathBuf {
    let dir = Path::new(REPO).join("target/senders/ptz");
    let ready = ["ptz_control_lib", "serial"];
    if !ready.iter().all(|m| dir.join(m).is_dir()) {
        std::fs::create_dir_all(&dir).unwrap();
        let pip = ["-m", "pip", "install", "--quiet", "--target", "."];
        let status = Command::new("python3")
            .args([&pip[..], PY_PACKAGES].concat())
            .current_dir(&dir)
            .status()
            .expect("python3 runs");
        assert!(status.success(), "pip install {PY_PACKAGES:?} failed");
    }
    dir
}

/// Types `line` on the console and returns its reply lines up to `ok`.
fn console(link: &Path, line: &str) -> Vec<String> {
    let mut port = std::fs::OpenOptions::new()
        .read(true)
        .write(true)
        .open(link)
        .expect("open the console PTY");
    port.write_all(format!("{line}\r\n").as_bytes()).unwrap();
    let mut reader = BufReader::new(port);
    let mut lines = Vec::new();
    loop {
        let mut reply = String::new();
        reader.read_line(&mut reply).unwrap();
        let reply = reply.trim_end().to_owned();
        if reply == "ok" || reply.starts_with("error") {
            assert_eq!(reply, "ok", "{line}: {lines:?}");
            return lines;
        }
        lines.push(reply);
    }
}

/// One session of the client in `dialect` (`D` or `P`): the report, the
/// positions the library decoded, and `pelco status`.
fn drive(dialect: &str) -> (SimReport, Vec<[f64; 2]>, Vec<String>) {
    let dir = installed();
    laser_sim::logger::init("warn".parse().unwrap());
    let work = std::env::temp_dir().join(format!("pelco-client-{}-{dialect}", std::process::id()));
    std::fs::create_dir_all(&work).unwrap();
    let pelco_link = work.join("pelco");
    let sim = SimOnPty::start(
        work.join("console"),
        SimOptions {
            max_time_ms: 300_000,
            pelco_pty: Some(PelcoPtyOptions {
                link: Some(pelco_link.clone()),
            }),
            ..SimOptions::default()
        },
    )
    .expect("the simulator starts");
    let out = Command::new("python3")
        .arg(Path::new(REPO).join("tests/senders/ptz_pty.py"))
        .arg(&pelco_link)
        .arg(dialect)
        .env("PYTHONPATH", &dir)
        .output()
        .expect("the client runs");
    let status = console(&sim.link, "pelco status");
    let report = sim.finish();
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "PELCO-{dialect} client failed: {stdout}\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let json: serde_json::Value =
        serde_json::from_str(stdout.lines().last().unwrap_or("")).expect("one JSON line");
    let positions = json["positions"]
        .as_array()
        .expect("positions")
        .iter()
        .map(|p| {
            let angle = |i: usize| p[i].as_f64().unwrap_or(f64::NAN);
            [angle(0), angle(1)]
        })
        .collect();
    (report, positions, status)
}

/// The frames the firmware read, each at the time it read it, µs.
fn frames_read(report: &SimReport) -> Vec<(u64, Frame)> {
    let mut decoder = Decoder::new(1);
    let mut frames = Vec::new();
    for (t, bytes) in &report.pelco.received {
        decoder.decode(bytes, |f| frames.push((*t, f)));
    }
    frames
}

/// `(t µs, [pan, tilt] deg)` of the spot.
fn spot_angles(report: &SimReport, oq_cm: f64) -> Vec<(u64, [f64; 2])> {
    report
        .recording
        .spot
        .iter()
        .map(|s| (s.t_us, angles_deg(PointCm::new(s.x_cm, s.y_cm), oq_cm)))
        .collect()
}

/// Least-squares slope of `axis` over `samples` in `[from, to]`, deg/s.
fn slope(samples: &[(u64, [f64; 2])], axis: usize, from: u64, to: u64) -> f64 {
    let window: Vec<(f64, f64)> = samples
        .iter()
        .filter(|(t, _)| (from..=to).contains(t))
        .map(|(t, a)| (*t as f64 / 1e6, a[axis]))
        .collect();
    assert!(window.len() > 20, "{} samples in the window", window.len());
    let n = window.len() as f64;
    let (mt, ma) = window
        .iter()
        .fold((0.0, 0.0), |(st, sa), (t, a)| (st + t / n, sa + a / n));
    let (num, den) = window.iter().fold((0.0, 0.0), |(num, den), (t, a)| {
        (num + (t - mt) * (a - ma), den + (t - mt) * (t - mt))
    });
    num / den
}

/// The spot's angles at `t_us` (the last sample at or before it).
fn angles_at(samples: &[(u64, [f64; 2])], t_us: u64) -> [f64; 2] {
    samples
        .iter()
        .rev()
        .find(|(t, _)| *t <= t_us)
        .map(|(_, a)| *a)
        .expect("a spot sample")
}

/// When the spot came to rest after `from_us` (the last sample that
/// differs from its position at `until_us`), µs.
fn at_rest_after(samples: &[(u64, [f64; 2])], from_us: u64, until_us: u64) -> u64 {
    let end = angles_at(samples, until_us);
    samples
        .iter()
        .rev()
        .filter(|(t, _)| (from_us..=until_us).contains(t))
        .find(|(_, a)| (a[0] - end[0]).abs() > 1e-6 || (a[1] - end[1]).abs() > 1e-6)
        .map(|(t, _)| *t)
        .unwrap_or(from_us)
}

/// Checks the moves' rates and the stops; returns the worst rate error.
fn check_moves(label: &str, frames: &[(u64, Frame)], spot: &[(u64, [f64; 2])]) -> f64 {
    let mut worst: f64 = 0.0;
    let mut moves = 0;
    for pair in frames.windows(3) {
        let [(t_move, f), (t_stop, stop), (t_next, _)] = pair else {
            continue;
        };
        let (Pelco::Motion(m), Pelco::Motion(s)) = (Pelco::of(f), Pelco::of(stop)) else {
            continue;
        };
        if m.is_stop() || !s.is_stop() {
            continue;
        }
        moves += 1;
        let (axis, expected) = match (m.pan, m.tilt) {
            (PanDirection::Right, _) => (0, f64::from(rate_deg_s(m.pan_speed))),
            (PanDirection::Left, _) => (0, -f64::from(rate_deg_s(m.pan_speed))),
            (_, TiltDirection::Up) => (1, f64::from(rate_deg_s(m.tilt_speed))),
            (_, TiltDirection::Down) => (1, -f64::from(rate_deg_s(m.tilt_speed))),
            _ => unreachable!("a move moves"),
        };
        let rate = slope(spot, axis, t_move + RAMP_US, *t_stop);
        let error = (rate - expected).abs() / expected.abs();
        worst = worst.max(error);
        // At rest: the jogs queued ahead are cancelled; the gimbal brakes.
        let rest_us = at_rest_after(spot, *t_stop, t_next.saturating_sub(1000));
        let stop_us = rest_us.saturating_sub(*t_stop);
        let speed = rate.abs();
        eprintln!(
            "{label}: {} at {:.2} deg/s (table {expected:+.2}, {:+.2} %), at rest {:.0} ms after the stop",
            ["pan", "tilt"][axis],
            rate,
            100.0 * (rate - expected) / expected.abs(),
            stop_us as f64 / 1e3
        );
        if error > RATE_TOLERANCE {
            let around: Vec<_> = spot
                .iter()
                .filter(|(t, _)| (t_move.saturating_sub(50_000)..=*t_stop + 50_000).contains(t))
                .step_by(10)
                .collect();
            eprintln!("DIAG move {t_move} stop {t_stop} next {t_next}: {around:?}");
        }
        assert!(
            error <= RATE_TOLERANCE,
            "{label}: rate {rate} vs {expected}"
        );
        let braking_us = braking_us(speed);
        assert!(
            stop_us <= LEAD_MS * 1000 + braking_us + SERVO_STEP_US,
            "{label}: at rest {stop_us} µs after the stop (braking {braking_us} µs)"
        );
    }
    assert_eq!(moves, 6, "{label}: the six timed moves");
    worst
}

/// The gimbal's joint acceleration in its G-code stream, deg/s²
/// (`sequencer::drivers::gimbal::GIMBAL_ACCEL_DEG_S2`).
const GIMBAL_ACCEL_DEG_S2: f64 = 2000.0;

/// How long the gimbal brakes from `deg_s` (joint and line of sight
/// nearly agree near the board's centre), µs.
fn braking_us(deg_s: f64) -> u64 {
    (1e6 * deg_s / GIMBAL_ACCEL_DEG_S2) as u64
}

fn check_session(dialect: &str) {
    let label = format!("PELCO-{dialect}");
    let oq_cm = laser_app::settings::Settings::default().oq_cm;
    let (report, positions, status) = drive(dialect);
    let frames = frames_read(&report);
    let spot = spot_angles(&report, oq_cm);
    let worst = check_moves(&label, &frames, &spot);
    eprintln!("{label}: worst rate error {:.2} %", 100.0 * worst);

    // `pelco status`: every frame counted, none bad.
    let counts = status
        .iter()
        .find(|l| l.starts_with("frames"))
        .expect("a counts line");
    assert!(
        counts.starts_with(&format!("frames {} bad_checksums 0 ", frames.len())),
        "{label}: {status:?}"
    );

    // Where the firmware aimed (its dwell records) at each reply.
    let replies: Vec<u64> = report
        .pelco
        .sent
        .iter()
        .map(|(t, _)| *t)
        .collect::<Vec<_>>()
        .chunks(2)
        .map(|c| c[0])
        .collect();
    assert_eq!(
        replies.len(),
        positions.len(),
        "{label}: two replies a query"
    );
    let aimed = |t: u64| {
        let d = report
            .recording
            .dwells
            .iter()
            .rev()
            .find(|d| d.t_us <= t)
            .expect("a dwell before the query");
        angles_deg(PointCm::new(d.target_cm.0, d.target_cm.1), oq_cm)
    };
    // The library reads pan 0–360.
    let decoded = |p: [f64; 2]| [if p[0] > 180.0 { p[0] - 360.0 } else { p[0] }, p[1]];
    let asked = [[8.0, -6.0], [-8.5, 4.25], [-8.5, 4.25], [0.0, 0.0]];
    for ((t, p), want) in replies.iter().zip(&positions).zip(asked) {
        let (got, at, spot_now) = (decoded(*p), aimed(*t), angles_at(&spot, *t));
        eprintln!("{label}: asked {want:?}, reply {got:?}, aimed {at:.4?}, spot {spot_now:.4?}");
        for axis in 0..2 {
            assert!(
                (got[axis] - at[axis]).abs() <= REPLY_TOLERANCE_DEG + 1e-9,
                "{label}: reply {got:?} vs aimed {at:?}"
            );
            assert!(
                (at[axis] - want[axis]).abs() <= GIMBAL_RESOLUTION_DEG,
                "{label}: aimed {at:?} for {want:?}"
            );
            assert!(
                (spot_now[axis] - want[axis]).abs() <= GIMBAL_RESOLUTION_DEG,
                "{label}: spot {spot_now:?} for {want:?}"
            );
        }
    }
}

#[test]
#[ignore = "real time, installs PyPI packages: cargo xtask senders"]
fn pyptzcontroller_drives_the_simulator_in_pelco_d() {
    check_session("D");
}

#[test]
#[ignore = "real time, installs PyPI packages: cargo xtask senders"]
fn pyptzcontroller_drives_the_simulator_in_pelco_p() {
    check_session("P");
}
