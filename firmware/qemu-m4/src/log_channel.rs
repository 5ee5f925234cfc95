//! The log channel on UART2: plain text, one line per record, each
//! stamped with the board's time in µs (embassy-time):
//!
//! ```text
//! 1234567 INFO console: host connected     (laser-app's logs, `log` crate)
//! 1234600 @laser 1 300                      (the laser lit at 300 ‰; `@laser 0` dark)
//! 1300000 @leds heartbeat=1 laser=1 fault=0 (the status LEDs changed)
//! ```
//!
//! `cargo xtask qemu` reads it from QEMU's socket, prints the log lines and
//! records the `@` events. Lines are written whole inside a critical
//! section (from tasks, interrupt handlers or the fault handlers alike), so
//! they never interleave.

use core::fmt::{self, Write};

use embassy_time::Instant;

use crate::uart::UART2;

/// Writes into the UART byte by byte.
struct LogWriter;

impl Write for LogWriter {
    fn write_str(&mut self, s: &str) -> fmt::Result {
        for &b in s.as_bytes() {
            UART2.write_blocking(b);
        }
        Ok(())
    }
}

/// Writes one line: the time, then `args`.
pub fn line(args: fmt::Arguments<'_>) {
    let t_us = Instant::now().as_micros();
    critical_section::with(|_| {
        // The writer cannot fail.
        let _ = writeln!(LogWriter, "{t_us} {args}");
    });
}

/// laser-app's log records, on the channel.
struct ChannelLogger;

impl log::Log for ChannelLogger {
    fn enabled(&self, metadata: &log::Metadata<'_>) -> bool {
        metadata.level() <= log::Level::Info
    }

    fn log(&self, record: &log::Record<'_>) {
        if self.enabled(record.metadata()) {
            line(format_args!("{} {}", record.level(), record.args()));
        }
    }

    fn flush(&self) {}
}

static LOGGER: ChannelLogger = ChannelLogger;

/// Sends laser-app's logs (info and above) to the channel.
pub fn init() {
    // Only fails when a logger is set already, which is then this one.
    let _ = log::set_logger(&LOGGER);
    log::set_max_level(log::LevelFilter::Info);
}
