//! The simulated USB host: a terminal that types the script into the
//! firmware's command line (over byte pipes standing in for CDC-ACM) and
//! reads back every reply, one command at a time like a G-code sender.
//!
//! The device → host pipe is bounded ([`FromDevice`]), like the CDC-ACM
//! endpoint and the host driver's buffer: when the terminal stops reading
//! (`@stall-read <ms>` in a script) the device's writes block once it is
//! full, so back-pressure reaches the firmware as it does on a real port.

use std::cell::{Cell, RefCell};
use std::rc::Rc;

use embassy_executor::Spawner;
use embassy_futures::select::{Either, select};
use embassy_sync::blocking_mutex::raw::CriticalSectionRawMutex;
use embassy_sync::pipe::Pipe;
use embassy_sync::signal::Signal;
use embassy_time::Timer;

use crate::controls::ControlWiring;
use crate::executor::{self, TaskKind};
use crate::panel::ButtonContacts;
use crate::script::Step;

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
    /// Bytes received after the last line end (a line cut short shows
    /// here).
    pub unterminated: String,
}

/// Shared between the script and terminal tasks.
pub struct UsbHost {
    /// Host → device pipe.
    pub to_device: ToDevice,
    /// Device → host pipe.
    pub from_device: FromDevice,
    /// Lines typed whose closing reply has not been read yet.
    outstanding: Cell<usize>,
    /// A closing reply was read (wakes the script task).
    closed: Signal<CriticalSectionRawMutex, ()>,
    /// The terminal does not read before this time, µs.
    stall_until_us: Cell<u64>,
    /// A stall began or ended early (wakes the terminal).
    stalled: Signal<CriticalSectionRawMutex, ()>,
    /// The port is open (the host is connected: DTR on USB).
    open: Cell<bool>,
    /// Connections so far (each open begins one).
    connection: Cell<u32>,
    /// The port was opened or closed (wakes the board's console: its only
    /// waiter).
    port_changed: Signal<CriticalSectionRawMutex, ()>,
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
            outstanding: Cell::new(0),
            closed: Signal::new(),
            stall_until_us: Cell::new(0),
            stalled: Signal::new(),
            open: Cell::new(true),
            connection: Cell::new(0),
            port_changed: Signal::new(),
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

    /// Records the lines the host typed (bytes arriving in chunks;
    /// `typed` holds the unfinished line and whether the last byte was a
    /// CR). grbl's realtime bytes are not part of lines; CR LF ends one.
    pub fn record_typed(&self, typed: &mut (Vec<u8>, bool), bytes: &[u8]) {
        for &b in bytes {
            if laser_app::grbl::realtime::Realtime::from_byte(b).is_some() {
                continue;
            }
            let after_cr = std::mem::replace(&mut typed.1, b == b'\r');
            match b {
                b'\n' if after_cr => {}
                b'\r' | b'\n' => {
                    self.record(format!("> {}", String::from_utf8_lossy(&typed.0)));
                    typed.0.clear();
                }
                _ => typed.0.push(b),
            }
        }
    }

    /// Records the device's output lines (bytes arriving in chunks).
    pub fn record_received(&self, pending: &mut Vec<u8>, bytes: &[u8]) {
        pending.extend_from_slice(bytes);
        while let Some(end) = pending.iter().position(|&b| b == b'\n') {
            let raw: Vec<u8> = pending.drain(..=end).collect();
            let line = String::from_utf8_lossy(&raw).trim_end().to_owned();
            let mut transcript = self.transcript.borrow_mut();
            if line.starts_with('[') {
                let t = crate::clock::now_us();
                transcript.notices.push((t, line.clone()));
            } else if line.starts_with("error:") {
                transcript.error_replies += 1;
            }
            drop(transcript);
            self.record(line);
        }
    }

    /// Stops reading the device's output for `ms` from now.
    pub fn stall_read(&self, ms: u64) {
        let until = crate::clock::now_us() + ms * 1000;
        self.stall_until_us
            .set(self.stall_until_us.get().max(until));
        self.stalled.signal(());
    }

    /// Closes the port (a no-op when closed): bytes either way not read
    /// yet are lost, and so are the replies still awaited.
    pub fn close_port(&self) {
        if self.open.replace(false) {
            self.record("@close".to_owned());
        }
        self.to_device.clear();
        self.from_device.clear();
        self.outstanding.set(0);
        self.closed.signal(());
        self.port_changed.signal(());
    }

    /// Opens the port (closing it first if open): a new connection.
    pub fn open_port(&self) {
        if self.open.get() {
            self.close_port();
        }
        self.to_device.clear();
        self.from_device.clear();
        self.open.set(true);
        self.connection.set(self.connection.get().wrapping_add(1));
        // The program that opened it reads (a stall was the last one's).
        self.stall_until_us.set(0);
        self.stalled.signal(());
        self.record("@open".to_owned());
        self.port_changed.signal(());
    }

    /// Whether the port is open.
    pub fn port_is_open(&self) -> bool {
        self.open.get()
    }

    /// The number of the current (or last) connection.
    pub fn connection(&self) -> u32 {
        self.connection.get()
    }

    /// Waits until the port is open; returns its connection number.
    pub async fn port_opened(&self) -> u32 {
        while !self.open.get() {
            self.port_changed.wait().await;
        }
        self.connection.get()
    }

    /// Waits until connection `connection` has ended (the port closed or
    /// opened again).
    pub async fn port_closed(&self, connection: u32) {
        while self.open.get() && self.connection.get() == connection {
            self.port_changed.wait().await;
        }
    }

    /// Waits until every line typed so far has its closing reply.
    async fn replies_read(&self) {
        while self.outstanding.get() > 0 {
            self.closed.wait().await;
        }
    }
}

/// What the script's `@` steps reach on the bench: the board's stop
/// button and the servo bus's cables.
#[derive(Clone)]
pub struct Hands {
    /// The board's stop button (`@button`).
    pub button: Rc<ButtonContacts>,
    /// The servo bus (`@unplug-servo`, `@plug-servo`).
    pub bus: Rc<RefCell<crate::servo_model::SimServoBus>>,
    /// The laser controls' inputs (`@interlock`, `@key`), on a board
    /// fitted with them.
    pub controls: Option<Rc<ControlWiring>>,
}

/// Runs one script step; `@` steps act through `hands` (the interactive
/// terminal has none).
async fn run_step(host: &UsbHost, step: Step, hands: Option<&Hands>) {
    match step {
        Step::Interlock(closed) => {
            if let Some(controls) = hands.and_then(|h| h.controls.as_deref()) {
                controls.set_interlock(closed);
            }
        }
        Step::Key(on) => {
            if let Some(controls) = hands.and_then(|h| h.controls.as_deref()) {
                controls.set_key(on);
            }
        }
        Step::StopButton => {
            if let Some(hands) = hands {
                hands.button.press();
            }
        }
        Step::ServoCable { slot, plugged } => {
            let done = hands.is_some_and(|h| h.bus.borrow_mut().set_plugged(slot, plugged));
            let what = if plugged { "plugged" } else { "unplugged" };
            // A log line, not the transcript: that holds the console's
            // lines only.
            log::info!(
                "bench: servo in slot {} {}",
                slot + 1,
                if done { what } else { "not there" }
            );
        }
        Step::WaitMs(ms) => Timer::after_millis(ms).await,
        Step::Send(line) => {
            type_line(host, &line).await;
            host.replies_read().await;
        }
        Step::SendAhead(line) => type_line(host, &line).await,
        Step::StallReadMs(ms) => host.stall_read(ms),
        Step::ClosePort => host.close_port(),
        Step::OpenPort => host.open_port(),
        Step::Realtime(byte) => {
            host.record(format!(">> 0x{byte:02x}"));
            host.to_device.write_all(&[byte]).await;
        }
    }
}

/// Types the script: each command line, then waits for its closing reply;
/// `@` steps act through `hands`.
pub async fn script_task(steps: Vec<Step>, host: Rc<UsbHost>, hands: Hands) {
    for step in steps {
        run_step(&host, step, Some(&hands)).await;
    }
    host.replies_read().await;
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
                    run_step(&host, step, None).await;
                }
            }
            Err(std::sync::mpsc::TryRecvError::Empty) => Timer::after_millis(20).await,
            Err(std::sync::mpsc::TryRecvError::Disconnected) => break,
        }
    }
    host.transcript.borrow_mut().script_done = true;
}

/// Starts the simulated host: the script (or the interactive terminal)
/// typing (from stdin when `interactive`), and the terminal reading;
/// `@` steps act through `hands`.
pub fn host_tasks(
    interactive: bool,
    script: Vec<Step>,
    host: Rc<UsbHost>,
    hands: Hands,
) -> impl FnOnce(&Spawner) + 'static {
    move |spawner| {
        if interactive {
            let (send, lines) = std::sync::mpsc::channel();
            std::thread::spawn(move || {
                for line in std::io::stdin().lines().map_while(Result::ok) {
                    if send.send(line).is_err() {
                        break;
                    }
                }
            });
            executor::spawn_task(
                spawner,
                "host (interactive)",
                TaskKind::Simulator,
                interactive_task(lines, host.clone()),
            );
        } else {
            executor::spawn_task(
                spawner,
                "host (script)",
                TaskKind::Simulator,
                script_task(script, host.clone(), hands),
            );
        }
        executor::spawn_task(
            spawner,
            "host (terminal)",
            TaskKind::Simulator,
            terminal_task(host),
        );
    }
}

/// Types one command line (its reply is then outstanding).
async fn type_line(host: &UsbHost, line: &str) {
    host.record(format!("> {line}"));
    host.outstanding.set(host.outstanding.get() + 1);
    host.to_device.write_all(line.as_bytes()).await;
    host.to_device.write_all(b"\r\n").await;
}

/// Reads the device's output line by line (not while stalled).
pub async fn terminal_task(host: Rc<UsbHost>) {
    let mut pending = Vec::new();
    let mut chunk = [0u8; 128];
    let mut connection = host.connection.get();
    loop {
        let now = crate::clock::now_us();
        let until = host.stall_until_us.get();
        if now < until {
            // Until the stall ends, or a new host opens the port.
            select(Timer::after_micros(until - now), host.stalled.wait()).await;
            continue;
        }
        // A stall that begins while waiting wins over bytes ready.
        let n = match select(host.stalled.wait(), host.from_device.read(&mut chunk)).await {
            Either::First(()) => continue,
            Either::Second(n) => n,
        };
        if host.connection.get() != connection {
            // A line cut by a close is lost with it (the pipes were
            // emptied when the port opened again).
            pending.clear();
            connection = host.connection.get();
        }
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
                host.outstanding
                    .set(host.outstanding.get().saturating_sub(1));
                host.closed.signal(());
            }
        }
        host.transcript.borrow_mut().unterminated = String::from_utf8_lossy(&pending).into_owned();
    }
}

#[cfg(test)]
mod tests;
