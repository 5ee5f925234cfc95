//! The MPS2 AN386's interrupt lines this board uses (its vector table is
//! in `vectors.rs`). Lines as QEMU's `mps2-an386` wires them: UART n
//! receive at 2n and transmit at 2n + 1 (n = 0..2), UART3 at 18/19, UART4
//! at 20/21, APB timer 0 at 8, timer 1 at 9.

use cortex_m::interrupt::InterruptNumber;
use cortex_m::peripheral::NVIC;

/// An interrupt line of the board.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[repr(u16)]
pub enum Irq {
    /// UART0 (console) byte received.
    Uart0Rx = 0,
    /// UART0 byte sent.
    Uart0Tx = 1,
    /// UART1 (servo bus) byte received.
    Uart1Rx = 2,
    /// UART1 byte sent.
    Uart1Tx = 3,
    /// UART2 (log channel; the stop button's input) byte received.
    Uart2Rx = 4,
    /// UART2 byte sent.
    Uart2Tx = 5,
    /// UART4 (PELCO port) byte received.
    Uart4Rx = 20,
    /// UART4 byte sent.
    Uart4Tx = 21,
    /// APB timer 0 wrapped (the time base's upper bits).
    Timer0 = 8,
    /// APB timer 1 reached zero (the alarm).
    Timer1 = 9,
    /// Dual timer (the galvo DAC's sample clock, feature `galvo-dac`).
    #[cfg(feature = "galvo-dac")]
    DualTimer = 10,
}

// SAFETY: every value is a line number below the board's 32 external
// interrupts.
unsafe impl InterruptNumber for Irq {
    fn number(self) -> u16 {
        self as u16
    }
}

/// Enables `irq` in the NVIC.
pub fn enable(irq: Irq) {
    // SAFETY: every handler in the vector table (`vectors.rs`) is ready
    // before its line is enabled (the drivers enable their lines after
    // setting up their state).
    unsafe { NVIC::unmask(irq) }
}
