//! ARM semihosting (`bkpt 0xab`): console output and the exit code, which
//! QEMU's `-semihosting-config enable=on,target=native` turns into its own.

/// SYS_WRITE0: write a NUL-terminated string to the debug console.
const SYS_WRITE0: u32 = 0x04;
/// SYS_EXIT: report an exception reason to the debugger (QEMU exits).
const SYS_EXIT: u32 = 0x18;
/// ADP_Stopped_ApplicationExit: QEMU exits with status 0.
const ADP_STOPPED_APPLICATION_EXIT: u32 = 0x2_0026;
/// ADP_Stopped_RunTimeErrorUnknown: QEMU exits with status 1.
const ADP_STOPPED_RUN_TIME_ERROR: u32 = 0x2_0023;

/// One semihosting call: operation in r0, parameter in r1.
fn call(op: u32, arg: u32) -> u32 {
    #[cfg(target_arch = "arm")]
    {
        let r: u32;
        // SAFETY: the semihosting breakpoint; the host reads only the
        // buffer `arg` points to (NUL-terminated for SYS_WRITE0).
        unsafe {
            core::arch::asm!(
                "bkpt #0xab",
                inout("r0") op => r,
                in("r1") arg,
                options(nostack, readonly),
            );
        }
        r
    }
    #[cfg(not(target_arch = "arm"))]
    {
        let _ = (op, arg);
        0
    }
}

/// Line-buffered console output.
pub struct Out {
    buf: [u8; 256],
    len: usize,
}

impl Out {
    /// An empty buffer.
    pub const fn new() -> Self {
        Self {
            buf: [0; 256],
            len: 0,
        }
    }

    /// Writes the buffered text.
    pub fn flush(&mut self) {
        if self.len == 0 {
            return;
        }
        if let Some(end) = self.buf.get_mut(self.len) {
            *end = 0;
        }
        call(SYS_WRITE0, self.buf.as_ptr() as u32);
        self.len = 0;
    }
}

impl core::fmt::Write for Out {
    fn write_str(&mut self, s: &str) -> core::fmt::Result {
        for &c in s.as_bytes() {
            // Keep one byte for the terminating NUL.
            if self.len + 1 >= self.buf.len() {
                self.flush();
            }
            if let Some(slot) = self.buf.get_mut(self.len) {
                *slot = c;
                self.len += 1;
            }
        }
        Ok(())
    }
}

/// Ends the run: QEMU exits with status 0 (`success`) or 1.
pub fn exit(success: bool) -> ! {
    let reason = if success {
        ADP_STOPPED_APPLICATION_EXIT
    } else {
        ADP_STOPPED_RUN_TIME_ERROR
    };
    loop {
        call(SYS_EXIT, reason);
    }
}
