//! The sequencer task body: receives commands from the command channel and
//! answers each with exactly one closing reply.

use embassy_time::Instant;

use crate::build_info;
use crate::cli::parse::HELP_LINES;
use crate::command::{Command, CommandLink};
use crate::log;

/// Runs the sequencer forever: one command at a time, in arrival order.
pub async fn run_sequencer(link: &CommandLink) -> ! {
    let booted_at = Instant::now();
    loop {
        let command = link.commands.receive().await;
        log::debug!("command: {:?}", command);
        match command {
            Command::Help => {
                for line in HELP_LINES {
                    link.data(format_args!("{line}")).await;
                }
                link.ok().await;
            }
            Command::Version => {
                link.data(format_args!(
                    "{} {} (git {}, {} build for {})",
                    build_info::PRODUCT,
                    build_info::VERSION,
                    build_info::GIT_REV,
                    build_info::PROFILE,
                    build_info::TARGET
                ))
                .await;
                link.ok().await;
            }
            Command::Status => {
                let uptime_ms = booted_at.elapsed().as_millis();
                link.data(format_args!(
                    "uptime: {}.{:03} s",
                    uptime_ms / 1000,
                    uptime_ms % 1000
                ))
                .await;
                link.data(format_args!(
                    "build: {} {} git {} {}",
                    build_info::PRODUCT,
                    build_info::VERSION,
                    build_info::GIT_REV,
                    build_info::PROFILE
                ))
                .await;
                link.ok().await;
            }
        }
    }
}
