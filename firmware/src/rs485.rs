//! The PELCO port's RS-485 transmit half: USART3 TX and the transceiver's
//! driver enable (PB12, DE and /RE tied together). The F4's USART has no
//! hardware driver-enable output, so the pin is driven here: high before
//! the first byte of a reply goes into the buffer, low once `flush` has
//! seen the transmission complete (TC) after the last stop bit — the port
//! task flushes after every reply (`laser_app::pelco::task`). While it is
//! high the transceiver's receiver is off (no echo of our own reply).

use embassy_stm32::gpio::Output;
use embassy_stm32::usart::{self, BufferedUartTx};
use laser_app::pelco::PelcoLine;

/// USART3's transmit half with the RS-485 driver enable.
pub struct Rs485Tx {
    /// USART3 TX (PB10), interrupt-driven, buffered.
    pub tx: BufferedUartTx<'static>,
    /// Driver enable (PB12), low (receiving) at rest.
    pub de: Output<'static>,
}

impl embedded_io_async::ErrorType for Rs485Tx {
    type Error = usart::Error;
}

impl embedded_io_async::Write for Rs485Tx {
    /// Drives the bus, then queues `buf`.
    async fn write(&mut self, buf: &[u8]) -> Result<usize, usart::Error> {
        self.de.set_high();
        embedded_io_async::Write::write(&mut self.tx, buf).await
    }

    /// Waits until the last byte has left the shift register, then
    /// releases the bus (also when the wait fails).
    async fn flush(&mut self) -> Result<(), usart::Error> {
        let done = embedded_io_async::Write::flush(&mut self.tx).await;
        self.de.set_low();
        done
    }
}

impl PelcoLine for Rs485Tx {
    /// Sets USART3's baud rate (8N1 stays); a rate the clock cannot make
    /// keeps the old one (logged; the four PELCO rates all fit 42 MHz).
    fn set_baud(&mut self, baud: u32) {
        if self.tx.set_baudrate(baud).is_err() {
            defmt::warn!("pelco: USART3 refused {} baud", baud);
        }
    }
}
