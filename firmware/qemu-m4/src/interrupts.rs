//! The MPS2 AN386's interrupt lines this board uses and its vector table
//! (`__INTERRUPTS`, which cortex-m-rt's `device` feature expects from the
//! device crate; this board has none). Lines as QEMU's `mps2-an386` wires
//! them: UART n receive at 2n and transmit at 2n + 1 (n = 0..2), UART3 at
//! 18/19, UART4 at 20/21, APB timer 0 at 8, timer 1 at 9.

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
    // SAFETY: every handler in the table below is ready before its line is
    // enabled (the drivers enable their lines after setting up their state).
    unsafe { NVIC::unmask(irq) }
}

/// One entry of the vector table.
pub type Vector = unsafe extern "C" fn();

unsafe extern "C" {
    fn DefaultHandler();
}

/// The external interrupt vectors: the drivers' handlers at their lines,
/// cortex-m-rt's default handler (a fault loop) elsewhere.
#[unsafe(link_section = ".vector_table.interrupts")]
#[unsafe(no_mangle)]
pub static __INTERRUPTS: [Vector; 32] = {
    let mut table: [Vector; 32] = [DefaultHandler; 32];
    table[Irq::Uart0Rx as usize] = crate::uart::uart0_rx;
    table[Irq::Uart0Tx as usize] = crate::uart::uart0_tx;
    table[Irq::Uart1Rx as usize] = crate::uart::uart1_rx;
    table[Irq::Uart1Tx as usize] = crate::uart::uart1_tx;
    table[Irq::Uart2Rx as usize] = crate::uart::uart2_rx;
    table[Irq::Uart2Tx as usize] = crate::uart::uart2_tx;
    table[Irq::Uart4Rx as usize] = crate::uart::uart4_rx;
    table[Irq::Uart4Tx as usize] = crate::uart::uart4_tx;
    table[Irq::Timer0 as usize] = crate::time_driver::timer0_wrapped;
    table[Irq::Timer1 as usize] = crate::time_driver::timer1_alarm;
    #[cfg(feature = "galvo-dac")]
    {
        table[Irq::DualTimer as usize] = crate::galvo_dac::dual_timer;
    }
    table
};
