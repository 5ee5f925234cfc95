//! The console on the simulator's PTY (`cargo xtask sim --pty`), driven
//! by a host program as a serial port, in real time: the cases of issue
//! 25 that were seen on a PTY. The assertions hold whatever the host's
//! speed; times are the simulator's (paced by, never ahead of, the wall
//! clock), and wall-clock limits only end a run that hangs.

use std::fs::{File, OpenOptions};
use std::io::{Read, Write};
use std::path::Path;
use std::sync::mpsc::{Receiver, channel};
use std::time::{Duration, Instant};

use laser_sim::on_pty::SimOnPty;
use laser_sim::world::SimOptions;

/// Ends a run that hangs.
const GUARD: Duration = Duration::from_secs(120);

/// Starts the simulator with its console on a PTY named after `name`.
fn start(name: &str) -> SimOnPty {
    let link = std::env::temp_dir().join(format!("laser-pty-{name}-{}", std::process::id()));
    let options = SimOptions {
        max_time_ms: GUARD.as_millis() as u64,
        ..SimOptions::default()
    };
    SimOnPty::start(link, options).expect("the simulator's PTY")
}

/// Opens the port (the host's side).
fn open_port(path: &Path) -> File {
    OpenOptions::new()
        .read(true)
        .write(true)
        .open(path)
        .expect("the PTY opens")
}

/// Reads `port` on a thread, sending each line (without its end).
fn read_lines(port: &File) -> Receiver<String> {
    let mut port = port.try_clone().expect("clone");
    let (send, lines) = channel();
    std::thread::spawn(move || {
        let mut pending = Vec::new();
        let mut buf = [0u8; 4096];
        while let Ok(n) = port.read(&mut buf) {
            if n == 0 {
                break;
            }
            pending.extend_from_slice(&buf[..n]);
            while let Some(end) = pending.iter().position(|&b| b == b'\n') {
                let raw: Vec<u8> = pending.drain(..=end).collect();
                let line = String::from_utf8_lossy(&raw).trim_end().to_owned();
                if send.send(line).is_err() {
                    return;
                }
            }
        }
    });
    lines
}

/// Lines from `lines` up to and including the first that `last` accepts.
fn lines_until(lines: &Receiver<String>, mut last: impl FnMut(&str) -> bool) -> Vec<String> {
    let started = Instant::now();
    let mut seen = Vec::new();
    loop {
        let left = GUARD.saturating_sub(started.elapsed());
        let line = lines
            .recv_timeout(left)
            .unwrap_or_else(|_| panic!("no end line within {GUARD:?}: {seen:#?}"));
        let done = last(&line);
        seen.push(line);
        if done {
            return seen;
        }
    }
}

#[test]
fn a_reading_host_typing_ahead_on_the_pty_gets_every_line_run() {
    // Issue 25, defect 7: with a thread reading everything, 49 821 of
    // 50 000 typed-ahead `version` lines were refused as "not reading".
    const LINES: usize = 5_000;
    let sim = start("typeahead");
    let port = open_port(&sim.link);
    let lines = read_lines(&port);
    let mut writer = port.try_clone().expect("clone");
    let typing = std::thread::spawn(move || {
        let text = "version\r\n$G\r\n".repeat(LINES / 2);
        writer.write_all(text.as_bytes()).expect("typed");
    });
    let mut closers = 0;
    let seen = lines_until(&lines, |l| {
        closers += usize::from(l == "ok" || l.starts_with("error"));
        closers == LINES
    });
    typing.join().expect("typed");
    let report = sim.finish();
    let refused: Vec<&String> = seen
        .iter()
        .filter(|l| l.starts_with("error") || l.contains("dropped"))
        .collect();
    assert!(
        refused.is_empty(),
        "{} refused: {:?}",
        refused.len(),
        refused.first()
    );
    let versions = seen
        .iter()
        .filter(|l| l.starts_with("laser-pointer"))
        .count();
    let modes = seen.iter().filter(|l| l.starts_with("[GC:")).count();
    assert_eq!((versions, modes), (LINES / 2, LINES / 2));
    assert!(report.transcript.lines.len() > LINES);
}

#[test]
fn a_host_that_flooded_and_closed_the_pty_is_followed_by_one_answered_at_once() {
    // Issue 25, defect 8: 711 414 lines written in 8 s without reading,
    // the port closed and opened again: `stop` and `version` were not
    // answered within 15 s.
    let sim = start("reopen");
    let mut port = open_port(&sim.link);
    let flood = "version\r\n".repeat(2_000);
    // The host's writes stop when nothing more fits (back-pressure): write
    // from a thread and close the port with what is still unwritten.
    let mut writer = port.try_clone().expect("clone");
    let flooding = std::thread::spawn(move || {
        let _ = writer.write_all(flood.as_bytes());
    });
    std::thread::sleep(Duration::from_millis(1_500));
    port.flush().expect("flush");
    drop(port);
    // The writer blocked in the kernel holds the port open: it ends once
    // the console has taken its lines (each refused or answered).
    flooding.join().expect("flooded");
    std::thread::sleep(Duration::from_millis(200));
    let mut port = open_port(&sim.link);
    let lines = read_lines(&port);
    port.write_all(b"stop\r\nversion\r\n").expect("typed");
    let seen = lines_until(&lines, |l| l.starts_with("laser-pointer"));
    let after = lines_until(&lines, |l| l == "ok" || l.starts_with("error"));
    drop(port);
    let report = sim.finish();
    assert_eq!(seen.len(), 2, "only the new session's lines: {seen:#?}");
    assert_eq!(seen[0], "ok", "{seen:#?}");
    assert_eq!(after, ["ok"]);
    // Simulated time from the port opening to the `version` reply.
    let transcript = &report.transcript.lines;
    let opened = transcript
        .iter()
        .rposition(|(_, l)| l == "@open")
        .expect("the port opened again");
    let (answered_us, _) = transcript[opened..]
        .iter()
        .find(|(_, l)| l.starts_with("laser-pointer"))
        .expect("answered");
    let delay_us = answered_us - transcript[opened].0;
    assert!(
        delay_us < 1_000_000,
        "answered {delay_us} µs after the port opened"
    );
}

#[test]
fn an_unlock_written_with_the_soft_reset_on_the_pty_unlocks_after_it() {
    // Issue 25, defect 5: `\x18$X\n` in one write answered `ok` to `$X`
    // before ALARM:3 and the banner (5 of 5 on a PTY).
    let sim = start("reset");
    let mut port = open_port(&sim.link);
    let lines = read_lines(&port);
    port.write_all(b"G1 X20 Y0 F300\r\n").expect("typed");
    lines_until(&lines, |l| l == "ok");
    std::thread::sleep(Duration::from_millis(300));
    port.write_all(b"\x18$X\r\nG0 X0 Y0\r\n").expect("typed");
    let seen = lines_until(&lines, |l| l.starts_with("error") || l == "ok");
    let rest = lines_until(&lines, |l| l.starts_with("error") || l == "ok");
    drop(port);
    sim.finish();
    let alarm = seen.iter().position(|l| l == "ALARM:3");
    let banner = seen.iter().position(|l| l.starts_with("Grbl 1.1"));
    assert!(alarm.is_some() && banner.is_some(), "{seen:#?}");
    assert_eq!(rest, ["ok"], "the G0 after the unlock runs: {seen:#?}");
}
