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
        // Every file the run publishes is there before `start` returns (a
        // caller reading the spot feed at once found none under load).
        let published: Vec<PathBuf> = pelco_link
            .iter()
            .chain(&options.spot_feed)
            .cloned()
            .collect();
        for path in &published {
            let _ = std::fs::remove_file(path);
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
        for path in std::iter::once(&link).chain(&published) {
            while !path.exists() {
                if started.elapsed() > START_LIMIT || thread.is_finished() {
                    stop.store(true, Ordering::Relaxed);
                    bail!("the simulator's {} did not appear", path.display());
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_spot_feed_is_there_when_start_returns() {
        let dir = std::env::temp_dir().join(format!("laser-sim-on-pty-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let link = dir.join("console");
        let feed = crate::spot_feed::beside(&link);
        // A stale feed of an earlier run must not count.
        std::fs::write(&feed, "stale\n").unwrap();
        let sim = SimOnPty::start(
            link,
            SimOptions {
                spot_feed: Some(feed.clone()),
                max_time_ms: 60_000,
                ..SimOptions::default()
            },
        )
        .unwrap();
        let sample = crate::spot_feed::FeedSample::read(&feed);
        sim.finish();
        assert!(sample.is_ok(), "{sample:?}");
        let _ = std::fs::remove_dir_all(&dir);
    }
}
