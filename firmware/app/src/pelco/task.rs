//! The PELCO port's task body: bytes in, frames through the session, the
//! session's commands through the console's command channel, replies out.

use ::pelco::Decoder;
use embassy_futures::select::{Either, select};
use embassy_time::{Duration, Instant, Timer};
use embedded_io_async::{Read, Write};

use super::session::{Request, Session, View};
use crate::command::{Command, CommandLink, PresetCommand, RealtimeRequest};
use crate::grbl::realtime::Realtime;
use crate::log;
use crate::outbound::{LineKind, QuietReply};
use crate::settings::find_param;
use crate::status::StatusBoard;

/// How often the task looks whether the command slot is free, or its
/// command closed.
const POLL: Duration = Duration::from_millis(1);
/// Longest wait for a command's reply before the port gives up on it.
const REPLY_TIMEOUT: Duration = Duration::from_secs(2);
/// Longest wait for the status to show a goto's point.
const SHOW_LIMIT: Duration = Duration::from_millis(100);
/// Most requests one frame or tick gives (stop + goto, or the jogs of
/// [`super::session::LEAD_MS`]).
const MAX_REQUESTS: usize = 4;

/// The PELCO port's line (on a board, the transmit half of its UART): the
/// baud rate, set by the port task once it has read the saved
/// `pelco.baud`.
pub trait PelcoLine {
    /// Runs the line at `baud` (one of
    /// [`PELCO_BAUDS`](crate::settings::PELCO_BAUDS)), 8N1.
    fn set_baud(&mut self, baud: u32);
}

/// The PELCO port: its receive and transmit halves and the links.
pub struct PelcoTask<R, W> {
    /// Bytes from the bus.
    pub rx: R,
    /// Bytes to the bus (the board drives its RS-485 driver-enable).
    pub tx: W,
    /// The console's command channel (shared with the console).
    pub link: &'static CommandLink,
    /// Where the spot is.
    pub status: &'static StatusBoard,
}

/// The settings the port reads at start (through `get`).
#[derive(Debug, Clone, Copy)]
struct PortSettings {
    address: u8,
    baud: u32,
    timeout_s: f64,
    oq_cm: f64,
}

impl<R: Read, W: Write + PelcoLine> PelcoTask<R, W> {
    /// Reads its settings, sets the line's baud rate, then serves the bus
    /// forever.
    pub async fn run(mut self) -> ! {
        let settings = self.settings().await;
        self.tx.set_baud(settings.baud);
        log::info!(
            "pelco: address {} at {} baud",
            settings.address,
            settings.baud
        );
        let mut decoder = Decoder::new(settings.address);
        let mut session = Session::new();
        session.set_motion_timeout_ms((settings.timeout_s * 1000.0) as u64);
        self.link.pelco.set_address(settings.address);
        let mut buf = [0u8; 16];
        loop {
            let tick = session.next_tick_ms();
            let timer = async {
                match tick {
                    Some(ms) => Timer::at(Instant::from_millis(ms)).await,
                    None => core::future::pending::<()>().await,
                }
            };
            let mut requests = heapless::Vec::<Request, MAX_REQUESTS>::new();
            let mut push = |r: Request| {
                if requests.push(r).is_err() {
                    log::warning!("pelco: request dropped");
                }
            };
            match select(self.rx.read(&mut buf), timer).await {
                Either::First(Ok(n)) => {
                    for &b in buf.get(..n).unwrap_or(&[]) {
                        if let Some(frame) = decoder.feed(b) {
                            self.link.pelco.note_frame(&frame);
                            session.on_frame(&frame, self.view(settings), &mut push);
                        }
                    }
                    self.link.pelco.publish(decoder.counters());
                }
                Either::First(Err(_)) => {
                    log::warning!("pelco: read error");
                    Timer::after(POLL).await;
                }
                Either::Second(()) => session.on_tick(self.view(settings), &mut push),
            }
            for request in requests {
                self.carry_out(request).await;
            }
        }
    }

    fn view(&self, settings: PortSettings) -> View {
        View {
            now_ms: Instant::now().as_millis(),
            at: self.aimed(),
            oq_cm: settings.oq_cm,
        }
    }

    async fn carry_out(&mut self, request: Request) {
        match request {
            Request::Command(command) => {
                let before = self.aimed();
                let reply = send_quietly(self.link, command).await;
                let done = reply.as_ref().is_some_and(|r| r.closed == Some(true));
                if !done {
                    let why = reply.as_ref().map_or("no reply", |r| r.data.as_str());
                    log::debug!("pelco: {} refused: {}", command.name(), why);
                } else if let Command::Goto(point) = command {
                    self.until_shown(|aimed| aimed == Some(point)).await;
                } else if let Command::Preset(PresetCommand::Goto(_)) = command {
                    // The preset's point is in the settings flash: wait
                    // for the aim to change (or the limit, when the spot
                    // is there already).
                    self.until_shown(|aimed| aimed != before).await;
                }
            }
            Request::JogCancel => {
                let cancel = RealtimeRequest {
                    command: Realtime::JogCancel,
                    rx_free_bytes: crate::grbl::RX_BUFFER_BYTES as u16,
                };
                if self.link.realtime.try_send(cancel).is_err() {
                    log::warning!("pelco: realtime queue full");
                }
            }
            Request::Reply(frame) => {
                let sent = self.tx.write_all(frame.encode().as_slice()).await;
                if sent.is_err() || self.tx.flush().await.is_err() {
                    log::warning!("pelco: reply not sent");
                }
            }
        }
    }

    /// Waits until `shown` holds for the point the status shows as aimed
    /// (the sequencer publishes it after a goto's reply, once its servo
    /// moves are out), at most [`SHOW_LIMIT`]: the next frame's angles
    /// (an absolute tilt after an absolute pan keeps the new pan) start
    /// from it.
    async fn until_shown(&self, shown: impl Fn(Option<crate::domain::PointCm>) -> bool) {
        let deadline = Instant::now() + SHOW_LIMIT;
        while Instant::now() < deadline {
            if shown(self.aimed()) {
                return;
            }
            Timer::after(POLL).await;
        }
    }

    /// The board point the status shows as aimed, if any.
    fn aimed(&self) -> Option<crate::domain::PointCm> {
        self.status.snapshot().target.map(|(t, _)| t.point)
    }

    /// The port's settings, read like `get` does.
    async fn settings(&self) -> PortSettings {
        let defaults = crate::settings::Settings::default();
        let read = async |name: &str, default: f64| {
            let Some(param) = find_param(name) else {
                return default;
            };
            send_quietly(self.link, Command::Get(param))
                .await
                .and_then(|r| param_value(&r.data))
                .unwrap_or(default)
        };
        let address = read("pelco.address", f64::from(defaults.pelco.address)).await;
        let baud = read("pelco.baud", defaults.pelco.baud).await;
        PortSettings {
            address: (address as u8).max(1),
            baud: baud_of(baud),
            timeout_s: read("pelco.timeout_s", defaults.pelco.motion_timeout_s).await,
            oq_cm: read("oq_cm", defaults.oq_cm).await,
        }
    }
}

/// Sends `command` through the command channel when no other command is in
/// flight, its reply kept from the console's host; waits for the reply
/// (`None` when none came within `REPLY_TIMEOUT`).
pub async fn send_quietly(link: &CommandLink, command: Command) -> Option<QuietReply> {
    while !link.outbound.begin_quiet_command() {
        Timer::after(POLL).await;
    }
    if link.commands.try_send(command).is_err() {
        // Close it ourselves (kept quiet like the reply would be).
        link.outbound.push(LineKind::Error, "busy");
        return None;
    }
    let deadline = Instant::now() + REPLY_TIMEOUT;
    while Instant::now() < deadline {
        if let Some(reply) = link.outbound.take_quiet_reply() {
            return Some(reply);
        }
        Timer::after(POLL).await;
    }
    log::warning!("pelco: no reply to {}", command.name());
    None
}

/// The line rate of the `pelco.baud` value `value` (the default 9600 for
/// one the port does not run at: the parameter's range check keeps them
/// out of the settings).
fn baud_of(value: f64) -> u32 {
    crate::settings::PELCO_BAUDS
        .into_iter()
        .find(|b| f64::from(*b) == value)
        .unwrap_or(9600)
}

/// The value of a `get` line (`name = value  # help …`).
fn param_value(line: &str) -> Option<f64> {
    let (_, rest) = line.split_once('=')?;
    // The firmware's own parser: core's would link its 10 KB table.
    crate::text::decimal::parse_f64(rest.split_whitespace().next()?.as_bytes())
}
