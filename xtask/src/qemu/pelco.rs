//! The QEMU board's PELCO port (UART4) checked end to end, as `cargo
//! xtask test` runs it after the scenarios: absolute pan and tilt frames
//! in PELCO-D, then position queries in PELCO-D and PELCO-P, whose reply
//! frames must carry the angles asked for; a query for another address
//! gets no reply. (`cargo xtask qemu --pelco-pty` joins the same port to
//! a PTY for a real client.)

use std::io::{Read, Write};
use std::os::unix::net::UnixStream;
use std::path::Path;
use std::time::{Duration, Instant};

use anyhow::{Context, Result, bail};
use pelco::{Command as Pelco, Decoder, Protocol};

use super::machine::{Machine, MachineOptions};

/// How long the board may take to answer a query.
const REPLY_LIMIT: Duration = Duration::from_secs(3);
/// How long the gimbal may take to reach the asked angles.
const SETTLE: Duration = Duration::from_secs(2);
/// The angles asked, hundredths of a degree on the wire: pan 5° right,
/// tilt 3° up (PTZ tilt counts downwards).
const PAN: u16 = 500;
const TILT: u16 = 36_000 - 300;

/// Writes `command` to device 1 in `protocol`.
fn send(port: &mut UnixStream, command: Pelco, protocol: Protocol, address: u8) -> Result<()> {
    let frame = command.frame(protocol, address);
    port.write_all(frame.encode().as_slice())
        .context("writing to the PELCO socket")
}

/// The next reply frame's command, or `None` when none came in time.
fn reply(port: &mut UnixStream, decoder: &mut Decoder) -> Result<Option<Pelco>> {
    let deadline = Instant::now() + REPLY_LIMIT;
    let mut buf = [0u8; 16];
    while Instant::now() < deadline {
        port.set_read_timeout(Some(Duration::from_millis(100)))?;
        let n = match port.read(&mut buf) {
            Ok(n) => n,
            Err(e) if e.kind() == std::io::ErrorKind::WouldBlock => continue,
            Err(e) if e.kind() == std::io::ErrorKind::TimedOut => continue,
            Err(e) => return Err(e).context("reading the PELCO socket"),
        };
        let mut found = None;
        decoder.decode(&buf[..n], |f| found = Some(Pelco::of(&f)));
        if found.is_some() {
            return Ok(found);
        }
    }
    Ok(None)
}

/// Runs the check on a fresh board from `elf`.
pub fn check_port(elf: &Path) -> Result<()> {
    let machine = Machine::start(elf, &MachineOptions::default())?;
    let mut port = machine.pelco_port()?;
    let mut decoder = Decoder::new(1);
    send(&mut port, Pelco::SetPan(PAN), Protocol::D, 1)?;
    // The tilt keeps the pan the board aims at: after the pan's goto.
    std::thread::sleep(Duration::from_millis(200));
    send(&mut port, Pelco::SetTilt(TILT), Protocol::D, 1)?;
    std::thread::sleep(SETTLE);
    // Another device's query: no reply (a shared bus).
    send(&mut port, Pelco::QueryPan, Protocol::D, 2)?;
    if let Some(other) = reply(&mut port, &mut decoder)? {
        bail!("a query for device 2 was answered: {other:?}");
    }
    for protocol in [Protocol::D, Protocol::P] {
        // PELCO-P numbers devices from 0.
        let address = if protocol == Protocol::P { 0 } else { 1 };
        send(&mut port, Pelco::QueryPan, protocol, address)?;
        let pan = reply(&mut port, &mut decoder)?;
        send(&mut port, Pelco::QueryTilt, protocol, address)?;
        let tilt = reply(&mut port, &mut decoder)?;
        if pan != Some(Pelco::PanPosition(PAN)) || tilt != Some(Pelco::TiltPosition(TILT)) {
            bail!("{protocol:?} queries answered {pan:?}, {tilt:?} for pan {PAN}, tilt {TILT}");
        }
    }
    Ok(())
}
