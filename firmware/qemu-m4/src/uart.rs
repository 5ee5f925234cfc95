//! Interrupt-driven driver of the MPS2's CMSDK APB UARTs, implementing
//! `embedded-io-async`'s `Read` and `Write`.
//!
//! Receive: the UART holds one byte. Its interrupt handler clears the
//! interrupt first, then moves every byte it holds into a ring; when the
//! ring is full it turns the receive interrupt off and leaves the byte in
//! the UART (QEMU then holds further input back: nothing is lost), and the
//! reader turns it on again after making room and draining the UART.
//! Transmit: bytes go straight to the data register while it has room;
//! when it is full the writer waits for the transmit interrupt.

use core::cell::RefCell;
use core::convert::Infallible;
use core::future::poll_fn;
use core::task::{Context, Poll};

use critical_section::{CriticalSection, Mutex};
use embassy_sync::waitqueue::WakerRegistration;

use crate::interrupts::{self, Irq};
use crate::mmio::Reg;

/// Bytes a UART's receive ring holds.
pub const RX_RING_BYTES: usize = 256;
/// The peripheral clock divided by the baud rate QEMU is told (115200 baud
/// at 25 MHz; QEMU sends at host speed whatever the divisor, but refuses a
/// divisor below 16).
const BAUD_DIVISOR: u32 = 217;

/// STATE: transmit buffer full.
const STATE_TX_FULL: u32 = 1 << 0;
/// STATE: receive buffer full.
const STATE_RX_FULL: u32 = 1 << 1;
/// CTRL: transmitter on.
const CTRL_TX_ENABLE: u32 = 1 << 0;
/// CTRL: receiver on.
const CTRL_RX_ENABLE: u32 = 1 << 1;
/// CTRL (and INTSTATUS/INTCLEAR): transmit interrupt.
const CTRL_TX_IRQ: u32 = 1 << 2;
/// CTRL (and INTSTATUS/INTCLEAR): receive interrupt.
const CTRL_RX_IRQ: u32 = 1 << 3;
/// INTCLEAR: transmit.
const INT_TX: u32 = 1 << 0;
/// INTCLEAR: receive.
const INT_RX: u32 = 1 << 1;

/// One UART's registers.
#[derive(Debug, Clone, Copy)]
struct Regs {
    base: usize,
}

impl Regs {
    const fn data(self) -> Reg {
        Reg(self.base)
    }
    const fn state(self) -> Reg {
        Reg(self.base + 0x04)
    }
    const fn ctrl(self) -> Reg {
        Reg(self.base + 0x08)
    }
    /// INTSTATUS on read, INTCLEAR on write.
    const fn int(self) -> Reg {
        Reg(self.base + 0x0C)
    }
    const fn bauddiv(self) -> Reg {
        Reg(self.base + 0x10)
    }
}

/// What the interrupt handlers share with the driver.
struct Shared {
    ring: [u8; RX_RING_BYTES],
    /// Index of the oldest byte.
    head: usize,
    /// Bytes in the ring.
    len: usize,
    rx_waker: WakerRegistration,
    tx_waker: WakerRegistration,
}

impl Shared {
    const fn new() -> Self {
        Self {
            ring: [0; RX_RING_BYTES],
            head: 0,
            len: 0,
            rx_waker: WakerRegistration::new(),
            tx_waker: WakerRegistration::new(),
        }
    }

    /// Moves the bytes the UART holds into the ring while there is room;
    /// whether the ring still has room.
    fn drain(&mut self, regs: Regs) -> bool {
        while regs.state().read() & STATE_RX_FULL != 0 {
            if self.len == RX_RING_BYTES {
                return false;
            }
            let tail = (self.head + self.len) % RX_RING_BYTES;
            self.ring[tail] = regs.data().read() as u8;
            self.len += 1;
        }
        true
    }

    /// Copies up to `buf.len()` bytes out of the ring.
    fn take(&mut self, buf: &mut [u8]) -> usize {
        let n = buf.len().min(self.len);
        for slot in buf.iter_mut().take(n) {
            *slot = self.ring[self.head];
            self.head = (self.head + 1) % RX_RING_BYTES;
        }
        self.len -= n;
        n
    }
}

/// One UART: its registers, its interrupt lines and the state its
/// handlers share.
pub struct UartState {
    regs: Regs,
    rx_irq: Irq,
    tx_irq: Irq,
    shared: Mutex<RefCell<Shared>>,
}

impl UartState {
    const fn new(base: usize, rx_irq: Irq, tx_irq: Irq) -> Self {
        Self {
            regs: Regs { base },
            rx_irq,
            tx_irq,
            shared: Mutex::new(RefCell::new(Shared::new())),
        }
    }

    fn with<R>(&self, f: impl FnOnce(CriticalSection<'_>, &mut Shared) -> R) -> R {
        critical_section::with(|cs| f(cs, &mut self.shared.borrow(cs).borrow_mut()))
    }

    /// Receive interrupt: clear it, then drain the UART into the ring.
    fn on_rx(&self) {
        self.regs.int().write(INT_RX);
        self.with(|_, s| {
            if !s.drain(self.regs) {
                self.regs.ctrl().clear_bits(CTRL_RX_IRQ);
            }
            s.rx_waker.wake();
        });
    }

    /// Transmit interrupt: room in the UART again.
    fn on_tx(&self) {
        self.regs.int().write(INT_TX);
        self.regs.ctrl().clear_bits(CTRL_TX_IRQ);
        self.with(|_, s| s.tx_waker.wake());
    }

    /// Enables the transmitter only (no interrupts): for a polled output.
    #[cfg(feature = "defmt-log")]
    pub fn enable_tx(&self) {
        self.regs.ctrl().set_bits(CTRL_TX_ENABLE);
    }

    /// Writes `byte`, waiting (spinning) while the UART is full: for the
    /// log channel, which must work from any context.
    pub fn write_blocking(&self, byte: u8) {
        while self.regs.state().read() & STATE_TX_FULL != 0 {}
        self.regs.data().write(u32::from(byte));
    }
}

/// UART0: the console.
pub static UART0: UartState = UartState::new(0x4000_4000, Irq::Uart0Rx, Irq::Uart0Tx);
/// UART1: the FashionStar servo bus.
pub static UART1: UartState = UartState::new(0x4000_5000, Irq::Uart1Rx, Irq::Uart1Tx);
/// UART3: laser-app's defmt logs (feature `defmt-log`; out only, polled:
/// its interrupts are never enabled, so the lines named here are unused).
#[cfg(feature = "defmt-log")]
pub static UART3: UartState = UartState::new(0x4000_7000, Irq::Uart2Rx, Irq::Uart2Tx);
/// UART2: the log channel (out) and the stop button (in).
pub static UART2: UartState = UartState::new(0x4000_6000, Irq::Uart2Rx, Irq::Uart2Tx);
/// UART4: the PELCO port (the STM32 board's RS-485 USART3).
pub static UART4: UartState = UartState::new(0x4000_9000, Irq::Uart4Rx, Irq::Uart4Tx);

/// The peripheral clock the baud divisor divides, Hz.
const PCLK_HZ: u32 = 25_000_000;

/// A UART, started (115200 baud as far as QEMU cares, both directions on,
/// receive interrupt on).
#[derive(Clone, Copy)]
pub struct Uart {
    state: &'static UartState,
}

impl Uart {
    /// Starts `state`'s UART and enables its interrupt lines.
    pub fn start(state: &'static UartState) -> Self {
        let regs = state.regs;
        regs.ctrl().write(0);
        regs.bauddiv().write(BAUD_DIVISOR);
        regs.int().write(INT_TX | INT_RX);
        regs.ctrl()
            .write(CTRL_TX_ENABLE | CTRL_RX_ENABLE | CTRL_RX_IRQ);
        interrupts::enable(state.rx_irq);
        interrupts::enable(state.tx_irq);
        Self { state }
    }
}

impl laser_app::pelco::PelcoLine for Uart {
    /// Sets the divisor for `baud` (QEMU sends at host speed whatever it
    /// is; the register holds what a real CMSDK UART would need).
    fn set_baud(&mut self, baud: u32) {
        let divisor = PCLK_HZ.checked_div(baud).unwrap_or(BAUD_DIVISOR).max(16);
        self.state.regs.bauddiv().write(divisor);
    }
}

impl embedded_io_async::ErrorType for Uart {
    type Error = Infallible;
}

impl embedded_io_async::Read for Uart {
    async fn read(&mut self, buf: &mut [u8]) -> Result<usize, Infallible> {
        if buf.is_empty() {
            return Ok(0);
        }
        let state = self.state;
        let n = poll_fn(|cx| {
            state.with(|_, s| {
                s.rx_waker.register(cx.waker());
                let n = s.take(buf);
                // Room again: take what the UART holds, then let its
                // interrupt in again.
                if s.drain(state.regs) {
                    state.regs.ctrl().set_bits(CTRL_RX_IRQ);
                }
                if n > 0 { Poll::Ready(n) } else { Poll::Pending }
            })
        })
        .await;
        Ok(n)
    }
}

impl UartState {
    /// `Ready` when the UART has room for a byte; otherwise the transmit
    /// interrupt is on and the waker registered.
    ///
    /// QEMU's UART raises the transmit interrupt only for a byte that
    /// leaves while the interrupt is enabled, and a byte can leave (on
    /// QEMU's I/O thread) between reading STATE and enabling it: so after
    /// enabling, STATE is read again, and a UART with room is reported at
    /// once instead of waiting for an interrupt that never comes.
    fn poll_room(&self, cx: &mut Context<'_>, s: &mut Shared) -> Poll<()> {
        if self.regs.state().read() & STATE_TX_FULL == 0 {
            return Poll::Ready(());
        }
        s.tx_waker.register(cx.waker());
        self.regs.ctrl().set_bits(CTRL_TX_IRQ);
        if self.regs.state().read() & STATE_TX_FULL != 0 {
            return Poll::Pending;
        }
        self.regs.ctrl().clear_bits(CTRL_TX_IRQ);
        Poll::Ready(())
    }

    /// Writes what fits into the UART (at least one byte of a non-empty
    /// `buf`), or `Pending` while it is full.
    fn poll_write(&self, cx: &mut Context<'_>, buf: &[u8]) -> Poll<usize> {
        self.with(|_, s| {
            if self.poll_room(cx, s).is_pending() {
                return Poll::Pending;
            }
            let mut n = 0;
            while n < buf.len() && self.regs.state().read() & STATE_TX_FULL == 0 {
                self.regs.data().write(u32::from(buf[n]));
                n += 1;
            }
            Poll::Ready(n)
        })
    }
}

impl embedded_io_async::Write for Uart {
    async fn write(&mut self, buf: &[u8]) -> Result<usize, Infallible> {
        if buf.is_empty() {
            return Ok(0);
        }
        let state = self.state;
        Ok(poll_fn(|cx| state.poll_write(cx, buf)).await)
    }

    /// Waits until the UART has room again (QEMU sends each byte as it is
    /// written, so room means sent).
    async fn flush(&mut self) -> Result<(), Infallible> {
        let state = self.state;
        poll_fn(|cx| state.with(|_, s| state.poll_room(cx, s))).await;
        Ok(())
    }
}

/// UART0 receive interrupt.
pub unsafe extern "C" fn uart0_rx() {
    UART0.on_rx();
}
/// UART0 transmit interrupt.
pub unsafe extern "C" fn uart0_tx() {
    UART0.on_tx();
}
/// UART1 receive interrupt.
pub unsafe extern "C" fn uart1_rx() {
    UART1.on_rx();
}
/// UART1 transmit interrupt.
pub unsafe extern "C" fn uart1_tx() {
    UART1.on_tx();
}
/// UART2 receive interrupt.
pub unsafe extern "C" fn uart2_rx() {
    UART2.on_rx();
}
/// UART2 transmit interrupt.
pub unsafe extern "C" fn uart2_tx() {
    UART2.on_tx();
}
/// UART4 receive interrupt.
pub unsafe extern "C" fn uart4_rx() {
    UART4.on_rx();
}
/// UART4 transmit interrupt.
pub unsafe extern "C" fn uart4_tx() {
    UART4.on_tx();
}
