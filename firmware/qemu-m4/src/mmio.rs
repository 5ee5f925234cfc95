//! A memory-mapped 32-bit register of the MPS2 AN386's APB peripherals.

/// The register at this address.
#[derive(Debug, Clone, Copy)]
pub struct Reg(pub usize);

impl Reg {
    /// Reads the register.
    #[inline(always)]
    pub fn read(self) -> u32 {
        // SAFETY: every `Reg` the board builds is a peripheral register of
        // the MPS2 AN386 memory map (aligned, always mapped).
        unsafe { (self.0 as *const u32).read_volatile() }
    }

    /// Writes the register.
    #[inline(always)]
    pub fn write(self, value: u32) {
        // SAFETY: as in `read`.
        unsafe { (self.0 as *mut u32).write_volatile(value) }
    }

    /// Sets the bits of `mask`.
    #[inline(always)]
    pub fn set_bits(self, mask: u32) {
        self.write(self.read() | mask);
    }

    /// Clears the bits of `mask`.
    #[inline(always)]
    pub fn clear_bits(self, mask: u32) {
        self.write(self.read() & !mask);
    }
}
