//! The board's vector table of external interrupts (`__INTERRUPTS`, which
//! cortex-m-rt's `device` feature expects from the device crate; this
//! board has none): each driver's handler at its line (`interrupts.rs`).

use crate::interrupts::Irq;

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
