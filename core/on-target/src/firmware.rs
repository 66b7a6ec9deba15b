//! The firmware side: output over semihosting, exit codes, static buffers.
#![allow(unsafe_code)]

pub use semihosting::{print, println};

/// Ends the emulation with `code` (QEMU exits with it).
pub fn exit(code: i32) -> ! {
    semihosting::process::exit(code)
}

/// A `&'static mut` to a `static mut` array, for `main` to call once per
/// buffer.
#[macro_export]
macro_rules! take {
    ($name:ident) => {{
        // SAFETY: called once, from `main`, before anything else can
        // refer to the static.
        #[allow(unsafe_code)]
        unsafe {
            &mut *(&raw mut $name)
        }
    }};
}

/// Stack painting: the bytes of stack `f` used, measured by filling the
/// free stack below the caller's stack pointer with a pattern, running
/// `f`, and finding the lowest word the pattern no longer holds. The
/// figure is the deepest point `f` reached on these inputs (its frames and
/// everything it called, the call into it included); other inputs may go
/// deeper. Interrupts must not fire meanwhile (their frames would count).
pub fn stack_use<R>(window: usize, f: impl FnOnce() -> R) -> (R, usize) {
    const PAINT: u32 = 0x5aa5_c33c;
    let sp: usize;
    // SAFETY: reads the stack pointer; no memory access.
    unsafe {
        core::arch::asm!("mov {}, sp", out(reg) sp, options(nomem, nostack, preserves_flags))
    };
    let top = sp & !3;
    let low = top - window;
    let mut p = low;
    while p < top {
        // SAFETY: `low..top` lies below the stack pointer: free stack that
        // nothing else uses (the firmware's statics sit far below it).
        unsafe { core::ptr::write_volatile(p as *mut u32, PAINT) };
        p += 4;
    }
    let r = f();
    let mut q = low;
    // SAFETY: as above; `f` has returned, so nothing lives there now.
    while q < top && unsafe { core::ptr::read_volatile(q as *const u32) } == PAINT {
        q += 4;
    }
    (r, top - q)
}

/// Retired-instruction counting through SysTick. Under `qemu-system-arm
/// -icount shift=0` every guest instruction advances the virtual clock by
/// 1 ns, and the MPS2 boards clock SysTick from their 25 MHz system clock,
/// so one SysTick decrement is 40 instructions (the firmware measures the
/// ratio on a loop of known length, [`calibrate`]). The figure counts
/// instructions, not cycles: a Cortex-M4 takes more cycles than
/// instructions (loads, taken branches, multi-cycle multiplies).
pub mod systick {
    use core::sync::atomic::{AtomicU32, Ordering};

    const CSR: *mut u32 = 0xe000_e010 as *mut u32;
    const RVR: *mut u32 = 0xe000_e014 as *mut u32;
    const CVR: *mut u32 = 0xe000_e018 as *mut u32;
    const RELOAD: u32 = 0x00ff_ffff;

    static WRAPS: AtomicU32 = AtomicU32::new(0);

    /// Counts a wrap of the 24-bit counter (the SysTick exception).
    pub fn on_wrap() {
        WRAPS.store(
            WRAPS.load(Ordering::Relaxed).wrapping_add(1),
            Ordering::Relaxed,
        );
    }

    /// Starts the counter at the processor clock with its wrap exception.
    pub fn start() {
        // SAFETY: the architected SysTick registers of every Cortex-M.
        unsafe {
            core::ptr::write_volatile(RVR, RELOAD);
            core::ptr::write_volatile(CVR, 0);
            core::ptr::write_volatile(CSR, 0b111);
            // The first decrement loads the reload value; count from there.
            while core::ptr::read_volatile(CVR) == 0 {}
        }
        WRAPS.store(0, Ordering::Relaxed);
    }

    /// Stops the counter (and its exception).
    pub fn stop() {
        // SAFETY: as in `start`.
        unsafe { core::ptr::write_volatile(CSR, 0) };
    }

    /// SysTick decrements since `start`.
    pub fn ticks() -> u64 {
        loop {
            let w = WRAPS.load(Ordering::Relaxed);
            // SAFETY: as in `start`.
            let v = unsafe { core::ptr::read_volatile(CVR) };
            if WRAPS.load(Ordering::Relaxed) == w {
                return u64::from(w) * u64::from(RELOAD + 1) + u64::from(RELOAD - v);
            }
        }
    }

    /// Ticks taken by a loop of `2 * n` instructions (`subs`, `bne`).
    pub fn calibrate(n: u32) -> u64 {
        let t0 = ticks();
        // SAFETY: a register-only countdown loop.
        unsafe {
            core::arch::asm!(
                "2:",
                "subs {n}, #1",
                "bne 2b",
                n = inout(reg) n => _,
                options(nomem, nostack),
            );
        }
        ticks() - t0
    }
}
