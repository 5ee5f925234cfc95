//! Real G-code senders from the ecosystem stream a laser job to the
//! simulator through its PTY console (`cargo xtask sim --pty` in-process):
//! `grbl-streamer` (PyPI, the gerbil interface, character counting, `?`
//! every 0.2 s) and `pygrbl-streamer` (PyPI, character counting; the
//! driver polls `?` at 5 Hz). The senders are installed with pip into a
//! private directory when missing (`target/senders/py`). The drawn path
//! must match the job's toolpath, every `?` must be answered, no error.
//!
//! Real time and network (the first install): not in `cargo xtask test`;
//! `cargo xtask senders` runs them (`--ignored`).

use std::io::{BufRead, BufReader, Write};
use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

use kinematics_core::Galvo;
use laser_sim::pty::PtyOptions;
use laser_sim::world::{SimOptions, SimReport, run};
use system_tests::gcode_job::{Job, fit, laser_job};

const REPO: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/..");
/// Versions the tests were written against.
const PACKAGES: &[&str] = &[
    "grbl-streamer==2.0.2",
    "pygrbl-streamer==1.0.5",
    "pyserial==3.5",
];

/// The private directory the senders are installed in (installed now if
/// missing).
fn senders_dir() -> PathBuf {
    let dir = Path::new(REPO).join("target/senders/py");
    let have = |m: &str| dir.join(m).is_dir();
    if !(have("grbl_streamer") && have("pygrbl_streamer") && have("serial")) {
        let status = Command::new("python3")
            .args(["-m", "pip", "install", "--quiet", "--target"])
            .arg(&dir)
            .args(PACKAGES)
            .status()
            .expect("python3 runs");
        assert!(status.success(), "pip install {PACKAGES:?} failed");
    }
    dir
}

/// What a sender driver printed.
struct Summary {
    json: serde_json::Value,
}

impl Summary {
    fn count(&self, key: &str) -> u64 {
        self.json[key].as_u64().unwrap_or(0)
    }
}

/// Types one product command on the console (e.g. `target galvo`).
fn type_command(link: &Path, line: &str) {
    let mut port = std::fs::OpenOptions::new()
        .read(true)
        .write(true)
        .open(link)
        .expect("open the PTY");
    port.write_all(format!("{line}\r\n").as_bytes()).unwrap();
    let mut reader = BufReader::new(port);
    loop {
        let mut reply = String::new();
        reader.read_line(&mut reply).unwrap();
        let reply = reply.trim_end();
        if reply == "ok" || reply.starts_with("error") {
            assert_eq!(reply, "ok", "{line}");
            return;
        }
    }
}

/// Runs the simulator with its console on a PTY, `prepare` typed first,
/// then `driver` streaming `job`; the report and the driver's summary.
fn stream(driver: &str, prepare: &[&str], job: &Job) -> (SimReport, Summary) {
    let dir = senders_dir();
    let work = std::env::temp_dir().join(format!("gcode-senders-{}-{driver}", std::process::id()));
    std::fs::create_dir_all(&work).unwrap();
    let link = work.join("pty");
    let file = work.join("job.gcode");
    std::fs::write(&file, job.text()).unwrap();
    let stop = Arc::new(AtomicBool::new(false));
    let options = SimOptions {
        pty: Some(PtyOptions {
            link: Some(link.clone()),
            stop: stop.clone(),
        }),
        realtime: true,
        max_time_ms: 400_000,
        ..SimOptions::default()
    };
    let _ = std::fs::remove_file(&link);
    let sim = std::thread::spawn(move || run(options));
    let started = Instant::now();
    while !link.exists() {
        assert!(started.elapsed() < Duration::from_secs(20), "no PTY");
        std::thread::sleep(Duration::from_millis(10));
    }
    for line in prepare {
        type_command(&link, line);
    }
    let output = Command::new("python3")
        .arg(Path::new(REPO).join("tests/senders").join(driver))
        .arg(&link)
        .arg(&file)
        .env("PYTHONPATH", &dir)
        .output()
        .expect("the sender runs");
    stop.store(true, Ordering::Relaxed);
    let report = sim.join().expect("the simulator ends");
    let stdout = String::from_utf8_lossy(&output.stdout);
    assert!(
        output.status.success(),
        "{driver} failed: {stdout}\n{}",
        String::from_utf8_lossy(&output.stderr)
    );
    let json = serde_json::from_str(stdout.lines().last().unwrap_or(""))
        .unwrap_or_else(|e| panic!("{driver} printed {stdout:?}: {e}"));
    (report, Summary { json })
}

fn check_sender(label: &str, summary: &Summary, report: &SimReport, job: &Job) {
    eprintln!("{label}: {}", summary.json);
    assert_eq!(summary.json["completed"], true, "{label}");
    assert_eq!(summary.json["errors"], serde_json::json!([]), "{label}");
    assert_eq!(summary.json["alarms"], serde_json::json!([]), "{label}");
    let seconds = summary.json["seconds"].as_f64().unwrap_or(0.0);
    let (polls, statuses) = (summary.count("polls"), summary.count("statuses"));
    assert!(
        polls as f64 >= 4.0 * seconds,
        "{label}: {polls} polls in {seconds:.1} s"
    );
    assert_eq!(statuses, polls, "{label}: every `?` answered");
    let lines = job.lines.len() as f64;
    eprintln!(
        "{label}: {} lines in {seconds:.1} s ({:.1} lines/s, motion-bound)",
        job.lines.len(),
        lines / seconds
    );
    let errors: Vec<_> = report
        .transcript
        .lines
        .iter()
        .filter(|(_, l)| l.starts_with("error") || l.starts_with("ALARM"))
        .collect();
    assert!(errors.is_empty(), "{label}: {errors:?}");
}

#[test]
#[ignore = "real time, installs PyPI packages: cargo xtask senders"]
fn grbl_streamer_draws_the_job_on_the_gimbal() {
    let job = laser_job(40.0);
    let (report, summary) = stream("stream_grbl_streamer.py", &[], &job);
    // Every G-code line the sender wrote reached the console.
    let received = system_tests::terminal_lines(&report)
        .iter()
        .filter(|l| l.starts_with("> G"))
        .count() as u64;
    assert_eq!(received, summary.count("g_lines_written"), "lines lost");
    check_sender("grbl-streamer (gimbal)", &summary, &report, &job);
    let lit: Vec<[f64; 2]> = report
        .recording
        .spot
        .iter()
        .filter(|s| s.laser)
        .map(|s| [s.x_cm * 10.0, s.y_cm * 10.0])
        .collect();
    let fit = fit(&lit, &job.pieces);
    eprintln!(
        "grbl-streamer (gimbal): {fit:?}, worst piece {:?}",
        job.pieces[fit.worst_piece]
    );
    assert!(fit.worst_lit_mm <= 0.45, "{fit:?}");
    assert!(fit.worst_missed_mm <= 1.5, "{fit:?}");
}

#[test]
#[ignore = "real time, installs PyPI packages: cargo xtask senders"]
fn pygrbl_streamer_draws_the_job_on_the_galvo() {
    let job = laser_job(25.0);
    let (report, summary) = stream("stream_pygrbl.py", &["target galvo"], &job);
    check_sender("pygrbl-streamer (galvo)", &summary, &report, &job);
    let galvo = Galvo::<f64>::default();
    let lit: Vec<[f64; 2]> = report
        .dac
        .iter()
        .filter(|(_, s)| s.laser)
        .filter_map(|(_, s)| galvo.codes_to_board(s.x_code, s.y_code).ok())
        .map(|p| [p.x_mm, p.y_mm])
        .collect();
    let fit = fit(&lit, &job.pieces);
    eprintln!("pygrbl-streamer (galvo): {fit:?}");
    assert!(fit.worst_lit_mm <= 0.2, "{fit:?}");
    assert!(fit.worst_missed_mm <= 0.5, "{fit:?}");
}

#[test]
#[ignore = "real time, installs PyPI packages: cargo xtask senders"]
fn streaming_throughput_in_check_mode() {
    // Protocol throughput: 2000 short G1 lines parsed and answered in
    // check mode (`$C`, nothing moves), character counting.
    let mut job = Job::default();
    job.lines.push("$C".into());
    for k in 0..2000 {
        let (x, y) = ((k % 40) as f64 - 20.0, (k / 40 % 30) as f64 - 15.0);
        job.lines.push(format!("G1 X{x} Y{y} F3000 S500"));
    }
    job.lines.push("$C".into());
    let (report, summary) = stream("stream_pygrbl.py", &[], &job);
    eprintln!("throughput: {}", summary.json);
    assert_eq!(summary.json["completed"], true);
    assert_eq!(summary.json["errors"], serde_json::json!([]));
    let seconds = summary.json["seconds"].as_f64().unwrap_or(f64::INFINITY);
    let rate = job.lines.len() as f64 / seconds;
    eprintln!(
        "throughput: {} lines in {seconds:.2} s = {rate:.0} lines/s (pygrbl-streamer, character counting, check mode)",
        job.lines.len()
    );
    assert!(rate > 100.0, "{rate:.0} lines/s");
    let received = system_tests::terminal_lines(&report)
        .iter()
        .filter(|l| l.starts_with("> G1"))
        .count();
    assert_eq!(received, 2000, "every line arrived");
}
