//! One run of the emulated board: QEMU started on the image with its five
//! UARTs and its monitor on Unix sockets this process listens on, and the
//! threads that serve them (console terminal, servo bus, log channel).

use std::io::Write;
use std::os::unix::net::{UnixListener, UnixStream};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::mpsc::{Receiver, SyncSender};
use std::sync::{Arc, Condvar, Mutex};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use anyhow::{Context, Result, bail};
use laser_sim::servo_model::SimServoBus;
use laser_sim::servo_port::{BusFaults, FaultInjector};

use super::board_log::{BoardLog, SharedLog, read_channel};
use super::defmt_log::read_defmt;
use super::servo_bus::{ServoSide, serve};
use super::terminal::{SharedTerminal, Terminal, read_console};
use crate::bench_m4::qemu::MACHINE_ARGS;

/// How long QEMU may take to connect its sockets and the board to boot.
const BOOT_TIMEOUT: Duration = Duration::from_secs(20);
/// The byte that presses the board's stop button (`firmware/qemu-m4`'s
/// `BUTTON_BYTE`), sent on the log channel's input.
const BUTTON_BYTE: u8 = b'B';
/// The bytes that open / close the board's remote interlock and turn its
/// key switch off / on (`firmware/qemu-m4`'s `controls.rs`).
const INTERLOCK_BYTES: [u8; 2] = [b'I', b'i'];
const KEY_BYTES: [u8; 2] = [b'K', b'k'];
/// The byte that asks the board for its `@stats` report.
const STATS_BYTE: u8 = b'S';
/// Seed of the fault injection's random numbers (as the simulator's).
const FAULT_SEED: u64 = 0x5eed;

/// What a run serves the board with.
#[derive(Debug, Clone, Default)]
pub struct MachineOptions {
    /// Injected servo-bus faults (times in ms since QEMU started).
    pub faults: BusFaults,
    /// Servos move this many times slower than commanded.
    pub slow_factor: f64,
    /// Print the console transcript on stdout.
    pub echo: bool,
    /// Print the board's log records on stderr.
    pub echo_log: bool,
    /// Also send the console's output here (the `--pty` bridge).
    pub console_tee: Option<SyncSender<Vec<u8>>>,
    /// The PELCO port's bytes to and from a client (the `--pelco-pty`
    /// bridge); none: the port is connected but silent.
    pub pelco: Option<PelcoWire>,
}

/// The PELCO port (UART4) joined to a client's byte channels.
#[derive(Debug, Clone)]
pub struct PelcoWire {
    /// The board's bytes, for the client.
    pub to_host: SyncSender<Vec<u8>>,
    /// The client's bytes, for the board.
    pub from_host: Arc<Mutex<Receiver<Vec<u8>>>>,
}

/// A running emulated board.
pub struct Machine {
    child: Child,
    dir: PathBuf,
    console: UnixStream,
    /// The PELCO port (UART4).
    pelco: UnixStream,
    log_input: UnixStream,
    monitor: UnixStream,
    /// The console terminal.
    pub terminal: SharedTerminal,
    /// The log channel.
    pub log: SharedLog,
    /// The servos.
    pub servos: Arc<Mutex<ServoSide>>,
    /// When QEMU started (host time origin of the run).
    pub t0: Instant,
    /// Lines typed so far (each gets one closing reply).
    sent: usize,
    threads: Vec<JoinHandle<()>>,
}

/// A fresh directory for one run's sockets.
fn socket_dir() -> Result<PathBuf> {
    static RUNS: AtomicUsize = AtomicUsize::new(0);
    let n = RUNS.fetch_add(1, Ordering::Relaxed);
    let dir = std::env::temp_dir().join(format!("xtask-qemu-{}-{n}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).with_context(|| format!("cannot create {}", dir.display()))?;
    Ok(dir)
}

/// Waits for QEMU to connect to `listener`.
fn accept(listener: &UnixListener, child: &mut Child, what: &str) -> Result<UnixStream> {
    listener.set_nonblocking(true)?;
    let start = Instant::now();
    loop {
        match listener.accept() {
            Ok((stream, _)) => {
                stream.set_nonblocking(false)?;
                return Ok(stream);
            }
            Err(e) if e.kind() == std::io::ErrorKind::WouldBlock => {}
            Err(e) => return Err(e).context("accepting QEMU's connection"),
        }
        if let Some(status) = child.try_wait()? {
            bail!("qemu-system-arm exited ({status}) before connecting its {what}");
        }
        if start.elapsed() > BOOT_TIMEOUT {
            bail!("qemu-system-arm did not connect its {what} within {BOOT_TIMEOUT:?}");
        }
        std::thread::sleep(Duration::from_millis(5));
    }
}

fn spawn_qemu(elf: &Path, sockets: &[(&str, PathBuf)]) -> Result<Child> {
    let mut cmd = Command::new("qemu-system-arm");
    cmd.args(MACHINE_ARGS)
        .args(["-nographic", "-kernel"])
        .arg(elf);
    for (id, path) in sockets {
        cmd.arg("-chardev")
            .arg(format!("socket,id={id},path={}", path.display()));
    }
    cmd.args(["-serial", "chardev:uart0", "-serial", "chardev:uart1"])
        .args([
            "-serial",
            "chardev:uart2",
            "-serial",
            "chardev:uart3",
            "-serial",
            "chardev:uart4",
            "-mon",
            "chardev=mon,mode=readline",
        ])
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(Stdio::inherit());
    cmd.spawn().context("could not start qemu-system-arm")
}

/// Joins the PELCO port's socket to `wire`: the board's bytes to the
/// client (a thread the socket's shutdown ends), the client's to the board
/// (a thread that ends with the client's channel).
fn wire_pelco(
    pelco: &UnixStream,
    wire: PelcoWire,
    threads: &mut Vec<JoinHandle<()>>,
) -> Result<()> {
    let (mut reader, mut writer) = (pelco.try_clone()?, pelco.try_clone()?);
    let to_host = wire.to_host;
    threads.push(std::thread::spawn(move || {
        let mut buf = [0u8; 256];
        while let Ok(n) = std::io::Read::read(&mut reader, &mut buf) {
            if n == 0 || to_host.send(buf[..n].to_vec()).is_err() {
                return;
            }
        }
    }));
    std::thread::spawn(move || {
        loop {
            let bytes = match wire.from_host.lock() {
                Ok(from_host) => from_host.recv(),
                Err(_) => return,
            };
            match bytes {
                Ok(bytes) if writer.write_all(&bytes).is_ok() => {}
                _ => return,
            }
        }
    });
    Ok(())
}

impl Machine {
    /// Starts QEMU on `elf` and waits for the board to boot.
    pub fn start(elf: &Path, options: &MachineOptions) -> Result<Self> {
        let dir = socket_dir()?;
        let names = ["uart0", "uart1", "uart2", "uart3", "uart4", "mon"];
        let mut sockets = Vec::new();
        let mut listeners = Vec::new();
        for name in names {
            let path = dir.join(format!("{name}.sock"));
            listeners.push(UnixListener::bind(&path).context("binding a socket for QEMU")?);
            sockets.push((name, path));
        }
        let mut child = spawn_qemu(elf, &sockets)?;
        let t0 = Instant::now();
        let mut streams = Vec::new();
        for (listener, name) in listeners.iter().zip(names) {
            match accept(listener, &mut child, name) {
                Ok(s) => streams.push(s),
                Err(e) => {
                    let _ = child.kill();
                    let _ = child.wait();
                    return Err(e);
                }
            }
        }
        let [console, servo, log, defmt, pelco, monitor] = <[UnixStream; 6]>::try_from(streams)
            .map_err(|_| anyhow::anyhow!("six sockets expected"))?;

        let elf_bytes =
            std::fs::read(elf).with_context(|| format!("cannot read {}", elf.display()))?;
        let terminal: SharedTerminal = Arc::new((
            Mutex::new(Terminal {
                echo: options.echo,
                ..Terminal::default()
            }),
            Condvar::new(),
        ));
        let board_log: SharedLog = Arc::new((Mutex::new(BoardLog::default()), Condvar::new()));
        let gimbal = laser_sim::physics::PhysicalGimbal::default();
        let servos = Arc::new(Mutex::new(ServoSide {
            bus: SimServoBus::new(&[gimbal.yaw_id, gimbal.pitch_id], options.slow_factor),
            injector: FaultInjector::new(options.faults.clone(), FAULT_SEED),
            frames: Vec::new(),
            damaged: Vec::new(),
        }));
        let mut threads = Vec::new();
        if let Some(wire) = &options.pelco {
            wire_pelco(&pelco, wire.clone(), &mut threads)?;
        }
        let (term, reader) = (terminal.clone(), console.try_clone()?);
        let tee = options.console_tee.clone();
        threads.push(std::thread::spawn(move || {
            read_console(reader, term, t0, tee)
        }));
        let side = servos.clone();
        threads.push(std::thread::spawn(move || serve(servo, side, t0)));
        let (shared_log, reader, echo_log) =
            (board_log.clone(), log.try_clone()?, options.echo_log);
        threads.push(std::thread::spawn(move || {
            read_channel(reader, shared_log, echo_log)
        }));
        let (shared_log, echo_log) = (board_log.clone(), options.echo_log);
        threads.push(std::thread::spawn(move || {
            read_defmt(defmt, elf_bytes, shared_log, echo_log)
        }));
        let machine = Self {
            child,
            dir,
            console,
            pelco,
            log_input: log,
            monitor,
            terminal,
            log: board_log,
            servos,
            t0,
            sent: 0,
            threads,
        };
        machine.wait_for_boot(1)?;
        Ok(machine)
    }

    /// A second handle on the PELCO port's socket (UART4): bytes written
    /// reach the board's PELCO task, its replies are read here (only when
    /// the run has no [`MachineOptions::pelco`] wire).
    pub fn pelco_port(&self) -> Result<UnixStream> {
        self.pelco
            .try_clone()
            .context("cannot clone the PELCO socket")
    }

    /// Host µs since QEMU started.
    pub fn now_us(&self) -> u64 {
        self.t0.elapsed().as_micros() as u64
    }

    /// Waits until the board has booted `boots` times and its executor
    /// runs the tasks (its UARTs are up: input typed from now on is read).
    fn wait_for_boot(&self, boots: usize) -> Result<()> {
        let (lock, signal) = &*self.log;
        let start = Instant::now();
        let mut log = lock
            .lock()
            .map_err(|_| anyhow::anyhow!("log reader died"))?;
        loop {
            if log.ready_boots >= boots {
                return Ok(());
            }
            if start.elapsed() > BOOT_TIMEOUT {
                bail!("the emulated board did not boot within {BOOT_TIMEOUT:?}");
            }
            log = signal
                .wait_timeout(log, Duration::from_millis(100))
                .map_err(|_| anyhow::anyhow!("log reader died"))?
                .0;
        }
    }

    /// Types `line` on the console (its reply is then outstanding),
    /// recording it in the transcript unless the terminal is quiet.
    pub fn type_line(&mut self, line: &str) -> Result<()> {
        let t = self.now_us();
        if let Ok(mut term) = self.terminal.0.lock()
            && !term.quiet
        {
            term.typed_line(t, line);
        }
        self.sent += 1;
        self.console
            .write_all(format!("{line}\r\n").as_bytes())
            .context("writing to the console socket")
    }

    /// Sends one grbl realtime byte on the console (no line, no reply
    /// outstanding).
    pub fn send_realtime(&mut self, byte: u8) -> Result<()> {
        self.console
            .write_all(&[byte])
            .context("writing to the console socket")
    }

    /// A second handle on the console socket (bytes written to it are
    /// typed on the board's console; a write blocks while QEMU holds input
    /// back).
    pub fn console_writer(&self) -> Result<UnixStream> {
        self.console
            .try_clone()
            .context("cannot clone the console socket")
    }

    /// Waits until every line typed has its closing reply; `false` at
    /// `deadline`.
    pub fn replies_read(&self, deadline: Instant) -> bool {
        let (lock, signal) = &*self.terminal;
        let Ok(mut term) = lock.lock() else {
            return false;
        };
        while term.closed < self.sent {
            let now = Instant::now();
            if now >= deadline {
                return false;
            }
            match signal.wait_timeout(term, (deadline - now).min(Duration::from_millis(100))) {
                Ok((t, _)) => term = t,
                Err(_) => return false,
            }
        }
        true
    }

    /// Presses the stop button.
    pub fn press_button(&mut self) -> Result<()> {
        self.log_input
            .write_all(&[BUTTON_BYTE])
            .context("writing to the log channel socket")
    }

    /// Opens (`false`) or closes the board's remote interlock (an image
    /// built with the `laser-controls` feature).
    pub fn set_interlock(&mut self, closed: bool) -> Result<()> {
        self.log_input
            .write_all(&[INTERLOCK_BYTES[usize::from(closed)]])
            .context("writing to the log channel socket")
    }

    /// Turns the board's key switch off (`false`) or on.
    pub fn set_key(&mut self, on: bool) -> Result<()> {
        self.log_input
            .write_all(&[KEY_BYTES[usize::from(on)]])
            .context("writing to the log channel socket")
    }

    /// Asks the board for its measurements and waits for the `@stats`
    /// line (the text after `@stats`).
    pub fn stats(&mut self) -> Result<String> {
        let before = self.log.0.lock().map(|l| l.stats.len()).unwrap_or(0);
        self.log_input
            .write_all(&[STATS_BYTE])
            .context("writing to the log channel socket")?;
        let (lock, signal) = &*self.log;
        let start = Instant::now();
        let mut log = lock
            .lock()
            .map_err(|_| anyhow::anyhow!("log reader died"))?;
        while log.stats.len() <= before {
            if start.elapsed() > BOOT_TIMEOUT {
                bail!("the board did not report its measurements");
            }
            log = signal
                .wait_timeout(log, Duration::from_millis(50))
                .map_err(|_| anyhow::anyhow!("log reader died"))?
                .0;
        }
        Ok(log.stats[before].clone())
    }

    /// Resets the board (QEMU's `system_reset`: as the reset pin) and
    /// waits for it to boot again.
    pub fn reset(&mut self) -> Result<()> {
        let boots = self.log.0.lock().map(|l| l.boots).unwrap_or(0);
        self.monitor
            .write_all(b"system_reset\n")
            .context("writing to QEMU's monitor")?;
        self.wait_for_boot(boots + 1)?;
        // Replies outstanding at the reset never come.
        self.sent = self.terminal.0.lock().map(|t| t.closed).unwrap_or(0);
        Ok(())
    }

    /// Stops QEMU and the threads; the recordings stay readable.
    pub fn stop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
        for stream in [&self.console, &self.pelco, &self.log_input, &self.monitor] {
            let _ = stream.shutdown(std::net::Shutdown::Both);
        }
        for thread in self.threads.drain(..) {
            let _ = thread.join();
        }
        let _ = std::fs::remove_dir_all(&self.dir);
    }
}

impl Drop for Machine {
    fn drop(&mut self) {
        self.stop();
    }
}
