//! A console client for a serial device: the board's USB CDC port, or a
//! simulator's or QEMU board's pseudo-terminal. Raw mode (no echo, no line
//! editing, no CR/LF translation), lines written whole, replies read with
//! a deadline.

use std::fs::{File, OpenOptions};
use std::io::{Read, Write};
use std::os::fd::AsRawFd;
use std::os::unix::fs::OpenOptionsExt;
use std::path::Path;
use std::time::{Duration, Instant};

use anyhow::{Context, Result, bail};

/// An open console.
pub struct Console {
    port: File,
    /// Bytes read but not yet returned as a line.
    pending: Vec<u8>,
}

impl Console {
    /// Opens `path` read-write in raw mode (any baud rate: CDC ignores it).
    pub fn open(path: &Path) -> Result<Self> {
        let port = OpenOptions::new()
            .read(true)
            .write(true)
            .custom_flags(libc::O_NOCTTY | libc::O_NONBLOCK)
            .open(path)
            .with_context(|| format!("cannot open {}", path.display()))?;
        let fd = port.as_raw_fd();
        // SAFETY: `fd` is an open descriptor owned by `port`; termios is a
        // plain C struct filled by tcgetattr before it is read.
        unsafe {
            let mut termios: libc::termios = std::mem::zeroed();
            if libc::tcgetattr(fd, &mut termios) != 0 {
                bail!(
                    "{} is not a terminal: {}",
                    path.display(),
                    std::io::Error::last_os_error()
                );
            }
            libc::cfmakeraw(&mut termios);
            termios.c_cflag |= libc::CLOCAL | libc::CREAD;
            libc::cfsetspeed(&mut termios, libc::B115200);
            if libc::tcsetattr(fd, libc::TCSANOW, &termios) != 0 {
                bail!(
                    "tcsetattr on {}: {}",
                    path.display(),
                    std::io::Error::last_os_error()
                );
            }
        }
        Ok(Self {
            port,
            pending: Vec::new(),
        })
    }

    /// Writes `line` and a newline.
    pub fn send_line(&mut self, line: &str) -> Result<()> {
        let mut bytes = line.as_bytes().to_vec();
        bytes.push(b'\n');
        self.send_bytes(&bytes)
    }

    /// Writes `bytes` as they are (e.g. a grbl realtime byte).
    pub fn send_bytes(&mut self, bytes: &[u8]) -> Result<()> {
        let deadline = Instant::now() + Duration::from_secs(5);
        let mut written = 0;
        while written < bytes.len() {
            match self.port.write(&bytes[written..]) {
                Ok(n) => written += n,
                Err(e) if e.kind() == std::io::ErrorKind::WouldBlock => {
                    if Instant::now() > deadline {
                        bail!("the device does not take input (5 s)");
                    }
                    self.wait(libc::POLLOUT, Duration::from_millis(50))?;
                }
                Err(e) => return Err(e).context("write to the device"),
            }
        }
        Ok(())
    }

    /// The next whole line (without its line end) within `timeout`, or
    /// `None` when none arrived.
    pub fn read_line(&mut self, timeout: Duration) -> Result<Option<String>> {
        let deadline = Instant::now() + timeout;
        loop {
            if let Some(end) = self.pending.iter().position(|&b| b == b'\n') {
                let line: Vec<u8> = self.pending.drain(..=end).collect();
                let text = String::from_utf8_lossy(&line);
                return Ok(Some(text.trim_end_matches(['\r', '\n']).to_owned()));
            }
            let now = Instant::now();
            if now >= deadline {
                return Ok(None);
            }
            self.wait(libc::POLLIN, deadline - now)?;
            let mut buf = [0u8; 512];
            match self.port.read(&mut buf) {
                Ok(0) => {}
                Ok(n) => self.pending.extend_from_slice(&buf[..n]),
                Err(e) if e.kind() == std::io::ErrorKind::WouldBlock => {}
                Err(e) => return Err(e).context("read from the device"),
            }
        }
    }

    /// Sends `command` and reads its reply: the data lines and the closer
    /// (`ok` or `error…`), skipping notices (`[…]`) and the grbl banner.
    pub fn command(&mut self, command: &str, timeout: Duration) -> Result<(Vec<String>, String)> {
        self.send_line(command)?;
        let deadline = Instant::now() + timeout;
        let mut data = Vec::new();
        loop {
            let left = deadline.saturating_duration_since(Instant::now());
            let Some(line) = self.read_line(left)? else {
                bail!(
                    "no reply to {command:?} within {:.1} s",
                    timeout.as_secs_f64()
                );
            };
            if line.starts_with('[') || line.starts_with("Grbl ") || line.is_empty() {
                continue;
            }
            if line == "ok" || line.starts_with("error") {
                return Ok((data, line));
            }
            data.push(line);
        }
    }

    /// Reads and drops whatever arrives within `quiet` of the last byte.
    pub fn drain(&mut self, quiet: Duration) -> Result<()> {
        while self.read_line(quiet)?.is_some() {}
        self.pending.clear();
        Ok(())
    }

    fn wait(&self, events: i16, timeout: Duration) -> Result<()> {
        let mut fd = libc::pollfd {
            fd: self.port.as_raw_fd(),
            events,
            revents: 0,
        };
        let ms = i32::try_from(timeout.as_millis()).unwrap_or(i32::MAX);
        // SAFETY: one valid pollfd for the duration of the call.
        let n = unsafe { libc::poll(&mut fd, 1, ms) };
        if n < 0 {
            let err = std::io::Error::last_os_error();
            if err.kind() != std::io::ErrorKind::Interrupted {
                return Err(err).context("poll on the device");
            }
        }
        Ok(())
    }
}
