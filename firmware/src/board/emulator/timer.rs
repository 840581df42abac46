//! The Arm CMSDK APB timer of the MPS2 (QEMU's `cmsdk-apb-timer`): a 32-bit down-counter on
//! the 25 MHz system clock, used here in one-shot mode (RELOAD = 0): the interrupt comes when
//! VALUE reaches 0, and the line stays high until INTSTATUS is written.

use core::ptr::write_volatile;

const CTRL: usize = 0x0;
const VALUE: usize = 0x4;
const RELOAD: usize = 0x8;
const INTSTATUS: usize = 0xC;
const CTRL_ENABLE: u32 = 1 << 0;
const CTRL_IRQ_ENABLE: u32 = 1 << 3;

/// One timer at its register block's address.
#[derive(Clone, Copy)]
pub struct CmsdkTimer {
    base: usize,
}

impl CmsdkTimer {
    pub const fn at(base: usize) -> Self {
        Self { base }
    }

    fn write(self, offset: usize, value: u32) {
        // SAFETY: a write to one of the timer's registers.
        unsafe { write_volatile((self.base + offset) as *mut u32, value) }
    }

    /// Interrupts once, `ticks` (≥ 1) clock ticks from now.
    pub fn one_shot(self, ticks: u32) {
        self.write(CTRL, 0);
        self.write(RELOAD, 0);
        // VALUE before ENABLE: QEMU disables a timer enabled with a zero count.
        self.write(VALUE, ticks.max(1));
        self.write(INTSTATUS, 1);
        self.write(CTRL, CTRL_ENABLE | CTRL_IRQ_ENABLE);
    }

    /// Stops the timer and clears its interrupt.
    pub fn stop(self) {
        self.write(CTRL, 0);
        self.write(INTSTATUS, 1);
    }

    /// Clears the interrupt (before the handler returns: the line is level-sensitive).
    pub fn clear(self) {
        self.write(INTSTATUS, 1);
    }
}
