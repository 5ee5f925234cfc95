//! The simulated USB host: a terminal that types the script into the
//! firmware's command line (over byte pipes standing in for CDC-ACM) and
//! reads back every reply, one command at a time like a G-code sender.

use std::cell::RefCell;
use std::rc::Rc;

use embassy_sync::blocking_mutex::raw::CriticalSectionRawMutex;
use embassy_sync::channel::Channel;
use embassy_sync::pipe::Pipe;
use embassy_time::Timer;

use crate::script::Step;
use laser_app::command::CommandLink;

/// Host → firmware bytes.
pub type ToDevice = Pipe<CriticalSectionRawMutex, 256>;
/// Firmware → host bytes.
pub type FromDevice = Pipe<CriticalSectionRawMutex, 1024>;

/// What the terminal saw.
#[derive(Debug, Default, Clone)]
pub struct Transcript {
    /// Every line, in order: `> command` for what was sent, the device's
    /// lines as printed.
    pub lines: Vec<(u64, String)>,
    /// Closing replies that were `error: …` (unsolicited `[…]` notices are
    /// not counted).
    pub error_replies: usize,
    /// Unsolicited notices (`[error: …]`, `[info: …]`).
    pub notices: Vec<(u64, String)>,
    /// The script has been sent completely and every reply received.
    pub script_done: bool,
}

/// Shared between the script and terminal tasks.
pub struct UsbHost {
    /// Host → device pipe.
    pub to_device: ToDevice,
    /// Device → host pipe.
    pub from_device: FromDevice,
    /// Closing replies (true = `ok`), terminal → script task.
    finals: Channel<CriticalSectionRawMutex, bool, 4>,
    /// What happened.
    pub transcript: RefCell<Transcript>,
    /// Echo the transcript on stdout as it happens.
    pub echo: bool,
}

impl UsbHost {
    /// A host with empty pipes.
    pub fn new(echo: bool) -> Self {
        Self {
            to_device: Pipe::new(),
            from_device: Pipe::new(),
            finals: Channel::new(),
            transcript: RefCell::default(),
            echo,
        }
    }

    fn record(&self, line: String) {
        if self.echo {
            println!("{line}");
        }
        let t = crate::clock::now_us();
        self.transcript.borrow_mut().lines.push((t, line));
    }
}

/// Types the script: each command line, then waits for its closing reply;
/// `@button` steps press the board's stop button (`link`'s stop request).
pub async fn script_task(steps: Vec<Step>, host: Rc<UsbHost>, link: &CommandLink) {
    for step in steps {
        match step {
            Step::WaitMs(ms) => Timer::after_millis(ms).await,
            Step::Send(line) => send_line(&host, &line).await,
            Step::StopButton => link.stop_request.signal(()),
        }
    }
    host.transcript.borrow_mut().script_done = true;
}

/// Types lines as they come from `lines` (a terminal, read on another
/// thread), checking every 20 ms; the end of input ends the script. For
/// interactive use in real time.
pub async fn interactive_task(lines: std::sync::mpsc::Receiver<String>, host: Rc<UsbHost>) {
    loop {
        match lines.try_recv() {
            Ok(line) => {
                for step in crate::script::parse_script(&line).unwrap_or_default() {
                    match step {
                        Step::WaitMs(ms) => Timer::after_millis(ms).await,
                        Step::Send(line) => send_line(&host, &line).await,
                        // The terminal has no stop button.
                        Step::StopButton => {}
                    }
                }
            }
            Err(std::sync::mpsc::TryRecvError::Empty) => Timer::after_millis(20).await,
            Err(std::sync::mpsc::TryRecvError::Disconnected) => break,
        }
    }
    host.transcript.borrow_mut().script_done = true;
}

/// Types one command line and waits for its closing reply.
async fn send_line(host: &UsbHost, line: &str) {
    host.record(format!("> {line}"));
    host.to_device.write_all(line.as_bytes()).await;
    host.to_device.write_all(b"\r\n").await;
    host.finals.receive().await;
}

/// Reads the device's output line by line.
pub async fn terminal_task(host: Rc<UsbHost>) {
    let mut pending = Vec::new();
    let mut chunk = [0u8; 128];
    loop {
        let n = host.from_device.read(&mut chunk).await;
        pending.extend_from_slice(chunk.get(..n).unwrap_or(&[]));
        while let Some(end) = pending.iter().position(|&b| b == b'\n') {
            let raw: Vec<u8> = pending.drain(..=end).collect();
            let line = String::from_utf8_lossy(&raw).trim_end().to_owned();
            let is_notice = line.starts_with('[');
            let is_ok = line == "ok";
            let is_error = line.starts_with("error:");
            host.record(line.clone());
            if is_notice {
                let t = crate::clock::now_us();
                host.transcript.borrow_mut().notices.push((t, line));
            } else if is_ok || is_error {
                if is_error {
                    host.transcript.borrow_mut().error_replies += 1;
                }
                host.finals.send(is_ok).await;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::executor;

    /// A device that answers every line with `ok`.
    async fn echo_ok_device(host: Rc<UsbHost>) {
        let mut buf = [0u8; 64];
        loop {
            let n = host.to_device.read(&mut buf).await;
            for _ in buf[..n].iter().filter(|&&b| b == b'\n') {
                host.from_device.write_all(b"ok\r\n").await;
            }
        }
    }

    #[test]
    fn interactive_lines_are_typed_in_order_until_the_input_ends() {
        let host = Rc::new(UsbHost::new(false));
        let (send, lines) = std::sync::mpsc::channel();
        for line in ["status", "# a comment", "wait 100", "goto 1 2"] {
            send.send(line.to_owned()).unwrap();
        }
        drop(send);
        let (h1, h2, h3, stop) = (host.clone(), host.clone(), host.clone(), host.clone());
        let end = executor::run(
            false,
            10_000_000,
            move |spawner| {
                executor::spawn(&spawner, interactive_task(lines, h1));
                executor::spawn(&spawner, terminal_task(h2));
                executor::spawn(&spawner, echo_ok_device(h3));
            },
            move || stop.transcript.borrow().script_done,
        );
        assert_eq!(end, executor::RunEnd::Stopped);
        let transcript = host.transcript.borrow();
        let lines: Vec<&str> = transcript.lines.iter().map(|(_, l)| l.as_str()).collect();
        assert_eq!(lines, ["> status", "ok", "> goto 1 2", "ok"]);
        let goto_at = transcript.lines[2].0;
        assert!(goto_at >= 100_000, "the wait line waited: {goto_at} µs");
    }
}
