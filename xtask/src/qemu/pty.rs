//! `cargo xtask qemu --pty [PATH]`: the emulated board's console UART on a
//! raw pseudo-terminal, so a serial program (picocom, a G-code sender)
//! talks to the board as to its USB port. The PTY and its bridge threads
//! are the simulator's (`laser_sim::pty`); this side joins them to QEMU's
//! console socket.
//!
//! No byte is lost: host bytes go to the console socket with blocking
//! writes (QEMU stops reading the socket while the board's UART RX is
//! full, so the bridge stops reading the PTY and the sender's writes
//! block); the board's output goes to the bridge with a blocking send from
//! the console reader (a host that does not read stops that reader, QEMU's
//! socket fills and the board's UART TX waits).

use std::fs::{File, OpenOptions};
use std::io::{Read, Write};
use std::path::Path;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{Receiver, channel};
use std::time::{Duration, Instant};

use anyhow::{Context, Result, bail};
use laser_sim::pty::{Pty, PtyBridge};

use super::board_run::{BoardRun, Drive, run_board};
use super::machine::MachineOptions;

/// Opens the PTY (making `link` a symlink to it) and starts its bridge.
pub fn open(link: Option<&Path>) -> Result<(Pty, PtyBridge)> {
    let pty = laser_sim::pty::open()?;
    if let Some(link) = link {
        laser_sim::pty::link_to(link, &pty.path)?;
    }
    let bridge = PtyBridge::start(&pty)?;
    Ok((pty, bridge))
}

/// Appends the PTY's `chunks` to `text` until an `ok` line has appeared
/// after byte `from`; an error at `deadline`.
fn read_until_ok(
    chunks: &Receiver<Vec<u8>>,
    text: &mut String,
    from: usize,
    deadline: Instant,
) -> Result<()> {
    while !text[from..].contains("ok\r\n") && !text[from..].contains("ok\n") {
        let left = deadline.saturating_duration_since(Instant::now());
        match chunks.recv_timeout(left) {
            Ok(bytes) => text.push_str(&String::from_utf8_lossy(&bytes)),
            Err(_) => bail!("no `ok` from the board on the PTY; read so far: {text:?}"),
        }
    }
    Ok(())
}

/// Opens the PTY's device as a host program does; a thread reads it.
fn connect(path: &Path) -> Result<(File, Receiver<Vec<u8>>)> {
    let port = OpenOptions::new()
        .read(true)
        .write(true)
        .open(path)
        .with_context(|| format!("cannot open {}", path.display()))?;
    let mut reader = port.try_clone()?;
    let (tx, rx) = channel();
    std::thread::spawn(move || {
        let mut buf = [0u8; 256];
        while let Ok(n) = reader.read(&mut buf) {
            if n == 0 || tx.send(buf[..n].to_vec()).is_err() {
                return;
            }
        }
    });
    Ok((port, rx))
}

/// Runs the board from `elf` with its console on a fresh PTY, calls
/// `talk` with the PTY's device path while it runs, then stops the board:
/// `talk`'s result and the board's run.
pub fn with_board_on_pty<T>(
    elf: &Path,
    limit: Duration,
    talk: impl FnOnce(&Path) -> T,
) -> Result<(T, BoardRun)> {
    let (pty, bridge) = open(None)?;
    let path = pty.path.clone();
    let stop = Arc::new(AtomicBool::new(false));
    let options = MachineOptions {
        console_tee: Some(bridge.to_host.clone()),
        ..MachineOptions::default()
    };
    let drive = Drive::Pty {
        from_host: bridge.from_host,
        stop: stop.clone(),
    };
    let elf = elf.to_owned();
    let board = std::thread::spawn(move || run_board(&elf, &options, drive, false, limit, false));
    let talked = talk(&path);
    stop.store(true, Ordering::Relaxed);
    let run = board
        .join()
        .map_err(|_| anyhow::anyhow!("the board thread panicked"))??;
    drop(pty);
    Ok((talked, run))
}

/// The `--pty` console checked end to end on the board from `elf`: a host
/// program opens the PTY, types `version` and the G-code `$I`, and reads
/// both replies from the emulated board.
pub fn check_console(elf: &Path) -> Result<()> {
    const LIMIT: Duration = Duration::from_secs(30);
    let talk = |path: &Path| -> Result<String> {
        let (mut port, chunks) = connect(path)?;
        let deadline = Instant::now() + LIMIT;
        let mut text = String::new();
        port.write_all(b"version\r\n")?;
        read_until_ok(&chunks, &mut text, 0, deadline)?;
        let from = text.len();
        port.write_all(b"$I\r\n")?;
        read_until_ok(&chunks, &mut text, from, deadline)?;
        Ok(text)
    };
    let (talked, run) = with_board_on_pty(elf, LIMIT, talk)?;
    let text = talked?;
    if !text.contains("[VER:") {
        bail!("`$I` on the PTY got no [VER:…] line: {text:?}");
    }
    let typed: Vec<&str> = run
        .terminal
        .lines
        .iter()
        .filter_map(|(_, l)| l.strip_prefix("> "))
        .collect();
    if typed != ["version", "$I"] {
        bail!("the transcript's typed lines are {typed:?}");
    }
    if run.terminal.error_replies != 0 {
        bail!("error replies on the PTY: {text:?}");
    }
    Ok(())
}
