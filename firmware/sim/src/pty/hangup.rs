//! A PTY bridge that sees the host close and open the port (the PTY's
//! DTR): [`PtyBridge::start_with_hangups`].
//!
//! The simulator releases its own handle on the slave, so reading the
//! master fails (EIO) once the host's last handle is closed. The reader
//! thread then empties what the host had not read yet (opening the slave
//! for a moment to flush its input), sends an empty chunk (a *marker*),
//! waits until a host opens the port again (the master stops reporting a
//! hang-up) and sends another marker: markers alternate, closed then
//! opened. The writer thread drops the device's bytes from a close until
//! the simulator acknowledges it with an empty chunk of its own (its
//! session's output ends there).

use std::fs::{File, OpenOptions};
use std::io::{Read, Write};
use std::os::fd::AsRawFd;
use std::os::unix::fs::OpenOptionsExt;
use std::path::Path;
use std::sync::Arc;
use std::sync::atomic::{AtomicU32, Ordering};
use std::sync::mpsc::{Receiver, sync_channel};
use std::time::Duration;

use anyhow::Result;

use super::{CHUNKS_IN_FLIGHT, Pty, PtyBridge};

/// How often a closed port is checked for a host opening it.
const OPEN_POLL: Duration = Duration::from_millis(5);
/// How long the device's last bytes of a closed session may still arrive
/// at the master (the writer finishing its chunk) before the final flush.
const FLUSH_SETTLE: Duration = Duration::from_millis(20);

impl PtyBridge {
    /// Starts the reader and writer threads on `pty`'s master, releasing
    /// the simulator's own handle on the slave so that the host closing
    /// the port shows: `from_host` then carries an empty chunk when the
    /// host closes the port and another when a host opens it again
    /// (alternating; the port counts as closed until a host opens it), and
    /// the caller sends an empty chunk on `to_host` once it has ended the
    /// closed session (its output before that is dropped).
    pub fn start_with_hangups(pty: &mut Pty) -> Result<Self> {
        let (mut reader, mut writer) = pty.master_pair()?;
        pty._slave = None;
        let path = pty.path.clone();
        let closes = Arc::new(AtomicU32::new(0));
        let (host_tx, from_host) = sync_channel::<Vec<u8>>(CHUNKS_IN_FLIGHT);
        let (to_host, device_rx) = sync_channel::<Vec<u8>>(CHUNKS_IN_FLIGHT);
        let closes_seen = closes.clone();
        std::thread::spawn(move || {
            let mut buf = [0u8; 256];
            loop {
                match reader.read(&mut buf) {
                    Ok(0) => continue,
                    Ok(n) => {
                        if host_tx.send(buf[..n].to_vec()).is_err() {
                            return;
                        }
                    }
                    Err(_) => {
                        closes_seen.fetch_add(1, Ordering::SeqCst);
                        if host_tx.send(Vec::new()).is_err() {
                            return;
                        }
                        flush_unread_output(&path);
                        wait_for_open(&reader);
                        if host_tx.send(Vec::new()).is_err() {
                            return;
                        }
                    }
                }
            }
        });
        std::thread::spawn(move || write_sessions(&mut writer, &device_rx, &closes));
        Ok(Self { from_host, to_host })
    }
}

/// Writes the device's bytes to the host, dropping those of closed
/// sessions (after each close, up to the simulator's acknowledgement).
fn write_sessions(writer: &mut File, device_rx: &Receiver<Vec<u8>>, closes: &AtomicU32) {
    let mut acknowledged = 0u32;
    for bytes in device_rx {
        if bytes.is_empty() {
            acknowledged = acknowledged.wrapping_add(1);
            continue;
        }
        if acknowledged != closes.load(Ordering::SeqCst) {
            continue;
        }
        // A failed write: the host went away meanwhile (the reader sees it).
        let _ = writer.write_all(&bytes);
    }
}

/// Drops what the device wrote and the closed host did not read (it would
/// greet the next host): opens the slave for a moment to flush its input,
/// twice around a pause so the writer's last chunk goes too.
fn flush_unread_output(path: &Path) {
    let slave = OpenOptions::new()
        .read(true)
        .write(true)
        .custom_flags(libc::O_NOCTTY | libc::O_NONBLOCK)
        .open(path);
    if let Ok(slave) = slave {
        // SAFETY: tcflush on a descriptor owned here.
        unsafe { libc::tcflush(slave.as_raw_fd(), libc::TCIFLUSH) };
        std::thread::sleep(FLUSH_SETTLE);
        // SAFETY: as above.
        unsafe { libc::tcflush(slave.as_raw_fd(), libc::TCIFLUSH) };
    }
}

/// Waits until a host has the slave open (the master no longer reports a
/// hang-up).
fn wait_for_open(master: &File) {
    loop {
        let mut fd = libc::pollfd {
            fd: master.as_raw_fd(),
            events: libc::POLLIN,
            revents: 0,
        };
        // SAFETY: one valid pollfd; a zero timeout does not block.
        let ready = unsafe { libc::poll(&mut fd, 1, 0) };
        if ready >= 0 && fd.revents & libc::POLLHUP == 0 {
            return;
        }
        std::thread::sleep(OPEN_POLL);
    }
}
