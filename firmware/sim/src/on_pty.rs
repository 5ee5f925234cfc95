//! The simulator serving its console on a pseudo-terminal, in real time, on
//! a thread of its own: for tests and tools that talk to it as to a board
//! over a serial port.

use std::path::PathBuf;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use anyhow::{Result, bail};

use crate::pty::PtyOptions;
use crate::world::{SimOptions, SimReport, run};

/// How long the PTY may take to appear.
const START_LIMIT: Duration = Duration::from_secs(20);

/// A simulation running with its console on a PTY.
pub struct SimOnPty {
    /// The symlink to the PTY's device: open it as the board's port.
    pub link: PathBuf,
    stop: Arc<AtomicBool>,
    thread: JoinHandle<SimReport>,
}

impl SimOnPty {
    /// Starts `options` (its `pty` and `realtime` set here) with the
    /// console on a PTY linked at `link`; returns once the link exists
    /// (and the PELCO port's, when `options` asks for one with a link).
    pub fn start(link: PathBuf, options: SimOptions) -> Result<Self> {
        let stop = Arc::new(AtomicBool::new(false));
        let _ = std::fs::remove_file(&link);
        let pelco_link = options.pelco_pty.as_ref().and_then(|p| p.link.clone());
        if let Some(pelco) = &pelco_link {
            let _ = std::fs::remove_file(pelco);
        }
        let options = SimOptions {
            pty: Some(PtyOptions {
                link: Some(link.clone()),
                stop: stop.clone(),
            }),
            realtime: true,
            ..options
        };
        let thread = std::thread::spawn(move || run(options));
        let started = Instant::now();
        for link in std::iter::once(&link).chain(&pelco_link) {
            while !link.exists() {
                if started.elapsed() > START_LIMIT || thread.is_finished() {
                    stop.store(true, Ordering::Relaxed);
                    bail!("the simulator's PTY did not appear at {}", link.display());
                }
                std::thread::sleep(Duration::from_millis(10));
            }
        }
        Ok(Self { link, stop, thread })
    }

    /// Ends the run: its report.
    pub fn finish(self) -> SimReport {
        self.stop.store(true, Ordering::Relaxed);
        match self.thread.join() {
            Ok(report) => report,
            Err(panic) => std::panic::resume_unwind(panic),
        }
    }
}
