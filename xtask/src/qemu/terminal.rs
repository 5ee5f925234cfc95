//! The console of the emulated board (UART0 through QEMU's socket): a
//! terminal that records every line the firmware prints, and counts the
//! closing replies (`ok`, `error: …`) so a script can wait for them, as the
//! simulator's USB host does.

use std::io::{ErrorKind, Read};
use std::os::unix::net::UnixStream;
use std::sync::mpsc::SyncSender;
use std::sync::{Arc, Condvar, Mutex};
use std::time::{Duration, Instant};

/// How often a blocked read looks at the stall flag.
const READ_POLL: Duration = Duration::from_millis(20);

/// What the terminal saw (host µs since QEMU started).
#[derive(Debug, Default, Clone)]
pub struct Terminal {
    /// Every line, in order: `> command` for what was sent, the device's
    /// lines as printed.
    pub lines: Vec<(u64, String)>,
    /// Closing replies read (`ok` or `error: …`).
    pub closed: usize,
    /// Closing replies that were `error: …`.
    pub error_replies: usize,
    /// Unsolicited notices (`[…]`).
    pub notices: Vec<(u64, String)>,
    /// Bytes after the last line end.
    pub unterminated: String,
    /// While set, lines go to `probe_lines` instead (the `--until-idle`
    /// status probe, not part of the transcript).
    pub quiet: bool,
    /// Lines read while `quiet`.
    pub probe_lines: Vec<String>,
    /// The terminal does not read before this instant (`@stall-read`).
    pub stall_until: Option<Instant>,
    /// Print the transcript on stdout as it happens.
    pub echo: bool,
}

impl Terminal {
    /// Records one line the device printed.
    pub fn device_line(&mut self, t_us: u64, line: String) {
        let closing = line == "ok" || line.starts_with("error:");
        if closing {
            self.closed += 1;
        }
        // A notice (`[…]`) is unsolicited: it belongs to the run, not to
        // the idle probe's reply, whenever it comes. (Under host load the
        // board runs behind the host's clock, so a fault's notice could
        // arrive during the probe that follows a script's last `wait` and
        // was lost with the probe's lines: `silent_servo` saw no notice.)
        if self.quiet && !line.starts_with('[') {
            self.probe_lines.push(line);
            return;
        }
        if closing && line.starts_with("error:") {
            self.error_replies += 1;
        }
        if line.starts_with('[') {
            self.notices.push((t_us, line.clone()));
        }
        if self.echo {
            println!("{line}");
        }
        self.lines.push((t_us, line));
    }

    /// Records a line the host typed.
    pub fn typed_line(&mut self, t_us: u64, line: &str) {
        if self.echo {
            println!("> {line}");
        }
        self.lines.push((t_us, format!("> {line}")));
    }
}

/// The terminal as the reader thread and the typist share it.
pub type SharedTerminal = Arc<(Mutex<Terminal>, Condvar)>;

/// Reads the console until QEMU closes it; every chunk also goes to `tee`
/// when given (the `--pty` bridge: a blocking send, so a host that does
/// not read holds the board's output back instead of losing it).
pub fn read_console(
    mut stream: UnixStream,
    terminal: SharedTerminal,
    t0: Instant,
    tee: Option<SyncSender<Vec<u8>>>,
) {
    let _ = stream.set_read_timeout(Some(READ_POLL));
    let mut pending: Vec<u8> = Vec::new();
    let mut chunk = [0u8; 512];
    loop {
        let stall = terminal.0.lock().ok().and_then(|t| t.stall_until);
        if let Some(until) = stall
            && Instant::now() < until
        {
            std::thread::sleep(READ_POLL.min(until - Instant::now()));
            continue;
        }
        let n = match stream.read(&mut chunk) {
            Ok(0) => return,
            Ok(n) => n,
            Err(e) if matches!(e.kind(), ErrorKind::WouldBlock | ErrorKind::TimedOut) => continue,
            Err(_) => return,
        };
        if let Some(tee) = &tee {
            let _ = tee.send(chunk[..n].to_vec());
        }
        pending.extend_from_slice(&chunk[..n]);
        let (lock, signal) = &*terminal;
        let Ok(mut term) = lock.lock() else { return };
        let t_us = t0.elapsed().as_micros() as u64;
        while let Some(end) = pending.iter().position(|&b| b == b'\n') {
            let raw: Vec<u8> = pending.drain(..=end).collect();
            term.device_line(t_us, String::from_utf8_lossy(&raw).trim_end().to_owned());
        }
        term.unterminated = String::from_utf8_lossy(&pending).into_owned();
        drop(term);
        signal.notify_all();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn closing_replies_and_notices_are_counted_and_probes_kept_apart() {
        let mut t = Terminal::default();
        t.typed_line(0, "get x");
        t.device_line(1, "error: unknown parameter".into());
        t.device_line(2, "[error: servo 1 not answering]".into());
        t.quiet = true;
        t.device_line(3, "state: idle".into());
        // A notice while the idle probe reads is still the run's.
        t.device_line(3, "[error: servo 0 not answering]".into());
        t.device_line(3, "ok".into());
        assert_eq!(t.closed, 2);
        assert_eq!(t.error_replies, 1);
        assert_eq!(t.notices.len(), 2);
        assert_eq!(t.notices[1].1, "[error: servo 0 not answering]");
        assert_eq!(t.probe_lines, ["state: idle", "ok"]);
        assert_eq!(t.lines.len(), 4);
    }
}
