//! A `log` backend for the simulator: `[  t_ms LEVEL] message` on stderr,
//! stamped with the simulated clock, like defmt's uptime stamps.

use std::sync::OnceLock;

use log::{Level, LevelFilter, Log, Metadata, Record};

struct SimLogger {
    level: LevelFilter,
}

impl Log for SimLogger {
    fn enabled(&self, metadata: &Metadata<'_>) -> bool {
        metadata.level() <= self.level
    }

    fn log(&self, record: &Record<'_>) {
        if !self.enabled(record.metadata()) {
            return;
        }
        let t_ms = crate::clock::now_us() as f64 / 1000.0;
        let level = match record.level() {
            Level::Error => "ERROR",
            Level::Warn => "WARN ",
            Level::Info => "INFO ",
            Level::Debug => "DEBUG",
            Level::Trace => "TRACE",
        };
        eprintln!("[{t_ms:>10.3} {level}] {}", record.args());
    }

    fn flush(&self) {}
}

static LOGGER: OnceLock<SimLogger> = OnceLock::new();

/// Installs the logger once per process (later calls keep the first level).
pub fn init(level: LevelFilter) {
    let logger = LOGGER.get_or_init(|| SimLogger { level });
    if log::set_logger(logger).is_ok() {
        log::set_max_level(level);
    }
}
