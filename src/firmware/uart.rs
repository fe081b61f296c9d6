//! A driver for the CMSDK APB UART (Arm Cortex-M System Design Kit, DDI0479C §4.3), the UARTs of
//! the MPS2 boards; UART0 of `mps2-an386` carries the processor-in-the-loop link's frames.
//!
//! The UART has no FIFO: one byte of transmit and one of receive buffer. [`Uart`] polls its
//! STATE register and implements the `embedded-io` byte-stream traits, blocking for at most
//! [`MAX_POLLS`] polls (then [`UartError::TimedOut`]), so no call can hang.
//!
//! QEMU's model (`hw/char/cmsdk-apb-uart.c`) ignores the baud rate (bytes move as fast as the
//! character backend takes them) but only transmits when TX is enabled with BAUDDIV ≥ 16, and
//! only accepts a byte when RX is enabled and the receive buffer is empty.

use core::ptr;

/// Base address of UART0 on `mps2-an386` (AN386 application note, memory map: APB UART0).
pub const UART0_BASE: usize = 0x4000_4000;

/// APB clock of the MPS2 FPGA images, Hz (QEMU: `pclk-frq` of the board's UARTs).
pub const PCLK_HZ: u32 = 25_000_000;

/// Line rate of the link, bit/s (on hardware; QEMU does not pace bytes).
pub const BAUD: u32 = 115_200;

/// The smallest BAUDDIV the UART accepts (DDI0479C: "must be at least 16").
const BAUDDIV_MIN: u32 = 16;

/// Register offsets (DDI0479C Table 4-4).
const DATA: usize = 0x00;
const STATE: usize = 0x04;
const CTRL: usize = 0x08;
const BAUDDIV: usize = 0x10;

/// STATE bits.
const STATE_TX_FULL: u32 = 1 << 0;
const STATE_RX_FULL: u32 = 1 << 1;
const STATE_TX_OVERRUN: u32 = 1 << 2;
const STATE_RX_OVERRUN: u32 = 1 << 3;

/// CTRL bits.
const CTRL_TX_EN: u32 = 1 << 0;
const CTRL_RX_EN: u32 = 1 << 1;

/// Largest number of STATE polls one blocking call makes before it gives up.
pub const MAX_POLLS: u32 = 1 << 24;

/// A UART failure.
#[derive(Clone, Copy, Debug, PartialEq, Eq, defmt::Format)]
pub enum UartError {
    /// No byte (read) or no room (write) within [`MAX_POLLS`] polls.
    TimedOut,
    /// A received byte was overwritten before it was read (counted, then cleared).
    Overrun,
}

impl core::fmt::Display for UartError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str(match self {
            Self::TimedOut => "UART timed out",
            Self::Overrun => "UART receive overrun",
        })
    }
}

impl core::error::Error for UartError {}

impl embedded_io::Error for UartError {
    fn kind(&self) -> embedded_io::ErrorKind {
        match self {
            Self::TimedOut => embedded_io::ErrorKind::TimedOut,
            Self::Overrun => embedded_io::ErrorKind::Other,
        }
    }
}

/// One CMSDK APB UART, owned: nothing else touches its registers.
pub struct Uart {
    base: usize,
    overruns: u32,
}

impl Uart {
    /// Takes UART0 of `mps2-an386` and enables it at [`BAUD`], 8N1, polled (no interrupts).
    ///
    /// Call once: a second instance would share the registers.
    pub fn uart0() -> Self {
        let mut uart = Self {
            base: UART0_BASE,
            overruns: 0,
        };
        let div = (PCLK_HZ / BAUD).max(BAUDDIV_MIN);
        uart.write_reg(CTRL, 0);
        uart.write_reg(BAUDDIV, div);
        uart.write_reg(STATE, STATE_TX_OVERRUN | STATE_RX_OVERRUN); // write 1 to clear
        uart.write_reg(CTRL, CTRL_TX_EN | CTRL_RX_EN);
        uart
    }

    /// Receive overruns seen so far (bytes lost because the previous one was not read in time).
    pub fn overruns(&self) -> u32 {
        self.overruns
    }

    /// One byte if one has arrived, without waiting.
    pub fn try_read_byte(&mut self) -> Result<Option<u8>, UartError> {
        let state = self.read_reg(STATE);
        if state & STATE_RX_OVERRUN != 0 {
            self.write_reg(STATE, STATE_RX_OVERRUN);
            self.overruns = self.overruns.saturating_add(1);
            return Err(UartError::Overrun);
        }
        if state & STATE_RX_FULL == 0 {
            return Ok(None);
        }
        // Only the low 8 bits of DATA are the byte.
        Ok(Some((self.read_reg(DATA) & 0xff) as u8))
    }

    fn wait_tx_room(&mut self) -> Result<(), UartError> {
        for _ in 0..MAX_POLLS {
            if self.read_reg(STATE) & STATE_TX_FULL == 0 {
                return Ok(());
            }
        }
        Err(UartError::TimedOut)
    }

    fn read_reg(&self, offset: usize) -> u32 {
        let addr = (self.base + offset) as *const u32;
        // SAFETY: `base` is the UART's register block (constructed only by `uart0` with the
        // board's UART0 address) and `offset` one of the register offsets above: an aligned,
        // always-mapped device register. A volatile read is the required access; it has no
        // effect on memory that Rust owns.
        #[allow(unsafe_code)]
        unsafe {
            ptr::read_volatile(addr)
        }
    }

    fn write_reg(&mut self, offset: usize, value: u32) {
        let addr = (self.base + offset) as *mut u32;
        // SAFETY: as in `read_reg`; `&mut self` makes this the only writer of the registers.
        #[allow(unsafe_code)]
        unsafe {
            ptr::write_volatile(addr, value)
        }
    }
}

impl embedded_io::ErrorType for Uart {
    type Error = UartError;
}

impl embedded_io::ReadReady for Uart {
    fn read_ready(&mut self) -> Result<bool, UartError> {
        Ok(self.read_reg(STATE) & STATE_RX_FULL != 0)
    }
}

impl embedded_io::Read for Uart {
    /// Blocks until at least one byte has arrived (at most [`MAX_POLLS`] polls), then returns
    /// the bytes already there, up to `buf.len()`.
    fn read(&mut self, buf: &mut [u8]) -> Result<usize, UartError> {
        let mut n = 0;
        for _ in 0..MAX_POLLS {
            let Some(slot) = buf.get_mut(n) else {
                break;
            };
            match self.try_read_byte()? {
                Some(b) => {
                    *slot = b;
                    n += 1;
                }
                None if n > 0 => break,
                None => {}
            }
        }
        if n == 0 && !buf.is_empty() {
            return Err(UartError::TimedOut);
        }
        Ok(n)
    }
}

impl embedded_io::WriteReady for Uart {
    fn write_ready(&mut self) -> Result<bool, UartError> {
        Ok(self.read_reg(STATE) & STATE_TX_FULL == 0)
    }
}

impl embedded_io::Write for Uart {
    /// Sends every byte of `buf`, each as soon as the transmit buffer has room.
    fn write(&mut self, buf: &[u8]) -> Result<usize, UartError> {
        // In detail (`DEFMT_LOG=trace`): the PIL link writes one whole encoded frame per call.
        defmt::trace!("uart0 tx {=usize} bytes: {=[u8]:02x}", buf.len(), buf);
        for &b in buf {
            self.wait_tx_room()?;
            self.write_reg(DATA, u32::from(b));
        }
        Ok(buf.len())
    }

    /// Waits until the last byte has left the transmit buffer.
    fn flush(&mut self) -> Result<(), UartError> {
        self.wait_tx_room()
    }
}
