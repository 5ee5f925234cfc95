//! The simulated board's PELCO port (`cargo xtask sim --pelco-pty
//! [PATH]`): the RS-485 UART of the target, here a pseudo-terminal that a
//! PELCO-D / PELCO-P client (PTZ software, a PyPI library over pyserial, a
//! CCTV keyboard on a USB–RS-485 adapter bridged to it) opens as its
//! serial port.
//!
//! The bytes go through the same threads as the console's PTY
//! ([`crate::pty::PtyBridge`]; the simulator keeps the slave side open, so
//! a client may close and reopen the port). The firmware's PELCO task
//! reads and writes the two halves as it does the target's USART3; the
//! baud rate it sets is recorded (a PTY has none).

use std::cell::RefCell;
use std::convert::Infallible;
use std::path::PathBuf;
use std::rc::Rc;
use std::sync::mpsc::{Receiver, SyncSender, TryRecvError, TrySendError};

use embassy_time::Timer;
use laser_app::pelco::PelcoLine;

/// How often an idle half looks at its channel again, µs of simulated
/// (real) time: 0.5 ms, a twentieth of a byte at 19 200 baud.
const POLL_US: u64 = 500;

/// What crossed the PELCO port, each chunk at its simulated time (the
/// client's bytes when the firmware read them, the firmware's when it
/// wrote them).
#[derive(Debug, Clone, Default)]
pub struct PelcoTraffic {
    /// Bytes the firmware read: (µs, bytes).
    pub received: Vec<(u64, Vec<u8>)>,
    /// Bytes the firmware wrote: (µs, bytes).
    pub sent: Vec<(u64, Vec<u8>)>,
    /// The baud rate the firmware set (none yet).
    pub baud: Option<u32>,
}

/// The traffic record the port's halves share with the run's report.
pub type SharedTraffic = Rc<RefCell<PelcoTraffic>>;

/// Where the PELCO port appears.
#[derive(Debug, Clone, Default)]
pub struct PelcoPtyOptions {
    /// Also make this path a symlink to the PTY's device.
    pub link: Option<PathBuf>,
}

/// Bytes from the client (the port's receive half).
pub struct PelcoRx {
    from_host: Receiver<Vec<u8>>,
    /// Received bytes not read yet.
    pending: Vec<u8>,
    traffic: SharedTraffic,
    /// The PTY, kept open as long as the port lives.
    #[cfg(unix)]
    _pty: Option<crate::pty::Pty>,
}

/// Bytes to the client (the port's transmit half) and the line's baud
/// rate.
pub struct PelcoTx {
    to_host: SyncSender<Vec<u8>>,
    traffic: SharedTraffic,
}

/// The port's two halves over a pair of byte channels (`from_host`: the
/// client's bytes; `to_host`: the device's), recording into `traffic`.
pub fn port(
    from_host: Receiver<Vec<u8>>,
    to_host: SyncSender<Vec<u8>>,
    traffic: SharedTraffic,
) -> (PelcoRx, PelcoTx) {
    (
        PelcoRx {
            from_host,
            pending: Vec::new(),
            traffic: traffic.clone(),
            #[cfg(unix)]
            _pty: None,
        },
        PelcoTx { to_host, traffic },
    )
}

/// Opens the PELCO port on a new PTY (printing its path, making the
/// symlink when asked).
#[cfg(unix)]
pub fn open_on_pty(
    options: &PelcoPtyOptions,
    traffic: SharedTraffic,
) -> anyhow::Result<(PelcoRx, PelcoTx)> {
    let pty = crate::pty::open()?;
    if let Some(link) = &options.link {
        crate::pty::link_to(link, &pty.path)?;
    }
    let bridge = crate::pty::PtyBridge::start(&pty)?;
    eprintln!("xtask sim: PELCO port on {}", pty.path.display());
    let (mut rx, tx) = port(bridge.from_host, bridge.to_host, traffic);
    rx._pty = Some(pty);
    Ok((rx, tx))
}

impl embedded_io_async::ErrorType for PelcoRx {
    type Error = Infallible;
}

impl embedded_io_async::Read for PelcoRx {
    /// Waits for the client's next bytes (forever once the PTY is gone).
    async fn read(&mut self, buf: &mut [u8]) -> Result<usize, Infallible> {
        if buf.is_empty() {
            return Ok(0);
        }
        while self.pending.is_empty() {
            match self.from_host.try_recv() {
                Ok(bytes) => {
                    let t = crate::clock::now_us();
                    self.traffic.borrow_mut().received.push((t, bytes.clone()));
                    self.pending = bytes;
                }
                Err(TryRecvError::Empty | TryRecvError::Disconnected) => {
                    Timer::after_micros(POLL_US).await
                }
            }
        }
        let n = buf.len().min(self.pending.len());
        buf[..n].copy_from_slice(&self.pending[..n]);
        self.pending.drain(..n);
        Ok(n)
    }
}

impl embedded_io_async::ErrorType for PelcoTx {
    type Error = Infallible;
}

impl embedded_io_async::Write for PelcoTx {
    /// Hands `buf` to the writer thread (waits while its channel is full;
    /// dropped once the PTY is gone, as on a bus nobody listens to).
    async fn write(&mut self, buf: &[u8]) -> Result<usize, Infallible> {
        let mut bytes = buf.to_vec();
        let t = crate::clock::now_us();
        self.traffic.borrow_mut().sent.push((t, bytes.clone()));
        loop {
            match self.to_host.try_send(bytes) {
                Ok(()) | Err(TrySendError::Disconnected(_)) => return Ok(buf.len()),
                Err(TrySendError::Full(back)) => {
                    bytes = back;
                    Timer::after_micros(POLL_US).await;
                }
            }
        }
    }

    async fn flush(&mut self) -> Result<(), Infallible> {
        Ok(())
    }
}

impl PelcoLine for PelcoTx {
    fn set_baud(&mut self, baud: u32) {
        log::info!("PELCO port at {baud} baud (8N1)");
        self.traffic.borrow_mut().baud = Some(baud);
    }
}

#[cfg(test)]
mod tests {
    use embedded_io_async::{Read, Write};

    use super::*;

    #[test]
    fn bytes_pass_both_ways_in_order() {
        let (host_tx, from_host) = std::sync::mpsc::sync_channel(4);
        let (to_host, device_rx) = std::sync::mpsc::sync_channel(4);
        let traffic = SharedTraffic::default();
        let (mut rx, mut tx) = port(from_host, to_host, traffic.clone());
        host_tx.send(vec![0xFF, 0x01, 0x00]).unwrap();
        host_tx.send(vec![0x00, 0x00, 0x00, 0x01]).unwrap();
        let mut got = Vec::new();
        let mut buf = [0u8; 2];
        while got.len() < 7 {
            let n = embassy_futures::block_on(rx.read(&mut buf)).unwrap();
            got.extend_from_slice(&buf[..n]);
        }
        assert_eq!(got, [0xFF, 0x01, 0x00, 0x00, 0x00, 0x00, 0x01]);
        embassy_futures::block_on(tx.write_all(&[0xFF, 0x01, 0x00, 0x59])).unwrap();
        assert_eq!(device_rx.try_recv().unwrap(), [0xFF, 0x01, 0x00, 0x59]);
        tx.set_baud(4800);
        let traffic = traffic.borrow();
        assert_eq!(traffic.baud, Some(4800));
        assert_eq!(traffic.received.len(), 2);
        assert_eq!(traffic.sent, [(0, vec![0xFF, 0x01, 0x00, 0x59])]);
    }
}
