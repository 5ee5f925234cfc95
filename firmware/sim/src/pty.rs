//! The simulated board's console on a pseudo-terminal (`cargo xtask sim
//! --pty`): any serial program — picocom, a G-code sender — opens the
//! PTY's device path and talks to the firmware's console exactly as to
//! the board's USB port, in real time.
//!
//! No byte is lost either way: a reader thread takes the host's bytes
//! from the PTY master only as fast as the simulated console takes them
//! (a bounded channel; when it is full the thread stops reading and the
//! kernel's PTY buffer fills, so the sender's writes block), and the
//! device's output goes out through a bounded channel to a writer thread
//! that blocks when the host does not read (the device's writes then wait,
//! as on USB). With [`PtyBridge::start`] the simulator keeps the slave
//! side open itself, so a host may close and reopen the port unnoticed;
//! the simulator's console uses [`PtyBridge::start_with_hangups`]
//! instead, which tells when the host closes and opens the port, so the
//! console starts a new session for each host (as USB's DTR does).

use std::fs::{File, OpenOptions};
use std::io::{Read, Write};
use std::os::fd::{AsRawFd, FromRawFd};
use std::os::unix::fs::OpenOptionsExt;
use std::path::PathBuf;
use std::rc::Rc;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{Receiver, SyncSender, TryRecvError, TrySendError, sync_channel};

use anyhow::{Context, Result, bail};
use embassy_executor::Spawner;
use embassy_time::Timer;

use crate::usb_host::UsbHost;

mod hangup;

/// Where the console appears and what ends the run.
#[derive(Debug, Clone)]
pub struct PtyOptions {
    /// Also make this path a symlink to the PTY's device (replaced if it
    /// is one already).
    pub link: Option<PathBuf>,
    /// Set to end the run (the simulator then writes its outputs).
    pub stop: Arc<AtomicBool>,
}

/// An open pseudo-terminal: the master (the simulator's end), and the
/// slave's device path the host opens.
pub struct Pty {
    master: File,
    /// Kept open so the master never sees a hang-up between host sessions
    /// (released by [`PtyBridge::start_with_hangups`]).
    _slave: Option<File>,
    /// The device path (`/dev/pts/N`).
    pub path: PathBuf,
}

/// Opens a PTY in raw mode (no echo, no line editing, 8-bit clean).
pub fn open() -> Result<Pty> {
    // SAFETY: plain libc calls on a descriptor this function owns; every
    // result is checked.
    unsafe {
        let fd = libc::posix_openpt(libc::O_RDWR | libc::O_NOCTTY);
        if fd < 0 {
            bail!("posix_openpt: {}", std::io::Error::last_os_error());
        }
        let master = File::from_raw_fd(fd);
        if libc::grantpt(fd) != 0 || libc::unlockpt(fd) != 0 {
            bail!("grantpt/unlockpt: {}", std::io::Error::last_os_error());
        }
        let mut name = [0 as libc::c_char; 128];
        if libc::ptsname_r(fd, name.as_mut_ptr(), name.len()) != 0 {
            bail!("ptsname_r: {}", std::io::Error::last_os_error());
        }
        let path = PathBuf::from(
            std::ffi::CStr::from_ptr(name.as_ptr())
                .to_string_lossy()
                .into_owned(),
        );
        let slave = OpenOptions::new()
            .read(true)
            .write(true)
            .custom_flags(libc::O_NOCTTY)
            .open(&path)
            .with_context(|| format!("cannot open {}", path.display()))?;
        let mut termios: libc::termios = std::mem::zeroed();
        if libc::tcgetattr(slave.as_raw_fd(), &mut termios) != 0 {
            bail!("tcgetattr: {}", std::io::Error::last_os_error());
        }
        libc::cfmakeraw(&mut termios);
        if libc::tcsetattr(slave.as_raw_fd(), libc::TCSANOW, &termios) != 0 {
            bail!("tcsetattr: {}", std::io::Error::last_os_error());
        }
        Ok(Pty {
            master,
            _slave: Some(slave),
            path,
        })
    }
}

/// Makes `link` a symlink to `target` (replacing an existing symlink).
pub fn link_to(link: &std::path::Path, target: &std::path::Path) -> Result<()> {
    if link
        .symlink_metadata()
        .is_ok_and(|m| m.file_type().is_symlink())
    {
        std::fs::remove_file(link).with_context(|| format!("cannot replace {}", link.display()))?;
    }
    std::os::unix::fs::symlink(target, link)
        .with_context(|| format!("cannot create the symlink {}", link.display()))
}

/// Host bytes in flight between the reader thread and the simulator.
const CHUNKS_IN_FLIGHT: usize = 4;

/// The threads moving bytes between the PTY master and the simulator.
pub struct PtyBridge {
    /// Bytes the host wrote (the reader thread stops reading while full).
    pub from_host: Receiver<Vec<u8>>,
    /// Bytes for the host (a send blocks while the host does not read).
    pub to_host: SyncSender<Vec<u8>>,
}

impl Pty {
    /// Two handles on the master: one for the reader thread, one for the
    /// writer thread.
    fn master_pair(&self) -> Result<(File, File)> {
        let clone = || {
            self.master
                .try_clone()
                .context("cannot clone the PTY master")
        };
        Ok((clone()?, clone()?))
    }
}

impl PtyBridge {
    /// Starts the reader and writer threads on `pty`'s master; they end
    /// with the process (or when the master fails).
    pub fn start(pty: &Pty) -> Result<Self> {
        let (mut reader, mut writer) = pty.master_pair()?;
        let (host_tx, from_host) = sync_channel::<Vec<u8>>(CHUNKS_IN_FLIGHT);
        let (to_host, device_rx) = sync_channel::<Vec<u8>>(CHUNKS_IN_FLIGHT);
        std::thread::spawn(move || {
            let mut buf = [0u8; 256];
            while let Ok(n) = reader.read(&mut buf) {
                if n > 0 && host_tx.send(buf[..n].to_vec()).is_err() {
                    break;
                }
            }
        });
        std::thread::spawn(move || {
            for bytes in device_rx {
                if writer.write_all(&bytes).is_err() {
                    break;
                }
            }
        });
        Ok(Self { from_host, to_host })
    }
}

/// Poll period of the bridge task in simulated (= wall) time, µs.
const POLL_US: u64 = 500;

/// The simulator's side of the bridge: host bytes to the console's input
/// pipe, the console's output to the host (recorded in the transcript as
/// lines, like the scripted terminal's), both at once (the host's input
/// waits while the console's input pipe is full, never its output).
/// A bridge started with hangups closes and opens the simulated port as
/// the host does. Marks the script done once `stop` is set.
pub async fn pty_task(host: Rc<UsbHost>, pty: Pty, bridge: PtyBridge, stop: Arc<AtomicBool>) {
    let _open = pty;
    let PtyBridge { from_host, to_host } = bridge;
    embassy_futures::join::join(
        host_to_device(&host, &from_host, &to_host, &stop),
        device_to_host(&host, &to_host),
    )
    .await;
}

/// Host → device (waits while the console's input pipe is full); markers
/// of a bridge with hangups close and open the port.
async fn host_to_device(
    host: &UsbHost,
    from_host: &Receiver<Vec<u8>>,
    to_host: &SyncSender<Vec<u8>>,
    stop: &AtomicBool,
) {
    let mut typed = (Vec::new(), false);
    loop {
        if stop.load(Ordering::Relaxed) {
            host.transcript.borrow_mut().script_done = true;
        }
        match from_host.try_recv() {
            Ok(bytes) if bytes.is_empty() && host.port_is_open() => {
                host.close_port();
                typed = (Vec::new(), false);
                acknowledge_close(to_host);
            }
            Ok(bytes) if bytes.is_empty() => host.open_port(),
            Ok(bytes) if host.port_is_open() => {
                host.record_typed(&mut typed, &bytes);
                host.to_device.write_all(&bytes).await;
            }
            Ok(_) => {}
            Err(TryRecvError::Empty | TryRecvError::Disconnected) => {
                Timer::after_micros(POLL_US).await;
            }
        }
    }
}

/// Tells the writer thread of a bridge started with hangups that the
/// closed session's output has ended.
fn acknowledge_close(to_host: &SyncSender<Vec<u8>>) {
    // The writer thread only ends with the process.
    let _ = to_host.send(Vec::new());
}

/// Device → host, one chunk in hand at a time (dropped when the port
/// closes meanwhile).
async fn device_to_host(host: &UsbHost, to_host: &SyncSender<Vec<u8>>) {
    let mut outgoing: Option<(u32, Vec<u8>)> = None;
    let mut received = Vec::new();
    let mut chunk = [0u8; 128];
    loop {
        if let Some((connection, bytes)) = outgoing.take() {
            if !host.port_is_open() || host.connection() != connection {
                continue;
            }
            match to_host.try_send(bytes) {
                Ok(()) | Err(TrySendError::Disconnected(_)) => {}
                Err(TrySendError::Full(bytes)) => {
                    outgoing = Some((connection, bytes));
                    Timer::after_micros(POLL_US).await;
                }
            }
            continue;
        }
        let n = host.from_device.read(&mut chunk).await;
        let bytes = chunk.get(..n).unwrap_or(&[]).to_vec();
        host.record_received(&mut received, &bytes);
        outgoing = Some((host.connection(), bytes));
    }
}

/// Opens the PTY (printing its path, making the symlink) and returns
/// what starts the bridge task; on failure the run ends at once with the
/// reason on stderr.
pub fn host_start(host: Rc<UsbHost>, options: PtyOptions) -> impl FnOnce(&Spawner) + 'static {
    let opened = open().and_then(|pty| {
        if let Some(link) = &options.link {
            link_to(link, &pty.path)?;
        }
        let mut pty = pty;
        let bridge = PtyBridge::start_with_hangups(&mut pty)?;
        Ok((pty, bridge))
    });
    move |spawner| match opened {
        Ok((pty, bridge)) => {
            eprintln!("xtask sim: console on {}", pty.path.display());
            crate::executor::spawn_task(
                spawner,
                "host (pty)",
                crate::executor::TaskKind::Simulator,
                pty_task(host, pty, bridge, options.stop),
            );
        }
        Err(e) => {
            eprintln!("xtask sim: no PTY console: {e:#}");
            host.transcript.borrow_mut().script_done = true;
        }
    }
}

/// SIGINT/SIGTERM received (set by the handler [`stop_on_signals`] installs).
static SIGNALLED: AtomicBool = AtomicBool::new(false);

extern "C" fn on_signal(_: libc::c_int) {
    SIGNALLED.store(true, Ordering::Relaxed);
}

/// Sets `stop` when the process gets SIGINT or SIGTERM (Ctrl-C), so the
/// run ends cleanly with every output written.
pub fn stop_on_signals(stop: Arc<AtomicBool>) {
    // SAFETY: the handler only stores to an atomic (async-signal-safe).
    unsafe {
        libc::signal(libc::SIGINT, on_signal as *const () as libc::sighandler_t);
        libc::signal(libc::SIGTERM, on_signal as *const () as libc::sighandler_t);
    }
    std::thread::spawn(move || {
        while !SIGNALLED.load(Ordering::Relaxed) {
            std::thread::sleep(std::time::Duration::from_millis(20));
        }
        stop.store(true, Ordering::Relaxed);
    });
}
